#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <tuple>

#include "ops/info.h"

namespace dpoint {
namespace {

TEST(Info, boundsExtentAndFloatSpacing) {
  PointSet s;
  s.positions = {{-1, 2, 3}, {4, -5, 0.5}, {0, 0, -6378137.0}};
  const PointSetInfo i = computeInfo(s);
  EXPECT_EQ(i.count, 3u);
  EXPECT_EQ(i.min, glm::dvec3(-1, -5, -6378137.0));
  EXPECT_EQ(i.max, glm::dvec3(4, 2, 3));
  EXPECT_EQ(i.extent, glm::dvec3(5, 7, 6378140.0));
  EXPECT_EQ(i.max_abs, 6378137.0);
  EXPECT_EQ(i.float_spacing, 0.5);  // floats in [2^22, 2^23) are 0.5 apart
  EXPECT_TRUE(i.floatRepresents());
}

TEST(Info, detectsPointsThatFloatMerges) {
  // Millimetre spacing at the Earth's radius: float32 steps there are 0.5 m.
  PointSet s;
  for (int k = 0; k < 100; ++k) s.positions.emplace_back(6.378e6 + 0.001 * k, 0.0, 0.0);
  s.positions.emplace_back(6.378e6, 0.0, 0.0);  // an exact duplicate is not a merge
  const PointSetInfo i = computeInfo(s);
  EXPECT_FALSE(i.floatRepresents());
  EXPECT_GE(i.float_merged, 90u);
  EXPECT_NEAR(i.min_neighbor_distance, 0.001, 1e-9);
  // The same cloud near the origin is fine in float.
  for (glm::dvec3& p : s.positions) p.x -= 6.378e6;
  EXPECT_TRUE(computeInfo(s).floatRepresents());
}

// The merge count, dealt into buckets on several cores, is the count of a plain reference (each
// float32 point's distinct double points but one): runs across many buckets, exact duplicates,
// -0 beside +0 (equal in float and in double), NaN passed over; the same for any thread count.
// With 3 float32 cells, each run is a bucket of more than a core's share, sorted on all cores in
// pieces that are then merged (a deep zoom far from the origin).
TEST(Info, floatMergeCountIsTheReferenceOnAnyThreadCount) {
  for (int cells : {40000, 2}) {
    SCOPED_TRACE(std::to_string(cells + 1) + " float32 cells");
    std::mt19937_64 random(7);
    std::uniform_int_distribution<int> cell(0, cells), jitter(0, 3), fine(0, 1 << 20);
    PointSet s;
    for (int k = 0; k < 300000; ++k) {  // 6.4e6 + steps of 1/8 (float spacing there: 0.5)
      const double x = 6.4e6 + cell(random) * 0.5 + (cells > 2 ? jitter(random) * 0.125 : fine(random) * 0x1p-23);
      s.positions.emplace_back(x, k % 3 == 0 ? -0.0 : 0.0, k % 1000 == 0 ? std::nan("") : 1.0);
    }
    std::map<std::tuple<float, float, float>, std::set<std::tuple<double, double, double>>> runs;
    for (const glm::dvec3& p : s.positions) {
      if (std::isnan(p.z)) continue;
      const glm::vec3 f(p);
      runs[{f.x + 0.0f, f.y + 0.0f, f.z + 0.0f}].insert({p.x, p.y + 0.0, p.z});
    }
    size_t want = 0;
    for (const auto& [f, doubles] : runs) want += doubles.size() - 1;
    ASSERT_GT(want, 50000u);
    if (cells == 2) {
      ASSERT_LE(runs.size(), 4u);
    }
    for (unsigned threads : {1u, 2u, 3u, 7u}) EXPECT_EQ(computeInfo(s, 10, threads).float_merged, want) << threads;
  }
}

TEST(Info, nearestNeighbourSkipsDuplicatesAndFindsTinySpacing) {
  PointSet s;
  for (int k = 0; k < 5000; ++k) s.positions.emplace_back(std::cos(k) * 10.0, std::sin(k) * 10.0, k * 1e-3);
  s.positions.push_back(s.positions[0]);  // a duplicate: distance 0 does not count
  s.positions.emplace_back(0.0, 0.0, 0.0);
  s.positions.emplace_back(1e-40, 0.0, 0.0);  // float32 has no normal number this small
  const PointSetInfo i = computeInfo(s, s.size());
  EXPECT_EQ(i.min_neighbor_distance, 1e-40);
}

// Many copies of a few points (a scanner's returns at its origin, a set made from a grid) in no
// order: the trees hold ranges of one point many times over, which a search visits once. The
// nearest distance is still the set's own, here between two points beside a copied one; streamed
// the same. (Before the build of 2026-12-02 a query visited every copy of its own point: 2M copies
// beside one other point took minutes; `bench/results/2026-12-02/cpu/info-copies.md`.)
TEST(Info, nearestNeighbourOfManyCopiesIsTheirNeighbours) {
  PointSet s;
  const glm::dvec3 a(6.378e6, 1.0, 2.0), b(-3.0, 4.0, 0.5), c(0.0, 0.0, 0.0);
  for (int k = 0; k < 4000; ++k) s.positions.insert(s.positions.end(), {a, b, c});
  // Beside a, a close pair: each nearer to the other than to a, so a search that took the copies'
  // range for one point (the mutation x alone the same) misses the pair.
  s.positions.push_back(a + glm::dvec3(0.0, 0.0, 0x1p-30));
  s.positions.push_back(a + glm::dvec3(0.0, 0.0, 0x1p-30 + 0x1p-40));
  for (int k = 0; k < 50; ++k) s.positions.emplace_back(k * 10.0, 100.0, 0.0);
  std::mt19937 shuffle(5);
  std::shuffle(s.positions.begin(), s.positions.end(), shuffle);
  for (size_t sample : {size_t{10}, s.size()}) {
    for (unsigned threads : {1u, 3u}) {
      const PointSetInfo i = computeInfo(s, sample, threads);
      // With every point a query, the pair finds each other; sampled sparsely, no nearer distance.
      if (sample == s.size()) EXPECT_EQ(i.min_neighbor_distance, 0x1p-40) << threads;
      else EXPECT_GE(i.min_neighbor_distance, 0x1p-40) << threads;
      const BlockReader read = [&](uint64_t first, uint64_t n, PointSet& out) -> Status {
        out.positions.assign(s.positions.begin() + static_cast<long>(first),
                             s.positions.begin() + static_cast<long>(first + n));
        return okStatus();
      };
      Result<StreamedInfo> streamed = computeStreamedInfo(s.size(), false, 0, read, 1000, sample, threads);
      ASSERT_TRUE(streamed.ok());
      EXPECT_EQ(streamed->info.min_neighbor_distance, i.min_neighbor_distance) << threads;
    }
  }
}

TEST(Info, overflowBeyondFloatRange) {
  PointSet s;
  s.positions = {{1e39, 0, 0}, {0, 0, 0}};
  const PointSetInfo i = computeInfo(s);
  EXPECT_EQ(i.float_overflow, 1u);
  EXPECT_FALSE(i.floatRepresents());
  EXPECT_TRUE(std::isinf(i.float_spacing));
}

// A set read a block at a time (info --stream) gives computeInfo's facts: bounds, overflow and the
// sampled nearest neighbour, whose nearest point may lie in another block; blocks of 7 points and
// samples that do not divide the count test the sample's indices across block edges.
TEST(Info, streamedInfoEqualsTheWholeSetsWhateverTheBlocks) {
  PointSet s;
  for (int k = 0; k < 1000; ++k) s.positions.emplace_back(std::cos(k) * 1e3, std::sin(k) * 1e3, 6.378e6 + k * 0.25);
  s.positions.emplace_back(s.positions[10].x + 1e-6, s.positions[10].y, s.positions[10].z);  // a close pair
  s.positions.emplace_back(1e39, 0.0, 0.0);
  for (size_t sample : {size_t{1}, size_t{7}, size_t{333}, size_t{5000}}) {
    for (uint64_t block : {uint64_t{1}, uint64_t{7}, uint64_t{1002}, uint64_t{4096}}) {
      SCOPED_TRACE(std::to_string(sample) + " sampled, blocks of " + std::to_string(block));
      const PointSetInfo whole = computeInfo(s, sample);
      uint64_t reads = 0;
      const BlockReader read = [&](uint64_t first, uint64_t n, PointSet& out) -> Status {
        ++reads;
        out.positions.assign(s.positions.begin() + static_cast<long>(first),
                             s.positions.begin() + static_cast<long>(first + n));
        return okStatus();
      };
      Result<StreamedInfo> streamed = computeStreamedInfo(s.size(), false, 0, read, block, sample);
      ASSERT_TRUE(streamed.ok());
      const PointSetInfo& i = streamed->info;
      EXPECT_FALSE(streamed->merged_computed);
      EXPECT_EQ(i.count, whole.count);
      EXPECT_EQ(i.min, whole.min);
      EXPECT_EQ(i.max, whole.max);
      EXPECT_EQ(i.max_abs, whole.max_abs);
      EXPECT_EQ(i.float_overflow, whole.float_overflow);
      EXPECT_EQ(i.neighbor_sample, whole.neighbor_sample);
      EXPECT_EQ(i.min_neighbor_distance, whole.min_neighbor_distance);
      // Every block once, then again only those near another block's samples.
      const uint64_t blocks = (s.size() + block - 1) / block;
      EXPECT_GE(reads, blocks);
      EXPECT_LE(reads, 2 * blocks);
    }
  }
  // A read error ends it.
  const BlockReader failing = [](uint64_t, uint64_t, PointSet&) -> Status { return Error{"x.ply: truncated"}; };
  Result<StreamedInfo> failed = computeStreamedInfo(10, false, 0, failing, 4);
  ASSERT_FALSE(failed.ok());
  EXPECT_EQ(failed.error().message, "x.ply: truncated");
}

// A file in a spatial order (here 32 x 32 tiles of a grid, as Morton order keeps 1024 points
// together) reads again only the boxes near a sample; in no order, its blocks whole. Both give the
// set's own exact distances.
TEST(Info, streamedInfoReadsAgainOnlyTheBoxesNearASample) {
  PointSet tiled;
  uint64_t state = 99;
  const auto jitter = [&] { return double((state = state * 6364136223846793005ull + 1442695040888963407ull) >> 11) * 0x1p-60; };
  for (int ti = 0; ti < 16; ++ti)
    for (int tj = 0; tj < 16; ++tj)
      for (int i = 0; i < 32; ++i)
        for (int j = 0; j < 32; ++j) tiled.positions.emplace_back((ti * 32 + i) * 0.5 + jitter(), (tj * 32 + j) * 0.5, jitter());
  PointSet shuffled = tiled;
  for (size_t k = shuffled.size() - 1; k > 0; --k) std::swap(shuffled.positions[k], shuffled.positions[(k * 7919) % (k + 1)]);
  for (const PointSet* set : {&tiled, &shuffled}) {
    SCOPED_TRACE(set == &tiled ? "tiled" : "shuffled");
    const PointSetInfo whole = computeInfo(*set, 8);
    const BlockReader read = [&](uint64_t first, uint64_t n, PointSet& out) -> Status {
      out.positions.assign(set->positions.begin() + static_cast<long>(first), set->positions.begin() + static_cast<long>(first + n));
      return okStatus();
    };
    Result<StreamedInfo> streamed = computeStreamedInfo(set->size(), false, 0, read, 16384, 8, 2);
    ASSERT_TRUE(streamed.ok());
    EXPECT_EQ(streamed->info.min_neighbor_distance, whole.min_neighbor_distance);
    EXPECT_EQ(streamed->info.min, whole.min);
    EXPECT_EQ(streamed->info.max, whole.max);
    if (set == &tiled) {
      EXPECT_LT(streamed->points_read_again, set->size() / 2);
    } else {
      EXPECT_EQ(streamed->points_read_again, set->size());
    }
  }
}

// Non-finite points (read with --allow-nonfinite) take no part in the nearest distance, whole or
// streamed, and do not upset the trees' ordering.
TEST(Info, nonFinitePointsAreLeftOutOfTheNearestDistance) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  PointSet s;
  for (int k = 0; k < 300; ++k) {
    s.positions.emplace_back(k * 2.0, 0.0, 0.0);
    if (k % 7 == 0) s.positions.emplace_back(nan, k, 0.0);
    if (k % 11 == 0) s.positions.emplace_back(0.0, -inf, k);
  }
  s.positions.emplace_back(101.5, 0.0, 0.0);  // 1.5 from 100, 0.5 from 102
  const PointSetInfo whole = computeInfo(s, s.size());
  EXPECT_EQ(whole.min_neighbor_distance, 0.5);
  EXPECT_EQ(whole.float_merged, 0u);
  const BlockReader read = [&](uint64_t first, uint64_t n, PointSet& out) -> Status {
    out.positions.assign(s.positions.begin() + static_cast<long>(first), s.positions.begin() + static_cast<long>(first + n));
    return okStatus();
  };
  Result<StreamedInfo> streamed = computeStreamedInfo(s.size(), false, 0, read, 13, s.size());
  ASSERT_TRUE(streamed.ok());
  EXPECT_EQ(streamed->info.min_neighbor_distance, 0.5);
  // Without infinities the float32 merge count runs, over the finite points: 1 + 1e-12 merges.
  PointSet merged;
  for (int k = 0; k < 50; ++k) merged.positions.emplace_back(k % 5 == 0 ? nan : k, 0.0, 0.0);
  merged.positions.emplace_back(1.0 + 1e-12, 0.0, 0.0);
  EXPECT_EQ(computeInfo(merged).float_merged, 1u);
}

// The bounds pass NaN coordinates over, whatever the points' order, whole or streamed: with a NaN
// first they were NaN, with it later they were the other points' (helper review, --allow-nonfinite).
// An axis of NaNs only is NaN; an infinity is a bound.
TEST(Info, boundsPassNanOverInAnyOrder) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (bool nan_first : {true, false}) {
    PointSet s;
    s.positions = {{1.0, 1.0, nan}, {nan, 0.0, nan}};
    if (nan_first) std::swap(s.positions[0], s.positions[1]);
    const PointSetInfo whole = computeInfo(s);
    EXPECT_EQ(whole.min.x, 1.0) << nan_first;
    EXPECT_EQ(whole.max.x, 1.0) << nan_first;
    EXPECT_EQ(whole.min.y, 0.0) << nan_first;
    EXPECT_EQ(whole.max.y, 1.0) << nan_first;
    EXPECT_TRUE(std::isnan(whole.min.z) && std::isnan(whole.max.z)) << nan_first;
    const BlockReader read = [&](uint64_t first, uint64_t n, PointSet& out) -> Status {
      out.positions.assign(s.positions.begin() + static_cast<long>(first), s.positions.begin() + static_cast<long>(first + n));
      return okStatus();
    };
    Result<StreamedInfo> streamed = computeStreamedInfo(s.size(), false, 0, read, 1, s.size());
    ASSERT_TRUE(streamed.ok());
    EXPECT_EQ(streamed->info.min.x, 1.0) << nan_first;
    EXPECT_EQ(streamed->info.min.y, 0.0) << nan_first;
  }
  PointSet with_inf;
  with_inf.positions = {{0.0, 0.0, 0.0}, {inf, 1.0, 1.0}};
  EXPECT_EQ(computeInfo(with_inf).max.x, inf);
}

