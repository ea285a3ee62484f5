// dpoint generate as a user runs it: every kind writes what it says, bad parameters exit 1 or 4
// with the flag named, and nothing is written then.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "converters/csv.h"
#include "converters/ply.h"
#include "converters/point_io.h"
#include "ops/point_order.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::concat;
using test::readFile;
using test::runDpoint;
using test::TempDir;

TEST(CliGenerate, everyKindWritesAMeshOrPointSet) {
  struct Kind {
    std::vector<std::string> args;
    size_t vertices;   // 0: only check > 0
    size_t triangles;  // 0: a point set
  };
  const std::vector<Kind> kinds = {
      {{"mandelbulb", "--resolution", "64", "--frame", "seed"}, 13112, 1},
      {{"julia", "--resolution", "64", "--frame", "seed"}, 3844, 1},
      {{"menger", "--level", "2"}, 0, 2 * (2 * 400 + 4 * 64)},
      {{"menger", "--level", "2", "--method", "voxel", "--resolution", "27"}, 0, 1},
      {{"sierpinski", "--level", "3"}, 2 * 64 + 2, 4 * 64},
      {{"sierpinski", "--level", "3", "--unwelded"}, 4 * 64, 4 * 64},  // 4^(n+1) rows
      {{"mandelbrot2d", "--resolution", "32", "--max-iter", "300"}, 32 * 32, 0},
      {{"random2d", "--count", "500"}, 500, 0},
  };
  for (const Kind& k : kinds) {
    SCOPED_TRACE(k.args[0]);
    TempDir dir;
    std::vector<std::string> args = {"generate"};
    args.insert(args.end(), k.args.begin(), k.args.end());
    args.insert(args.end(), {"-o", dir.file("out.ply")});
    test::CommandResult r = runDpoint(args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    Result<PointSet> points = readPly(dir.file("out.ply"));
    ASSERT_TRUE(points.ok()) << points.error().message;
    EXPECT_GT(points->size(), 0u);
    if (k.vertices) {
      EXPECT_EQ(points->size(), k.vertices);
    }
    if (k.triangles > 1) {
      EXPECT_EQ(points->triangles.size() / 3, k.triangles);
    } else if (k.triangles == 1) {
      EXPECT_GT(points->triangles.size(), 0u);
    } else {
      EXPECT_TRUE(points->triangles.empty());
    }
    EXPECT_EQ(points->hasColors(), k.args[0] != "random2d");
  }
}

TEST(CliGenerate, gridOutOfTheSeedVariantEqualsTheReference) {
  TempDir dir;
  test::CommandResult r = runDpoint({"generate", "mandelbulb", "--resolution", "64", "--variant", "seed", "--grid-out",
                                     dir.file("grid.u8"), "-o", dir.file("m.csv"), "--colors", "none"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(readFile(dir.file("grid.u8")) == readFile(DPOINT_REFERENCE_DIR "/mandelbulb_r64_i100_escape.u8"));
  r = runDpoint({"generate", "julia", "--resolution", "64", "--grid-out", dir.file("j.u8"), "-o", dir.file("j.csv")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(readFile(dir.file("j.u8")) == readFile(DPOINT_REFERENCE_DIR "/julia_r64_i200_escape.u8"));
}

// A review finding: a run whose output failed left the --grid-out file it had written, and
// `--grid-out X -o X` kept only one of them. Now the output never is the grid, a failed run takes
// its grid away again, and a grid file that was there before a run refused up front stays.
TEST(CliGenerate, aFailedRunLeavesNoGridAndTheGridIsNeverTheOutput) {
  TempDir dir;
  std::filesystem::create_symlink("/dev/full", dir.file("full.ply"));  // writing it fails: no space
  test::CommandResult failed =
      runDpoint({"generate", "mandelbulb", "--resolution", "20", "--grid-out", dir.file("g.bin"), "-o", dir.file("full.ply")});
  EXPECT_EQ(failed.exit_code, 4) << failed.err;  // a full disk: a resource limit
  EXPECT_NE(failed.err.find("No space left on device"), std::string::npos) << failed.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("g.bin")));
  test::writeFile(dir.file("kept.bin"), "before");
  test::CommandResult refused = runDpoint({"generate", "julia", "--resolution", "20", "--grid-out", dir.file("kept.bin"),
                                           "-o", dir.file("no-such-folder/x.ply")});
  EXPECT_EQ(refused.exit_code, 1) << refused.err;
  EXPECT_EQ(readFile(dir.file("kept.bin")), "before");
  test::CommandResult same =
      runDpoint({"generate", "mandelbulb", "--resolution", "20", "--grid-out", dir.file("x.ply"), "-o", dir.file("x.ply")});
  EXPECT_EQ(same.exit_code, 1);
  EXPECT_NE(same.err.find("--grid-out " + dir.file("x.ply") + ": is also -o"), std::string::npos) << same.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("x.ply")));
  test::CommandResult missing = runDpoint({"generate", "mandelbrot2d", "--resolution", "64", "--grid-out",
                                           dir.file("no-such-folder/g.bin"), "-o", dir.file("m.ply")});
  EXPECT_EQ(missing.exit_code, 1) << "checked before the work, as -o is";
  EXPECT_FALSE(std::filesystem::exists(dir.file("m.ply")));
}

TEST(CliGenerate, offsetTranslatesExactlyAndKeepsColours) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "sierpinski", "--level", "2", "-o", dir.file("a.csv")}).exit_code, 0);
  ASSERT_EQ(runDpoint({"generate", "sierpinski", "--level", "2", "--offset", "6378137,-1e8,0.5", "-o", dir.file("b.csv")})
                .exit_code,
            0);
  Result<PointSet> a = readCsv(dir.file("a.csv")), b = readCsv(dir.file("b.csv"));
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a->size(), b->size());
  for (size_t i = 0; i < a->size(); ++i) {
    EXPECT_EQ(b->positions[i], a->positions[i] + glm::dvec3(6378137.0, -1e8, 0.5));
    EXPECT_EQ(b->colors[i], a->colors[i]);  // colours come from the untranslated fractal
  }
}

