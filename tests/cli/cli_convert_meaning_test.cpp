// `dpoint convert` keeps what the data means (issue #24, item 5): z when the input has one, empty
// inputs as empty outputs, material colours, CSV extra columns and whitespace, LAS values at the
// file's step, z-up from LAS. Real files, exit codes, messages by content, bytes.
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "converters/csv.h"
#include "converters/las.h"
#include "converters/ply.h"
#include "converters/point_io.h"
#include "test_config.h"
#include "cli/cli_png.h"
#include "test_support.h"

namespace dpoint {
namespace {

using namespace test;  // readFile, runDpoint, TempDir, writeFile

const std::string kLas = std::string(DPOINT_CORPUS_DIR) + "/las/";
const std::string kEngine = "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";

void expectConverts(const std::vector<std::string>& args) {
  test::CommandResult r = runDpoint(test::concat({"convert"}, args));
  ASSERT_EQ(r.exit_code, 0) << r.err;
}

// `text` written as dir/NAME and converted to dir/OUT (a .csv): OUT's text ("" when convert failed).
std::string convertedCsv(const TempDir& dir, const std::string& name, const std::string& text, const std::string& out) {
  writeFile(dir.file(name), text);
  test::CommandResult r = runDpoint({"convert", dir.file(name), "-o", dir.file(out)});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return r.exit_code == 0 ? readFile(dir.file(out)) : std::string();
}

// `text` written as dir/NAME and converted to dir/NAME.ply: refused with exit 2 and nothing written;
// convert's stderr.
std::string refusedCsv(const TempDir& dir, const std::string& name, const std::string& text) {
  writeFile(dir.file(name), text);
  const test::CommandResult r = runDpoint({"convert", dir.file(name), "-o", dir.file(name + ".ply")});
  EXPECT_EQ(r.exit_code, 2) << name;
  EXPECT_FALSE(test::fileExists(dir.file(name + ".ply"))) << name;
  return r.err;
}

// simple.las with every Z set to 0 (the same header, records rewritten), and with no points.
void writeFlatLas(const std::string& path) {
  std::string bytes = readFile(kLas + "simple.las");
  uint32_t offset, length, count;
  std::memcpy(&offset, bytes.data() + 96, 4);
  std::memcpy(&length, bytes.data() + 105, 2);
  length &= 0xffff;
  std::memcpy(&count, bytes.data() + 107, 4);
  for (uint32_t i = 0; i < count; ++i) std::memset(bytes.data() + offset + size_t(i) * length + 8, 0, 4);
  writeFile(path, bytes);
}
void writeEmptyLas(const std::string& path) {
  std::string bytes = readFile(kLas + "simple.las");
  uint32_t offset;
  std::memcpy(&offset, bytes.data() + 96, 4);
  bytes.resize(offset);
  std::memset(bytes.data() + 107, 0, 4 + 5 * 4);  // legacy count and counts by return
  writeFile(path, bytes);
}

TEST(CliConvertMeaning, lasWhoseZAreAllZeroKeepsItsZColumn) {
  TempDir dir;
  writeFlatLas(dir.file("flat.las"));
  expectConverts({dir.file("flat.las"), "-o", dir.file("flat.csv")});
  const std::string csv = readFile(dir.file("flat.csv"));
  // Point format 3's fields follow the colours (issue #34).
  const std::string header = "x,y,z,r,g,b,intensity,return_number,number_of_returns,scan_direction,"
                             "edge_of_flight_line,classification,synthetic,key_point,withheld,scan_angle_rank,"
                             "user_data,point_source_id,gps_time\n";
  EXPECT_EQ(firstLine(csv), header);
  EXPECT_TRUE(test::contains(csv, "\n637012.24,849028.31,0,"));
  // And through PLY: the PLY has z, so its CSV too.
  expectConverts({dir.file("flat.las"), "-o", dir.file("flat.ply")});
  expectConverts({dir.file("flat.ply"), "-o", dir.file("flat_ply.csv")});
  EXPECT_EQ(firstLine(readFile(dir.file("flat_ply.csv"))), header);
}

TEST(CliConvertMeaning, threeColumnCsvAtZeroStaysThreeColumnsAndTwoColumnsStayTwo) {
  TempDir dir;
  EXPECT_EQ(convertedCsv(dir, "xyz.csv", "x,y,z\n1.5,2,0\n3,4,0\n", "xyz_out.csv"), "x,y,z\n1.5,2,0\n3,4,0\n");
  // Genuinely 2D: CSV → PLY → CSV comes back as x,y (the PLY says so in a header comment).
  writeFile(dir.file("xy.csv"), "x,y\n1.5,2\n3,4\n");
  expectConverts({dir.file("xy.csv"), "-o", dir.file("xy.ply")});
  EXPECT_TRUE(test::contains(readFile(dir.file("xy.ply")), "\ncomment dpoint: 2D (the source has x,y only; z is 0)\n"));
  expectConverts({dir.file("xy.ply"), "-o", dir.file("xy_out.csv")});
  EXPECT_EQ(readFile(dir.file("xy_out.csv")), "x,y\n1.5,2\n3,4\n");
  // GLB positions have z, but dpoint's GLB of a 2D set says it is one (issue #34): x,y again.
  expectConverts({dir.file("xy.csv"), "-o", dir.file("xy.glb")});
  expectConverts({dir.file("xy.glb"), "-o", dir.file("xy_glb.csv")});
  EXPECT_EQ(readFile(dir.file("xy_glb.csv")), "x,y\n1.5,2\n3,4\n");
}

TEST(CliConvertMeaning, plyWithoutZIsTwoDimensional) {
  TempDir dir;
  writeFile(dir.file("xy.ply"),
            "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\nproperty float y\nend_header\n1 2\n3.25 4\n");
  expectConverts({dir.file("xy.ply"), "-o", dir.file("xy.csv")});
  EXPECT_EQ(readFile(dir.file("xy.csv")), "x,y\n1,2\n3.25,4\n");
  // A PLY without y is still refused, with its message.
  writeFile(dir.file("x.ply"), "ply\nformat ascii 1.0\nelement vertex 1\nproperty double x\nend_header\n1\n");
  test::CommandResult r = runDpoint({"convert", dir.file("x.ply"), "-o", dir.file("x.csv")});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(test::contains(r.err, "element 'vertex' has no 'y' property"));
  EXPECT_FALSE(test::fileExists(dir.file("x.csv")));
}

// A 2D generator's PLY says it is 2D, so it converts back to x,y as the CSV the generator writes;
// a 3D generator's PLY does not say so.
TEST(CliConvertMeaning, generated2dPlyConvertsToTwoColumns) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "random2d", "--count", "50", "-q", "-o", dir.file("r.ply")}).exit_code, 0);
  ASSERT_EQ(runDpoint({"generate", "random2d", "--count", "50", "-q", "-o", dir.file("r.csv")}).exit_code, 0);
  EXPECT_TRUE(test::contains(readFile(dir.file("r.ply")), "comment dpoint: 2D"));
  expectConverts({dir.file("r.ply"), "-o", dir.file("back.csv")});
  EXPECT_EQ(readFile(dir.file("back.csv")), readFile(dir.file("r.csv")));
  ASSERT_EQ(runDpoint({"generate", "menger", "--level", "1", "-q", "-o", dir.file("m.ply")}).exit_code, 0);
  EXPECT_FALSE(test::contains(readFile(dir.file("m.ply")), "comment dpoint: 2D"));
}

