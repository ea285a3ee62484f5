// Sampled spacing (ops/point_spacing.h): the distances are the exact 4th-nearest on a grid, the
// samples depend on the points and not on their order or on how they are split into blocks, and
// a set too sparse for its box (or with one distinct position) gives none.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "ops/point_spacing.h"

namespace dpoint {
namespace {

// n × n points `step` apart in the z = 0 plane (z = 0.001·x when `tilt`, so the set is 3D).
PositionArray grid(int n, double step, bool tilt = false) {
  PositionArray points;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) points.push_back({i * step, j * step, tilt ? 0.001 * i * step : 0.0});
  return points;
}

TEST(PointSpacing, aGridsSpacingIsItsStep) {
  for (bool tilt : {false, true}) {
    const PositionArray points = grid(200, 0.25, tilt);
    const std::vector<SpacingSample> samples = sampleSpacing(points, boundingBox(points), 256);
    ASSERT_GE(samples.size(), 200u) << "tilt " << tilt;  // edge points too: their 4th nearest is a step away
    size_t at_step = 0;
    for (const SpacingSample& s : samples) at_step += std::abs(s.distance - 0.25) < 1e-3;
    EXPECT_GT(at_step, samples.size() * 9 / 10) << "tilt " << tilt;
  }
}

// The same grid at 1e200 and 1e-200 (and powers of two near them) has its step, scaled (the
// build before squared the distances as they were: infinite or 0 there, and found no spacing, so
// `render` drew 3000 random points at 4 px where it draws them at 46 at scale 1).
TEST(PointSpacing, aGridsSpacingHoldsAtAnyScale) {
  const PositionArray unit = grid(100, 0.25, true);
  for (double scale : {0x1p+664, 0x1p-664, 1e200, 1e-200}) {
    PositionArray points = unit;
    for (glm::dvec3& p : points) p *= scale;
    const std::vector<SpacingSample> samples = sampleSpacing(points, boundingBox(points), 256);
    ASSERT_GE(samples.size(), 200u) << scale;
    size_t at_step = 0;
    for (const SpacingSample& s : samples) at_step += std::abs(s.distance / scale - 0.25) < 1e-3;
    EXPECT_GT(at_step, samples.size() * 9 / 10) << scale;
  }
}

// Workers, not threads asked for: --threads 1000000 on a small set made a million per-worker lists
// (16 GB, then the kernel's OOM kill); the result does not depend on it.
TEST(PointSpacing, manyThreadsAskedMakeNoMoreWorkers) {
  const PositionArray points = grid(60, 1.0, true);
  const std::vector<SpacingSample> two = sampleSpacing(points, boundingBox(points), 256, 2);
  const std::vector<SpacingSample> many = sampleSpacing(points, boundingBox(points), 256, 1000000);
  ASSERT_EQ(many.size(), two.size());
  for (size_t k = 0; k < two.size(); ++k) EXPECT_EQ(many[k].distance, two[k].distance);
}

TEST(PointSpacing, samplesDoNotDependOnOrderOrBlocks) {
  PositionArray points = grid(120, 1.0);
  std::mt19937 random(7);
  for (glm::dvec3& p : points) p.z = std::uniform_real_distribution<double>(0.0, 0.5)(random);
  const Box box = boundingBox(points);
  const std::vector<SpacingSample> whole = sampleSpacing(points, box, 300, 1);
  PositionArray shuffled = points;
  std::shuffle(shuffled.begin(), shuffled.end(), random);
  // Two passes in blocks of 1000, as a streamed file is read, on two threads.
  SpacingSampler sampler(300, 2);
  for (size_t first = 0; first < shuffled.size(); first += 1000)
    sampler.add(std::span(shuffled).subspan(first, std::min<size_t>(1000, shuffled.size() - first)));
  SpacingSearch search(box, shuffled.size(), sampler.finish(), 2);
  for (size_t first = 0; first < shuffled.size(); first += 1000)
    search.add(std::span(shuffled).subspan(first, std::min<size_t>(1000, shuffled.size() - first)));
  const std::vector<SpacingSample> blocks = search.finish();
  ASSERT_EQ(whole.size(), blocks.size());
  ASSERT_GT(whole.size(), 150u);
  for (size_t k = 0; k < whole.size(); ++k) {
    EXPECT_EQ(whole[k].position, blocks[k].position) << k;
    EXPECT_EQ(whole[k].distance, blocks[k].distance) << k;
  }
}

// A set of many blocks (65,536 points each) on several threads, each keeping one heap over all the
// blocks it takes, in one call and in calls of uneven size: the samples of one thread in one call.
TEST(PointSpacing, samplesOfManyBlocksDoNotDependOnThreads) {
  PositionArray points(300'000);
  std::mt19937 random(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (glm::dvec3& p : points) p = {unit(random), unit(random), unit(random)};
  points.insert(points.end(), points.begin(), points.begin() + 70'000);  // copies, sampled once each
  SpacingSampler one(512, 1);
  one.add(points);
  const PositionArray expected = one.finish();
  ASSERT_GT(expected.size(), 256u);  // fewer than 512: a copy counts twice among the smallest
  for (unsigned threads : {2u, 3u, 5u}) {
    SpacingSampler together(512, threads), parts(512, threads);
    together.add(points);
    EXPECT_EQ(together.finish(), expected) << threads;
    for (size_t first = 0, size = 100'000; first < points.size(); first += size, size += 37'000)
      parts.add(std::span(points).subspan(first, std::min(size, points.size() - first)));
    EXPECT_EQ(parts.finish(), expected) << threads;
  }
}

// A streamed set's second pass reads only the batches whose box mayUse: the points of the rest lie
// in no kept cell, so the distances are those of every point; on a set in grid order most batches
// are passed over.
TEST(PointSpacing, batchesClearOfTheKeptCellsChangeNothing) {
  // A 320 × 320 grid in 32 × 32 tiles, one batch each (as Morton order keeps a batch compact).
  PositionArray points;
  std::mt19937 random(11);
  for (int ti = 0; ti < 10; ++ti)
    for (int tj = 0; tj < 10; ++tj)
      for (int i = 0; i < 32; ++i)
        for (int j = 0; j < 32; ++j)
          points.push_back({(ti * 32 + i) * 0.5, (tj * 32 + j) * 0.5, std::uniform_real_distribution<double>(0.0, 0.2)(random)});
  const Box box = boundingBox(points);
  const std::vector<SpacingSample> whole = sampleSpacing(points, box, 16, 2);
  SpacingSampler sampler(16, 2);
  sampler.add(points);
  SpacingSearch search(box, points.size(), sampler.finish(), 2);
  size_t read = 0;
  for (size_t first = 0; first < points.size(); first += 1024) {
    const std::span<const glm::dvec3> batch = std::span(points).subspan(first, std::min<size_t>(1024, points.size() - first));
    if (!search.mayUse(boundingBox(PositionArray(batch.begin(), batch.end())))) continue;
    search.add(batch);
    read += batch.size();
  }
  const std::vector<SpacingSample> selective = search.finish();
  ASSERT_EQ(whole.size(), selective.size());
  ASSERT_GT(whole.size(), 10u);
  for (size_t k = 0; k < whole.size(); ++k) EXPECT_EQ(whole[k].distance, selective[k].distance) << k;
  EXPECT_GT(read, 0u);
  EXPECT_LT(read, points.size() / 2);
  // A box beyond the grid, or far from every sample, needs nothing.
  EXPECT_FALSE(search.mayUse(Box{box.max + glm::dvec3(1.0), box.max + glm::dvec3(2.0)}));
}

TEST(PointSpacing, copiesOfAPointAreNotItsNeighbours) {
  PositionArray points = grid(50, 2.0);
  const PositionArray copies = points;
  points.insert(points.end(), copies.begin(), copies.end());  // every point twice
  const std::vector<SpacingSample> samples = sampleSpacing(points, boundingBox(points), 64);
  ASSERT_FALSE(samples.empty());
  for (const SpacingSample& s : samples) EXPECT_GE(s.distance, 2.0 - 1e-9);
}

TEST(PointSpacing, noSamplesWithoutTwoPositionsOrForAFewFarClusters) {
  EXPECT_TRUE(sampleSpacing(PositionArray(10, glm::dvec3(1, 2, 3)), Box{{1, 2, 3}, {1, 2, 3}}, 8).empty());
  EXPECT_TRUE(sampleSpacing({glm::dvec3(0.0)}, Box{}, 8).empty());
  // Two points at opposite corners of a huge box with 1000 copies each: the 4th nearest distinct
  // position is the other corner, far beyond a cell.
  PositionArray far;
  for (int i = 0; i < 4; ++i) far.push_back({0, 0, 0}), far.push_back({1e6, 1e6, 1e6});
  EXPECT_TRUE(sampleSpacing(far, boundingBox(far), 8).empty());
}

}  // namespace
}  // namespace dpoint
