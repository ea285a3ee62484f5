// The Sierpinski tetrahedron of the seed study: 4^n tetrahedra after n midpoint subdivisions of
// the seed's regular tetrahedron, 4 outward-facing triangles each.
//
// Exact by construction: tetrahedron t of level n has its corners on the lattice of barycentric
// coordinates (a, b, c, d)/2^n with a + b + c + d = 2^n (integers). Every corner is computed from
// its integer lattice coordinates by a fixed formula, each coordinate with a single rounding (see
// sierpinski.cpp), never by repeated midpoints, so a point shared by two tetrahedra comes out
// bit-identical from both and welding by exact equality is the true vertex set: 2·4^n + 2
// vertices. The seed's four corners are reproduced exactly.
#pragma once

#include <cstdint>

#include "core/point_set.h"
#include "core/progress.h"
#include "core/result.h"
#include "core/tile.h"

namespace dpoint {

constexpr int kSierpinskiMaxLevel = 12;

struct SierpinskiParams {
  int level = 9;                 // 0..kSierpinskiMaxLevel
  bool unwelded = false;         // the seed's 4^(n+1) rows instead of the 2·4^n + 2 vertices
  unsigned threads = 0;          // 0: all cores
  uint64_t max_memory = 0;       // bytes; 0: half of physical memory
  Progress* progress = nullptr;
};

// Tetrahedra are numbered in the seed's order: t's base-4 digits, most significant first, are the
// child chosen at each subdivision (child k keeps corner k and halves the edges toward it, so its
// corner j is the midpoint of the parent's corners k and j).
//
// Unwelded: row 4t + j is corner j of tetrahedron t (4^(n+1) rows, the seed's order).
// Welded: the distinct corners in the order of their first row in the unwelded listing (the
// unwelded rows with repeats dropped).
// Both: triangles 12t .. 12t+11 are the 4 faces of tetrahedron t, the face opposite corner k
// k-th, each counter-clockwise seen from outside.
// Errors: level outside 0..kSierpinskiMaxLevel (kUsage), over the memory limit (kResourceLimit).
Result<PointSet> generateSierpinski(const SierpinskiParams& params);

// Tile `tile` (core/tile.h): tetrahedra [⌊I·4^n/N⌋, ⌊(I+1)·4^n/N⌋) with the vertices whose first
// occurrence they hold (welded) or their 4 rows each (unwelded); a corner first met in an earlier
// tile is a foreign vertex. Same errors.
Result<PointTile> generateSierpinskiTile(const SierpinskiParams& params, TileSpec tile);

// The seed's corners: (0,0,1), (√(8/9),0,−1/3), (−√(2/9),√(2/3),−1/3), (−√(2/9),−√(2/3),−1/3).
glm::dvec3 sierpinskiCorner(int k);

}  // namespace dpoint
