// dpoint generate --tile and dpoint merge as a user or a scheduler runs them: the merged file is
// the single process's, byte for byte, for every kind and output format; bad tiles are refused
// with the flag or file named; render and info take the tiles as the whole set.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include <string>
#include <vector>

#include "cli/cli_png.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::readFile;
using test::runCommand;
using test::runDpoint;
using test::concat;
using test::TempDir;

// Runs the N tiles and the merge into `out_name`, returns the merged bytes ("" on failure).
std::string mergedTiles(const TempDir& dir, const std::vector<std::string>& kind, uint32_t count,
                        const std::string& out_name, const std::vector<std::string>& merge_args = {}) {
  std::vector<std::string> merge = {"merge", "-q", "-o", dir.file(out_name)};
  for (uint32_t i = 0; i < count; ++i) {
    const std::string part = dir.file("part-" + std::to_string(i) + ".ply");
    test::CommandResult r = runDpoint(concat(concat({"generate"}, kind),
                                             {"-q", "--tile", std::to_string(i) + "/" + std::to_string(count), "-o", part}));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    if (r.exit_code != 0) return "";
    merge.push_back(part);
  }
  test::CommandResult r = runDpoint(concat(merge, merge_args));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return r.exit_code == 0 ? readFile(dir.file(out_name)) : "";
}

// The number after `key` in a tile's header ("element vertex ", "comment dpoint-tile-owned ").
uint64_t headerNumber(const std::string& bytes, const std::string& key) {
  const size_t at = bytes.find(key);
  EXPECT_NE(at, std::string::npos) << key;
  return at == std::string::npos ? 0 : std::stoull(bytes.substr(at + key.size()));
}

// Header counts summed over the parts part-0.ply … part-(parts − 1).ply that mergedTiles made.
struct PartCounts {
  uint64_t vertices = 0, faces = 0, owned = 0;  // vertices − owned: the seam copies
};
PartCounts partCounts(const TempDir& dir, uint32_t parts) {
  PartCounts sum;
  for (uint32_t i = 0; i < parts; ++i) {
    const std::string bytes = readFile(dir.file("part-" + std::to_string(i) + ".ply"));
    sum.vertices += headerNumber(bytes, "element vertex ");
    sum.faces += headerNumber(bytes, "element face ");
    sum.owned += headerNumber(bytes, "comment dpoint-tile-owned ");
  }
  return sum;
}

std::string whole(const TempDir& dir, const std::vector<std::string>& kind, const std::string& out_name,
                  const std::vector<std::string>& args = {}) {
  test::CommandResult r = runDpoint(concat(concat(concat({"generate"}, kind), {"-q", "-o", dir.file(out_name)}), args));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return readFile(dir.file(out_name));
}

TEST(CliTiles, everyKindMergesToTheSingleProcessFileByteForByte) {
  const std::vector<std::vector<std::string>> kinds = {
      {"mandelbulb", "--resolution", "33", "--variant", "fast"},
      {"mandelbulb", "--resolution", "17"},
      {"julia", "--resolution", "25", "--frame", "seed"},
      {"menger", "--level", "2"},
      {"sierpinski", "--level", "3"},
      {"random2d", "--count", "999"},
      {"mandelbrot2d", "--resolution", "31", "--max-iter", "300"},
  };
  for (const std::vector<std::string>& kind : kinds) {
    for (uint32_t count : {3u, 40u}) {  // 40: more tiles than slabs, lattice planes or rows
      SCOPED_TRACE(kind[0] + " " + kind[2] + " N=" + std::to_string(count));
      TempDir dir;
      const std::string expected = whole(dir, kind, "whole.ply");
      ASSERT_FALSE(expected.empty());
      EXPECT_TRUE(mergedTiles(dir, kind, count, "merged.ply") == expected);
    }
  }
}

