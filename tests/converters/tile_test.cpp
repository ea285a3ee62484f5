// Tile files and their merge (core/tile.h): the split of work units, the file round trip, and a
// merge that refuses every way tiles can fail to make one set, naming the file.
#include "converters/tile_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

#include "converters/ply.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::contains;
using test::readFile;
using test::TempDir;
using test::writeFile;

TEST(Tile, rangesPartitionTheItemsEvenWithMoreTilesThanItems) {
  for (uint64_t items : {0ull, 1ull, 5ull, 7ull, 1000ull}) {
    for (uint32_t count : {1u, 2u, 3u, 7u, 13u}) {
      uint64_t next = 0;
      for (uint32_t i = 0; i < count; ++i) {
        const TileRange r = tileRange(items, {i, count});
        EXPECT_EQ(r.begin, next);
        EXPECT_LE(r.begin, r.end);
        for (uint64_t item = r.begin; item < r.end; ++item) EXPECT_EQ(tileOfItem(items, count, item), i);
        const uint32_t after = nextNonEmptyTile(items, {i, count});
        for (uint32_t j = i + 1; j < after; ++j) EXPECT_TRUE(tileRange(items, {j, count}).empty());
        if (after < count) {
          EXPECT_FALSE(tileRange(items, {after, count}).empty());
        }
        next = r.end;
      }
      EXPECT_EQ(next, items);
    }
  }
}

TEST(Tile, specParsingRejectsWhatIsNotATile) {
  Result<TileSpec> ok = parseTileSpec("--tile", "3/8");
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(ok->index, 3u);
  EXPECT_EQ(ok->count, 8u);
  for (const char* bad : {"5/4", "4/4", "0/0", "1", "a/2", "-1/2", "1/", "/2", "1/2/3", ""}) {
    Result<TileSpec> r = parseTileSpec("--tile", bad);
    ASSERT_FALSE(r.ok()) << bad;
    EXPECT_EQ(r.error().code, ExitCode::kUsage);
    EXPECT_TRUE(contains(r.error().message, std::string("--tile: '") + bad + "'"));
  }
}

// Two tiles of a square split down the middle: tile 0 owns the left column and copies the
// middle one, which tile 1 owns with the right column.
PointTile leftHalf() {
  PointTile t;
  t.tile = {0, 2};
  t.points.positions = {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}};
  t.points.colors = {glm::vec3(0.1f), glm::vec3(0.2f), glm::vec3(0.3f), glm::vec3(0.4f)};
  t.points.triangles = {0, 2, 1, 1, 2, 3};
  t.owned = 2;
  t.foreign = {{1, 0}, {1, 1}};
  return t;
}
PointTile rightHalf() {
  PointTile t;
  t.tile = {1, 2};
  t.points.positions = {{1, 0, 0}, {1, 1, 0}, {2, 0, 0}, {2, 1, 0}};
  t.points.colors = {glm::vec3(0.3f), glm::vec3(0.4f), glm::vec3(0.5f), glm::vec3(0.6f)};
  t.points.triangles = {0, 2, 1, 1, 2, 3};
  t.owned = 4;
  return t;
}

TEST(Tile, fileRoundTripIsExactAndAPlyReaderTakesIt) {
  TempDir dir;
  const PointTile left = leftHalf();
  ASSERT_TRUE(writeTile(dir.file("a.ply"), left, "kind x=1").ok());
  EXPECT_TRUE(isTileFile(dir.file("a.ply")));
  Result<PointTile> back = readTile(dir.file("a.ply"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->tile.index, 0u);
  EXPECT_EQ(back->tile.count, 2u);
  EXPECT_EQ(back->owned, 2u);
  EXPECT_TRUE(back->points.positions == left.points.positions);
  EXPECT_TRUE(back->points.colors == left.points.colors);
  EXPECT_TRUE(back->points.triangles == left.points.triangles);
  ASSERT_EQ(back->foreign.size(), 2u);
  EXPECT_EQ(back->foreign[1].tile, 1u);
  EXPECT_EQ(back->foreign[1].index, 1u);
  Result<TileHeader> h = readTileHeader(dir.file("a.ply"));
  ASSERT_TRUE(h.ok());
  EXPECT_EQ(h->signature, "kind x=1");
  // Any PLY reader sees a mesh: the copies are ordinary vertices, the foreign element is skipped.
  Result<PointSet> plain = readPly(dir.file("a.ply"));
  ASSERT_TRUE(plain.ok()) << plain.error().message;
  EXPECT_EQ(plain->size(), 4u);
  EXPECT_EQ(plain->triangles.size(), 6u);
  EXPECT_FALSE(isTileFile(DPOINT_SAMPLES_DIR "/earth_offset_mm.csv"));
}

TEST(Tile, mergeWeldsByIdentityInTileOrder) {
  TempDir dir;
  ASSERT_TRUE(writeTile(dir.file("b.ply"), rightHalf(), "s").ok());
  ASSERT_TRUE(writeTile(dir.file("a.ply"), leftHalf(), "s").ok());
  Result<PointSet> merged = mergeTiles({dir.file("b.ply"), dir.file("a.ply")});  // any order
  ASSERT_TRUE(merged.ok()) << merged.error().message;
  const PositionArray positions = {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}, {2, 0, 0}, {2, 1, 0}};
  EXPECT_TRUE(merged->positions == positions);
  EXPECT_EQ(merged->colors.size(), 6u);
  const std::vector<uint32_t> triangles = {0, 2, 1, 1, 2, 3, 2, 4, 3, 3, 4, 5};
  EXPECT_TRUE(merged->triangles == triangles);
}

