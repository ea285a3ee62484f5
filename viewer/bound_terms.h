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

// The four rows of a clip position side by side, two in each SSE2 register (GCC/Clang vector
// extensions). Lane arithmetic is the scalar IEEE arithmetic lane by lane, in the order written and
// never contracted (-ffp-contract=off), so a bound computed in lanes is the same to the bit as the
// same expression computed a row at a time. A comparison gives a mask lane of all ones where it
// holds (false for NaN, as in scalar code).
using Lanes = double __attribute__((vector_size(16)));
using LaneMask = long long __attribute__((vector_size(16)));
struct Rows {
  Lanes lo, hi;  // rows 0, 1 and rows 2, 3
};
struct RowMask {
  LaneMask lo, hi;
};

inline Rows splat(double x) { return {Lanes{x, x}, Lanes{x, x}}; }
inline Rows rowsOf(const Vec4& v) { return {Lanes{v[0], v[1]}, Lanes{v[2], v[3]}}; }
inline Vec4 vec4Of(const Rows& v) { return {v.lo[0], v.lo[1], v.hi[0], v.hi[1]}; }
inline Rows operator+(const Rows& a, const Rows& b) { return {a.lo + b.lo, a.hi + b.hi}; }
inline Rows operator*(const Rows& a, const Rows& b) { return {a.lo * b.lo, a.hi * b.hi}; }
inline RowMask operator<=(const Rows& a, const Rows& b) { return {a.lo <= b.lo, a.hi <= b.hi}; }
inline RowMask operator&(const RowMask& a, const RowMask& b) { return {a.lo & b.lo, a.hi & b.hi}; }
inline RowMask operator~(const RowMask& a) { return {~a.lo, ~a.hi}; }
inline bool anyOf(const RowMask& m) { return ((m.lo[0] | m.lo[1]) | (m.hi[0] | m.hi[1])) != 0; }
// |x| by clearing the sign bit, exactly as std::fabs.
inline Lanes absOf(const Lanes& x) {
  return reinterpret_cast<Lanes>(reinterpret_cast<LaneMask>(x) & LaneMask{~(1ll << 63), ~(1ll << 63)});
}
inline Rows absOf(const Rows& x) { return {absOf(x.lo), absOf(x.hi)}; }
// mask ? a : b, lane by lane.
inline Lanes select(const LaneMask& mask, const Lanes& a, const Lanes& b) {
  return reinterpret_cast<Lanes>((mask & reinterpret_cast<LaneMask>(a)) | (~mask & reinterpret_cast<LaneMask>(b)));
}
inline Rows select(const RowMask& mask, const Rows& a, const Rows& b) {
  return {select(mask.lo, a.lo, b.lo), select(mask.hi, a.hi, b.hi)};
}

// fl32(M_r0·v_0 + M_r1·v_1 + M_r2·v_2 + M_r3) in float against M·v_true, where the GPU holds
// fl32(M) and v (the stored floats, off from the true values by at most dv). Four products and
// three sums: γ_4; the matrix's own rounding: u; its computation in double: a few ud. A GPU may
// flush subnormal operands and results: FLT_MIN per operation, and a whole matrix entry's term
// where the entry itself is subnormal. A fused multiply-add only tightens this.
// A row with no linear part (ortho's w row: 0, 0, 0, 1) is its constant, rounded once to float
// (and flushed below FLT_MIN).
//
// What of M does not depend on the point is worked out once per matrix (FloatRows), not per point:
// which rows are constant and their error, the entries' magnitudes (a column of |M| is the four
// rows' entries), which entries are below FLT_MIN, and whether an entry of a row with a linear
// part is past FLT_MAX (then every point's bound is unbounded).
struct FloatRows {
  bool overflows = false;  // a row with a linear part has an entry past FLT_MAX (or NaN)
  RowMask constant{};      // rows with no linear part
  Rows constant_error{};   // of a constant row: |fl32(M_r3) − M_r3|, plus FLT_MIN where M_r3 is below it
  Rows magnitude[4]{};     // |M_rc|, column c = 0..3
  RowMask tiny[3]{};       // |M_rc| < FLT_MIN, c = 0..2
};

inline FloatRows floatRows(const glm::dmat4& m) {
  FloatRows out;
  Vec4 magnitude[4], constant_error{};
  std::array<long long, 4> tiny[3], constant;
  for (int r = 0; r < 4; ++r) {
    const size_t row = static_cast<size_t>(r);
    for (int c = 0; c < 4; ++c) magnitude[c][row] = std::fabs(m[c][r]);
    for (int c = 0; c < 3; ++c) tiny[c][row] = magnitude[c][row] < kFloatMin ? -1 : 0;
    constant[row] = !(m[0][r] != 0.0 || m[1][r] != 0.0 || m[2][r] != 0.0) ? -1 : 0;
    if (constant[row]) {
      const double x = m[3][r];
      constant_error[row] = std::fabs(double(static_cast<float>(x)) - x) + (std::fabs(x) < kFloatMin ? kFloatMin : 0.0);
      continue;
    }
    for (int c = 0; c < 4; ++c)
      if (!(magnitude[c][row] <= kFloatMax)) out.overflows = true;
  }
  auto mask = [](const std::array<long long, 4>& lanes) {
    return RowMask{LaneMask{lanes[0], lanes[1]}, LaneMask{lanes[2], lanes[3]}};
  };
  out.constant = mask(constant);
  out.constant_error = rowsOf(constant_error);
  for (int c = 0; c < 4; ++c) out.magnitude[c] = rowsOf(magnitude[c]);
  for (int c = 0; c < 3; ++c) out.tiny[c] = mask(tiny[c]);
  return out;
}

// Per row, as the scalar bound reads: sum = |M_r3| + Σ_c |M_rc|·(|v_c| + dv_c), input = Σ_c
// |M_rc|·dv_c, flushed = 8·FLT_MIN + Σ over entries below FLT_MIN of |M_rc|·|v_c| (adding 0 for
// the others leaves it as it is: it is positive); unbounded when a row with a linear part has
// sum > FLT_MAX/2; else input + (γ_4 + u)(1 + u)·sum + 4ud·sum + flushed, or the constant's error.
inline Vec4 floatAffine(const FloatRows& m, const glm::dvec3& v, const glm::dvec3& dv) {
  if (m.overflows) return kUnbounded;
  Rows sum = m.magnitude[3], input = splat(0.0), flushed = splat(8.0 * kFloatMin);
  for (int c = 0; c < 3; ++c) {
    const double magnitude = std::fabs(v[c]);
    sum = sum + m.magnitude[c] * splat(magnitude + dv[c]);
    input = input + m.magnitude[c] * splat(dv[c]);
    flushed = flushed + select(m.tiny[c], m.magnitude[c] * splat(magnitude), splat(0.0));
  }
  if (anyOf(~m.constant & ~(sum <= splat(0.5 * kFloatMax)))) return kUnbounded;
  const Rows out = input + splat((gamma(4, kU) + kU) * (1.0 + kU) + 4.0 * kUd) * sum + flushed;
  return vec4Of(select(m.constant, m.constant_error, out));
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
inline double storedFloatError(double x) {
  const double a = std::fabs(x);
  return a < kFloatMin ? a : kU * a;
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

}  // namespace dpoint::bound
