// The renderer on real Vulkan (Mesa lavapipe in CI) with the Khronos validation layer on: every
// test fails on any validation message. The hard cases are DESIGN §7's, at small sizes.
#include <cstdio>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>

#include "generators/mandelbrot2d.h"
#include "viewer/camera.h"
#include "vulkan/context.h"
#include "viewer/probe.h"
#include "viewer/render.h"
#include "viewer/selftest.h"
#include "ortho_camera.h"
#include "render_test_support.h"

namespace dpoint {
namespace {

// Every test runs on both backends (raster and compute): same modes, same projection code.
class Render : public VulkanRenderTest {};

// The guard itself: the layer is on and a misuse reaches the message list the tests check.
TEST_P(Render, validationLayerReportsMisuse) {
  VkBufferCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  info.size = 0;  // VUID-VkBufferCreateInfo-size-00912
  info.usage = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT;
  VkBuffer buffer = VK_NULL_HANDLE;
  if (vkCreateBuffer(context_->device, &info, nullptr, &buffer) == VK_SUCCESS && buffer)
    vkDestroyBuffer(context_->device, buffer, nullptr);
  ASSERT_FALSE(context_->validationMessages().empty());
  EXPECT_NE(context_->validationMessages()[0].find("00912"), std::string::npos) << context_->validationMessages()[0];
  context_->clearValidationMessages();
}

// What the double modes hold to on the DESIGN §7 offset and scale cases: 0.01 px, but adaptive,
// which loads as few tiers as keep it within its tolerance (0.05 px) and no closer.
double heldWithin(PrecisionMode mode) { return mode == PrecisionMode::kAdaptive ? kDefaultTolerancePx : 0.01; }

TEST_P(Render, selfTestKeepsTheLowPartsOnThisDevice) {
  Result<SelfTest> t = runPrecisionSelfTest(*context_);
  ASSERT_TRUE(t.ok()) << t.error().message;
  EXPECT_TRUE(t->low_parts_survive) << t->detail;
}

// DESIGN §7 offset: 1000 points 1 mm apart at the Earth's radius, the camera 1 m away.
TEST_P(Render, earthRadiusOffsetSeparatesTheFloatModesFromTheDoubleOnes) {
  const glm::dvec3 centre(6.378e6, 0.0, 0.0);
  PointSet s = cloud(centre, 1e-3);
  Camera camera = lookAtCloud(s, centre, 1.0);
  for (PrecisionMode mode : kAllModes) {
    Measured m = measure(s, camera, mode);
    const ErrorStats& e = m.error.stats;
    ASSERT_EQ(e.points, s.size()) << "the reference sees the whole cloud";
    if (mode == PrecisionMode::kFp32 || mode == PrecisionMode::kSplit) {
      // float spacing at 6.4e6 is 0.5 m: the cloud collapses; points land far off or leave the view.
      EXPECT_TRUE(e.max_px >= 1.0 || e.lost > 0) << modeName(mode) << " max " << e.max_px;
      EXPECT_GT(e.share_off_half_px, 0.5) << modeName(mode);
    } else {
      EXPECT_EQ(e.lost, 0u) << modeName(mode);
      EXPECT_LE(e.max_px, heldWithin(mode)) << modeName(mode);
      EXPECT_EQ(e.share_off_half_px, 0.0) << modeName(mode);
    }
  }
}

// Measured on lavapipe: at 1e8 every emulated mode still holds to 0.01 px; fp32 and split fail.
TEST_P(Render, offset1e8HoldsForEveryDoubleMode) {
  const glm::dvec3 centre(1e8, -2e7, 5e7);
  PointSet s = cloud(centre, 1e-3);
  Camera camera = lookAtCloud(s, centre, 1.0);
  for (PrecisionMode mode : kAllModes) {
    const ErrorStats e = measure(s, camera, mode).error.stats;
    RecordProperty(std::string(modeName(mode)) + "_max_px", std::to_string(e.max_px));
    if (mode == PrecisionMode::kFp32 || mode == PrecisionMode::kSplit) {
      EXPECT_GT(e.share_off_half_px, 0.5) << modeName(mode);
    } else {
      EXPECT_EQ(e.lost, 0u) << modeName(mode);
      EXPECT_LE(e.max_px, heldWithin(mode)) << modeName(mode) << " rms " << e.rms_px;
    }
  }
}

// The same cloud scaled down to 1e-40 m spacing at the origin, camera 1e-37 m away. Every mode
// that works in the scene frame (viewer/encode.h) sees the same numbers as at 1 mm and holds;
// fp32 and split (absolute) hinge on float subnormals, which devices flush as they like: only
// recorded. (Before the scene frame, df64 lost every point here and rte/batch failed on
// lavapipe's vertex stage.)
TEST_P(Render, tinyScaleNearTheOriginHoldsInEverySceneFrameMode) {
  const glm::dvec3 centre(0.0);
  PointSet s = cloud(centre, 1e-40);
  Camera camera = lookAtCloud(s, centre, 1e-37);
  for (PrecisionMode mode : kAllModes) {
    const ErrorStats e = measure(s, camera, mode).error.stats;
    ASSERT_EQ(e.points, s.size());
    RecordProperty(std::string(modeName(mode)) + "_max_px", std::to_string(e.max_px));
    if (!modeInfo(mode).scene_frame) continue;
    EXPECT_EQ(e.lost, 0u) << modeName(mode);
    EXPECT_LE(e.max_px, heldWithin(mode)) << modeName(mode) << " rms " << e.rms_px;
  }
}

// DESIGN §7 deepzoom at view width 1e-9: one grid point per pixel centre.
TEST_P(Render, deepZoomPutsEveryPointOnItsOwnPixelInDoubleModes) {
  const DeepZoom zoom = deepZoom(1e-9, 96, 600);
  ASSERT_FALSE(zoom.grid.positions.empty());
  const PointSet* grid = &zoom.grid;
  const Camera* camera = &zoom.camera;
  for (PrecisionMode mode : kAllModes) {
    Measured m = measure(*grid, *camera, mode);
    if (mode == PrecisionMode::kFp32 || mode == PrecisionMode::kSplit) {
      EXPECT_GT(m.error.pixels_differing, grid->size() / 2) << modeName(mode);
    } else {
      EXPECT_EQ(m.error.pixels_differing, 0u) << modeName(mode);
      EXPECT_EQ(m.error.stats.share_off_half_px, 0.0) << modeName(mode);
      EXPECT_LT(m.error.stats.max_px, 0.01) << modeName(mode);
    }
  }
}

TEST_P(Render, emptySetIsAClearError) {
  PointSet empty;
  Camera camera = *makeCamera(CameraSpec{}, Bounds{});
  RenderOptions options;
  options.backend = GetParam();
  Result<RenderResult> r = renderPoints(*context_, empty, camera, options);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ExitCode::kBadInput);
  EXPECT_NE(r.error().message.find("empty"), std::string::npos) << r.error().message;
}

size_t litPixels(const Image& image, uint32_t background) {
  size_t lit = 0;
  for (size_t i = 0; i < image.rgba.size(); i += 4) {
    uint32_t v = image.rgba[i] | image.rgba[i + 1] << 8 | image.rgba[i + 2] << 16 | uint32_t{image.rgba[i + 3]} << 24;
    lit += v != background;
  }
  return lit;
}

TEST_P(Render, onePointAndIdenticalPointsLightOnePixelInTheCentre) {
  for (size_t copies : {size_t{1}, size_t{500}}) {
    PointSet s;
    s.positions.assign(copies, glm::dvec3(6.378e6, 1.5, -2.25));
    CameraSpec spec;
    spec.width = 101;  // odd, so the view axis goes through a pixel centre
    spec.height = 75;
    Camera camera = *makeCamera(spec, boundsOf(s));  // the fit of a degenerate box
    for (PrecisionMode mode : kAllModes) {
      Measured m = measure(s, camera, mode);
      if (mode == PrecisionMode::kFp32 || mode == PrecisionMode::kSplit) {
        // The fit stands 6.4e-4 m away; float's 0.5 m spacing at 6.4e6 throws the point out.
        EXPECT_LE(litPixels(m.render.image, RenderOptions{}.background_rgba8), 1u) << modeName(mode);
        continue;
      }
      EXPECT_EQ(litPixels(m.render.image, RenderOptions{}.background_rgba8), 1u) << modeName(mode) << " x" << copies;
      EXPECT_EQ(m.render.image.rgba[4 * (37 * 101 + 50)], 255) << "the centre pixel is lit";
      EXPECT_EQ(m.error.pixels_differing, 0u) << modeName(mode) << " x" << copies;
    }
  }
}

TEST_P(Render, pointsBehindAtAndBesideTheEyeAreCulledWithoutNaN) {
  PointSet s;
  s.positions = {{0, 0, -5}, {0, 0, 5}, {0, 0, 10}, {0, 0, 0}, {3, 0, 0}};  // front, behind ×2, at the eye, beside
  CameraSpec spec;
  spec.width = 101;
  spec.height = 75;
  spec.eye = glm::dvec3(0, 0, 0);
  spec.target = glm::dvec3(0, 0, -1);
  spec.up = glm::dvec3(0, 1, 0);
  Camera camera = *makeCamera(spec, boundsOf(s));
  for (PrecisionMode mode : kAllModes) {
    Measured m = measure(s, camera, mode);
    for (const glm::vec4& clip : m.render.probe_clip)
      for (int c = 0; c < 4; ++c) EXPECT_TRUE(std::isfinite(clip[c])) << modeName(mode);
    EXPECT_EQ(litPixels(m.render.image, RenderOptions{}.background_rgba8), 1u) << modeName(mode);
    EXPECT_EQ(m.error.stats.points, 1u);
    EXPECT_EQ(m.error.pixels_differing, 0u) << modeName(mode);
  }
}

TEST_P(Render, aPointOnTheNearPlaneLeavesNoNaN) {
  PointSet s;
  s.positions = {{0, 0, -1}, {0, 0, -2}};
  CameraSpec spec;
  spec.eye = glm::dvec3(0, 0, 0);
  spec.target = glm::dvec3(0, 0, -1);
  spec.up = glm::dvec3(0, 1, 0);
  Camera camera = *makeCamera(spec, boundsOf(s));
  s.positions.push_back({0, 0, -camera.near_plane});  // exactly on the near plane
  for (PrecisionMode mode : kAllModes) {
    Measured m = measure(s, camera, mode);
    for (const glm::vec4& clip : m.render.probe_clip)
      for (int c = 0; c < 4; ++c) EXPECT_TRUE(std::isfinite(clip[c])) << modeName(mode);
  }
}

// Splitting into several draws (as large sets are) changes nothing: same picture, same probe.
TEST_P(Render, chunkedDrawsGiveTheSamePictureAndProbe) {
  const glm::dvec3 centre(1e6, 2e6, -3e6);
  PointSet s = cloud(centre, 1e-3);
  Camera camera = lookAtCloud(s, centre, 0.5);
  for (PrecisionMode mode : kAllModes) {
    Measured whole = measure(s, camera, mode);
    EXPECT_EQ(whole.render.chunks, 1u);
    // 300: 4 draws, batch mode's 4096-point batches cut across them; 301: draws starting at odd
    // points (batch mode, whose compute splat reads pairs, rounds it down to 300).
    for (uint64_t chunk : {300u, 301u}) {
      RenderOptions chunked;
      chunked.max_chunk_points = chunk;
      Measured parts = measure(s, camera, mode, chunked);
      // adaptive's chunks hold whole batches (its splat loads 16 bytes of 4 points): one here.
      const uint32_t chunks = modeInfo(mode).chunk_multiple > 301 ? 1u : 4u;
      EXPECT_EQ(parts.render.chunks, chunks) << modeName(mode) << " " << chunk;
      EXPECT_EQ(whole.render.image.rgba, parts.render.image.rgba) << modeName(mode) << " " << chunk;
      EXPECT_EQ(0, std::memcmp(whole.render.probe_clip.data(), parts.render.probe_clip.data(),
                               s.size() * sizeof(glm::vec4))) << modeName(mode) << " " << chunk;
    }
  }
}

// Both ways for native: vertex attributes where the device lists R64G64B64_SFLOAT (NVIDIA), a
// storage buffer otherwise (lavapipe). Each path that the device has must give the same picture.
TEST_P(Render, nativeVertexInputAndVertexPullingAgree) {
  if (GetParam() == Backend::kCompute) GTEST_SKIP() << "vertex input is the raster backend's";
  const glm::dvec3 centre(6.378e6, 0.0, 0.0);
  PointSet s = cloud(centre, 1e-3);
  Camera camera = lookAtCloud(s, centre, 1.0);
  RenderOptions pull;
  pull.native_path = NativePath::kPull;
  Measured pulled = measure(s, camera, PrecisionMode::kNative, pull);
  EXPECT_TRUE(pulled.render.pulled_positions);
  RenderOptions attribute;
  attribute.native_path = NativePath::kAttribute;
  attribute.mode = PrecisionMode::kNative;
  attribute.probe = true;
  Result<RenderResult> r = renderPoints(*context_, s, camera, attribute);
  if (!context_->facts.r64g64b64_vertex) {
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ExitCode::kNoDevice);
    EXPECT_NE(r.error().message.find("R64G64B64_SFLOAT"), std::string::npos) << r.error().message;
    return;
  }
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_FALSE(r->pulled_positions);
  EXPECT_EQ(r->image.rgba, pulled.render.image.rgba);
}

