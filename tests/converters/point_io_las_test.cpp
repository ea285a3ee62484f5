// LAS through converters/point_io: .las and .laz by name, and the colour sources a caller can ask
// of any input (converters/las.h has the LAS reader's own tests).
#include <gtest/gtest.h>

#include <filesystem>

#include "converters/point_io.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::TempDir;
using test::writeFile;

const std::string kCorpus = std::string(DPOINT_CORPUS_DIR) + "/las/";

TEST(PointIoLas, lasAndLazAreKnownByTheirExtension) {
  EXPECT_EQ(*formatOf("scan.LAS"), FileFormat::kLas);
  EXPECT_EQ(*formatOf("scan.laz"), FileFormat::kLaz);
  Result<PointSet> las = readPoints(kCorpus + "simple.las");
  ASSERT_TRUE(las.ok()) << las.error().message;
  EXPECT_EQ(las->size(), 1065u);
}

TEST(PointIoLas, lazIsReadAndWrittenLikeLas) {
  Result<PointSet> laz = readPoints(kCorpus + "simple.laz"), las = readPoints(kCorpus + "simple.las");
  ASSERT_TRUE(laz.ok()) << laz.error().message;
  ASSERT_TRUE(las.ok());
  EXPECT_EQ(laz->positions, las->positions);
  // Written as .laz and as .las, the same points, colours and fields come back; one point too.
  TempDir dir;
  PointSet one;
  one.positions = {{1.5, -2.25, 3e6}};
  for (const PointSet* set : {static_cast<const PointSet*>(&*las), static_cast<const PointSet*>(&one)}) {
    ASSERT_TRUE(writePoints(dir.file("out.laz"), *set).ok());
    ASSERT_TRUE(writePoints(dir.file("out.las"), *set).ok());
    Result<PointSet> from_laz = readPoints(dir.file("out.laz")), from_las = readPoints(dir.file("out.las"));
    ASSERT_TRUE(from_laz.ok()) << from_laz.error().message;
    ASSERT_TRUE(from_las.ok());
    EXPECT_EQ(from_laz->positions, set->positions);
    EXPECT_EQ(from_laz->positions, from_las->positions);
    EXPECT_EQ(from_laz->colors, from_las->colors);
    ASSERT_EQ(from_laz->dimensions.count(), from_las->dimensions.count());
    for (size_t d = 0; d < from_laz->dimensions.count(); ++d) {
      EXPECT_EQ(from_laz->dimensions.all()[d].name, from_las->dimensions.all()[d].name);
      EXPECT_EQ(from_laz->dimensions.all()[d].bytes, from_las->dimensions.all()[d].bytes);
    }
    // Compressed: well under the records' size for a real scan.
    if (set->size() > 1000) {
      EXPECT_LT(std::filesystem::file_size(dir.file("out.laz")) * 3 / 2, std::filesystem::file_size(dir.file("out.las")));
    }
  }
}

TEST(PointIoLas, lasFieldsAskedOfOtherFormatsAreErrorsNamingTheFile) {
  TempDir dir;
  writeFile(dir.file("a.csv"), "x,y,z\n1,2,3\n");
  ReadOptions read;
  read.las_color = LasColorSource::kIntensity;
  Result<PointSet> csv = readPoints(dir.file("a.csv"), read);
  ASSERT_FALSE(csv.ok());
  EXPECT_EQ(csv.error().message,
            dir.file("a.csv") + ": colour by intensity needs a LAS file; this file has no such field");
  read.las_color = LasColorSource::kClassification;
  EXPECT_FALSE(readPoints(dir.file("a.csv"), read).ok());
  read.las_color = LasColorSource::kRgb;
  csv = readPoints(dir.file("a.csv"), read);
  ASSERT_FALSE(csv.ok());
  EXPECT_EQ(csv.error().message, dir.file("a.csv") + ": colour by RGB asked for, but the file has no colours");
}

TEST(PointIoLas, noneDropsColoursOfAnyFormat) {
  TempDir dir;
  writeFile(dir.file("c.csv"), "x,y,z,r,g,b\n1,2,3,0.5,0.5,0.5\n");
  ReadOptions read;
  read.las_color = LasColorSource::kNone;
  for (const std::string& path : {dir.file("c.csv"), kCorpus + "simple.las"}) {
    Result<PointSet> points = readPoints(path, read);
    ASSERT_TRUE(points.ok()) << points.error().message;
    EXPECT_FALSE(points->hasColors()) << path;
  }
}

TEST(PointIoLas, writePointsStoresLasAtTheAskedScale) {
  TempDir dir;
  PointSet set;
  set.positions = {{0.5, 0.25, 0.125}, {2, 3, 4}};
  WriteOptions write;
  write.las_scale = 0.125;
  ASSERT_TRUE(writePoints(dir.file("s.las"), set, write).ok());
  Result<LasHeader> header = readLasHeader(dir.file("s.las"));
  ASSERT_TRUE(header.ok()) << header.error().message;
  EXPECT_EQ(header->scale, glm::dvec3(0.125));
  Result<PointSet> back = readPoints(dir.file("s.las"));
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->positions, set.positions);
}

}  // namespace
}  // namespace dpoint
