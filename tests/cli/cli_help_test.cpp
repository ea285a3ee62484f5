// A CLI that helps (issue #24): a mistyped command, kind, option or value is named with the nearest
// known one; `dpoint` alone lists the commands; -o is checked before any work; the sizes asked for
// are the sizes written; one list of output formats.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "cli/cli_suggest.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::concat;
using test::contains;
using test::readFile;
using test::runDpoint;
using test::TempDir;
using test::writeFile;

size_t lines(const std::string& text) { return size_t(std::count(text.begin(), text.end(), '\n')); }

TEST(CliSuggest, editDistanceCountsASwapOfNeighboursAsOne) {
  EXPECT_EQ(editDistance("", "abc"), 3u);
  EXPECT_EQ(editDistance("render", "render"), 0u);
  EXPECT_EQ(editDistance("rendr", "render"), 1u);
  EXPECT_EQ(editDistance("mandlebulb", "mandelbulb"), 1u) << "le/el is one swap";
  EXPECT_EQ(editDistance("colour", "color"), 1u);
  EXPECT_EQ(editDistance("kitten", "sitting"), 3u);
}

TEST(CliSuggest, closestMatchTakesTheNearestOrAPrefixAndNothingFarOff) {
  const std::vector<std::string> modes = {"auto", "fp32", "split", "rte", "df64", "native", "batch"};
  EXPECT_EQ(closestMatch("natve", modes), "native");
  EXPECT_EQ(closestMatch("df46", modes), "df64");
  EXPECT_EQ(closestMatch("nat", modes), "native") << "a prefix of 3 characters";
  EXPECT_EQ(closestMatch("zzzzzz", modes), std::nullopt);
  EXPECT_EQ(closestMatch("x", modes), std::nullopt) << "a one-letter word is not corrected";
  EXPECT_EQ(closestMatch("--colour", {"--color", "--background"}), "--color");
  EXPECT_EQ(didYouMean("rendr", {"generate", "render"}), "; did you mean 'render'?");
  EXPECT_EQ(didYouMean("qqqq", {"generate", "render"}), "");
}

// Each mistake ends with one line naming the mistyped word and the nearest known one, exit 1.
TEST(CliHelp, mistypedWordsGetOneLineWithTheNearestKnownOne) {
  TempDir dir;
  writeFile(dir.file("one.csv"), "x,y,z\n1,2,3\n4,5,6\n");
  struct Case {
    std::vector<std::string> args;
    const char* message;
  };
  const std::vector<Case> cases = {
      {{"rendr"}, "unknown command 'rendr'; did you mean 'render'? (commands: generate, merge, convert, render"},
      {{"generate", "mandlebulb", "-o", dir.file("t.ply")},
       "generate: unknown kind 'mandlebulb'; did you mean 'mandelbulb'? (kinds: mandelbulb, julia"},
      {{"render", dir.file("one.csv"), "-o", dir.file("t.png"), "--mode", "natve"},
       "--mode natve: must be auto, fp32, split, rte, df64, native, batch or adaptive; did you mean 'native'?"},
      {{"render", dir.file("one.csv"), "-o", dir.file("t.png"), "--colour", "rgb"},
       "render: unknown option '--colour'; did you mean '--color'?"},
      {{"generate", "random2d", "--colour", "none", "-o", dir.file("t.ply")},
       "generate random2d: unknown option '--colour'; did you mean '--colors'?"},
      {{"render", dir.file("one.csv"), "-o", dir.file("t.png"), "--backend", "computee"},
       "--backend computee: must be auto, raster or compute; did you mean 'compute'?"},
      {{"--bogus"}, "unknown option '--bogus'"},
      {{"frobnicate"}, "unknown command 'frobnicate' (commands: generate,"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args[0] + " " + (c.args.size() > 1 ? c.args[1] : ""));
    test::CommandResult r = runDpoint(c.args);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_TRUE(contains(r.err, std::string("dpoint: error: ") + c.message)) << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_EQ(r.out, "");
  }
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"one.csv"}) << "nothing written";
}

