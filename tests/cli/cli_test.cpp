// Tests of the dpoint executable as a user runs it: exit codes, messages, files left behind.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include "converters/csv.h"
#include "ops/point_order.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::readFile;
using test::runDpoint;
using test::TempDir;
using test::writeFile;

size_t lineCount(const std::string& text) { return static_cast<size_t>(std::count(text.begin(), text.end(), '\n')); }

TEST(Cli, helpAndVersionExitZero) {
  test::CommandResult help = runDpoint({"--help"});
  EXPECT_EQ(help.exit_code, 0);
  for (const char* word : {"generate", "convert", "info", "Exit codes"})
    EXPECT_NE(help.out.find(word), std::string::npos) << word;
  test::CommandResult version = runDpoint({"--version"});
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.out.find("dpoint 0."), std::string::npos) << version.out;
  EXPECT_EQ(runDpoint({"convert", "--help"}).exit_code, 0);
}

TEST(Cli, usageErrorsExitOne) {
  EXPECT_EQ(runDpoint({}).exit_code, 1);
  EXPECT_EQ(runDpoint({"frobnicate"}).exit_code, 1);
  EXPECT_EQ(runDpoint({"generate", "random2d", "--count", "10"}).exit_code, 1);  // no -o
  EXPECT_EQ(runDpoint({"generate", "random2d", "--count", "-5", "-o", "/tmp/x.csv"}).exit_code, 1);
  test::CommandResult r = runDpoint({"generate", "random2d", "--bogus", "-o", "/tmp/x.csv"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--bogus"), std::string::npos) << r.err;
  TempDir dir;
  test::CommandResult ext = runDpoint({"generate", "random2d", "--count", "10", "-o", dir.file("a.dat")});
  EXPECT_EQ(ext.exit_code, 1);
  EXPECT_NE(ext.err.find("unknown file type '.dat'"), std::string::npos) << ext.err;
  EXPECT_TRUE(dir.entries().empty());
}

struct BadInput {
  std::string name;      // file name (its extension picks the reader)
  std::string content;   // empty with `folder` / `missing`
  std::vector<std::string> expected;  // parts of the one-line message
  bool folder = false;
  bool missing = false;
};

std::string binaryPly(int vertices_declared, int vertices_written) {
  std::string s = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(vertices_declared) +
                  "\nproperty double x\nproperty double y\nproperty double z\nend_header\n";
  for (int i = 0; i < vertices_written * 3; ++i) {
    double v = i;
    s.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  return s;
}

TEST(Cli, benchRefusesUnknownSuiteBackendFramesAndSizesBeforeDrawing) {
  test::TempDir dir;
  const std::vector<std::vector<std::string>> bad = {
      {"--suite", "fast"}, {"--backend", "vertex"}, {"--frames", "0"}, {"--suite", "paper", "--sizes", "3M"},
      {"--suite", "ci", "--sizes", "1M"}};
  for (const std::vector<std::string>& flags : bad) {
    std::vector<std::string> args = {"bench", "--out", dir.file("out"), "--cache", dir.file("cache")};
    args.insert(args.end(), flags.begin(), flags.end());
    test::CommandResult r = runDpoint(args);
    EXPECT_EQ(r.exit_code, 1) << flags[1];
    EXPECT_NE(r.err.find(flags[flags.size() - 2]), std::string::npos) << "names the flag: " << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir.file("out"))) << "nothing written for " << flags[1];
    EXPECT_FALSE(std::filesystem::exists(dir.file("cache"))) << "nothing made for " << flags[1];
  }
  test::CommandResult sizes = runDpoint({"bench", "--suite", "paper", "--sizes", "3M"});
  EXPECT_NE(sizes.err.find("16.7M"), std::string::npos) << "lists the sizes there are: " << sizes.err;
}

// The copy bandwidth alone: both copies measured and named; a bad size is refused with the flag.
TEST(Cli, benchCopyMeasuresBothCopiesAndRefusesABadSize) {
  test::CommandResult r = runDpoint({"bench", "copy", "--copy-bytes", "8M", "--copy-repeats", "3", "--validate"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("read+write"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("8.0 MiB vkCmdCopyBuffer, median of 3"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("compute-shader copy"), std::string::npos) << r.out;
  test::CommandResult bad = runDpoint({"bench", "copy", "--copy-bytes", "lots"});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("--copy-bytes"), std::string::npos) << bad.err;
}

TEST(Cli, badInputExitsTwoWithOneLineAndWritesNothing) {
  std::string garbage;
  std::mt19937 rng(11);
  for (int i = 0; i < 2000; ++i) garbage += static_cast<char>(rng() & 0xff);
  garbage[3] = '\0';
  const std::vector<BadInput> cases = {
      {"missing.csv", "", {"missing.csv", "not found"}, false, true},
      {"folder.csv", "", {"folder.csv", "folder"}, true},
      {"empty.csv", "", {"empty.csv", "empty"}},
      {"columns.csv", "x,y,z\n1,2,3\n1,2,3\n1,2,3,4\n", {"columns.csv:4:", "4 columns, expected 3"}},
      {"text.csv", "x,y,z\n1,2,3\n1,two,3\n", {"text.csv:3:", "column 2", "'two'"}},
      {"nan.csv", "x,y,z\n1,2,3\n1,2,nan\n", {"nan.csv:3:", "column 3", "'nan'", "--allow-nonfinite"}},
      {"inf.csv", "x,y\ninf,2\n", {"inf.csv:2:", "column 1", "'inf'"}},
      {"range.csv", "x,y,z\n1,2,3e400\n", {"range.csv:2:", "column 3", "'3e400'", "out of double range"}},
      {"long.csv", "x,y,z\n" + std::string(1 << 20, '1') + ",2,3\n", {"long.csv:2:", "longer than"}},
      {"garbage.csv", garbage, {"garbage.csv:1:"}},
      {"truncated.ply", binaryPly(10, 7), {"truncated.ply", "truncated"}},
      {"type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nproperty float y\nproperty float z\nend_header\n1 2 3\n",
       {"type.ply", "float128"}},
      {"garbage.ply", garbage, {"garbage.ply"}},
  };
  for (const BadInput& c : cases) {
    SCOPED_TRACE(c.name);
    TempDir dir;
    const std::string in = dir.file(c.name);
    if (c.folder) std::filesystem::create_directory(in);
    else if (!c.missing) writeFile(in, c.content);
    const auto before = dir.entries();
    for (const char* out : {"out.ply", "out.csv", "out.glb"}) {
      test::CommandResult r = runDpoint({"convert", in, "-o", dir.file(out)});
      EXPECT_EQ(r.exit_code, 2) << r.err;
      EXPECT_EQ(lineCount(r.err), 1u) << r.err;
      for (const std::string& part : c.expected) EXPECT_NE(r.err.find(part), std::string::npos) << r.err << " lacks " << part;
      EXPECT_EQ(dir.entries(), before) << "something was written";
    }
    EXPECT_EQ(runDpoint({"info", in}).exit_code, 2);
  }
}

TEST(Cli, allowNonfiniteAcceptsNan) {
  TempDir dir;
  writeFile(dir.file("nan.csv"), "x,y,z\n1,2,nan\n");
  test::CommandResult r = runDpoint({"convert", dir.file("nan.csv"), "--allow-nonfinite", "-o", dir.file("out.csv")});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(readFile(dir.file("out.csv")), "x,y,z\n1,2,nan\n");
}

TEST(Cli, unwritableOutputGivesClearErrorAndNoFile) {
  TempDir dir;
  writeFile(dir.file("in.csv"), "x,y,z\n1,2,3\n");
  // -o is checked as it is parsed, before the input is read: a usage error, as for every command.
  test::CommandResult missing = runDpoint({"convert", dir.file("in.csv"), "-o", dir.file("no/where/out.csv")});
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("does not exist"), std::string::npos) << missing.err;
  test::CommandResult proc = runDpoint({"convert", dir.file("in.csv"), "-o", "/proc/dpoint-out.csv"});
  EXPECT_EQ(proc.exit_code, 1);
  EXPECT_NE(proc.err.find("/proc"), std::string::npos) << proc.err;
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"in.csv"});
}

