#include <gtest/gtest.h>

#include <cmath>

#include "core/info.h"

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

TEST(Info, nearestNeighbourSkipsDuplicatesAndFindsTinySpacing) {
  PointSet s;
  for (int k = 0; k < 5000; ++k) s.positions.emplace_back(std::cos(k) * 10.0, std::sin(k) * 10.0, k * 1e-3);
  s.positions.push_back(s.positions[0]);  // a duplicate: distance 0 does not count
  s.positions.emplace_back(0.0, 0.0, 0.0);
  s.positions.emplace_back(1e-40, 0.0, 0.0);  // float32 has no normal number this small
  const PointSetInfo i = computeInfo(s, s.size());
  EXPECT_EQ(i.min_neighbor_distance, 1e-40);
}

TEST(Info, overflowBeyondFloatRange) {
  PointSet s;
  s.positions = {{1e39, 0, 0}, {0, 0, 0}};
  const PointSetInfo i = computeInfo(s);
  EXPECT_EQ(i.float_overflow, 1u);
  EXPECT_FALSE(i.floatRepresents());
  EXPECT_TRUE(std::isinf(i.float_spacing));
}

TEST(Info, emptySetHasZeroCount) {
  const PointSetInfo i = computeInfo(PointSet{});
  EXPECT_EQ(i.count, 0u);
  EXPECT_EQ(i.neighbor_sample, 0u);
}

}  // namespace
}  // namespace dpoint
