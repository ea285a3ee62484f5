// What generate does around any generator (generators/generate.h): colours, offset, tile signature.
#include "generators/generate.h"

#include <gtest/gtest.h>

namespace dpoint {
namespace {

PointSet threePoints() {
  PointSet points;
  points.positions = {{0.1, 0.2, 0.3}, {1.0, 2.0, 3.0}, {-1.0, 0.5, 0.25}};
  points.colors = {glm::vec3(1.0f), glm::vec3(0.5f), glm::vec3(0.0f)};
  return points;
}

TEST(Generate, colorsAreDroppedKeptOrNoiseWithinTheLimit) {
  PointSet none = threePoints();
  ASSERT_TRUE(colorGenerated(none, PointColoring{PointColors::kNone, true, 1, 0}).ok());
  EXPECT_FALSE(none.hasColors());
  PointSet kept = threePoints();
  ASSERT_TRUE(colorGenerated(kept, PointColoring{PointColors::kAuto, false, 1, 0}).ok());
  EXPECT_EQ(kept.colors, threePoints().colors);
  PointSet noise = threePoints();
  noise.colors.clear();
  ASSERT_TRUE(colorGenerated(noise, PointColoring{PointColors::kAuto, true, 1, 0}).ok());
  EXPECT_EQ(noise.colors.size(), 3u);
  PointSet over = threePoints();
  Status refused = colorGenerated(over, PointColoring{PointColors::kNoise, false, 1, 16});
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().code, ExitCode::kResourceLimit);
}

TEST(Generate, offsetIsOneExactSumAPoint) {
  PointSet points = threePoints();
  ASSERT_TRUE(offsetPoints(points, {1e9, -0.5, 0.0}));
  EXPECT_EQ(points.positions[0], glm::dvec3(0.1 + 1e9, 0.2 - 0.5, 0.3));
  EXPECT_EQ(points.positions[2], glm::dvec3(-1.0 + 1e9, 0.0, 0.25));
}

// A sum beyond double's range is refused, naming the point (the build before wrote "inf").
TEST(Generate, anOffsetBeyondDoublesRangeIsRefused) {
  PointSet points;
  points.positions = {{0, 0, 0}, {1e308, 0, 0}};
  const Status s = offsetPoints(points, {1e308, 0.0, 0.0});
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().code, ExitCode::kUsage);
  EXPECT_NE(s.error().message.find("point 1 moved by it leaves double's range"), std::string::npos) << s.error().message;
}

TEST(Generate, tileSignatureKeepsWhatShapesThePoints) {
  const std::string lines =
      "resolution=64\noutput=\"a.ply\"\ntile=\"0/2\"\nthreads=4\nmax-iter=100\n\ncolors=\"auto\"\nmesh=\"device\"\ncounts=\"full\"\n";
  EXPECT_EQ(tileSignature("mandelbulb", lines), "mandelbulb resolution=64 max-iter=100 colors=\"auto\"");
  EXPECT_NE(tileSignature("mandelbulb", lines), tileSignature("julia", lines));
}

}  // namespace
}  // namespace dpoint