TEST(CliTiles, mergeWritesEveryFormatAndOrderAsGenerateDoes) {
  TempDir dir;
  const std::vector<std::string> kind = {"julia", "--resolution", "21", "--offset", "6378137,0,0.5"};
  for (const std::vector<std::string>& options :
       std::vector<std::vector<std::string>>{{}, {"--decimals", "15"}, {"--order", "morton"}}) {
    for (const char* ext : {".csv", ".glb", ".ply"}) {
      SCOPED_TRACE(std::string(ext) + (options.empty() ? "" : " " + options[0]));
      const std::string expected = whole(dir, kind, std::string("whole") + ext, options);
      ASSERT_FALSE(expected.empty());
      EXPECT_TRUE(mergedTiles(dir, kind, 5, std::string("merged") + ext, options) == expected);
    }
  }
}

TEST(CliTiles, badTilesAreRefusedNamingTheFlag) {
  TempDir dir;
  const std::string out = dir.file("t.ply");
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{"julia", "--tile", "5/4", "-o", out}, "--tile: '5/4' asks for tile 5, but tiles are 0..3"},
      {{"julia", "--tile", "0/0", "-o", out}, "--tile: '0/0' asks for N outside"},
      {{"julia", "--tile", "x", "-o", out}, "--tile: 'x' is not I/N"},
      {{"julia", "--tile", "", "-o", out}, "--tile: empty; give I/N"},  // wrote the whole set before
      {{"julia", "--tile", "0/2", "-o", dir.file("t.csv")}, "a tile is written as .ply"},
      {{"julia", "--tile", "0/2", "--order", "morton", "-o", out}, "--order morton needs the whole set"},
      {{"menger", "--method", "voxel", "--tile", "0/2", "-o", out}, "--method voxel has no split"},
  };
  for (const Case& c : cases) {
    test::CommandResult r = runDpoint(concat({"generate"}, c.args));
    EXPECT_EQ(r.exit_code, 1) << c.message;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
  }
  EXPECT_TRUE(dir.entries().empty());
}

TEST(CliTiles, mergeRefusesAnIncompleteOrMixedSet) {
  TempDir dir;
  for (int i = 0; i < 3; ++i)
    ASSERT_EQ(runDpoint({"generate", "sierpinski", "--level", "2", "-q", "--tile", std::to_string(i) + "/3", "-o",
                         dir.file(std::to_string(i) + "-s.ply")})
                  .exit_code,
              0);
  ASSERT_EQ(runDpoint({"generate", "sierpinski", "--level", "3", "-q", "--tile", "1/3", "-o", dir.file("other.ply")})
                .exit_code,
            0);
  test::CommandResult r = runDpoint({"merge", dir.file("0-s.ply"), dir.file("2-s.ply"), "-o", dir.file("m.ply")});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("missing tile(s) 1 of 0..2"), std::string::npos) << r.err;
  r = runDpoint({"merge", dir.file("0-s.ply"), dir.file("other.ply"), dir.file("2-s.ply"), "-o", dir.file("m.ply")});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("other.ply: a tile of another run"), std::string::npos) << r.err;
  r = runDpoint({"merge", DPOINT_SAMPLES_DIR "/earth_offset_mm.csv", "-o", dir.file("m.ply")});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("not a PLY file"), std::string::npos) << r.err;
  EXPECT_FALSE(test::fileExists(dir.file("m.ply")));
}