// fp32 and split hold absolute floats and refuse what float cannot hold; the scene-frame modes
// see the set scaled to the view, where it fits.
TEST_P(Render, absoluteFloatModesRefuseCoordinatesBeyondFloatRange) {
  PointSet s;
  s.positions = {{0, 0, 0}, {1e39, 0, 0}};
  Camera camera = *makeCamera(CameraSpec{}, boundsOf(s));
  for (PrecisionMode mode : kAllModes) {
    RenderOptions options;
    options.mode = mode;
    options.backend = GetParam();
    Result<RenderResult> r = renderPoints(*context_, s, camera, options);
    if (modeInfo(mode).scene_frame) {
      EXPECT_TRUE(r.ok()) << modeName(mode) << ": " << r.error().message;
      continue;
    }
    ASSERT_FALSE(r.ok()) << modeName(mode);
    EXPECT_EQ(r.error().code, ExitCode::kBadInput);
    EXPECT_NE(r.error().message.find("point 1: x = 1e+39 is beyond float32 range"), std::string::npos) << r.error().message;
  }
}

TEST_P(Render, pointSizeCoversASquareAndTheBackgroundFillsTheRest) {
  PointSet s;
  s.positions = {{0, 0, 0}, {1, 1, 0}, {2, 2, 0}};
  s.colors = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  CameraSpec spec;
  spec.width = spec.height = 65;
  spec.view_center = glm::dvec3(1, 1, 0);
  spec.view_width = 20.0;  // the points land 3.25 px apart on the diagonal, the middle one on a pixel centre
  Camera camera = *makeCamera(spec, boundsOf(s));
  RenderOptions options;
  options.backend = GetParam();
  options.point_size = 3.0f;
  options.background_rgba8 = 0xff332211u;
  Result<RenderResult> r = renderPoints(*context_, s, camera, options);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(litPixels(r->image, options.background_rgba8), 27u);
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) EXPECT_EQ(r->image.rgba[4 * ((32 + dy) * 65 + 32 + dx) + 1], 255);
  EXPECT_EQ(r->image.rgba[0], 0x11);
  EXPECT_EQ(r->image.rgba[1], 0x22);
  EXPECT_EQ(r->image.rgba[2], 0x33);
}

