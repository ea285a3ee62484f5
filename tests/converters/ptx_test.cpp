// Leica PTX files (converters/ptx_read.cpp): scans of a ten-line header and rows in the scanner's
// frame, read into the registered frame, the points with no echo left out.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "converters/csv.h"
#include "core/dimensions.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::TempDir;
using test::writeFile;

// A scan's header: columns, rows, the scanner's pose (unused by the reader) and the transformation
// in PTX's row-vector form, its fourth row the translation.
std::string header(int columns, int rows, const std::string& translation = "0 0 0",
                   const std::string& rotation = "1 0 0 0\n0 1 0 0\n0 0 1 0\n") {
  return std::to_string(columns) + "\n" + std::to_string(rows) + "\n" + translation + "\n1 0 0\n0 1 0\n0 0 1\n" + rotation +
         translation + " 1\n";
}

Result<PointSet> readText(const TempDir& dir, const std::string& text, std::vector<std::string>* notices = nullptr,
                          unsigned threads = 0) {
  const std::string path = dir.file("scan.ptx");
  writeFile(path, text);
  CsvReadOptions options;
  options.notices = notices;
  options.threads = threads;
  return readCsv(path, options);
}

TEST(Ptx, readsAScanIntoItsRegisteredFrameLeavingOutPointsWithNoEcho) {
  TempDir dir;
  const double tx = 558312.218127, ty = 5240857.469093, tz = 76.298415;
  const std::string text = header(2, 2, "558312.218127 5240857.469093 76.298415") +
                           "0 0 0 0.500000 0 0 0\n"
                           "12.032272 -2.613480 -2.036392 0.159304 168 183 142\n"
                           "12.860123 -2.793289 -2.162979 0.183719 118 121 94\n"
                           "0 0 0 0.5 0 0 0\n";
  std::vector<std::string> notices;
  Result<PointSet> points = readText(dir, text, &notices);
  ASSERT_TRUE(points.ok()) << points.error().message;
  ASSERT_EQ(points->size(), 2u);
  // A translation alone: x + tx, rounded once, as double adds them.
  EXPECT_EQ(points->positions[0], glm::dvec3(12.032272 + tx, -2.613480 + ty, -2.036392 + tz));
  EXPECT_EQ(points->positions[1], glm::dvec3(12.860123 + tx, -2.793289 + ty, -2.162979 + tz));
  EXPECT_TRUE(points->hasZ());
  ASSERT_TRUE(points->hasColors());
  EXPECT_EQ(points->color_full_scale, 255);
  EXPECT_EQ(points->colors[0], glm::vec3(168.0f, 183.0f, 142.0f) / 255.0f);
  const Dimension* intensity = points->dimensions.find(dim::kIntensity);
  ASSERT_NE(intensity, nullptr);
  EXPECT_EQ(intensity->value(0), 0.159304);
  EXPECT_EQ(intensity->value(1), 0.183719);
  EXPECT_EQ(points->dimensions.find(dim::kPointSourceId), nullptr);  // one scan
  ASSERT_EQ(notices.size(), 1u);
  EXPECT_NE(notices[0].find("2 of its 4 rows are points with no echo"), std::string::npos) << notices[0];
}

TEST(Ptx, appliesTheRotationAsARowVectorTimesTheMatrix) {
  TempDir dir;
  // The transformation of rapidlasso's sample.ptx; CloudCompare reads its first point as
  // (2.15576, 10.5531, 2.68531) (tests/external/cloudcompare_reads_ptx.py compares every point).
  const std::string text = header(1, 2, "3.847211 12.235314 -0.425777",
                                  "-0.955179 0.296021 -0.002106 0.000000\n"
                                  "-0.296023 -0.955180 0.001152 0.000000\n"
                                  "-0.001670 0.001724 0.999997 0.000000\n") +
                           "1.111111 2.111111 3.111 0.111\r\n"
                           "1.222222 2.222222 3.222 0.212\r\n";
  Result<PointSet> points = readText(dir, text);
  ASSERT_TRUE(points.ok()) << points.error().message;
  ASSERT_EQ(points->size(), 2u);
  const glm::dvec3 p = points->positions[0];
  EXPECT_EQ(p.x, 1.111111 * -0.955179 + 2.111111 * -0.296023 + 3.111 * -0.001670 + 3.847211);
  EXPECT_EQ(p.y, 1.111111 * 0.296021 + 2.111111 * -0.955180 + 3.111 * 0.001724 + 12.235314);
  EXPECT_NEAR(p.x, 2.15576, 1e-5);
  EXPECT_NEAR(p.y, 10.5531, 1e-4);
  EXPECT_NEAR(p.z, 2.68531, 1e-5);
  EXPECT_FALSE(points->hasColors());
}

