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
//
// Colouring (issue #24):
// - The smooth ("normalised") iteration count: for |z_j| large, log|z_{j+1}| ≈ 2·log|z_j|, so
//   j − log2(log|z_j|) tends to a continuous function of c (Douady–Hubbard potential, G(c) =
//   lim 2^-j·log|z_j|); Linas Vepstas, "Renormalizing the Mandelbrot escape" (1997). The bailout
//   |z|² > 4 that defines the count is too small a radius for it, hence the tail to 2^64.
// - Histogram equalisation of the smooth count (as in fractal renderers since Kalles Fraktaler):
//   at depth most points share a count band, and a palette over counts shows one colour (97.5% of
//   the default 1e-12 view did); the empirical distribution spreads the palette over what is there.
#include "generators/mandelbrot2d.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <string>

#include <glm/vec2.hpp>

#include "core/interrupt.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "core/text.h"
#include "generators/escape_grid.h"

namespace dpoint {
namespace {

constexpr int kMaxResolution = 65536;
constexpr double kMinWidth = 1e-300;
// Views stay within ±1e300, so sums and differences of a centre and offsets never overflow (an
// infinite δc against an infinite reference point would make NaN orbits that never escape).
constexpr double kMaxExtent = 1e300;

constexpr int kPaletteStops = 5;
constexpr float kPalette[kPaletteStops][3] = {
    {0.02f, 0.05f, 0.35f}, {0.10f, 0.45f, 0.85f}, {0.95f, 0.97f, 0.90f},
    {0.95f, 0.60f, 0.05f}, {0.30f, 0.05f, 0.10f},
};

constexpr int kMinAutoIter = 2000;  // --max-iter auto's floor: the old default

// log2(x) for finite x > 0 from frexp (exact), +, −, × and ÷ only, so the same bits on every machine
// and libm: colours and --max-iter auto must not depend on the math library. x = m·2^e with m in
// [√½, √2); ln m = 2·atanh(s), s = (m − 1)/(m + 1), |s| ≤ 0.1716, whose series to s^25 leaves a
// truncation under 1e-20 (the rounding of the sum, a few 1e-16 relative, dominates).
double portableLog2(double x) {
  assert(x > 0.0 && x <= DBL_MAX);
  int e = 0;
  double m = std::frexp(x, &e);  // [0.5, 1)
  constexpr double kSqrtHalf = 0.70710678118654752440;
  if (m < kSqrtHalf) {
    m *= 2.0;  // exact
    --e;
  }
  // 1 / (2k + 1), k = 0..12, rounded to nearest as the compiler folds them (as the FPU would).
  static constexpr double kInverseOdd[13] = {1.0,      1.0 / 3,  1.0 / 5,  1.0 / 7,  1.0 / 9,
                                             1.0 / 11, 1.0 / 13, 1.0 / 15, 1.0 / 17, 1.0 / 19,
                                             1.0 / 21, 1.0 / 23, 1.0 / 25};
  const double s = (m - 1.0) / (m + 1.0);
  const double s2 = s * s;
  double series = 0.0;  // Σ s^(2k) / (2k + 1), by Horner
  for (int k = 12; k >= 0; --k) series = series * s2 + kInverseOdd[k];
  constexpr double kInvLn2 = 1.44269504088896340736;  // 1 / ln 2
  return static_cast<double>(e) + 2.0 * s * series * kInvLn2;
}

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
  orbit.reserve(std::min<size_t>(static_cast<size_t>(max_iter) + 1, size_t{1} << 16));  // auto may be millions
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

uint32_t doubleCount(double cx, double cy, int max_iter, EscapeTail& tail) {
  double x = 0.0, y = 0.0;
  for (int n = 0; n < max_iter; ++n) {
    const double next_x = x * x - y * y + cx;
    y = 2.0 * x * y + cy;
    x = next_x;
    double z2 = x * x + y * y;
    if (z2 > 4.0) {
      uint32_t steps = 0;
      for (; z2 <= kTailRadius2 && steps < kMaxTailSteps; ++steps) {
        const double tail_x = x * x - y * y + cx;
        y = 2.0 * x * y + cy;
        x = tail_x;
        z2 = x * x + y * y;
      }
      tail = {z2, steps, 0};
      return static_cast<uint32_t>(n);
    }
  }
  tail = {};
  return static_cast<uint32_t>(max_iter);
}

// One perturbation step, δ ← (2·Z_m + δ)·δ + δc: 2·Z·δ + δ² as one complex product.
inline void perturbationStep(glm::dvec2 reference, double dcx, double dcy, double& dx, double& dy) {
  const double tx = 2.0 * reference.x + dx;
  const double ty = 2.0 * reference.y + dy;
  const double next_dx = tx * dx - ty * dy + dcx;
  dy = tx * dy + ty * dx + dcy;
  dx = next_dx;
}

// The pixel's orbit is z_n = Z_m + δ (m = n until the first rebase). Past the escape the tail goes
// on with the same steps: the rebase test the loop skipped at the escape comes first.
uint32_t perturbedCount(const std::vector<glm::dvec2>& orbit, double dcx, double dcy, int max_iter, EscapeTail& tail) {
  const size_t last = orbit.size() - 1;
  size_t m = 0;
  double dx = 0.0, dy = 0.0;
  for (int n = 0; n < max_iter; ++n) {
    perturbationStep(orbit[m], dcx, dcy, dx, dy);
    ++m;
    double zx = orbit[m].x + dx;
    double zy = orbit[m].y + dy;
    double z2 = zx * zx + zy * zy;
    if (z2 > 4.0) {
      uint32_t steps = 0;
      for (; z2 <= kTailRadius2 && steps < kMaxTailSteps; ++steps) {
        if (z2 < dx * dx + dy * dy || m == last) {
          dx = zx;
          dy = zy;
          m = 0;
        }
        perturbationStep(orbit[m], dcx, dcy, dx, dy);
        ++m;
        zx = orbit[m].x + dx;
        zy = orbit[m].y + dy;
        z2 = zx * zx + zy * zy;
      }
      tail = {z2, steps, 0};
      return static_cast<uint32_t>(n);
    }
    if (z2 < dx * dx + dy * dy || m == last) {  // rebase onto Z_0 = 0
      dx = zx;
      dy = zy;
      m = 0;
    }
  }
  tail = {};
  return static_cast<uint32_t>(max_iter);
}

double pixelSpacing(const Mandelbrot2dParams& p) { return p.width / p.resolution; }

// The max_iter of parameters resolved by resolveParams.
int iterations(const Mandelbrot2dParams& p) {
  assert(p.max_iter);
  return *p.max_iter;
}

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
  const int max_iter = iterations(p);
  best.orbit = referenceOrbit(center, best.offset, max_iter, spacing);
  const size_t probes = static_cast<size_t>(std::min(kProbeGrid, p.resolution));
  const auto probePixel = [&](size_t k) {  // evenly spread pixel indices
    return static_cast<int>((2 * k + 1) * static_cast<size_t>(p.resolution) / (2 * probes));
  };
  std::vector<uint32_t> counts(probes * probes);
  for (int round = 0; round < kReferenceRounds; ++round) {
    const size_t length = best.orbit.size() - 1;  // the reference's last index
    if (length >= static_cast<size_t>(max_iter)) break;
    parallelFor(probes, p.threads, [&](size_t i, unsigned) {
      const double dcy = pixelOffset(probePixel(i), p.resolution, spacing) - best.offset.y;
      EscapeTail tail;
      for (size_t j = 0; j < probes; ++j) {
        const double dcx = pixelOffset(probePixel(j), p.resolution, spacing) - best.offset.x;
        counts[i * probes + j] = perturbedCount(best.orbit, dcx, dcy, max_iter, tail);
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
    next.orbit = referenceOrbit(center, next.offset, max_iter, spacing);
    if (next.orbit.size() <= best.orbit.size()) break;
    best = std::move(next);
  }
  return best;
}

Status validate(const Mandelbrot2dParams& p) {
  // A fixed range: outside it is a usage error either way (a size inside it that needs more memory
  // than there is fails the memory estimate, exit 4, later).
  if (p.resolution < 2 || p.resolution > kMaxResolution)
    return Error{"--resolution " + std::to_string(p.resolution) + ": must be 2.." + std::to_string(kMaxResolution),
                 ExitCode::kUsage};
  if (p.max_iter && *p.max_iter < 1)
    return Error{"--max-iter " + std::to_string(*p.max_iter) + ": must be at least 1", ExitCode::kUsage};
  if (!std::isfinite(p.width) || !(p.width >= kMinWidth))
    return Error{"--width must be finite and at least 1e-300, got " + formatDouble(p.width), ExitCode::kUsage};
  const std::string center = formatDouble(p.center_x) + "," + formatDouble(p.center_y);
  if (!(std::abs(p.center_x) <= kMaxExtent) || !(std::abs(p.center_y) <= kMaxExtent))
    return Error{"--center must be finite and within ±1e300, got " + center, ExitCode::kUsage};
  if (std::max(std::abs(p.center_x), std::abs(p.center_y)) + p.width > kMaxExtent)
    return Error{"--width " + formatDouble(p.width) + " around --center " + center + " reaches past ±1e300",
                 ExitCode::kUsage};
  const int max_iter = p.max_iter ? *p.max_iter : autoMaxIter(p.width);
  if (!p.grid_out.empty() && max_iter > kMaxEscapeIterations)
    return Error{"--grid-out stores counts up to " + std::to_string(kMaxEscapeIterations) + ", but --max-iter is " +
                     (p.max_iter ? std::to_string(max_iter)
                                 : "auto, " + std::to_string(max_iter) + " at --width " + formatNumber(p.width) +
                                       " (give a --max-iter)"),
                 ExitCode::kUsage};
  return okStatus();
}

// Checked parameters with max_iter resolved (auto: autoMaxIter).
Result<Mandelbrot2dParams> resolveParams(const Mandelbrot2dParams& params) {
  if (Status s = validate(params); !s) return s.error();
  Mandelbrot2dParams p = params;
  if (!p.max_iter) p.max_iter = autoMaxIter(p.width);
  return p;
}

// Two reference orbits live at once while the reference is chosen.
uint64_t referenceBytes(const Mandelbrot2dParams& p) {
  if (p.method == Mandelbrot2dMethod::kDouble) return 0;
  return 2 * (static_cast<uint64_t>(iterations(p)) + 1) * sizeof(glm::dvec2);
}

// The pre-pass: its grid, escapes and sorted smooth counts.
uint64_t prepassBytes() {
  return static_cast<uint64_t>(kPrepassResolution) * kPrepassResolution *
         (sizeof(uint32_t) + sizeof(EscapeTail) + sizeof(double));
}

// `rows` of the grid at bytes_per_point, the reference orbits and the pre-pass.
Status checkBudget(const Mandelbrot2dParams& p, uint64_t rows, uint64_t bytes_per_point) {
  const uint64_t points = rows * static_cast<uint64_t>(p.resolution);
  return checkMemory("mandelbrot2d at --resolution " + std::to_string(p.resolution) + " with --max-iter " +
                         std::to_string(iterations(p)),
                     points * bytes_per_point + referenceBytes(p) + prepassBytes(), p.max_memory);
}

// A square grid over the view: the output's (resolution, width / resolution) or the pre-pass's.
struct Grid {
  int resolution;
  double spacing;
};

// Escapes of rows [first_row, first_row + rows) of `grid` into counts and tails (rows·resolution
// each, preallocated). Each row writes only its own cells, so the result does not depend on the
// thread count. `progress` may be null.
Status computeEscapes(const Mandelbrot2dParams& p, const Reference& reference, Grid grid, size_t first_row, size_t rows,
                      uint32_t* counts, EscapeTail* tails, Progress* progress) {
  const bool perturb = p.method == Mandelbrot2dMethod::kPerturbation;
  const int max_iter = iterations(p);
  const size_t res = static_cast<size_t>(grid.resolution);
  if (perturb && p.perturbation) {  // elsewhere (a GPU), from the same δc
    std::vector<double> dcx(res), dcy(rows);
    for (size_t col = 0; col < res; ++col)
      dcx[col] = pixelOffset(static_cast<int>(col), grid.resolution, grid.spacing) - reference.offset.x;
    for (size_t row = 0; row < rows; ++row)
      dcy[row] = pixelOffset(static_cast<int>(first_row + row), grid.resolution, grid.spacing) - reference.offset.y;
    return p.perturbation(reference.orbit, dcx, dcy, max_iter, counts, tails);
  }
  if (progress) progress->start("mandelbrot2d", static_cast<uint64_t>(res) * rows);
  parallelFor(rows, p.threads, [&](size_t r, unsigned) {
    if (interrupted()) return;  // computeEscapes returns interruptedError()
    const size_t row = first_row + r;
    const double offset_y = pixelOffset(static_cast<int>(row), grid.resolution, grid.spacing);
    uint32_t* out = counts + r * res;
    EscapeTail* tail = tails + r * res;
    for (int col = 0; col < grid.resolution; ++col) {
      const double offset_x = pixelOffset(col, grid.resolution, grid.spacing);
      out[col] = perturb ? perturbedCount(reference.orbit, offset_x - reference.offset.x,
                                          offset_y - reference.offset.y, max_iter, tail[col])
                         : doubleCount(p.center_x + offset_x, p.center_y + offset_y, max_iter, tail[col]);
    }
    if (progress) progress->advance(res);
  });
  if (progress) progress->finish();
  if (interrupted()) return interruptedError();
  return okStatus();
}

Reference referenceFor(const Mandelbrot2dParams& p) {
  return p.method == Mandelbrot2dMethod::kPerturbation ? chooseReference(p) : Reference{};
}

// The smooth counts of the escaped points among `counts`, sorted: the empirical distribution the
// colours follow.
std::vector<double> sortedSmoothCounts(const std::vector<uint32_t>& counts, const std::vector<EscapeTail>& tails,
                                       int max_iter) {
  std::vector<double> smooth;
  smooth.reserve(counts.size());
  for (size_t i = 0; i < counts.size(); ++i)
    if (counts[i] < static_cast<uint32_t>(max_iter)) smooth.push_back(mandelbrot2dSmoothCount(counts[i], tails[i]));
  std::sort(smooth.begin(), smooth.end());
  return smooth;
}

// The pre-pass over the whole view: a kPrepassResolution² grid (the output grid itself when that is
// no larger), against the output's reference.
Result<std::vector<double>> prepassDistribution(const Mandelbrot2dParams& p, const Reference& reference) {
  const int res = std::min(kPrepassResolution, p.resolution);
  const Grid grid{res, p.width / res};
  const size_t points = static_cast<size_t>(res) * static_cast<size_t>(res);
  std::vector<uint32_t> counts(points);
  std::vector<EscapeTail> tails(points);
  if (Status s = computeEscapes(p, reference, grid, 0, static_cast<size_t>(res), counts.data(), tails.data(), nullptr);
      !s)
    return s.error();
  return sortedSmoothCounts(counts, tails, iterations(p));
}

// The share of `sorted` below ν, linear between neighbouring values: 0 at or below the lowest, 1 at
// or above the highest. Basic operations only (the same bits everywhere).
double distributionAt(const std::vector<double>& sorted, double nu) {
  if (sorted.empty() || nu <= sorted.front()) return 0.0;
  if (nu >= sorted.back()) return 1.0;
  // sorted[k] ≤ ν < sorted[k + 1], so the two differ.
  const size_t k = static_cast<size_t>(std::upper_bound(sorted.begin(), sorted.end(), nu) - sorted.begin()) - 1;
  const double within = (nu - sorted[k]) / (sorted[k + 1] - sorted[k]);
  return (static_cast<double>(k) + within) / static_cast<double>(sorted.size() - 1);
}

// Rows [first_row, first_row + rows) of the grid as points.
Result<PointSet> generateRows(const Mandelbrot2dParams& params, size_t first_row, size_t rows) {
  Result<Mandelbrot2dParams> resolved = resolveParams(params);
  if (!resolved) return resolved.error();
  const Mandelbrot2dParams& p = *resolved;
  const int max_iter = iterations(p);
  const size_t res = static_cast<size_t>(p.resolution);
  if (Status s = checkBudget(p, rows, sizeof(uint32_t) + sizeof(EscapeTail) + sizeof(glm::dvec3) + sizeof(glm::vec3));
      !s)
    return s.error();
  const Reference reference = referenceFor(p);
  std::vector<uint32_t> counts(rows * res);
  std::vector<EscapeTail> tails(rows * res);
  const Grid grid{p.resolution, pixelSpacing(p)};
  if (Status s = computeEscapes(p, reference, grid, first_row, rows, counts.data(), tails.data(), p.progress); !s)
    return s.error();
  if (!p.grid_out.empty())
    if (Status s = writeEscapeGrid(p.grid_out, counts, max_iter); !s) return s.error();
  // The whole grid no larger than the pre-pass is the pre-pass: the same δc, the same escapes.
  Result<std::vector<double>> distribution = p.resolution <= kPrepassResolution && rows == res
                                                 ? sortedSmoothCounts(counts, tails, max_iter)
                                                 : prepassDistribution(p, reference);
  if (!distribution) return distribution.error();
  PointSet set;
  resizePrefaulted(set.positions, rows * res, p.threads);
  resizePrefaulted(set.colors, rows * res, p.threads);
  parallelFor(rows, p.threads, [&](size_t r, unsigned) {
    // Correctly rounded centre + offset (the offsets are exact doubles).
    const double y = p.center_y + pixelOffset(static_cast<int>(first_row + r), p.resolution, grid.spacing);
    for (size_t col = 0; col < res; ++col) {
      const size_t i = r * res + col;
      const double x = p.center_x + pixelOffset(static_cast<int>(col), p.resolution, grid.spacing);
      set.positions[i] = glm::dvec3(x, y, 0.0);
      set.colors[i] = counts[i] >= static_cast<uint32_t>(max_iter)
                          ? glm::vec3(0.0f)
                          : mandelbrot2dPalette(static_cast<float>(
                                distributionAt(*distribution, mandelbrot2dSmoothCount(counts[i], tails[i]))));
    }
  });
  return set;
}

}  // namespace

int autoMaxIter(double width) {
  assert(width > 0.0 && width <= DBL_MAX);
  const double depth = portableLog2(std::min(4.0 / width, DBL_MAX)) / portableLog2(10.0);
  const double iter = 50.0 * depth * depth;
  if (!(iter > kMinAutoIter)) return kMinAutoIter;  // also a width above 4 (negative depth)
  return static_cast<int>(iter + 0.5);  // d ≤ 309 even for DBL_MAX / 4: at most 4.8 million
}

Result<int> mandelbrot2dMaxIter(const Mandelbrot2dParams& params) {
  Result<Mandelbrot2dParams> p = resolveParams(params);
  if (!p) return p.error();
  return iterations(*p);
}

double mandelbrot2dSmoothCount(uint32_t count, const EscapeTail& tail) {
  // Past DBL_MAX (a view far outside, where |z_1|² = |c|² overflows) the last double stands in. An
  // escaped orbit only grows (|z| > 2 ≥ |c|, or z_1 = c), but the clamp at 4 keeps log2(log2) finite
  // should rounding ever take a tail's last step back under the bailout.
  const double z2 = std::clamp(tail.z2, 4.0, DBL_MAX);
  const double j = static_cast<double>(count) + 1.0 + static_cast<double>(tail.steps);
  return j + 1.0 - portableLog2(portableLog2(z2));
}

glm::vec3 mandelbrot2dPalette(float f) {
  // Piecewise linear through the stops, stop i at f = i / (kPaletteStops − 1); float arithmetic
  // only, so the colours do not depend on the math library.
  const float phase = std::clamp(f, 0.0f, 1.0f) * static_cast<float>(kPaletteStops - 1);
  const int stop = std::min(static_cast<int>(phase), kPaletteStops - 2);
  const float t = phase - static_cast<float>(stop);
  const float* a = kPalette[stop];
  const float* b = kPalette[stop + 1];
  return glm::vec3(a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t);
}

Result<Mandelbrot2dEscapes> mandelbrot2dEscapes(const Mandelbrot2dParams& params) {
  Result<Mandelbrot2dParams> resolved = resolveParams(params);
  if (!resolved) return resolved.error();
  const Mandelbrot2dParams& p = *resolved;
  const size_t res = static_cast<size_t>(p.resolution);
  if (Status s = checkBudget(p, res, sizeof(uint32_t) + sizeof(EscapeTail)); !s) return s.error();
  Mandelbrot2dEscapes escapes;
  escapes.counts.resize(res * res);
  escapes.tails.resize(res * res);
  if (Status s = computeEscapes(p, referenceFor(p), Grid{p.resolution, pixelSpacing(p)}, 0, res, escapes.counts.data(),
                                escapes.tails.data(), p.progress);
      !s)
    return s.error();
  return escapes;
}

Result<std::vector<uint32_t>> mandelbrot2dCounts(const Mandelbrot2dParams& params) {
  Result<Mandelbrot2dEscapes> escapes = mandelbrot2dEscapes(params);
  if (!escapes) return escapes.error();
  return std::move(escapes->counts);
}

Result<PointSet> generateMandelbrot2d(const Mandelbrot2dParams& params) {
  return generateRows(params, 0, static_cast<size_t>(std::max(params.resolution, 0)));
}

Result<PointTile> generateMandelbrot2dTile(const Mandelbrot2dParams& params, TileSpec tile) {
  Result<Mandelbrot2dParams> resolved = resolveParams(params);
  if (!resolved) return resolved.error();
  const TileRange rows = tileRange(static_cast<uint64_t>(params.resolution), tile);
  PointTile out;
  out.tile = tile;
  if (rows.empty()) {  // more tiles than rows: no points, an empty piece of the grid file
    if (!params.grid_out.empty())
      if (Status s = writeEscapeGrid(params.grid_out, {}, iterations(*resolved)); !s) return s.error();
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
