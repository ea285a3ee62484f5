// Mandelbrot deep zoom by perturbation against one high-precision reference orbit.
//
// Sources:
// - K. I. Martin, "Superfractalthing maths" (2013): iterate each pixel's difference from a
//   reference orbit Z_n computed once in high precision and rounded to double,
//   δ_{n+1} = 2·Z_n·δ_n + δ_n² + δc, all in double. The rounded Z_n follow the true orbit (each
//   within about an ulp, not a pseudo-orbit drifting away as a double iteration does) and δ
//   carries only relative rounding, so the pixel orbits escape the chaotic growth of absolute
//   errors that plain double iteration suffers; δc is exact, so pixels are told apart even where
//   centre + offset is not a double.
// - Zhuoran (fractalforums.org, 2021), "rebasing": when |Z_m + δ| < |δ| the pixel is nearer the
//   start of the reference than its current point; set δ ← Z_m + δ and go on from Z_0 = 0. This
//   replaces glitch detection (Pauldelbrot's criterion) and needs one reference. The same step
//   covers a reference that escapes before the pixel: at its last point the pixel rebases.
//
// The reference orbit is computed in fixed point with 64-bit limbs (the library needs no MPFR;
// the tests compare against MPFR). Precision: the per-step truncation (≤ 2^-p) grows along the
// orbit as the orbit's own derivative with respect to c does, so to first order it acts on the
// image like moving the reference point by about 2^-p. p ≥ 64 + log2(1 / pixel spacing) keeps that
// under 2^-64 of a pixel at every depth: 120 fraction bits down to spacings of 2^-56, 1080 at the
// deepest allowed. (Double-double's 106 bits would fall short of this rule below spacings of 2^-42.)
#include "generators/mandelbrot2d.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <string>

#include <glm/vec2.hpp>

#include "core/interrupt.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "generators/escape_grid.h"