// A part whose copy of a vertex another part owns differs from it (one bit of a coordinate, or of a
// colour) is refused whether the merge streams into a PLY file or takes the set in memory first.
TEST(CliTiles, mergeRefusesACopyThatDiffersFromItsOwner) {
  TempDir dir;
  const std::vector<std::string> kind = {"mandelbulb", "--resolution", "17", "--variant", "fast"};
  ASSERT_FALSE(mergedTiles(dir, kind, 2, "good.ply").empty());
  // The part holding copies: more vertices than it owns. Its rows are 36 bytes (3 double, 3 float).
  std::string part, bytes;
  uint64_t owned = 0, vertices = 0;
  for (const char* name : {"part-0.ply", "part-1.ply"}) {
    bytes = readFile(dir.file(name));
    const size_t at_owned = bytes.find("comment dpoint-tile-owned ");
    const size_t at_vertices = bytes.find("element vertex ");
    ASSERT_NE(at_owned, std::string::npos);
    owned = std::stoull(bytes.substr(at_owned + 26));
    vertices = std::stoull(bytes.substr(at_vertices + 15));
    part = name;
    if (vertices > owned) break;
  }
  ASSERT_GT(vertices, owned) << "no part holds a copy";
  const size_t data = bytes.find("end_header\n") + 11;
  ASSERT_NE(bytes.find("property float red"), std::string::npos);
  for (size_t field : {size_t{8}, size_t{24}}) {  // the last byte of y; the first byte of red
    SCOPED_TRACE(field == 8 ? "position" : "colour");
    std::string bad = bytes;
    bad[data + owned * 36 + field + (field == 8 ? 7 : 0)] ^= 1;
    test::writeFile(dir.file(part), bad);
    for (const char* out : {"bad.ply", "bad.csv"}) {
      test::CommandResult r = runDpoint({"merge", "-q", dir.file("part-0.ply"), dir.file("part-1.ply"), "-o", dir.file(out)});
      EXPECT_EQ(r.exit_code, 2) << out;
      EXPECT_NE(r.err.find(dir.file(part) + ": its copy of vertex "), std::string::npos) << r.err;
      EXPECT_NE(r.err.find(std::string("differs from the owner's ") + (field == 8 ? "position" : "colour")),
                std::string::npos)
          << r.err;
      EXPECT_FALSE(test::fileExists(dir.file(out)));
    }
    // The parts read as one set, whole or streamed (each copy checked as its owner's block passes;
    // the stream had drawn the seam of two builds without a word), give the same error.
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"info", "--stream", "off"}, {"info", "--stream", "on"},
          {"render", "-q", "--stream", "on", "--width", "64", "--height", "48", "-o", dir.file("bad.png")}}) {
      std::vector<std::string> all = args;
      all.insert(all.end(), {dir.file("part-0.ply"), dir.file("part-1.ply")});
      test::CommandResult r = runDpoint(all);
      EXPECT_EQ(r.exit_code, 2) << args[0] << " " << args[2];
      EXPECT_NE(r.err.find(dir.file(part) + ": its copy of vertex "), std::string::npos) << r.err;
      EXPECT_NE(r.err.find(std::string("differs from the owner's ") + (field == 8 ? "position" : "colour")),
                std::string::npos)
          << r.err;
    }
    EXPECT_FALSE(test::fileExists(dir.file("bad.png")));
  }
  // The good parts, streamed: the copies are the owners'.
  test::writeFile(dir.file(part), bytes);
  test::CommandResult streamed = runDpoint({"info", "--stream", "on", dir.file("part-0.ply"), dir.file("part-1.ply")});
  EXPECT_EQ(streamed.exit_code, 0) << streamed.err;
  // With a bad face as well, the merge into a .ply names the face: rows are read and checked before
  // copies. Into a .csv the faces are not read (a point format keeps none): the copy is named.
  std::string bad = bytes;
  bad[data + owned * 36] ^= 1;
  bad[data + vertices * 36] = 4;  // the first face's corner count
  test::writeFile(dir.file(part), bad);
  for (const char* out : {"bad.ply", "bad.csv"}) {
    test::CommandResult r = runDpoint({"merge", "-q", dir.file("part-0.ply"), dir.file("part-1.ply"), "-o", dir.file(out)});
    EXPECT_EQ(r.exit_code, 2) << out;
    const std::string named = std::string(out) == "bad.ply" ? ": byte " + std::to_string(data + vertices * 36) + ": face 0 has 4 corners"
                                                            : ": its copy of vertex ";
    EXPECT_NE(r.err.find(dir.file(part) + named), std::string::npos) << out << ": " << r.err;
  }
}

