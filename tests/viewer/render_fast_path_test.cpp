// The compute backend's fast path against its plain one (issue #11), on lavapipe with the validation
// layer on: the early depth test must give the very same picture as doing every atomic, and a
// Morton-ordered set the same picture as the set in its input order, except which of two points
// at the same depth on one pixel wins (the lower index wins, and the order changes the indices).
// The hard cases are DESIGN §7's, at small sizes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <set>

#include "ops/point_order.h"
#include "generators/mandelbrot2d.h"
#include "render_test_support.h"

namespace dpoint {
namespace {

class FastPath : public VulkanRenderTest {};

struct HardCase {
  std::string name;
  PointSet points;
  Camera camera;
};

// Colour from the position's bits, so coincident points share a colour whatever their order.
void colourByPosition(PointSet& s) {
  s.colors.resize(s.size());
  for (size_t i = 0; i < s.size(); ++i) {
    uint64_t h = 1469598103934665603ull;
    for (int a = 0; a < 3; ++a) {
      uint64_t bits = 0;
      std::memcpy(&bits, &s.positions[i][a], 8);
      h = (h ^ bits) * 1099511628211ull;
      h ^= h >> 29;
    }
    for (int c = 0; c < 3; ++c) s.colors[i][c] = static_cast<float>((h >> (16 * c)) & 0xffu) / 255.0f;
  }
}

// 20 × 20 × 20 points (more than one 4096-point block) `spacing` apart around `centre`.
PointSet bigCloud(const glm::dvec3& centre, double spacing) {
  PointSet s;
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j)
      for (int k = 0; k < 20; ++k) s.positions.push_back(centre + spacing * glm::dvec3(i - 9.5, j - 9.5, k - 9.5));
  return s;
}

std::vector<HardCase> hardCases() {
  std::vector<HardCase> out;
  for (double offset : {0.0, 6.378e6, 1e8}) {
    const glm::dvec3 centre(offset, offset * 0.5, 0.0);
    PointSet s = bigCloud(centre, 1e-3);
    Camera camera = lookAtCloud(s, centre, 0.05);
    out.push_back({"cloud at " + std::to_string(offset), std::move(s), camera});
  }
  {
    PointSet s = bigCloud(glm::dvec3(3e-300), 1e-303);  // tiny, near the origin
    Camera camera = lookAtCloud(s, glm::dvec3(3e-300), 5e-302);
    out.push_back({"tiny", std::move(s), camera});
  }
  {
    DeepZoom zoom = deepZoom(1e-13, 96, 600);  // a flat grid: every depth ties
    out.push_back({"deep zoom 1e-13", std::move(zoom.grid), zoom.camera});
  }
  {
    PointSet s;
    for (size_t i = 0; i < 100; ++i) s.positions.emplace_back(6.378e6 + 1e-4 * static_cast<double>(100 - i), 1.5, -2.25);
    s.positions.insert(s.positions.end(), 5000, glm::dvec3(6.378e6, 1.5, -2.25));
    CameraSpec spec;
    spec.width = 101;
    spec.height = 75;
    Camera camera = *makeCamera(spec, boundsOf(s));
    out.push_back({"identical points", std::move(s), camera});
  }
  for (HardCase& c : out) colourByPosition(c.points);
  return out;
}

uint32_t pixelAt(const Image& image, size_t p) {
  uint32_t v = 0;
  std::memcpy(&v, image.rgba.data() + 4 * p, 4);
  return v;
}

// For every pixel, the colours of the points that could win it: those at its greatest depth, from
// the GPU's own clip positions (the probe), with the shader's pixel and depth arithmetic.
std::vector<std::set<uint32_t>> contenders(const PointSet& points, const RenderResult& probed, const Camera& camera) {
  const uint32_t w = camera.width, h = camera.height;
  std::vector<float> best(size_t{w} * h, -1.0f);
  std::vector<std::set<uint32_t>> out(size_t{w} * h);
  const std::vector<uint32_t> colors = encodeColors(points);
  for (size_t i = 0; i < points.size(); ++i) {
    const glm::vec4& c = probed.probe_clip[i];
    if (!(c.w > 0.0f) || std::fabs(c.x) > c.w || std::fabs(c.y) > c.w || c.z < 0.0f || c.z > c.w) continue;
    const float depth = c.z / c.w;
    const int px = static_cast<int>(std::ceil((c.x / c.w * 0.5f + 0.5f) * static_cast<float>(w))) - 1;
    const int py = static_cast<int>(std::ceil((c.y / c.w * 0.5f + 0.5f) * static_cast<float>(h))) - 1;
    if (px < 0 || py < 0 || px >= static_cast<int>(w) || py >= static_cast<int>(h)) continue;
    const size_t p = static_cast<size_t>(py) * w + static_cast<size_t>(px);
    if (depth > best[p]) {
      best[p] = depth;
      out[p].clear();
    }
    if (depth == best[p]) out[p].insert(colors[i]);
  }
  return out;
}

TEST_P(FastPath, earlyDepthTestGivesThePlainPictureInEveryMode) {
  if (GetParam() != Backend::kCompute) GTEST_SKIP() << "the early depth test is the compute backend's";
  for (const HardCase& c : hardCases()) {
    for (PrecisionMode mode : kAllModes) {
      RenderOptions options;
      options.mode = mode;
      options.backend = Backend::kCompute;
      options.early_depth = false;
      Result<RenderResult> plain = renderPoints(*context_, c.points, c.camera, options);
      ASSERT_TRUE(plain.ok()) << c.name << " " << modeName(mode) << ": " << plain.error().message;
      options.early_depth = true;
      Result<RenderResult> fast = renderPoints(*context_, c.points, c.camera, options);
      ASSERT_TRUE(fast.ok()) << c.name << " " << modeName(mode) << ": " << fast.error().message;
      EXPECT_EQ(fast->image.rgba, plain->image.rgba) << c.name << " " << modeName(mode);
    }
  }
}

// RenderOptions::near_end_first: a chunk whose points come nearer along their order is splatted
// from its far end, with the very same picture, in modes with and without batches, at every point
// size and shape, over chunks that end inside a workgroup's points; a chunk seen from its first
// points is left in its order.
TEST_P(FastPath, nearEndFirstGivesTheSamePictureAndTurnsOnlyChunksThatComeNearer) {
  if (GetParam() != Backend::kCompute) GTEST_SKIP() << "the order is for the compute backend";
  const glm::dvec3 centre(6.378e6, 1.5, -2.25);
  PointSet s = bigCloud(centre, 1e-3);  // x grows slowest along the order
  colourByPosition(s);
  for (double side : {1.0, -1.0}) {
    CameraSpec spec;
    spec.width = 160;
    spec.height = 120;
    spec.eye = centre + glm::dvec3(side * 0.05, 0.002, 0.001);  // nearly along x: the last points (+x) nearest, or the first
    spec.target = centre;
    spec.up = glm::dvec3(0, 1, 0);
    Result<Camera> camera = makeCamera(spec, boundsOf(s));
    ASSERT_TRUE(camera.ok()) << camera.error().message;
    for (PrecisionMode mode : {PrecisionMode::kFp32, PrecisionMode::kDf64, PrecisionMode::kNative, PrecisionMode::kBatch,
                               PrecisionMode::kAdaptive}) {
      for (float size : {1.0f, 3.0f, 4.0f}) {
        for (bool round : {false, true}) {
          const std::string what = std::string(side > 0 ? "seen from its last points" : "seen from its first points") +
                                   " " + std::string(modeName(mode)) + " " + std::to_string(size) + " px" + (round ? " round" : "");
          RenderOptions options;
          options.mode = mode;
          options.backend = Backend::kCompute;
          options.point_size = size;
          options.round_points = round;
          // Three chunks, each ending inside a group of 1024 points (and, in batch and adaptive
          // modes, a batch: their workgroups then take the batch list).
          options.max_chunk_points = 3000;
          options.near_end_first = false;
          Result<RenderResult> plain = renderPoints(*context_, s, *camera, options);
          ASSERT_TRUE(plain.ok()) << what << ": " << plain.error().message;
          options.near_end_first = true;
          Result<RenderResult> turned = renderPoints(*context_, s, *camera, options);
          ASSERT_TRUE(turned.ok()) << what << ": " << turned.error().message;
          EXPECT_EQ(plain->reversed_chunks, 0u) << what;
          EXPECT_EQ(turned->reversed_chunks, side > 0 ? turned->chunks : 0u) << what;
          EXPECT_GT(turned->chunks, 2u) << what;
          EXPECT_EQ(turned->image.rgba, plain->image.rgba) << what;
        }
      }
    }
  }
}

// A stream settled after its upload (dpoint render's one pass over a file) gets its options made
// afresh: its chunks still run from their nearer end, as chosen when its samples were kept at the
// upload, whatever the settled options say, with the picture of the set in memory.
TEST_P(FastPath, aSettledStreamKeepsItsSplatOrder) {
  if (GetParam() != Backend::kCompute) GTEST_SKIP() << "the order is for the compute backend";
  const glm::dvec3 centre(6.378e6, 1.5, -2.25);
  PointSet s = bigCloud(centre, 1e-3);
  colourByPosition(s);
  CameraSpec spec;
  spec.width = 160;
  spec.height = 120;
  spec.eye = centre + glm::dvec3(0.05, 0.002, 0.001);  // nearest the set's last points
  spec.target = centre;
  spec.up = glm::dvec3(0, 1, 0);
  Result<Camera> camera = makeCamera(spec, boundsOf(s));
  ASSERT_TRUE(camera.ok()) << camera.error().message;
  PointStream stream;
  stream.count = s.size();
  stream.has_colors = true;
  stream.read = [&](size_t first, size_t n, PointSet& block) -> Status {
    block.positions.assign(s.positions.begin() + static_cast<std::ptrdiff_t>(first),
                           s.positions.begin() + static_cast<std::ptrdiff_t>(first + n));
    block.colors.assign(s.colors.begin() + static_cast<std::ptrdiff_t>(first),
                        s.colors.begin() + static_cast<std::ptrdiff_t>(first + n));
    return okStatus();
  };
  RenderOptions options;
  options.backend = Backend::kCompute;
  options.point_size = 3.0f;
  options.round_points = true;
  options.max_chunk_points = 3000;
  options.near_end_first = true;
  Result<RenderResult> whole = renderPoints(*context_, s, *camera, options);
  ASSERT_TRUE(whole.ok()) << whole.error().message;
  const StreamSettle settle = [&](Camera&, RenderOptions& settled) -> Status {
    settled = RenderOptions{};  // made afresh, as the render job makes them
    settled.near_end_first = false;
    settled.backend = Backend::kCompute;
    settled.point_size = 3.0f;
    settled.round_points = true;
    return okStatus();
  };
  Result<RenderResult> streamed = renderStreamOnce(*context_, stream, *camera, options, settle);
  ASSERT_TRUE(streamed.ok()) << streamed.error().message;
  EXPECT_EQ(whole->reversed_chunks, whole->chunks);
  EXPECT_EQ(streamed->reversed_chunks, streamed->chunks);
  EXPECT_GE(streamed->chunks, 3u);
  EXPECT_TRUE(streamed->image.rgba == whole->image.rgba);
}

// Modes whose arithmetic per point does not depend on the other points (batch's does: its batches
// are formed in storage order, so reordering moves their origins).
TEST_P(FastPath, mortonOrderGivesTheInputOrderPictureTiesAside) {
  if (GetParam() != Backend::kCompute) GTEST_SKIP() << "the order is for the compute backend";
  size_t all_ties = 0, all_differing = 0;
  for (const HardCase& c : hardCases()) {
    PointSet morton = c.points;
    reorderPoints(morton, PointOrder::kMorton);
    EXPECT_TRUE(morton.positions != c.points.positions) << c.name << ": the order changed";
    for (PrecisionMode mode : {PrecisionMode::kFp32, PrecisionMode::kRte, PrecisionMode::kDf64, PrecisionMode::kNative}) {
      RenderOptions options;
      options.mode = mode;
      options.backend = Backend::kCompute;
      options.probe = true;
      Result<RenderResult> input = renderPoints(*context_, c.points, c.camera, options);
      ASSERT_TRUE(input.ok()) << c.name << " " << modeName(mode) << ": " << input.error().message;
      Result<RenderResult> sorted = renderPoints(*context_, morton, c.camera, options);
      ASSERT_TRUE(sorted.ok()) << c.name << " " << modeName(mode) << ": " << sorted.error().message;
      const std::vector<std::set<uint32_t>> could_win = contenders(c.points, *input, c.camera);
      size_t differing = 0, ties = 0;
      for (size_t p = 0; p < could_win.size(); ++p) {
        ties += could_win[p].size() > 1;
        const uint32_t a = pixelAt(input->image, p), b = pixelAt(sorted->image, p);
        if (a == b) continue;
        ++differing;
        EXPECT_TRUE(could_win[p].count(a) && could_win[p].count(b))
            << c.name << " " << modeName(mode) << ": pixel " << p << " differs and is no tie";
      }
      EXPECT_LE(differing, ties) << c.name << " " << modeName(mode);
      all_ties += ties;
      all_differing += differing;
    }
  }
  EXPECT_GT(all_differing, 0u) << "some ties went the other way: the comparison saw them";
  std::printf("%zu pixels with ties, %zu of them won by another point\n", all_ties, all_differing);
}

INSTANTIATE_TEST_SUITE_P(Backends, FastPath, ::testing::Values(Backend::kCompute), backendName);

}  // namespace
}  // namespace dpoint
