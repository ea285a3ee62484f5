// CSV → GLB → CSV is byte-identical to CSV → CSV (issue #24 item 5): the Earth-radius sample,
// generated sets, extreme magnitudes; a set GLB cannot hold exactly gets one notice line.
#include <gtest/gtest.h>

#include <string>

#include "test_config.h"
#include "test_support.h"

namespace dpoint {
namespace {

using namespace test;  // readFile, runDpoint, TempDir, writeFile

// `csv` converted to CSV directly and through GLB: the same bytes, and no notice.
void expectGlbRoundTripIdentical(const TempDir& dir, const std::string& csv) {
  ASSERT_EQ(runDpoint({"convert", csv, "-o", dir.file("direct.csv")}).exit_code, 0);
  test::CommandResult to_glb = runDpoint({"convert", csv, "-o", dir.file("via.glb")});
  ASSERT_EQ(to_glb.exit_code, 0) << to_glb.err;
  EXPECT_EQ(to_glb.err.find("note:"), std::string::npos) << to_glb.err;
  ASSERT_EQ(runDpoint({"convert", dir.file("via.glb"), "-o", dir.file("back.csv")}).exit_code, 0);
  EXPECT_TRUE(readFile(dir.file("direct.csv")) == readFile(dir.file("back.csv")));
}

TEST(CliGlbExact, earthOffsetSampleRoundTripsByteIdentical) {
  TempDir dir;
  expectGlbRoundTripIdentical(dir, std::string(DPOINT_SAMPLES_DIR) + "/earth_offset_mm.csv");
}

TEST(CliGlbExact, mandelbulbAtEarthRadiusRoundTripsByteIdentical) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "mandelbulb", "--resolution", "64", "--offset", "6378137,0,0", "-q", "-o",
                       dir.file("m.csv")}).exit_code, 0);
  expectGlbRoundTripIdentical(dir, dir.file("m.csv"));
}

TEST(CliGlbExact, random2dCoordinatesRoundTripExactly) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "random2d", "--count", "20000", "-q", "-o", dir.file("r.csv")}).exit_code, 0);
  // GLB positions are VEC3, so the set comes back with z = 0 (docs/formats.md): compare via a
  // 3-column CSV of the same points.
  std::string text = readFile(dir.file("r.csv"));
  std::string three = "x,y,z\n";
  for (size_t at = text.find('\n') + 1; at < text.size();) {
    const size_t end = text.find('\n', at);
    three += text.substr(at, end - at) + ",0\n";
    at = end + 1;
  }
  writeFile(dir.file("r3.csv"), three);
  expectGlbRoundTripIdentical(dir, dir.file("r3.csv"));
}

TEST(CliGlbExact, hardMagnitudesRoundTripByteIdentical) {
  TempDir tiny, mixed;
  // 1e-300 and 1e300 scales: offsets beyond float32's range, held through a power-of-two node scale.
  writeFile(tiny.file("tiny.csv"),
            "x,y,z\n1e-300,3.5e-301,1e300\n-2.5e-300,1.0000000000000002e-300,-7.1e299\n"
            "1.7976931348623157e-300,4.9406564584124654e-300,1.2345678901234567e300\n");
  expectGlbRoundTripIdentical(tiny, tiny.file("tiny.csv"));
  // Earth radius with nanometres, full-precision decimals near zero, 1e-20 next to 3e-20 and 1e20.
  writeFile(mixed.file("mixed.csv"),
            "x,y,z\n6378137.123456789,0.1,1e-20\n6378137.000000001,0.30000000000000004,3e-20\n"
            "6378136.999999999,-0.7,1e20\n");
  expectGlbRoundTripIdentical(mixed, mixed.file("mixed.csv"));
}

TEST(CliGlbExact, setBeyondFloatRangeOnOneAxisGetsOneNotice) {
  TempDir dir;
  writeFile(dir.file("wide.csv"), "x,y,z\n1e-300,0,0\n1,1,1\n");
  test::CommandResult r = runDpoint({"convert", dir.file("wide.csv"), "-o", dir.file("wide.glb")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("dpoint: note: " + dir.file("wide.glb") + ": 1 of 2 points will not read back bit-exactly"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("Write .ply or .csv"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace dpoint