TEST_P(Render, timedFramesReportGpuTimestamps) {
  PointSet s = cloud(glm::dvec3(0.0), 1.0);
  Camera camera = *makeCamera(CameraSpec{}, boundsOf(s));
  RenderOptions options;
  options.backend = GetParam();
  options.frames = 5;
  Result<RenderResult> r = renderPoints(*context_, s, camera, options);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_GT(context_->facts.timestamp_period_ns, 0.0f) << "lavapipe has timestamps";
  ASSERT_EQ(r->gpu_ms.size(), 5u);
  ASSERT_EQ(r->frame_ms.size(), 5u);
  for (double ms : r->gpu_ms) EXPECT_GT(ms, 0.0);
  EXPECT_EQ(r->gpu_bytes, s.size() * 28u);
}

// The compute backend draws the raster picture at every point size: each pixel of a point's square
// is depth-tested at the point's depth, ties to the point drawn first. Pixel for pixel on a 2D grid with
// a point per pixel centre; on a 3D cloud whose points overlap at arbitrary sub-pixel positions, all
// but under 1% of the lit pixels.
TEST_P(Render, computeAgreesWithRasterAtPointSizes1To3) {
  if (GetParam() == Backend::kRaster) GTEST_SKIP() << "compares the compute backend against raster";
  const PointSet cube = cloud(glm::dvec3(0.0), 1.0);
  const Camera near = lookAtCloud(cube, glm::dvec3(0.0), 40.0);
  const DeepZoom zoom = deepZoom(1e-6, 64, 300);
  ASSERT_FALSE(zoom.grid.positions.empty());
  for (float size : {1.0f, 2.0f, 3.0f}) {
    for (const auto& [points, camera] : {std::pair{&cube, &near}, std::pair{&zoom.grid, &zoom.camera}}) {
      RenderOptions raster, compute;
      raster.mode = compute.mode = PrecisionMode::kDf64;
      raster.point_size = compute.point_size = size;
      compute.backend = Backend::kCompute;
      Result<RenderResult> a = renderPoints(*context_, *points, *camera, raster);
      Result<RenderResult> b = renderPoints(*context_, *points, *camera, compute);
      ASSERT_TRUE(a.ok() && b.ok());
      const size_t lit = litPixels(a->image, raster.background_rgba8), differing = countDifferingPixels(a->image, b->image);
      EXPECT_GT(lit, 0u);
      std::printf("%g px, %zu points: %zu of %zu lit pixels differ\n", double(size), points->size(), differing, lit);
      // The grid is exact. In the cloud a few points lie within lavapipe's sub-pixel snapping (1/256 px)
      // of a pixel edge or tie in depth to float rounding: the same at size 1 as before larger points.
      if (points == &zoom.grid) EXPECT_EQ(differing, 0u) << size << " px";
      else EXPECT_LE(differing, lit / 100) << size << " px";
    }
  }
}

