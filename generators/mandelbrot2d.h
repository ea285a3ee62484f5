// The study's 2D deep-zoom dataset: a resolution² grid of points around a centre of the Mandelbrot
// set, coloured by escape count.
//
// Grid: pixel spacing h = fl(width / resolution); pixel (row, col) has the offset
//   (fl((col + 0.5 - resolution/2) · h), fl((row + 0.5 - resolution/2) · h))
// from the centre (the half-integer factor is exact, so each offset is one rounding), rows going up
// in y. The sampled point is c = centre + offset, the exact sum: the centre is carried separately,
// so the iteration sees that sum (to within 2^-37 of a pixel spacing, see the .cpp) even where it
// is not a double. The emitted position is the correctly rounded sum fl(centre + offset), z = 0;
// where the spacing is below an ulp of the centre, neighbouring points share a position.
//
// Escape count of c (0-based): the smallest n in [0, max_iter) with |z_{n+1}|² > 4, where
// z_0 = 0 and z_{n+1} = z_n² + c; max_iter when there is none. So c itself escapes at count 0 when
// |c| > 2, and a point counted max_iter was iterated max_iter times without leaving the disc.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include <glm/vec2.hpp>

#include "core/point_set.h"
#include "core/progress.h"
#include "core/result.h"
#include "core/tile.h"

namespace dpoint {

// Perturbation is used at every width: against MPFR on 64² grids around the study's centre, plain
// double already gets 1.4% of the counts wrong at width 1e-6 and 5% at 1e-9 (perturbation: 0.2%).
enum class Mandelbrot2dMethod {
  kPerturbation,  // high-precision reference orbit, double deltas per pixel (see the .cpp)
  kDouble,        // z_{n+1} = z_n² + fl(c) in double per pixel: for comparison only
};

// Perturbation counts computed elsewhere (a GPU, generators/gpu_generate.h): counts[r·dcx.size() + c]
// = the pixel count of δc = (dcx[c], dcy[r]) against `orbit` (the reference Z_0, Z_1, ...), equal to
// the CPU's bit for bit.
using PerturbationFunction =
    std::function<Status(const std::vector<glm::dvec2>& orbit, const std::vector<double>& dcx,
                         const std::vector<double>& dcy, int max_iter, uint32_t* counts)>;

struct Mandelbrot2dParams {
  double center_x = -0.7436450;
  double center_y = 0.1318259;
  double width = 1e-6;           // view width; the view is square
  int resolution = 1024;         // points per side, 2..65536
  int max_iter = 2000;           // at least 1
  unsigned threads = 0;          // 0: all cores
  uint64_t max_memory = 0;       // bytes; 0: half of physical memory
  Progress* progress = nullptr;
  Mandelbrot2dMethod method = Mandelbrot2dMethod::kPerturbation;
  PerturbationFunction perturbation;  // perturbation deltas elsewhere (a GPU); empty: on the CPU
  // Also write the counts there, row-major, in the escape-grid format (escape_grid.h; a tile its
  // rows); needs max_iter ≤ kMaxEscapeIterations.
  std::string grid_out;
};

// resolution² points in row-major order (row 0 at the lowest y), every grid point emitted; colour
// from a cyclic palette over the escape count, black for count == max_iter. Errors: kUsage naming
// --resolution, --max-iter, --width, --center or --grid-out and the limit; kResourceLimit over
// max_memory; the grid file's.
Result<PointSet> generateMandelbrot2d(const Mandelbrot2dParams& params);

// Tile `tile` (core/tile.h): rows [⌊I·res/N⌋, ⌊(I+1)·res/N⌋), same order and values. Same errors.
Result<PointTile> generateMandelbrot2dTile(const Mandelbrot2dParams& params, TileSpec tile);

// The escape counts alone, row-major: counts[row * resolution + col]. Same errors.
Result<std::vector<uint32_t>> mandelbrot2dCounts(const Mandelbrot2dParams& params);

// The palette: count → linear RGB in [0, 1]; black for count >= max_iter.
glm::vec3 mandelbrot2dColor(uint32_t count, int max_iter);

}  // namespace dpoint