// A 2D kind lifted off z = 0 by --offset has a z: every format writes it (a set marked 2D by its
// generator once lost it here).
TEST(CliGenerate, anOffsetInZGivesA2dKindItsZ) {
  TempDir dir;
  for (const char* kind : {"random2d", "mandelbrot2d"}) {
    SCOPED_TRACE(kind);
    const std::vector<std::string> size = std::string(kind) == "random2d" ? std::vector<std::string>{"--count", "5"}
                                                                           : std::vector<std::string>{"--resolution", "4"};
    for (const char* ext : {".csv", ".ply"}) {
      const std::string out = dir.file(std::string("lifted") + ext);
      ASSERT_EQ(runDpoint(test::concat(test::concat({"generate", kind}, size), {"--offset", "0,0,5", "-q", "-o", out})).exit_code,
                0);
      Result<PointSet> back = readPoints(out);
      ASSERT_TRUE(back.ok()) << back.error().message;
      EXPECT_TRUE(back->hasZ()) << ext;
      for (const glm::dvec3& p : back->positions) EXPECT_EQ(p.z, 5.0) << ext;
    }
  }
}

// random2d into a .ply makes its points as the rows are written (no array of them); the file is
// the one the held set gives: byte for byte what `convert` writes from the held path's CSV (input
// and Morton order), and, with an offset or noise colours, the same points and colours as the
// held path's CSV in the same order, for 1 and 2 threads.
TEST(CliGenerate, random2dMadeAsWrittenIsTheHeldSetsFile) {
  TempDir dir;
  const std::vector<std::string> base = {"generate", "random2d", "--count", "20000", "--seed", "9"};
  ASSERT_EQ(runDpoint(test::concat(base, {"-q", "-o", dir.file("held.csv")})).exit_code, 0);
  for (const char* order : {"input", "morton"}) {
    SCOPED_TRACE(order);
    ASSERT_EQ(runDpoint(test::concat(base, {"-q", "--order", order, "-o", dir.file("made.ply")})).exit_code, 0);
    ASSERT_EQ(runDpoint({"convert", dir.file("held.csv"), "--order", order, "-q", "-o", dir.file("held.ply")}).exit_code, 0);
    EXPECT_TRUE(readFile(dir.file("made.ply")) == readFile(dir.file("held.ply")));
  }
  for (const std::vector<std::string>& dress :
       {std::vector<std::string>{"--offset", "1e9,-3,0.25"}, std::vector<std::string>{"--colors", "noise"}}) {
    const std::vector<std::string> dressed = test::concat(test::concat(base, {"--order", "morton"}), dress);
    ASSERT_EQ(runDpoint(test::concat(dressed, {"-q", "-o", dir.file("held.csv")})).exit_code, 0);
    Result<PointSet> held = readPoints(dir.file("held.csv"));
    ASSERT_TRUE(held.ok()) << held.error().message;
    EXPECT_EQ(held->hasColors(), dress[0] == "--colors");
    for (const char* threads : {"1", "2"}) {
      SCOPED_TRACE(dress[0] + " " + threads);
      test::CommandResult r = runDpoint(test::concat(dressed, {"--threads", threads, "-o", dir.file("made.ply")}));
      ASSERT_EQ(r.exit_code, 0) << r.err;
      EXPECT_NE(r.err.find("the points made as the rows were written"), std::string::npos) << r.err;
      Result<PointSet> made = readPoints(dir.file("made.ply"));
      ASSERT_TRUE(made.ok()) << made.error().message;
      ASSERT_EQ(made->size(), held->size());
      EXPECT_TRUE(made->positions == held->positions);
      ASSERT_EQ(made->colors.size(), held->colors.size());
      for (size_t i = 0; i < made->colors.size(); ++i)  // the CSV keeps floats, the PLY bytes
        for (int k = 0; k < 3; ++k)
          ASSERT_EQ(colorInteger(made->colors[i][k], 255), colorInteger(held->colors[i][k], 255)) << i;
      EXPECT_EQ(made->hasZ(), dress[0] == "--offset");
    }
  }
}