// The tiles' face rows are read only where the output holds triangles (PLY, GLB) or the reader
// keeps them: merge to a point format, and render's points, pass over them (the tiles' sizes are
// still checked). A face index past the vertices is then not seen, as nothing is written from it.
TEST(CliTiles, aPointOutputReadsNoFacesOfTheTiles) {
  TempDir dir;
  const std::vector<std::string> kind = {"julia", "--resolution", "21"};
  ASSERT_FALSE(mergedTiles(dir, kind, 2, "good.pcd").empty());
  const std::string good_pcd = readFile(dir.file("good.pcd"));
  const std::string bytes = readFile(dir.file("part-0.ply"));
  const uint64_t vertices = headerNumber(bytes, "element vertex ");
  const size_t face = bytes.find("end_header\n") + 11 + vertices * 36;  // rows of 3 double, 3 float
  ASSERT_EQ(bytes[face], 3);
  std::string bad = bytes;
  bad.replace(face + 1, 4, "\xff\xff\xff\xff");  // the first face's first corner: vertex 2^32 - 1
  test::writeFile(dir.file("part-0.ply"), bad);
  const auto merge = [&](const std::string& out) {
    return runDpoint({"merge", "-q", dir.file("part-0.ply"), dir.file("part-1.ply"), "-o", dir.file(out)});
  };
  for (const char* out : {"m.pcd", "m.csv", "m.las"}) EXPECT_EQ(merge(out).exit_code, 0) << out << ": " << merge(out).err;
  EXPECT_TRUE(readFile(dir.file("m.pcd")) == good_pcd);
  for (const char* out : {"m.ply", "m.glb"}) {
    test::CommandResult r = merge(out);
    EXPECT_EQ(r.exit_code, 2) << out;
    EXPECT_TRUE(test::contains(r.err, dir.file("part-0.ply") + ": byte " + std::to_string(face) + ": face 0 uses vertex 4294967295"))
        << out << ": " << r.err;
    EXPECT_FALSE(test::fileExists(dir.file(out)));
  }
  // render of the vertices reads the set as points (the build before read and welded every face,
  // then dropped them); info counts the triangles, so it reads them.
  test::CommandResult r = runDpoint({"render", "-q", "--surface", "off", "--width", "32", "--height", "24", "-o",
                                     dir.file("p.png"), dir.file("part-0.ply"), dir.file("part-1.ply")});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  r = runDpoint({"info", dir.file("part-0.ply"), dir.file("part-1.ply")});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  // A tile cut short is refused to every format.
  test::writeFile(dir.file("part-0.ply"), bytes.substr(0, bytes.size() - 1));
  for (const char* out : {"cut.pcd", "cut.ply"}) {
    r = merge(out);
    EXPECT_EQ(r.exit_code, 2) << out;
    EXPECT_TRUE(test::contains(r.err, "(a truncated or padded tile)")) << r.err;
  }
}

// A tile set read whole (render, info) is held to --max-memory as `dpoint merge` holds it: its
// points, the seam copies beside them and the faces it reads (the build before read it whole under
// any limit).
TEST(CliTiles, aTileSetReadWholeKeepsToMaxMemory) {
  TempDir dir;
  ASSERT_FALSE(mergedTiles(dir, {"mandelbulb", "--resolution", "33", "--variant", "fast"}, 2, "good.ply").empty());
  const auto [vertices, faces, owned] = partCounts(dir, 2);
  const uint64_t needs = vertices * 36 + faces * 12;  // every row of both parts; three indices a face
  const auto info = [&](uint64_t limit) {
    return runDpoint({"info", "--max-memory", std::to_string(limit), dir.file("part-0.ply"), dir.file("part-1.ply")});
  };
  test::CommandResult r = info(needs - 1);
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_TRUE(test::contains(r.err, dir.file("part-0.ply") + " and 1 more: merging 2 tiles needs about " + std::to_string(needs) +
                                        " bytes"))
      << r.err;
  r = info(needs);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  // render of the vertices reads no faces: its limit is the points' and copies' (past its picture's).
  const uint64_t points = vertices * 36;
  ASSERT_GT(points, 32u * 24 * 32) << "a set too small to be refused after the picture";
  r = runDpoint({"render", "-q", "--surface", "off", "--width", "32", "--height", "24", "--max-memory",
                 std::to_string(points - 1), "-o", dir.file("p.png"), dir.file("part-0.ply"), dir.file("part-1.ply")});
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_TRUE(test::contains(r.err, "merging 2 tiles needs about " + std::to_string(points) + " bytes")) << r.err;
  EXPECT_TRUE(test::contains(r.err, "merging 2 tiles needs about")) << r.err;
  EXPECT_FALSE(test::fileExists(dir.file("p.png")));
}