TEST(Ptx, joinsScansTellingThemApartByPointSourceId) {
  TempDir dir;
  const std::string text = header(1, 2, "100 0 0") + "1 2 3 0.25\n4 5 6 1\n" + "\n" +  // a blank line between scans
                           header(1, 1, "0 100 0") + "7 8 9 1 255 0 0\n" + header(0, 0) + "\n\n";
  std::vector<std::string> notices;
  Result<PointSet> points = readText(dir, text, &notices);
  ASSERT_TRUE(points.ok()) << points.error().message;
  ASSERT_EQ(points->size(), 3u);
  EXPECT_EQ(points->positions[0], glm::dvec3(101, 2, 3));
  EXPECT_EQ(points->positions[2], glm::dvec3(7, 108, 9));
  const Dimension* source = points->dimensions.find(dim::kPointSourceId);
  ASSERT_NE(source, nullptr);
  EXPECT_EQ(source->type, DimType::kU16);
  EXPECT_EQ(source->value(0), 1.0);
  EXPECT_EQ(source->value(1), 1.0);
  EXPECT_EQ(source->value(2), 2.0);
  // The first scan's intensities are 0.25 and 1, the second's a whole 1: float64 in both.
  const Dimension* intensity = points->dimensions.find(dim::kIntensity);
  ASSERT_NE(intensity, nullptr);
  EXPECT_EQ(intensity->type, DimType::kF64);
  EXPECT_EQ(intensity->value(0), 0.25);
  EXPECT_EQ(intensity->value(2), 1.0);
  // The scan without colours is white beside the one with.
  ASSERT_TRUE(points->hasColors());
  EXPECT_EQ(points->colors[0], glm::vec3(1.0f));
  EXPECT_EQ(points->colors[2], glm::vec3(1.0f, 0.0f, 0.0f));
  EXPECT_EQ(points->color_full_scale, 255);
  EXPECT_TRUE(notices.empty());

  // Colours are 0..255 values in every scan, dark ones too (the CSV reader's rule took 0 1 1 as
  // fractions in a scan without a value above 1, and 256 as a 16-bit scale: a review finding).
  Result<PointSet> dark = readText(dir, header(1, 1) + "1 2 3 0.5 0 1 1\n" + header(1, 1) + "1 2 3 0.5 10 20 30\n");
  ASSERT_TRUE(dark.ok()) << dark.error().message;
  EXPECT_EQ(dark->colors[0], glm::vec3(0.0f, 1.0f, 1.0f) / 255.0f);  // as takeColorsAsIntegers scales
  EXPECT_EQ(dark->colors[1], glm::vec3(10.0f, 20.0f, 30.0f) / 255.0f);
  EXPECT_EQ(dark->color_full_scale, 255);
}

TEST(Ptx, placesScansPastTheLineIndexsBlocksAlikeForAnyThreadCount) {
  TempDir dir;
  // 2 x 400,000 rows of about 25 bytes: the second scan's header lies past the index's first 8 MiB.
  std::string text;
  for (int scan = 0; scan < 2; ++scan) {
    text += header(400, 1000, scan == 0 ? "0 0 0" : "1000 0 0");
    for (int i = 0; i < 400000; ++i)
      text += i % 7 == 3 ? "0 0 0 0\n" : std::to_string(i) + ".5 " + std::to_string(scan) + " -1.25 0.5\n";
  }
  Result<PointSet> one = readText(dir, text, nullptr, 1);
  ASSERT_TRUE(one.ok()) << one.error().message;
  Result<PointSet> four = readText(dir, text, nullptr, 4);
  ASSERT_TRUE(four.ok()) << four.error().message;
  const size_t kept = 400000 - 400000 / 7 - (400000 % 7 > 3 ? 1 : 0);
  ASSERT_EQ(one->size(), 2 * kept);
  EXPECT_EQ(one->positions, four->positions);
  EXPECT_EQ(one->positions[kept - 1], glm::dvec3(399999.5, 0, -1.25));
  EXPECT_EQ(one->positions[kept], glm::dvec3(1000.5, 1, -1.25));
  EXPECT_EQ(one->positions.back(), glm::dvec3(400999.5, 1, -1.25));
  EXPECT_EQ(one->dimensions.find(dim::kPointSourceId)->value(kept), 2.0);
}

