// The terms the per-mode error bounds share (viewer/precision.h states the analysis; each mode's
// bound is a function beside its row in viewer/modes.cpp). Internal to viewer/: precision.cpp
// runs the pass, modes.cpp holds the per-mode arithmetic. Notation: u = 2^-24 (float), ud = 2^-53
// (double), γ_n = n·u/(1 − n·u); p the point, e the eye, primes the scene frame (p' = p·2^k,
// exact); M the double matrix of the mode, rounded to float on upload where the mode uses float.
// Every bound is on the clip position, per row r, against the exact P·R·(p − e); `pixels` turns
// it into window pixels.
#pragma once

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <span>
#include <type_traits>
#include <vector>

#include <glm/mat4x4.hpp>

#include "core/point_set.h"
#include "viewer/camera.h"
#include "viewer/encode.h"

namespace dpoint::bound {

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

// One point or two side by side. The bounds of fp32, split and native run on two points at once,
// one in each lane of an SSE2 register (GCC/Clang vector extensions: T = Lanes); the same template
// with T = double bounds one point (the others' bounds, and an odd point left over). Lane
// arithmetic is the scalar IEEE arithmetic lane by lane, in the order written and never
// contracted (-ffp-contract=off), so a bound is the same to the bit either way. A scalar operand
// of a lane operation stands for itself in both lanes. A comparison gives a mask (MaskOf<T>): a
// bool, or a lane of all ones where it holds, false for NaN either way.
using Lanes = double __attribute__((vector_size(16)));
using LaneMask = decltype(Lanes{} < Lanes{});
template <class T>
using MaskOf = decltype(T{} < T{});
template <class T>
using Coords = std::array<T, 3>;
template <class T>
using Clip = std::array<T, 4>;

template <class T>
T broadcast(double x) {
  if constexpr (std::is_same_v<T, double>) {
    return x;
  } else {
    return T{x, x};
  }
}
inline double absOf(double x) { return std::fabs(x); }
inline Lanes absOf(Lanes x) {  // the sign bit cleared, as std::fabs does
  return reinterpret_cast<Lanes>(reinterpret_cast<LaneMask>(x) & LaneMask{~(1ll << 63), ~(1ll << 63)});
}
// mask ? a : b
inline double pick(bool mask, double a, double b) { return mask ? a : b; }
inline Lanes pick(LaneMask mask, Lanes a, Lanes b) {
  return reinterpret_cast<Lanes>((mask & reinterpret_cast<LaneMask>(a)) | (~mask & reinterpret_cast<LaneMask>(b)));
}
inline bool either(bool a, bool b) { return a || b; }
inline LaneMask either(LaneMask a, LaneMask b) { return a | b; }
inline bool negation(bool a) { return !a; }
inline LaneMask negation(LaneMask a) { return ~a; }
inline Coords<double> coordsOf(const glm::dvec3& v) { return {v.x, v.y, v.z}; }

// fl32(M_r0·v_0 + M_r1·v_1 + M_r2·v_2 + M_r3) in float against M·v_true, where the GPU holds
// fl32(M) and v (the stored floats, off from the true values by at most dv). Four products and
// three sums: γ_4; the matrix's own rounding: u; its computation in double: a few ud. A GPU may
// flush subnormal operands and results: FLT_MIN per operation, and a whole matrix entry's term
// where the entry itself is subnormal. A fused multiply-add only tightens this.
// A row with no linear part (ortho's w row: 0, 0, 0, 1) is its constant, rounded once to float
// (and flushed below FLT_MIN).
//
// What of M does not depend on the point is worked out once per matrix (FloatRows), not per point:
// which rows are constant and their error, the entries' magnitudes, and whether an entry of a row
// with a linear part is past FLT_MAX (then every point's bound is unbounded).
struct FloatRows {
  bool overflows = false;             // a row with a linear part has an entry past FLT_MAX (or NaN)
  std::array<bool, 4> constant{};     // rows with no linear part
  Vec4 constant_error{};              // of a constant row: |fl32(M_r3) − M_r3|, plus FLT_MIN where M_r3 is below it
  std::array<Vec4, 4> magnitude{};    // [c][r]: |M_rc|
};

inline FloatRows floatRows(const glm::dmat4& m) {
  FloatRows out;
  for (int r = 0; r < 4; ++r) {
    const size_t row = static_cast<size_t>(r);
    for (int c = 0; c < 4; ++c) out.magnitude[static_cast<size_t>(c)][row] = std::fabs(m[c][r]);
    out.constant[row] = !(m[0][r] != 0.0 || m[1][r] != 0.0 || m[2][r] != 0.0);
    if (out.constant[row]) {
      const double x = m[3][r];
      out.constant_error[row] = std::fabs(double(static_cast<float>(x)) - x) + (std::fabs(x) < kFloatMin ? kFloatMin : 0.0);
      continue;
    }
    for (size_t c = 0; c < 4; ++c)
      if (!(out.magnitude[c][row] <= kFloatMax)) out.overflows = true;
  }
  return out;
}

// Every row +inf (a lane's rows, where its mask holds).
template <class T>
Clip<T> unboundedWhere(const MaskOf<T>& mask, Clip<T> clip) {
  for (T& x : clip) x = pick(mask, broadcast<T>(kInf), x);
  return clip;
}

// Per row: Σ = |M_r3| + Σ_c |M_rc|·(|v_c| + dv_c), and the bound Σ_c |M_rc|·dv_c + ((γ_4 + u)(1 + u)
// + 4ud)·Σ + the flushes; a point whose Σ passes FLT_MAX/2 in any row with a linear part is
// unbounded (every row +inf). (inline: GCC would otherwise keep floatAffine<Lanes> out of line and
// pass its lanes through memory.)
template <class T>
inline Clip<T> floatAffine(const FloatRows& m, const Coords<T>& v, const Coords<T>& dv) {
  if (m.overflows) return unboundedWhere<T>(negation(MaskOf<T>{}), Clip<T>{});
  Clip<T> out;
  MaskOf<T> unbounded{};
  for (size_t r = 0; r < 4; ++r) {
    if (m.constant[r]) {
      out[r] = broadcast<T>(m.constant_error[r]);
      continue;
    }
    T sum = broadcast<T>(m.magnitude[3][r]), input = broadcast<T>(0.0), flushed = broadcast<T>(8.0 * kFloatMin);
    for (size_t c = 0; c < 3; ++c) {
      const double a = m.magnitude[c][r];
      sum = sum + a * (absOf(v[c]) + dv[c]);
      input = input + a * dv[c];
      if (a < kFloatMin) flushed = flushed + a * absOf(v[c]);
    }
    unbounded = either(unbounded, negation(sum <= 0.5 * kFloatMax));
    out[r] = input + ((gamma(4, kU) + kU) * (1.0 + kU) + 4.0 * kUd) * sum + flushed;
  }
  return unboundedWhere<T>(unbounded, out);
}

// Squared window-pixel distance from a clip error d around the exact clip position c (visible:
// w > 0, |x|, |y| ≤ w): δ(x/w) ≤ (δx + |x/w|·δw) / (w − δw), and a window pixel is width/2 of x/w.
// Squared so the pass takes one square root at the end; +inf once δw could reach w/2 or the
// distance passes 1e150 px (no point is on its pixel then anyway). Without branches: the
// divisions are made even where the answer is +inf (nothing traps), and their result dropped.
template <class T>
inline T pixelsSquared(const Clip<T>& c, const Clip<T>& d, double half_width, double half_height) {
  const T w = c[3];
  const MaskOf<T> near_w = negation(d[3] < 0.5 * w);
  const T inverse = 1.0 / (w - d[3]);
  const T ex = half_width * (d[0] + absOf(c[0]) * (d[3] / w)) * inverse;
  const T ey = half_height * (d[1] + absOf(c[1]) * (d[3] / w)) * inverse;
  const MaskOf<T> far = negation(pick(ex < ey, ey, ex) < 1e150);  // std::max(ex, ey), as std::max picks
  return pick(either(near_w, far), broadcast<T>(kInf), ex * ex + ey * ey);
}

// Float rounding of a stored coordinate, with a flush to zero below FLT_MIN.
template <class T>
T storedFloatError(T x) {
  const T a = absOf(x);
  return pick(a < kFloatMin, a, kU * a);
}

// The double rounding of a batch matrix's translation (projection · rotation · (origin − eye) plus
// the projection's own translation, each a few ud of its terms), per row.
inline Vec4 batchTranslationError(const SceneFrame& frame, const glm::dvec3& origin) {
  const glm::dvec3 relative = origin - frame.eye;
  Vec4 error{};
  for (int r = 0; r < 4; ++r) {
    double sum = std::fabs(frame.projection_rotation[3][r]);
    for (int c = 0; c < 3; ++c) sum += std::fabs(frame.projection_rotation[c][r] * relative[c]);
    error[static_cast<size_t>(r)] = 4.0 * kUd * sum;
  }
  return error;
}

// How far a per-batch mode's stored offset, |steps| from its batch's origin (in steps), may be from
// the exact one, in steps. batch: (p' − origin) / extent rounds once in double, then to an integer
// step (half a step, one at the clamped edge t = 1), which a float holds exactly. adaptive with
// `tiers` tiers loaded: the step error of those tiers (viewer/encode.h, adaptiveStepError) and, with
// all three, the rounding of the 30-bit integer to float (2u·|q|: SPIR-V leaves the direction open;
// with fewer tiers the rebuilt integer has at most 21 significant bits and converts exactly).
inline double batchOffsetError(double steps) { return 1.0 + 2.0 * kUd * steps; }
inline double adaptiveOffsetError(uint32_t tiers, double steps) {
  const double step_error = adaptiveStepError(tiers);
  return step_error + 2.0 * kUd * steps + (tiers == kAdaptiveTiers ? 2.0 * kU * (steps + step_error) : 0.0);
}

// Batch b's float matrix applied to offsets of at most `steps` off by at most dv, plus the double
// rounding of its translation (both worked out here; the per-point pass keeps them per batch).
inline Clip<double> batchMatrixError(const ModeEncoding& e, size_t b, const Coords<double>& steps,
                                     const Coords<double>& dv) {
  Clip<double> out = floatAffine(floatRows(e.batch_matrices[b]), steps, dv);
  const Vec4 translation = batchTranslationError(e.frame, e.batches[b].origin);
  for (size_t r = 0; r < 4; ++r) out[r] += translation[r];
  return out;
}

// What every mode's bound reads: the camera in the scene frame and its derived matrices, computed
// once per pass (precision.cpp, makeSetup).
struct Setup {
  SceneFrame frame;  // the scaled scene frame (fp32 and split use world_mvp)
  glm::dmat4 world_mvp, df64_mvp;
  FloatRows world_rows, projection_rows;  // of world_mvp and frame.projection_rotation
  std::array<FloatPair, 3> eye_split{};
  std::array<bool, kModeCount> wanted{}, unbounded{};
};

// What one mode's bound reads of its own encoding: the encoding itself (per-batch modes: their
// frames and matrices) and the double rounding of each batch matrix's translation.
struct ModeState {
  ModeEncoding encoding;
  std::vector<Vec4> batch_translation_error;
  std::vector<FloatRows> batch_rows;  // of each batch matrix
};

// The exact clip position of p (double: only visibility and x/w, y/w use it) and whether the
// view volume holds it; frame: the scaled scene frame (Setup::frame).
struct Projected {
  glm::dvec3 ps;  // p in the scene frame
  Vec4 clip;
  bool visible;
};
inline Projected project(const SceneFrame& frame, const glm::dvec3& p) {
  Projected out;
  out.ps = scaleBy(p, frame);
  const glm::dvec3 d = out.ps - frame.eye;
  const glm::dmat4& m = frame.projection_rotation;
  for (int r = 0; r < 4; ++r) out.clip[static_cast<size_t>(r)] = m[0][r] * d.x + m[1][r] * d.y + m[2][r] * d.z + m[3][r];
  const Vec4& c = out.clip;
  out.visible = c[3] > 0.0 && std::fabs(c[0]) <= c[3] && std::fabs(c[1]) <= c[3] && c[2] >= 0.0 && c[2] <= c[3];
  return out;
}

// A point the camera sees, in the block of points being bounded: its index in the set and its
// exact projection. The pass projects a block once and hands it to every mode it bounds.
struct SeenPoint {
  size_t index;
  Projected q;
};

// One mode's per-point bound on the clip position: p the point as stored, q its exact projection,
// i its index in the set.
using PointError = Vec4 (*)(const Setup& s, const ModeState& own, const glm::dvec3& p, const Projected& q, size_t i);

// The largest squared bound in pixels of one mode over the seen points of a block (0 when there
// are none): one loop per mode, so each is compiled for its own arithmetic (kError is a constant,
// inlined). A NaN distance is passed over, as std::max does.
template <PointError kError>
double worstOf(const Setup& s, const ModeState& own, const PointSet& points, std::span<const SeenPoint> seen,
               const Camera& camera) {
  double worst = 0.0;
  const double half_width = 0.5 * camera.width, half_height = 0.5 * camera.height;
  for (const SeenPoint& seen_point : seen) {
    const Vec4 error = kError(s, own, points.positions[seen_point.index], seen_point.q, seen_point.index);
    worst = std::max(worst, pixelsSquared(seen_point.q.clip, error, half_width, half_height));
  }
  return worst;
}

// What a paired bound reads of a point, or of two side by side: the point as stored, in the scene
// frame, and its exact clip position.
template <class T>
struct PointIn {
  Coords<T> p, ps;
  Clip<T> clip;
};

// worstOf for a bound that takes one point or two (Kernel::error<T>, T = double or Lanes): two
// seen points at a time, the odd one left over alone. Each lane keeps its largest distance as
// std::max does (a NaN passed over), so the result is worstOf's to the bit.
template <class Kernel>
double worstOfPairs(const Setup& s, const ModeState& own, const PointSet& points, std::span<const SeenPoint> seen,
                    const Camera& camera) {
  const double half_width = 0.5 * camera.width, half_height = 0.5 * camera.height;
  Lanes worst_pair = broadcast<Lanes>(0.0);
  size_t i = 0;
  // Two loops: the bounds of up to 64 pairs, then their pixel distances, so that the distances'
  // divisions of many pairs are in flight at once.
  constexpr size_t kPairs = 64;
  std::array<Clip<Lanes>, kPairs> clip, error;
  while (i + 2 <= seen.size()) {
    size_t n = 0;
    for (; n < kPairs && i + 2 <= seen.size(); ++n, i += 2) {
      const SeenPoint& a = seen[i];
      const SeenPoint& b = seen[i + 1];
      const glm::dvec3& pa = points.positions[a.index];
      const glm::dvec3& pb = points.positions[b.index];
      PointIn<Lanes> in;
      for (size_t c = 0; c < 3; ++c) {
        const glm::length_t axis = static_cast<glm::length_t>(c);
        in.p[c] = Lanes{pa[axis], pb[axis]};
        in.ps[c] = Lanes{a.q.ps[axis], b.q.ps[axis]};
      }
      for (size_t r = 0; r < 4; ++r) in.clip[r] = Lanes{a.q.clip[r], b.q.clip[r]};
      clip[n] = in.clip;
      error[n] = Kernel::error(s, own, in);
      error[n][2] = broadcast<Lanes>(0.0);  // pixelsSquared reads x, y, w: z's bound need not be kept
    }
    for (size_t k = 0; k < n; ++k) {
      const Lanes px = pixelsSquared(clip[k], error[k], half_width, half_height);
      worst_pair = pick(worst_pair < px, px, worst_pair);
    }
  }
  double worst = std::max(worst_pair[0], worst_pair[1]);
  if (i < seen.size()) {
    const SeenPoint& a = seen[i];
    const PointIn<double> in{coordsOf(points.positions[a.index]), coordsOf(a.q.ps), a.q.clip};
    worst = std::max(worst, pixelsSquared(in.clip, Kernel::error(s, own, in), half_width, half_height));
  }
  return worst;
}

}  // namespace dpoint::bound