// The nearest distance at any scale: a grid 1e-200 or 1e200 apart (the build before squared the
// raw differences, 0 or infinite there, and found none), whole or streamed; streamed in the grid's
// order in blocks of 2 (the second pass by boxes) and shuffled (by blocks, whose points are scaled as read).
TEST(Info, nearestNeighbourHoldsAtAnyScale) {
  const auto streamed = [](const PointSet& s, uint64_t block) {
    const BlockReader read = [&](uint64_t first, uint64_t n, PointSet& out) -> Status {
      out.positions.assign(s.positions.begin() + static_cast<long>(first), s.positions.begin() + static_cast<long>(first + n));
      return okStatus();
    };
    Result<StreamedInfo> info = computeStreamedInfo(s.size(), false, 0, read, block, 64);
    EXPECT_TRUE(info.ok());
    return info.ok() ? info->info.min_neighbor_distance : -1.0;
  };
  for (double scale : {1e-200, 1.0, 1e200}) {
    PointSet s;
    for (int k = 0; k < 8000; ++k) s.positions.emplace_back(k % 20 * scale, k / 20 % 20 * scale, k / 400 * scale);
    const PointSetInfo info = computeInfo(s, s.size());
    EXPECT_NEAR(info.min_neighbor_distance / scale, 1.0, 1e-12) << scale;
    EXPECT_EQ(streamed(s, 2), computeInfo(s, 64).min_neighbor_distance) << scale;  // boxes of 2: compact
    PointSet shuffled = s;
    std::mt19937 random(7);
    std::shuffle(shuffled.positions.begin(), shuffled.positions.end(), random);
    EXPECT_EQ(streamed(shuffled, 1024), computeInfo(shuffled, 64).min_neighbor_distance) << scale;
    EXPECT_NEAR(streamed(shuffled, 1024) / scale, 1.0, 1e-12) << scale;
  }
  PointSet far;  // near the largest double, a tiny extent: the unit keeps the coordinates finite
  far.positions = {{1e300, 0.0, 0.0}, {1e300 + 1e285, 0.0, 0.0}, {1e300 + 3e285, 0.0, 0.0}};
  EXPECT_EQ(computeInfo(far).min_neighbor_distance, far.positions[1].x - far.positions[0].x);
  EXPECT_EQ(streamed(far, 1), far.positions[1].x - far.positions[0].x);
}

TEST(Info, emptySetHasZeroCount) {
  const PointSetInfo i = computeInfo(PointSet{});
  EXPECT_EQ(i.count, 0u);
  EXPECT_EQ(i.neighbor_sample, 0u);
}

}  // namespace
}  // namespace dpoint
