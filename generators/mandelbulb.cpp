#include "generators/mandelbulb.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <charconv>
#include <cmath>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace dpoint {
namespace {

// Off the polar axis the fast map divides by ρ^8 = (x² + y²)^4, which stays a normal double
// while x² + y² > 1e-60. Closer to the axis the map's limit is used instead; it differs from the
// map by |Im (z + iρ)^8| ≤ 8·r^7·ρ < 1e-27 (r ≤ 2: only such points are updated).
constexpr double kAxisRho2 = kMandelbulbAxisRho2;

// (re + i·im)^8 by three complex squarings.
inline void power8(double& re, double& im) {
  for (int s = 0; s < 3; ++s) {
    const double r2 = re * re - im * im;
    im = 2.0 * re * im;
    re = r2;
  }
}

// One step of the fast map; false when r² > 4 (escaped before the update, as the seed tests).
// (cos 8φ, sin 8φ) = (x + iy)^8 / (x² + y²)^4 and r^8 (cos 8θ, sin 8θ) = (z + iρ)^8: the division
// does not wait for the square root, which keeps the chain of dependent operations short.
inline bool fastStep(double& x, double& y, double& z, double cx, double cy, double cz) {
  const double rho2 = x * x + y * y;
  if (rho2 + z * z > 4.0) return false;
  double wr = z, wi = std::sqrt(rho2);  // r (cos θ + i sin θ)
  double cp = x, sp = y;
  power8(cp, sp);
  if (rho2 > kAxisRho2) {
    const double q = rho2 * rho2;
    const double inv = 1.0 / (q * q);
    cp = cp * inv;
    sp = sp * inv;
  } else {  // φ = 0 on the axis, as the seed's atan2(0, 0)
    cp = 1.0;
    sp = 0.0;
  }
  power8(wr, wi);
  x = wi * cp + cx;
  y = wi * sp + cy;
  z = wr + cz;
  return true;
}

// Whether c lies in the ball whose points never escape (the trap of mandelbulbEscapeSeed, for the
// fast map: it lands within r^8 + |c| as the seed's does, its rounding as far below the margin).
inline bool trapped(double cx, double cy, double cz) { return cx * cx + cy * cy + cz * cz <= kMandelbulbTrapC2; }

#if defined(__SSE2__)
inline void power8(__m128d& re, __m128d& im) {
  const __m128d two = _mm_set1_pd(2.0);
  for (int s = 0; s < 3; ++s) {
    const __m128d r2 = _mm_sub_pd(_mm_mul_pd(re, re), _mm_mul_pd(im, im));
    im = _mm_mul_pd(_mm_mul_pd(two, re), im);
    re = r2;
  }
}

// fastStep on two points at once (SSE2, part of every x86-64): the same IEEE operations in the
// same order, so the same bits. Returns a bit per lane with r² > 4; the update is computed for
// those lanes too and discarded by the caller.
inline int fastStep2(__m128d& x, __m128d& y, __m128d& z, __m128d cx, __m128d cy, __m128d cz) {
  const __m128d rho2 = _mm_add_pd(_mm_mul_pd(x, x), _mm_mul_pd(y, y));
  const int escaped = _mm_movemask_pd(_mm_cmpgt_pd(_mm_add_pd(rho2, _mm_mul_pd(z, z)), _mm_set1_pd(4.0)));
  __m128d wr = z, wi = _mm_sqrt_pd(rho2);
  __m128d cp = x, sp = y;
  power8(cp, sp);
  const __m128d off_axis = _mm_cmpgt_pd(rho2, _mm_set1_pd(kAxisRho2));
  const __m128d q = _mm_mul_pd(rho2, rho2);
  const __m128d inv = _mm_div_pd(_mm_set1_pd(1.0), _mm_mul_pd(q, q));
  cp = _mm_or_pd(_mm_and_pd(off_axis, _mm_mul_pd(cp, inv)), _mm_andnot_pd(off_axis, _mm_set1_pd(1.0)));
  sp = _mm_and_pd(off_axis, _mm_mul_pd(sp, inv));
  power8(wr, wi);
  x = _mm_add_pd(_mm_mul_pd(wi, cp), cx);
  y = _mm_add_pd(_mm_mul_pd(wi, sp), cy);
  z = _mm_add_pd(wr, cz);
  return escaped;
}

// Points still inside r ≤ 2 after the first iterations of a row, with their state.
struct Survivors {
  std::vector<double> x, y, z;
  std::vector<size_t> index;
  size_t size = 0;
  void reset(size_t n) {
    if (x.size() < n) {
      x.resize(n);
      y.resize(n);
      z.resize(n);
      index.resize(n);
    }
    size = 0;
  }
  void push(double px, double py, double pz, size_t k) {
    x[size] = px;
    y[size] = py;
    z[size] = pz;
    index[size++] = k;
  }
};

// Fast counts of a row, in two phases. Most points of the cube escape within two iterations;
// phase one runs those two on every point, two per SSE2 register, in a plain loop. Phase two
// keeps 2·kVectors survivors in flight: one point's iteration is a chain of dependent operations,
// so independent points fill the pipeline; a lane whose point is done takes the next survivor.
constexpr int kVectors = 3;
constexpr int kFirstSteps = 2;

void fastRow(double x0, double y0, const double* zs, size_t n, int limit, uint32_t* counts) {
  assert(limit >= 1);
  thread_local Survivors survivors;
  survivors.reset(n);
  const int first_steps = std::min(limit, kFirstSteps);
  const __m128d cx = _mm_set1_pd(x0), cy = _mm_set1_pd(y0);
  size_t k = 0;
  for (; k + 2 <= n; k += 2) {
    __m128d xv = cx, yv = cy, zv = _mm_loadu_pd(zs + k);
    const __m128d czv = zv;
    unsigned alive = 3;
    for (int step = 0; step < first_steps && alive != 0; ++step) {
      const unsigned escaped = static_cast<unsigned>(fastStep2(xv, yv, zv, cx, cy, czv)) & alive;
      if (escaped & 1u) counts[k] = static_cast<uint32_t>(step);
      if (escaped & 2u) counts[k + 1] = static_cast<uint32_t>(step);
      alive &= ~escaped;
    }
    if (alive == 0) continue;
    alignas(16) double px[2], py[2], pz[2];
    _mm_store_pd(px, xv);
    _mm_store_pd(py, yv);
    _mm_store_pd(pz, zv);
    for (unsigned lane = 0; lane < 2; ++lane) {
      if (((alive >> lane) & 1u) == 0) continue;
      if (first_steps == limit || trapped(x0, y0, zs[k + lane])) counts[k + lane] = static_cast<uint32_t>(limit);
      else survivors.push(px[lane], py[lane], pz[lane], k + lane);
    }
  }
  for (; k < n; ++k) {
    double px = x0, py = y0, pz = zs[k];
    int step = 0;
    while (step < first_steps && fastStep(px, py, pz, x0, y0, zs[k])) ++step;
    if (step < first_steps || first_steps == limit) counts[k] = static_cast<uint32_t>(step);
    else if (trapped(x0, y0, zs[k])) counts[k] = static_cast<uint32_t>(limit);
    else survivors.push(px, py, pz, k);
  }

  constexpr int kLanes = 2 * kVectors;
  alignas(16) double x[kLanes], y[kLanes], z[kLanes], cz[kLanes];
  int iter[kLanes] = {};
  size_t index[kLanes] = {};
  unsigned live = 0;  // bit per lane holding a point
  size_t next = 0;
  auto start = [&](int lane) {
    if (next < survivors.size) {
      x[lane] = survivors.x[next];
      y[lane] = survivors.y[next];
      z[lane] = survivors.z[next];
      index[lane] = survivors.index[next++];
      cz[lane] = zs[index[lane]];
      iter[lane] = first_steps;
      live |= 1u << lane;
    } else {
      x[lane] = y[lane] = z[lane] = cz[lane] = 0.0;
      live &= ~(1u << lane);
    }
  };
  for (int lane = 0; lane < kLanes; ++lane) start(lane);
  while (live != 0) {
    __m128d xv[kVectors], yv[kVectors], zv[kVectors];
    for (int v = 0; v < kVectors; ++v) {
      xv[v] = _mm_load_pd(x + 2 * v);
      yv[v] = _mm_load_pd(y + 2 * v);
      zv[v] = _mm_load_pd(z + 2 * v);
    }
    unsigned done = 0;
    while (done == 0) {
      unsigned escaped = 0;
      for (int v = 0; v < kVectors; ++v)
        escaped |= static_cast<unsigned>(fastStep2(xv[v], yv[v], zv[v], cx, cy, _mm_load_pd(cz + 2 * v))) << (2 * v);
      for (int lane = 0; lane < kLanes; ++lane) {
        if (((live >> lane) & 1u) == 0) continue;
        if (((escaped >> lane) & 1u) != 0 || ++iter[lane] == limit) done |= 1u << lane;
      }
    }
    for (int v = 0; v < kVectors; ++v) {
      _mm_store_pd(x + 2 * v, xv[v]);
      _mm_store_pd(y + 2 * v, yv[v]);
      _mm_store_pd(z + 2 * v, zv[v]);
    }
    for (int lane = 0; lane < kLanes; ++lane) {
      if (((done >> lane) & 1u) == 0) continue;
      counts[index[lane]] = static_cast<uint32_t>(iter[lane]);  // escaped lanes were not advanced
      start(lane);
    }
  }
}
#else
void fastRow(double x0, double y0, const double* zs, size_t n, int limit, uint32_t* counts) {
  for (size_t k = 0; k < n; ++k)
    counts[k] = static_cast<uint32_t>(trapped(x0, y0, zs[k]) ? limit : mandelbulbEscapeFast(x0, y0, zs[k], limit));
}
#endif

}  // namespace

