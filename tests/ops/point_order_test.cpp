// reorderPoints: the Morton order in shuffled blocks is a permutation of the points (colours and
// triangles follow), sorted within blocks, the sorted blocks reshuffled with the partial block
// last, stable, independent of the thread count, and meaningful on degenerate and far-off sets.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <numeric>
#include <random>

#include "ops/point_order.h"
#include "viewer/encode.h"  // kBatchSize, for the static_assert only

namespace dpoint {
namespace {

static_assert(kOrderBlock == kBatchSize, "a Morton block must be one GPU batch");

constexpr uint64_t kAxisOnes = 0x1249249249249249ull;  // bits 0, 3, ..., 60: x all ones

uint64_t bitsOf(double v) {
  uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

// A point with its colour, compared by bit pattern (so NaN and -0.0 count as themselves).
using Row = std::array<uint64_t, 6>;
Row rowOf(const PointSet& s, size_t i) {
  const glm::vec3 c = s.hasColors() ? s.colors[i] : glm::vec3(0.0f);
  return {bitsOf(s.positions[i].x), bitsOf(s.positions[i].y), bitsOf(s.positions[i].z),
          bitsOf(c.r), bitsOf(c.g), bitsOf(c.b)};
}

// The Morton order as the header defines it, computed the slow, obvious way: a stable sort by
// code, cut into blocks. Each block is its rows.
std::vector<std::vector<Row>> sortedBlocks(const PointSet& s) {
  const MortonFrame frame = mortonFrame(s.positions, 1);
  std::vector<size_t> order(s.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return mortonCode(frame, s.positions[a]) < mortonCode(frame, s.positions[b]);
  });
  std::vector<std::vector<Row>> blocks;
  for (size_t i = 0; i < order.size(); ++i) {
    if (i % kOrderBlock == 0) blocks.emplace_back();
    blocks.back().push_back(rowOf(s, order[i]));
  }
  return blocks;
}

// Checks `after` is `before` in the Morton order: every output block is one of the sorted blocks,
// each used once, the partial block (if any) last; codes never decrease within a block.
void expectMortonOrderOf(const PointSet& before, const PointSet& after) {
  ASSERT_EQ(after.size(), before.size());
  ASSERT_EQ(after.colors.size(), before.colors.size());
  const std::vector<std::vector<Row>> expected = sortedBlocks(before);
  const MortonFrame frame = mortonFrame(after.positions, 1);
  std::vector<bool> used(expected.size(), false);
  for (size_t b = 0; b * kOrderBlock < after.size(); ++b) {
    const size_t first = b * kOrderBlock, count = std::min(kOrderBlock, after.size() - first);
    std::vector<Row> block;
    for (size_t i = first; i < first + count; ++i) {
      block.push_back(rowOf(after, i));
      if (i > first) {
        ASSERT_LE(mortonCode(frame, after.positions[i - 1]), mortonCode(frame, after.positions[i])) << "point " << i;
      }
    }
    if (count < kOrderBlock) {
      ASSERT_EQ(b + 1, expected.size()) << "a partial block must be the last";
      ASSERT_TRUE(block == expected.back()) << "the partial block is not the last sorted one";
      used.back() = true;
      continue;
    }
    bool found = false;
    for (size_t e = 0; e < expected.size() && !found; ++e) {
      if (!used[e] && expected[e] == block) used[e] = found = true;
    }
    ASSERT_TRUE(found) << "output block " << b << " is not a block of the stable sort";
  }
  EXPECT_TRUE(std::all_of(used.begin(), used.end(), [](bool u) { return u; }));
}

PointSet randomCloud(size_t n, uint64_t seed, bool colors = true) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  PointSet s;
  for (size_t i = 0; i < n; ++i) {
    s.positions.push_back({u(rng), u(rng), u(rng)});
    // The colour tags the input index, so a wrong pairing or a broken tie order shows.
    if (colors) s.colors.push_back({static_cast<float>(i), static_cast<float>(i % 7), 0.5f});
  }
  return s;
}

PointSet reordered(PointSet s, unsigned threads = 0) {
  reorderPoints(s, PointOrder::kMorton, threads);
  return s;
}

TEST(PointOrder, parseNamesTheFlagAndTheValue) {
  EXPECT_EQ(*parsePointOrder("--order", "input"), PointOrder::kInput);
  EXPECT_EQ(*parsePointOrder("--order", "morton"), PointOrder::kMorton);
  Result<PointOrder> bad = parsePointOrder("--order", "hilbert");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, ExitCode::kUsage);
  EXPECT_EQ(bad.error().message, "--order hilbert: must be input or morton");
  EXPECT_STREQ(pointOrderName(PointOrder::kMorton), "morton");
}

