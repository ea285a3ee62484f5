// The Menger sponge as an exact surface mesh (--method exact).
//
// Level n is the union of the 20^n unit cells (x, y, z) of the integer lattice [0, 3^n)³ for
// which no base-3 digit position has a 1 in two or more of x, y, z. The mesh is the set of
// exposed cell faces (a face whose neighbouring cell is outside the sponge or outside the cube),
// 2·20^n + 4·8^n unit quads, each split into 2 triangles, counter-clockwise seen from outside.
// Exact by construction: every vertex is a lattice point, and the coordinate of lattice integer k
// is computed once as (k·size)/3^n (for size 1 a single correctly rounded division, k/3^n), so
// points on one lattice plane share one coordinate bit for bit and vertices are welded by their
// integer coordinates, never by comparing doubles.
#pragma once

#include <cstdint>

#include "core/point_set.h"
#include "core/progress.h"
#include "core/result.h"
#include "core/tile.h"

namespace dpoint {

constexpr int kMengerMaxLevel = 8;

enum class MengerMethod {
  kExact,  // the exposed faces of the lattice cubes (this file)
  kVoxel,  // sampled on a grid and meshed by marching cubes, as the seed did (menger_voxel.cpp)
};

struct MengerParams {
  int level = 4;                 // 0..kMengerMaxLevel
  double size = 1.0;             // edge length; the sponge spans [0, size]³
  MengerMethod method = MengerMethod::kExact;
  int resolution = 200;          // voxel method: samples per axis across the sponge
  unsigned threads = 0;          // 0: all cores
  uint64_t max_memory = 0;       // bytes; 0: half of physical memory
  Progress* progress = nullptr;
};

// The exact method (`--method exact`, so far the only one). Vertices: every lattice point that is a corner of an exposed face, once, ordered by (x, y, z)
// lattice coordinates (x slowest). Triangles: the quads of the cell slabs x = 0, 1, ... in turn;
// within a slab by cell row y, then face direction (−x, +x, −y, +y, −z, +z), then z.
// The surface is closed and consistently oriented, and it has no edge where it touches itself:
// every directed edge of the triangles appears exactly once and its reverse exactly once (tested
// for levels 0..4, seen for 5: of the 4 cells around a lattice edge, never just a diagonal pair is
// in the sponge).
// Errors: level outside 0..kMengerMaxLevel or size not finite and positive (kUsage); over the
// memory limit (kResourceLimit, checked before anything large is allocated).
Result<PointSet> generateMenger(const MengerParams& params);

// Tile `tile` (core/tile.h) of the exact mesh: the cell slabs x ∈ [⌊I·3^n/N⌋, ⌊(I+1)·3^n/N⌋), owning
// the points of their planes but the last, which opens the next tile's. Same errors; --method
// voxel is refused (kUsage).
Result<PointTile> generateMengerTile(const MengerParams& params, TileSpec tile);

// The voxel method: the sponge's occupancy sampled at the centres of resolution³ voxels over
// [0, size]³ (1 inside, 0 outside, with a border of empty samples so the surface closes), meshed
// by marching cubes at level 0.5. Approximates the surface within one voxel; kept to reproduce
// the seed's datasets. Called by generateMenger after its checks of level and size; errors:
// resolution out of 2..4096 (kUsage), memory.
Result<PointSet> generateMengerVoxel(const MengerParams& params);

// True when lattice cell (x, y, z) of level n (coordinates in [0, 3^n)) belongs to the sponge.
bool mengerCellInSponge(uint64_t x, uint64_t y, uint64_t z);

// 2·20^n + 4·8^n: the number of exposed unit faces of the level-n sponge.
uint64_t mengerFaceCount(int level);

// The number of vertices of the level-n mesh, (224·20^n + 456·8^n + 384)/133 (8, 64, 896, 15232,
// ...). Fitted to the exact counts of levels 0..5, which it matches with three to spare (the tests
// check it against the generator), and used to size the memory check before anything is built.
uint64_t mengerVertexCount(int level);

}  // namespace dpoint