// Two shortcuts give the count the plain loop gives, for less libm:
// - The last update of an escaping point is not computed when its outcome is certain: the update
//   of a point at radius r lands at r^n·u + c with |u| = 1, so at least r^n − |c| from the origin.
//   When that is over 2 by a margin far above the few ulps (of values ≤ 258) that the computed
//   r^n, u, sum and square root can be off, the next test escapes: the count is i + 1. Over two
//   thirds of a default grid's points escape after one update; they now call no trigonometry.
// - An orbit that returns to a state it had, bit for bit, repeats forever (the map is a function
//   of the state), so it never escapes: the count is max_iter. Brent's cycle detection compares
//   the state with one saved at powers of two; two fifths of the interior points of a res-140
//   grid repeat within 26 updates (the lazy pass's cap), most of the rest within 100.
// - The count is max_iter as soon as every test still to come is certain to pass. The last update
//   is never tested, so it is not computed; before it, a point at radius r lands within r^n + |c|
//   of the origin, and that one within (r^n + |c|)^n + |c|, and so on: when each bound of the
//   (at most kInteriorLookahead) tests to come is under 2 by the same margin, none escapes.
// - Whatever the tests to come, a point inside a trap stays there. The bound map b → b^n + |c|
//   (+ the margin) is increasing, so a radius t that it takes to one no larger is a trap: from
//   r ≤ t every later radius is at most t < 2. b^n − b is least at t = (1/n)^(1/(n−1)) (for
//   n = 8, 0.743, where it is −0.650), which is so a trap for every |c| under 0.650; the orbit
//   starts at r = |c| < t, so such a point never escapes: the ball of that radius lies in the
//   bulb, and its points (on a res-140 grid of the default cube, 47% of the interior points and
//   41% of all the trigonometry) take none. (Where t is no trap, no radius is: b − b^n is
//   largest at t.)
int mandelbulbEscapeSeed(double cx, double cy, double cz, int max_iter, double power) {
  constexpr double kMargin = 1e-9;
  constexpr int kInteriorLookahead = 3;
  double x = cx, y = cy, z = cz;
  const bool eight = power == 8.0;
  const double c_norm = std::sqrt(cx * cx + cy * cy + cz * cz);
  const double escape_over = 2.0 + kMargin + c_norm;
  const auto power_of = [eight, power](double r) {
    if (!eight) return std::pow(r, power);
    const double r2 = r * r;
    const double r4 = r2 * r2;
    return r4 * r4;
  };
  // The trap radius. It needs no precision: the test below is what makes it a trap.
  thread_local double t_power = 8.0, t_radius = 0.7429971445684742;  // 8^(−1/7)
  if (power != t_power) t_power = power, t_radius = std::pow(1.0 / power, 1.0 / (power - 1.0));
  if (power_of(t_radius) + c_norm + 2.0 * kMargin <= t_radius) return max_iter;
  // True when radius bound `bound` after the next update keeps all `tests` tests to come under 2.
  const auto stays_inside = [&](double bound, int tests) {
    for (int t = 0;; ++t) {
      if (bound > 2.0 - kMargin) return false;
      if (t + 1 == tests) return true;
      bound = power_of(bound) + c_norm + kMargin;
    }
  };
  const auto bits = [](double v) { return std::bit_cast<uint64_t>(v); };
  uint64_t saved[3] = {bits(x), bits(y), bits(z)};  // Brent: the state at the last power of two
  int period = 1, since_saved = 0;
  // The last two states too: most interior orbits end in a fixed point or a 2-cycle, found so
  // as soon as they close (Brent finds them up to twice as late).
  uint64_t last[2][3] = {{bits(x), bits(y), bits(z)}, {~uint64_t{0}, ~uint64_t{0}, ~uint64_t{0}}};
  for (int i = 0; i < max_iter; ++i) {
    const double r = std::sqrt(x * x + y * y + z * z);
    if (r > 2.0) return i;
    const int tests_left = max_iter - 1 - i;  // the tests the updates from here on meet
    if (tests_left == 0) return max_iter;
    if (r == 0.0) {  // r^n · anything = 0: the next point is c (the seed divided 0/0 here)
      x = cx;
      y = cy;
      z = cz;
      continue;
    }
    const double rn = power_of(r);
    if (rn > escape_over) return i + 1;
    if (tests_left <= kInteriorLookahead && stays_inside(rn + c_norm + kMargin, tests_left)) return max_iter;
    const double theta = std::acos(z / r);
    const double phi = std::atan2(y, x);
    const double nt = power * theta, np = power * phi;
    const double sin_t = std::sin(nt);
    x = rn * sin_t * std::cos(np) + cx;
    y = rn * sin_t * std::sin(np) + cy;
    z = rn * std::cos(nt) + cz;
    const uint64_t now[3] = {bits(x), bits(y), bits(z)};
    const auto same = [&now](const uint64_t* state) { return now[0] == state[0] && now[1] == state[1] && now[2] == state[2]; };
    if (same(saved) || same(last[0]) || same(last[1])) return max_iter;
    std::copy(last[0], last[0] + 3, last[1]);
    std::copy(now, now + 3, last[0]);
    if (++since_saved == period) {
      saved[0] = bits(x), saved[1] = bits(y), saved[2] = bits(z);
      period *= 2;
      since_saved = 0;
    }
  }
  return max_iter;
}