// `dpoint` alone prints the top-level help (the command list) and exits 1, a usage error.
TEST(CliHelp, dpointAloneListsTheCommandsAndExitsOne) {
  test::CommandResult bare = runDpoint({});
  EXPECT_EQ(bare.exit_code, 1);
  test::CommandResult help = runDpoint({"--help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_EQ(bare.out, help.out) << "the same text as --help";
  for (const char* command : {"generate", "merge", "convert", "render", "info", "devices", "bench"})
    EXPECT_TRUE(contains(bare.out, std::string("\n  ") + command)) << command;
}

// --views 4 --width 800 --height 600 writes 800 x 600 (it wrote 802 x 602, the 2-px lines added),
// and an odd size is kept too; a sheet too small for four views and their lines is refused.
TEST(CliHelp, fourViewSheetIsTheSizeAskedFor) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "mandelbulb", "--resolution", "24", "-q", "-o", dir.file("mb.ply")}).exit_code, 0);
  for (const auto& [w, h] : std::vector<std::pair<uint32_t, uint32_t>>{{800, 600}, {321, 241}}) {
    const std::string out = dir.file("v" + std::to_string(w) + ".png");
    test::CommandResult r = runDpoint({"render", dir.file("mb.ply"), "-o", out, "--views", "4", "--width",
                                       std::to_string(w), "--height", std::to_string(h)});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(test::pngSize(readFile(out)), std::make_pair(w, h));
    EXPECT_TRUE(contains(r.out, std::to_string(w) + "x" + std::to_string(h))) << r.out;
  }
  test::CommandResult tiny = runDpoint({"render", dir.file("mb.ply"), "-o", dir.file("tiny.png"), "--views", "4",
                                        "--width", "3", "--height", "600"});
  EXPECT_EQ(tiny.exit_code, 1);
  EXPECT_TRUE(contains(tiny.err, "--views 4 needs --width and --height of at least 4 px, got 3x600")) << tiny.err;
  EXPECT_FALSE(test::fileExists(dir.file("tiny.png")));
}

// A bad -o ends the run with one line naming the path, exit 1, before any work: a generation
// that would take minutes (a 2000^3 grid) ends at once, an input that does not exist is not
// reached, and nothing is written. The same for merge, render's --json and bench's --out.
TEST(CliHelp, badOutputIsRefusedBeforeAnyWorkAndNothingIsWritten) {
  TempDir dir;
  writeFile(dir.file("file.txt"), "x");
  const std::vector<std::string> slow = {"generate", "mandelbulb", "--resolution", "2000", "-o"};
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases = {
      {concat(slow, {dir.file("missing/x.ply")}),
       "cannot write '" + dir.file("missing/x.ply") + "': folder '" + dir.file("missing") + "' does not exist"},
      {concat(slow, {dir.path()}), "cannot write '" + dir.path() + "': it is a folder"},
      {concat(slow, {dir.file("x.dat")}), dir.file("x.dat") + ": unknown file type '.dat' (write .csv, .xyz, .txt, .asc, .pts, .ptx, .ply, .pcd, .glb, .las, .laz or .e57)"},
      {concat(slow, {dir.file("x.gltf")}), dir.file("x.gltf") + ": .gltf is read, not written; write .glb"},
      {concat(slow, {"/sys/dpoint-test.ply"}), "'/sys/dpoint-test.ply': Permission denied"},  // even for root
      {{"merge", dir.file("no-such-tile.ply"), "-o", dir.file("missing/x.csv")}, "folder '" + dir.file("missing") + "' does not exist"},
      {{"merge", dir.file("no-such-tile.ply"), "-o", dir.file("x.gltf")}, ".gltf is read, not written"},
      {{"convert", dir.file("no-such-input.csv"), "-o", dir.file("missing/x.csv")}, "folder '" + dir.file("missing") + "' does not exist"},
      {{"convert", dir.file("no-such-input.csv"), "-o", dir.file("x.gltf")}, ".gltf is read, not written"},
      {{"render", dir.file("no-such-input.ply"), "-o", dir.file("missing/x.png")}, "folder '" + dir.file("missing") + "' does not exist"},
      {{"render", dir.file("no-such-input.ply"), "-o", dir.path()}, "it is a folder"},
      {{"render", dir.file("no-such-input.ply"), "-o", dir.file("x.jpg")}, "name it .png"},
      {{"render", dir.file("no-such-input.ply"), "-o", dir.file("x.png"), "--json", dir.file("missing/r.json")},
       "folder '" + dir.file("missing") + "' does not exist"},
      {{"bench", "--out", dir.file("file.txt"), "--cache", dir.file("cache")}, "--out " + dir.file("file.txt") + ": is a file, not a folder"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args[0] + " " + c.args.back());
    test::CommandResult r = test::runCommand(concat({DPOINT_EXE}, c.args), std::chrono::seconds(20));
    ASSERT_FALSE(r.timed_out) << "the work started";
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_TRUE(contains(r.err, "dpoint: error: ")) << r.err;
    EXPECT_TRUE(contains(r.err, c.message)) << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_EQ(dir.entries(), std::vector<std::string>{"file.txt"}) << "nothing written";
  }
}

