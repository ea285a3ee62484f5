// Every generator's tiles, merged, are its whole set bit for bit and in the same order: at small
// sizes, odd tile counts, and more tiles than the generator has work units.
#include <gtest/gtest.h>

#include <cstring>
#include <functional>

#include "converters/tile_file.h"
#include "generators/julia.h"
#include "generators/mandelbrot2d.h"
#include "generators/mandelbulb.h"
#include "generators/menger.h"
#include "generators/random2d.h"
#include "generators/sierpinski.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::TempDir;

// Bit for bit (NaN-proof); memcmp is never given an empty vector's null data (UBSan).
void expectSameBits(const PointSet& a, const PointSet& b) {
  ASSERT_EQ(a.size(), b.size());
  if (a.size() > 0) {
    EXPECT_EQ(std::memcmp(a.positions.data(), b.positions.data(), a.size() * sizeof(glm::dvec3)), 0);
  }
  ASSERT_EQ(a.colors.size(), b.colors.size());
  if (!a.colors.empty()) {
    EXPECT_EQ(std::memcmp(a.colors.data(), b.colors.data(), a.colors.size() * sizeof(glm::vec3)), 0);
  }
  EXPECT_TRUE(a.triangles == b.triangles);
}

// Generates each tile, writes it, merges the files: the result must be `whole`.
void expectTilesMakeWhole(const PointSet& whole, uint32_t count, const std::function<Result<PointTile>(TileSpec)>& tile) {
  SCOPED_TRACE("N = " + std::to_string(count));
  TempDir dir;
  std::vector<std::string> paths;
  size_t foreign = 0;
  for (uint32_t i = count; i-- > 0;) {  // any order
    Result<PointTile> part = tile({i, count});
    ASSERT_TRUE(part.ok()) << part.error().message;
    EXPECT_EQ(part->tile.index, i);
    foreign += part->foreign.size();
    paths.push_back(dir.file("part-" + std::to_string(i) + ".ply"));
    ASSERT_TRUE(writeTile(paths.back(), *part, "test").ok());
  }
  Result<PointSet> merged = mergeTiles(paths);
  ASSERT_TRUE(merged.ok()) << merged.error().message;
  expectSameBits(whole, *merged);
  if (count == 1) {
    EXPECT_EQ(foreign, 0u);
  }
}

TEST(GeneratorTiles, mandelbulbTilesMergeToTheWholeMesh) {
  for (MandelbulbVariant variant : {MandelbulbVariant::kSeed, MandelbulbVariant::kFast}) {
    MandelbulbParams params;
    params.resolution = 27;  // odd: the origin is sampled; 26 cell layers
    params.variant = variant;
    Result<PointSet> whole = generateMandelbulb(params);
    ASSERT_TRUE(whole.ok());
    for (uint32_t n : {1u, 3u, 7u, 40u})
      expectTilesMakeWhole(*whole, n, [&](TileSpec t) { return generateMandelbulbTile(params, t); });
  }
}

TEST(GeneratorTiles, juliaTilesMergeToTheWholeMeshAndGridPieces) {
  JuliaParams params;
  params.resolution = 30;
  TempDir dir;
  params.grid_out = dir.file("whole.u8");
  Result<PointSet> whole = generateJulia(params);
  ASSERT_TRUE(whole.ok());
  std::string pieces;
  for (uint32_t i = 0; i < 5; ++i) {
    JuliaParams part = params;
    part.grid_out = dir.file("grid-" + std::to_string(i) + ".u8");
    ASSERT_TRUE(generateJuliaTile(part, {i, 5}).ok());
    pieces += test::readFile(part.grid_out);
  }
  EXPECT_TRUE(pieces == test::readFile(params.grid_out)) << "the grid pieces concatenated are the whole grid";
  params.grid_out.clear();
  for (uint32_t n : {2u, 5u, 31u})
    expectTilesMakeWhole(*whole, n, [&](TileSpec t) { return generateJuliaTile(params, t); });
}

TEST(GeneratorTiles, mengerTilesMergeToTheWholeMesh) {
  for (int level : {0, 1, 2}) {
    MengerParams params;
    params.level = level;
    Result<PointSet> whole = generateMenger(params);
    ASSERT_TRUE(whole.ok());
    for (uint32_t n : {1u, 2u, 5u, 11u})
      expectTilesMakeWhole(*whole, n, [&](TileSpec t) { return generateMengerTile(params, t); });
  }
  MengerParams voxel;
  voxel.method = MengerMethod::kVoxel;
  Result<PointTile> refused = generateMengerTile(voxel, {0, 2});
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("--method voxel has no split"), std::string::npos);
}

TEST(GeneratorTiles, sierpinskiTilesMergeToTheWholeMesh) {
  for (bool unwelded : {false, true}) {
    for (int level : {0, 1, 3, 4}) {
      SierpinskiParams params;
      params.level = level;
      params.unwelded = unwelded;
      Result<PointSet> whole = generateSierpinski(params);
      ASSERT_TRUE(whole.ok());
      for (uint32_t n : {1u, 3u, 7u, 300u})
        expectTilesMakeWhole(*whole, n, [&](TileSpec t) { return generateSierpinskiTile(params, t); });
    }
  }
}

TEST(GeneratorTiles, pointSetTilesMergeToTheWholeSet) {
  Random2dParams random;
  random.count = 1001;
  Result<PointSet> points = generateRandom2d(random);
  ASSERT_TRUE(points.ok());
  for (uint32_t n : {1u, 3u, 7u})
    expectTilesMakeWhole(*points, n, [&](TileSpec t) { return generateRandom2dTile(random, t); });
  Mandelbrot2dParams zoom;
  zoom.resolution = 23;
  zoom.max_iter = 400;
  Result<PointSet> grid = generateMandelbrot2d(zoom);
  ASSERT_TRUE(grid.ok());
  for (uint32_t n : {2u, 7u, 30u})
    expectTilesMakeWhole(*grid, n, [&](TileSpec t) { return generateMandelbrot2dTile(zoom, t); });
}

TEST(GeneratorTiles, mandelbrot2dTilesShareTheWholeViewsColours) {
  // Above the pre-pass's resolution (kPrepassResolution), with auto max_iter: every tile maps its
  // points through the distribution of the whole view, so the colours are the whole set's.
  for (double width : {1e-6, 1e-12}) {
    SCOPED_TRACE(width);
    Mandelbrot2dParams zoom;
    zoom.width = width;
    zoom.resolution = kPrepassResolution + 23;
    if (width == 1e-6) zoom.max_iter = 500;  // the inside costs max_iter per point
    Result<PointSet> grid = generateMandelbrot2d(zoom);
    ASSERT_TRUE(grid.ok());
    for (uint32_t n : {3u, 7u})
      expectTilesMakeWhole(*grid, n, [&](TileSpec t) { return generateMandelbrot2dTile(zoom, t); });
  }
}

}  // namespace
}  // namespace dpoint
