// The Mandelbulb (White & Nylander's spherical "triplex" power map, 2009) as the seed study built
// it: escape counts on a grid, meshed by marching cubes at max_iter/4 (escape_grid.h).
//
// Variant seed reproduces the seed's escape function bit for bit (its res-64 grid is
// shared/reference/mandelbulb_r64_i100_escape.u8): per iteration r = sqrt(x² + y² + z²),
// θ = acos(z/r), φ = atan2(y, x), r8 = ((r²)²)² (repeated squaring, not pow), new point
// r8·(sin 8θ cos 8φ, sin 8θ sin 8φ, cos 8θ) + c, evaluated left to right in double with glibc's
// libm and no FMA contraction; it returns the index i of the first iteration whose r (before the
// update) exceeds 2, or max_iter. Testing r before computing the update returns the same i and
// skips the discarded update. Other powers n use pow(r, n) and n·θ, n·φ (not bit-compared to
// anything). At r = 0 (the origin, sampled when the resolution is odd) the seed divides 0/0 and
// crashed; the map sends 0 to 0 + c, so the next point is c, and the origin itself never escapes.
//
// Variant fast (power 8 only) is the same map without trigonometry, by de Moivre: with
// ρ² = x² + y², r^8 (cos 8θ + i sin 8θ) = (z + iρ)^8 and cos 8φ + i sin 8φ = (x + iy)^8 / ρ^8,
// each power by three complex squarings: one square root and one division per iteration, and
// two points per SSE2 register. On the polar axis (ρ² ≤ 1e-60, where ρ^8 would underflow) φ is
// taken as 0, as the seed's atan2(0, 0) = 0 does (at ρ = 0 the point goes to (cx, cy, z^8 + cz));
// the map's own value differs by less than 1e-27 there. The escape test is r² > 4. Rounding
// differs from the seed's, so a few counts differ: 2,224 of the 8 million voxels of the res-200
// grid (0.028%), of which 2 change side of the level 25.
#pragma once

#include <cstdint>
#include <string>

#include "core/point_set.h"
#include "core/progress.h"
#include "core/result.h"
#include "generators/escape_grid.h"

namespace dpoint {

enum class MandelbulbVariant { kSeed, kFast };

// The fast variant's polar axis: at x² + y² ≤ this, φ is taken as 0 (see mandelbulb.cpp).
constexpr double kMandelbulbAxisRho2 = 1e-60;
// |c|² at or below which a point of the power-8 Mandelbulb never escapes (mandelbulb.cpp's trap:
// the ball of radius t − t^8 = 0.6501…, t = 8^(−1/7), lies in the set); 0.42 leaves 0.0026 of
// |c| for the rounding of either variant, far more than it needs.
constexpr double kMandelbulbTrapC2 = 0.42;

struct MandelbulbParams {
  int resolution = 200;          // grid points per axis, 2..65536
  int max_iter = 100;            // 1..65535
  double power = 8.0;
  double lo = -1.5, hi = 1.5;    // --bounds
  double level = -1.0;           // -1: max_iter / 4; else inside (0, max_iter)
  MandelbulbVariant variant = MandelbulbVariant::kSeed;
  GridFrame frame = GridFrame::kNative;
  std::string grid_out;          // also write the count grid there (escape_grid.h format)
  unsigned threads = 0;          // 0: all cores
  uint64_t max_memory = 0;       // bytes; 0: half of physical memory
  Progress* progress = nullptr;
  EscapePlaneFunction planes;    // the classification elsewhere (a GPU); empty: on the CPU
  EscapeArena arena;             // where `planes` writes fastest (escape_grid.h); empty: the heap
  EscapeSlabMesher mesher;       // meshes the slabs of `planes` elsewhere (escape_grid.h); empty: here
  bool noise_colors = false;     // the mesher makes the seed noise colours too where it can (escape_grid.h)
  EscapeRowSink rows;            // the mesh as PLY rows as it is made, where the mesher takes it (escape_grid.h)
  bool full_counts = false;      // every count to max_iter, not capped above the level (escape_grid.h)
};

// Welded surface mesh (no colours). Errors: bad parameters name the flag and the limit (kUsage;
// --variant fast with a power other than 8 too); over the memory limit (kResourceLimit).
Result<PointSet> generateMandelbulb(const MandelbulbParams& params);
// Tile `tile` of that mesh (escape_grid.h); same errors. With params.planes, variant seed is
// refused (kUsage): its libm calls have no bit-exact shader form.
Result<PointTile> generateMandelbulbTile(const MandelbulbParams& params, TileSpec tile);

// The escape counts themselves, for tests and --grid-out.
int mandelbulbEscapeSeed(double cx, double cy, double cz, int max_iter, double power = 8.0);
int mandelbulbEscapeFast(double cx, double cy, double cz, int max_iter);
EscapeRowFunction mandelbulbRow(MandelbulbVariant variant, double power);

}  // namespace dpoint