// More points than an order holds: refused before any work, naming the count, nothing written.
TEST(CliGenerate, anOrderOfMoreThan2To32PointsIsRefused) {
  TempDir dir;
  test::CommandResult r = runDpoint(
      {"generate", "random2d", "--count", "4294967296", "--order", "morton", "-o", dir.file("big.ply")});
  EXPECT_EQ(r.exit_code, static_cast<int>(ExitCode::kResourceLimit));
  EXPECT_NE(r.err.find("4294967296 points"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("big.ply")));
}

// A file larger than the disk: refused before any row is made (random2d's rows are made as they are
// written into a .ply), naming what it takes and what is free, exit 4, nothing left: 2^40 points
// are 24 TiB. Run under a file-size limit of 1 MiB, so that a writer without the check stops there
// (SIGXFSZ) instead of filling the disk. (Into other formats the points are held first, and
// --max-memory refuses so many.)
TEST(CliGenerate, aFileLargerThanTheDiskIsRefusedBeforeAnyWork) {
  TempDir dir;
  for (const char* name : {"big.ply"}) {
    const test::CommandResult r = test::runCommand(
        {"/bin/sh", "-c", std::string("ulimit -f 2048; exec \"$0\" \"$@\""), DPOINT_EXE, "generate", "random2d",
         "--count", "1099511627776", "-o", dir.file(name)},
        std::chrono::seconds(120));
    EXPECT_EQ(r.exit_code, static_cast<int>(ExitCode::kResourceLimit)) << name << ": " << r.err;
    EXPECT_NE(r.err.find("cannot write '" + dir.file(name) + "': it takes at least "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(" free"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir.file(name))) << name;
  }
}

// Each format whose size is known before writing, on a file system of 1 MiB (a tmpfs, where this
// machine lets the test mount one): the Menger sponge's 3-21 MiB are refused at once, naming the
// file, what it takes and what is free, and nothing is left; a small set is written.
TEST(CliGenerate, eachFormatLargerThanTheDiskIsRefused) {
  TempDir dir;
  const std::string small = dir.file("small");
  std::filesystem::create_directory(small);
  if (test::runCommand({"/bin/mount", "-t", "tmpfs", "-o", "size=1m", "tmpfs", small}).exit_code != 0)
    GTEST_SKIP() << "cannot mount a 1 MiB tmpfs here";
  struct Unmount {
    std::string path;
    ~Unmount() { test::runCommand({"/bin/umount", path}); }
  } unmount{small};
  for (const char* name : {"m.ply", "m.las", "m.csv", "m.glb", "m.pcd", "m.xyz", "m.pts"}) {
    const std::string path = small + "/" + name;
    const test::CommandResult r = runDpoint({"generate", "menger", "-q", "-o", path});
    EXPECT_EQ(r.exit_code, static_cast<int>(ExitCode::kResourceLimit)) << name << ": " << r.err;
    EXPECT_NE(r.err.find("cannot write '" + path + "': it takes at least "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("has 1.0 MiB free"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(path)) << name;
  }
  // The device's rows, written as they are meshed: 4.8 MiB estimated, refused for half of it.
  const std::string julia = small + "/j.ply";
  const test::CommandResult rows = runDpoint(
      {"generate", "julia", "--resolution", "192", "--device", "0", "--mesh", "device", "-q", "-o", julia});
  EXPECT_EQ(rows.exit_code, static_cast<int>(ExitCode::kResourceLimit)) << rows.err;
  EXPECT_NE(rows.err.find("cannot write '" + julia + "': it takes at least 2.4 MiB"), std::string::npos) << rows.err;
  EXPECT_FALSE(std::filesystem::exists(julia));
  const test::CommandResult fits =
      runDpoint({"generate", "sierpinski", "--level", "3", "-q", "-o", small + "/s.ply"});
  EXPECT_EQ(fits.exit_code, 0) << fits.err;
  EXPECT_TRUE(std::filesystem::exists(small + "/s.ply"));
}

// A sponge or an offset whose coordinates leave double's range is refused, exit 1, nothing
// written: the build before wrote "inf" coordinates and "nan" colours that no reader takes.
TEST(CliGenerate, coordinatesBeyondDoublesRangeAreRefused) {
  TempDir dir;
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"generate", "menger", "--level", "1", "--size", "1e308", "-o", dir.file("m.csv")},
        std::vector<std::string>{"generate", "menger", "--level", "1", "--size", "1e307", "--offset", "1.75e308,0,0",
                                 "-o", dir.file("m.csv")}}) {
    const test::CommandResult r = runDpoint(args);
    EXPECT_EQ(r.exit_code, static_cast<int>(ExitCode::kUsage)) << r.err;
    EXPECT_NE(r.err.find("double's range"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir.file("m.csv")));
  }
  // Beyond float's range but within double's: written, its noise colours finite (they were "nan":
  // the noise took the coordinates as floats).
  ASSERT_EQ(runDpoint({"generate", "menger", "--level", "2", "--size", "1e40", "-q", "-o", dir.file("big.csv")}).exit_code, 0);
  const std::string csv = readFile(dir.file("big.csv"));
  EXPECT_EQ(csv.find("nan"), std::string::npos);
  EXPECT_EQ(csv.find("inf"), std::string::npos);
  EXPECT_EQ(runDpoint({"convert", dir.file("big.csv"), "-o", dir.file("big.ply")}).exit_code, 0);
}