int mandelbulbEscapeFast(double cx, double cy, double cz, int max_iter) {
  double x = cx, y = cy, z = cz;
  for (int i = 0; i < max_iter; ++i)
    if (!fastStep(x, y, z, cx, cy, cz)) return i;
  return max_iter;
}

EscapeRowFunction mandelbulbRow(MandelbulbVariant variant, double power) {
  if (variant == MandelbulbVariant::kFast)
    return fastRow;
  return [power](double x, double y, const double* zs, size_t n, int limit, uint32_t* counts) {
    for (size_t k = 0; k < n; ++k) counts[k] = static_cast<uint32_t>(mandelbulbEscapeSeed(x, y, zs[k], limit, power));
  };
}

namespace {
std::string powerText(double power) {
  char buffer[32];
  const std::to_chars_result r = std::to_chars(buffer, buffer + sizeof buffer, power);
  return std::string(buffer, r.ptr);
}
}  // namespace

namespace {
Status validateMandelbulb(const MandelbulbParams& params) {
  if (Status s = validateEscapeParams(params.resolution, params.max_iter, params.lo, params.hi, params.level); !s)
    return s;
  if (!std::isfinite(params.power) || params.power < 2.0 || params.power > 64.0)
    return Error{"--power " + powerText(params.power) + ": must be 2..64", ExitCode::kUsage};
  if (params.variant == MandelbulbVariant::kFast && params.power != 8.0)
    return Error{"--variant fast: only --power 8 has a trig-free form; use --variant seed", ExitCode::kUsage};
  if (params.variant == MandelbulbVariant::kSeed && params.planes)
    return Error{"--variant seed runs on the CPU only (it calls libm's acos, atan2, sin, cos and pow, which a shader "
                 "cannot reproduce bit for bit): use --device none, or --variant fast on a device",
                 ExitCode::kUsage};
  return okStatus();
}
}  // namespace

Result<PointSet> generateMandelbulb(const MandelbulbParams& params) {
  if (Status s = validateMandelbulb(params); !s) return s.error();
  return generateEscapeSurface(escapeSurfaceParams("mandelbulb", params), mandelbulbRow(params.variant, params.power));
}

Result<PointTile> generateMandelbulbTile(const MandelbulbParams& params, TileSpec tile) {
  if (Status s = validateMandelbulb(params); !s) return s.error();
  return generateEscapeSurfaceTile(escapeSurfaceParams("mandelbulb", params), mandelbulbRow(params.variant, params.power),
                                   tile);
}

}  // namespace dpoint
