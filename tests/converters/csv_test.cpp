#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <charconv>
#include <iterator>
#include <random>
#include <span>

#include <unistd.h>

#include "converters/csv.h"
#include "core/fixed_format.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::readFile;
using test::TempDir;
using test::writeFile;

uint64_t bitsOf(double v) {
  uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

// 1M doubles: random bit patterns (every exponent, subnormals included) and the hard values.
std::vector<double> hardDoubles(size_t count) {
  std::vector<double> v = {0.0, -0.0, DBL_MAX, -DBL_MAX, DBL_MIN, -DBL_MIN, DBL_TRUE_MIN, -DBL_TRUE_MIN,
                           1e-300, -1e-300, 0.1, -0.1, 0.30000000000000004, 1.2345678901234567,
                           9007199254740993.0, 4.9406564584124654e-324, 2.2250738585072009e-308,
                           1.7976931348623157e308, 6378137.123456789, 123456789.12345679, 1.0 / 3.0};
  std::mt19937_64 rng(20261122);
  while (v.size() < count) {
    uint64_t bits = rng();
    double d;
    std::memcpy(&d, &bits, sizeof d);
    if (!std::isfinite(d)) continue;
    switch (v.size() % 4) {
      case 0: v.push_back(d); break;                                                   // any exponent
      case 1: v.push_back(std::ldexp(static_cast<double>(bits >> 11), -1074)); break;  // subnormal range
      case 2: v.push_back(std::ldexp(static_cast<double>(bits >> 11), -53) * 1e7); break;  // 17 digits
      default: v.push_back(static_cast<double>(static_cast<int64_t>(bits)) * 1e-9); break;
    }
  }
  return v;
}

PointSet setFromDoubles(const std::vector<double>& values, bool colors) {
  PointSet s;
  for (size_t i = 0; i + 2 < values.size(); i += 3) s.positions.emplace_back(values[i], values[i + 1], values[i + 2]);
  if (colors) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (size_t i = 0; i < s.positions.size(); ++i) s.colors.emplace_back(unit(rng), unit(rng), unit(rng));
  }
  return s;
}

void expectBitIdentical(const PointSet& a, const PointSet& b) {
  ASSERT_EQ(a.positions.size(), b.positions.size());
  ASSERT_EQ(a.colors.size(), b.colors.size());
  for (size_t i = 0; i < a.positions.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(bitsOf(a.positions[i][k]), bitsOf(b.positions[i][k])) << "row " << i << " column " << k;
    }
  }
  for (size_t i = 0; i < a.colors.size(); ++i) ASSERT_EQ(a.colors[i], b.colors[i]) << "row " << i;
}

TEST(Csv, roundTripIsBitExactAndByteIdentical) {
  TempDir dir;
  const PointSet original = setFromDoubles(hardDoubles(1000002), true);
  ASSERT_TRUE(writeCsv(dir.file("a.csv"), original).ok());
  Result<PointSet> read = readCsv(dir.file("a.csv"));
  ASSERT_TRUE(read.ok()) << read.error().message;
  expectBitIdentical(original, *read);
  ASSERT_TRUE(writeCsv(dir.file("b.csv"), *read).ok());
  EXPECT_TRUE(readFile(dir.file("a.csv")) == readFile(dir.file("b.csv")));
}

TEST(Csv, readIsIdenticalForAnyThreadCount) {
  TempDir dir;
  // About 50 MB: several 8 MB blocks, with lines crossing block boundaries.
  const PointSet original = setFromDoubles(hardDoubles(2400000), true);
  ASSERT_TRUE(writeCsv(dir.file("a.csv"), original, CsvWriteOptions{-1, 2, nullptr}).ok());
  Result<PointSet> one = readCsv(dir.file("a.csv"), CsvReadOptions{1, false, nullptr});
  Result<PointSet> two = readCsv(dir.file("a.csv"), CsvReadOptions{2, false, nullptr});
  Result<PointSet> five = readCsv(dir.file("a.csv"), CsvReadOptions{5, false, nullptr});
  ASSERT_TRUE(one.ok() && two.ok() && five.ok());
  expectBitIdentical(*one, *two);
  expectBitIdentical(*one, *five);
  expectBitIdentical(original, *one);
  ASSERT_TRUE(writeCsv(dir.file("b.csv"), original, CsvWriteOptions{-1, 1, nullptr}).ok());
  EXPECT_TRUE(readFile(dir.file("a.csv")) == readFile(dir.file("b.csv")));
}

// The fixture was made once with python3: '%.15f' % v for each value of the input file (see
// samples/fixtures/README.md). glibc printf rounds the same way (exact value, ties to even).
TEST(Csv, decimals15MatchesPythonPercentFormat) {
  TempDir dir;
  Result<PointSet> values = readCsv(DPOINT_SAMPLES_DIR "/fixtures/decimals15_input.csv");
  ASSERT_TRUE(values.ok()) << values.error().message;
  ASSERT_TRUE(writeCsv(dir.file("out.csv"), *values, CsvWriteOptions{15, 0, nullptr}).ok());
  EXPECT_TRUE(readFile(dir.file("out.csv")) == readFile(DPOINT_SAMPLES_DIR "/fixtures/decimals15_expected.csv"));
}