// A large point whose centre lies just outside the picture still draws the part of its square
// inside, on both backends alike (the rasterizer's guard band): the compute backend clipped such a
// point by its centre, so points along the picture's edges were missing there and the backends
// differed (35,560 pixels of a close-up Mandelbulb at 1024x768, 29,638 of them at its edges).
TEST_P(Render, aLargePointJustOutsideThePictureDrawsItsPartInside) {
  PointSet set;
  set.positions = {{1.2, 0.0, 0.0}, {-1.0, -0.5, 0.0}, {0.0, 1.6, 0.0}};  // the last: its square is all outside
  set.colors = {glm::vec3(1.0f), glm::vec3(1.0f), glm::vec3(1.0f)};
  CameraSpec spec;
  spec.width = 400, spec.height = 300;
  spec.ortho = true;
  spec.view_center = glm::dvec3(0.0);
  spec.view_width = 2.0;
  Result<Camera> camera = makeCamera(spec, boundsOf(set));
  ASSERT_TRUE(camera.ok()) << camera.error().message;
  RenderOptions options;
  options.point_size = 100.0f;
  options.backend = GetParam();
  Result<RenderResult> r = renderPoints(*context_, set, *camera, options);
  ASSERT_TRUE(r.ok()) << r.error().message;
  const auto lit = [&](uint32_t x, uint32_t y) {
    const size_t at = (size_t{y} * r->image.width + x) * 4;
    return r->image.rgba[at] != 0 || r->image.rgba[at + 1] != 0 || r->image.rgba[at + 2] != 0;
  };
  // x = 1.2 is pixel 440 of 400: its square spans 390-489, so columns 390-399 of rows 100-199.
  EXPECT_TRUE(lit(399, 150) && lit(390, 150) && lit(395, 100) && lit(395, 199));
  EXPECT_FALSE(lit(389, 150) || lit(395, 99) || lit(395, 200));
  EXPECT_TRUE(lit(0, 50) || lit(0, 249)) << "the point on the left edge, half inside";
  EXPECT_EQ(litPixels(r->image, options.background_rgba8), size_t{10 * 100 + 50 * 100}) << "nothing of the third";
}