TEST(CliGenerate, outputIsIdenticalForOneAndTwoThreads) {
  TempDir dir;
  for (const char* threads : {"1", "2"}) {
    for (const std::vector<std::string>& kind :
         {std::vector<std::string>{"mandelbulb", "--resolution", "48", "--variant", "fast"},
          std::vector<std::string>{"mandelbrot2d", "--resolution", "48", "--width", "1e-9"},
          std::vector<std::string>{"menger", "--level", "3"}}) {
      std::vector<std::string> args = {"generate"};
      args.insert(args.end(), kind.begin(), kind.end());
      args.insert(args.end(), {"--threads", threads, "-o", dir.file(kind[0] + threads + ".ply")});
      ASSERT_EQ(runDpoint(args).exit_code, 0);
    }
  }
  for (const char* kind : {"mandelbulb", "mandelbrot2d", "menger"})
    EXPECT_TRUE(readFile(dir.file(std::string(kind) + "1.ply")) == readFile(dir.file(std::string(kind) + "2.ply"))) << kind;
}

// --order morton writes the set --order input writes, reordered: the same points with their
// colours, the same triangles over them, in the library's Morton order.
TEST(CliGenerate, mortonOrderWritesTheSameMeshReordered) {
  TempDir dir;
  for (const char* order : {"input", "morton"}) {
    test::CommandResult r = runDpoint({"generate", "sierpinski", "--level", "6", "--order", order, "--threads", "2",
                                       "-o", dir.file(std::string(order) + ".ply")});
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  Result<PointSet> input = readPly(dir.file("input.ply")), morton = readPly(dir.file("morton.ply"));
  ASSERT_TRUE(input.ok() && morton.ok());
  ASSERT_EQ(morton->size(), input->size());
  ASSERT_GT(input->size(), 2 * kOrderBlock);  // whole blocks to shuffle and a partial one
  ASSERT_TRUE(input->hasColors() && input->isMesh());
  EXPECT_FALSE(morton->positions == input->positions) << "nothing moved";

  ASSERT_EQ(morton->triangles.size(), input->triangles.size());
  for (size_t i = 0; i < input->triangles.size(); ++i) {
    ASSERT_EQ(morton->positions[morton->triangles[i]], input->positions[input->triangles[i]]) << "corner " << i;
    ASSERT_EQ(morton->colors[morton->triangles[i]], input->colors[input->triangles[i]]) << "corner " << i;
  }
  PointSet expected = *input;
  reorderPoints(expected, PointOrder::kMorton, 1);
  EXPECT_TRUE(morton->positions == expected.positions);
  EXPECT_TRUE(morton->colors == expected.colors);
  EXPECT_TRUE(morton->triangles == expected.triangles);
}

TEST(CliGenerate, badParametersNameTheFlagAndWriteNothing) {
  struct Bad {
    std::vector<std::string> args;
    int exit_code;
    std::string expected;
  };
  const std::vector<Bad> cases = {
      {{"mandelbulb", "--resolution", "1"}, 1, "--resolution"},
      {{"mandelbulb", "--resolution", "70000"}, 1, "--resolution 70000: must be 2..65536"},
      {{"mandelbulb", "--max-iter", "0"}, 1, "--max-iter"},
      {{"mandelbulb", "--resolution", "16", "--level", "100"}, 1, "--level"},
      {{"mandelbulb", "--resolution", "16", "--level", "-3"}, 1, "--level"},
      {{"mandelbulb", "--bounds", "1,oops"}, 1, "--bounds"},
      {{"julia", "--c", "1,2,3"}, 1, "--c"},
      {{"julia", "--c", "nan,0,0,0"}, 1, "--c"},
      {{"mandelbrot2d", "--center", "0.3"}, 1, "--center"},
      {{"mandelbrot2d", "--width", "0"}, 1, "--width"},
      {{"mandelbrot2d", "--max-iter", "0"}, 1, "--max-iter 0: must be a whole number from 1"},
      {{"mandelbrot2d", "--max-iter", "abc"}, 1, "--max-iter abc: must be a whole number from 1 to 2147483647, or auto"},
      {{"mandelbrot2d", "--max-iter", "2.5"}, 1, "--max-iter"},
      {{"mandelbrot2d", "--max-iter", "-3"}, 1, "--max-iter"},
      {{"mandelbrot2d", "--max-iter", "99999999999"}, 1, "--max-iter"},
      {{"mandelbrot2d", "--max-iter", "Auto"}, 1, "--max-iter"},
      {{"sierpinski", "--level", "13"}, 1, "--level"},
      {{"sierpinski", "--offset", "1,2"}, 1, "--offset"},
      {{"menger", "--level", "8"}, 4, "--max-memory"},
      {{"menger", "--level", "5", "--max-memory", "1M"}, 4, "--max-memory"},
      {{"random2d", "--max-memory", "lots"}, 1, "--max-memory"},
      {{"mandelbulb", "--variant", "fastest"}, 1, "--variant"},
      {{"random2d", "--order", "bogus"}, 1, "--order"},
      {{"sierpinski", "--level", "2", "--order", "Morton"}, 1, "--order"},
      {{"spiral"}, 1, "spiral"},
  };
  for (const Bad& c : cases) {
    SCOPED_TRACE(c.args[0] + " " + (c.args.size() > 1 ? c.args[1] : ""));
    TempDir dir;
    std::vector<std::string> args = {"generate"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    args.insert(args.end(), {"-o", dir.file("out.csv")});
    test::CommandResult r = runDpoint(args);
    EXPECT_EQ(r.exit_code, c.exit_code) << r.err;
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << r.err;
    EXPECT_TRUE(dir.entries().empty());
  }
}

// --max-iter of mandelbrot2d takes a whole number or auto (the default), and generate says what
// auto chose; the help says how it is chosen.
TEST(CliGenerate, mandelbrot2dMaxIterAutoIsTheDefaultAndNamesItsValue) {
  TempDir dir;
  const std::vector<std::string> base = {"generate", "mandelbrot2d", "--resolution", "16", "--width", "1e-12"};
  test::CommandResult r = runDpoint(concat(base, {"-o", dir.file("default.ply")}));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("dpoint: mandelbrot2d --max-iter auto: 7941 at --width 1e-12"), std::string::npos) << r.err;
  r = runDpoint(concat(base, {"--max-iter", "auto", "-o", dir.file("auto.ply")}));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(readFile(dir.file("default.ply")) == readFile(dir.file("auto.ply")));
  r = runDpoint(concat(base, {"--max-iter", "7941", "-o", dir.file("explicit.ply")}));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("--max-iter auto"), std::string::npos) << r.err;
  EXPECT_TRUE(readFile(dir.file("default.ply")) == readFile(dir.file("explicit.ply")));
  r = runDpoint(concat(base, {"--max-iter", "500", "-q", "-o", dir.file("500.ply")}));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  r = runDpoint({"generate", "mandelbrot2d", "--help"});
  EXPECT_NE(r.out.find("max(2000, 50*d^2)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("d = log10(4 / width)"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace dpoint