TEST(Cli, random2dMatchesGoldenForOneAndTwoThreads) {
  TempDir dir;
  for (const char* threads : {"1", "2"}) {
    const std::string out = dir.file(std::string("r") + threads + ".csv");
    test::CommandResult r = runDpoint({"generate", "random2d", "--count", "1000", "--seed", "42", "--threads", threads, "-o", out});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(readFile(out) == readFile(DPOINT_SAMPLES_DIR "/golden/random2d_n1000_s42.csv")) << threads;
  }
  // Larger sets span many chunks; still identical across thread counts.
  for (const char* threads : {"1", "2"}) {
    ASSERT_EQ(runDpoint({"generate", "random2d", "--count", "200000", "--threads", threads, "-o",
                         dir.file(std::string("big") + threads + ".csv")}).exit_code, 0);
  }
  EXPECT_TRUE(readFile(dir.file("big1.csv")) == readFile(dir.file("big2.csv")));
}

TEST(Cli, random2dRefusesOverMemoryLimitWithExitFour) {
  TempDir dir;
  test::CommandResult r = runDpoint({"generate", "random2d", "--count", "10000000", "--max-memory", "10M", "-o", dir.file("a.csv")});
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_NE(r.err.find("needs about"), std::string::npos) << r.err;
  EXPECT_TRUE(dir.entries().empty());
}