// The streamed merge into a .ply holds a few blocks a thread and the copies: --max-memory still
// refuses it (exit 4) below that, as it refuses the merge that holds the set.
TEST(CliTiles, mergeKeepsToMaxMemoryWhenItStreams) {
  TempDir dir;
  ASSERT_FALSE(mergedTiles(dir, {"julia", "--resolution", "21"}, 2, "good.ply").empty());
  for (const char* out : {"small.ply", "small.csv"}) {
    test::CommandResult r =
        runDpoint({"merge", "-q", "--max-memory", "1K", dir.file("part-0.ply"), dir.file("part-1.ply"), "-o", dir.file(out)});
    EXPECT_EQ(r.exit_code, 4) << out << ": " << r.err;
    EXPECT_NE(r.err.find(dir.file("part-0.ply") + " and 1 more: merging 2 tiles"), std::string::npos) << r.err;
    EXPECT_FALSE(test::fileExists(dir.file(out)));
  }
  EXPECT_EQ(runDpoint({"merge", "-q", "--max-memory", "1G", dir.file("part-0.ply"), dir.file("part-1.ply"), "-o",
                       dir.file("big.ply")})
                .exit_code,
            0);
}

// A streamed tile set holds its seam copies (a row, a place and a reference each: 60 bytes) for the
// whole stream: --max-memory counts them beside the two blocks, refusing before they are read where
// they alone do not fit (the build before held them uncounted).
TEST(CliTiles, aStreamedTileSetCountsItsCopiesAgainstMaxMemory) {
  TempDir dir;
  ASSERT_FALSE(mergedTiles(dir, {"mandelbulb", "--resolution", "33", "--variant", "fast"}, 2, "good.ply").empty());
  const PartCounts counts = partCounts(dir, 2);
  const uint64_t owned = counts.owned, copies = counts.vertices - counts.owned;
  ASSERT_GT(copies, 0u);
  const uint64_t held = copies * 60, blocks = 2 * owned * 36;  // two blocks of 36-byte points
  const auto info = [&](uint64_t limit) {
    return runDpoint({"info", "--stream", "on", "--max-memory", std::to_string(limit), dir.file("part-0.ply"),
                      dir.file("part-1.ply")});
  };
  test::CommandResult r = info(held - 1);
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_NE(r.err.find("holding the " + std::to_string(copies) + " seam copies of 2 tiles while they stream needs"), std::string::npos) << r.err;
  r = info(blocks + held - 1);
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_NE(r.err.find("points a block at a time beside"), std::string::npos) << r.err;
  r = info(blocks + held);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  // Under --stream auto a set this small is read whole: the copies' limit is the stream's (the
  // first version refused it, naming a stream that was never to be), and the whole set's is the
  // merge's (aTileSetReadWholeKeepsToMaxMemory).
  r = runDpoint({"info", "--max-memory", std::to_string(held - 1), dir.file("part-0.ply"), dir.file("part-1.ply")});
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_TRUE(test::contains(r.err, "merging 2 tiles needs about")) << r.err;
  EXPECT_FALSE(test::contains(r.err, "while they stream")) << r.err;
  r = runDpoint({"info", "--max-memory", "1G", dir.file("part-0.ply"), dir.file("part-1.ply")});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find(std::to_string(owned)), std::string::npos) << r.out;
  r = runDpoint({"render", "-q", "--stream", "on", "--width", "32", "--height", "24", "--max-memory",
                 std::to_string(blocks + held - 1), "-o", dir.file("small.png"), dir.file("part-0.ply"),
                 dir.file("part-1.ply")});
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_NE(r.err.find("of seam copies"), std::string::npos) << r.err;
  EXPECT_FALSE(test::fileExists(dir.file("small.png")));
}

