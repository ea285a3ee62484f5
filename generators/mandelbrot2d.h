// The study's 2D deep-zoom dataset: a resolution² grid of points around a centre of the Mandelbrot
// set, coloured by smooth escape count.
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
//
// max_iter auto (the default): autoMaxIter(width), growing with the zoom depth.
//
// Colour (issue #24): histogram-equalised over the smooth count. An escaped point's orbit goes on
// past the bailout until |z_j|² > kTailRadius2 (the escape tail, EscapeTail), and its smooth count
// is ν = j + 1 − log2(log2 |z_j|²) (the usual j + 1 − log2(log2 |z_j|), less 1): continuous in c
// where the count jumps by 1, and a little above the count (by 0.15 to 1.2 in the default view at
// 1e-12). The colour is palette(F(ν)), F the empirical distribution of ν over a low-resolution
// pre-pass of the whole view (kPrepassResolution² points of the same view against the same
// reference), so that every tile maps its points through the same F and the tiles are the whole
// set bit for bit; the palette spreads over the smooth counts present, whatever the depth. Points
// counted max_iter are black.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
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

// The escape tail of a point: the orbit iterated on past the count (the same steps, rebases
// included) while |z|² ≤ kTailRadius2, at most kMaxTailSteps more. The shader
// (shaders/generate/perturbation.comp) writes the same 16 bytes (std430).
inline constexpr double kTailRadius2 = 0x1p64;  // |z| > 2^32: ν's error from the finite radius is ~2^-64
inline constexpr uint32_t kMaxTailSteps = 64;   // from |z|² > 4 a tail takes about 6 steps; near c = −2 more
struct EscapeTail {
  double z2 = 0.0;      // |z_j|² at the tail's end, j = count + 1 + steps; 0 for a point counted max_iter
  uint32_t steps = 0;   // steps past the escape
  uint32_t unused = 0;  // std430 padding
};
static_assert(sizeof(EscapeTail) == 16);

// Perturbation counts computed elsewhere (a GPU, generators/gpu_generate.h): counts[r·dcx.size() + c]
// = the pixel count of δc = (dcx[c], dcy[r]) against `orbit` (the reference Z_0, Z_1, ...), and
// tails[r·dcx.size() + c] its escape tail, both equal to the CPU's bit for bit.
using PerturbationFunction =
    std::function<Status(const std::vector<glm::dvec2>& orbit, const std::vector<double>& dcx,
                         const std::vector<double>& dcy, int max_iter, uint32_t* counts, EscapeTail* tails)>;

// The pre-pass whose smooth counts make the colour distribution: this many points per side
// (fewer when the resolution is lower: then the pre-pass is the grid itself).
inline constexpr int kPrepassResolution = 128;

struct Mandelbrot2dParams {
  double center_x = -0.7436450;
  double center_y = 0.1318259;
  double width = 1e-6;           // view width; the view is square
  int resolution = 1024;         // points per side, 2..65536
  std::optional<int> max_iter;   // at least 1; empty: auto, autoMaxIter(width)
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
// histogram-equalised over the smooth count (above), black for count == max_iter. Errors: kUsage
// naming --resolution, --max-iter, --width, --center or --grid-out and the limit; kResourceLimit
// over max_memory; the grid file's.
Result<PointSet> generateMandelbrot2d(const Mandelbrot2dParams& params);

// Tile `tile` (core/tile.h): rows [⌊I·res/N⌋, ⌊(I+1)·res/N⌋), same order and values. Same errors.
Result<PointTile> generateMandelbrot2dTile(const Mandelbrot2dParams& params, TileSpec tile);

// The escape counts alone, row-major: counts[row * resolution + col]. Same errors.
Result<std::vector<uint32_t>> mandelbrot2dCounts(const Mandelbrot2dParams& params);

// The counts and their escape tails, row-major. Same errors.
struct Mandelbrot2dEscapes {
  std::vector<uint32_t> counts;
  std::vector<EscapeTail> tails;
};
Result<Mandelbrot2dEscapes> mandelbrot2dEscapes(const Mandelbrot2dParams& params);

// --max-iter auto: max(2000, 50·d²) rounded to the nearest integer, where d = log10(4 / width) is
// the zoom depth (4: the width that shows the whole set). 2000 down to width 1.9e-6 (d = √40), then
// 2179 at 1e-6, 4610 at 1e-9, 7941 at 1e-12, 12171 at 1e-15, about 4.5 million at 1e-300: the
// escape counts near the boundary grow with the depth (the minibrots met on the way down have ever
// longer periods), and quadratic growth keeps ahead of them without making shallow views slower.
// Computed with basic operations only (no libm), so every machine picks the same value. `width`
// finite and > 0.
int autoMaxIter(double width);

// The max_iter a generation uses: params.max_iter, or autoMaxIter(width) for auto. The same errors
// as generateMandelbrot2d's parameter checks.
Result<int> mandelbrot2dMaxIter(const Mandelbrot2dParams& params);

// ν = j + 1 − log2(log2 z2), j = count + 1 + tail.steps, z2 = tail.z2 (clamped to [4, DBL_MAX]),
// for an escaped point (count < max_iter). log2 from basic operations only: the same bits everywhere.
double mandelbrot2dSmoothCount(uint32_t count, const EscapeTail& tail);

// The palette: position f in [0, 1] (the point's share of the escaped points with a lower smooth
// count) → linear RGB in [0, 1], dark blue through white to dark red; float arithmetic only, so the
// colours do not depend on the math library.
glm::vec3 mandelbrot2dPalette(float f);

}  // namespace dpoint