// Issue #34: a 2D set stays 2D through GLB (the asset's extras say so), on the streamed glTF → CSV
// path and through a set in memory (GLB → PLY → CSV); a 3D set's GLB carries no such mark.
TEST(CliConvertMeaning, a2dSetStays2dThroughGlb) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "random2d", "--count", "50", "-q", "-o", dir.file("r.csv")}).exit_code, 0);
  expectConverts({dir.file("r.csv"), "-o", dir.file("r.glb")});
  expectConverts({dir.file("r.glb"), "-o", dir.file("streamed.csv")});
  EXPECT_EQ(readFile(dir.file("streamed.csv")), readFile(dir.file("r.csv")));
  expectConverts({dir.file("r.glb"), "-o", dir.file("r.ply")});
  expectConverts({dir.file("r.ply"), "-o", dir.file("held.csv")});
  EXPECT_EQ(readFile(dir.file("held.csv")), readFile(dir.file("r.csv")));
  ASSERT_EQ(runDpoint({"generate", "menger", "--level", "1", "-q", "-o", dir.file("m.glb")}).exit_code, 0);
  EXPECT_FALSE(test::contains(readFile(dir.file("m.glb")), "\"2d\""));
  expectConverts({dir.file("m.glb"), "-o", dir.file("m.csv")});
  EXPECT_EQ(readFile(dir.file("m.csv")).substr(0, 6), "x,y,z,");
}

// A survey's fields through GLB: the streamed glTF → CSV (no point set held) writes the same bytes
// as the held path through PLY.
TEST(CliConvertMeaning, dimensionsComeThroughGlbStreamedOrHeld) {
  TempDir dir;
  expectConverts({kLas + "extrabytes.las", "-o", dir.file("e.glb")});
  expectConverts({dir.file("e.glb"), "-o", dir.file("streamed.csv")});
  expectConverts({dir.file("e.glb"), "-o", dir.file("e.ply")});
  expectConverts({dir.file("e.ply"), "-o", dir.file("held.csv")});
  const std::string streamed = readFile(dir.file("streamed.csv"));
  EXPECT_TRUE(test::contains(firstLine(streamed), ",gps_time,Colors_0,"));
  EXPECT_TRUE(test::contains(firstLine(streamed), ",Intensity,Time\n"));
  EXPECT_TRUE(streamed == readFile(dir.file("held.csv")));
  // --keep on a glTF input takes the held path and keeps the one asked for.
  expectConverts({dir.file("e.glb"), "-o", dir.file("k.csv"), "--keep", "Time"});
  EXPECT_EQ(firstLine(readFile(dir.file("k.csv"))), "x,y,z,r,g,b,Time\n");
}

TEST(CliConvertMeaning, emptyLasConvertsToEmptyCsvPlyAndLasAndGlbSaysWhyNot) {
  TempDir dir;
  writeEmptyLas(dir.file("empty.las"));
  expectConverts({dir.file("empty.las"), "-o", dir.file("empty.csv")});
  // No points, and still the columns of the file's point format (1).
  const std::string columns = "x,y,z,intensity,return_number,number_of_returns,scan_direction,"
                              "edge_of_flight_line,classification,synthetic,key_point,withheld,scan_angle_rank,"
                              "user_data,point_source_id,gps_time\n";
  EXPECT_EQ(readFile(dir.file("empty.csv")), columns);
  expectConverts({dir.file("empty.las"), "-o", dir.file("empty.ply")});
  const std::string ply = readFile(dir.file("empty.ply"));
  EXPECT_TRUE(test::contains(ply, "\nelement vertex 0\n"));
  EXPECT_EQ(ply.substr(ply.size() - 11), "end_header\n");  // no vertex bytes
  expectConverts({dir.file("empty.las"), "-o", dir.file("empty_out.las")});
  Result<LasHeader> header = readLasHeader(dir.file("empty_out.las"));
  ASSERT_TRUE(header) << header.error().message;
  EXPECT_EQ(header->point_count, 0u);
  // Each empty output reads back as an empty set, and converts again.
  for (const char* name : {"empty.csv", "empty.ply", "empty_out.las"}) {
    expectConverts({dir.file(name), "-o", dir.file(std::string("again_") + name + ".csv")});
    EXPECT_EQ(readFile(dir.file(std::string("again_") + name + ".csv")), columns) << name;
  }
  test::CommandResult r = runDpoint({"convert", dir.file("empty.las"), "-o", dir.file("empty.glb")});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(test::contains(r.err, "empty.glb: cannot write GLB: the point set is empty"));
  EXPECT_TRUE(test::contains(r.err, "write .csv, .ply or .las"));
  EXPECT_FALSE(test::fileExists(dir.file("empty.glb")));
}

