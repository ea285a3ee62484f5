// Precision (issue #9) on real Vulkan, both backends, validation layer on: points at pixel centres
// whose true pixel is worked out exactly here (not by the renderer's reference), every mode's
// predicted bound against its measured probe error on the DESIGN §7 hard cases, and --mode auto.
//
// Each case prints one line per mode ("precision: …") with the bound, the measured error and the
// points off their pixel: run the binary with --gtest_filter='*Precision*' to read the table.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <set>

#include "generators/mandelbulb.h"
#include "render_test_support.h"
#include "viewer/precision.h"
#include "viewer/selftest.h"

namespace dpoint {
namespace {

class Precision : public VulkanRenderTest {
 protected:
  struct Row {
    double bound = 0.0;
    ErrorStats stats;
    size_t pixels_differing = 0;
    size_t near_edge = 0;  // points the reference sees within `bound` px of the picture's edge
  };
  // Renders in `mode` with the probe, and prints and returns bound and measurement.
  Row run(const char* label, const PointSet& points, const Camera& camera, PrecisionMode mode,
          const ErrorBounds& bounds, Image* image = nullptr) {
    Measured m = measure(points, camera, mode);
    Row row{bounds.px[modeIndex(mode)], m.error.stats, m.error.pixels_differing, 0};
    for (const WindowPoint& w : projectReference(points.positions, camera))
      row.near_edge += w.visible && (w.x <= row.bound || w.y <= row.bound || w.x > camera.width - row.bound ||
                                     w.y > camera.height - row.bound);
    std::printf("precision: %-34s %-7s %-6s bound %-12s measured max %-10.3g lost %zu/%zu, off >= 0.5 px %.4g%%\n",
                label, GetParam() == Backend::kRaster ? "raster" : "compute", std::string(modeName(mode)).c_str(),
                formatBound(row.bound).c_str(), row.stats.max_px, row.stats.lost, row.stats.points,
                100.0 * row.stats.share_off_half_px);
    if (image) *image = std::move(m.render.image);
    return row;
  }
  // The bound holds: no measured error above it, and under half a pixel no point lost or moved,
  // but one the reference puts within the bound of the picture's edge, which an error within the
  // bound may take out of the view (the 1e-15 deep zoom's grid collapses onto a few doubles, some
  // exactly on the edge: adaptive's 0.03 px takes them out, native's 1e-6 px happens not to).
  void expectWithinBound(const char* label, PrecisionMode mode, const Row& row) {
    if (!std::isfinite(row.bound)) return;
    EXPECT_LE(row.stats.max_px, row.bound) << label << " " << modeName(mode);
    if (row.bound < 0.5) {
      EXPECT_LE(row.stats.lost, row.near_edge) << label << " " << modeName(mode);
      EXPECT_LE(row.stats.share_off_half_px * static_cast<double>(row.stats.points), static_cast<double>(row.near_edge))
          << label << " " << modeName(mode);
    }
  }
  void everyModeWithinItsBound(const char* label, const PointSet& points, const Camera& camera) {
    const ErrorBounds bounds = predictErrorBounds(points, camera);
    ASSERT_GT(bounds.visible, 0u) << label;
    for (PrecisionMode mode : kAllModes) expectWithinBound(label, mode, run(label, points, camera, mode, bounds));
  }
};

// --- Points at pixel centres of a 512² orthographic view, their pixel computed exactly --------

constexpr uint32_t kSide = 512;
constexpr size_t kCentredPoints = 4000;

struct CentredView {
  const char* label;
  glm::dvec2 centre;
  double width;
};

// The view of the table: 4,000 distinct pixels (fixed seed), a point at each centre as
// double rounds it, and a colour that names the point (RGB = index + 1).
PointSet centredPoints(const CentredView& view) {
  std::mt19937_64 random(20261123);
  std::set<uint32_t> taken;
  PointSet s;
  while (s.size() < kCentredPoints) {
    const uint32_t pixel = static_cast<uint32_t>(random() % (kSide * kSide));
    if (!taken.insert(pixel).second) continue;
    const double i = pixel % kSide, j = pixel / kSide;
    // y grows downwards in the window: row j is below the centre when j > kSide / 2.
    s.positions.emplace_back(view.centre.x + ((i + 0.5) / kSide - 0.5) * view.width,
                             view.centre.y - ((j + 0.5) / kSide - 0.5) * view.width, 0.0);
    const uint32_t id = static_cast<uint32_t>(s.size());
    s.colors.emplace_back(float(id & 0xffu) / 255.0f, float((id >> 8) & 0xffu) / 255.0f, float(id >> 16) / 255.0f);
  }
  return s;
}

// The pixel (column, row) whose half-open square (i, i+1] × (j, j+1] holds the exact window
// position of p. x_win = ((p.x − c.x)/w + 1/2)·512, so column i holds p when
// (2i − 512)·w/1024 < p.x − c.x ≤ (2i + 2 − 512)·w/1024. p.x − c.x is exact (Sterbenz: they are
// within a factor of 2, checked) and so is each side in long double: a 10-bit integer times the
// 53-bit w fits the 64-bit significand, and 1024 is a power of two. Rows likewise, with y flipped.
glm::ivec2 exactPixel(const glm::dvec3& p, const CentredView& view) {
  auto within_factor_two = [](double a, double b) { return a == b || (a / b >= 0.5 && a / b <= 2.0); };
  EXPECT_TRUE(within_factor_two(p.x, view.centre.x) && within_factor_two(p.y, view.centre.y));
  const long double dx = static_cast<long double>(p.x - view.centre.x);
  const long double dy = static_cast<long double>(p.y - view.centre.y);
  const long double w = view.width;
  auto edge = [&](int k) { return static_cast<long double>(2 * k - int(kSide)) * w / (2.0L * kSide); };
  int i = static_cast<int>(std::floor(static_cast<double>(dx / w + 0.5L) * kSide));
  while (!(edge(i) < dx)) --i;
  while (!(dx <= edge(i + 1))) ++i;
  // Row j holds p when −(2j + 2 − 512)·w/1024 ≤ p.y − c.y < −(2j − 512)·w/1024.
  int j = static_cast<int>(std::floor(static_cast<double>(0.5L - dy / w) * kSide));
  while (!(-edge(j + 1) <= dy)) --j;
  while (!(dy < -edge(j))) ++j;
  return {i, j};
}

size_t pointsOnTheirPixel(const PointSet& s, const CentredView& view, const Image& image) {
  size_t on = 0;
  for (size_t n = 0; n < s.size(); ++n) {
    const glm::ivec2 px = exactPixel(s.positions[n], view);
    if (px.x < 0 || px.y < 0 || px.x >= int(kSide) || px.y >= int(kSide)) continue;
    const uint8_t* rgba = &image.rgba[4 * (size_t(px.y) * kSide + size_t(px.x))];
    const uint32_t id = rgba[0] | uint32_t{rgba[1]} << 8 | uint32_t{rgba[2]} << 16;
    on += id == n + 1;
  }
  return on;
}

Camera centredCamera(const CentredView& view, const PointSet& s) {
  CameraSpec spec;
  spec.width = spec.height = kSide;
  spec.view_center = glm::dvec3(view.centre, 0.0);
  spec.view_width = view.width;
  Result<Camera> camera = makeCamera(spec, boundsOf(s));
  EXPECT_TRUE(camera.ok()) << camera.error().message;
  EXPECT_TRUE(camera->ortho);
  return *camera;
}

const CentredView kCentredViews[] = {
    {"earth (6378137.12, -2345678.99) 1e-4", {6378137.123456789, -2345678.987654321}, 1e-4},
    {"deep zoom (-0.743645, 0.1318259) 1e-13", {-0.743645, 0.1318259}, 1e-13},
    {"tiny (1e-30, 2e-30) 1e-40", {1e-30, 2e-30}, 1e-40},
};

// Every mode whose bound is under half a pixel puts all 4,000 points on their exact pixel; fp32
// fails where its bound says it will; no measured error exceeds its bound.
TEST_P(Precision, pointsAtPixelCentresLandOnTheirPixelWhereverTheBoundAllows) {
  for (const CentredView& view : kCentredViews) {
    const PointSet s = centredPoints(view);
    const Camera camera = centredCamera(view, s);
    const ErrorBounds bounds = predictErrorBounds(s, camera);
    EXPECT_EQ(bounds.visible, kCentredPoints) << view.label;
    for (PrecisionMode mode : kAllModes) {
      Image image;
      const Row row = run(view.label, s, camera, mode, bounds, &image);
      const size_t on = pointsOnTheirPixel(s, view, image);
      std::printf("precision: %-34s %-7s %-6s %zu of %zu on their pixel\n", view.label,
                  GetParam() == Backend::kRaster ? "raster" : "compute", std::string(modeName(mode)).c_str(), on,
                  kCentredPoints);
      expectWithinBound(view.label, mode, row);
      if (row.bound < 0.5) {
        EXPECT_EQ(on, kCentredPoints) << view.label << " " << modeName(mode);
      }
      if (mode == PrecisionMode::kFp32) {
        EXPECT_GE(row.bound, 0.5) << view.label;
        EXPECT_LT(on, kCentredPoints) << view.label;
      }
    }
    // What the issue asks of the bounds themselves: native at the float floor in all three
    // views, batch and rte under half a pixel in all but the 1e-13 zoom (48 bits of 0.74 are
    // 13 pixels there), where native and batch still are.
    const double floor = bounds.float_floor_px;
    EXPECT_LE(bounds.px[modeIndex(PrecisionMode::kNative)], 2.0 * floor) << view.label;
    EXPECT_LT(bounds.px[modeIndex(PrecisionMode::kBatch)], 0.5) << view.label;
  }
}

TEST_P(Precision, autoPicksAModeThatPutsEveryPointOnItsPixel) {
  for (const CentredView& view : kCentredViews) {
    const PointSet s = centredPoints(view);
    const Camera camera = centredCamera(view, s);
    Result<ModeChoice> choice = chooseModeOnDevice(*context_, s, camera, GetParam(), true);
    ASSERT_TRUE(choice.ok()) << choice.error().message;
    EXPECT_TRUE(choice->enough) << view.label;
    EXPECT_LE(choice->bound_px, kAutoBoundPx) << view.label;
    const PrecisionMode fp32 = PrecisionMode::kFp32;
    EXPECT_NE(choice->mode, fp32) << view.label;
    Image image;
    run(view.label, s, camera, choice->mode, choice->bounds, &image);
    EXPECT_EQ(pointsOnTheirPixel(s, view, image), kCentredPoints) << view.label << " auto → " << modeName(choice->mode);
  }
}

// --- DESIGN §7: every mode's measured error within its bound -----------------------------------

TEST_P(Precision, offsetCasesStayWithinTheirBounds) {
  for (const glm::dvec3& centre : {glm::dvec3(1e6, 0, 0), glm::dvec3(6.378e6, 0, 0), glm::dvec3(1e8, -2e7, 5e7)}) {
    const PointSet s = cloud(centre, 1e-3);
    const std::string label = "offset " + std::to_string(centre.x);
    everyModeWithinItsBound(label.c_str(), s, lookAtCloud(s, centre, 1.0));
  }
}

// The offset scene (points and camera) scaled by 1e-40 (float subnormals) and 1e-300: every
// scene-frame mode errs as it does at 1 m, since it sees the same numbers up to a power of two.
TEST_P(Precision, tinyScenesErrAsTheyDoAtOneMetre) {
  const glm::dvec3 centre(6.378e6, 0, 0);
  const PointSet metre = cloud(centre, 1e-3);
  const Camera metre_camera = lookAtCloud(metre, centre, 1.0);
  const ErrorBounds metre_bounds = predictErrorBounds(metre, metre_camera);
  std::array<double, kModeCount> metre_max{};
  for (PrecisionMode mode : kAllModes) {
    if (modeInfo(mode).scene_frame)
      metre_max[modeIndex(mode)] = run("tiny x1", metre, metre_camera, mode, metre_bounds).stats.max_px;
  }
  for (double scale : {1e-40, 1e-300}) {
    PointSet s = metre;
    for (glm::dvec3& p : s.positions) p *= scale;
    const glm::dvec3 c = centre * scale;
    const Camera camera = lookAtCloud(s, c, scale);
    const ErrorBounds bounds = predictErrorBounds(s, camera);
    const std::string label = "tiny x" + std::string(scale == 1e-40 ? "1e-40" : "1e-300");
    for (PrecisionMode mode : kAllModes) {
      const Row row = run(label.c_str(), s, camera, mode, bounds);
      expectWithinBound(label.c_str(), mode, row);
      if (!modeInfo(mode).scene_frame) continue;
      const size_t m = modeIndex(mode);
      EXPECT_LE(bounds.px[m], 2.0 * metre_bounds.px[m]) << label << " " << modeName(mode);
      EXPECT_EQ(row.stats.lost, 0u) << label << " " << modeName(mode);
      EXPECT_LE(row.stats.max_px, 4.0 * metre_max[m] + 4.0 * bounds.float_floor_px) << label << " " << modeName(mode);
    }
  }
}

// The deep-zoom sweep 1e-1 … 1e-15 around the study's centre, one point per pixel centre.
TEST_P(Precision, deepZoomSweepStaysWithinTheBounds) {
  for (double width : {1e-1, 1e-4, 1e-6, 1e-9, 1e-12, 1e-13, 1e-14, 1e-15}) {
    const DeepZoom zoom = deepZoom(width, 48, 300);
    ASSERT_FALSE(zoom.grid.positions.empty());
    const PointSet* grid = &zoom.grid;
    const Camera* camera = &zoom.camera;
    char label[48];
    std::snprintf(label, sizeof label, "deepzoom %g", width);
    everyModeWithinItsBound(label, *grid, *camera);
    // Double still holds the grid distinctly down to 1e-14 here (a pixel of 48 is ≥ 18 ulps of
    // 0.74): native stays at the float floor.
    if (width >= 1e-14) {
      const ErrorBounds bounds = predictErrorBounds(*grid, *camera, std::array{PrecisionMode::kNative});
      EXPECT_LE(bounds.px[modeIndex(PrecisionMode::kNative)], 2.0 * bounds.float_floor_px) << label;
    }
  }
}

// The origin of a fractal (odd resolution: the grid samples it) framed by --fit, perspective.
TEST_P(Precision, mandelbulbThroughTheOriginStaysWithinTheBounds) {
  MandelbulbParams params;
  params.resolution = 33;
  params.max_iter = 20;
  params.variant = MandelbulbVariant::kFast;
  Result<PointSet> bulb = generateMandelbulb(params);
  ASSERT_TRUE(bulb.ok()) << bulb.error().message;
  CameraSpec spec;
  spec.width = 640;
  spec.height = 480;
  Result<Camera> camera = makeCamera(spec, boundsOf(*bulb));
  ASSERT_TRUE(camera.ok());
  everyModeWithinItsBound("origin mandelbulb 33", *bulb, *camera);
}

TEST_P(Precision, degenerateSetsStayWithinTheBounds) {
  PointSet one;
  one.positions = {{6.378e6, 1.5, -2.25}};
  PointSet same;
  same.positions.assign(300, glm::dvec3(-1e-30, 4e-31, 0.0));
  for (const PointSet* s : {&one, &same}) {
    CameraSpec spec;
    spec.width = 101;
    spec.height = 75;
    Result<Camera> camera = makeCamera(spec, boundsOf(*s));
    ASSERT_TRUE(camera.ok());
    everyModeWithinItsBound(s == &one ? "one point" : "identical points", *s, *camera);
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, Precision, ::testing::Values(Backend::kRaster, Backend::kCompute), backendName);

// --- The pass itself: modes bounded together, two points at a time -----------------------------

// Bounds computed together in one pass (fp32, split and native two points at a time, an odd point
// alone) are each mode's bound from a pass of its own, to the bit: an odd count of points, far
// from the origin, at 1e-300 (subnormal floats) and under an ortho camera (a constant w row).
TEST(PrecisionPass, modesBoundedTogetherGetTheirOwnPassesBoundsToTheBit) {
  const glm::dvec3 centre(6.378e6, 0.5, -3.0);
  PointSet odd = cloud(centre, 1e-3);
  odd.positions.pop_back();
  odd.colors.pop_back();
  PointSet tiny = odd;
  for (glm::dvec3& p : tiny.positions) p *= 1e-300;
  CameraSpec ortho_spec;
  ortho_spec.ortho = true;
  const Result<Camera> ortho = makeCamera(ortho_spec, boundsOf(odd));
  ASSERT_TRUE(ortho.ok()) << ortho.error().message;
  const std::pair<const PointSet*, Camera> cases[] = {
      {&odd, lookAtCloud(odd, centre, 1.0)}, {&tiny, lookAtCloud(tiny, centre * 1e-300, 1e-300)}, {&odd, *ortho}};
  for (const auto& [points, camera] : cases) {
    const ErrorBounds together = predictErrorBounds(*points, camera);
    EXPECT_EQ(together.visible, points->size());
    for (PrecisionMode mode : kAllModes) {
      const ErrorBounds alone = predictErrorBounds(*points, camera, std::array{mode});
      const size_t m = modeIndex(mode);
      EXPECT_EQ(std::bit_cast<uint64_t>(together.px[m]), std::bit_cast<uint64_t>(alone.px[m])) << modeName(mode);
      EXPECT_EQ(together.visible, alone.visible) << modeName(mode);
    }
  }
}

// A coordinate beyond float range, checked in the pass for the modes without batch frames: the
// float modes (fp32, split; rte and df64, whose scene frame is the world's at this size) are
// unbounded, native is not.
TEST(PrecisionPass, aPointBeyondFloatRangeLeavesTheFloatModesUnbounded) {
  PointSet s = cloud(glm::dvec3(0.0), 1e-3);
  const Camera camera = lookAtCloud(s, glm::dvec3(0.0), 1.0);
  s.positions.emplace_back(1e39, 0.0, 0.0);  // past the far plane
  s.colors.emplace_back(1.0f, 1.0f, 1.0f);
  const ErrorBounds bounds = predictErrorBounds(s, camera);
  EXPECT_EQ(bounds.visible, s.size() - 1);
  for (PrecisionMode mode : {PrecisionMode::kFp32, PrecisionMode::kSplit, PrecisionMode::kRte, PrecisionMode::kDf64})
    EXPECT_TRUE(std::isinf(bounds.px[modeIndex(mode)])) << modeName(mode);
  EXPECT_LE(bounds.px[modeIndex(PrecisionMode::kNative)], 2.0 * bounds.float_floor_px);
}

// --mode auto bounds only what its walk looks at: fp32 and its runner-up where fp32 is within the
// limit; where fp32 is not, native and the mode after it as well, never the modes past those.
TEST(PrecisionPass, chooseModeBoundsOnlyTheModesItLooksAt) {
  const auto all = [](PrecisionMode) { return true; };
  const std::span<const PrecisionMode> order = measuredSpeedOrder(DeviceClass::kCpu, true);
  ASSERT_GE(order.size(), 4u);
  const glm::dvec3 near(1.0, 2.0, 3.0), far(6.378e6, 0.5, -3.0);
  for (const glm::dvec3& centre : {near, far}) {
    const PointSet s = cloud(centre, 1e-3);
    const ModeChoice choice = chooseMode(s, lookAtCloud(s, centre, 1.0), order, all);
    const bool fp32_enough = choice.mode == order[0];
    const size_t looked_at = fp32_enough ? 2 : 3;
    EXPECT_EQ(fp32_enough, centre == near);
    for (size_t k = 0; k < order.size(); ++k)
      EXPECT_EQ(choice.bounds.computed[modeIndex(order[k])], k < looked_at) << modeName(order[k]);
    EXPECT_EQ(choice.runner_up, order[looked_at - 1]);
  }
}

// With the set's box to ask, a mode the box shows within the limit is the choice or the runner-up
// without a pass over the points (its bound the box's, no less than the points', and its encoding
// the box's); the mode drawn is the same, and every mode passed over keeps its points' bound to
// the bit.
TEST(PrecisionPass, aModeWithinTheLimitOverTheBoxTakesNoPass) {
  const auto all = [](PrecisionMode) { return true; };
  const PrecisionMode order[] = {PrecisionMode::kFp32, PrecisionMode::kNative, PrecisionMode::kDf64};
  const glm::dvec3 near(1.0, 2.0, 3.0), far(6.378e6, 0.5, -3.0);
  for (const glm::dvec3& centre : {near, far}) {
    const PointSet s = cloud(centre, 1e-3);
    const Camera camera = lookAtCloud(s, centre, 1.0);
    std::vector<std::vector<PrecisionMode>> passes;
    const BoundsOf points = [&](std::span<const PrecisionMode> modes) {
      passes.emplace_back(modes.begin(), modes.end());
      return predictErrorBounds(s, camera, modes);
    };
    const BoundsOf box = [&](std::span<const PrecisionMode> modes) {
      return predictBoxBounds(BatchBoxes{s.size(), {boundingBox(s.positions)}}, camera, modes);
    };
    const ModeChoice plain = chooseMode(order, all, points);
    passes.clear();
    const ModeChoice boxed = chooseMode(order, all, points, box);
    SCOPED_TRACE(centre == near ? "near" : "far");
    EXPECT_EQ(boxed.mode, plain.mode);
    EXPECT_TRUE(boxed.from_box);
    EXPECT_FALSE(plain.from_box);
    EXPECT_GE(boxed.bound_px, plain.bound_px);
    EXPECT_LE(boxed.bound_px, kAutoBoundPx);
    // The encoding the render draws with: the one a pass over the points makes (the frame alone).
    ASSERT_TRUE(boxed.encoding() && plain.encoding());
    EXPECT_EQ(boxed.encoding()->mode, plain.encoding()->mode);
    EXPECT_EQ(boxed.encoding()->frame.eye, plain.encoding()->frame.eye);
    EXPECT_EQ(boxed.encoding()->frame.exponent, plain.encoding()->frame.exponent);
    ASSERT_TRUE(boxed.runner_up && plain.runner_up);
    EXPECT_EQ(*boxed.runner_up, *plain.runner_up);
    EXPECT_GE(boxed.runner_up_bound_px, plain.runner_up_bound_px);
    EXPECT_LE(boxed.runner_up_bound_px, kAutoBoundPx);
    EXPECT_TRUE(boxed.runner_up_from_box);
    EXPECT_FALSE(plain.runner_up_from_box);
    // Near the origin fp32 and native are within the limit over the box: no pass at all. Far from
    // it fp32 is not (its points' bound is needed to pass it over), native and df64 are: one pass,
    // of fp32 alone.
    if (centre == near) {
      EXPECT_TRUE(passes.empty());
      EXPECT_EQ(boxed.mode, PrecisionMode::kFp32);
    } else {
      ASSERT_EQ(passes.size(), 1u);
      EXPECT_EQ(passes[0], std::vector{PrecisionMode::kFp32});
      EXPECT_EQ(boxed.mode, PrecisionMode::kNative);
    }
    ASSERT_EQ(boxed.rejected.size(), plain.rejected.size());
    for (size_t k = 0; k < plain.rejected.size(); ++k)
      EXPECT_EQ(std::bit_cast<uint64_t>(boxed.rejected[k].bound_px), std::bit_cast<uint64_t>(plain.rejected[k].bound_px));
  }
  // A box that shows no mode within the limit leaves the walk as it was.
  const PointSet s = cloud(near, 1e-3);
  const Camera camera = lookAtCloud(s, near, 1.0);
  const BoundsOf points = [&](std::span<const PrecisionMode> modes) { return predictErrorBounds(s, camera, modes); };
  const BoundsOf wide = [&](std::span<const PrecisionMode> modes) {
    ErrorBounds b;
    for (PrecisionMode mode : modes) b.px[modeIndex(mode)] = 1.0, b.computed[modeIndex(mode)] = true;
    return b;
  };
  const ModeChoice plain = chooseMode(order, all, points), boxed = chooseMode(order, all, points, wide);
  EXPECT_FALSE(boxed.from_box);
  EXPECT_EQ(std::bit_cast<uint64_t>(boxed.bound_px), std::bit_cast<uint64_t>(plain.bound_px));
  EXPECT_FALSE(boxed.runner_up_from_box);
  EXPECT_EQ(boxed.runner_up, plain.runner_up);
  EXPECT_EQ(std::bit_cast<uint64_t>(boxed.runner_up_bound_px), std::bit_cast<uint64_t>(plain.runner_up_bound_px));
  EXPECT_EQ(boxed.bounds.computed, plain.bounds.computed);
}

}  // namespace
}  // namespace dpoint