// One list of output formats: every format the -o help of generate and merge lists is written,
// and the top-level help names the same four.
TEST(CliHelp, everyListedOutputFormatIsWritten) {
  for (const char* command : {"merge", "convert"}) {
    test::CommandResult help = runDpoint({command, "--help"});
    EXPECT_TRUE(contains(help.out, "Output file (.csv, .xyz, .txt, .asc, .pts, .ptx, .ply, .pcd, .glb, .las, .laz, .e57)")) << command;
  }
  test::CommandResult help = runDpoint({"generate", "random2d", "--help"});
  EXPECT_TRUE(contains(help.out, "Output file (.csv, .xyz, .txt, .asc, .pts, .ptx, .ply, .pcd, .glb, .las, .laz, .e57)")) << help.out;
  EXPECT_FALSE(contains(help.out, ".gltf"));
  // The top help names every format convert reads and writes (it had named five of them).
  EXPECT_TRUE(contains(runDpoint({"--help"}).out, "CSV and text exports (PTS, PTX), PLY, PCD, GLB, LAS, LAZ, COPC and E57"));
  TempDir dir;
  for (const char* ext : {"csv", "ply", "glb", "las", "laz", "pcd", "e57", "ptx", "pts", "xyz"}) {
    test::CommandResult r = runDpoint({"generate", "random2d", "-n", "10", "-q", "-o", dir.file(std::string("p.") + ext)});
    EXPECT_EQ(r.exit_code, 0) << ext << ": " << r.err;
    EXPECT_TRUE(test::fileExists(dir.file(std::string("p.") + ext))) << ext;
  }
}