TEST(Cli, sigkillWhileWritingLeavesNoFile) {
  TempDir dir;
  const std::string out = dir.file("big.csv");
  pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::execl(DPOINT_EXE, DPOINT_EXE, "generate", "random2d", "--count", "40000000", "--threads", "1", "--quiet", "-o",
            out.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  // Wait until 20 MB of the ~1.6 GB file are written, then kill.
  bool writing = false;
  for (int i = 0; i < 3000 && !writing; ++i) {
    writing = test::bytesWrittenBy(pid) > (20u << 20);
    if (!writing) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(writing) << "the writer never got going";
  ASSERT_TRUE(WIFSIGNALED(status)) << "the writer finished before it was killed";
  EXPECT_TRUE(dir.entries().empty()) << "left: " << (dir.entries().empty() ? "" : dir.entries()[0]);
}

TEST(Cli, convertRoundTripsCsvPlyGlb) {
  TempDir dir;
  // Millimetre detail at the Earth's radius, with colours.
  std::string csv = "x,y,z,r,g,b\n";
  std::mt19937_64 rng(5);
  PointSet original;
  for (int i = 0; i < 2000; ++i) {
    glm::dvec3 p(6378137.0 + static_cast<double>(rng() % 100000) * 1e-3, -1234.5 + static_cast<double>(rng() % 1000) * 1e-3,
                 static_cast<double>(rng() % 7919) * 1e-4);
    original.positions.push_back(p);
    original.colors.emplace_back(static_cast<float>(rng() % 256) / 255.0f, static_cast<float>(rng() % 256) / 255.0f, 128.0f / 255.0f);
  }
  ASSERT_TRUE(writeCsv(dir.file("a.csv"), original).ok());
  for (const char* ply_args : {"", "--ply-ascii"}) {
    std::vector<std::string> args = {"convert", dir.file("a.csv"), "-o", dir.file("b.ply")};
    if (*ply_args) args.push_back(ply_args);
    ASSERT_EQ(runDpoint(args).exit_code, 0);
    test::CommandResult back = runDpoint({"convert", dir.file("b.ply"), "-o", dir.file("c.csv")});
    ASSERT_EQ(back.exit_code, 0) << back.err;
    EXPECT_TRUE(readFile(dir.file("a.csv")) == readFile(dir.file("c.csv"))) << ply_args;
  }
  ASSERT_EQ(runDpoint({"convert", dir.file("b.ply"), "-o", dir.file("d.glb")}).exit_code, 0);
  test::CommandResult back = runDpoint({"convert", dir.file("d.glb"), "-o", dir.file("e.csv")});
  ASSERT_EQ(back.exit_code, 0) << back.err;
  Result<PointSet> glb = readCsv(dir.file("e.csv"));
  ASSERT_TRUE(glb.ok()) << glb.error().message;
  ASSERT_EQ(glb->size(), original.size());
  // Extent ~100 m far from the origin: POSITION alone is float of the extent (~7.6e-6 m steps),
  // and with the _POSITION_LOW residuals dpoint reads every double back exactly.
  for (size_t i = 0; i < original.size(); ++i) {
    ASSERT_EQ(glb->positions[i], original.positions[i]) << i;
    ASSERT_EQ(glb->colors[i], original.colors[i]);
  }
}

// --order morton on every path convert takes, the glTF-to-CSV stream included (which must then
// build the whole set); an unknown order is a usage error that writes nothing.
TEST(Cli, convertOrdersPointsMortonAndRefusesAnUnknownOrder) {
  TempDir dir;
  PointSet original;
  std::mt19937_64 rng(11);
  for (int i = 0; i < 9000; ++i) {
    original.positions.emplace_back(1e8 + static_cast<double>(rng() % 100000) * 1e-8,
                                    static_cast<double>(rng() % 1000), static_cast<double>(rng() % 7));
    original.colors.emplace_back(static_cast<float>(i % 256) / 255.0f, 0.5f, 1.0f);
  }
  ASSERT_TRUE(writeCsv(dir.file("a.csv"), original).ok());
  ASSERT_EQ(runDpoint({"convert", dir.file("a.csv"), "-o", dir.file("a.glb")}).exit_code, 0);
  for (const char* input : {"a.csv", "a.glb"}) {
    SCOPED_TRACE(input);
    for (const char* order : {"input", "morton"}) {
      test::CommandResult r = runDpoint({"convert", dir.file(input), "-o", dir.file(order + std::string(".csv")),
                                         "--order", order});
      ASSERT_EQ(r.exit_code, 0) << r.err;
    }
    Result<PointSet> as_read = readCsv(dir.file("input.csv")), morton = readCsv(dir.file("morton.csv"));
    ASSERT_TRUE(as_read.ok() && morton.ok());
    ASSERT_EQ(as_read->size(), original.size());
    PointSet expected = *as_read;
    reorderPoints(expected, PointOrder::kMorton, 1);
    EXPECT_FALSE(morton->positions == as_read->positions) << "nothing moved";
    EXPECT_TRUE(morton->positions == expected.positions);
    EXPECT_TRUE(morton->colors == expected.colors);
  }
  test::CommandResult bad = runDpoint({"convert", dir.file("a.csv"), "-o", dir.file("bad.csv"), "--order", "bogus"});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("--order bogus: must be input or morton"), std::string::npos) << bad.err;
  EXPECT_FALSE(test::fileExists(dir.file("bad.csv")));
}

TEST(Cli, infoReportsFloatMergesAsJson) {
  TempDir dir;
  std::string csv = "x,y,z\n";
  for (int i = 0; i < 1000; ++i) csv += "6378000." + std::to_string(1000 + i).substr(1) + ",0,0\n";
  writeFile(dir.file("a.csv"), csv);
  test::CommandResult r = runDpoint({"info", dir.file("a.csv"), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"points\": 1000"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"float32_represents\": false"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"float32_spacing\": 0.5"), std::string::npos) << r.out;
  const size_t key = r.out.find("\"min_neighbor_distance\": ");
  ASSERT_NE(key, std::string::npos) << r.out;
  EXPECT_NEAR(std::stod(r.out.substr(key + 25)), 0.001, 1e-6);
  test::CommandResult text = runDpoint({"info", dir.file("a.csv")});
  EXPECT_NE(text.out.find("float32 enough:     no"), std::string::npos) << text.out;
}

// --columns is read by info and render as by convert: a headerless file whose first column is an
// intensity is refused without it (naming the option), and read with it.
TEST(Cli, infoAndRenderTakeColumnsAsConvertDoes) {
  TempDir dir;
  writeFile(dir.file("a.xyz"), "7 1.5 2.5 3.5\n9 4.5 5.5 6.5\n8 2 3 4\n");
  test::CommandResult plain = runDpoint({"info", dir.file("a.xyz"), "--json"});
  EXPECT_EQ(plain.exit_code, 2);
  EXPECT_NE(plain.err.find("a.xyz:1: 4 columns without a header"), std::string::npos) << plain.err;
  EXPECT_NE(plain.err.find("--columns"), std::string::npos) << plain.err;
  test::CommandResult info = runDpoint({"info", dir.file("a.xyz"), "--columns", "intensity,x,y,z", "--json"});
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_NE(info.out.find("\"min\": [1.5, 2.5, 3.5]"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("{\"name\": \"intensity\", \"type\": \"uint16\", \"min\": 7, \"max\": 9}"),
            std::string::npos)
      << info.out;
  test::CommandResult render = runDpoint({"render", dir.file("a.xyz"), "--columns", "intensity,x,y,z", "--color",
                                          "intensity", "--width", "64", "--height", "48", "-o", dir.file("a.png"),
                                          "--json", dir.file("a.json"), "-q"});
  ASSERT_EQ(render.exit_code, 0) << render.err;
  EXPECT_NE(test::readFile(dir.file("a.json")).find("\"points\": 3"), std::string::npos);
  test::CommandResult short_row = runDpoint({"render", dir.file("a.xyz"), "--columns", "q,x,y", "-o", dir.file("b.png")});
  EXPECT_EQ(short_row.exit_code, 2);
  EXPECT_NE(short_row.err.find("a.xyz:1: 4 columns, expected 3 (q,x,y)"), std::string::npos) << short_row.err;
  EXPECT_FALSE(test::fileExists(dir.file("b.png")));
}

// info prints each render mode's predicted error for a view: fp32 fails at a 1e-13 zoom of 0.74,
// native and batch do not; the camera flags are render's.
TEST(Cli, infoAdvisesEachModesErrorBoundForAView) {
  TempDir dir;
  writeFile(dir.file("zoom.csv"), "x,y\n-0.743645,0.1318259\n-0.74364500000001,0.13182590000001\n");
  test::CommandResult r = runDpoint({"info", dir.file("zoom.csv"), "--view-center", "-0.743645,0.1318259",
                                     "--view-width", "1e-13", "--width", "512", "--height", "512", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"error_bound_px\": {\"fp32\": "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"ortho\": true"), std::string::npos) << r.out;
  auto bound = [&](const std::string& mode) {
    size_t at = r.out.find("\"" + mode + "\": ", r.out.find("error_bound_px"));
    return std::strtod(r.out.c_str() + at + mode.size() + 4, nullptr);
  };
  EXPECT_GT(bound("fp32"), 0.5);
  EXPECT_GT(bound("rte"), 0.5) << "48 bits of 0.74 are several pixels at this zoom";
  EXPECT_LT(bound("native"), 1e-4);
  EXPECT_LT(bound("batch"), 1e-3);
  test::CommandResult text = runDpoint({"info", dir.file("zoom.csv"), "--view-center", "-0.743645,0.1318259",
                                        "--view-width", "1e-13"});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("error bound by mode"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("points leave their pixel"), std::string::npos) << text.out;
  EXPECT_EQ(runDpoint({"info", dir.file("zoom.csv"), "--view-width", "-1"}).exit_code, 1);
}

// bench io prints its one JSON line whole at the end: a write that fails leaves nothing on stdout
// (a review finding: an interrupted one left half an object there).
TEST(CliBench, ioPrintsItsLineWholeOrNotAtAll) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "random2d", "--count", "1000", "-q", "-o", dir.file("r.ply")}).exit_code, 0);
  std::filesystem::create_symlink("/dev/full", dir.file("full.csv"));
  const test::CommandResult failed = runDpoint({"bench", "io", dir.file("r.ply"), "--write", dir.file("full.csv")});
  EXPECT_EQ(failed.exit_code, 4) << failed.err;
  EXPECT_EQ(failed.out, "");
  const test::CommandResult timed = runDpoint({"bench", "io", dir.file("r.ply"), "--write", dir.file("w.csv")});
  EXPECT_EQ(timed.exit_code, 0) << timed.err;
  EXPECT_EQ(timed.out.rfind("{\"points\": 1000, \"read_s\": ", 0), 0u) << timed.out;
  EXPECT_NE(timed.out.find("\"write_MBps\": "), std::string::npos) << timed.out;
}

}  // namespace
}  // namespace dpoint