TEST(PointOrder, mortonCodeInterleavesXyzFromTheLowestBit) {
  const MortonFrame frame = mortonFrame({{0, 0, 0}, {1, 1, 1}});
  EXPECT_EQ(mortonCode(frame, {0, 0, 0}), 0u);
  EXPECT_EQ(mortonCode(frame, {1, 0, 0}), kAxisOnes);
  EXPECT_EQ(mortonCode(frame, {0, 1, 0}), kAxisOnes << 1);
  EXPECT_EQ(mortonCode(frame, {0, 0, 1}), kAxisOnes << 2);
  EXPECT_EQ(mortonCode(frame, {1, 1, 1}), ~uint64_t{0} >> 1);
  EXPECT_EQ(mortonCode(frame, {0.5, 0, 0}), uint64_t{1} << 60);
  EXPECT_EQ(mortonCode(frame, {0, 0.5, 0}), uint64_t{1} << 61);
  EXPECT_EQ(mortonCode(frame, {0, 0, 0.5}), uint64_t{1} << 62);
  // q / 2^21 quantizes back to q exactly in this frame; compare with interleaving bit by bit.
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 1000; ++trial) {
    const uint32_t q[3] = {static_cast<uint32_t>(rng() >> 43), static_cast<uint32_t>(rng() >> 43),
                           static_cast<uint32_t>(rng() >> 43)};
    uint64_t expected = 0;
    for (int bit = 0; bit < 21; ++bit)
      for (int a = 0; a < 3; ++a) expected |= uint64_t{(q[a] >> bit) & 1u} << (3 * bit + a);
    EXPECT_EQ(mortonCode(frame, glm::dvec3(q[0], q[1], q[2]) * 0x1p-21), expected);
  }
}

TEST(PointOrder, mortonCodeSendsNonFiniteToTheEndsAndNeverOverflows) {
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  const MortonFrame frame = mortonFrame({{-1e308, 0, nan}, {1e308, 0, inf}, {0, 0, 0}});
  EXPECT_TRUE(std::isfinite(frame.half_extent.x));
  EXPECT_EQ(frame.half_extent.y, 0.0);  // flat
  EXPECT_EQ(frame.half_extent.z, 0.0);  // one finite value
  EXPECT_EQ(mortonCode(frame, {-1e308, 5, 0}), 0u);
  EXPECT_EQ(mortonCode(frame, {1e308, 0, 0}), kAxisOnes);
  EXPECT_EQ(mortonCode(frame, {0, 0, 0}), uint64_t{1} << 60);  // the middle of x
  EXPECT_EQ(mortonCode(frame, {nan, 0, 0}), 0u);
  EXPECT_EQ(mortonCode(frame, {-inf, 0, 0}), 0u);
  EXPECT_EQ(mortonCode(frame, {inf, 0, 0}), kAxisOnes);
}

TEST(PointOrder, shuffledBlocksIsAFixedPermutation) {
  for (size_t count : {0, 1, 2, 3, 1000}) {
    std::vector<uint32_t> p = shuffledBlocks(count);
    ASSERT_EQ(p.size(), count);
    std::sort(p.begin(), p.end());
    for (size_t i = 0; i < count; ++i) EXPECT_EQ(p[i], i);
  }
  // Pinned: the bench's compute-backend timings depend on this layout; a change must be deliberate.
  EXPECT_EQ(shuffledBlocks(8), shuffledBlocks(8));
  const std::vector<uint32_t> ten = shuffledBlocks(10);
  // Checked against a separate Python mt19937_64 (its 10000th output from the default seed is the
  // standard's 9981545732273789042) with the same rejection and Fisher–Yates steps.
  EXPECT_EQ(ten, (std::vector<uint32_t>{4, 5, 7, 6, 3, 2, 1, 8, 9, 0}));
}