TEST(CliConvertMeaning, csvHeaderOnlyIsAnEmptySetAndAnEmptyFileStillFails) {
  TempDir dir;
  writeFile(dir.file("header.csv"), "x,y\r\n");
  expectConverts({dir.file("header.csv"), "-o", dir.file("header.ply")});
  EXPECT_TRUE(test::contains(readFile(dir.file("header.ply")), "\nelement vertex 0\n"));
  expectConverts({dir.file("header.ply"), "-o", dir.file("header_out.csv")});
  EXPECT_EQ(readFile(dir.file("header_out.csv")), "x,y\n");
  EXPECT_TRUE(test::contains(refusedCsv(dir, "empty.csv", ""), "empty.csv: empty file"));
}

TEST(CliConvertMeaning, materialBaseColoursBecomePointColours) {
  // 2CylinderEngine has no COLOR_0 anywhere: its parts are coloured by materials only.
  TempDir dir;
  expectConverts({kEngine, "-o", dir.file("engine.csv")});
  const std::string csv = readFile(dir.file("engine.csv"));
  EXPECT_EQ(firstLine(csv), "x,y,z,r,g,b\n");
  EXPECT_TRUE(test::contains(csv, ",0,0,0.85\n"));  // a material's baseColorFactor
  // --no-colors still drops them; a GLB dpoint wrote without colours gains none.
  expectConverts({kEngine, "-o", dir.file("plain.csv"), "--no-colors"});
  EXPECT_EQ(firstLine(readFile(dir.file("plain.csv"))), "x,y,z\n");
  writeFile(dir.file("p.csv"), "x,y,z\n1,2,3\n");
  expectConverts({dir.file("p.csv"), "-o", dir.file("p.glb")});
  expectConverts({dir.file("p.glb"), "-o", dir.file("p_out.csv")});
  EXPECT_EQ(readFile(dir.file("p_out.csv")), "x,y,z\n1,2,3\n");
}