TEST(Csv, acceptsHeaderVariantsCrlfBomSpacesAndBlankLines) {
  TempDir dir;
  writeFile(dir.file("a.csv"), "\xEF\xBB\xBF X , Y ,z\r\n 1.5 ,\t-2, +3\r\n\r\n4,5e-1,6\r\n");
  Result<PointSet> a = readCsv(dir.file("a.csv"));
  ASSERT_TRUE(a.ok()) << a.error().message;
  ASSERT_EQ(a->size(), 2u);
  EXPECT_EQ(a->positions[0], glm::dvec3(1.5, -2, 3));
  EXPECT_EQ(a->positions[1], glm::dvec3(4, 0.5, 6));
  EXPECT_FALSE(a->hasColors());

  writeFile(dir.file("b.csv"), "x,y\n1,2\n3,4");  // 2D, no final newline
  Result<PointSet> b = readCsv(dir.file("b.csv"));
  ASSERT_TRUE(b.ok()) << b.error().message;
  ASSERT_EQ(b->size(), 2u);
  EXPECT_EQ(b->positions[1], glm::dvec3(3, 4, 0));
  EXPECT_TRUE(b->isPlanar());

  writeFile(dir.file("c.csv"), "1,2,3,0.5,0.25,1\n-1,-2,-3,0,0,0\n");  // headerless, by column count
  Result<PointSet> c = readCsv(dir.file("c.csv"));
  ASSERT_TRUE(c.ok()) << c.error().message;
  ASSERT_EQ(c->colors.size(), 2u);
  EXPECT_EQ(c->colors[0], glm::vec3(0.5f, 0.25f, 1.0f));

  writeFile(dir.file("d.csv"), "1,2\n");
  Result<PointSet> d = readCsv(dir.file("d.csv"));
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d->positions[0], glm::dvec3(1, 2, 0));
}

// CloudCompare's and PDAL's text exports name the known dimensions their own way (`Intensity`,
// `scalar_Classification`, `GpsTime`, `ScanDirectionFlag`): read as dpoint's names, with a note,
// so LAS gets them in its fields (they had been extra bytes beside zeros). A column already named
// as the known one keeps the other spelling; one that names nothing known keeps its name.
TEST(Csv, knownDimensionsSpeltAsOtherToolsWriteThemTakeTheirNames) {
  TempDir dir;
  writeFile(dir.file("cc.txt"), "//X Y Z R G B Intensity scalar_Classification GpsTime ScanDirectionFlag Other\n"
                                "1 2 3 10 20 30 500 2 7.5 1 9\n");
  std::vector<std::string> notices;
  CsvReadOptions options;
  options.notices = &notices;
  Result<PointSet> cc = readCsv(dir.file("cc.txt"), options);
  ASSERT_TRUE(cc.ok()) << cc.error().message;
  std::vector<std::string> names;
  for (const Dimension& d : cc->dimensions.all()) names.push_back(d.name);
  EXPECT_EQ(names, (std::vector<std::string>{"intensity", "classification", "gps_time", "scan_direction", "Other"}));
  EXPECT_EQ(cc->dimensions.find("intensity")->type, DimType::kU16);
  EXPECT_EQ(cc->dimensions.find("classification")->value(0), 2.0);
  ASSERT_EQ(notices.size(), 1u);
  EXPECT_EQ(notices[0], dir.file("cc.txt") + ": columns read as the dimensions they name (LAS's fields where LAS is "
                                             "written): Intensity as intensity, scalar_Classification as classification, "
                                             "GpsTime as gps_time, ScanDirectionFlag as scan_direction");
  writeFile(dir.file("both.csv"), "x,y,z,Intensity,intensity\n1,2,3,4,5\n");
  notices.clear();
  Result<PointSet> both = readCsv(dir.file("both.csv"), options);
  ASSERT_TRUE(both.ok()) << both.error().message;
  EXPECT_TRUE(both->dimensions.find("Intensity") && both->dimensions.find("intensity"));
  EXPECT_TRUE(notices.empty());
}

TEST(Csv, writesPlanarSetsAsXy) {
  TempDir dir;
  PointSet s;
  s.positions = {{1, 2, 0}, {3, 4, 0}};
  ASSERT_TRUE(writeCsv(dir.file("a.csv"), s).ok());
  EXPECT_EQ(readFile(dir.file("a.csv")), "x,y\n1,2\n3,4\n");
  s.positions[1].z = -0.0;  // not +0: the z column is kept so the sign survives
  ASSERT_TRUE(writeCsv(dir.file("b.csv"), s).ok());
  EXPECT_EQ(readFile(dir.file("b.csv")), "x,y,z\n1,2,0\n3,4,-0\n");
}