TEST(Tile, mergeRejectsMissingRepeatedAndForeignTiles) {
  TempDir dir;
  ASSERT_TRUE(writeTile(dir.file("a.ply"), leftHalf(), "s").ok());
  ASSERT_TRUE(writeTile(dir.file("b.ply"), rightHalf(), "s").ok());
  ASSERT_TRUE(writeTile(dir.file("other.ply"), rightHalf(), "t").ok());
  PointTile three = rightHalf();
  three.tile = {1, 3};
  ASSERT_TRUE(writeTile(dir.file("three.ply"), three, "s").ok());

  Result<PointSet> r = mergeTiles({dir.file("a.ply")});
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "missing tile(s) 1 of 0..1"));
  r = mergeTiles({dir.file("a.ply"), dir.file("a.ply"), dir.file("b.ply")});
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "tile 0 again"));
  r = mergeTiles({dir.file("a.ply"), dir.file("other.ply")});
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "other.ply: a tile of another run"));
  r = mergeTiles({dir.file("a.ply"), dir.file("three.ply")});
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "three.ply: tile 1/3"));
  EXPECT_EQ(r.error().code, ExitCode::kBadInput);
}

TEST(Tile, mergeRejectsACopyThatDiffersFromItsOwner) {
  TempDir dir;
  PointTile left = leftHalf();
  left.points.positions[3].y = std::nextafter(1.0, 2.0);
  ASSERT_TRUE(writeTile(dir.file("a.ply"), left, "s").ok());
  ASSERT_TRUE(writeTile(dir.file("b.ply"), rightHalf(), "s").ok());
  Result<PointSet> r = mergeTiles({dir.file("a.ply"), dir.file("b.ply")});
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "a.ply: its copy of vertex 3 differs from the owner's position"));
  left = leftHalf();
  left.foreign[1] = {1, 9};
  ASSERT_TRUE(writeTile(dir.file("a.ply"), left, "s").ok());
  r = mergeTiles({dir.file("a.ply"), dir.file("b.ply")});
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "refers to vertex 9 of tile 1, which does not exist"));
}

// A vertex that is not finite is refused where the tile is read, by the merge in memory and the one
// that streams its rows to a PLY, naming the tile, the byte and the vertex, as the PLY reader names
// them (the build before merged a NaN into a file dpoint then refused, with exit 0).
TEST(Tile, mergeRefusesAVertexThatIsNotFinite) {
  TempDir dir;
  PointTile right = rightHalf();
  right.points.positions[2].y = std::numeric_limits<double>::quiet_NaN();
  ASSERT_TRUE(writeTile(dir.file("a.ply"), leftHalf(), "s").ok());
  ASSERT_TRUE(writeTile(dir.file("b.ply"), right, "s").ok());
  Result<PointSet> r = mergeTiles({dir.file("a.ply"), dir.file("b.ply")});
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "b.ply: byte ")) << r.error().message;
  EXPECT_TRUE(contains(r.error().message, ": vertex 2: y is nan, not a finite number")) << r.error().message;
  Status s = mergeTilesToPly({dir.file("a.ply"), dir.file("b.ply")}, dir.file("m.ply"), PlyWriteOptions{});
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().message, r.error().message);
  EXPECT_FALSE(std::filesystem::exists(dir.file("m.ply")));
}

TEST(Tile, readRejectsTruncatedAndMalformedFiles) {
  TempDir dir;
  ASSERT_TRUE(writeTile(dir.file("a.ply"), leftHalf(), "s").ok());
  const std::string bytes = readFile(dir.file("a.ply"));
  writeFile(dir.file("short.ply"), bytes.substr(0, bytes.size() - 3));
  Result<PointTile> r = readTile(dir.file("short.ply"));
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "short.ply: " + std::to_string(bytes.size() - 3) + " bytes, but the header describes"));
  std::string bad_face = bytes;
  const size_t faces = bad_face.find("end_header\n") + 11 + 4 * 36;
  bad_face[faces] = 4;
  writeFile(dir.file("face.ply"), bad_face);
  r = readTile(dir.file("face.ply"));
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "face 0 has 4 corners, not 3"));
  std::string bad_index = bytes;
  const uint32_t far = 7;
  std::memcpy(&bad_index[faces + 1], &far, sizeof far);
  writeFile(dir.file("index.ply"), bad_index);
  r = readTile(dir.file("index.ply"));
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "face 0 uses vertex 7 of 4"));
  std::string header = bytes;
  header.replace(header.find("property double y"), 17, "property float y ");
  writeFile(dir.file("header.ply"), header);
  r = readTile(dir.file("header.ply"));
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "expected 'property double y', found 'property float y '"));
  writeFile(dir.file("plain.ply"), "ply\nformat ascii 1.0\nelement vertex 0\nproperty double x\nend_header\n");
  r = readTile(dir.file("plain.ply"));
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "not a dpoint tile"));
}

}  // namespace
}  // namespace dpoint