TEST(PointOrder, inputOrderLeavesTheSetAlone) {
  PointSet s = randomCloud(5000, 1);
  const PointSet before = s;
  reorderPoints(s, PointOrder::kInput);
  EXPECT_EQ(s.positions, before.positions);
  EXPECT_EQ(s.colors, before.colors);
}

TEST(PointOrder, mortonIsSortedBlocksInShuffledOrderWithThePartialBlockLast) {
  const PointSet before = randomCloud(10 * kOrderBlock + 123, 2);
  const PointSet after = reordered(before);
  expectMortonOrderOf(before, after);
  // Shuffled, not merely sorted: some whole block is away from its sorted place.
  const std::vector<std::vector<Row>> sorted = sortedBlocks(before);
  size_t moved = 0;
  for (size_t b = 0; b < 10; ++b) moved += rowOf(after, b * kOrderBlock) != sorted[b][0];
  EXPECT_GE(moved, 2u);
}

TEST(PointOrder, exactMultipleOfTheBlockHasNoPartialBlock) {
  const PointSet before = randomCloud(3 * kOrderBlock, 3);
  expectMortonOrderOf(before, reordered(before));
}

TEST(PointOrder, resultDoesNotDependOnTheThreadCount) {
  // A dense cluster and a few far points: most points share the first digit, so the sort takes
  // its path for one bucket of more than 2^20 points, split over threads.
  PointSet before = randomCloud((size_t{1} << 20) + 5000, 4);
  for (size_t i = 0; i < before.size(); ++i) before.positions[i] = before.positions[i] * 1e-6 + glm::dvec3(0.25);
  before.positions[17] = {-1000, -1000, -1000};
  before.positions[999] = {1000, 1000, 1000};
  const PointSet one = reordered(before, 1), four = reordered(before, 4), three = reordered(before, 3);
  EXPECT_TRUE(one.positions == four.positions && one.colors == four.colors);
  EXPECT_TRUE(one.positions == three.positions && one.colors == three.colors);
  expectMortonOrderOf(before, one);
}

TEST(PointOrder, equalCodesKeepTheirInputOrder) {
  // 8 distinct positions, many copies of each, tagged by input index in the colour; enough of
  // them that the first digit's counting sort is split into chunks over the threads.
  PointSet before;
  for (size_t i = 0; i < 50 * kOrderBlock + 77; ++i) {
    const size_t corner = (i * 5) % 8;
    before.positions.push_back({double(corner & 1), double((corner >> 1) & 1), double(corner >> 2)});
    before.colors.push_back({static_cast<float>(i), 0, 0});
  }
  const PointSet after = reordered(before, 4);
  expectMortonOrderOf(before, after);
  for (size_t first = 0; first < after.size(); first += kOrderBlock) {
    for (size_t i = first + 1; i < std::min(after.size(), first + kOrderBlock); ++i) {
      if (after.positions[i] == after.positions[i - 1]) {
        ASSERT_LT(after.colors[i - 1].r, after.colors[i].r) << i;
      }
    }
  }
}

// Short ranges are sorted by insertion, not by digits: ties there must keep their order too.
TEST(PointOrder, equalCodesKeepTheirInputOrderInShortRanges) {
  for (size_t n : {3, 17, 30, 100}) {
    PointSet before;
    for (size_t i = 0; i < n; ++i) {
      before.positions.push_back({double((i * 7) % 3), double(i % 2), 0.0});
      before.colors.push_back({static_cast<float>(i), 0, 0});
    }
    const PointSet after = reordered(before);
    expectMortonOrderOf(before, after);
    for (size_t i = 1; i < n; ++i) {
      if (after.positions[i] == after.positions[i - 1]) {
        ASSERT_LT(after.colors[i - 1].r, after.colors[i].r) << n << " points, " << i;
      }
    }
  }
}