// Scans are numbered as the file has them, empty ones too (as CloudCompare counts them); many
// small scans read in one pass over the file (a review found 65,535 one-point scans took 2 min);
// a byte order mark is passed over; the limit on memory is the whole file's, not each scan's.
TEST(Ptx, numbersEveryScanAndKeepsTheWholeFileToTheMemoryLimit) {
  TempDir dir;
  std::string text = "\xEF\xBB\xBF" + header(0, 0);
  for (int scan = 0; scan < 20000; ++scan) text += header(1, 1, std::to_string(scan) + " 0 0") + "1 2 3 0.5\n";
  Result<PointSet> points = readText(dir, text);
  ASSERT_TRUE(points.ok()) << points.error().message;
  ASSERT_EQ(points->size(), 20000u);
  EXPECT_EQ(points->positions[19999], glm::dvec3(20000, 2, 3));
  const Dimension* source = points->dimensions.find(dim::kPointSourceId);
  ASSERT_NE(source, nullptr);
  EXPECT_EQ(source->value(0), 2.0);  // the empty scan before it is scan 1
  EXPECT_EQ(source->value(19999), 20001.0);

  // Two scans of 1,000 rows, each within a limit of 40 KB (1,000 x 32 bytes, and 1 KiB a scan), together not.
  std::string two;
  for (int scan = 0; scan < 2; ++scan) {
    two += header(10, 100);
    for (int i = 0; i < 1000; ++i) two += "1 2 3 0.5\n";
  }
  writeFile(dir.file("two.ptx"), two);
  CsvReadOptions limited;
  limited.max_memory = 40000;
  Result<PointSet> refused = readCsv(dir.file("two.ptx"), limited);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().code, ExitCode::kResourceLimit);
  EXPECT_NE(refused.error().message.find("2000 rows of 2 scans"), std::string::npos) << refused.error().message;
  limited.max_memory = 70000;
  EXPECT_TRUE(readCsv(dir.file("two.ptx"), limited).ok());
}