// 2D sets with colours are written `x,y,r,g,b` and must read back (the mandelbrot2d output).
TEST(Csv, planarColouredSetsRoundTripAsXyRgb) {
  TempDir dir;
  PointSet s;
  s.positions = {{-0.7436450000001, 0.1318259, 0}, {3, 4, 0}};
  s.colors = {{0.25f, 0.5f, 1.0f}, {0.0f, 0.125f, 0.75f}};
  ASSERT_TRUE(writeCsv(dir.file("a.csv"), s).ok());
  EXPECT_EQ(readFile(dir.file("a.csv")).substr(0, 10), "x,y,r,g,b\n");
  Result<PointSet> back = readCsv(dir.file("a.csv"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->positions, s.positions);
  EXPECT_EQ(back->colors, s.colors);
  EXPECT_TRUE(back->isPlanar());
  writeFile(dir.file("b.csv"), "1,2,0.5,0.5,0.5\n3,4,0,0,1\n");  // no header: five columns
  Result<PointSet> headless = readCsv(dir.file("b.csv"));
  ASSERT_TRUE(headless.ok()) << headless.error().message;
  EXPECT_EQ(headless->colors[1], glm::vec3(0, 0, 1));
}

// A failing read returns an Error whose message contains every expected part.
void expectReadError(const std::string& path, const std::vector<std::string>& parts, bool allow_nonfinite = false) {
  Result<PointSet> r = readCsv(path, CsvReadOptions{0, allow_nonfinite, nullptr});
  ASSERT_FALSE(r.ok()) << path << " was accepted";
  EXPECT_EQ(r.error().code, ExitCode::kBadInput);
  for (const std::string& part : parts)
    EXPECT_NE(r.error().message.find(part), std::string::npos) << "'" << r.error().message << "' lacks '" << part << "'";
  EXPECT_EQ(r.error().message.find('\n'), std::string::npos) << "message is not one line";
}

// Text point files as spreadsheets and survey tools write them (issue #37): each variant reads to
// the same two points. The separator is the first line's: semicolons (then a decimal comma is
// read), else commas, else runs of spaces and tabs; header names in any case, UTF-8, and the
// common names of the axes and colours.
TEST(Csv, readsTheVariantsPeopleWriteToTheSamePoints) {
  TempDir dir;
  struct Variant {
    std::string name, text, extension = ".csv";
    std::vector<std::string> columns = {};  // --columns
  };
  const std::vector<Variant> variants = {
      {"commas", "x,y,z\n1.5,-2.25,3\n4,5,6.125\n"},
      {"semicolons_decimal_commas", "X;Y;Z\n1,5;-2,25;3\n4;5;6,125\n"},
      {"semicolons_decimal_points", "x;y;z\n1.5;-2.25;3\n4;5;6.125\n"},
      {"semicolons_no_header", "1,5;-2,25;3\r\n4;5;6,125\r\n"},
      {"tabs", "x\ty\tz\n1.5\t-2.25\t3\n4\t5\t6.125\n"},
      {"spaces_no_header", "1.5 -2.25 3\n  4   5 6.125  \n"},
      {"cloudcompare", "//X,Y,Z\n1.5,-2.25,3\n4,5,6.125\n"},
      {"lon_lat_alt", "Lon,Lat,Alt\n1.5,-2.25,3\n4,5,6.125\n"},
      {"longitude_latitude_height", "longitude latitude height\n1.5 -2.25 3\n4 5 6.125\n"},
      {"e_n_h", "E;N;H\n1,5;-2,25;3\n4;5;6,125\n"},
      {"easting_northing_elevation", "Easting,Northing,Elevation\n1.5,-2.25,3\n4,5,6.125\n"},
      {"german_utf8", "Rechtswert;Hochwert;H\xc3\xb6he\n1,5;-2,25;3\n4;5;6,125\n"},
      {"bom_crlf_upper", "\xEF\xBB\xBFX,Y,Z\r\n1.5,-2.25,3\r\n4,5,6.125\r\n"},
      {"xyz_export", "//X Y Z\n1.5 -2.25 3\n4 5 6.125\n", ".xyz"},
      {"txt_tabs", "1.5\t-2.25\t3\n4\t5\t6.125\n", ".txt"},
      {"asc_upper_extension", "1.5 -2.25 3\n4 5 6.125\n", ".ASC"},
      {"pts_count_line", "2\n1.5 -2.25 3\n4 5 6.125\n", ".pts"},
      {"pts_intensity_colours", "2\r\n1.5 -2.25 3 -120 255 0 0\r\n4 5 6.125 2047 0 128 1\r\n", ".pts"},
      {"pts_without_count", "1.5 -2.25 3 7\n4 5 6.125 8\n", ".pts"},
      {"columns_skip_an_id", "id;Rechts;Hoch;Z\n7;1,5;-2,25;3\n8;4;5;6,125\n", ".csv", {"-", "x", "y", "z"}},
      {"columns_in_another_order", "3 1.5 -2.25 0.5\n6.125 4 5 0.25\n", ".txt", {"z", "X", "y", "quality"}},
      // A review's findings: each was refused, or lost its first row.
      {"columns_label_first_no_header", "pt1,1.5,-2.25,3\npt2,4,5,6.125\n", ".csv", {"-", "x", "y", "z"}},
      {"pandas_index", ",x,y,z\n0,1.5,-2.25,3\n1,4,5,6.125\n"},
      {"numpy_savetxt_header", "# x,y,z\n1.5,-2.25,3\n4,5,6.125\n"},
      {"comment_lines", "# exported by a scanner\n1.5 -2.25 3\n# a comment between rows\n4 5 6.125\n", ".xyz"},
      {"cloudcompare_spaced_marker", "// X Y Z\n1.5 -2.25 3\n4 5 6.125\n", ".xyz"},
      {"quoted_header", "\"x\",\"y\",\"z\"\n1.5,-2.25,3\n4,5,6.125\n"},
  };
  for (const Variant& v : variants) {
    SCOPED_TRACE(v.name);
    writeFile(dir.file(v.name + v.extension), v.text);
    CsvReadOptions options;
    options.columns = v.columns;
    Result<PointSet> p = readCsv(dir.file(v.name + v.extension), options);
    ASSERT_TRUE(p.ok()) << p.error().message;
    ASSERT_EQ(p->size(), 2u);
    EXPECT_EQ(p->positions[0], glm::dvec3(1.5, -2.25, 3));
    EXPECT_EQ(p->positions[1], glm::dvec3(4, 5, 6.125));
  }
  // PTS: the intensity between z and the colours, the colours 0-255 whatever their values; a row of
  // another width is refused by line.
  Result<PointSet> pts = readCsv(dir.file("pts_intensity_colours.pts"));
  ASSERT_TRUE(pts.ok()) << pts.error().message;
  ASSERT_NE(pts->dimensions.find("intensity"), nullptr);
  EXPECT_EQ(pts->dimensions.find("intensity")->value(0), -120.0);
  EXPECT_EQ(pts->dimensions.find("intensity")->value(1), 2047.0);
  EXPECT_EQ(pts->colors.at(1), glm::vec3(0.0f, 128.0f / 255.0f, 1.0f / 255.0f));
  EXPECT_EQ(pts->color_full_scale, 255);
  writeFile(dir.file("five.pts"), "2\n1 2 3 4 5\n");
  expectReadError(dir.file("five.pts"), {"five.pts:2: 5 columns in a PTS row", "7 (x y z intensity r g b)"});
  // A count line that is not the rows' count (a file cut short, or one with rows added) is refused.
  writeFile(dir.file("short.pts"), "\n100000000000\n1 2 3\n");
  expectReadError(dir.file("short.pts"), {"short.pts:2: the count line declares 100000000000 points, but the file has 1 rows"});
  CsvReadOptions quality;
  quality.columns = {"z", "x", "y", "quality"};
  Result<PointSet> named = readCsv(dir.file("columns_in_another_order.txt"), quality);
  ASSERT_TRUE(named.ok()) << named.error().message;
  ASSERT_NE(named->dimensions.find("quality"), nullptr);
  EXPECT_EQ(named->dimensions.find("quality")->value(1), 0.25);
  // --columns that do not fit the rows, or name no y, are refused: by line, or as a usage error.
  quality.columns = {"x", "y", "z"};
  Result<PointSet> narrow = readCsv(dir.file("columns_in_another_order.txt"), quality);
  ASSERT_FALSE(narrow.ok());
  EXPECT_TRUE(test::contains(narrow.error().message, "columns_in_another_order.txt:1: 4 columns, expected 3 (x,y,z)"));
  quality.columns = {"x", "-", "z"};
  Result<PointSet> no_y = readCsv(dir.file("columns_in_another_order.txt"), quality);
  ASSERT_FALSE(no_y.ok());
  EXPECT_EQ(no_y.error().code, ExitCode::kUsage);
  writeFile(dir.file("ragged.pts"), "2\n1 2 3 4\n1 2 3\n");
  expectReadError(dir.file("ragged.pts"), {"ragged.pts:3: 3 columns, expected 4 (x y z intensity)"});
  // Colour words and a further column keep their meaning; a column named h after the position is
  // a dimension, not a second z.
  writeFile(dir.file("words.csv"), "X;Y;Z;Red;Green;Blue;h\n1;2;3;0,5;0,25;1;7,5\n");
  Result<PointSet> words = readCsv(dir.file("words.csv"));
  ASSERT_TRUE(words.ok()) << words.error().message;
  EXPECT_EQ(words->colors.at(0), glm::vec3(0.5f, 0.25f, 1.0f));
  ASSERT_NE(words->dimensions.find("h"), nullptr);
  // A header it cannot map says how it split the line, and prints UTF-8 as it is.
  writeFile(dir.file("unknown.csv"), "Rechts;Hoch;H\xc3\xb6henlage\n1;2;3\n");
  expectReadError(dir.file("unknown.csv"), {"unknown.csv:1: header 'Rechts;Hoch;H\xc3\xb6henlage' (split at semicolons)",
                                            "lon,lat,alt"});
}

// A review of the inputs people bring (2026-12-01): an attribute's empty field is a missing value
// (pandas writes NaN so) and a skipped column's is nothing; a known float32 dimension keeps the
// digits float32 cannot hold (nx was parsed as float: 0.123456789012345 became 0.12345679), and
// its shortest float text still reads as float32; a negative colour fraction, a PTS count past
// 2^64 and CR-only line ends are refused naming why; a PTS file of 0 points is an empty set.
TEST(Csv, missingValuesFloatDimensionsAndOddLinesAreReadAsMeant) {
  TempDir dir;
  writeFile(dir.file("missing.csv"), "x,y,z,gps_time\n1,2,3,\n4,5,6,7.5\n");
  Result<PointSet> missing = readCsv(dir.file("missing.csv"));
  ASSERT_TRUE(missing.ok()) << missing.error().message;
  ASSERT_NE(missing->dimensions.find("gps_time"), nullptr);
  EXPECT_TRUE(std::isnan(missing->dimensions.find("gps_time")->value(0)));
  EXPECT_EQ(missing->dimensions.find("gps_time")->value(1), 7.5);
  // An attribute may be infinite, as the writer writes it (it had been refused, coordinates alike).
  writeFile(dir.file("inf.csv"), "x,y,z,v\n1,2,3,inf\n4,5,6,-inf\n");
  Result<PointSet> infinite = readCsv(dir.file("inf.csv"));
  ASSERT_TRUE(infinite.ok()) << infinite.error().message;
  EXPECT_EQ(infinite->dimensions.find("v")->value(1), -HUGE_VAL);
  writeFile(dir.file("inf_position.csv"), "x,y,z,v\n1,inf,3,4\n");
  expectReadError(dir.file("inf_position.csv"), {"inf_position.csv:2: column 2: 'inf' is not a finite number"});
  writeFile(dir.file("empty_position.csv"), "x,y,z\n1,,3\n");
  expectReadError(dir.file("empty_position.csv"), {"empty_position.csv:2: column 2: empty field"});
  CsvReadOptions skip;
  skip.columns = {"-", "x", "y", "z"};
  writeFile(dir.file("empty_skipped.csv"), ",1,2,3\n");
  Result<PointSet> skipped = readCsv(dir.file("empty_skipped.csv"), skip);
  ASSERT_TRUE(skipped.ok()) << skipped.error().message;
  EXPECT_EQ(skipped->size(), 1u);

  writeFile(dir.file("normals.csv"), "x,y,z,nx,ny\n1,2,3,0.123456789012345,0.12345679\n4,5,6,0.5,0.25\n");
  Result<PointSet> normals = readCsv(dir.file("normals.csv"));
  ASSERT_TRUE(normals.ok()) << normals.error().message;
  EXPECT_EQ(normals->dimensions.find("nx")->type, DimType::kF64);
  EXPECT_EQ(normals->dimensions.find("nx")->value(0), 0.123456789012345);
  EXPECT_EQ(normals->dimensions.find("ny")->type, DimType::kF32);
  EXPECT_EQ(normals->dimensions.find("ny")->value(0), double(0.12345679f));

  writeFile(dir.file("negative.csv"), "x,y,z,r,g,b\n1,2,3,0.5,0,1\n1,2,3,-5,0,1\n");
  expectReadError(dir.file("negative.csv"), {"negative.csv: data row 2, colour column 1: -5", "fractions are 0..1"});
  writeFile(dir.file("huge.pts"), "99999999999999999999\n1 2 3\n");
  expectReadError(dir.file("huge.pts"), {"huge.pts:1: the count line 99999999999999999999 is 2^64 points or more"});
  // Twenty digits: 2^64 - 1 is a count (of points the file lacks), 2^64 is past every count.
  writeFile(dir.file("huge.pts"), "18446744073709551615\n1 2 3\n");
  expectReadError(dir.file("huge.pts"), {"huge.pts:1: the count line declares 18446744073709551615 points, but the file has 1 rows"});
  writeFile(dir.file("huge.pts"), "18446744073709551616\n1 2 3\n");
  expectReadError(dir.file("huge.pts"), {"huge.pts:1: the count line 18446744073709551616 is 2^64 points or more"});
  writeFile(dir.file("huge.pts"), "000000000000000000001\n1 2 3\n");
  ASSERT_TRUE(readCsv(dir.file("huge.pts")).ok());
  writeFile(dir.file("mac.xyz"), "1 2 3\r4 5 6\r");
  expectReadError(dir.file("mac.xyz"), {"mac.xyz:1: carriage returns inside a line", "CR alone"});
  writeFile(dir.file("id.csv"), "id,x,y,z\n1,1,2,3\n");
  expectReadError(dir.file("id.csv"), {"id.csv:1: header 'id,x,y,z'", "--columns names each column instead"});
  for (const char* text : {"0\n", "0"}) {
    writeFile(dir.file("none.pts"), text);
    Result<PointSet> none = readCsv(dir.file("none.pts"));
    ASSERT_TRUE(none.ok()) << none.error().message;
    EXPECT_EQ(none->size(), 0u);
  }
}

// Integers past 2^53 (nanosecond time stamps, 64-bit ids) were read as the nearest double:
// 9007199254740993 came back as ...992 (a review finding). A column of them is int64 (uint64 past
// 2^63), every value exact, over blank lines and on any thread count; where the column also holds
// a fraction or a missing value, it stays double and a note says so.
TEST(Csv, integersPastTwoToThe53AreKeptExactly) {
  TempDir dir;
  std::string text = "x,y,z,id,t,small\n";
  const int rows = 300000;  // several of the reader's 8 MiB blocks
  for (int i = 0; i < rows; ++i) {
    // Odd x and small: the writer's shortest text of 100000 is 1e+05.
    text += std::to_string(2 * i + 1) + ",0,0," + std::to_string(9007199254740993ull + 2ull * static_cast<uint64_t>(i)) +
            "," + std::to_string(-1700000000123456789ll + i) + "," + std::to_string(2 * i + 1) + "\n";
    if (i == 5) text += "\n";
  }
  text += "1,2,3,18446744073709551615,5,1\n";
  writeFile(dir.file("big.csv"), text);
  for (const unsigned threads : {1u, 4u}) {
    CsvReadOptions options;
    options.threads = threads;
    std::vector<std::string> notices;
    options.notices = &notices;
    Result<PointSet> set = readCsv(dir.file("big.csv"), options);
    ASSERT_TRUE(set.ok()) << set.error().message;
    ASSERT_EQ(set->size(), static_cast<size_t>(rows) + 1);
    EXPECT_TRUE(notices.empty());
    const Dimension& id = *set->dimensions.find("id");
    const Dimension& t = *set->dimensions.find("t");
    ASSERT_EQ(id.type, DimType::kU64);
    ASSERT_EQ(t.type, DimType::kI64);
    EXPECT_EQ(set->dimensions.find("small")->type, DimType::kF64);
    for (size_t i : {size_t{0}, size_t{5}, size_t{6}, size_t{rows - 1}}) {
      EXPECT_EQ(id.get<uint64_t>(i), 9007199254740993ull + 2ull * i) << i;
      EXPECT_EQ(t.get<int64_t>(i), -1700000000123456789ll + static_cast<int64_t>(i)) << i;
    }
    EXPECT_EQ(id.get<uint64_t>(rows), 18446744073709551615ull);
  }
  // CSV → CSV gives the same digits.
  Result<PointSet> set = readCsv(dir.file("big.csv"));
  ASSERT_TRUE(set.ok());
  ASSERT_TRUE(writeCsv(dir.file("back.csv"), *set).ok());
  const std::string back = readFile(dir.file("back.csv"));
  EXPECT_TRUE(back == text.substr(0, text.find("\n\n") + 1) + text.substr(text.find("\n\n") + 2))  // no gtest diff of 20 MB
      << back.substr(0, 300);

  for (const char* mixed : {"x,y,z,id\n1,2,3,9007199254740993\n4,5,6,1.5\n", "x,y,z,id\n1,2,3,9007199254740993\n4,5,6,\n",
                            "x,y,z,id\n1,2,3,-9007199254740993\n4,5,6,18446744073709551615\n"}) {
    writeFile(dir.file("mixed.csv"), mixed);
    CsvReadOptions options;
    std::vector<std::string> notices;
    options.notices = &notices;
    Result<PointSet> read = readCsv(dir.file("mixed.csv"), options);
    ASSERT_TRUE(read.ok()) << read.error().message;
    EXPECT_EQ(read->dimensions.find("id")->type, DimType::kF64) << mixed;
    ASSERT_EQ(notices.size(), 1u) << mixed;
    EXPECT_TRUE(test::contains(notices[0], "mixed.csv: column 'id' has integers past 2^53, read as the nearest double"))
        << notices[0];
  }
  // Blank and comment lines among them (their rows, closed up after, were read unset: a review
  // finding, valgrind's "uninitialised value" and a double column).
  writeFile(dir.file("blank.csv"), "x,y,z,id\n0,0,0,9007199254740993\n\n# comment\n1,1,1,5\n");
  Result<PointSet> blank = readCsv(dir.file("blank.csv"));
  ASSERT_TRUE(blank.ok()) << blank.error().message;
  ASSERT_EQ(blank->size(), 2u);
  ASSERT_EQ(blank->dimensions.find("id")->type, DimType::kI64);
  EXPECT_EQ(blank->dimensions.find("id")->get<int64_t>(0), 9007199254740993ll);
  EXPECT_EQ(blank->dimensions.find("id")->get<int64_t>(1), 5);
  // Large values that are no integer's text are doubles, without a word.
  writeFile(dir.file("doubles.csv"), "x,y,z,v\n1,2,3,1e20\n4,5,6,12345678901234567890.5\n");
  CsvReadOptions options;
  std::vector<std::string> notices;
  options.notices = &notices;
  Result<PointSet> doubles = readCsv(dir.file("doubles.csv"), options);
  ASSERT_TRUE(doubles.ok()) << doubles.error().message;
  EXPECT_EQ(doubles->dimensions.find("v")->type, DimType::kF64);
  EXPECT_TRUE(notices.empty());
  // Beyond --max-memory for the exact values: doubles, and the note says why.
  std::string ids = "x,y,z,id\n";
  for (int i = 0; i < 20; ++i) ids += "1,2,3,9007199254740993\n";
  writeFile(dir.file("ids.csv"), ids);
  options.max_memory = 20 * 32 + 10;  // the set's 32 bytes a row fit, the 8 of each exact value do not
  Result<PointSet> refused = readCsv(dir.file("ids.csv"), options);
  ASSERT_TRUE(refused.ok()) << refused.error().message;
  EXPECT_EQ(refused->dimensions.find("id")->type, DimType::kF64);
  ASSERT_FALSE(notices.empty());
  EXPECT_TRUE(test::contains(notices.back(), "need more memory than --max-memory allows")) << notices.back();
}

// The text exports (.xyz, .txt, .asc) are written with spaces and CloudCompare's comment header,
// and read back to the same doubles, colours and dimensions.
TEST(Csv, textExportsAreWrittenWithSpacesAndReadBack) {
  TempDir dir;
  PointSet set = setFromDoubles({1.5, -2.25, 3, 0.1, 4, 5, 6.125, 1e-300}, true);
  set.dimensions.add("intensity", DimType::kU16, set.size()).set<uint16_t>(1, 7);
  for (const std::string ext : {".xyz", ".TXT", ".asc"}) {
    SCOPED_TRACE(ext);
    const std::string path = dir.file("p" + ext);
    ASSERT_TRUE(writeCsv(path, set).ok());
    const std::string text = readFile(path);
    EXPECT_EQ(text.substr(0, text.find('\n')), "//x y z r g b intensity");
    EXPECT_EQ(text.find(','), std::string::npos) << text;
    Result<PointSet> back = readCsv(path);
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back->positions, set.positions);
    EXPECT_EQ(back->colors, set.colors);
    ASSERT_NE(back->dimensions.find("intensity"), nullptr);
    EXPECT_EQ(back->dimensions.find("intensity")->get<uint16_t>(1), 7);
  }
}

