// render --color NAME's plans (issue #34): ASPRS classes, categories, and a ramp over the 1st to
// 99th percentile that a few extreme values do not stretch.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "ops/attribute_colors.h"
#include "ops/colormap.h"

namespace dpoint {
namespace {

Dimension column(const char* name, DimType type, const std::vector<double>& values) {
  Dimension d(name, type, values.size());
  for (size_t i = 0; i < values.size(); ++i) d.setValue(i, values[i]);
  return d;
}

TEST(AttributeColors, classificationTakesTheAsprsColoursAndNames) {
  const Dimension d = column("classification", DimType::kU8, {2, 6, 2, 9, 6});
  const AttributeColoring plan = planAttributeColoring(d);
  EXPECT_EQ(plan.kind, AttributeColoring::Kind::kClasses);
  EXPECT_EQ(plan.values, (std::vector<double>{2, 6, 9}));
  EXPECT_EQ(plan.colorOf(2), packRgb(139, 90, 43));  // ground
  EXPECT_EQ(plan.colorOf(6), packRgb(178, 34, 34));  // building
  const std::vector<LegendLine> lines = legendLines(plan);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0].label, "2 ground");
  EXPECT_EQ(lines[1].label, "6 building");
  EXPECT_EQ(lines[2].label, "9 water");
  EXPECT_EQ(legendLines(planAttributeColoring(column("classification", DimType::kU8, {64})))[0].label, "64 user class");
}

TEST(AttributeColors, aFewIntegerValuesAreCategoriesEachItsOwnColour) {
  const AttributeColoring plan = planAttributeColoring(column("return_number", DimType::kU8, {1, 2, 3, 1, 4}));
  EXPECT_EQ(plan.kind, AttributeColoring::Kind::kCategories);
  EXPECT_EQ(plan.values, (std::vector<double>{1, 2, 3, 4}));
  EXPECT_NE(plan.colorOf(1), plan.colorOf(2));
  EXPECT_EQ(plan.colorOf(3), categoryColor(2));
  // More than kMaxCategories values: a ramp.
  std::vector<double> many;
  for (int i = 0; i < 13; ++i) many.push_back(i);
  EXPECT_EQ(planAttributeColoring(column("user_data", DimType::kU8, many)).kind, AttributeColoring::Kind::kRamp);
}

TEST(AttributeColors, aRampSpansThe1stTo99thPercentileAndSkipsNan) {
  std::vector<double> values;
  for (int i = 0; i <= 1000; ++i) values.push_back(i);
  values[0] = -1e9;  // one outlier at each end does not stretch the ramp
  values[1000] = 1e9;
  values.push_back(std::numeric_limits<double>::quiet_NaN());
  const AttributeColoring plan = planAttributeColoring(column("gps_time", DimType::kF64, values));
  EXPECT_EQ(plan.kind, AttributeColoring::Kind::kRamp);
  EXPECT_EQ(plan.low, 10.0);
  EXPECT_EQ(plan.high, 990.0);
  EXPECT_EQ(plan.colorOf(plan.low), viridis(0.0));
  EXPECT_EQ(plan.colorOf(1e9), viridis(1.0));
  EXPECT_EQ(plan.colorOf(std::nan("")), viridis(0.0));
  // One value: a ramp of width 1 around it, not a division by zero.
  const AttributeColoring flat = planAttributeColoring(column("intensity", DimType::kF32, {5, 5, 5}));
  EXPECT_EQ(flat.low, 5.0);
  EXPECT_EQ(flat.high, 6.0);
}

TEST(AttributeColors, colorByAttributeWritesEachPointsColour) {
  const Dimension d = column("classification", DimType::kU8, {2, 6});
  const AttributeColoring plan = planAttributeColoring(d);
  std::vector<glm::vec3> colors(2);
  colorByAttribute(d, 0, 2, plan, colors.data());
  EXPECT_EQ(colors[0], glm::vec3(139, 90, 43) / 255.0f);
  EXPECT_EQ(colors[1], glm::vec3(178, 34, 34) / 255.0f);
}

}  // namespace
}  // namespace dpoint