TEST(CliConvertMeaning, csvFurtherColumnsAreDimensionsKeptInOrder) {
  TempDir dir;
  writeFile(dir.file("i.csv"), "x,y,z,intensity\n1,2,3,40\n4,5,6,41\n");
  test::CommandResult r = runDpoint({"convert", dir.file("i.csv"), "-o", dir.file("i_out.csv")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(readFile(dir.file("i_out.csv")), "x,y,z,intensity\n1,2,3,40\n4,5,6,41\n");
  EXPECT_EQ(r.err, "");
  // Colours then dimensions; a name keeps its spelling, a float its digits.
  EXPECT_EQ(convertedCsv(dir, "c.csv", "x,y,z,r,g,b,Amp,t\n1,2,3,0.5,0.25,1,9,0.1\n", "c_out.csv"),
            "x,y,z,r,g,b,Amp,t\n1,2,3,0.5,0.25,1,9,0.1\n");
  // Existing rejections keep their messages: a row of the wrong length, a bad header, 4 columns
  // without a header (what they are is unknown), a partial colour set.
  const std::vector<std::pair<std::string, std::vector<std::string>>> bad = {
      {"x,y,z,intensity\n1,2,3\n", {":2:", "3 columns, expected 4 (x,y,z,intensity)"}},
      {"x,y,w\n1,2,3\n", {":1:", "header 'x,y,w' (split at commas) is not one of"}},
      {"1,2,3,4\n", {":1:", "4 columns without a header"}},
      {"x,y,z,r,g\n1,2,3,4,5\n", {":1:", "header 'x,y,z,r,g' (split at commas) is not one of"}},
      {"x,y,z\n1,two,3\n", {":2:", "column 2", "'two' is not a number"}},
  };
  for (size_t k = 0; k < bad.size(); ++k) {
    const std::string name = "bad" + std::to_string(k) + ".csv";
    const std::string err = refusedCsv(dir, name, bad[k].first);
    for (const std::string& part : bad[k].second) EXPECT_TRUE(test::contains(err, part)) << name;
  }
}

TEST(CliConvertMeaning, whitespaceSeparatedCsvAsCloudCompareWritesIt) {
  TempDir dir;
  // Space-separated with CloudCompare's `//X Y Z` header, tab-separated without one, runs of blanks.
  EXPECT_EQ(convertedCsv(dir, "cc.csv", "//X Y Z R G B\n1.5 2 3 0.5 0.25 1\n-4  5\t6 0 0 0 \n", "cc_out.csv"),
            "x,y,z,r,g,b\n1.5,2,3,0.5,0.25,1\n-4,5,6,0,0,0\n");
  EXPECT_EQ(convertedCsv(dir, "tab.csv", "1\t2\t3\n4\t5\t6\n", "tab_out.csv"), "x,y,z\n1,2,3\n4,5,6\n");
  EXPECT_EQ(convertedCsv(dir, "xy.txt.csv", "x y\n1 2\n", "xy_out.csv"), "x,y\n1,2\n");
  // A row of the wrong length names its line and the layout.
  EXPECT_TRUE(test::contains(refusedCsv(dir, "short.csv", "1 2 3\n4 5\n"), "short.csv:2: 2 columns, expected 3 (x,y,z)"));
}

TEST(CliConvertMeaning, lasToCsvWritesValuesAtTheFilesStep) {
  TempDir dir;
  expectConverts({kLas + "simple.las", "-o", dir.file("s.csv")});
  const std::string csv = readFile(dir.file("s.csv"));
  // 849087.70 at scale 0.01: the double X·0.01 is 849087.7000000001, written as the file means it.
  EXPECT_TRUE(test::contains(csv, "\n636896.33,849087.7,446.39,"));
  EXPECT_FALSE(test::contains(csv, "849087.7000000001"));
  // Every value read back is the LAS reader's double to within half a step, and LAS at the same
  // scale gives the same integers: CSV → LAS at 0.01 → CSV is byte-identical.
  expectConverts({dir.file("s.csv"), "-o", dir.file("s.las"), "--las-scale", "0.01"});
  expectConverts({dir.file("s.las"), "-o", dir.file("s2.csv")});
  EXPECT_TRUE(readFile(dir.file("s2.csv")) == csv);
  // --decimals overrides: fixed digits, zeros kept, colours too.
  expectConverts({kLas + "simple.las", "-o", dir.file("d.csv"), "--decimals", "3"});
  EXPECT_TRUE(test::contains(readFile(dir.file("d.csv")), "\n636896.330,849087.700,446.390,"));
  // Other inputs keep the shortest round trip.
  EXPECT_EQ(convertedCsv(dir, "p.csv", "x,y,z\n849087.7000000001,1,2\n", "p_out.csv"),
            "x,y,z\n849087.7000000001,1,2\n");
}

TEST(CliConvertMeaning, plyWrittenFromLasRecordsZUp) {
  TempDir dir;
  expectConverts({kLas + "simple.las", "-o", dir.file("s.ply")});
  EXPECT_TRUE(test::contains(readFile(dir.file("s.ply")), "\ncomment dpoint: up axis z\n"));
  Result<PointSet> set = readPly(dir.file("s.ply"));
  ASSERT_TRUE(set) << set.error().message;
  EXPECT_TRUE(set->z_up);
  // Kept through PLY → PLY; a PLY from CSV has no such comment.
  expectConverts({dir.file("s.ply"), "-o", dir.file("s2.ply")});
  EXPECT_TRUE(test::contains(readFile(dir.file("s2.ply")), "\ncomment dpoint: up axis z\n"));
  writeFile(dir.file("p.csv"), "x,y,z\n1,2,3\n");
  expectConverts({dir.file("p.csv"), "-o", dir.file("p.ply")});
  EXPECT_FALSE(test::contains(readFile(dir.file("p.ply")), "up axis"));
}

// Colours given as 0-255 integers stay integers through CSV -> PLY -> CSV (and 16-bit ones through
// a PLY's ushort), render as the colours they are, and a fraction among them is refused by row and column.
TEST(CliConvertMeaning, integerColoursKeepTheirFormThroughPly) {
  TempDir dir;
  const std::string bytes = "x,y,z,r,g,b\n0,0,0,255,0,0\n1,0,0,128,64,32\n0,1,0.5,0,0,255\n";
  writeFile(dir.file("a.csv"), bytes);
  expectConverts({dir.file("a.csv"), "-o", dir.file("a.ply")});
  expectConverts({dir.file("a.ply"), "-o", dir.file("b.csv")});
  EXPECT_EQ(readFile(dir.file("b.csv")), bytes);
  Result<PointSet> read = readCsv(dir.file("a.csv"));
  ASSERT_TRUE(read.ok()) << read.error().message;
  EXPECT_EQ(read->color_full_scale, 255);
  EXPECT_FLOAT_EQ(read->colors[1].r, 128.0f / 255.0f);
  const std::string words = "x,y,z,r,g,b\n0,0,0,65535,0,0\n1,0,0,256,64,32\n";
  writeFile(dir.file("w.csv"), words);
  expectConverts({dir.file("w.csv"), "-o", dir.file("w.ply")});
  EXPECT_TRUE(test::contains(readFile(dir.file("w.ply")), "property ushort red"));
  expectConverts({dir.file("w.ply"), "-o", dir.file("w2.csv")});
  EXPECT_EQ(readFile(dir.file("w2.csv")), words);
  // 0-1 colours stay 0-1 values.
  const std::string fractions = "x,y,z,r,g,b\n0,0,0,1,0,0\n1,0,0,0,0.2509804,1\n";
  writeFile(dir.file("f.csv"), fractions);
  expectConverts({dir.file("f.csv"), "-o", dir.file("f.ply")});
  expectConverts({dir.file("f.ply"), "-o", dir.file("f2.csv")});
  EXPECT_EQ(readFile(dir.file("f2.csv")), fractions);
  writeFile(dir.file("bad.csv"), "x,y,z,r,g,b\n0,0,0,255,0,0\n1,0,0,0.5,64,32\n");
  test::CommandResult bad = runDpoint({"convert", dir.file("bad.csv"), "-o", dir.file("bad.ply")});
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_TRUE(test::contains(bad.err, "bad.csv: data row 2, colour column 1: 0.5 among integer colours"));
  EXPECT_FALSE(std::filesystem::exists(dir.file("bad.ply")));
}

// Colours read as fractions that an integer format rounds are said (once the file is there; the
// build before rounded them in silence); colours already on the format's grid, colours kept as
// floats and colours made here (generate's) are not.
TEST(CliConvertMeaning, fractionColoursRoundedToIntegersAreSaid) {
  TempDir dir;
  // Two of three points have a channel between 8-bit steps (0.5, 0.1); 0.2, 0.4, 0.6 and 128/255 are steps.
  writeFile(dir.file("f.csv"), "x,y,z,r,g,b\n0,0,0,0.5,0.25,1\n1,0,0,0.2,0.4,0.6\n2,0,0,1,0.1,0.50196078\n");
  for (const char* out : {"f.ply", "f.pcd", "f.pts", "f.las", "f.laz"}) {
    const test::CommandResult r = runDpoint({"convert", dir.file("f.csv"), "-o", dir.file(out)});
    ASSERT_EQ(r.exit_code, 0) << out << ": " << r.err;
    const bool words = std::string(out).find(".la") != std::string::npos;
    // At 16 bits 0.1 is 6553.5 too: the same two points.
    EXPECT_TRUE(test::contains(r.err, dir.file(out) + ": 2 of 3 points have colours read as fractions that are not " +
                                          (words ? "16-bit values: written rounded to 0..65535" : "8-bit values: written rounded to 0..255")))
        << out << ": " << r.err;
  }
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{dir.file("f.csv"), "-o", dir.file("kept.ply"), "--ply-colors", "float"},
        {dir.file("f.csv"), "-o", dir.file("kept.glb")},
        {dir.file("f.csv"), "-o", dir.file("kept.csv")},
        {dir.file("f.ply"), "-o", dir.file("bytes.pcd")},           // its colours are 8-bit now
        {dir.file("kept.ply"), "-o", dir.file("words.ply"), "--ply-colors", "ushort"}}) {
    const test::CommandResult r = runDpoint(test::concat({"convert"}, args));
    ASSERT_EQ(r.exit_code, 0) << args[2] << ": " << r.err;
    if (args[2].find("words") != std::string::npos) {
      EXPECT_TRUE(test::contains(r.err, "2 of 3 points have colours read as fractions that are not 16-bit")) << r.err;
      continue;
    }
    EXPECT_FALSE(test::contains(r.err, "read as fractions")) << args[2] << ": " << r.err;
  }
  // A float PLY of 8-bit values (as other tools write them) and 0..255 integers convert without a word.
  writeFile(dir.file("i.csv"), "x,y,z,r,g,b\n0,0,0,255,0,0\n1,0,0,128,64,32\n");
  expectConverts({dir.file("i.csv"), "-o", dir.file("i.ply"), "--ply-colors", "float"});
  for (const char* out : {"i.pcd", "i.pts", "i.las"}) {
    const test::CommandResult r = runDpoint({"convert", dir.file("i.ply"), "-o", dir.file(out)});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_FALSE(test::contains(r.err, "read as fractions")) << out << ": " << r.err;
  }
  // Generated colours are rounded by design.
  const test::CommandResult made =
      runDpoint({"generate", "mandelbulb", "--resolution", "24", "-o", dir.file("made.pcd")});
  ASSERT_EQ(made.exit_code, 0) << made.err;
  EXPECT_FALSE(test::contains(made.err, "read as fractions")) << made.err;
  // So are a tile's, read back (the PLY reader knows a tile by its header comment); a float PLY
  // written from it is a file's like any other.
  ASSERT_EQ(runDpoint({"generate", "mandelbulb", "--resolution", "24", "--tile", "0/2", "-q", "-o", dir.file("t.ply")})
                .exit_code,
            0);
  test::CommandResult tile = runDpoint({"convert", dir.file("t.ply"), "-o", dir.file("t.pcd")});
  ASSERT_EQ(tile.exit_code, 0) << tile.err;
  EXPECT_FALSE(test::contains(tile.err, "read as fractions")) << tile.err;
  expectConverts({dir.file("t.ply"), "-o", dir.file("tf.ply"), "--ply-colors", "float"});
  tile = runDpoint({"convert", dir.file("tf.ply"), "-o", dir.file("tf.pcd")});
  ASSERT_EQ(tile.exit_code, 0) << tile.err;
  EXPECT_TRUE(test::contains(tile.err, "read as fractions")) << tile.err;
}