TEST(Csv, rejectsMissingFileFolderAndEmptyFile) {
  TempDir dir;
  expectReadError(dir.file("missing.csv"), {"missing.csv", "not found"});
  expectReadError(dir.path(), {dir.path(), "folder"});
  writeFile(dir.file("empty.csv"), "");
  expectReadError(dir.file("empty.csv"), {"empty.csv", "empty file"});
  writeFile(dir.file("blank.csv"), "\n  \n");
  expectReadError(dir.file("blank.csv"), {"blank.csv", "no data rows"});
  writeFile(dir.file("bad_header.csv"), "x,y,w\n1,2,3\n");
  expectReadError(dir.file("bad_header.csv"), {"bad_header.csv:1:", "'x,y,w'"});
}

TEST(Csv, rejectsWrongColumnCountOnLineK) {
  TempDir dir;
  writeFile(dir.file("a.csv"), "x,y,z\n1,2,3\n4,5,6\n7,8\n");
  expectReadError(dir.file("a.csv"), {"a.csv:4:", "2 columns, expected 3"});
  writeFile(dir.file("b.csv"), "1,2,3\n4,5,6,7\n");
  expectReadError(dir.file("b.csv"), {"b.csv:2:", "4 columns, expected 3"});
  writeFile(dir.file("c.csv"), "1,2,3,4\n");
  expectReadError(dir.file("c.csv"), {"c.csv:1:", "4 columns without a header"});
  writeFile(dir.file("d.csv"), "x,y,z\n1,,3\n");
  expectReadError(dir.file("d.csv"), {"d.csv:2:", "column 2", "empty field"});
}

