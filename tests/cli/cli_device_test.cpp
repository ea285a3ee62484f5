// dpoint generate --device as a user runs it, on lavapipe here (--device cpu) with the validation
// layer: each kind's grid (--grid-out) and output file equal the CPU path's at small odd and even
// resolutions, whole and in tiles; the seed variant and missing devices are refused with exit codes;
// Vulkan faults (the DPOINT_TEST_VULKAN_FAULT switch) end generate and bench cleanly.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include "test_support.h"

namespace dpoint {
namespace {

using test::readFile;
using test::runDpoint;
using test::concat;
using test::TempDir;

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
      // Marching cubes on the device too (which runs every count to --max-iter): the same file.
      gpu = runDpoint(concat(base, {"--device", "cpu", "--mesh", "device", "--validate", "-o", dir.file("mesh.ply")}));
      ASSERT_EQ(gpu.exit_code, 0) << gpu.err;
      EXPECT_TRUE(readFile(dir.file("cpu.ply")) == readFile(dir.file("mesh.ply")));
    }
  }
}

// Marching cubes on the device makes the seed noise colours with the mesh where every coordinate
// is in the noise's fast range (not for --bounds ±800 then): the CPU path's file either way, with
// colours or none, native or seed frame, PLY or CSV.
TEST(CliGenerateDevice, noiseColoursMadeWithTheMeshOnTheDeviceAreTheCpus) {
  TempDir dir;
  struct Case {
    std::vector<std::string> args;
    const char* note;  // in the time line
  };
  const std::vector<Case> cases = {
      // Streamed: the device's rows written as they come (converters/ply.h PlyRowStream).
      {{"julia", "--resolution", "40", "-o", "X.ply"},
       "; the colours made with the mesh on the device; the rows made on the device and written as they came\n"},
      {{"mandelbulb", "--variant", "fast", "--resolution", "41", "--frame", "seed", "-o", "X.ply"},
       "; the colours made with the mesh on the device; the rows made on the device and written as they came\n"},
      {{"julia", "--resolution", "40", "--colors", "none", "-o", "X.ply"},
       "triangles; the rows made on the device and written as they came\n"},
      // Not streamed: the mesh is reordered, or its colours are made on the host, or it is a CSV.
      {{"julia", "--resolution", "40", "--order", "morton", "-o", "X.ply"}, "; the colours made with the mesh on the device\n"},
      {{"julia", "--resolution", "40", "--bounds", "-800,800", "-o", "X.ply"}, "; the colours made as the rows were written"},
      {{"julia", "--resolution", "30", "-o", "X.csv"}, "triangles\n"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = concat({"generate"}, c.args);
    const std::string name = args.back();
    SCOPED_TRACE(args[1] + " " + name);
    args.back() = dir.file("cpu-" + name);
    test::CommandResult cpu = runDpoint(concat(args, {"--device", "none", "-q"}));
    ASSERT_EQ(cpu.exit_code, 0) << cpu.err;
    args.back() = dir.file("gpu-" + name);
    test::CommandResult gpu = runDpoint(concat(args, {"--device", "cpu", "--mesh", "device", "--validate"}));
    ASSERT_EQ(gpu.exit_code, 0) << gpu.err;
    EXPECT_NE(gpu.err.find(c.note), std::string::npos) << gpu.err << "wanted: " << c.note;
    EXPECT_TRUE(readFile(dir.file("cpu-" + name)) == readFile(dir.file("gpu-" + name)));
  }
}

TEST(CliGenerateDevice, tilesOnTheDeviceMergeToTheCpuFile) {
  TempDir dir;
  const std::vector<std::string> kind = {"generate", "julia", "--resolution", "27", "-q"};
  ASSERT_EQ(runDpoint(concat(kind, {"--device", "none", "-o", dir.file("cpu.ply")})).exit_code, 0);
  std::vector<std::string> merge = {"merge", "-q", "-o", dir.file("merged.ply")};
  for (int i = 0; i < 3; ++i) {
    merge.push_back(dir.file("part-" + std::to_string(i) + ".ply"));
    // The middle tile's marching cubes on the device: its seam copies and triangles as the host's.
    std::vector<std::string> args = concat(kind, {"--device", "0", "--validate", "--tile", std::to_string(i) + "/3", "-o", merge.back()});
    if (i == 1) args = concat(args, {"--mesh", "device"});
    test::CommandResult r = runDpoint(args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  ASSERT_EQ(runDpoint(merge).exit_code, 0);
  EXPECT_TRUE(readFile(dir.file("cpu.ply")) == readFile(dir.file("merged.ply")));
}

// A tile meshed on the device goes to its part file as the device's rows, as they are made
// (converters/tile_file.h TileRowStream): owned vertices, then the seam's copies with their
// colours as floats, the faces and the references. Every part is the host's byte for byte (empty
// ones too, at the ends of 8 tiles; tiles of 16 or more cell layers, whose counts the header first
// estimates from a sample, with 2), and the parts merge to the whole file.
TEST(CliGenerateDevice, tilesMeshedOnTheDeviceAreWrittenAsTheirRowsAndAreTheHostsParts) {
  struct Case {
    int tiles;
    const char* colors;
  };
  for (const Case c : {Case{8, "auto"}, Case{2, "none"}}) {
    SCOPED_TRACE(std::to_string(c.tiles) + " tiles, --colors " + c.colors);
    TempDir dir;
    const std::vector<std::string> kind = {"generate", "mandelbulb", "--variant", "fast", "--resolution", "40",
                                           "--colors", c.colors};
    ASSERT_EQ(runDpoint(concat(kind, {"--device", "none", "-q", "-o", dir.file("whole.ply")})).exit_code, 0);
    std::vector<std::string> merge = {"merge", "-q", "-o", dir.file("merged.ply")};
    for (int i = 0; i < c.tiles; ++i) {
      SCOPED_TRACE(i);
      const std::string tile = std::to_string(i) + "/" + std::to_string(c.tiles);
      const std::string host = dir.file("host-" + std::to_string(i) + ".ply");
      merge.push_back(dir.file("device-" + std::to_string(i) + ".ply"));
      ASSERT_EQ(runDpoint(concat(kind, {"--device", "none", "-q", "--tile", tile, "-o", host})).exit_code, 0);
      test::CommandResult r =
          runDpoint(concat(kind, {"--device", "cpu", "--mesh", "device", "--validate", "--tile", tile, "-o", merge.back()}));
      ASSERT_EQ(r.exit_code, 0) << r.err;
      EXPECT_NE(r.err.find("the rows made on the device and written as they came"), std::string::npos) << r.err;
      const std::string part = readFile(merge.back());
      EXPECT_NE(part.find("comment dpoint-tile " + tile + "\n"), std::string::npos);
      EXPECT_TRUE(readFile(host) == part);
    }
    test::CommandResult r = runDpoint(merge);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(readFile(dir.file("whole.ply")) == readFile(dir.file("merged.ply")));
  }
}

// The header of a streamed tile is laid out from its sampled counts before its rows: where the
// sample finds no vertex and the tile has some (the bulb's tip between the sampled layers), the
// colour properties join the header and the rows move after it. Where the stream is opened but
// the device does not take the rows (an empty share; --grid-out, which meshes on the host), the
// part is written from the mesh instead. Each part is the host's byte for byte.
TEST(CliGenerateDevice, streamedTilesWhoseHeaderGrowsOrWhoseRowsAreNotTakenAreTheHostsParts) {
  TempDir dir;
  struct Case {
    std::vector<std::string> args;
    bool streamed;
  };
  const std::vector<Case> cases = {
      {{"--resolution", "120", "--bounds", "-2.28,1.5", "--tile", "0/3"}, true},
      {{"--resolution", "40", "--tile", "45/50"}, false},
      {{"--resolution", "40", "--tile", "2/5", "--grid-out", "GRID"}, false},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args[1] + " " + c.args.back());
    std::vector<std::string> args = concat({"generate", "mandelbulb", "--variant", "fast"}, c.args);
    for (std::string& a : args)
      if (a == "GRID") a = dir.file("grid");
    ASSERT_EQ(runDpoint(concat(args, {"--device", "none", "-q", "-o", dir.file("host.ply")})).exit_code, 0);
    test::CommandResult r =
        runDpoint(concat(args, {"--device", "cpu", "--mesh", "device", "--validate", "-o", dir.file("device.ply")}));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err.find("the rows made on the device and written as they came (the header laid out first had "
                         "another length: the vertex rows were moved)") != std::string::npos,
              c.streamed)
        << r.err;
    EXPECT_TRUE(readFile(dir.file("host.ply")) == readFile(dir.file("device.ply")));
  }
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
  // Marching cubes on a device, with none to run on.
  for (const char* device : {"none", "auto"}) {
    r = runDpoint({"generate", "julia", "--resolution", "9", "--device", device, "--mesh", "device", "-o", dir.file("j.ply")});
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("--mesh device: no device makes the counts (--device " + std::string(device)), std::string::npos)
        << r.err;
  }
  r = runDpoint({"generate", "julia", "--resolution", "9", "--mesh", "sideways", "-o", dir.file("j.ply")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--mesh"), std::string::npos) << r.err;
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

// Vulkan faults (issue #12) with the test switch: a device without shaderFloat64, a device lost at
// a submission, and one lost at the first fence wait after a submission went through each end the
// run with exit 3 and one line naming the problem, well before a generous bound (no hang), and
// leave nothing (no output, no temporary) in the folder.
TEST(CliGenerateDevice, vulkanFaultsEndWithOneLineAndNoOutput) {
  struct Case {
    const char* fault;
    const char* message;
  };
  const std::vector<Case> cases = {
      {"no-float64", "lacks shaderFloat64, which generation on the device needs"},
      {"device-lost", "VK_ERROR_DEVICE_LOST"},
      {"device-lost-wait", "VK_ERROR_DEVICE_LOST"},
  };
  for (const Case& c : cases) {
    for (const char* mesh : {"host", "device"}) {  // marching cubes on the device: its submissions too
      SCOPED_TRACE(std::string(c.fault) + ", --mesh " + mesh);
      TempDir dir;
      test::CommandResult r = test::runCommand(
          {"/usr/bin/env", std::string("DPOINT_TEST_VULKAN_FAULT=") + c.fault, DPOINT_EXE, "generate", "mandelbulb",
           "--variant", "fast", "--resolution", "16", "--device", "cpu", "--mesh", mesh, "-q", "-o", dir.file("X.ply")},
          std::chrono::seconds(60));
      ASSERT_FALSE(r.timed_out);
      EXPECT_EQ(r.exit_code, 3) << r.err;
      EXPECT_TRUE(test::contains(r.err, c.message));
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
      EXPECT_TRUE(dir.entries().empty());
      // The run is already on the CPU: the hint does not send it there.
      EXPECT_FALSE(test::contains(r.err, "or --device cpu")) << r.err;
    }
  }
  // Generation on the device uses no 64-bit atomics: with them hidden it runs, to the same file.
  TempDir dir;
  const std::vector<std::string> args = {DPOINT_EXE, "generate", "mandelbulb", "--variant", "fast", "--resolution",
                                         "16", "--device", "cpu", "-q", "-o"};
  test::CommandResult plain = test::runCommand(concat(concat({"/usr/bin/env", "DPOINT_TEST_VULKAN_FAULT="}, args),
                                                      {dir.file("plain.ply")}));
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  test::CommandResult hidden = test::runCommand(
      concat(concat({"/usr/bin/env", "DPOINT_TEST_VULKAN_FAULT=no-int64-atomics"}, args), {dir.file("hidden.ply")}));
  ASSERT_EQ(hidden.exit_code, 0) << hidden.err;
  EXPECT_TRUE(readFile(dir.file("plain.ply")) == readFile(dir.file("hidden.ply")));
}

// The bench's device work starts with its own submissions (the precision self-test, the copy
// bandwidth): a device lost at a submission or at a fence wait ends `bench` and `bench copy` with
// exit 3 and one line, before any dataset, cache folder or report is made.
TEST(CliGenerateDevice, benchEndsWithOneLineAndNothingWrittenOnALostDevice) {
  const std::vector<std::vector<std::string>> commands = {
      {"bench", "--device", "cpu", "-q", "--out", "report", "--cache", "cache"},
      {"bench", "copy", "--device", "cpu", "--copy-bytes", "1M", "--copy-repeats", "1"},
  };
  for (const char* fault : {"device-lost", "device-lost-wait"}) {
    for (const std::vector<std::string>& command : commands) {
      SCOPED_TRACE(std::string(fault) + (command[1] == "copy" ? " bench copy" : " bench"));
      TempDir dir;
      std::vector<std::string> argv = {"/usr/bin/env", std::string("DPOINT_TEST_VULKAN_FAULT=") + fault, DPOINT_EXE};
      for (const std::string& a : command)
        argv.push_back(a == "report" || a == "cache" ? dir.file(a) : a);
      test::CommandResult r = test::runCommand(argv, std::chrono::seconds(60));
      ASSERT_FALSE(r.timed_out);
      EXPECT_EQ(r.exit_code, 3) << r.err;
      EXPECT_TRUE(test::contains(r.err, "VK_ERROR_DEVICE_LOST"));
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
      EXPECT_TRUE(dir.entries().empty());
    }
  }
}

}  // namespace
}  // namespace dpoint