// A PLY whose float colours are whole numbers above 1 (0..255 values, as some tools write them)
// is read as CSV reads integer colours, with a note: the build before clamped every channel to 1,
// and drew the set white. Fractions, HDR values among them and numbers between integers are read
// as ever.
TEST(CliConvertMeaning, aFloatPlyOfWholeColourValuesIsReadAsIntegers) {
  TempDir dir;
  const std::string header = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                             "property float z\nproperty float red\nproperty float green\nproperty float blue\nend_header\n";
  writeFile(dir.file("bytes.ply"), header + "0 0 0 255 128 0\n1 0 0 0 0 12\n");
  writeFile(dir.file("words.ply"), header + "0 0 0 65535 256 0\n1 0 0 0 0 1\n");
  writeFile(dir.file("hdr.ply"), header + "0 0 0 1.5 0.5 0\n1 0 0 0 0 1\n");
  writeFile(dir.file("halves.ply"), header + "0 0 0 127.5 128 0\n1 0 0 0 0 12\n");
  for (const auto& [name, csv] : std::vector<std::pair<std::string, std::string>>{
           {"bytes", "0,0,0,255,128,0\n1,0,0,0,0,12\n"},
           {"words", "0,0,0,65535,256,0\n1,0,0,0,0,1\n"},
           {"hdr", "0,0,0,1.5,0.5,0\n1,0,0,0,0,1\n"},
           {"halves", "0,0,0,127.5,128,0\n1,0,0,0,0,12\n"}}) {
    const test::CommandResult r = runDpoint({"convert", dir.file(name + ".ply"), "-o", dir.file(name + ".csv")});
    ASSERT_EQ(r.exit_code, 0) << name << ": " << r.err;
    EXPECT_EQ(readFile(dir.file(name + ".csv")), "x,y,z,r,g,b\n" + csv) << name;
    const bool whole = name == "bytes" || name == "words";
    EXPECT_EQ(test::contains(r.err, dir.file(name + ".ply") + ": its float colours are whole numbers above 1 (PLY's are 0..1): read as 0.." +
                                        (name == "words" ? "65535" : "255") + " values"),
              whole)
        << name << ": " << r.err;
    EXPECT_FALSE(test::contains(r.err, "nearly all whole")) << name << ": " << r.err;  // halves: one of two is no few
  }
  // One value no integer scale holds among nearly all whole ones, some above 1: said, naming it (a
  // review finding); the colours stay 0..1 values.
  std::string odd = "ply\nformat ascii 1.0\nelement vertex 150\nproperty float x\nproperty float y\nproperty float z\n"
                    "property float red\nproperty float green\nproperty float blue\nend_header\n";
  for (int i = 0; i < 150; ++i) odd += std::to_string(i) + (i == 120 ? " 0 0 127.5 128 0\n" : " 0 0 200 100 0\n");
  writeFile(dir.file("odd.ply"), odd);
  const test::CommandResult said = runDpoint({"convert", dir.file("odd.ply"), "-o", dir.file("odd.csv")});
  ASSERT_EQ(said.exit_code, 0) << said.err;
  EXPECT_TRUE(test::contains(said.err, dir.file("odd.ply") + ": its float colours are nearly all whole numbers, some above 1 "
                                                             "(0..255 values?), but vertex 120's (127.5, 128, 0) is not a whole "
                                                             "number of 0 to 65535"))
      << said.err;
  // Colours dropped are not spoken of (a review finding).
  const test::CommandResult dropped = runDpoint({"convert", dir.file("bytes.ply"), "-o", dir.file("none.csv"), "--no-colors"});
  ASSERT_EQ(dropped.exit_code, 0) << dropped.err;
  EXPECT_FALSE(test::contains(dropped.err, "whole numbers")) << dropped.err;
  EXPECT_EQ(readFile(dir.file("none.csv")), "x,y,z\n0,0,0\n1,0,0\n");
  // To 8-bit outputs the values are the file's, with no rounding note.
  const test::CommandResult pcd = runDpoint({"convert", dir.file("bytes.ply"), "-o", dir.file("bytes.ply.ply"), "--ply-ascii"});
  ASSERT_EQ(pcd.exit_code, 0) << pcd.err;
  EXPECT_TRUE(test::contains(readFile(dir.file("bytes.ply.ply")), "\n0 0 0 255 128 0\n1 0 0 0 0 12\n")) << readFile(dir.file("bytes.ply.ply"));
  EXPECT_FALSE(test::contains(pcd.err, "read as fractions")) << pcd.err;
  // render draws the colours (the build before drew 255, 128, 0 as white).
  const test::CommandResult r = runDpoint({"render", "-q", "--width", "40", "--height", "30", "--point-size", "9",
                                           "--fit", "-o", dir.file("bytes.png"), dir.file("bytes.ply")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const test::Pixels image = test::decodePng(readFile(dir.file("bytes.png")));
  bool orange = false, white = false;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      orange = orange || image.at(x, y) == 0xff0080ffu;  // A B G R: 255, 128, 0
      white = white || (image.at(x, y) & 0xffffffu) == 0xffffffu;
    }
  EXPECT_TRUE(orange);
  EXPECT_FALSE(white);
  // A stream judges the scale from a file's first 65,536 rows, as the whole read judges it from all
  // (the build before clamped such colours to white in a stream), and says so.
  const auto binaryPly = [&](const std::string& name, const std::vector<std::array<float, 6>>& rows) {
    std::string bytes = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(rows.size()) +
                        "\nproperty float x\nproperty float y\nproperty float z\nproperty float red\nproperty float green\n"
                        "property float blue\nend_header\n";
    for (const std::array<float, 6>& row : rows) bytes.append(reinterpret_cast<const char*>(row.data()), sizeof row);
    writeFile(dir.file(name), bytes);
  };
  binaryPly("binary.ply", {{0, 0, 0, 255, 128, 0}, {1, 0, 0, 0, 0, 12}});
  const std::string scaled = dir.file("binary.ply") + ": its float colours are whole numbers above 1 (PLY's are 0..1): read as 0..255 values";
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"render", "-q", "--stream", "on", "--width", "40", "--height", "30", "--point-size", "9",
                                 "--fit", "-o", dir.file("s.png")},
        {"info", "--stream", "on"}, {"info", "--stream", "off"}}) {
    const test::CommandResult s = runDpoint(test::concat(args, {dir.file("binary.ply")}));
    ASSERT_EQ(s.exit_code, 0) << args[0] << ": " << s.err;
    EXPECT_TRUE(test::contains(s.err, scaled)) << args[0] << ": " << s.err;
    EXPECT_FALSE(test::contains(s.err, "clamped")) << args[0] << ": " << s.err;
  }
  EXPECT_EQ(readFile(dir.file("s.png")), readFile(dir.file("bytes.png")));  // the whole read's picture, streamed
  // Past the first rows, a colour no such value is said, naming its vertex; fractions from the first
  // row on are clamped above 1 as before.
  std::vector<std::array<float, 6>> rows(70000, std::array<float, 6>{0, 0, 0, 200, 100, 0});
  for (size_t i = 0; i < rows.size(); ++i) rows[i][0] = static_cast<float>(i);
  rows[69000][4] = 0.5f;
  binaryPly("late.ply", rows);
  const test::CommandResult late = runDpoint({"info", "--stream", "on", dir.file("late.ply")});
  ASSERT_EQ(late.exit_code, 0) << late.err;
  EXPECT_TRUE(test::contains(late.err, dir.file("late.ply") + ": its float colours are whole numbers above 1 in its first "
                                                              "65536 rows (PLY's are 0..1): read as 0..255 values"))
      << late.err;
  EXPECT_TRUE(test::contains(late.err, dir.file("late.ply") + ": vertex 69000's colour (200, 0.5, 0) is not a whole number of "
                                                              "0 to 255 a channel, though the first 65536 rows' are"))
      << late.err;
  binaryPly("fractions.ply", {{0, 0, 0, 0.5f, 0.25f, 0}, {1, 0, 0, 1.5f, 0, 1}});
  const test::CommandResult hdr = runDpoint({"info", "--stream", "on", dir.file("fractions.ply")});
  ASSERT_EQ(hdr.exit_code, 0) << hdr.err;
  EXPECT_TRUE(test::contains(hdr.err, dir.file("fractions.ply") +
                                          ": float colours above 1 (0..255 values?) streamed as PLY's 0..1 and clamped"))
      << hdr.err;
}