TEST(Csv, rejectsNonNumericTextWithLineAndColumn) {
  TempDir dir;
  writeFile(dir.file("a.csv"), "x,y,z\n1,2,3\n1,2abc,3\n");
  expectReadError(dir.file("a.csv"), {"a.csv:3:", "column 2", "'2abc'", "not a number"});
  writeFile(dir.file("b.csv"), "x,y,z\n1,2,3\n1,2,hello world\n");
  expectReadError(dir.file("b.csv"), {"b.csv:3:", "column 3", "'hello world'"});
}

TEST(Csv, rejectsNonFiniteUnlessAllowed) {
  TempDir dir;
  writeFile(dir.file("a.csv"), "x,y,z\n1,2,3\n4,nan,6\n");
  expectReadError(dir.file("a.csv"), {"a.csv:3:", "column 2", "'nan'", "not a finite number"});
  writeFile(dir.file("b.csv"), "x,y,z\n1,2,-inf\n");
  expectReadError(dir.file("b.csv"), {"b.csv:2:", "column 3", "'-inf'"});
  Result<PointSet> allowed = readCsv(dir.file("a.csv"), CsvReadOptions{0, true, nullptr});
  ASSERT_TRUE(allowed.ok());
  EXPECT_TRUE(std::isnan(allowed->positions[1].y));
}