// One voice for errors (issue #36 item 2): every bad invocation of every command is one line
// "dpoint: error: FLAG VALUE: what is accepted" (or "FILE: what is wrong"), with the exit code of
// its class (README: 1 usage, 2 bad input, 3 no usable device, 4 resource limit), and nothing
// written; a closed set's value gets "did you mean" and its other case is taken; a whole number may
// be written 1e6. tests/python/test_errors.py holds the Python module's side of the table.
TEST(CliVoice, badInvocationsSpeakOneVoice) {
  TempDir dir;
  test::writeFile(dir.file("one.csv"), "x,y,z\n1,2,3\n");
  test::writeFile(dir.file("bad.csv"), "x,y,z\n1,2\n");
  const std::string in = dir.file("one.csv"), png = dir.file("o.png"), ply = dir.file("o.ply");
  const std::string bad = dir.file("bad.csv"), missing = dir.file("missing.csv");
  TempDir links;  // a device behind a point file's name (a review finding: it read as "empty file")
  std::filesystem::create_symlink("/dev/zero", links.file("zero.ply"));
  struct Case {
    std::vector<std::string> args;
    std::string message;
    int code = 1;
  };
  const std::vector<Case> cases = {
      {{"generate", "menger", "--method", "voxl", "-o", ply},
       "--method voxl: must be exact or voxel; did you mean 'voxel'?"},
      {{"render", in, "-o", png, "--width", "-100"}, "--width -100: not a valid value for --width (dpoint render --help)"},
      {{"convert", in}, "convert: --output is required (dpoint convert --help)"},
      // A review finding: CLI11 wrapped -1 and clamped 2^64 onto 2^64 - 1, the same set for both.
      {{"generate", "random2d", "--seed", "-1", "-o", ply}, "--seed -1: must be a whole number from 0 to 18446744073709551615"},
      {{"generate", "random2d", "--seed", "18446744073709551616", "-o", ply},
       "--seed 18446744073709551616: must be a whole number from 0 to 18446744073709551615"},
      {{"convert", in, "-o", ply, "--sample", "10", "--sample-seed", "-2"},
       "--sample-seed -2: must be a whole number from 0 to 18446744073709551615"},
      // Options the output does not use were passed over in silence (a review finding).
      {{"convert", in, "-o", png + ".csv", "--ply-ascii"}, "--ply-ascii: only a PLY output (.ply) has it"},
      {{"convert", in, "-o", png + ".pcd", "--ply-colors", "uchar"}, "--ply-colors: only a PLY output (.ply) has it"},
      {{"convert", in, "-o", ply, "--pcd-encoding", "ascii"}, "--pcd-encoding: only a PCD output (.pcd) has an encoding"},
      {{"render", in, "-o", png, "--up-axis", "q"}, "--up-axis q: must be auto, y or z"},
      {{"render", in, "-o", png, "--shade", "edll"}, "--shade edll: must be auto, none or edl; did you mean 'edl'?"},
      {{"generate", "menger", "--size", "-1", "-o", ply}, "--size -1: must be a finite number above 0"},
      {{"render", in, "-o", png, "--edl-strength", "500"}, "--edl-strength 500: must be in (0, 100]"},
      {{"render", in, "-o", png, "--mode", "emulated"}, "--mode emulated: must be auto, fp32, split, rte, df64"},
      {{"render", in, "-o", png, "--views", "2"}, "--views 2: must be 1 or 4"},
      {{"render", in, "-o", png, "--order", "hilbert"}, "--order hilbert: must be input or morton"},
      {{"convert", in, "-o", ply, "--order", "hilbert"}, "--order hilbert: must be input or morton"},
      {{"bench", "--suite", "nightly"}, "--suite nightly: must be ci, paper, hard or all"},
      {{"render", in, "-o", png, "--device", "gpu"}, "--device gpu: must be auto, cpu or a device index"},
      {{"render", in, "-o", png, "--device", "-1"}, "--device -1: must be auto, cpu or a device index"},
      {{"generate", "menger", "--method", "voxel", "--resolution", "4097", "-o", ply},
       "--resolution 4097: must be 2..4096 for the voxel method"},
      {{"generate", "mandelbrot2d", "--max-iter", "abc", "-o", ply},
       "--max-iter abc: must be a whole number from 1 to 2147483647, or auto"},
      {{"convert", in, "-o", ply, "--keep", "intensity"}, "--keep intensity: " + in + " has no dimension 'intensity'"},
      {{"render", in, "-o", png, "--color", "intensity"}, "--color intensity: " + in + " has no dimension 'intensity'"},
      {{"generate", "mandelbulb", "--resolution", "100000", "-o", ply}, "--resolution 100000: must be 2..65536"},
      {{"generate", "mandelbrot2d", "--resolution", "1", "-o", ply}, "--resolution 1: must be 2.."},
      {{"info", dir.path()}, dir.path() + ": is a folder, not a point file (.csv, .xyz, .txt, .asc, .pts, .ptx, .ply, .pcd, .glb, .gltf, .las, .laz or .e57)"},
      {{"convert", dir.path(), "-o", ply}, dir.path() + ": is a folder, not a point file"},
      {{"info", in, "--scene", "1"}, in + ": --scene and --all-scenes apply to .glb/.gltf input only"},
      {{"info", in, in, "--all-scenes"}, in + " and 1 more: --scene and --all-scenes apply to one .glb/.gltf input"},
      {{"generate", "menger", "--level", "99", "-o", ply}, "--level 99: must be 0..8 for menger"},
      {{"generate", "sierpinski", "--level", "40", "-o", ply}, "--level 40: must be 0..12 for sierpinski"},
      {{"generate", "julia", "--c", "1,2", "-o", ply}, "--c 1,2: must be 4 comma-separated finite numbers"},
      {{"generate", "nosuch", "-o", ply}, "generate: unknown kind 'nosuch' (kinds: mandelbulb, julia, menger,"},
      {{"generate", "random2d", "--count", "0", "-o", ply}, "--count 0: must be a number from 1 to 1099511627776"},
      {{"merge", "-o", ply}, "merge: TILES is required (dpoint merge --help)"},
      {{"merge", in, in}, "merge: --output is required (dpoint merge --help)"},
      {{"convert", in, "-o", ply, "--max-memory", "12Q"}, "--max-memory 12Q: not a size (examples: 512M, 8G, 1000000)"},
      // A fraction of a byte was cut: 1.5 was 1 byte, 0.5 was 0 (the default limit); 0.1G is taken.
      {{"convert", in, "-o", ply, "--max-memory", "1.5"}, "--max-memory 1.5: not a whole number of bytes"},
      {{"convert", in, "-o", ply, "--max-memory", "0.5"}, "--max-memory 0.5: not a whole number of bytes"},
      {{"convert", in, "-o", dir.file("o.gltf")}, dir.file("o.gltf") + ": .gltf is read, not written; write .glb"},
      {{"render", in, "-o", dir.file("o.jpg")}, "-o " + dir.file("o.jpg") + ": the picture is written as PNG; name it .png"},
      {{"render", in, "-o", png, "--point-size", "0"}, "--point-size 0: must be 1.."},
      {{"render", in, "-o", png, "--height", "0"}, "--height 0: must be at least 1"},
      {{"render", in, "-o", png, "--fov", "200"}, "--fov 200: must be in (0, 180)"},
      {{"render", in, "-o", png, "--tolerance", "-1"}, "--tolerance -1: must be a number of pixels above 0"},
      {{"render", in, "-o", png, "--frames", "0"}, "--frames 0: must be at least 1"},
      {{"render", in, "-o", png, "--views", "4", "--json", dir.file("r.json")}, "--views 4 makes a contact sheet; --json measures one view"},
      {{"render", in, "-o", png, "--views", "4", "--error"}, "--views 4 makes a contact sheet; --error measures one view"},
      {{"render", in, "-o", png, "--stream", "sometimes"}, "--stream sometimes: must be auto, on or off"},
      {{"info", in, "--view-width", "-3"}, "--view-width -3: must be a finite number above 0"},
      {{"info", in, "--view-width", "0"}, "--view-width 0: must be a finite number above 0"},  // 0 was "not given"
      {{"info", in, "--sample", "0"}, "--sample 0: must be a number from 1 to 100000000 (dpoint info --help)"},
      {{"devices", "extra"}, "devices: unexpected argument 'extra' (dpoint devices --help)"},
      {{"bench", "--frames", "0", "--out", dir.file("b")}, "--frames 0: must be at least 1"},
      // As --out (a review finding: a file given as --cache was exit 2, after the device started).
      {{"bench", "--cache", in, "--out", dir.file("b")}, "--cache " + in + ": is a file, not a folder"},
      // A review finding: CLI11's positive and non-negative checks printed the largest double in
      // 309 digits; a lone number's refusal spoke of "1 comma-separated finite numbers".
      {{"generate", "mandelbulb", "--level", "0", "-o", ply}, "--level 0: must be a number above 0"},
      {{"convert", in, "-o", ply, "--max-points", "0"}, "--max-points 0: must be a number above 0"},
      {{"convert", in, "-o", dir.file("o.las"), "--las-scale", "-1"}, "--las-scale -1: must be a number above 0"},
      {{"info", in, "--scene", "-1"}, "--scene -1: must be 0 or more"},
      {{"render", in, "-o", png, "--point-size", "nan"}, "--point-size nan: must be a finite number"},
      {{"render", in, "-o", png, "--json", in}, "--json " + in + ": is also an input (" + in + ")"},
      {{"render", in, "-o", png, "--frames", "1", "--frames", "2"}, "--frames: given 2 times; give it once (dpoint render --help)"},
      // README's promise for every command (a review finding: convert and merge replaced their input).
      {{"convert", in, "-o", in}, "-o " + in + ": is also the input (" + in + ")"},
      {{"merge", ply, in, "-o", in}, "-o " + in + ": is also a tile (" + in + ")"},
      // Review findings: bench io --write over its input replaced it; a --bounds span past the
      // largest double wrote NaN positions.
      {{"bench", "io", in, "--write", in}, "--write " + in + ": is also the input (" + in + ")"},
      {{"generate", "julia", "--resolution", "10", "--bounds=-1e308,1e308", "-o", ply},
       "--bounds -1e308,1e308: HI - LO is beyond the largest double"},
      // The other classes: bad input (2), no usable device (3), a resource limit (4).
      {{"convert", missing, "-o", ply}, missing + ": file not found", 2},
      {{"info", links.file("zero.ply")}, links.file("zero.ply") + ": not a regular file (a device)", 2},
      // One line whatever a file's name holds (a review finding: a newline split the error).
      {{"info", dir.file("new\nline.ply")}, dir.file("new\\x0aline.ply") + ": file not found", 2},
      {{"info", bad}, bad + ":2: 2 columns, expected 3 (x,y,z)", 2},
      {{"merge", in, "-o", ply}, in + ": not a PLY file (no 'ply' line at the start)", 2},
      {{"merge", dir.path(), "-o", ply}, dir.path() + ": is a folder, not a tile (.ply)", 2},
      {{"render", in, "-o", png, "--device", "99"}, "--device 99: only ", 3},
      {{"info", in, "--max-memory", "1"}, in + ": 1 lines needs about 24 bytes, more than the limit of 1 bytes", 4},
      {{"render", in, "-o", png, "--max-memory", "1"}, "a 1024x768 picture needs about 24.0 MiB, more than the limit", 4},
  };
  ASSERT_GE(cases.size(), 40u);
  for (const Case& c : cases) {
    std::string line;
    for (const std::string& a : c.args) line += a + " ";
    SCOPED_TRACE(line);
    test::CommandResult r = runDpoint(c.args);
    EXPECT_EQ(r.exit_code, c.code) << r.err;
    EXPECT_TRUE(contains(r.err, "dpoint: error: " + c.message)) << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
  }
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"bad.csv", "one.csv"})) << "nothing written";
}

TEST(CliVoice, closedSetsTakeAnotherCaseAndCountsTakeExponentForm) {
  TempDir dir;
  test::CommandResult r = runDpoint({"generate", "random2d", "--count", "1e3", "-o", dir.file("r.csv"), "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(lines(readFile(dir.file("r.csv"))), 1001u);
  r = runDpoint({"generate", "menger", "--method", "VOXEL", "--level", "1", "-o", dir.file("m.ply"), "-q"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  // 1e-3 is not a whole number: a count refuses it.
  r = runDpoint({"generate", "random2d", "--count", "1e-3", "-o", dir.file("x.csv")});
  EXPECT_EQ(r.exit_code, 1);
}

}  // namespace
}  // namespace dpoint