// A Leica PTX scan, the usual export of a terrestrial scanner, converts to LAS in its registered
// frame: its 0..1 intensities as LAS's 16-bit ones (a note says so; the writer had refused 0.159304
// as no whole number), its colours, the points with no echo left out. info and render read it
// too; it is not written, and --columns does not apply.
// An E57 file LAStools' las2e57 made from LAS: its 16-bit colours, point source ids and returns go
// back to LAS fields; `info` and `render` read it; the LAS file goes back to E57.
TEST(CliConvertMeaning, anE57ScanConvertsToLasKeepingItsColoursAndFields) {
  TempDir dir;
  const std::string e57 = std::string(DPOINT_SOURCE_DIR) + "/tests/data/e57/ColourRepresentation.e57";
  const test::CommandResult r = runDpoint({"convert", e57, "-o", dir.file("scan.las")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  Result<PointSet> las = readLas(dir.file("scan.las"));
  ASSERT_TRUE(las.ok()) << las.error().message;
  ASSERT_EQ(las->size(), 153u);
  EXPECT_EQ(las->positions[0], glm::dvec3(-0.5, -0.015, -0.432));  // scaled integers of step 0.001
  ASSERT_TRUE(las->hasColors());
  EXPECT_EQ(las->colors[0], glm::vec3(0.0f, 0.0f, 65280.0f / 65535.0f));  // 16-bit, as the file has them
  for (const char* name : {"point_source_id", "return_number", "number_of_returns"})
    ASSERT_NE(las->dimensions.find(name), nullptr) << name;
  EXPECT_EQ(las->dimensions.find("point_source_id")->value(0), 1.0);
  EXPECT_EQ(las->dimensions.find("number_of_returns")->value(0), 1.0);

  const test::CommandResult info = runDpoint({"info", dir.file("scan.las"), e57});
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_TRUE(test::contains(info.out, " 306\ntriangles:")) << info.out;
  EXPECT_EQ(runDpoint({"render", "-q", "--width", "32", "--height", "24", "-o", dir.file("scan.png"), e57}).exit_code, 0);
  // Back to E57 and read again: the same points, colours and fields.
  const test::CommandResult written = runDpoint({"convert", dir.file("scan.las"), "-o", dir.file("back.e57")});
  ASSERT_EQ(written.exit_code, 0) << written.err;
  Result<PointSet> back = readPoints(dir.file("back.e57"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  ASSERT_EQ(back->size(), las->size());
  EXPECT_EQ(back->positions[7], las->positions[7]);
  EXPECT_EQ(back->colors[7], las->colors[7]);
  EXPECT_EQ(back->color_full_scale, 65535);
  for (const char* name : {"point_source_id", "return_number", "number_of_returns", "classification", "intensity"})
    ASSERT_NE(back->dimensions.find(name), nullptr) << name;
  EXPECT_EQ(back->dimensions.find("return_number")->value(0), las->dimensions.find("return_number")->value(0));
  const test::CommandResult damaged = runDpoint({"convert", std::string(DPOINT_SOURCE_DIR) + "/tests/data/e57/bad-crc.e57",
                                                 "-o", dir.file("bad.csv")});
  EXPECT_EQ(damaged.exit_code, 2);
  EXPECT_TRUE(test::contains(damaged.err, "bad-crc.e57: page 0 (bytes 0 to 1023) fails its CRC-32C checksum")) << damaged.err;
  EXPECT_FALSE(test::fileExists(dir.file("bad.csv")));
}

TEST(CliConvertMeaning, aPtxScanConvertsToLasWithItsIntensityAsSixteenBits) {
  TempDir dir;
  writeFile(dir.file("scan.ptx"), "2\n2\n558312.218127 5240857.469093 76.298415\n1 0 0\n0 1 0\n0 0 1\n"
                                  "1 0 0 0\n0 1 0 0\n0 0 1 0\n558312.218127 5240857.469093 76.298415 1\n"
                                  "0 0 0 0.500000 0 0 0\n"
                                  "12.032272 -2.613480 -2.036392 0.159304 168 183 142\n"
                                  "12.860123 -2.793289 -2.162979 0.183719 118 121 94\n"
                                  "12.881760 -2.798019 -2.153061 1 0 0 0\n");
  const test::CommandResult r = runDpoint({"convert", dir.file("scan.ptx"), "-o", dir.file("scan.las")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(test::contains(r.err, dir.file("scan.ptx") + ": 1 of its 4 rows are points with no echo")) << r.err;
  EXPECT_TRUE(test::contains(r.err, dir.file("scan.las") + ": intensity of 0..1 values (as PTX and E57 scans hold it) written as 0..65535"))
      << r.err;
  Result<PointSet> las = readLas(dir.file("scan.las"));
  ASSERT_TRUE(las.ok()) << las.error().message;
  ASSERT_EQ(las->size(), 3u);
  EXPECT_NEAR(las->positions[0].x, 558312.218127 + 12.032272, 1e-6);
  EXPECT_NEAR(las->positions[0].y, 5240857.469093 - 2.613480, 1e-6);
  const Dimension* intensity = las->dimensions.find("intensity");
  ASSERT_NE(intensity, nullptr);
  EXPECT_EQ(intensity->value(0), 10440.0);  // round(0.159304 · 65535)
  EXPECT_EQ(intensity->value(1), 12040.0);  // round(0.183719 · 65535)
  EXPECT_EQ(intensity->value(2), 65535.0);
  ASSERT_TRUE(las->hasColors());
  EXPECT_EQ(las->colors[0], glm::vec3(168.0f, 183.0f, 142.0f) / 255.0f);
  // Whole intensities are written as they are, as before.
  writeFile(dir.file("whole.csv"), "x,y,z,intensity\n1,2,3,0\n4,5,6,1\n");
  const test::CommandResult whole = runDpoint({"convert", dir.file("whole.csv"), "-o", dir.file("whole.las")});
  ASSERT_EQ(whole.exit_code, 0) << whole.err;
  EXPECT_FALSE(test::contains(whole.err, "0..65535")) << whole.err;
  EXPECT_EQ(readLas(dir.file("whole.las"))->dimensions.find("intensity")->value(1), 1.0);

  const test::CommandResult info = runDpoint({"info", dir.file("scan.ptx")});
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_TRUE(test::contains(info.out, " 3\ntriangles:")) << info.out;
  EXPECT_EQ(runDpoint({"render", "-q", "--width", "32", "--height", "24", "-o", dir.file("scan.png"), dir.file("scan.ptx")}).exit_code,
            0);
  // Back to PTX: one scan, its rows about a translation of whole units (so that small numbers carry
  // the digits), read back to the same doubles, intensities and colours.
  const test::CommandResult written = runDpoint({"convert", dir.file("scan.ptx"), "-o", dir.file("back.ptx")});
  ASSERT_EQ(written.exit_code, 0) << written.err;
  const std::string text = readFile(dir.file("back.ptx"));
  size_t header_end = 0;
  for (int line = 0; line < 10; ++line) header_end = text.find('\n', header_end) + 1;
  EXPECT_EQ(text.substr(0, header_end),
            "3\n1\n558325 5240855 74\n1 0 0\n0 1 0\n0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n558325 5240855 74 1\n")
      << text;
  Result<PointSet> ptx = readPoints(dir.file("scan.ptx"));
  Result<PointSet> again = readPoints(dir.file("back.ptx"));
  ASSERT_TRUE(again.ok()) << again.error().message;
  EXPECT_EQ(again->positions, ptx->positions);
  EXPECT_EQ(again->colors, ptx->colors);
  EXPECT_EQ(again->dimensions.find("intensity")->get<double>(1), ptx->dimensions.find("intensity")->get<double>(1));
  // LAS's dimensions other than the intensity have no place in a row: said.
  const test::CommandResult from_las = runDpoint({"convert", dir.file("scan.las"), "-o", dir.file("las.ptx")});
  ASSERT_EQ(from_las.exit_code, 0) << from_las.err;
  EXPECT_TRUE(test::contains(from_las.err, "las.ptx: PTX holds x, y, z, intensity and r, g, b only: ")) << from_las.err;
  EXPECT_EQ(readPoints(dir.file("las.ptx"))->positions, las->positions);
  // A glTF input takes the same path (a review finding: it was written as CSV rows).
  ASSERT_EQ(runDpoint({"generate", "menger", "--level", "1", "--offset", "10,20,30", "-o", dir.file("m.glb"), "-q"}).exit_code, 0);
  ASSERT_EQ(runDpoint({"convert", dir.file("m.glb"), "-o", dir.file("m.ptx"), "-q"}).exit_code, 0);
  Result<PointSet> mesh = readPoints(dir.file("m.glb")), mesh_ptx = readPoints(dir.file("m.ptx"));
  ASSERT_TRUE(mesh_ptx.ok()) << mesh_ptx.error().message;
  EXPECT_EQ(mesh_ptx->positions, mesh->positions);
  const test::CommandResult columns = runDpoint({"convert", dir.file("scan.ptx"), "--columns", "x,y,z", "-o", dir.file("c.csv")});
  EXPECT_EQ(columns.exit_code, 1) << columns.err;
  EXPECT_TRUE(test::contains(columns.err, "a PTX file's rows are x y z, an intensity and r g b")) << columns.err;
}

// Only PLY and GLB hold triangles: converting a PLY mesh to another format reads its vertices and
// stops before triangle rows whose size shows them whole (the build before read them all to drop
// them). An index past the vertices then does not stop a conversion that would not have written
// it; one to PLY still refuses it, and a file cut short or with bytes after its end is refused
// whatever the output (a review finding: the first version passed them).
TEST(CliConvertMeaning, aMeshToAPointFormatReadsNoFaces) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "mandelbulb", "--resolution", "17", "--variant", "fast", "-q", "-o",
                       dir.file("m.ply")})
                .exit_code,
            0);
  std::string bytes = readFile(dir.file("m.ply"));
  ASSERT_TRUE(test::contains(bytes, "property list uchar uint vertex_indices"));
  const uint64_t vertices = std::stoull(bytes.substr(bytes.find("element vertex ") + 15));
  const size_t first_face = bytes.find("end_header\n") + 11 + vertices * (3 * 8 + 3);
  ASSERT_LT(first_face + 13, bytes.size());
  ASSERT_EQ(bytes[first_face], 3);
  for (const char* out : {"good.pcd", "good.csv", "good.las"}) expectConverts({dir.file("m.ply"), "-o", dir.file(out)});
  bytes[first_face + 1] = bytes[first_face + 2] = bytes[first_face + 3] = bytes[first_face + 4] = '\xff';  // index 2^32 - 1
  writeFile(dir.file("bad.ply"), bytes);
  for (const char* name : {"pcd", "csv", "las"}) {
    const std::string out = dir.file(std::string("bad.") + name);
    expectConverts({dir.file("bad.ply"), "-o", out});
    EXPECT_EQ(readFile(out), readFile(dir.file(std::string("good.") + name))) << name;
  }
  for (const char* out : {"bad-out.ply", "bad-out.glb"}) {
    const test::CommandResult r = runDpoint({"convert", dir.file("bad.ply"), "-o", dir.file(out)});
    EXPECT_EQ(r.exit_code, 2) << out << ": " << r.err;
    EXPECT_FALSE(test::fileExists(dir.file(out)));
  }
  for (const bool cut : {true, false}) {
    SCOPED_TRACE(cut ? "cut short" : "bytes after the end");
    const std::string good = readFile(dir.file("m.ply"));
    writeFile(dir.file("broken.ply"), cut ? good.substr(0, good.size() - 100) : good + "garbage");
    for (const char* out : {"broken.pcd", "broken.csv", "broken-out.ply"}) {
      const test::CommandResult r = runDpoint({"convert", dir.file("broken.ply"), "-o", dir.file(out)});
      EXPECT_EQ(r.exit_code, 2) << out << ": " << r.err;
      EXPECT_TRUE(test::contains(r.err, dir.file("broken.ply"))) << r.err;
      EXPECT_FALSE(test::fileExists(dir.file(out)));
    }
  }
  // --sample needs the faces, whatever the output.
  const test::CommandResult sampled =
      runDpoint({"convert", dir.file("bad.ply"), "--sample", "100", "-o", dir.file("sampled.csv")});
  EXPECT_EQ(sampled.exit_code, 2) << sampled.err;
}

}  // namespace
}  // namespace dpoint