TEST(Csv, rejectsNumbersOutOfDoubleRange) {
  TempDir dir;
  writeFile(dir.file("a.csv"), "x,y,z\n1,2,3\n1e309,2,3\n");
  expectReadError(dir.file("a.csv"), {"a.csv:3:", "column 1", "'1e309'", "out of double range"});
  writeFile(dir.file("b.csv"), "x,y,z\n1,-2e-400,3\n");
  expectReadError(dir.file("b.csv"), {"b.csv:2:", "column 2", "'-2e-400'", "underflows"});
  writeFile(dir.file("c.csv"), "x,y,z,r,g,b\n1,2,3,1e39,0,0\n");
  expectReadError(dir.file("c.csv"), {"c.csv:2:", "column 4", "out of float range"});
  // The smallest subnormal is in range, and so is zero written with an exponent.
  writeFile(dir.file("d.csv"), "x,y,z\n4.9406564584124654e-324,0e-999,0.0\n");
  EXPECT_TRUE(readCsv(dir.file("d.csv")).ok());
}

TEST(Csv, rejectsOneMegabyteLine) {
  TempDir dir;
  writeFile(dir.file("a.csv"), "x,y,z\n1,2,3\n" + std::string(1 << 20, '7') + ",1,2\n4,5,6\n");
  expectReadError(dir.file("a.csv"), {"a.csv:3:", "line longer than"});
  writeFile(dir.file("b.csv"), std::string(1 << 20, ' ') + "\n");
  expectReadError(dir.file("b.csv"), {"b.csv:1:", "line longer than"});
}

