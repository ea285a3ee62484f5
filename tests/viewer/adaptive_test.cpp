// Adaptive mode (issue #25): its 30-bit tiers, the per-batch plan (tier choice and culling) at its
// edges, and on real Vulkan (validation layer on) that a batch straddling the view's edge is drawn
// while a culled batch's points are never read. The pixel-centre and DESIGN §7 cases run every
// mode, adaptive included, in precision_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "ortho_camera.h"
#include "render_test_support.h"
#include "viewer/batch_plan.h"
#include "viewer/precision.h"

namespace dpoint {
namespace {

TEST(AdaptiveTiers, quantizeToThirtyBitsAndRebuildTheCellCentre) {
  EXPECT_EQ(quantizeAdaptive(-1.0), 0u);
  EXPECT_EQ(quantizeAdaptive(0.0), 1u << 29);
  EXPECT_EQ(quantizeAdaptive(0.5), 3u << 28);
  EXPECT_EQ(quantizeAdaptive(1.0), (1u << 30) - 1) << "t = 1 is the one value clamped";
  EXPECT_EQ(quantizeAdaptive(0x1p-30), 1u << 29) << "half a step rounds to even";
  EXPECT_EQ(quantizeAdaptive(3 * 0x1p-30), (1u << 29) + 2);
  const glm::uvec3 q(0x2ABCDEF1u & 0x3FFFFFFFu, 0x15555555u, 0x3FFFFFFFu);
  for (uint32_t tier = 0; tier < 3; ++tier) {
    const uint32_t shift = 20 - 10 * tier;
    const uint32_t word = adaptiveTierWord(q, tier);
    EXPECT_EQ(word & 1023u, (q.x >> shift) & 1023u) << tier;
    EXPECT_EQ((word >> 10) & 1023u, (q.y >> shift) & 1023u) << tier;
    EXPECT_EQ(word >> 20, (q.z >> shift) & 1023u) << tier;
  }
  std::mt19937 random(25);
  for (int n = 0; n < 10000; ++n) {
    const uint32_t v = random() & 0x3FFFFFFFu;
    EXPECT_EQ(adaptiveRebuilt(v, 3), static_cast<int32_t>(v) - (1 << 29));
    for (uint32_t tiers = 1; tiers <= 2; ++tiers) {
      const int32_t rebuilt = adaptiveRebuilt(v, tiers);
      const uint32_t dropped = 10 * (3 - tiers);
      EXPECT_EQ(static_cast<uint32_t>(rebuilt + (1 << 29)) >> dropped, v >> dropped) << "in the cell the bits name";
      // Within half a cell of q: the step error's term for the bits not loaded.
      EXPECT_LE(std::abs(rebuilt - (static_cast<int32_t>(v) - (1 << 29))), 1 << (dropped - 1));
      EXPECT_LE(std::ldexp(1.0, static_cast<int>(dropped) - 1) + 1.0, adaptiveStepError(tiers));
      // One or two tiers rebuild at most 21 significant bits: the float conversion is exact.
      EXPECT_EQ(static_cast<double>(static_cast<float>(rebuilt)), static_cast<double>(rebuilt));
    }
  }
}

// 1024 points (one batch) on a square `side` wide around `centre`, z = 0, and an orthographic view
// `view` wide of it, 512².
struct Square {
  PointSet points;
  Camera camera;
};
Square square(const glm::dvec2& centre, double side, double view) {
  Square s;
  std::mt19937_64 random(2511);
  std::uniform_real_distribution<double> unit(-0.5, 0.5);
  for (int i = 0; i < 1024; ++i) s.points.positions.emplace_back(centre.x + side * unit(random), centre.y + side * unit(random), 0.0);
  s.camera = orthoCamera(s.points, glm::dvec3(centre, 0.0), view, 512);
  return s;
}

uint8_t planWith(const Square& s, double tolerance) {
  Result<ModeEncoding> e = prepareEncoding(PrecisionMode::kAdaptive, s.points, s.camera, tolerance);
  EXPECT_TRUE(e.ok()) << e.error().message;
  return e.ok() ? e->batch_plan.at(0) : uint8_t{255};
}

// A batch exactly at a tier's limit takes that tier; a hair under it, one more. And the bound the
// mode reports for the view (per point, with the tiers chosen) is within the box bound of the tier
// chosen, so within the tolerance wherever fewer than three tiers were enough.
TEST(AdaptivePlan, tierChoiceIsExactAtItsEdges) {
  for (const glm::dvec2& centre : {glm::dvec2(0.25, -0.5), glm::dvec2(6378137.0, -2345678.5)}) {
    const Square s = square(centre, 0.02, 0.25);  // the batch is about 40 px wide
    Result<ModeEncoding> e = prepareEncoding(PrecisionMode::kAdaptive, s.points, s.camera);
    ASSERT_TRUE(e.ok()) << e.error().message;
    ASSERT_EQ(e->batches.size(), 1u);
    const double one = adaptiveBoxBoundPx(*e, 0, 1), two = adaptiveBoxBoundPx(*e, 0, 2), three = adaptiveBoxBoundPx(*e, 0, 3);
    std::printf("adaptive box bounds at %g: %.3g, %.3g, %.3g px\n", centre.x, one, two, three);
    ASSERT_GT(one, two);
    ASSERT_GT(two, three);
    EXPECT_EQ(planWith(s, one), 1);
    EXPECT_EQ(planWith(s, std::nextafter(one, 0.0)), 2);
    EXPECT_EQ(planWith(s, two), 2);
    EXPECT_EQ(planWith(s, std::nextafter(two, 0.0)), 3);
    EXPECT_EQ(planWith(s, three / 2), 3) << "no tier is enough: all three";
    for (double tolerance : {one, two, std::nextafter(two, 0.0)}) {
      const PrecisionMode adaptive[] = {PrecisionMode::kAdaptive};
      const uint8_t tiers = planWith(s, tolerance);
      const double bound = predictErrorBounds(s.points, s.camera, adaptive, tolerance).px[modeIndex(PrecisionMode::kAdaptive)];
      EXPECT_LE(bound, adaptiveBoxBoundPx(*e, 0, tiers)) << tolerance;
      if (tiers < 3) {
        EXPECT_LE(bound, tolerance);
      }
    }
  }
}

// Perspective: a batch whose box reaches the eye's plane has no finite box bound (all three tiers)
// and is still drawn; one behind the eye is culled.
TEST(AdaptivePlan, boxesAtAndBehindTheEyeArePlannedSafely) {
  PointSet s;
  for (int i = 0; i < 1024; ++i) s.positions.emplace_back(0.001 * (i % 32), 0.001 * (i / 32), -0.5 + 0.001 * i);  // crosses z = 0
  for (int i = 0; i < 1024; ++i) s.positions.emplace_back(0.001 * (i % 32), 0.001 * (i / 32), 5.0 + 0.001 * i);   // behind
  for (int i = 0; i < 1024; ++i) s.positions.emplace_back(0.001 * (i % 32), 0.001 * (i / 32), -3.0 - 0.001 * i);  // in front
  CameraSpec spec;
  spec.width = spec.height = 256;
  spec.eye = glm::dvec3(0.0);
  spec.target = glm::dvec3(0, 0, -1);
  spec.up = glm::dvec3(0, 1, 0);
  Result<Camera> camera = makeCamera(spec, boundsOf(s));
  ASSERT_TRUE(camera.ok());
  Result<ModeEncoding> e = prepareEncoding(PrecisionMode::kAdaptive, s, *camera);
  ASSERT_TRUE(e.ok()) << e.error().message;
  ASSERT_EQ(e->batch_plan.size(), 3u);
  EXPECT_TRUE(std::isinf(adaptiveBoxBoundPx(*e, 0, 3)));
  EXPECT_EQ(e->batch_plan[0], 3);
  EXPECT_EQ(e->batch_plan[1], 0) << "behind the eye";
  EXPECT_GE(e->batch_plan[2], 1);
  const BatchPlanStats stats = batchPlanStats(*e, s.size());
  EXPECT_EQ(stats.culled, 1u);
  EXPECT_DOUBLE_EQ(stats.bytes_per_point, (1024.0 * 12 + 1024.0 * 4 * e->batch_plan[2]) / 3072.0);
}

class Adaptive : public VulkanRenderTest {};

// Four batches along x across an orthographic view of x in [−1, 1]: the outer two lie well outside
// it (a batch's box is its power-of-two extent around its centre) and are culled, the inner two
// straddle its edges. Every point the view holds is drawn on its
// pixel, and the splat never reads a culled batch's point (the probe, zeroed first, keeps w = 0
// for exactly those), so a view of a few batches costs what they cost.
TEST_P(Adaptive, straddlingBatchesAreDrawnAndCulledOnesAreNeverRead) {
  PointSet s;
  const double centres[4] = {-5.5, -1.0, 1.0, 5.5};
  for (int i = 0; i < 4096; ++i) {
    s.positions.emplace_back(centres[i / 1024] + ((i % 1024) + 0.5) / 1024.0 - 0.5, 0.3 * std::sin(0.01 * i), 0.0);
    s.colors.emplace_back(float(i % 7) / 7.0f, 0.5f, 1.0f);
  }
  const Camera camera = orthoCamera(s, glm::dvec3(0.0), 2.0, 256);
  for (PrecisionMode mode : {PrecisionMode::kAdaptive, PrecisionMode::kBatch}) {
    Measured m = measure(s, camera, mode);
    ASSERT_TRUE(m.render.batch_plan.has_value());
    const BatchPlanStats& plan = *m.render.batch_plan;
    const size_t batch = modeInfo(mode).batch_points;
    EXPECT_EQ(plan.culled, mode == PrecisionMode::kAdaptive ? 2u : 0u) << "batch mode's one batch holds them all";
    EXPECT_GT(m.error.stats.points, 900u);
    EXPECT_EQ(m.error.stats.lost, 0u) << modeName(mode);
    EXPECT_EQ(m.error.stats.share_off_half_px, 0.0) << modeName(mode);
    if (GetParam() != Backend::kCompute) continue;  // the raster backend draws every point
    size_t read = 0;
    for (size_t i = 0; i < s.size(); ++i) {
      const bool culled = mode == PrecisionMode::kAdaptive && (i / batch == 0 || i / batch == 3);
      const glm::vec4& clip = m.render.probe_clip[i];
      read += clip.w != 0.0f;
      EXPECT_EQ(clip.w, culled ? 0.0f : 1.0f) << modeName(mode) << " point " << i;
    }
    EXPECT_EQ(read, mode == PrecisionMode::kAdaptive ? 2048u : 4096u);
  }
}

// `s` drawn top-down in `mode` on the compute backend twice: with early depth off (no merge, one
// atomic a point) and with it on and `merge` applied to the options; the pictures must be the same.
// Returns how many pixels the merged picture draws (the background is opaque black).
size_t expectMergeKeepsThePicture(const VulkanContext& context, const PointSet& s, PrecisionMode mode,
                                  void (*merge)(RenderOptions&)) {
  const Camera camera = topDownCamera(s, 1.28, 128);  // pixels 0.01 wide
  RenderOptions options;
  options.mode = mode;
  options.backend = Backend::kCompute;
  options.early_depth = false;
  Result<RenderResult> plain = renderPoints(context, s, camera, options);
  EXPECT_TRUE(plain.ok()) << plain.error().message;
  options.early_depth = true;
  merge(options);
  Result<RenderResult> merged = renderPoints(context, s, camera, options);
  EXPECT_TRUE(merged.ok()) << merged.error().message;
  if (!plain.ok() || !merged.ok()) return 0;
  EXPECT_EQ(merged->image.rgba, plain->image.rgba) << modeName(mode);
  size_t drawn = 0;
  const std::vector<uint8_t>& rgba = merged->image.rgba;
  for (size_t p = 0; p + 3 < rgba.size(); p += 4) drawn += (rgba[p] | rgba[p + 1] | rgba[p + 2]) != 0 ? 1 : 0;
  return drawn;
}

// The splat merges the lanes of a subgroup that land on one pixel (DeviceFacts::subgroup_merge):
// 20,000 points in runs on a 3 × 3 patch of pixels at many depths, and a spread of others, give the
// picture every point's own atomic gives.
TEST_P(Adaptive, subgroupMergeGivesThePlainPicture) {
  if (GetParam() != Backend::kCompute) GTEST_SKIP() << "the merge is the compute splat's";
  std::printf("subgroup merge on %s: %s\n", context_->facts.name.c_str(), context_->facts.subgroup_merge ? "yes" : "no");
  EXPECT_TRUE(context_->facts.subgroup_merge) << "lavapipe has subgroup vote and arithmetic: the test must cover the merge";
  PointSet s;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < 20000; ++i) {
    // Runs of 1000 consecutive points on one pixel, as Morton order makes them in a dense set.
    const int pixel = (i / 1000) % 9;
    s.positions.emplace_back(0.01 * (pixel % 3), 0.01 * (pixel / 3), -1.0 - unit(random));
    s.colors.emplace_back(float(i % 11) / 11.0f, float(i % 5) / 5.0f, 0.2f);
  }
  for (int i = 0; i < 20000; ++i) {
    s.positions.emplace_back(unit(random) - 0.5, unit(random) - 0.5, -1.0 - unit(random));
    s.colors.emplace_back(0.9f, float(i % 3) / 3.0f, 0.4f);
  }
  for (PrecisionMode mode : {PrecisionMode::kFp32, PrecisionMode::kAdaptive})
    EXPECT_GT(expectMergeKeepsThePicture(*context_, s, mode,
                                         [](RenderOptions& o) { o.subgroup_merge = true; }),  // off on a CPU by default
              1000u)
        << modeName(mode);
}

// Batch and adaptive modes' splat keeps one key for two consecutive points on one pixel
// (RenderOptions::pair_merge): runs of points on a 3 × 3 patch of pixels at many depths (runs of
// even and odd length, so pairs start on either point of a run; the nearer point of a pair either
// first or second), a spread of others, and points alternating in and out of the view give the
// picture every point's own atomic gives.
TEST_P(Adaptive, pairMergeGivesThePlainPicture) {
  if (GetParam() != Backend::kCompute) GTEST_SKIP() << "the merge is the compute splat's";
  PointSet s;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int run = 0, i = 0; run < 27; ++run) {
    // In every other run the odd points lie nearer, in the others the even ones, so wherever the
    // camera looks from, some pixels' nearest points are the second of their pair.
    const int pixel = run % 9;
    for (int k = 0; k < 700 + run; ++k, ++i) {
      const double z = ((i + run) % 2 ? 0.3 : -0.3) + 0.05 * unit(random);
      s.positions.emplace_back(0.01 * (pixel % 3), 0.01 * (pixel / 3), z);
      s.colors.emplace_back(float(i % 11) / 11.0f, float(i % 5) / 5.0f, 0.2f);
    }
  }
  for (int i = 0; i < 20000; ++i) {
    s.positions.emplace_back(unit(random) - 0.5, unit(random) - 0.5, unit(random) - 0.5);
    s.colors.emplace_back(0.9f, float(i % 3) / 3.0f, 0.4f);
  }
  for (int i = 0; i < 2000; ++i) {  // every other point outside the view, the others on one pixel
    const double outside = (i % 2) ? 5.0 : 0.0;
    s.positions.emplace_back(0.3 + outside, 0.3, unit(random) - 0.5);
    s.colors.emplace_back(0.1f, 0.8f, float(i % 7) / 7.0f);
  }
  for (PrecisionMode mode : {PrecisionMode::kBatch, PrecisionMode::kAdaptive})
    EXPECT_GT(expectMergeKeepsThePicture(*context_, s, mode,
                                         [](RenderOptions& o) {
                                           o.pair_merge = true;  // off on a CPU by default
                                           o.subgroup_merge = false;
                                         }),
              1000u)
        << modeName(mode);
}

INSTANTIATE_TEST_SUITE_P(Backends, Adaptive, ::testing::Values(Backend::kRaster, Backend::kCompute), backendName);

}  // namespace
}  // namespace dpoint
