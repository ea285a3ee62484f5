// Tiles: one dataset computed as N independent parts (`dpoint generate KIND --tile I/N`) on any
// scheduler, and welded back into the file a single process writes, byte for byte
// (`dpoint merge`). This is the model: which share of the work a tile owns, and what a tile holds.
// The part file and the merge are converters/tile_file.h.
//
// Every generator numbers its vertices in one canonical order that does not depend on how the work
// is cut (the slabs of marching_cubes.h, the lattice planes of menger.h, the tetrahedra of
// sierpinski.h, the rows of mandelbrot2d and random2d). A tile computes a contiguous piece of that
// order: the vertices it *owns*, which in the whole set are consecutive and in the same order, and
// the triangles of its piece of the triangle order. Triangles may use vertices another tile owns
// (the seam plane of the next slab, a corner shared with an earlier tetrahedron); the tile then
// holds a copy of each such *foreign* vertex and the reference (owning tile, index among its owned
// vertices). Merging is thus concatenation with an index offset per tile, no geometric search: the
// weld is by identity, and the copies only serve to check it (a copy must equal its owner's vertex
// bit for bit, colour included).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/point_set.h"
#include "core/progress.h"
#include "core/result.h"

namespace dpoint {

// Tile `index` of `count` (0 ≤ index < count).
struct TileSpec {
  uint32_t index = 0;
  uint32_t count = 1;
};

// "I/N" with 0 ≤ I < N ≤ kMaxTiles. The error (kUsage) names `flag` and quotes the text.
constexpr uint32_t kMaxTiles = 1u << 20;
Result<TileSpec> parseTileSpec(const std::string& flag, const std::string& text);

// The tile's share of `items` work units (planes, rows, tetrahedra, points) in order:
// [⌊I·items/N⌋, ⌊(I+1)·items/N⌋). Empty when N > items for some tiles; the shares of all tiles
// partition [0, items).
struct TileRange {
  uint64_t begin = 0, end = 0;
  bool empty() const { return begin == end; }
};
TileRange tileRange(uint64_t items, TileSpec tile);
// The first tile after `tile` whose share of `items` is not empty; tile.count when there is none.
uint32_t nextNonEmptyTile(uint64_t items, TileSpec tile);
// The tile whose share of `items` holds `item` (< items).
uint32_t tileOfItem(uint64_t items, uint32_t count, uint64_t item);

struct TileVertexRef {
  uint32_t tile = 0;   // the owning tile
  uint32_t index = 0;  // among that tile's owned vertices
};

// One tile of a dataset. points.positions[0, owned) are the tile's own vertices, in the whole set's
// order; positions [owned, size) are copies of foreign vertices, foreign[i] naming the owner of
// copy owned + i. Triangles index into all of them (the whole set's triangle order).
struct PointTile {
  TileSpec tile;
  PointSet points;
  uint32_t owned = 0;
  std::vector<TileVertexRef> foreign;
};

}  // namespace dpoint
