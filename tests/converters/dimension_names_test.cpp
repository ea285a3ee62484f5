// Dimension names through every writer (core/dimensions.h, writableNames): a name a format cannot
// hold as it is, or that its readers would take for something else, is written under another
// name, said in a notice, and read back under that name with the same values. The build before
// wrote `property double my value` (a PLY no reader takes) and a CSV header `x,y,z,X` that its
// own reader refused, and renamed LAS and PCD fields without a word.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "converters/point_io.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::contains;
using test::TempDir;

TEST(DimensionNames, everyWriterNamesEachDimensionSoItsReaderTakesItBack) {
  const std::vector<std::string> names = {"red", "my value", "X", "a,b", "h\xc3\xb6he",
                                          "a_very_long_attribute_name_that_exceeds_32_chars_one",
                                          "a_very_long_attribute_name_that_exceeds_32_chars_two"};
  PointSet set;
  set.positions = {{0.5, 1.5, 2.5}, {3.5, 4.5, 5.5}};
  for (size_t k = 0; k < names.size(); ++k) {
    Dimension& d = set.dimensions.add(names[k], DimType::kF64, 2);
    d.set<double>(0, 10.0 * static_cast<double>(k)), d.set<double>(1, -0.25);
  }
  const std::vector<std::string> csv = {"red_2", "my_value", "X_2", "a_b", "h\xc3\xb6he", names[5], names[6]};
  const std::vector<std::string> ply = {"red_2", "my_value", "X", "a,b", "h\xc3\xb6he", names[5], names[6]};
  const std::vector<std::string> pcd = {"red", "my_value", "X", "a,b", "h\xc3\xb6he", names[5], names[6]};
  const std::vector<std::string> las = {"red_2", "my_value", "X", "a_b", "h__he", "a_very_long_attribute_name_that_",
                                        "a_very_long_attribute_name_tha_2"};
  const std::vector<std::pair<std::string, const std::vector<std::string>*>> cases = {
      {"n.csv", &csv}, {"n.xyz", &csv}, {"n.ply", &ply}, {"n.pcd", &pcd}, {"n.las", &las}, {"n.laz", &las}};
  TempDir dir;
  for (const auto& [file, want] : cases) {
    SCOPED_TRACE(file);
    std::vector<std::string> notices;
    WriteOptions options;
    options.notices = &notices;
    ASSERT_TRUE(writePoints(dir.file(file), set, options));
    size_t renamed = 0;
    for (size_t k = 0; k < names.size(); ++k)
      if ((*want)[k] != names[k]) {
        ++renamed;
        bool said = false;
        for (const std::string& n : notices) said = said || (contains(n, dir.file(file) + ": dimension '") && contains(n, "' written as '" + (*want)[k] + "'"));
        EXPECT_TRUE(said) << (*want)[k];
      }
    size_t notes_of_names = 0;
    for (const std::string& n : notices) notes_of_names += contains(n, ": dimension '");
    EXPECT_EQ(notes_of_names, renamed);
    Result<PointSet> back = readPoints(dir.file(file));
    ASSERT_TRUE(back) << back.error().message;
    for (size_t k = 0; k < names.size(); ++k) {
      const Dimension* d = back->dimensions.find((*want)[k]);
      ASSERT_TRUE(d) << (*want)[k];
      EXPECT_EQ(d->value(0), 10.0 * static_cast<double>(k)) << (*want)[k];
      EXPECT_EQ(d->value(1), -0.25) << (*want)[k];
    }
    EXPECT_FALSE(back->hasColors()) << "a dimension named red is not a colour";
  }
}

// The rule itself: bad characters, empty names, reserved names and repeats.
TEST(DimensionNames, writableNamesReplacesReservesAndNumbersRepeats) {
  std::vector<std::string> renamed;
  const std::vector<std::string> out = writableNames(
      {"a b", "a_b", "", "x", "x_2", "ok"}, isSpaceOrControl, [](const std::string& n, size_t) { return n == "x"; },
      &renamed);
  EXPECT_EQ(out, (std::vector<std::string>{"a_b", "a_b_2", "unnamed", "x_2", "x_2_2", "ok"}));
  ASSERT_EQ(renamed.size(), 5u);
  EXPECT_EQ(renamed[0], "dimension 'a b' written as 'a_b'");
}

}  // namespace
}  // namespace dpoint
