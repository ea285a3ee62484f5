#include <gtest/gtest.h>

#include <glm/vec2.hpp>

#include "converters/csv.h"
#include "generators/random2d.h"
#include "test_support.h"

namespace dpoint {
namespace {

TEST(Random2d, identicalForOneAndTwoThreads) {
  Random2dParams params;
  params.count = 300000;  // several chunks
  params.seed = 9;
  params.threads = 1;
  Result<PointSet> one = generateRandom2d(params);
  params.threads = 2;
  Result<PointSet> two = generateRandom2d(params);
  ASSERT_TRUE(one.ok() && two.ok());
  EXPECT_TRUE(one->positions == two->positions);
}

TEST(Random2d, matchesCommittedGoldenFile) {
  test::TempDir dir;
  Random2dParams params;
  params.count = 1000;
  params.seed = 42;
  Result<PointSet> points = generateRandom2d(params);
  ASSERT_TRUE(points.ok());
  ASSERT_TRUE(writeCsv(dir.file("a.csv"), *points).ok());
  EXPECT_TRUE(test::readFile(dir.file("a.csv")) == test::readFile(DPOINT_SAMPLES_DIR "/golden/random2d_n1000_s42.csv"));
}

TEST(Random2d, pointsAreInTheSquareAndPlanar) {
  Random2dParams params;
  params.count = 100000;
  Result<PointSet> points = generateRandom2d(params);
  ASSERT_TRUE(points.ok());
  EXPECT_TRUE(points->isPlanar());
  glm::dvec2 sum(0.0);
  for (const glm::dvec3& p : points->positions) {
    ASSERT_GE(p.x, -1.0);
    ASSERT_LT(p.x, 1.0);
    ASSERT_GE(p.y, -1.0);
    ASSERT_LT(p.y, 1.0);
    sum += glm::dvec2(p);
  }
  // Mean of 1e5 uniform samples: standard error 0.0018, so 0.01 is over five sigmas.
  EXPECT_NEAR(sum.x / 1e5, 0.0, 0.01);
  EXPECT_NEAR(sum.y / 1e5, 0.0, 0.01);
}

TEST(Random2d, seedsGiveDifferentSets) {
  Random2dParams params;
  params.count = 10;
  Result<PointSet> a = generateRandom2d(params);
  params.seed = 2;
  Result<PointSet> b = generateRandom2d(params);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_NE(a->positions, b->positions);
}

TEST(Random2d, refusesOverMemoryLimit) {
  Random2dParams params;
  params.count = 1000000;
  params.max_memory = 1000000;  // 1 MB for 24 MB of positions
  Result<PointSet> r = generateRandom2d(params);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ExitCode::kResourceLimit);
  EXPECT_NE(r.error().message.find("--max-memory"), std::string::npos) << r.error().message;
}

}  // namespace
}  // namespace dpoint