// Every tile is open at once: dpoint raises its soft limit on open files to the hard one (80 tiles
// under a soft limit of 40 merge), and where the hard limit itself is too low the error is a
// resource limit (exit 4) that says so (the build before failed both with exit 2).
TEST(CliTiles, mergeOfMoreTilesThanTheOpenFileLimitRaisesItOrSaysSo) {
  TempDir dir;
  std::vector<std::string> tiles;
  for (int t = 0; t < 80; ++t) {
    std::string name = "t";  // appended: GCC 12 warns falsely on "t" + string (bug 105651)
    name += std::to_string(t);
    tiles.push_back(dir.file(name + ".ply"));
    ASSERT_EQ(runDpoint({"generate", "random2d", "-n", "200", "-q", "--tile", std::to_string(t) + "/80", "-o", tiles.back()})
                  .exit_code,
              0);
  }
  const auto merge = [&](const std::string& limits, const std::string& out) {
    std::vector<std::string> argv = {"/bin/sh", "-c", limits + "; exec \"$0\" \"$@\"", DPOINT_EXE, "merge", "-q", "-o",
                                     dir.file(out)};
    argv.insert(argv.end(), tiles.begin(), tiles.end());
    return runCommand(argv);
  };
  test::CommandResult raised = merge("ulimit -Sn 40", "raised.ply");
  EXPECT_EQ(raised.exit_code, 0) << raised.err;
  test::CommandResult low = merge("ulimit -n 40", "low.ply");
  EXPECT_EQ(low.exit_code, 4) << low.err;
  EXPECT_TRUE(test::contains(low.err, "cannot open: Too many open files (this process may hold 40; a shell raises that with `ulimit -n`)"))
      << low.err;
  EXPECT_FALSE(test::fileExists(dir.file("low.ply")));
  // A stream of the tiles holds each open once: their copies' references are read before the parts
  // are opened (they were read with every file opened a second time, 160 here, a review finding).
  std::vector<std::string> info = {"/bin/sh", "-c", "ulimit -n 100; exec \"$0\" \"$@\"", DPOINT_EXE, "info", "--stream", "on"};
  info.insert(info.end(), tiles.begin(), tiles.end());
  test::CommandResult streamed = runCommand(info);
  EXPECT_EQ(streamed.exit_code, 0) << streamed.err;
  EXPECT_TRUE(test::contains(streamed.out, "points:             200\n")) << streamed.out;
}

// Tiles read file by file (one alone, a set with a tile left out) bring their copies of the seam
// vertices: info and render say so in a note, streamed or not; the whole set says nothing (the
// build before counted the copies without a word).
TEST(CliTiles, tilesReadFileByFileSaySo) {
  TempDir dir;
  ASSERT_FALSE(mergedTiles(dir, {"julia", "--resolution", "21"}, 3, "m.ply").empty());
  const std::string p0 = dir.file("part-0.ply"), p1 = dir.file("part-1.ply"), p2 = dir.file("part-2.ply");
  const std::string note = "dpoint: note: " + p0 + " and 1 more: 2 tiles of `generate --tile` read file by file";
  for (const std::vector<std::string>& command :
       {std::vector<std::string>{"info", p0, p1}, {"info", p0, p1, "--stream", "on"},
        {"render", p0, p1, "-o", dir.file("r.png"), "--width", "32", "--height", "24", "-q"}}) {
    test::CommandResult r = runDpoint(command);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(test::contains(r.err, note)) << command[0] << ": " << r.err;
  }
  test::CommandResult one = runDpoint({"info", p0});
  EXPECT_TRUE(test::contains(one.err, p0 + ": a tile of `generate --tile` read file by file")) << one.err;
  test::CommandResult all = runDpoint({"info", p0, p1, p2});
  ASSERT_EQ(all.exit_code, 0) << all.err;
  EXPECT_EQ(all.err.find("note:"), std::string::npos) << all.err;
}