TEST(Ptx, badFilesAreRefusedNamingTheLine) {
  TempDir dir;
  const auto error = [&](const std::string& text) {
    Result<PointSet> points = readText(dir, text);
    return points.ok() ? std::string("(read)") : points.error().message;
  };
  EXPECT_NE(error(header(3, 3) + "1 2 3 0.5\n1 2 3 0.5\n").find("scan.ptx:1: scan 1 (line 1) declares 3 x 3 = 9 points, "
                                                                "but the file has 2 lines after its header (cut short?)"),
            std::string::npos)
      << error(header(3, 3) + "1 2 3 0.5\n");
  EXPECT_NE(error("3\nthree\n").find("scan.ptx:2: not a whole number"), std::string::npos) << error("3\nthree\n");
  EXPECT_NE(error(header(1, 1, "0 0 0", "1 0 0 0\n0 1 0 0\n0 0 1 0.5\n") + "1 2 3 4\n").find("scan.ptx:9: its fourth number must be 0"),
            std::string::npos);
  EXPECT_NE(error("2\n1\n0 0 0\n1 0 0\n").find("scan.ptx:5: the file ends inside a scan's header"), std::string::npos)
      << error("2\n1\n0 0 0\n1 0 0\n");
  // A row's bad number: its line in the file, past the header and the first scan.
  const std::string two = header(1, 1) + "1 2 3 0.5\n" + header(1, 2) + "1 2 3 0.5\n1 2 x 0.5\n";
  EXPECT_NE(error(two).find("scan.ptx:23:"), std::string::npos) << error(two);
  EXPECT_NE(error(header(1, 1) + "1 2 3 0.5 9\n").find("scan.ptx:11: 5 fields, where a PTX row has"), std::string::npos)
      << error(header(1, 1) + "1 2 3 0.5 9\n");
  // Every line of a scan is a row: a blank or comment line among them is named (the CSV reader
  // passes them over, and the next scan's header would be read from the wrong line).
  EXPECT_NE(error(header(1, 2) + "1 2 3 0.5\n# a comment\n").find("scan.ptx:12: a comment line where every line is a row"),
            std::string::npos)
      << error(header(1, 2) + "1 2 3 0.5\n# a comment\n");
  EXPECT_NE(error(header(1, 2) + "\n1 2 3 0.5\n").find("scan.ptx:11: a blank line where every line is a row"),
            std::string::npos)
      << error(header(1, 2) + "\n1 2 3 0.5\n");
  // A bad first row is that row's error, not taken for a header line (a review finding).
  const std::string first = header(1, 1) + "1 2 3 0.5\n" + header(1, 2) + "abc 2 3 0.5\n1 2 3 0.5\n";
  EXPECT_NE(error(first).find("scan.ptx:22: column 1: 'abc'"), std::string::npos) << error(first);
  // A first row unlike the next two is the one blamed; a second unlike the first and third, the second.
  const std::string first_odd = header(1, 3) + "1 2 3\n1 2 3 0.5\n1 2 3 0.5\n";
  EXPECT_NE(error(first_odd).find("scan.ptx:11: 3 fields, where the scan's next rows have 4"), std::string::npos)
      << error(first_odd);
  const std::string second_odd = header(1, 3) + "1 2 3 0.5\n1 2 3\n1 2 3 0.5\n";
  EXPECT_NE(error(second_odd).find("scan.ptx:12:"), std::string::npos) << error(second_odd);
  // Row errors say which scan, and how many rows it declares (a scan cut short fails at the next header).
  const std::string short_scan = header(1, 3) + "1 2 3 0.5\n1 2 3 0.5\n" + header(1, 1) + "1 2 3 0.5\n";
  EXPECT_NE(error(short_scan).find("scan.ptx:13:"), std::string::npos) << error(short_scan);
  EXPECT_NE(error(short_scan).find("(in scan 1 (line 1), which declares 1 x 3 rows)"), std::string::npos) << error(short_scan);
  // Colours are 0..255 values whatever a scan holds; another is named by its line.
  const std::string colour = header(1, 2) + "1 2 3 0.5 1 2 3\n1 2 3 0.5 10.5 0 0\n";
  EXPECT_NE(error(colour).find("scan.ptx:12: colour column 1: 10.5 (a colour here is a whole number of 0 to 255)"),
            std::string::npos)
      << error(colour);
  EXPECT_NE(error(header(1, 1) + "1 2 3 0.5 256 0 0\n").find("scan.ptx:11: colour column 1: 256"), std::string::npos);
  // Lines that end in CR alone are said to.
  EXPECT_NE(error("1\r1\r0 0 0\r").find("carriage returns inside a line"), std::string::npos) << error("1\r1\r0 0 0\r");
  EXPECT_NE(error("").find("empty file"), std::string::npos);
  EXPECT_NE(error("\n\n").find("no scan"), std::string::npos) << error("\n\n");

  // Scans of no rows are an empty set, as an empty LAS file is.
  Result<PointSet> empty = readText(dir, header(0, 5) + header(3, 0));
  ASSERT_TRUE(empty.ok()) << empty.error().message;
  EXPECT_EQ(empty->size(), 0u);

  CsvReadOptions columns;
  columns.columns = {"x", "y", "z"};
  writeFile(dir.file("c.ptx"), header(1, 1) + "1 2 3\n");
  Result<PointSet> refused = readCsv(dir.file("c.ptx"), columns);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().code, ExitCode::kUsage);
}

