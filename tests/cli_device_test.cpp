// dpoint generate --device as a user runs it, on lavapipe here (--device cpu) with the validation
// layer: each kind's grid (--grid-out) and output file equal the CPU path's at small odd and even
// resolutions, whole and in tiles; the seed variant and missing devices are refused with exit codes.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "test_support.h"

namespace dpoint {
namespace {

using test::readFile;
using test::runDpoint;
using test::TempDir;

std::vector<std::string> concat(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

TEST(CliGenerateDevice, gridAndOutputOnTheDeviceEqualTheCpuPathsForEachKind) {
  const std::vector<std::vector<std::string>> kinds = {
      {"mandelbulb", "--variant", "fast", "--max-iter", "60"},
      {"julia"},
      {"mandelbrot2d", "--max-iter", "500", "--width", "1e-9"},
  };
  for (const std::vector<std::string>& kind : kinds) {
    for (const char* res : {"19", "32"}) {
      SCOPED_TRACE(kind[0] + " at " + res);
      TempDir dir;
      const std::vector<std::string> base = concat(concat({"generate"}, kind), {"--resolution", res, "-q"});
      test::CommandResult cpu =
          runDpoint(concat(base, {"--device", "none", "--grid-out", dir.file("cpu.grid"), "-o", dir.file("cpu.ply")}));
      ASSERT_EQ(cpu.exit_code, 0) << cpu.err;
      test::CommandResult gpu = runDpoint(concat(
          base, {"--device", "cpu", "--validate", "--grid-out", dir.file("gpu.grid"), "-o", dir.file("gpu.ply")}));
      ASSERT_EQ(gpu.exit_code, 0) << gpu.err;
      EXPECT_FALSE(readFile(dir.file("cpu.grid")).empty());
      EXPECT_TRUE(readFile(dir.file("cpu.grid")) == readFile(dir.file("gpu.grid")));
      EXPECT_TRUE(readFile(dir.file("cpu.ply")) == readFile(dir.file("gpu.ply")));
      // Without --grid-out the classification stops at the level's cap and the CPU finishes the
      // counts the mesh needs (auto on lavapipe, and --counts capped), or runs every count on the
      // device (--counts full, auto on a GPU): the same file again either way.
      if (kind[0] == "mandelbrot2d") {
        gpu = runDpoint(concat(base, {"--device", "cpu", "-o", dir.file("lazy.ply")}));
        ASSERT_EQ(gpu.exit_code, 0) << gpu.err;
        EXPECT_TRUE(readFile(dir.file("cpu.ply")) == readFile(dir.file("lazy.ply")));
        continue;
      }
      for (const char* counts : {"auto", "capped", "full"}) {
        SCOPED_TRACE(counts);
        gpu = runDpoint(concat(base, {"--device", "cpu", "--counts", counts, "-o", dir.file("lazy.ply")}));
        ASSERT_EQ(gpu.exit_code, 0) << gpu.err;
        EXPECT_TRUE(readFile(dir.file("cpu.ply")) == readFile(dir.file("lazy.ply")));
      }
    }
  }
}

TEST(CliGenerateDevice, tilesOnTheDeviceMergeToTheCpuFile) {
  TempDir dir;
  const std::vector<std::string> kind = {"generate", "julia", "--resolution", "27", "-q"};
  ASSERT_EQ(runDpoint(concat(kind, {"--device", "none", "-o", dir.file("cpu.ply")})).exit_code, 0);
  std::vector<std::string> merge = {"merge", "-q", "-o", dir.file("merged.ply")};
  for (int i = 0; i < 3; ++i) {
    merge.push_back(dir.file("part-" + std::to_string(i) + ".ply"));
    test::CommandResult r =
        runDpoint(concat(kind, {"--device", "0", "--validate", "--tile", std::to_string(i) + "/3", "-o", merge.back()}));
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  ASSERT_EQ(runDpoint(merge).exit_code, 0);
  EXPECT_TRUE(readFile(dir.file("cpu.ply")) == readFile(dir.file("merged.ply")));
}

TEST(CliGenerateDevice, seedVariantAndMissingDevicesAreRefused) {
  TempDir dir;
  test::CommandResult r =
      runDpoint({"generate", "mandelbulb", "--resolution", "9", "--device", "cpu", "-o", dir.file("m.ply")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--device cpu: --variant seed runs on the CPU only"), std::string::npos) << r.err;
  r = runDpoint({"generate", "julia", "--resolution", "9", "--device", "7", "-o", dir.file("j.ply")});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("--device 7: only"), std::string::npos) << r.err;
  r = runDpoint({"generate", "julia", "--resolution", "9", "--device", "gpu", "-o", dir.file("j.ply")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(dir.entries().empty());
  // auto: the seed variant takes the CPU; with no GPU here, so does everything else.
  r = runDpoint({"generate", "mandelbulb", "--resolution", "9", "-o", dir.file("m.ply")});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("escape counts on"), std::string::npos) << r.err;
  r = runDpoint({"generate", "mandelbulb", "--help"});
  EXPECT_NE(r.out.find("--variant seed always runs on the CPU"), std::string::npos);
  r = runDpoint({"generate", "mandelbrot2d", "--max-iter", "70000", "--resolution", "8", "--grid-out",
                 dir.file("g"), "-o", dir.file("m.csv")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--grid-out stores counts up to 65535"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace dpoint
