// The render policies and the report a front end gets from viewer/render_job.h. No device: these
// are the pure parts.
#include "viewer/render_job.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/memory.h"
#include "test_support.h"
#include "viewer/render.h"


namespace dpoint {
namespace {

Bounds cube() { return Bounds{glm::dvec3(-1.0), glm::dvec3(1.0), false}; }

DeviceFacts bigPoints() {
  DeviceFacts facts;
  facts.large_points = true;
  facts.max_point_size = 64.0f;
  return facts;
}

Camera cameraFor(const RenderRequest& request, const Bounds& bounds) {
  Result<std::vector<Camera>> cameras = viewCameras(request, viewsFor(1, zUpFor(request)), bounds, zUpFor(request));
  EXPECT_TRUE(cameras.ok());
  return cameras.ok() ? cameras->front() : Camera{};
}

// A stream's block under --max-memory: two of them (36 B a point) within the limit, whole units of
// 65536 points, from 2^20 to 2^24 points; 0 is the default limit's. A limit that holds not even two
// of the smallest is refused for a set that large.
TEST(StreamBlocks, sizedByMaxMemory) {
  const uint64_t mib = uint64_t{1} << 20;
  EXPECT_EQ(streamBlockPoints(1024 * mib), 227 * kStreamBlockUnit);  // 2^30 / 72 = 14.9M points
  EXPECT_EQ(streamBlockPoints(100 * mib), 22 * kStreamBlockUnit);
  EXPECT_EQ(streamBlockPoints(10 * mib), kMinStreamBlockPoints);
  EXPECT_EQ(streamBlockPoints(uint64_t{1} << 40), kStreamBlockPoints);
  EXPECT_EQ(streamBlockPoints(0), streamBlockPoints(defaultMemoryLimit()));
  for (uint64_t limit : {80 * mib, 100 * mib, 1000 * mib, 1200 * mib})
    EXPECT_LE(2 * streamBlockPoints(limit) * kStreamPointBytes, limit) << limit;
  const Result<uint64_t> fits = checkStreamMemory("s.ply", 100000000, 100 * mib);
  ASSERT_TRUE(fits);
  EXPECT_EQ(*fits, streamBlockPoints(100 * mib));  // the block to read in
  EXPECT_TRUE(checkStreamMemory("s.ply", 1000, mib));
  const Result<uint64_t> tight = checkStreamMemory("s.ply", 100000000, 50 * mib);
  ASSERT_FALSE(tight);
  EXPECT_EQ(tight.error().code, ExitCode::kResourceLimit);
}

TEST(RenderJob, pointSizeGrowsOnlyForSparse3dSets) {
  RenderRequest request;
  const Camera camera = cameraFor(request, cube());
  EXPECT_EQ(pointSizeFor(request, 100, cube(), camera, bigPoints()), 4.0f) << "a few points: at most 4 px";
  EXPECT_EQ(pointSizeFor(request, 100000000, cube(), camera, bigPoints()), 1.0f) << "dense: 1 px";
  const float middle = pointSizeFor(request, 1000000, cube(), camera, bigPoints());
  EXPECT_GT(middle, 1.0f);
  EXPECT_LT(middle, 4.0f);
  DeviceFacts small = bigPoints();
  small.max_point_size = 2.0f;
  EXPECT_EQ(pointSizeFor(request, 100, cube(), camera, small), 2.0f) << "never above the device's largest";
  small.large_points = false;
  EXPECT_EQ(pointSizeFor(request, 100, cube(), camera, small), 1.0f);
  RenderRequest error = request;
  error.error = true;
  EXPECT_EQ(pointSizeFor(error, 100, cube(), camera, bigPoints()), 1.0f) << "--error: the reference's 1-px points";
  RenderRequest compute = request;
  compute.backend = Backend::kCompute;
  EXPECT_EQ(pointSizeFor(compute, 100, cube(), camera, small), 2.0f) << "compute draws squares without largePoints";
  EXPECT_EQ(pointSizeFor(compute, 1000000, cube(), camera, bigPoints()), middle) << "the same size on both backends";
  RenderRequest ortho = request;
  ortho.camera.ortho = true;
  EXPECT_EQ(pointSizeFor(ortho, 100, cube(), cameraFor(ortho, cube()), bigPoints()), 1.0f);
  request.point_size = 2.5;
  EXPECT_EQ(pointSizeFor(request, 100000000, cube(), camera, bigPoints()), 2.5f) << "asked for: kept";
}

TEST(RenderJob, backendAutoIsComputeWhereTheDeviceRunsIt) {
  DeviceFacts facts;
  facts.int64_atomics = true;
  facts.max_storage_buffer_range = uint64_t{1} << 27;  // 128 MiB
  RenderRequest request;
  EXPECT_EQ(backendFor(request, 1000, 1024, 768, facts), Backend::kCompute);
  EXPECT_EQ(backendFor(request, uint64_t{1} << 26, 1024, 768, facts), Backend::kRaster) << "colours over the range";
  EXPECT_EQ(backendFor(request, 1000, 8192, 8192, facts), Backend::kRaster) << "keys over the range";
  request.backend = Backend::kRaster;
  EXPECT_EQ(backendFor(request, 1000, 1024, 768, facts), Backend::kRaster) << "asked for: kept";
  request.backend.reset();
  facts.int64_atomics = false;
  EXPECT_EQ(backendFor(request, 1000, 1024, 768, facts), Backend::kRaster);
}

TEST(RenderJob, viewsAndTheirCameras) {
  std::vector<RenderView> one = viewsFor(1, false);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_STREQ(one[0].label, "three-quarter");
  std::vector<RenderView> four = viewsFor(4, true);
  ASSERT_EQ(four.size(), 4u);
  EXPECT_STREQ(four[0].label, "front");
  EXPECT_EQ(four[0].direction, glm::dvec3(0, -1, 0)) << "z up: front looks along +y";
  EXPECT_EQ(four[2].up, glm::dvec3(0, 1, 0)) << "z up: the top view's up is y";
  EXPECT_EQ(viewsFor(4, false)[2].up, glm::dvec3(0, 0, -1));

  RenderRequest request;
  request.views = 4;
  request.camera.width = 401, request.camera.height = 300;
  Result<std::vector<Camera>> cameras = viewCameras(request, viewsFor(4, false), cube(), false);
  ASSERT_TRUE(cameras.ok());
  ASSERT_EQ(cameras->size(), 4u);
  // A quarter less the 2-px lines, rounded down: the sheet is 401 x 300 (the odd pixel goes to a line).
  for (const Camera& c : *cameras) EXPECT_EQ(std::make_pair(c.width, c.height), std::make_pair(199u, 149u));
  EXPECT_NE((*cameras)[0].eye, (*cameras)[1].eye);
}

TEST(RenderJob, upAxisShadingAndRequestChecks) {
  RenderRequest request;
  request.inputs = {"a.LAS", "b.las"};
  EXPECT_TRUE(zUpFor(request));
  request.inputs.push_back("c.ply");
  EXPECT_FALSE(zUpFor(request));
  EXPECT_TRUE(zUpFor(request, true));  // the data records z up (a PLY written from LAS)
  request.up_axis = UpAxis::kZ;
  EXPECT_TRUE(zUpFor(request));
  request.up_axis = UpAxis::kY;
  EXPECT_FALSE(zUpFor(request, true));

  Bounds flat = cube();
  flat.planar = true;
  EXPECT_EQ(shadingFor(request, cube()), Shading::kEdl);
  EXPECT_EQ(shadingFor(request, flat), Shading::kNone);
  request.shading = Shading::kEdl;
  EXPECT_EQ(shadingFor(request, flat), Shading::kEdl);
  request.shading.reset();
  request.error = true;
  EXPECT_EQ(shadingFor(request, cube()), Shading::kNone) << "--error compares plain pixels";

  EXPECT_TRUE(checkPictureOutput("a.PNG").ok());
  EXPECT_TRUE(checkPictureOutput("/dev/null").ok());
  EXPECT_EQ(checkPictureOutput("a.jpg").error().message, "-o a.jpg: the picture is written as PNG; name it .png");
  EXPECT_EQ(checkModeName("emulated").error().message,
            "--mode emulated: must be auto, fp32, split, rte, df64, native, batch or adaptive");
  EXPECT_TRUE(checkModeName("auto").ok() && checkModeName("df64").ok());
  RenderRequest sheet;
  sheet.views = 4;
  EXPECT_TRUE(checkRenderRequest(sheet).ok());
  sheet.report = true;
  EXPECT_EQ(checkRenderRequest(sheet).error().code, ExitCode::kUsage);
  sheet.report = false;
  sheet.camera.width = 3;
  EXPECT_EQ(checkRenderRequest(sheet).error().message, "--views 4 needs --width and --height of at least 4 px, got 3x768");
  sheet.views = 2;
  EXPECT_EQ(checkRenderRequest(sheet).error().message, "--views 2: must be 1 or 4");
}

TEST(RenderJob, reportHasTheKeysInOrderAndNullsWhereNothingWasMeasured) {
  RenderRequest request;
  request.mode = "fp32";
  request.camera.width = 64, request.camera.height = 48;
  RenderOutcome outcome;
  outcome.points = 10;
  outcome.device.name = "dev \"1\"";
  outcome.device.type = "cpu";
  outcome.prediction.mode = *parseMode("fp32");
  outcome.prediction.bound_px = std::nan("");
  outcome.result.frame_ms = {2.0, 4.0};
  outcome.result.chunks = 1;
  outcome.point_size = 2.5f;
  outcome.shading = Shading::kEdl;
  outcome.phases.mark("read");
  outcome.error = ErrorReport{};
  outcome.error->stats.points = 3;
  outcome.error->stats.lost = 3;
  const std::string json = renderReportJson(request, outcome);
  EXPECT_EQ(json.rfind("{\n  \"mode\": \"fp32\",\n  \"mode_requested\": \"fp32\",\n  \"predicted_bound_px\": null,\n"
                       "  \"predicted_from\": \"points\",\n  \"backend\": \"raster\",\n  \"order\": \"input\",\n  \"device\": \"dev \\\"1\\\"\",\n", 0),
            0u)
      << json;
  for (const char* line : {"  \"width\": 64,\n  \"height\": 48,\n  \"point_size\": 2.5,\n  \"shading\": \"edl\",\n"
                           "  \"frames\": 2,\n  \"gpu_ms\": null,\n",
                           "  \"frame_ms\": {\"median\": 3, \"p95\": 4},\n", "\"phases_ms\": {\"read\": ",
                           "  \"native_path\": null,\n  \"splat_order\": null,\n  \"error_px\": null,\n",
                           "  \"points_visible\": 3,\n  \"points_lost\": 3,\n  \"pixels_differing\": null,\n"
                           "  \"drawn_share\": null,\n  \"warnings\": []\n}\n"})
    EXPECT_NE(json.find(line), std::string::npos) << line << " in\n" << json;
  EXPECT_EQ(json.find("\"auto\""), std::string::npos) << "no choice made: no auto member";
}

// The warnings are data: a forced mode over 0.5 px names its bound and auto's pick; auto with no
// mode within 0.1 px says which is the most accurate; a picture drawn on under 1% of its pixels,
// or on none, says so. The report lists them, and auto's rejected modes with their bounds.
TEST(RenderJob, warningsSayWhenThePictureIsWrongOrPoor) {
  RenderRequest request;
  request.mode = "fp32";
  ModePrediction forced;
  forced.mode = *parseMode("fp32");
  forced.bound_px = 136.0;
  EXPECT_EQ(predictionWarning(request, forced, parseMode("native")),
            "--mode fp32: predicted error up to 1.4e+02 px (> 0.5 px): the picture is wrong here; --mode auto picks native");
  forced.bound_px = std::numeric_limits<double>::infinity();
  EXPECT_EQ(predictionWarning(request, forced, parseMode("rte")),
            "--mode fp32: predicted error unbounded (> 0.5 px): the picture is wrong here; --mode auto picks rte");
  forced.bound_px = 0.5;
  EXPECT_EQ(predictionWarning(request, forced, std::nullopt), "") << "0.5 px itself is not wrong";
  request.mode = "auto";
  ModePrediction chosen;
  chosen.mode = *parseMode("native");
  chosen.bound_px = 0.3;
  chosen.choice = ModeChoice{};
  chosen.choice->enough = false;
  EXPECT_EQ(predictionWarning(request, chosen, std::nullopt),
            "no mode this device runs stays within 0.1 px for this view; native is the most accurate here (bound 0.3 px)");
  chosen.choice->enough = true;
  EXPECT_EQ(predictionWarning(request, chosen, std::nullopt), "");

  Image image{10, 10, std::vector<uint8_t>(400, 0)};
  for (size_t i = 0; i < 100; ++i) image.rgba[4 * i + 3] = 255;
  EXPECT_EQ(drawnPixels(image, 0xff000000u).share(), 0.0);
  EXPECT_TRUE(coverWarning(0.0).starts_with("the picture shows nothing: no point was drawn in the view"));
  image.rgba[4 * 55] = 200;
  EXPECT_EQ(drawnPixels(image, 0xff000000u).share(), 0.01);
  EXPECT_EQ(drawnPixels(image, 0xff0000c8u).share(), 0.99) << "the background is what is not drawn";
  EXPECT_EQ(coverWarning(0.01), "") << "1% itself is enough";
  EXPECT_TRUE(coverWarning(0.005).starts_with("the data covers 0.5% of the picture (under 1%)")) << coverWarning(0.005);
  EXPECT_TRUE(coverWarning(0.005, 0.2).ends_with("frame it closer with --view-center and --view-width, or --eye and --target"));
  // Sparse points that span the picture ask for larger points, not a closer frame.
  EXPECT_TRUE(coverWarning(0.005, 0.9).ends_with("larger points (--point-size N) show more")) << coverWarning(0.005, 0.9);
  EXPECT_EQ(drawnPixels(image, 0xff000000u).span(), 0.1) << "drawn pixels reach 10% of the smaller side";

  RenderOutcome outcome;
  outcome.device.type = "cpu";
  outcome.prediction = chosen;
  outcome.prediction.choice->rejected = {{*parseMode("fp32"), 3.5, ""}, {*parseMode("rte"), std::nan(""), "needs X"}};
  outcome.warnings = {"a \"quoted\" warning", "two"};
  outcome.drawn_share = 0.25;
  const std::string json = renderReportJson(request, outcome);
  EXPECT_TRUE(test::contains(json, "\"rejected\": [{\"mode\": \"fp32\", \"predicted_bound_px\": 3.5, \"usable\": true}, "
                                   "{\"mode\": \"rte\", \"predicted_bound_px\": null, \"usable\": false, \"reason\": \"needs X\"}]}"))
      << json;
  EXPECT_TRUE(test::contains(json, "  \"drawn_share\": 0.25,\n  \"warnings\": [\"a \\\"quoted\\\" warning\", \"two\"]\n}\n")) << json;
}

}  // namespace
}  // namespace dpoint
