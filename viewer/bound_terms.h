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
#include <optional>
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

// fl32(M_r0·v_0 + M_r1·v_1 + M_r2·v_2 + M_r3) in float against M·v_true, where the GPU holds
// fl32(M) and v (the stored floats, off from the true values by at most dv). Four products and
// three sums: γ_4; the matrix's own rounding: u; its computation in double: a few ud. A GPU may
// flush subnormal operands and results: FLT_MIN per operation, and a whole matrix entry's term
// where the entry itself is subnormal. A fused multiply-add only tightens this.
// A row with no linear part (ortho's w row: 0, 0, 0, 1) is its constant, rounded once to float
// (and flushed below FLT_MIN): its error, or nothing when the row has a linear part.
inline std::optional<double> constantRowError(const glm::dmat4& m, int r) {
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
inline double storedFloatError(double x) {
  const double a = std::fabs(x);
  return a < kFloatMin ? a : kU * a;
}

// What every mode's bound reads: the camera in the scene frame and its derived matrices, computed
// once per pass (precision.cpp, makeSetup).
struct Setup {
  SceneFrame frame;  // the scaled scene frame (fp32 and split use world_mvp)
  glm::dmat4 world_mvp, df64_mvp;
  std::array<FloatPair, 3> eye_split{};
  std::array<bool, kModeCount> wanted{}, unbounded{};
};

// What one mode's bound reads of its own encoding: the encoding itself (per-batch modes: their
// frames and matrices) and the double rounding of each batch matrix's translation.
struct ModeState {
  ModeEncoding encoding;
  std::vector<Vec4> batch_translation_error;
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

struct Worst {
  double squared_px = 0.0;
  size_t visible = 0;
};

// One mode's per-point bound on the clip position: p the point as stored, q its exact projection,
// i its index in the set.
using PointError = Vec4 (*)(const Setup& s, const ModeState& own, const glm::dvec3& p, const Projected& q, size_t i);

// The largest bound of one mode over points [first, end): one loop per mode, so each is compiled
// for its own arithmetic (kError is a constant, inlined).
template <PointError kError>
Worst worstOf(const Setup& s, const ModeState& own, const PointSet& points, size_t first, size_t end,
              const Camera& camera) {
  Worst worst;
  const double half_width = 0.5 * camera.width, half_height = 0.5 * camera.height;
  for (size_t i = first; i < end; ++i) {
    const glm::dvec3& p = points.positions[i];
    const Projected q = project(s, p);
    if (!q.visible) continue;
    ++worst.visible;
    const Vec4 error = kError(s, own, p, q, i);
    worst.squared_px = std::max(worst.squared_px, pixelsSquared(q.clip, error, half_width, half_height));
  }
  return worst;
}

}  // namespace dpoint::bound