TEST(CliTiles, renderAndInfoTakeTheTilesAsTheWholeSet) {
  TempDir dir;
  const std::vector<std::string> kind = {"mandelbulb", "--resolution", "29"};
  whole(dir, kind, "whole.ply");
  std::vector<std::string> parts;
  for (int i = 0; i < 4; ++i) {
    parts.push_back(dir.file("part-" + std::to_string(i) + ".ply"));
    ASSERT_EQ(runDpoint(concat(concat({"generate"}, kind), {"-q", "--tile", std::to_string(i) + "/4", "-o", parts.back()}))
                  .exit_code,
              0);
  }
  test::CommandResult one = runDpoint({"info", "--json", dir.file("whole.ply")});
  test::CommandResult tiles = runDpoint(concat({"info", "--json"}, parts));
  ASSERT_EQ(one.exit_code, 0) << one.err;
  ASSERT_EQ(tiles.exit_code, 0) << tiles.err;
  auto afterFile = [](const std::string& json) { return json.substr(json.find("\"points\"")); };
  EXPECT_EQ(afterFile(one.out), afterFile(tiles.out));
  EXPECT_NE(tiles.out.find("part-0.ply and 3 more"), std::string::npos);
  // Streamed (as tiles larger than memory are): the same counts, bounds and nearest neighbour; the
  // float32 merge count, which needs every point at once, is left out, and the error bounds come
  // from the box of each batch.
  test::CommandResult streamed = runDpoint(concat({"info", "--json", "--stream", "on"}, parts));
  ASSERT_EQ(streamed.exit_code, 0) << streamed.err;
  for (const char* key : {"\"points\"", "\"triangles\"", "\"colors\"", "\"min\"", "\"max\"",
                          "\"min_neighbor_distance\"", "\"neighbor_sample\""}) {
    auto line = [&](const std::string& json) {
      const size_t at = json.find(key);
      return json.substr(at, json.find('\n', at) - at);
    };
    ASSERT_NE(streamed.out.find(key), std::string::npos) << key;
    EXPECT_EQ(line(one.out), line(streamed.out));
  }
  EXPECT_NE(streamed.out.find("\"float32_merged_points\": null"), std::string::npos) << streamed.out;
  EXPECT_NE(streamed.out.find("\"error_bound_from\": \"batch_boxes\",\n  \"error_bound_px\": {\"fp32\": "),
            std::string::npos)
      << streamed.out;
  EXPECT_NE(one.out.find("\"error_bound_from\": \"points\""), std::string::npos) << one.out;

  // The whole mesh's surface, as the tiles' (a res-29 bulb's triangles are long enough on screen for
  // --surface auto to draw it sampled): the build before drew the tiles as their vertices, while
  // the merged file drew its surface. The tiles hold the colours as floats, the file as bytes, so
  // the samples' interpolated colours may differ by a level; the points are the same.
  ASSERT_EQ(runDpoint({"render", dir.file("whole.ply"), "-q", "--validate", "-o", dir.file("whole.png")}).exit_code, 0);
  test::CommandResult r = runDpoint(concat(concat({"render", "-q", "--validate"}, parts), {"-o", dir.file("tiles.png")}));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  {
    const test::Pixels whole = test::decodePng(readFile(dir.file("whole.png")));
    const test::Pixels parted = test::decodePng(readFile(dir.file("tiles.png")));
    ASSERT_TRUE(whole.width == parted.width && whole.height == parted.height && !whole.rgba.empty());
    int most = 0;
    size_t lit = 0;
    for (size_t i = 0; i < whole.rgba.size(); ++i) {
      most = std::max(most, std::abs(int(whole.rgba[i]) - int(parted.rgba[i])));
      lit += i % 4 == 0 && (whole.rgba[i] || whole.rgba[i + 1] || whole.rgba[i + 2]);
    }
    EXPECT_LE(most, 1) << "the same surface, its colours within a level";
    EXPECT_GT(lit, size_t(whole.width) * size_t(whole.height) / 4) << "a surface, not 2020 vertices";
  }
  // A stream is drawn as its vertices: --surface on is refused there, not passed over.
  r = runDpoint(concat(concat({"render", "--stream", "on", "--surface", "on"}, parts), {"-o", dir.file("no.png")}));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("--surface on samples its surface in memory (--stream off)"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("no.png")));
  // Streamed a block at a time (as tiles larger than memory are): each tile's owned vertices in
  // tile order, given in any order, are the whole set; the same picture on both backends.
  for (const char* backend : {"raster", "compute"}) {
    SCOPED_TRACE(backend);
    const std::vector<std::string> common = {"-q", "--validate", "--mode", "native", "--backend", backend, "--surface", "off"};
    ASSERT_EQ(runDpoint(concat(concat({"render", dir.file("whole.ply")}, common), {"-o", dir.file("w.png")})).exit_code, 0);
    const std::vector<std::string> shuffled = {parts[2], parts[0], parts[3], parts[1]};
    r = runDpoint(concat(concat(concat({"render"}, shuffled), common), {"--stream", "on", "-o", dir.file("s.png")}));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(readFile(dir.file("w.png")) == readFile(dir.file("s.png")));
  }
  // A partial set is read file by file: its points are there, seam copies included; streamed, the
  // same picture.
  r = runDpoint({"info", "--json", parts[0], parts[1]});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"points\": "), std::string::npos);
  for (const char* stream : {"off", "on"}) {
    r = runDpoint({"render", parts[0], parts[1], "-q", "--mode", "native", "--surface", "off", "--stream", stream, "-o",
                   dir.file(std::string("partial-") + stream + ".png")});
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  EXPECT_TRUE(readFile(dir.file("partial-off.png")) == readFile(dir.file("partial-on.png")));
  // Tile 0 of another run (other options) beside this run's tile 0: two files, read file by file
  // (it was refused as "tile 0 again").
  ASSERT_EQ(runDpoint({"generate", "mandelbulb", "--resolution", "30", "-q", "--tile", "0/4", "-o", dir.file("other-0.ply")})
                .exit_code,
            0);
  r = runDpoint({"render", parts[0], dir.file("other-0.ply"), "-q", "-o", dir.file("two-runs.png")});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  // A review finding: a file or a tile given twice was read twice, a set too large with no word.
  std::filesystem::copy_file(parts[1], dir.file("copy-of-1.ply"));
  for (const char* stream : {"off", "on"}) {
    SCOPED_TRACE(stream);
    r = runDpoint({"info", parts[0], parts[1], parts[1], parts[2], parts[3], "--stream", stream});
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find(parts[1] + ": given twice as an input"), std::string::npos) << r.err;
    r = runDpoint({"render", parts[0], parts[1], dir.file("copy-of-1.ply"), parts[2], parts[3], "--stream", stream, "-o",
                   dir.file("twice.png")});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find(dir.file("copy-of-1.ply") + ": tile 1 again (also " + parts[1] + ")"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir.file("twice.png")));
  }
}