// Round points (RenderOptions::round_points) are the same discs on both backends, at one depth
// per pixel that falls towards the rim: all but under 1% of the lit pixels agree (a pixel centre on
// a disc's rim, lavapipe's sub-pixel snapping); and a disc is not its square: its corners are left
// out, so a lone 9-px point lights 69 of its 81 pixels, and of two discs at one depth the nearer
// centre wins the pixels between them (with squares, the point drawn first would take them all).
TEST_P(Render, roundPointsAreTheSameDiscsOnBothBackends) {
  if (GetParam() == Backend::kRaster) GTEST_SKIP() << "compares the compute backend against raster";
  const PointSet cube = cloud(glm::dvec3(0.0), 1.0);
  CameraSpec from_above;
  from_above.width = from_above.height = 200;
  from_above.ortho = true;
  Result<Camera> ortho = makeCamera(from_above, boundsOf(cube));
  ASSERT_TRUE(ortho.ok()) << ortho.error().message;
  for (const Camera& camera : {lookAtCloud(cube, glm::dvec3(0.0), 40.0), *ortho}) {
    for (float size : {5.0f, 9.0f}) {
      RenderOptions raster, compute;
      raster.point_size = compute.point_size = size;
      raster.round_points = compute.round_points = true;
      compute.backend = Backend::kCompute;
      Result<RenderResult> a = renderPoints(*context_, cube, camera, raster);
      Result<RenderResult> b = renderPoints(*context_, cube, camera, compute);
      ASSERT_TRUE(a.ok() && b.ok());
      const size_t lit = litPixels(a->image, raster.background_rgba8), differing = countDifferingPixels(a->image, b->image);
      std::printf("round %g px, %s: %zu of %zu lit pixels differ\n", double(size), camera.ortho ? "ortho" : "perspective",
                  differing, lit);
      EXPECT_GT(lit, 0u);
      EXPECT_LE(differing, lit / 100) << size << " px";
    }
  }
  // A lone point at a pixel's centre (the middle of a 63-px picture): 69 pixel centres lie within
  // 4.5 px of it.
  PointSet lone;
  lone.positions = {glm::dvec3(0.0, 0.0, 0.0), glm::dvec3(0.0, 0.0, 0.5)};
  lone.colors = {glm::vec3(1.0f), glm::vec3(1.0f)};
  const Camera camera = topDownCamera(lone, 1.0, 63);
  for (Backend backend : {Backend::kRaster, Backend::kCompute}) {
    RenderOptions options;
    options.point_size = 9.0f;
    options.round_points = true;
    options.backend = backend;
    Result<RenderResult> r = renderPoints(*context_, lone, camera, options);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(litPixels(r->image, options.background_rgba8), 69u) << (backend == Backend::kCompute ? "compute" : "raster");
  }
}