// The sort keys leave out the bits of flat axes (their coordinate quantizes to 0 in every code), so
// that a 2D set's radix digits split it evenly: the order must be the 3D codes' order all the same,
// ties included, for a plane of each orientation and a line, also past the sizes the top level
// sorts over all threads.
TEST(PointOrder, flatAxesGiveTheOrderOfTheFullCodes) {
  for (int flat : {0b100, 0b001, 0b010, 0b101}) {  // x; z; y; x and z
    SCOPED_TRACE("flat axes " + std::to_string(flat));
    PointSet s = randomCloud(150000, 11 + static_cast<uint64_t>(flat));
    for (size_t i = 0; i < s.size(); ++i) {
      for (int a = 0; a < 3; ++a)
        if ((flat >> (2 - a)) & 1) s.positions[i][a] = a == 0 ? 0.0 : 7.5;
      if (i % 97 == 0 && i > 0) s.positions[i] = s.positions[i - 1];  // ties, kept in input order
    }
    expectMortonOrderOf(s, reordered(s, 2));
  }
  PointSet plane = randomCloud(1300000, 5);  // > kParallelMin (2^20) points in the top-level range
  for (glm::dvec3& p : plane.positions) p.z = 0.0;
  expectMortonOrderOf(plane, reordered(plane, 3));
}

TEST(PointOrder, tinySetsAreSortedAndEmptyIsLeftAlone) {
  PointSet empty;
  reorderPoints(empty, PointOrder::kMorton);
  EXPECT_EQ(empty.size(), 0u);

  PointSet one;
  one.positions = {{3, 4, 5}};
  one.colors = {{0.1f, 0.2f, 0.3f}};
  reorderPoints(one, PointOrder::kMorton);
  EXPECT_EQ(one.positions[0], glm::dvec3(3, 4, 5));
  EXPECT_EQ(one.colors[0], glm::vec3(0.1f, 0.2f, 0.3f));

  PointSet two;
  two.positions = {{1, 1, 1}, {0, 0, 0}};
  two.colors = {{1, 1, 1}, {0, 0, 0}};
  reorderPoints(two, PointOrder::kMorton);
  EXPECT_EQ(two.positions, (PositionArray{{0, 0, 0}, {1, 1, 1}}));
  EXPECT_EQ(two.colors, (ColorArray{{0, 0, 0}, {1, 1, 1}}));
}

TEST(PointOrder, identicalPointsKeepOrderWithinBlocks) {
  PointSet before;
  for (size_t i = 0; i < 2 * kOrderBlock + 10; ++i) {
    before.positions.push_back({6378137.0, -1e8, 0.5});
    before.colors.push_back({static_cast<float>(i), 0, 0});
  }
  const PointSet after = reordered(before);
  expectMortonOrderOf(before, after);
  // The partial block is the input's tail, unmoved.
  for (size_t i = 2 * kOrderBlock; i < after.size(); ++i) EXPECT_EQ(after.colors[i].r, static_cast<float>(i));
}

TEST(PointOrder, flatAxisAndColourlessSetsAreOrdered) {
  PointSet planar = randomCloud(5 * kOrderBlock + 1, 5, false);
  for (glm::dvec3& p : planar.positions) p.z = 0.0;
  const PointSet after = reordered(planar);
  expectMortonOrderOf(planar, after);
  EXPECT_TRUE(after.isPlanar());
  EXPECT_FALSE(after.hasColors());
}

TEST(PointOrder, farOffsetWithTinyExtentStillSeparatesClusters) {
  // Two clusters 1e-3 apart at 1e8 (float spacing there is 8, double's 1.5e-8), interleaved in
  // the input. Quantized relative to the box, they fall in different halves of every axis, so
  // the sorted sequence is one cluster then the other, and only the block holding the boundary
  // can mix them.
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> u(0.0, 1e-4);
  PointSet before;
  for (size_t i = 0; i < 4 * kOrderBlock + 300; ++i) {
    const double base = (i % 2) ? 1e8 + 1e-3 : 1e8;
    before.positions.push_back({base + u(rng), base + u(rng), base + u(rng)});
  }
  const PointSet after = reordered(before);
  expectMortonOrderOf(before, after);
  size_t mixed = 0;
  for (size_t first = 0; first < after.size(); first += kOrderBlock) {
    size_t far = 0, count = std::min(kOrderBlock, after.size() - first);
    for (size_t i = first; i < first + count; ++i) far += after.positions[i].x > 1e8 + 5e-4;
    mixed += far != 0 && far != count;
  }
  EXPECT_LE(mixed, 1u);
}