// Written (writeCsv to .ptx): one scan whose translation is each axis's centre in whole units
// where every coordinate less it and added back is itself (else 0), its rows shortest round trip,
// an intensity of 0 where the set has none; read back to the same doubles. A point at the scan's
// origin is a row of 0 0 0, which a reader takes for no echo: said, as it is lost.
TEST(Ptx, writesOneScanAboutAWholeTranslationThatReadsBackExactly) {
  TempDir dir;
  PointSet far;
  far.positions = {{0.0, 0.0, 0.0}, {1e6, 2e6 + 0.125, -1e6}, {1e6 + 0.1, 2e6, -1e6 - 0.3}};
  std::vector<std::string> notices;
  CsvWriteOptions options;
  options.notices = &notices;
  ASSERT_TRUE(writeCsv(dir.file("far.ptx"), far, options).ok());
  const std::string text = test::readFile(dir.file("far.ptx"));
  EXPECT_EQ(text, header(3, 1, "500000 1000000 -500000") +
                      "-5e+05 -1e+06 5e+05 0\n5e+05 1000000.125 -5e+05 0\n500000.1 1e+06 -500000.30000000005 0\n");
  Result<PointSet> back = readText(dir, text);
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->positions, far.positions);  // the world's origin too: it is not the scan's
  ASSERT_EQ(notices.size(), 1u);
  EXPECT_NE(notices[0].find("far.ptx: the set has no intensity: each row's is 0"), std::string::npos) << notices[0];

  // Coordinates that a whole offset would not give back (0.1 - 1 + 1 is not 0.1): no translation
  // on that axis, and the point at the origin said to be lost.
  PointSet near;
  near.positions = {{0.0, 0.0, 0.0}, {0.1, 0.2, 0.3}, {2.0, 3.0, 4.0}};
  near.dimensions.add(dim::kIntensity, DimType::kF32, 3);
  near.dimensions.find(dim::kIntensity)->set<float>(1, 0.25f);
  notices.clear();
  ASSERT_TRUE(writeCsv(dir.file("near.ptx"), near, options).ok());
  EXPECT_TRUE(test::readFile(dir.file("near.ptx")).starts_with(header(3, 1))) << test::readFile(dir.file("near.ptx"));
  ASSERT_EQ(notices.size(), 1u);
  EXPECT_NE(notices[0].find("near.ptx: 1 point at the scan's origin (0, 0, 0) written as 0 0 0"), std::string::npos)
      << notices[0];
  back = readText(dir, test::readFile(dir.file("near.ptx")));
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->positions, PositionArray(near.positions.begin() + 1, near.positions.end()));
  EXPECT_EQ(back->dimensions.find(dim::kIntensity)->value(0), 0.25);
}

// A set of several scans (point_source_id in runs, as a PTX or E57 file of several scans reads) is
// written as those scans, each about its own translation, and read back with the same ids; ids
// other than 1, 2, … are said to be renumbered; ids whose points are not together make one scan.
TEST(Ptx, writesAScanForEachPointSourceIdWhosePointsLieTogether) {
  TempDir dir;
  PointSet scans;
  scans.positions = {{1000.5, 2000.25, 3.0}, {1001.0, 2000.0, 3.5}, {-50.0, 7.0, 1.0}, {-49.0, 8.0, 1.0}, {-51.0, 9.0, 2.0}};
  Dimension& ids = scans.dimensions.add(dim::kPointSourceId, DimType::kU16, 5);
  for (size_t i = 0; i < 5; ++i) ids.setValue(i, i < 2 ? 1.0 : 2.0);
  std::vector<std::string> notices;
  CsvWriteOptions options;
  options.notices = &notices;
  ASSERT_TRUE(writeCsv(dir.file("two.ptx"), scans, options).ok());
  const std::string text = test::readFile(dir.file("two.ptx"));
  EXPECT_TRUE(text.starts_with(header(2, 1, "1001 2000 3"))) << text;
  EXPECT_TRUE(test::contains(text, "0 0.5 0\n" + header(3, 1, "-50 8 2"))) << text;
  Result<PointSet> back = readText(dir, text);
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->positions, scans.positions);
  ASSERT_NE(back->dimensions.find(dim::kPointSourceId), nullptr);
  for (size_t i = 0; i < 5; ++i) EXPECT_EQ(back->dimensions.find(dim::kPointSourceId)->value(i), ids.value(i)) << i;
  for (const std::string& note : notices) EXPECT_FALSE(test::contains(note, "point_source_id")) << note;

  // Ids 7 and 3: two scans still, read back as 1 and 2, said.
  for (size_t i = 0; i < 5; ++i) ids.setValue(i, i < 2 ? 7.0 : 3.0);
  notices.clear();
  ASSERT_TRUE(writeCsv(dir.file("renumbered.ptx"), scans, options).ok());
  ASSERT_EQ(notices.size(), 2u);  // and no intensity
  EXPECT_TRUE(test::contains(notices[1], "point_source_id written as 2 scans, one for each id in the set's order, which "
                                         "PTX readers number 1 to 2 (its ids were 7, 3)"))
      << notices[1];
  back = readText(dir, test::readFile(dir.file("renumbered.ptx")));
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->dimensions.find(dim::kPointSourceId)->value(4), 2.0);

  // An id in two places: one scan, the ids left out.
  ids.setValue(4, 7.0);
  notices.clear();
  ASSERT_TRUE(writeCsv(dir.file("one.ptx"), scans, options).ok());
  EXPECT_TRUE(test::readFile(dir.file("one.ptx")).starts_with("5\n1\n")) << test::readFile(dir.file("one.ptx"));
  EXPECT_TRUE(test::contains(notices[0], "one.ptx: PTX holds x, y, z, intensity and r, g, b only: point_source_id left out"))
      << notices[0];
}