namespace dpoint {
namespace {

constexpr int kMaxResolution = 65536;
constexpr double kMinWidth = 1e-300;
// Views stay within ±1e300, so sums and differences of a centre and offsets never overflow (an
// infinite δc against an infinite reference point would make NaN orbits that never escape).
constexpr double kMaxExtent = 1e300;

constexpr uint32_t kPalettePeriod = 64;  // counts per colour cycle
constexpr int kPaletteStops = 5;
constexpr float kPalette[kPaletteStops][3] = {
    {0.02f, 0.05f, 0.35f}, {0.10f, 0.45f, 0.85f}, {0.95f, 0.97f, 0.90f},
    {0.95f, 0.60f, 0.05f}, {0.30f, 0.05f, 0.10f},
};

std::string formatDouble(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

// ---- fixed point: a two's-complement integer of `limbs` 64-bit words (least significant first)
// times 2^-fraction_bits, fraction_bits = 64·limbs − kIntegerBits ----

using u128 = unsigned __int128;

// Values stay below 2^7 in magnitude: |Z| ≤ 2 before escape, so |Z|² ≤ 4 and |Z|² + |c| ≤ 8
// (a reference with |c_x| or |c_y| > 4 is not iterated, see referenceOrbit).
constexpr int kIntegerBits = 8;
// Spacing ≥ 1e-300 / 65536 > 2^-1014, so p ≤ 64 + 1014 and limbs ≤ (1078 + 8) / 64 → 17.
constexpr int kMaxLimbs = 17;

using Limbs = std::array<uint64_t, kMaxLimbs>;

struct FixedFormat {
  int limbs;
  int fraction_bits() const { return 64 * limbs - kIntegerBits; }
};

bool isNegative(const Limbs& a, FixedFormat f) { return (a[static_cast<size_t>(f.limbs - 1)] >> 63) != 0; }

Limbs negate(const Limbs& a, FixedFormat f) {
  Limbs r{};
  uint64_t carry = 1;
  for (int i = 0; i < f.limbs; ++i) {
    const u128 t = static_cast<u128>(~a[static_cast<size_t>(i)]) + carry;
    r[static_cast<size_t>(i)] = static_cast<uint64_t>(t);
    carry = static_cast<uint64_t>(t >> 64);
  }
  return r;
}

Limbs add(const Limbs& a, const Limbs& b, FixedFormat f) {
  Limbs r{};
  uint64_t carry = 0;
  for (size_t i = 0; i < static_cast<size_t>(f.limbs); ++i) {
    const u128 t = static_cast<u128>(a[i]) + b[i] + carry;
    r[i] = static_cast<uint64_t>(t);
    carry = static_cast<uint64_t>(t >> 64);
  }
  return r;
}

Limbs sub(const Limbs& a, const Limbs& b, FixedFormat f) { return add(a, negate(b, f), f); }

// Product truncated toward zero: error < 2^-p.
Limbs mul(const Limbs& a, const Limbs& b, FixedFormat f) {
  const bool negative = isNegative(a, f) != isNegative(b, f);
  const Limbs x = isNegative(a, f) ? negate(a, f) : a;
  const Limbs y = isNegative(b, f) ? negate(b, f) : b;
  const size_t n = static_cast<size_t>(f.limbs);
  std::array<uint64_t, 2 * kMaxLimbs + 1> product{};
  for (size_t i = 0; i < n; ++i) {
    uint64_t carry = 0;
    for (size_t j = 0; j < n; ++j) {
      const u128 t = static_cast<u128>(x[i]) * y[j] + product[i + j] + carry;
      product[i + j] = static_cast<uint64_t>(t);
      carry = static_cast<uint64_t>(t >> 64);
    }
    product[i + n] = carry;
  }
  // Shift right by p = 64·(n − 1) + (64 − kIntegerBits) bits.
  constexpr int kShift = 64 - kIntegerBits;
  Limbs r{};
  for (size_t k = 0; k < n; ++k) r[k] = (product[k + n - 1] >> kShift) | (product[k + n] << (64 - kShift));
  return negative ? negate(r, f) : r;
}

// |value| < 2^(kIntegerBits − 1). Truncated toward zero below 2^-p (and below 2^-1074, where
// ldexp underflows: far under the tolerance above).
Limbs fromDouble(double value, FixedFormat f) {
  Limbs r{};
  double rest = std::abs(value);
  for (int i = f.limbs - 1; i >= 0; --i) {
    // rest < 2^(64·(i+1) − p): scaled so that limb i counts units, it is below 2^64.
    const double scaled = std::ldexp(rest, f.fraction_bits() - 64 * i);
    const double whole = std::floor(scaled);
    r[static_cast<size_t>(i)] = static_cast<uint64_t>(whole);
    rest = std::ldexp(scaled - whole, 64 * i - f.fraction_bits());  // exact: drops the integer part
  }
  return value < 0 ? negate(r, f) : r;
}

// Correctly rounded (to nearest): the 64 bits from the leading one, with a sticky bit for the rest,
// so the integer-to-double conversion rounds exactly as the whole value would.
double toDouble(const Limbs& a, FixedFormat f) {
  const bool negative = isNegative(a, f);
  const Limbs m = negative ? negate(a, f) : a;
  int top = f.limbs - 1;
  while (top >= 0 && m[static_cast<size_t>(top)] == 0) --top;
  if (top < 0) return 0.0;
  const int lead = 64 * top + 63 - __builtin_clzll(m[static_cast<size_t>(top)]);  // index of the leading one
  const int start = lead - 63;
  uint64_t window;
  bool sticky = false;
  if (start <= 0) {
    window = m[0] << (-start);
  } else {
    const size_t q = static_cast<size_t>(start / 64);
    const int s = start % 64;
    const uint64_t high = q + 1 < static_cast<size_t>(f.limbs) ? m[q + 1] : 0;
    window = s == 0 ? m[q] : (m[q] >> s) | (high << (64 - s));
    sticky = s != 0 && (m[q] << (64 - s)) != 0;
    for (size_t i = 0; i < q && !sticky; ++i) sticky = m[i] != 0;
  }
  // The lowest window bit lies 11 places under double's last, so it only breaks exact ties.
  const double d = std::ldexp(static_cast<double>(window | (sticky ? 1u : 0u)), start - f.fraction_bits());
  return negative ? -d : d;
}

FixedFormat referenceFormat(double spacing) {
  int exponent;
  std::frexp(spacing, &exponent);  // spacing ≥ 2^(exponent − 1)
  const int fraction_bits = 64 + std::max(0, 1 - exponent);
  const int limbs = std::max(2, (fraction_bits + kIntegerBits + 63) / 64);
  assert(limbs <= kMaxLimbs);  // validate() keeps width ≥ 1e-300
  return {limbs};
}

// ---- the orbits ----

// Knuth's two-sum: sum + error == a + b exactly (no overflow: views stay within ±1e300).
void twoSum(double a, double b, double& sum, double& error) {
  sum = a + b;
  const double b_virtual = sum - a;
  error = (a - (sum - b_virtual)) + (b - b_virtual);
}

// Z_0 = 0, Z_1 = c, ... each rounded to double, up to and including the first escaped point or
// Z_max_iter. c = centre + offset exactly (up to 2^-p). Always holds Z_0 and Z_1.
std::vector<glm::dvec2> referenceOrbit(glm::dvec2 center, glm::dvec2 offset, int max_iter, double spacing) {
  std::vector<glm::dvec2> orbit;
  orbit.reserve(static_cast<size_t>(max_iter) + 1);
  orbit.emplace_back(0.0, 0.0);
  glm::dvec2 sum, error;
  twoSum(center.x, offset.x, sum.x, error.x);
  twoSum(center.y, offset.y, sum.y, error.y);
  if (std::abs(sum.x) > 4.0 || std::abs(sum.y) > 4.0) {
    orbit.push_back(sum);  // |c| > 2: escaped at the first step
    return orbit;
  }
  // |sum| ≤ 4 and |error| ≤ ulp(sum) / 2: both within the fixed-point range.
  const FixedFormat f = referenceFormat(spacing);
  const Limbs cx = add(fromDouble(sum.x, f), fromDouble(error.x, f), f);
  const Limbs cy = add(fromDouble(sum.y, f), fromDouble(error.y, f), f);
  Limbs x{}, y{};
  for (int n = 0; n < max_iter; ++n) {
    const Limbs xy = mul(x, y, f);
    x = add(sub(mul(x, x, f), mul(y, y, f), f), cx, f);
    y = add(add(xy, xy, f), cy, f);
    const glm::dvec2 z(toDouble(x, f), toDouble(y, f));
    orbit.push_back(z);
    if (z.x * z.x + z.y * z.y > 4.0) break;  // the rounded test suffices: it only ends the orbit
  }
  return orbit;
}

uint32_t doubleCount(double cx, double cy, int max_iter) {
  double x = 0.0, y = 0.0;
  for (int n = 0; n < max_iter; ++n) {
    const double next_x = x * x - y * y + cx;
    y = 2.0 * x * y + cy;
    x = next_x;
    if (x * x + y * y > 4.0) return static_cast<uint32_t>(n);
  }
  return static_cast<uint32_t>(max_iter);
}

// The pixel's orbit is z_n = Z_m + δ (m = n until the first rebase).
uint32_t perturbedCount(const std::vector<glm::dvec2>& orbit, double dcx, double dcy, int max_iter) {
  const size_t last = orbit.size() - 1;
  size_t m = 0;
  double dx = 0.0, dy = 0.0;
  for (int n = 0; n < max_iter; ++n) {
    // δ ← (2·Z_m + δ)·δ + δc: 2·Z·δ + δ² as one complex product.
    const double tx = 2.0 * orbit[m].x + dx;
    const double ty = 2.0 * orbit[m].y + dy;
    const double next_dx = tx * dx - ty * dy + dcx;
    dy = tx * dy + ty * dx + dcy;
    dx = next_dx;
    ++m;
    const double zx = orbit[m].x + dx;
    const double zy = orbit[m].y + dy;
    const double z2 = zx * zx + zy * zy;
    if (z2 > 4.0) return static_cast<uint32_t>(n);
    if (z2 < dx * dx + dy * dy || m == last) {  // rebase onto Z_0 = 0
      dx = zx;
      dy = zy;
      m = 0;
    }
  }
  return static_cast<uint32_t>(max_iter);
}

double pixelSpacing(const Mandelbrot2dParams& p) { return p.width / p.resolution; }

// Offset of pixel `index` from the centre: the half-integer factor is exact, so one rounding.
double pixelOffset(int index, int resolution, double spacing) { return (index + 0.5 - resolution / 2.0) * spacing; }

// The reference: a grid point and its orbit. Pixels use δc = fl(pixel offset − reference offset),
// exact for the centre and otherwise off by ≤ 2^-53·width: under 2^-37 of a pixel spacing.
struct Reference {
  glm::dvec2 offset{0.0};
  std::vector<glm::dvec2> orbit;
};

// A reference that escapes early leaves pixels that outlive it to rebase at its end and iterate
// their full z, where double's absolute error costs counts near the boundary. So the orbit should
// last: start at the centre; while it escapes, probe a kProbeGrid² subgrid against it and move to
// the probe that lasts longest (nearest the centre on ties). Deterministic, at most 3·33² pixels.
constexpr int kProbeGrid = 33;
constexpr int kReferenceRounds = 3;

Reference chooseReference(const Mandelbrot2dParams& p) {
  const double spacing = pixelSpacing(p);
  const glm::dvec2 center(p.center_x, p.center_y);
  Reference best;
  best.orbit = referenceOrbit(center, best.offset, p.max_iter, spacing);
  const size_t probes = static_cast<size_t>(std::min(kProbeGrid, p.resolution));
  const auto probePixel = [&](size_t k) {  // evenly spread pixel indices
    return static_cast<int>((2 * k + 1) * static_cast<size_t>(p.resolution) / (2 * probes));
  };
  std::vector<uint32_t> counts(probes * probes);
  for (int round = 0; round < kReferenceRounds; ++round) {
    const size_t length = best.orbit.size() - 1;  // the reference's last index
    if (length >= static_cast<size_t>(p.max_iter)) break;
    parallelFor(probes, p.threads, [&](size_t i, unsigned) {
      const double dcy = pixelOffset(probePixel(i), p.resolution, spacing) - best.offset.y;
      for (size_t j = 0; j < probes; ++j) {
        const double dcx = pixelOffset(probePixel(j), p.resolution, spacing) - best.offset.x;
        counts[i * probes + j] = perturbedCount(best.orbit, dcx, dcy, p.max_iter);
      }
    });
    size_t pick = 0;
    int64_t pick_distance = 0;
    for (size_t k = 0; k < counts.size(); ++k) {
      const int64_t di = 2 * probePixel(k / probes) + 1 - p.resolution;
      const int64_t dj = 2 * probePixel(k % probes) + 1 - p.resolution;
      const int64_t distance = di * di + dj * dj;
      if (k == 0 || counts[k] > counts[pick] || (counts[k] == counts[pick] && distance < pick_distance)) {
        pick = k;
        pick_distance = distance;
      }
    }
    if (counts[pick] < length) break;  // no probe outlasts the reference
    Reference next;
    next.offset = glm::dvec2(pixelOffset(probePixel(pick % probes), p.resolution, spacing),
                             pixelOffset(probePixel(pick / probes), p.resolution, spacing));
    next.orbit = referenceOrbit(center, next.offset, p.max_iter, spacing);
    if (next.orbit.size() <= best.orbit.size()) break;
    best = std::move(next);
  }
  return best;
}

Status validate(const Mandelbrot2dParams& p) {
  // Too large is a resource limit (exit 4), like the memory estimate it would otherwise fail.
  if (p.resolution < 2 || p.resolution > kMaxResolution)
    return Error{"--resolution must be in [2, " + std::to_string(kMaxResolution) + "], got " +
                     std::to_string(p.resolution),
                 p.resolution < 2 ? ExitCode::kUsage : ExitCode::kResourceLimit};
  if (p.max_iter < 1)
    return Error{"--max-iter must be at least 1, got " + std::to_string(p.max_iter), ExitCode::kUsage};
  if (!p.grid_out.empty() && p.max_iter > kMaxEscapeIterations)
    return Error{"--grid-out stores counts up to " + std::to_string(kMaxEscapeIterations) + ", but --max-iter is " +
                     std::to_string(p.max_iter),
                 ExitCode::kUsage};
  if (!std::isfinite(p.width) || !(p.width >= kMinWidth))
    return Error{"--width must be finite and at least 1e-300, got " + formatDouble(p.width), ExitCode::kUsage};
  const std::string center = formatDouble(p.center_x) + "," + formatDouble(p.center_y);
  if (!(std::abs(p.center_x) <= kMaxExtent) || !(std::abs(p.center_y) <= kMaxExtent))
    return Error{"--center must be finite and within ±1e300, got " + center, ExitCode::kUsage};
  if (std::max(std::abs(p.center_x), std::abs(p.center_y)) + p.width > kMaxExtent)
    return Error{"--width " + formatDouble(p.width) + " around --center " + center + " reaches past ±1e300",
                 ExitCode::kUsage};
  return okStatus();
}

// Two reference orbits live at once while the reference is chosen.
uint64_t referenceBytes(const Mandelbrot2dParams& p) {
  if (p.method == Mandelbrot2dMethod::kDouble) return 0;
  return 2 * (static_cast<uint64_t>(p.max_iter) + 1) * sizeof(glm::dvec2);
}

// `rows` of the grid at bytes_per_point, and the reference orbits.
Status checkBudget(const Mandelbrot2dParams& p, uint64_t rows, uint64_t bytes_per_point) {
  const uint64_t points = rows * static_cast<uint64_t>(p.resolution);
  return checkMemory("mandelbrot2d at --resolution " + std::to_string(p.resolution) + " with --max-iter " +
                         std::to_string(p.max_iter),
                     points * bytes_per_point + referenceBytes(p), p.max_memory);
}

// Fills counts of rows [first_row, first_row + rows) (rows·resolution, preallocated). Each row writes
// only its own cells, so the result does not depend on the thread count.
Status computeCounts(const Mandelbrot2dParams& p, size_t first_row, size_t rows, std::vector<uint32_t>& counts) {
  const bool perturb = p.method == Mandelbrot2dMethod::kPerturbation;
  const Reference reference = perturb ? chooseReference(p) : Reference{};
  const double spacing = pixelSpacing(p);
  const size_t res = static_cast<size_t>(p.resolution);
  if (perturb && p.perturbation) {  // elsewhere (a GPU), from the same δc
    std::vector<double> dcx(res), dcy(rows);
    for (size_t col = 0; col < res; ++col)
      dcx[col] = pixelOffset(static_cast<int>(col), p.resolution, spacing) - reference.offset.x;
    for (size_t row = 0; row < rows; ++row)
      dcy[row] = pixelOffset(static_cast<int>(first_row + row), p.resolution, spacing) - reference.offset.y;
    return p.perturbation(reference.orbit, dcx, dcy, p.max_iter, counts.data());
  }
  if (p.progress) p.progress->start("mandelbrot2d", static_cast<uint64_t>(res) * rows);
  parallelFor(rows, p.threads, [&](size_t r, unsigned) {
    if (interrupted()) return;  // computeCounts returns interruptedError()
    const size_t row = first_row + r;
    const double offset_y = pixelOffset(static_cast<int>(row), p.resolution, spacing);
    uint32_t* out = counts.data() + r * res;
    for (int col = 0; col < p.resolution; ++col) {
      const double offset_x = pixelOffset(col, p.resolution, spacing);
      out[col] = perturb ? perturbedCount(reference.orbit, offset_x - reference.offset.x,
                                          offset_y - reference.offset.y, p.max_iter)
                         : doubleCount(p.center_x + offset_x, p.center_y + offset_y, p.max_iter);
    }
    if (p.progress) p.progress->advance(res);
  });
  if (p.progress) p.progress->finish();
  if (interrupted()) return interruptedError();
  return okStatus();
}

// Rows [first_row, first_row + rows) of the grid as points.
Result<PointSet> generateRows(const Mandelbrot2dParams& params, size_t first_row, size_t rows) {
  if (Status s = validate(params); !s) return s.error();
  const size_t res = static_cast<size_t>(params.resolution);
  if (Status s = checkBudget(params, rows, sizeof(uint32_t) + sizeof(glm::dvec3) + sizeof(glm::vec3)); !s)
    return s.error();
  std::vector<uint32_t> counts(rows * res);
  if (Status s = computeCounts(params, first_row, rows, counts); !s) return s.error();
  if (!params.grid_out.empty())
    if (Status s = writeEscapeGrid(params.grid_out, counts, params.max_iter); !s) return s.error();
  PointSet set;
  set.positions.resize(rows * res);
  set.colors.resize(rows * res);
  const double spacing = pixelSpacing(params);
  parallelFor(rows, params.threads, [&](size_t r, unsigned) {
    // Correctly rounded centre + offset (the offsets are exact doubles).
    const double y = params.center_y + pixelOffset(static_cast<int>(first_row + r), params.resolution, spacing);
    for (size_t col = 0; col < res; ++col) {
      const size_t i = r * res + col;
      const double x = params.center_x + pixelOffset(static_cast<int>(col), params.resolution, spacing);
      set.positions[i] = glm::dvec3(x, y, 0.0);
      set.colors[i] = mandelbrot2dColor(counts[i], params.max_iter);
    }
  });
  return set;
}

}  // namespace

glm::vec3 mandelbrot2dColor(uint32_t count, int max_iter) {
  if (max_iter <= 0 || count >= static_cast<uint32_t>(max_iter)) return glm::vec3(0.0f);
  // Cyclic and piecewise linear, stop i at phase i / kPaletteStops; float arithmetic only, so the
  // colours do not depend on the math library.
  const float phase =
      static_cast<float>(count % kPalettePeriod) * (static_cast<float>(kPaletteStops) / kPalettePeriod);
  const int stop = static_cast<int>(phase);
  const float t = phase - static_cast<float>(stop);
  const float* a = kPalette[stop];
  const float* b = kPalette[(stop + 1) % kPaletteStops];
  return glm::vec3(a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t);
}

Result<std::vector<uint32_t>> mandelbrot2dCounts(const Mandelbrot2dParams& params) {
  if (Status s = validate(params); !s) return s.error();
  const size_t res = static_cast<size_t>(params.resolution);
  if (Status s = checkBudget(params, res, sizeof(uint32_t)); !s) return s.error();
  std::vector<uint32_t> counts(res * res);
  if (Status s = computeCounts(params, 0, res, counts); !s) return s.error();
  return counts;
}

Result<PointSet> generateMandelbrot2d(const Mandelbrot2dParams& params) {
  return generateRows(params, 0, static_cast<size_t>(std::max(params.resolution, 0)));
}

Result<PointTile> generateMandelbrot2dTile(const Mandelbrot2dParams& params, TileSpec tile) {
  if (Status s = validate(params); !s) return s.error();
  const TileRange rows = tileRange(static_cast<uint64_t>(params.resolution), tile);
  PointTile out;
  out.tile = tile;
  if (rows.empty()) {  // more tiles than rows: no points, an empty piece of the grid file
    if (!params.grid_out.empty())
      if (Status s = writeEscapeGrid(params.grid_out, {}, params.max_iter); !s) return s.error();
    return out;
  }
  Result<PointSet> points = generateRows(params, rows.begin, rows.end - rows.begin);
  if (!points) return points.error();
  if (points->size() > UINT32_MAX)
    return Error{"mandelbrot2d: tile " + std::to_string(tile.index) + " has more than 2^32 points; use more tiles",
                 ExitCode::kResourceLimit};
  out.owned = static_cast<uint32_t>(points->size());
  out.points = std::move(*points);
  return out;
}

}  // namespace dpoint