// A scheduler runs the tiles: GNU parallel (Debian `parallel`, installed by scripts/setup) runs 7
// tiles two at a time, and the merge equals the single process.
TEST(CliTiles, gnuParallelRunsTheTilesAndTheMergeEqualsOneProcess) {
  TempDir dir;
  const std::vector<std::string> kind = {"mandelbulb", "--resolution", "45", "--variant", "fast"};
  const std::string expected = whole(dir, kind, "whole.ply");
  std::vector<std::string> command = {"/usr/bin/parallel", "--will-cite", "--halt", "now,fail=1", "-j2", DPOINT_EXE, "generate"};
  command = concat(command, kind);
  command = concat(command, {"-q", "--tile", "{}/7", "-o", dir.file("part-{}.ply"), ":::", "0", "1", "2", "3", "4", "5", "6"});
  test::CommandResult r = runCommand(command);
  ASSERT_EQ(r.exit_code, 0) << "is GNU parallel installed (scripts/setup)? " << r.err;
  std::vector<std::string> merge = {"merge", "-q", "-o", dir.file("merged.ply")};
  for (int i = 6; i >= 0; --i) merge.push_back(dir.file("part-" + std::to_string(i) + ".ply"));
  r = runDpoint(merge);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(readFile(dir.file("merged.ply")) == expected);
}

}  // namespace
}  // namespace dpoint
