// The seed study's "quaternion Julia" set: the quaternion map q → q² + c on the slice where the
// fourth component of the start point is 0, c = (−0.7, 0.27015, 0.27015, 0), sampled on a grid and
// meshed by marching cubes at max_iter/4 (escape_grid.h).
//
// Escape function, matching shared/reference/julia_r64_i200_escape.u8 byte for byte: start at
// q = (x, y, z, 0); per iteration i, if |q| > 2 return i, else q ← (x² − y² − z² − w², 2xy, 2xz,
// 2xw) + c (the square of a quaternion); max_iter if it never escapes. The sums are grouped as
// x² − (y² + z² + w²) and x² + (y² + z² + w²), which are symmetric in y and z, so with cy = cz the
// grid is exactly mirror symmetric (grid[i][j][k] = grid[i][k][j]); grouping left to right gives
// the same reference grid but no such guarantee.
#pragma once

#include <cstdint>
#include <string>

#include <glm/vec4.hpp>

#include "core/point_set.h"
#include "core/progress.h"
#include "core/result.h"
#include "generators/escape_grid.h"

namespace dpoint {

// The escape test sqrt(s) > 2 with a correctly rounded square root holds exactly when
// s > 4 + 2^-50, the double after 4: doubles in [4, 8) are 2^-50 apart, and sqrt(4 + 2^-50) =
// 2 + 2^-52 − ε lies below the midpoint 2 + 2^-52 between 2 and the next double, so it rounds to 2
// (not above 2), while sqrt(4 + 2^-49) = 2 + 2^-51 − ε rounds up. A device whose square root is
// not correctly rounded tests s against this instead (shaders/generate/escape.comp); tested exhaustively
// near 4.
constexpr double kJuliaEscapeSquare = 0x1.0000000000001p+2;

struct JuliaParams {
  int resolution = 200;          // grid points per axis, 2..65536
  int max_iter = 200;            // 1..65535
  glm::dvec4 c = glm::dvec4(-0.7, 0.27015, 0.27015, 0.0);
  double lo = -1.5, hi = 1.5;    // --bounds
  double level = -1.0;           // -1: max_iter / 4; else inside (0, max_iter)
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

// Welded surface mesh (no colours). Errors: bad parameters name the flag and the limit (kUsage);
// over the memory limit (kResourceLimit).
Result<PointSet> generateJulia(const JuliaParams& params);
// Tile `tile` of that mesh (escape_grid.h); same errors.
Result<PointTile> generateJuliaTile(const JuliaParams& params, TileSpec tile);

int juliaEscape(double x, double y, double z, const glm::dvec4& c, int max_iter);
EscapeRowFunction juliaRow(const glm::dvec4& c);

}  // namespace dpoint