// A set streamed block by block (dpoint render of a file larger than memory) draws the picture
// the set in memory draws, in every mode, with blocks that split it unevenly; a failing read ends
// the render with the stream's error, and a bad point is named by its index in the whole set.
TEST_P(Render, streamDrawsTheSamePictureAsTheSetInMemory) {
  PointSet s = cloud(glm::dvec3(6378137.0, 0.0, 0.0), 0.01);
  for (int copy = 0; copy < 12; ++copy)  // 12 000 points: three blocks of 4096 and a partial one
    for (size_t i = 0; i < 1000; ++i) {
      s.positions.push_back(s.positions[i] + glm::dvec3(0.001 * (copy + 1), 0.0, 0.0));
      s.colors.push_back(s.colors[i]);
    }
  const Camera camera = lookAtCloud(s, glm::dvec3(6378137.0, 0.0, 0.0), 1.0);
  PointStream stream;
  stream.count = s.size();
  stream.has_colors = true;
  size_t reads = 0;
  stream.read = [&](size_t first, size_t n, PointSet& block) -> Status {
    ++reads;
    block.positions.assign(s.positions.begin() + static_cast<std::ptrdiff_t>(first),
                           s.positions.begin() + static_cast<std::ptrdiff_t>(first + n));
    block.colors.assign(s.colors.begin() + static_cast<std::ptrdiff_t>(first),
                        s.colors.begin() + static_cast<std::ptrdiff_t>(first + n));
    return okStatus();
  };
  for (PrecisionMode mode : kAllModes) {
    SCOPED_TRACE(std::string(modeName(mode)));
    RenderOptions options;
    options.mode = mode;
    options.backend = GetParam();
    options.max_chunk_points = 5000;  // batch mode rounds it down to 4096
    Result<RenderResult> whole = renderPoints(*context_, s, camera, options);
    ASSERT_TRUE(whole.ok()) << whole.error().message;
    reads = 0;
    Result<RenderResult> streamed = renderStream(*context_, stream, camera, options);
    ASSERT_TRUE(streamed.ok()) << streamed.error().message;
    EXPECT_EQ(reads, streamed->chunks);
    EXPECT_GE(streamed->chunks, 3u);
    EXPECT_TRUE(streamed->image.rgba == whole->image.rgba);
  }
  RenderOptions options;
  options.backend = GetParam();
  options.max_chunk_points = 5000;
  PointStream failing = stream;
  failing.read = [&](size_t first, size_t n, PointSet& block) -> Status {
    if (first > 0) return Error{"cloud.ply: byte 1234: truncated"};
    return stream.read(first, n, block);
  };
  Result<RenderResult> failed = renderStream(*context_, failing, camera, options);
  ASSERT_FALSE(failed.ok());
  EXPECT_EQ(failed.error().message, "cloud.ply: byte 1234: truncated");
  s.positions[9000].y = 1e39;  // beyond float: fp32 names it
  options.mode = PrecisionMode::kFp32;
  failed = renderStream(*context_, stream, camera, options);
  ASSERT_FALSE(failed.ok());
  EXPECT_NE(failed.error().message.find("point 9000: y"), std::string::npos) << failed.error().message;
}

INSTANTIATE_TEST_SUITE_P(Backends, Render, ::testing::Values(Backend::kRaster, Backend::kCompute), backendName);

}  // namespace
}  // namespace dpoint
