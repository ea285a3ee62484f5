// Predicted error per mode: the analysis behind each bound, mode by mode. Notation: u = 2^-24
// (float), ud = 2^-53 (double), γ_n = n·u/(1 − n·u); p the point, e the eye, primes the scene
// frame (p' = p·2^k, exact); M the double matrix of the mode, rounded to float on upload where the
// mode uses float. Every bound is on the clip position, per row r, against the exact
// P·R·(p − e); `pixels` turns it into window pixels.
#include "viewer/precision.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <optional>
#include <vector>

#include "core/parallel.h"

namespace dpoint {
namespace {

using Vec4 = std::array<double, 4>;

constexpr double kU = 0x1p-24;
constexpr double kU2 = 0x1p-48;
constexpr double kUd = 0x1p-53;
constexpr double kFloatMin = FLT_MIN;
constexpr double kFloatMax = FLT_MAX;
constexpr double kDekkerMax = FLT_MAX / 4097.0;  // splitter · a must stay finite
constexpr double kInf = HUGE_VAL;

constexpr double gamma(int n, double u) { return n * u / (1.0 - n * u); }
constexpr Vec4 kUnbounded = {kInf, kInf, kInf, kInf};

// fl32(M_r0·v_0 + M_r1·v_1 + M_r2·v_2 + M_r3) in float against M·v_true, where the GPU holds
// fl32(M) and v (the stored floats, off from the true values by at most dv). Four products and
// three sums: γ_4; the matrix's own rounding: u; its computation in double: a few ud. A GPU may
// flush subnormal operands and results: FLT_MIN per operation, and a whole matrix entry's term
// where the entry itself is subnormal. A fused multiply-add only tightens this.
// A row with no linear part (ortho's w row: 0, 0, 0, 1) is its constant, rounded once to float
// (and flushed below FLT_MIN): its error, or nothing when the row has a linear part.
std::optional<double> constantRowError(const glm::dmat4& m, int r) {
  if (m[0][r] != 0.0 || m[1][r] != 0.0 || m[2][r] != 0.0) return std::nullopt;
  const double x = m[3][r];
  return std::fabs(double(static_cast<float>(x)) - x) + (std::fabs(x) < kFloatMin ? kFloatMin : 0.0);
}

inline Vec4 floatAffine(const glm::dmat4& m, const glm::dvec3& v, const glm::dvec3& dv) {
  Vec4 out;
  for (int r = 0; r < 4; ++r) {
    if (const std::optional<double> constant = constantRowError(m, r)) {
      out[static_cast<size_t>(r)] = *constant;
      continue;
    }
    double sum = std::fabs(m[3][r]), input = 0.0, flushed = 8.0 * kFloatMin;
    if (!(sum <= kFloatMax)) return kUnbounded;
    for (int c = 0; c < 3; ++c) {
      const double a = std::fabs(m[c][r]);
      if (!(a <= kFloatMax)) return kUnbounded;
      sum += a * (std::fabs(v[c]) + dv[c]);
      input += a * dv[c];
      if (a < kFloatMin) flushed += a * std::fabs(v[c]);
    }
    if (!(sum <= 0.5 * kFloatMax)) return kUnbounded;
    out[static_cast<size_t>(r)] = input + ((gamma(4, kU) + kU) * (1.0 + kU) + 4.0 * kUd) * sum + flushed;
  }
  return out;
}

// Squared window-pixel distance from a clip error d around the exact clip position c (visible:
// w > 0, |x|, |y| ≤ w): δ(x/w) ≤ (δx + |x/w|·δw) / (w − δw), and a window pixel is width/2 of x/w.
// Squared so the pass takes one square root at the end; +inf once δw could reach w/2 or the
// distance passes 1e150 px (no point is on its pixel then anyway).
inline double pixelsSquared(const Vec4& c, const Vec4& d, double half_width, double half_height) {
  const double w = c[3];
  if (!(d[3] < 0.5 * w)) return kInf;
  const double inverse = 1.0 / (w - d[3]);
  const double ex = half_width * (d[0] + std::fabs(c[0]) * (d[3] / w)) * inverse;
  const double ey = half_height * (d[1] + std::fabs(c[1]) * (d[3] / w)) * inverse;
  if (!(std::max(ex, ey) < 1e150)) return kInf;
  return ex * ex + ey * ey;
}

// Float rounding of a stored coordinate, with a flush to zero below FLT_MIN.
double storedFloatError(double x) {
  const double a = std::fabs(x);
  return a < kFloatMin ? a : kU * a;
}

struct Setup {
  SceneFrame frame;  // the scaled scene frame (fp32 and split use world_mvp)
  glm::dmat4 world_mvp, df64_mvp;
  std::array<FloatPair, 3> eye_split{};
  std::array<bool, kModeCount> wanted{}, unbounded{};
  ModeEncoding batch;
  std::vector<Vec4> batch_translation_error;  // the double rounding of each batch matrix's translation
};

Vec4 fp32Error(const Setup& s, const glm::dvec3& p, bool split) {
  glm::dvec3 dv;
  for (int a = 0; a < 3; ++a) {
    // split: hi + lo in float is within u·|p| of p, plus hi's and lo's flushes.
    dv[a] = split ? 1.01 * kU * std::fabs(p[a]) + 2.0 * kFloatMin : storedFloatError(p[a]);
  }
  return floatAffine(s.world_mvp, p, dv);
}

// rte: d_hi = hi_p − hi_e (exact when Sterbenz applies: checked, not assumed), d_lo = lo_p − lo_e
// (u), their sum (u), and the hi/lo representations themselves (u·|lo| each).
Vec4 rteError(const Setup& s, const glm::dvec3& ps) {
  glm::dvec3 v, dv;
  for (int a = 0; a < 3; ++a) {
    const FloatPair pp = splitDouble(ps[a]);
    const FloatPair& pe = s.eye_split[static_cast<size_t>(a)];
    const double dh = double(pp.hi) - double(pe.hi);
    double ddh = double(static_cast<float>(dh)) == dh ? 0.0 : kU * std::fabs(dh);
    if (dh != 0.0 && std::fabs(dh) < kFloatMin) ddh += kFloatMin;
    const double dl = double(pp.lo) - double(pe.lo);
    const double ddl = kU * std::fabs(dl) + 3.0 * kFloatMin;
    const double dsum = kU * (std::fabs(dh) + std::fabs(dl)) * (1.0 + kU) + kFloatMin;
    const double representation = kU * (std::fabs(double(pp.lo)) + std::fabs(double(pe.lo))) * (1.0 + kU) + 2.0 * kFloatMin;
    v[a] = dh + dl;
    dv[a] = ddh + ddl + dsum + representation;
  }
  return floatAffine(s.frame.projection_rotation, v, dv);
}

// df64: each hi/lo pair holds its value to u² (point and matrix: 2u² per product); dfMul drops
// lo·lo and rounds the cross terms and their sum (≤ 8u² of the product); each of the three dfAdds
// is off by ≤ 3u² of its operands (≤ 9u² of Σ|terms| in all); the final hi part rounds to u.
Vec4 df64Error(const Setup& s, const glm::dvec3& ps, const Vec4& clip) {
  for (int a = 0; a < 3; ++a)
    if (!(std::fabs(ps[a]) <= kDekkerMax)) return kUnbounded;
  Vec4 out;
  for (int r = 0; r < 4; ++r) {
    double terms = std::fabs(s.df64_mvp[3][r]);
    for (int c = 0; c < 3; ++c) terms += std::fabs(s.df64_mvp[c][r] * ps[c]);
    if (!(terms <= 0.5 * kFloatMax)) return kUnbounded;
    const size_t row = static_cast<size_t>(r);
    out[row] = (20.0 * kU2 + 4.0 * kUd) * terms + kU * std::fabs(clip[row]) * (1.0 + kU) + 32.0 * kFloatMin;
  }
  return out;
}

// native: p' − e' in double (ud), projection·rotation in double (γ_4 in ud), cast to float (u).
Vec4 nativeError(const Setup& s, const glm::dvec3& ps, const Vec4& clip) {
  const glm::dvec3 d = ps - s.frame.eye;
  const glm::dmat4& m = s.frame.projection_rotation;
  Vec4 out;
  for (int r = 0; r < 4; ++r) {
    if (const std::optional<double> constant = constantRowError(m, r)) {
      out[static_cast<size_t>(r)] = *constant;
      continue;
    }
    double sum = std::fabs(m[3][r]), input = 0.0;
    for (int c = 0; c < 3; ++c) {
      const double dd = kUd * std::fabs(d[c]);
      sum += std::fabs(m[c][r]) * (std::fabs(d[c]) + dd);
      input += std::fabs(m[c][r]) * dd;
    }
    const size_t row = static_cast<size_t>(r);
    const double in_double = input + (gamma(4, kUd) + 4.0 * kUd) * sum + 8.0 * DBL_MIN;
    out[row] = in_double + kU * (std::fabs(clip[row]) + in_double) + kFloatMin;
  }
  return out;
}

// batch: the offset (p' − origin) / extent rounds once in double, then to an integer step (half a
// step, one at the clamped edge t = 1), which a float holds exactly; the batch matrix, built in
// double (its translation's rounding is precomputed per batch), is applied in float.
Vec4 batchError(const Setup& s, const glm::dvec3& ps, size_t index) {
  const size_t b = index / kBatchSize;
  const BatchFrame& frame = s.batch.batches[b];
  const glm::dvec3 steps = (ps - frame.origin) / frame.extent * kBatchSteps;
  glm::dvec3 dv;
  for (int a = 0; a < 3; ++a) dv[a] = 1.0 + 2.0 * kUd * std::fabs(steps[a]);
  Vec4 out = floatAffine(s.batch.batch_matrices[b], steps, dv);
  for (size_t r = 0; r < 4; ++r) out[r] += s.batch_translation_error[b][r];
  return out;
}

Setup makeSetup(const PointSet& points, const Camera& camera, std::span<const PrecisionMode> modes) {
  Setup s;
  s.frame = sceneFrame(PrecisionMode::kNative, camera);
  s.world_mvp = camera.viewProjection();
  glm::dmat4 translate(1.0);
  translate[3] = glm::dvec4(-s.frame.eye, 1.0);
  s.df64_mvp = s.frame.projection_rotation * translate;
  for (int a = 0; a < 3; ++a) s.eye_split[static_cast<size_t>(a)] = splitDouble(s.frame.eye[a]);
  if (modes.empty()) modes = kAllModes;
  for (PrecisionMode mode : modes) {
    const size_t i = modeIndex(mode);
    s.wanted[i] = true;
    Result<ModeEncoding> encoding = prepareEncoding(mode, points, camera);
    if (!encoding) {
      s.unbounded[i] = true;  // the mode refuses the set: nothing reaches the picture
      continue;
    }
    if (mode == PrecisionMode::kBatch) s.batch = std::move(*encoding);
  }
  if (s.wanted[modeIndex(PrecisionMode::kDf64)]) {
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        if (!(std::fabs(s.df64_mvp[c][r]) <= kDekkerMax)) s.unbounded[modeIndex(PrecisionMode::kDf64)] = true;
  }
  for (size_t b = 0; b < s.batch.batches.size(); ++b) {
    const glm::dvec3 relative = s.batch.batches[b].origin - s.frame.eye;
    Vec4 error{};
    for (int r = 0; r < 4; ++r) {
      double sum = std::fabs(s.frame.projection_rotation[3][r]);
      for (int c = 0; c < 3; ++c) sum += std::fabs(s.frame.projection_rotation[c][r] * relative[c]);
      error[static_cast<size_t>(r)] = 4.0 * kUd * sum;
    }
    s.batch_translation_error.push_back(error);
  }
  return s;
}

// The exact clip position of p (double: only visibility and x/w, y/w use it) and whether the
// view volume holds it.
struct Projected {
  glm::dvec3 ps;  // p in the scene frame
  Vec4 clip;
  bool visible;
};
inline Projected project(const Setup& s, const glm::dvec3& p) {
  Projected out;
  out.ps = scaleBy(p, s.frame);
  const glm::dvec3 d = out.ps - s.frame.eye;
  const glm::dmat4& m = s.frame.projection_rotation;
  for (int r = 0; r < 4; ++r) out.clip[static_cast<size_t>(r)] = m[0][r] * d.x + m[1][r] * d.y + m[2][r] * d.z + m[3][r];
  const Vec4& c = out.clip;
  out.visible = c[3] > 0.0 && std::fabs(c[0]) <= c[3] && std::fabs(c[1]) <= c[3] && c[2] >= 0.0 && c[2] <= c[3];
  return out;
}

struct Worst {
  double squared_px = 0.0;
  size_t visible = 0;
};

// The largest bound of one mode over points [first, end): one loop per mode, so each is compiled
// for its own arithmetic.
template <PrecisionMode kMode>
Worst worstOf(const Setup& s, const PointSet& points, size_t first, size_t end, const Camera& camera) {
  Worst worst;
  const double half_width = 0.5 * camera.width, half_height = 0.5 * camera.height;
  for (size_t i = first; i < end; ++i) {
    const glm::dvec3& p = points.positions[i];
    const Projected q = project(s, p);
    if (!q.visible) continue;
    ++worst.visible;
    Vec4 error;
    if constexpr (kMode == PrecisionMode::kFp32) error = fp32Error(s, p, false);
    else if constexpr (kMode == PrecisionMode::kSplit) error = fp32Error(s, p, true);
    else if constexpr (kMode == PrecisionMode::kRte) error = rteError(s, q.ps);
    else if constexpr (kMode == PrecisionMode::kDf64) error = df64Error(s, q.ps, q.clip);
    else if constexpr (kMode == PrecisionMode::kNative) error = nativeError(s, q.ps, q.clip);
    else error = batchError(s, q.ps, i);
    worst.squared_px = std::max(worst.squared_px, pixelsSquared(q.clip, error, half_width, half_height));
  }
  return worst;
}

Worst worstOf(PrecisionMode mode, const Setup& s, const PointSet& points, size_t first, size_t end, const Camera& c) {
  switch (mode) {
    case PrecisionMode::kFp32: return worstOf<PrecisionMode::kFp32>(s, points, first, end, c);
    case PrecisionMode::kSplit: return worstOf<PrecisionMode::kSplit>(s, points, first, end, c);
    case PrecisionMode::kRte: return worstOf<PrecisionMode::kRte>(s, points, first, end, c);
    case PrecisionMode::kDf64: return worstOf<PrecisionMode::kDf64>(s, points, first, end, c);
    case PrecisionMode::kNative: return worstOf<PrecisionMode::kNative>(s, points, first, end, c);
    case PrecisionMode::kBatch: return worstOf<PrecisionMode::kBatch>(s, points, first, end, c);
  }
  return {};
}

}  // namespace

ErrorBounds predictErrorBounds(const PointSet& points, const Camera& camera, std::span<const PrecisionMode> modes) {
  const Setup s = makeSetup(points, camera, modes);
  constexpr size_t kChunk = 1 << 15;
  const size_t chunks = (points.size() + kChunk - 1) / kChunk;
  const unsigned threads = resolveThreads(0);
  std::vector<std::array<double, kModeCount>> worst(threads, std::array<double, kModeCount>{});
  std::vector<size_t> visible(threads, 0);
  parallelFor(chunks, threads, [&](size_t chunk, unsigned worker) {
    const size_t first = chunk * kChunk, end = std::min(points.size(), first + kChunk);
    bool counted = false;
    for (PrecisionMode mode : kAllModes) {
      const size_t m = modeIndex(mode);
      if (!s.wanted[m] || s.unbounded[m]) continue;
      const Worst w = worstOf(mode, s, points, first, end, camera);
      worst[worker][m] = std::max(worst[worker][m], w.squared_px);
      if (!counted) visible[worker] += w.visible;
      counted = true;
    }
    if (!counted) {  // every wanted mode is unbounded: count what the camera sees all the same
      for (size_t i = first; i < end; ++i) visible[worker] += project(s, points.positions[i]).visible;
    }
  });
  ErrorBounds out;
  for (unsigned t = 0; t < threads; ++t) {
    out.visible += visible[t];
    for (size_t m = 0; m < kModeCount; ++m) out.px[m] = std::max(out.px[m], worst[t][m]);
  }
  for (size_t m = 0; m < kModeCount; ++m) {
    out.px[m] = std::sqrt(out.px[m]) * (1.0 + 1e-9);
    out.computed[m] = s.wanted[m];
    if (s.unbounded[m] && out.visible > 0) out.px[m] = kInf;
  }
  out.float_floor_px = kU * 0.5 * std::max(camera.width, camera.height);
  return out;
}

std::string_view deviceClassName(DeviceClass device_class) {
  return device_class == DeviceClass::kCpu ? "lavapipe (CPU)" : "GPU (measured on an NVIDIA H100)";
}

std::span<const PrecisionMode> measuredSpeedOrder(DeviceClass device_class, bool compute_backend) {
  using M = PrecisionMode;
  // H100 compute, ms/frame × fp32 at 16.7M points: batch 1.01, rte 1.09, native 1.10, df64 1.16.
  static constexpr PrecisionMode kGpuCompute[] = {M::kFp32, M::kBatch, M::kRte, M::kNative, M::kDf64};
  // H100 raster is bound by the point rasterizer (all modes within 2% at 10M): fewest bytes first.
  static constexpr PrecisionMode kGpuRaster[] = {M::kFp32, M::kBatch, M::kNative, M::kRte, M::kDf64};
  // lavapipe compute at 1M and 10M: native 0.92–1.06, rte 1.17–1.28, batch 1.23–1.42, df64 1.28–1.49;
  // raster within noise of each other, so the same order.
  static constexpr PrecisionMode kCpu[] = {M::kFp32, M::kNative, M::kRte, M::kBatch, M::kDf64};
  if (device_class == DeviceClass::kCpu) return kCpu;
  return compute_backend ? std::span<const PrecisionMode>(kGpuCompute) : std::span<const PrecisionMode>(kGpuRaster);
}

ModeChoice chooseMode(const PointSet& points, const Camera& camera, std::span<const PrecisionMode> order,
                      const std::function<bool(PrecisionMode)>& usable) {
  ModeChoice choice;
  auto bound = [&](PrecisionMode mode) {
    const size_t i = modeIndex(mode);
    if (!choice.bounds.computed[i]) {
      const PrecisionMode one[] = {mode};
      const ErrorBounds b = predictErrorBounds(points, camera, one);
      choice.bounds.px[i] = b.px[i];
      choice.bounds.computed[i] = true;
      choice.bounds.visible = b.visible;
      choice.bounds.float_floor_px = b.float_floor_px;
    }
    return choice.bounds.px[i];
  };
  for (PrecisionMode mode : order) {
    if (!usable(mode) || !(bound(mode) <= kAutoBoundPx)) continue;
    if (!choice.enough) {
      choice.mode = mode;
      choice.bound_px = bound(mode);
      choice.enough = true;
    } else {
      choice.runner_up = mode;
      choice.runner_up_bound_px = bound(mode);
      return choice;
    }
  }
  if (choice.enough) return choice;
  std::optional<PrecisionMode> best;
  for (PrecisionMode mode : order) {
    if (!usable(mode)) continue;
    if (mode == PrecisionMode::kNative || !best || (*best != PrecisionMode::kNative && bound(mode) < bound(*best)))
      best = mode;
  }
  choice.mode = best.value_or(PrecisionMode::kNative);
  choice.bound_px = bound(choice.mode);
  return choice;
}

std::string formatBound(double px) {
  if (!std::isfinite(px)) return "unbounded";
  char text[32];
  std::snprintf(text, sizeof text, "%.2g px", px);
  return text;
}

}  // namespace dpoint