TEST(Csv, rejectsBinaryGarbage) {
  TempDir dir;
  std::string garbage;
  std::mt19937 rng(3);
  for (int i = 0; i < 4096; ++i) garbage += static_cast<char>(rng() & 0xff);
  garbage[5] = '\0';
  garbage[100] = '\n';
  writeFile(dir.file("a.csv"), garbage);
  Result<PointSet> r = readCsv(dir.file("a.csv"));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("a.csv:1:"), std::string::npos) << r.error().message;
  writeFile(dir.file("b.csv"), "1,2,3\n\x01\x02\x03\xff,2,3\n");
  expectReadError(dir.file("b.csv"), {"b.csv:2:", "column 1", "\\x01\\x02\\x03\\xff", "not a number"});
}

TEST(Csv, reportsTheFirstBadLineWhateverTheThreadCount) {
  TempDir dir;
  std::string text = "x,y,z\n";
  for (int i = 0; i < 800000; ++i) text += "1.25,2.5,3.75\n";  // ~11 MB: two blocks
  text += "bad,1,1\n";
  for (int i = 0; i < 10; ++i) text += "1,2,3\n";
  text += "alsobad,1,1\n";
  writeFile(dir.file("a.csv"), text);
  for (unsigned threads : {1u, 2u, 4u}) {
    Result<PointSet> r = readCsv(dir.file("a.csv"), CsvReadOptions{threads, false, nullptr});
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("a.csv:800002: column 1: 'bad'"), std::string::npos) << r.error().message;
  }
}

// The rows are sized and numbered from a first count of the lines: a file changed between that
// count and the parse is refused, not read into unset or misnumbered rows; one that only grew is
// read as it was counted.
TEST(Csv, aFileChangedBetweenThePassesIsRefused) {
  TempDir dir;
  std::string text = "x,y,z\n";
  for (int i = 0; i < 800000; ++i) text += "1.25,2.5,3.75\n";  // ~11 MB: two blocks
  const std::string path = dir.file("a.csv");
  auto readChanging = [&](unsigned threads, const std::function<void()>& change) {
    writeFile(path, text);
    CsvReadOptions options;
    options.threads = threads;
    options.between_passes = change;
    return readCsv(path, options);
  };
  auto cut = [&] { ASSERT_EQ(::truncate(path.c_str(), static_cast<off_t>(text.size() / 2)), 0); };
  auto joinLines = [&](size_t at) {  // the same size, one line end less
    return [&, at] {
      std::string changed = text;
      changed[changed.find('\n', at)] = ' ';
      writeFile(path, changed);
    };
  };
  auto grow = [&] { writeFile(path, text + "7,8,9\n"); };
  // As many line ends in each block, but the file's last byte no longer one of them.
  auto moveLastLineEnd = [&] {
    std::string changed = text;
    changed.back() = '5';
    changed[changed.rfind("1.25,") + 4] = '\n';
    writeFile(path, changed);
  };
  for (unsigned threads : {1u, 2u}) {
    for (const auto& [what, change] : std::vector<std::pair<std::string, std::function<void()>>>{
             {"cut", cut}, {"joined in block 0", joinLines(1000)}, {"joined in block 1", joinLines(text.size() - 1000)},
             {"last line end moved", moveLastLineEnd}}) {
      Result<PointSet> r = readChanging(threads, change);
      ASSERT_FALSE(r.ok()) << what << ", " << threads << " threads";
      EXPECT_NE(r.error().message.find("a.csv: the file changed while it was read"), std::string::npos)
          << what << ": " << r.error().message;
    }
    Result<PointSet> grown = readChanging(threads, grow);
    ASSERT_TRUE(grown.ok()) << grown.error().message;
    EXPECT_EQ(grown->size(), 800000u);
    EXPECT_EQ(grown->positions.back(), glm::dvec3(1.25, 2.5, 3.75));
  }
}

TEST(Csv, failedWriteLeavesNothing) {
  TempDir dir;
  PointSet s;
  s.positions = {{1, 2, 3}};
  Status missing = writeCsv(dir.file("no/such/folder/a.csv"), s);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("does not exist"), std::string::npos) << missing.error().message;
  Status proc = writeCsv("/proc/dpoint-test.csv", s);  // read-only even for root
  ASSERT_FALSE(proc.ok());
  EXPECT_NE(proc.error().message.find("/proc"), std::string::npos) << proc.error().message;
  EXPECT_TRUE(dir.entries().empty());
  // Overwriting an existing file replaces it whole.
  writeFile(dir.file("a.csv"), "old");
  ASSERT_TRUE(writeCsv(dir.file("a.csv"), s).ok());
  EXPECT_EQ(readFile(dir.file("a.csv")), "x,y,z\n1,2,3\n");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"a.csv"});
}