// Review findings: a translation on a point (a one-point set at whole coordinates), or one that
// --decimals rounds a row onto, made a 0 0 0 row that readers drop; the translation now moves a
// unit off where that is exact. A non-finite coordinate spread NaN over its point's other axes
// through the reader's matrix product, and -0 came back +0: no translation then, on those axes.
TEST(Ptx, aWrittenRowIsNoEchoOnlyWhereNoTranslationAvoidsIt) {
  TempDir dir;
  std::vector<std::string> notices;
  CsvWriteOptions options;
  options.notices = &notices;
  const auto roundTrip = [&](const PointSet& set, const CsvWriteOptions& how, CsvReadOptions read = {}) {
    notices.clear();
    EXPECT_TRUE(writeCsv(dir.file("t.ptx"), set, how).ok());
    Result<PointSet> back = readCsv(dir.file("t.ptx"), read);
    EXPECT_TRUE(back.ok()) << back.error().message;
    return back ? std::move(*back) : PointSet();
  };
  PointSet one;
  one.positions = {{1.0, 2.0, 3.0}};
  EXPECT_EQ(roundTrip(one, options).positions, one.positions);
  for (const std::string& note : notices) EXPECT_FALSE(test::contains(note, "origin")) << note;

  PointSet grid;  // rounds onto its centre at 2 decimals
  grid.positions = {{1000.0, 2000.0, 3000.0}, {1001.001, 2001.001, 3001.001}, {1002.0, 2002.0, 3002.0}};
  CsvWriteOptions two = options;
  two.decimals = 2;
  PointSet back = roundTrip(grid, two);
  ASSERT_EQ(back.size(), 3u);
  EXPECT_NEAR(back.positions[1].x, 1001.0, 1e-9);

  PointSet odd;
  odd.positions = {{-0.0, 100.0, 200.0}, {3.0, 110.0, 205.0}};
  back = roundTrip(odd, options);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_TRUE(std::signbit(back.positions[0].x));
  EXPECT_EQ(back.positions, odd.positions);

  PointSet nonfinite;
  nonfinite.positions = {{3.0, 100.0, 25.0}, {4.0, 12.0, 25.0}};
  nonfinite.positions[0].y = HUGE_VAL;
  nonfinite.positions[1].z = std::nan("");
  CsvReadOptions allow;
  allow.allow_nonfinite = true;
  back = roundTrip(nonfinite, options, allow);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back.positions[0], nonfinite.positions[0]);
  EXPECT_EQ(back.positions[1].x, 4.0);
  EXPECT_EQ(back.positions[1].y, 12.0);
  EXPECT_TRUE(std::isnan(back.positions[1].z));

  // No unit off is exact (0.1 - 1 + 1 is not 0.1): the point at the origin is lost, and said.
  PointSet origin;
  origin.positions = {{0.0, 0.0, 0.0}, {0.1, 0.2, 0.3}};
  EXPECT_EQ(roundTrip(origin, options).size(), 1u);
  EXPECT_TRUE(std::any_of(notices.begin(), notices.end(),
                          [](const std::string& n) { return test::contains(n, "1 point at the scan's origin (0, 0, 0)"); }));
}

}  // namespace
}  // namespace dpoint
