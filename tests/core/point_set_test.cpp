// The point set's helpers that writers lean on (core/point_set.h).
#include "core/point_set.h"

#include <gtest/gtest.h>

#include <cmath>

namespace dpoint {
namespace {

// Colours read as k / 255 or k / 65535 (float or double, rounded to float) are on their grid; a
// fraction between two steps is rounded, NaN and values outside 0..1 clamped, by a writer of integers.
TEST(PointSet, colorsOffGridCountsTheColoursAnIntegerWriterChanges) {
  ColorArray colors;
  for (int k = 0; k < 256; ++k) {
    colors.push_back(glm::vec3(static_cast<float>(k) / 255.0f, static_cast<float>(k / 255.0), 1.0f));
  }
  EXPECT_EQ(colorsOffGrid(colors, 255.0, 2).rounded + colorsOffGrid(colors, 255.0, 2).clamped, 0u);
  EXPECT_EQ(colorsOffGrid(colors, 65535.0, 2).rounded + colorsOffGrid(colors, 65535.0, 2).clamped, 0u);  // k / 255 is 257 k / 65535
  ColorArray words;
  for (int k = 0; k < 65536; k += 7) words.push_back(glm::vec3(static_cast<float>(k / 65535.0), 0.0f, 0.0f));
  EXPECT_EQ(colorsOffGrid(words, 65535.0, 2).rounded, 0u);
  EXPECT_GT(colorsOffGrid(words, 255.0, 2).rounded, words.size() * 9 / 10);
  ColorArray odd = {glm::vec3(0.5f, 0.0f, 0.0f), glm::vec3(0.0f, std::nanf(""), 0.0f), glm::vec3(0.0f, 0.0f, 1.5f),
                    glm::vec3(-0.25f, 0.0f, 0.0f), glm::vec3(0.2f, 0.4f, 0.6f)};
  for (double full : {255.0, 65535.0}) {
    EXPECT_EQ(colorsOffGrid(odd, full, 1).rounded, 1u);  // 0.5; 0.2, 0.4, 0.6 are 51, 102, 153
    EXPECT_EQ(colorsOffGrid(odd, full, 1).clamped, 3u);  // NaN, 1.5, -0.25
  }
  EXPECT_EQ(colorsOffGrid(ColorArray(), 255.0, 0).rounded, 0u);
  // Many blocks on several threads count as one.
  ColorArray many(1000000, glm::vec3(0.0f));
  for (size_t i = 0; i < many.size(); i += 1000) many[i].g = 0.3f;
  EXPECT_EQ(colorsOffGrid(many, 255.0, 4).rounded, 1000u);
}

// Float colours of whole numbers above 1 are 0..255 or 0..65535 values; fractions, HDR values among
// fractions, numbers between integers, a negative or NaN channel, or past 65535 are not.
TEST(PointSet, wholeColorScaleTellsIntegerColoursWrittenAsFloats) {
  EXPECT_EQ(wholeColorScale(ColorArray{glm::vec3(255.0f, 128.0f, 0.0f), glm::vec3(1.0f, 0.0f, 12.0f)}, 1).full, 255);
  EXPECT_EQ(wholeColorScale(ColorArray{glm::vec3(2.0f, 0.0f, 0.0f)}, 1).full, 255);
  EXPECT_EQ(wholeColorScale(ColorArray{glm::vec3(256.0f, 0.0f, 65535.0f)}, 1).full, 65535);
  EXPECT_EQ(wholeColorScale(ColorArray{glm::vec3(1.0f, 0.0f, 1.0f), glm::vec3(0.5f, 0.25f, 0.0f)}, 1).full, 0);
  EXPECT_EQ(wholeColorScale(ColorArray{glm::vec3(1.0f, 1.0f, 1.0f)}, 1).full, 0);  // 0/1 fractions
  EXPECT_EQ(wholeColorScale(ColorArray{glm::vec3(1.2f, 0.5f, 0.0f)}, 1).full, 0);
  EXPECT_EQ(wholeColorScale(ColorArray{glm::vec3(127.5f, 0.0f, 0.0f)}, 1).full, 0);
  EXPECT_EQ(wholeColorScale(ColorArray{glm::vec3(255.0f, -1.0f, 0.0f)}, 1).full, 0);
  EXPECT_EQ(wholeColorScale(ColorArray{glm::vec3(255.0f, std::nanf(""), 0.0f)}, 1).full, 0);
  EXPECT_EQ(wholeColorScale(ColorArray{glm::vec3(65536.0f, 0.0f, 0.0f)}, 1).full, 0);
  EXPECT_EQ(wholeColorScale(ColorArray(), 1).full, 0);
  // Over many blocks and threads: one channel decides.
  ColorArray many(1000000, glm::vec3(0.0f));
  many[999999].r = 300.0f;
  EXPECT_EQ(wholeColorScale(many, 4).full, 65535);
  many[5].b = 0.5f;
  EXPECT_EQ(wholeColorScale(many, 4).full, 0);
  EXPECT_EQ(wholeColorScale(many, 4).odd, 5u);  // one fraction beside whole values above 1: said
  // Whole numbers above 1 but for one channel no integer scale holds: that colour, named.
  ColorArray bytes(200, glm::vec3(255.0f, 3.0f, 0.0f));
  bytes[101] = glm::vec3(255.0f, -1.0f, 0.0f);
  bytes[150] = glm::vec3(0.5f, 0.0f, 0.0f);
  EXPECT_EQ(wholeColorScale(bytes, 1).odd, 101u);
  bytes[120].g = 2.5f;  // 3 odd ones in 200: more than 1%, no longer a few
  EXPECT_EQ(wholeColorScale(bytes, 1).odd, UINT64_MAX);
  EXPECT_EQ(wholeColorScale(ColorArray{glm::vec3(127.5f, 0.0f, 0.0f)}, 1).odd, UINT64_MAX);  // no whole one above 1
  EXPECT_EQ(wholeColorScale(ColorArray{glm::vec3(0.5f, 1.0f, 0.0f), glm::vec3(1.5f, 0.0f, 0.0f)}, 1).odd, UINT64_MAX);
  // HDR values with a whole one above 1 among them are not 0..255 values with an odd one (a review finding).
  EXPECT_EQ(wholeColorScale(ColorArray{glm::vec3(0.5f, 0.25f, 0.125f), glm::vec3(2.0f, 1.0f, 1.0f), glm::vec3(1.5f, 0.5f, 0.5f)}, 1).odd,
            UINT64_MAX);
  many[5].b = 0.0f;
  many[700000].g = 70000.0f;
  many[900000].g = -2.0f;
  EXPECT_EQ(wholeColorScale(many, 4).full, 0);
  EXPECT_EQ(wholeColorScale(many, 4).odd, 700000u);
}

// Sets joined (several inputs, a PTX file's scans): colours white for a set without beside one with,
// dimensions the union, a type that holds the other's values kept, else float64 for both (a
// review found a PTX's 0..1 intensities read after a LAS file's uint16 ones became 0 and 1).
TEST(PointSet, appendPointsJoinsColoursAndWidensADimensionOnlyWhereItMust) {
  PointSet out, bytes, fractions;
  out.positions = {{1, 2, 3}};
  out.dimensions.add("intensity", DimType::kU16, 1).setValue(0, 700.0);
  bytes.positions = {{4, 5, 6}};
  bytes.colors = {glm::vec3(0.5f)};
  bytes.dimensions.add("intensity", DimType::kU8, 1).setValue(0, 7.0);
  appendPoints(out, bytes);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out.colors, (ColorArray{glm::vec3(1.0f), glm::vec3(0.5f)}));
  EXPECT_EQ(out.dimensions.find("intensity")->type, DimType::kU16);  // holds every uint8
  fractions.positions = {{7, 8, 9}};
  fractions.dimensions.add("intensity", DimType::kF64, 1).setValue(0, 0.25);
  fractions.dimensions.add("gps_time", DimType::kF64, 1).setValue(0, 12.5);
  appendPoints(out, fractions);
  const Dimension* intensity = out.dimensions.find("intensity");
  EXPECT_EQ(intensity->type, DimType::kF64);
  EXPECT_EQ(intensity->value(0), 700.0);
  EXPECT_EQ(intensity->value(1), 7.0);
  EXPECT_EQ(intensity->value(2), 0.25);
  EXPECT_EQ(out.dimensions.find("gps_time")->value(0), 0.0);
  EXPECT_EQ(out.dimensions.find("gps_time")->value(2), 12.5);
  EXPECT_EQ(out.colors.back(), glm::vec3(1.0f));
}

// A stream's block shaped again as the same columns keeps their memory (and the values in the
// part both sizes share); other columns replace them.
TEST(PointSet, shapeUnsetKeepsTheColumnsInPlaceWhereTheyAreTheSame) {
  const Dimension intensity("intensity", DimType::kU16), time("gps_time", DimType::kF64);
  Dimensions d;
  d.shapeUnset({&intensity, &time}, 1000);
  ASSERT_EQ(d.count(), 2u);
  EXPECT_EQ(d.all()[0].name, "intensity");
  EXPECT_EQ(d.all()[1].type, DimType::kF64);
  EXPECT_EQ(d.all()[1].size(), 1000u);
  d.all()[1].set<double>(3, 2.5);
  const uint8_t* kept = d.all()[1].bytes.data();
  d.shapeUnset({&intensity, &time}, 500);
  d.shapeUnset({&intensity, &time}, 1000);
  EXPECT_EQ(d.all()[1].bytes.data(), kept);
  EXPECT_EQ(d.all()[1].get<double>(3), 2.5);
  const Dimension time32("gps_time", DimType::kF32);
  d.shapeUnset({&intensity, &time32}, 10);  // another type: new columns
  EXPECT_EQ(d.all()[1].type, DimType::kF32);
  EXPECT_EQ(d.all()[1].size(), 10u);
  d.shapeUnset({}, 10);
  EXPECT_TRUE(d.empty());
}

// The box of the finite coordinates, axis by axis, past one block (65,536 points) on several
// threads: a nan or inf on one axis leaves the others' bounds and is said.
TEST(PointSet, finiteBoxSkipsNonFiniteCoordinatesAxisByAxis) {
  PositionArray positions;
  for (int i = 0; i < 200000; ++i) positions.push_back({i * 0.5, -i, 7.0});
  positions[150000] = {NAN, 1e9, INFINITY};
  bool nonfinite = false;
  Box box = finiteBox(positions, 0, positions.size(), 4, &nonfinite);
  EXPECT_TRUE(nonfinite);
  EXPECT_EQ(box.min, glm::dvec3(0.0, -199999.0, 7.0));
  EXPECT_EQ(box.max, glm::dvec3(199999 * 0.5, 1e9, 7.0));
  // A range without it; and a range where one axis has no finite coordinate.
  box = finiteBox(positions, 10, 20, 0, &nonfinite);
  EXPECT_FALSE(nonfinite);
  EXPECT_EQ(box.min, glm::dvec3(5.0, -19.0, 7.0));
  EXPECT_EQ(box.max, glm::dvec3(9.5, -10.0, 7.0));
  box = finiteBox(positions, 150000, 150001, 1, &nonfinite);
  EXPECT_TRUE(nonfinite);
  EXPECT_TRUE(std::isinf(box.min.x) && box.min.x > 0 && std::isinf(box.max.z) && box.max.z < 0);
  EXPECT_EQ(box.min.y, 1e9);
  // An empty range: no bounds on any axis.
  box = finiteBox(positions, 5, 5, 0);
  EXPECT_GT(box.min.x, box.max.x);
}

}  // namespace
}  // namespace dpoint