// Rows appended in uneven pieces (empty ones, one row, more than a batch) give writeCsv's bytes
// for every layout, thread count and --decimals.
TEST(Csv, rowWriterInPiecesEqualsWriteCsv) {
  TempDir dir;
  PointSet set = setFromDoubles(hardDoubles(3 * 300001), true);
  PointSet planar = set;
  for (glm::dvec3& p : planar.positions) p.z = 0.0;
  const size_t pieces[] = {0, 1, 65535, 0, 2, 300000, 7};
  for (const PointSet* source : {&set, &planar})
    for (const bool colours : {true, false})
      for (const int decimals : {-1, 15})
        for (const unsigned threads : {1u, 2u}) {
          PointSet whole = *source;
          if (!colours) whole.colors.clear();
          const CsvWriteOptions options{decimals, threads, nullptr};
          ASSERT_TRUE(writeCsv(dir.file("whole.csv"), whole, options));
          Result<CsvRowWriter> writer =
              CsvRowWriter::create(dir.file("rows.csv"), CsvLayout{whole.isPlanar(), colours, {}}, options);
          ASSERT_TRUE(writer) << writer.error().message;
          size_t at = 0;
          for (size_t k = 0; at < whole.size(); k = (k + 1) % std::size(pieces)) {
            const size_t n = std::min(pieces[k], whole.size() - at);
            const std::span<const glm::vec3> c =
                colours ? std::span<const glm::vec3>(whole.colors).subspan(at, n) : std::span<const glm::vec3>();
            ASSERT_TRUE(writer->append(std::span<const glm::dvec3>(whole.positions).subspan(at, n), c));
            at += n;
          }
          ASSERT_TRUE(writer->commit());
          EXPECT_TRUE(readFile(dir.file("rows.csv")) == readFile(dir.file("whole.csv")))
              << "planar " << whole.isPlanar() << " colours " << colours << " decimals " << decimals << " threads "
              << threads;
        }
}

// Rows to come that cannot fit the disk even at two bytes a value: refused at create, exit 4,
// nothing written (AtomicFile::checkSpace).
TEST(Csv, rowWriterRefusesMoreRowsThanTheDiskHolds) {
  TempDir dir;
  Result<CsvRowWriter> big =
      CsvRowWriter::create(dir.file("big.csv"), CsvLayout{}, CsvWriteOptions{-1, 1, nullptr}, uint64_t{1} << 60);
  ASSERT_FALSE(big);
  EXPECT_EQ(big.error().code, ExitCode::kResourceLimit);
  EXPECT_NE(big.error().message.find("free"), std::string::npos) << big.error().message;
  EXPECT_TRUE(dir.entries().empty());
  EXPECT_TRUE(CsvRowWriter::create(dir.file("small.csv"), CsvLayout{}, CsvWriteOptions{-1, 1, nullptr}, 1000));
}

TEST(Csv, rowWriterWithoutCommitLeavesNothing) {
  TempDir dir;
  PointSet set = setFromDoubles(hardDoubles(3 * 200000), false);
  {
    // One thread: batches of 2 chunks (131072 rows), so megabytes reach the file before the end.
    Result<CsvRowWriter> writer = CsvRowWriter::create(dir.file("a.csv"), CsvLayout{}, CsvWriteOptions{-1, 1, nullptr});
    ASSERT_TRUE(writer) << writer.error().message;
    ASSERT_TRUE(writer->append(set.positions, {}));
  }
  EXPECT_TRUE(dir.entries().empty());
  Result<CsvRowWriter> bad = CsvRowWriter::create(dir.file("a.csv"), CsvLayout{}, CsvWriteOptions{101, 0, nullptr});
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, ExitCode::kUsage);
  EXPECT_NE(bad.error().message.find("--decimals 101"), std::string::npos) << bad.error().message;
  EXPECT_TRUE(dir.entries().empty());
}

}  // namespace
}  // namespace dpoint

namespace dpoint {
namespace {

// formatFixed must agree with glibc printf("%.*f") and std::to_chars' fixed form everywhere.
TEST(FixedFormat, matchesGlibcPrintfAndToCharsOnRandomAndTieValues) {
  std::mt19937_64 rng(99);
  char a[512], b[512];
  char c[512];
  auto check = [&](double v, int decimals) {
    char* end_a = formatFixed(a, v, decimals);
    auto r = std::to_chars(b, b + sizeof b, v, std::chars_format::fixed, decimals);
    ASSERT_EQ(std::string(a, end_a), std::string(b, r.ptr)) << "decimals " << decimals;
    // And glibc's printf itself, the behaviour --decimals promises.
    std::snprintf(c, sizeof c, "%.*f", decimals, v);
    ASSERT_EQ(std::string(a, end_a), std::string(c)) << "decimals " << decimals;
  };
  for (int i = 0; i < 300000; ++i) {
    const uint64_t bits = rng();
    double v;
    std::memcpy(&v, &bits, sizeof v);
    if (!std::isfinite(v)) continue;
    const int decimals = static_cast<int>(rng() % 30);
    check(v, decimals);
    check(std::ldexp(static_cast<double>(bits >> 11), -static_cast<int>(rng() % 80)), decimals);  // moderate
    check(static_cast<double>(static_cast<int64_t>(bits >> 40)) * 0.001, 15);
  }
  for (int k = 1; k < 80; ++k) {  // exact ties at every position
    for (int decimals = 0; decimals < 30; ++decimals) {
      check(std::ldexp(1.0, -k), decimals);
      check(-3.0 * std::ldexp(1.0, -k), decimals);
      check(2.5 + std::ldexp(1.0, -k), decimals);
    }
  }
  for (double v : {0.0, -0.0, DBL_MAX, -DBL_MAX, DBL_TRUE_MIN, 1e23, 9.5, 0.5, 1.5, -0.5, 1e-7})
    for (int decimals : {0, 1, 15, 27, 28, 60, 100}) check(v, decimals);
}

}  // namespace
}  // namespace dpoint