TEST(PointOrder, meshTrianglesFollowTheirVertices) {
  PointSet before = randomCloud(3 * kOrderBlock + 500, 8);
  std::mt19937_64 rng(9);
  for (size_t t = 0; t < 20000; ++t)
    for (int k = 0; k < 3; ++k) before.triangles.push_back(static_cast<uint32_t>(rng() % before.size()));
  const PointSet after = reordered(before);
  expectMortonOrderOf(before, after);
  ASSERT_EQ(after.triangles.size(), before.triangles.size());
  for (size_t i = 0; i < before.triangles.size(); ++i) {
    ASSERT_EQ(after.positions[after.triangles[i]], before.positions[before.triangles[i]]) << "corner " << i;
    ASSERT_EQ(after.colors[after.triangles[i]], before.colors[before.triangles[i]]) << "corner " << i;
  }
}

TEST(PointOrder, nonFiniteCoordinatesAreOrderedNotDropped) {
  PointSet before = randomCloud(kOrderBlock + 50, 10);
  before.positions[3].x = std::numeric_limits<double>::quiet_NaN();
  before.positions[40].y = std::numeric_limits<double>::infinity();
  before.positions[41].z = -std::numeric_limits<double>::infinity();
  expectMortonOrderOf(before, reordered(before));
}

// mortonRows, for points made from their index, gives the order reorderPoints gives the set
// holding them: row r is the point reorderPoints puts at r, colours (which tag the input index)
// included; for any thread count, sizes around the block, a 2D set, ties and non-finite values.
TEST(PointOrder, mortonRowsAreTheOrderReorderPointsGives) {
  std::vector<PointSet> sets;
  for (size_t n : {size_t{0}, size_t{1}, size_t{2}, size_t{33}, kOrderBlock, 3 * kOrderBlock + 17})
    sets.push_back(randomCloud(n, 20 + n));
  PointSet flat = randomCloud(2 * kOrderBlock + 5, 12);
  for (glm::dvec3& p : flat.positions) p.z = 0.0;
  sets.push_back(flat);
  PointSet odd = randomCloud(kOrderBlock + 300, 13);
  for (size_t i = 0; i < 200; ++i) odd.positions[100 + i] = odd.positions[7];  // ties
  odd.positions[3].x = std::numeric_limits<double>::quiet_NaN();
  odd.positions[40].y = -std::numeric_limits<double>::infinity();
  sets.push_back(odd);
  for (const PointSet& set : sets) {
    const PointSet expected = reordered(set);
    for (unsigned threads : {1u, 3u}) {
      SCOPED_TRACE(std::to_string(set.size()) + " points, " + std::to_string(threads) + " threads");
      const MortonRows rows =
          mortonRows(set.size(), [&set](uint64_t i) { return set.positions[i]; }, threads);
      ASSERT_EQ(rows.size(), set.size());
      for (size_t r = 0; r < set.size(); ++r) {
        ASSERT_LT(rows.source(r), set.size());
        ASSERT_EQ(rowOf(set, rows.source(r)), rowOf(expected, r)) << "row " << r;
      }
    }
  }
}

// At 2^20 points and more, the sort's top level runs over all threads: mortonRows still gives the
// rows reorderPoints gives, 3D and 2D, for 2 and 3 threads.
TEST(PointOrder, mortonRowsOfAMillionPointsAreTheOrderReorderPointsGives) {
  for (bool flat : {false, true}) {
    PointSet set = randomCloud((size_t{1} << 20) + 4321, flat ? 31 : 32);
    if (flat)
      for (glm::dvec3& p : set.positions) p.y = 0.0;
    const PointSet expected = reordered(set);
    for (unsigned threads : {2u, 3u}) {
      SCOPED_TRACE(std::string(flat ? "2D, " : "3D, ") + std::to_string(threads) + " threads");
      const MortonRows rows = mortonRows(set.size(), [&set](uint64_t i) { return set.positions[i]; }, threads);
      ASSERT_EQ(rows.size(), set.size());
      for (size_t r = 0; r < set.size(); ++r) ASSERT_EQ(rowOf(set, rows.source(r)), rowOf(expected, r)) << "row " << r;
    }
  }
}

TEST(PointOrder, moreThanAnOrderHoldsIsRefused) {
  EXPECT_TRUE(checkOrderable(4294967295u).ok());
  const Status refused = checkOrderable(4294967296u);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().code, ExitCode::kResourceLimit);
  EXPECT_NE(refused.error().message.find("4294967296"), std::string::npos);
}

}  // namespace
}  // namespace dpoint
