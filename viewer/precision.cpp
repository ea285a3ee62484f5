// Predicted error per mode: the pass over the points, and --mode auto's walk. Each mode's own
// analysis is the bound function beside its row in viewer/modes.cpp; the terms they share (and
// the notation) are in viewer/bound_terms.h.
#include "viewer/precision.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <optional>
#include <vector>

#include <glm/matrix.hpp>

#include "core/parallel.h"
#include "viewer/batch_plan.h"
#include "viewer/bound_terms.h"

namespace dpoint {
namespace {

using namespace bound;

// What prepareEncoding would check of every point, checked in the pass itself for modes with no
// per-batch frames to build (their encoding is their frame alone): each coordinate in the mode's
// frame (the scene frame's q.ps or the point as stored) within positionLimit, which for a finite
// limit is addPoints' test (finite and within it). One check per frame and limit, shared by the
// modes that need it (fp32 and split; rte and df64).
struct PositionCheck {
  bool scene_frame = false;
  double limit = 0.0;
  std::array<bool, kModeCount> modes{};
};

// The shared setup, each wanted mode's own state (empty for a mode that refuses the set) and the
// position checks the pass makes.
struct Pass {
  Setup setup;
  std::array<ModeState, kModeCount> own;
  std::vector<PositionCheck> checks;
  std::array<bool, kModeCount> refused{};  // the mode's encoding refuses the set
};

void addPositionCheck(std::vector<PositionCheck>& checks, PrecisionMode mode) {
  const bool scene_frame = modeInfo(mode).scene_frame;
  const double limit = positionLimit(mode);
  auto same = [&](const PositionCheck& c) { return c.scene_frame == scene_frame && c.limit == limit; };
  auto it = std::find_if(checks.begin(), checks.end(), same);
  if (it == checks.end()) it = checks.insert(checks.end(), PositionCheck{scene_frame, limit, {}});
  it->modes[modeIndex(mode)] = true;
}

inline bool withinLimit(const glm::dvec3& v, double limit) {
  return std::fabs(v.x) <= limit && std::fabs(v.y) <= limit && std::fabs(v.z) <= limit;
}

// The camera's part of every mode's bound (bound::Setup), before any point is seen.
Setup makeSetup(const Camera& camera, std::span<const PrecisionMode> modes) {
  Setup s;
  s.frame = sceneFrame(camera);
  s.world_mvp = camera.viewProjection();
  glm::dmat4 translate(1.0);
  translate[3] = glm::dvec4(-s.frame.eye, 1.0);
  s.df64_mvp = s.frame.projection_rotation * translate;
  for (int a = 0; a < 3; ++a) s.eye_split[static_cast<size_t>(a)] = splitDouble(s.frame.eye[a]);
  s.world_rows = floatRows(s.world_mvp);
  s.projection_rows = floatRows(s.frame.projection_rotation);
  for (PrecisionMode mode : modes) s.wanted[modeIndex(mode)] = true;
  for (PrecisionMode mode : modes) {
    const BoundRefusal refuses = modeInfo(mode).bound_refuses;
    if (refuses && refuses(s)) s.unbounded[modeIndex(mode)] = true;
  }
  return s;
}

// What the bounds of a per-batch mode read of each batch: the double rounding of its matrix's
// translation and the matrix's float rows.
void addBatchTerms(const Setup& s, ModeState& own) {
  for (const BatchFrame& batch : own.encoding.batches)
    own.batch_translation_error.push_back(batchTranslationError(s.frame, batch.origin));
  for (const glm::dmat4& m : own.encoding.batch_matrices) own.batch_rows.push_back(floatRows(m));
}

Pass makePass(const PointSet& points, const Camera& camera, std::span<const PrecisionMode> modes, double tolerance_px) {
  Pass pass;
  if (modes.empty()) modes = kAllModes;
  pass.setup = makeSetup(camera, modes);
  Setup& s = pass.setup;
  for (PrecisionMode mode : modes) {
    const size_t i = modeIndex(mode);
    if (modeInfo(mode).batch_points == 0) {
      pass.own[i].encoding = beginEncoding(mode, camera, tolerance_px);
      addPositionCheck(pass.checks, mode);
      continue;
    }
    Result<ModeEncoding> encoding = prepareEncoding(mode, points, camera, tolerance_px);
    if (!encoding) {
      s.unbounded[i] = true;  // the mode refuses the set: nothing reaches the picture
      pass.refused[i] = true;
      continue;
    }
    pass.own[i].encoding = std::move(*encoding);
  }
  for (ModeState& own : pass.own) addBatchTerms(s, own);
  return pass;
}

// ---- bounds from batch boxes (a streamed set) -----------------------------------------------------
//
// Each per-point bound of viewer/modes.cpp is a sum of terms that only grow with the magnitudes of
// its inputs (|p|, |p' − e'|, the batch offsets, |clip row|), turned into pixels by pixelsSquared,
// which grows with |x|, |y| and the clip error and shrinks with w. Over a box every input has a
// largest magnitude that a corner reaches (rounding is monotone, and the clip rows are affine in
// the point), so the terms taken there, and the pixel distance at the box's largest |x|, |y| and
// least w, bound every point of the box. Where a per-point bound decides something by the point's
// own value (rte's Sterbenz test, a flush below FLT_MIN), the box takes the costlier branch. Only
// the points the view shows count, so a box is first cut to the view volume (boundPiece), and cut
// in halves where its depth varies much (a near point's w paired with a far point's offset).

// The box's clip rows are computed in double, as each point's are: a few ud of their terms off
// from exact either way; 2^-40 of the terms covers both by far.
constexpr double kBoxSlack = 0x1p-40;
// A box's bound is computed with its own roundings (a few ud each) where the per-point bounds have
// theirs: 2^-20 more covers the difference by far.
constexpr double kBoxMargin = 0x1p-20;
// A perspective near plane read as w: a point nearer than it is not drawn (z > w). 2^-20 covers
// the rounding of z and w, a few ud of w there.
constexpr double kNearPlaneSlack = 0x1p-20;

// What every mode's box bound reads of one box.
struct BoxTerms {
  glm::dvec3 lo, hi;      // the box in the scene frame
  Coords<double> stored;  // largest |coordinate| as stored by fp32 and split (the world's)
  Coords<double> scaled;  // largest |coordinate| in the scene frame
  Coords<double> eye_relative;  // largest |fl(p' − e')|, native's first step
  Vec4 clip_abs;          // largest |clip row| of a point of the box the view shows (|x|, |y|, |z| ≤ w)
  double w_least = 0.0;   // the least w of a point of the box the view shows (≤ 0: the box reaches the eye's plane)
  double x_share = 1.0, y_share = 1.0;  // the largest |x|/w, |y|/w of such a point (≤ 1)
  bool in_view = false;   // the box may hold a point the view shows
};

// lo ≤ hi: the largest of |fl(lo − c)|, |fl(hi − c)|, which bounds |fl(x − c)| for x in [lo, hi].
inline double largestOffset(double lo, double hi, double c) { return std::max(std::fabs(lo - c), std::fabs(hi - c)); }

// The terms of the points of the view in the scene-frame box [lo, hi]; stored: the largest
// |coordinate| of the world box it was cut from.
BoxTerms boxTerms(const Setup& s, const glm::dvec3& lo, const glm::dvec3& hi, const Coords<double>& stored,
                  double least_w) {
  BoxTerms t;
  t.lo = lo;
  t.hi = hi;
  t.stored = stored;
  glm::dvec3 low, high;  // fl(p' − e') of the box's corners, between which every point's lies
  for (int a = 0; a < 3; ++a) {
    const size_t c = static_cast<size_t>(a);
    t.scaled[c] = std::max(std::fabs(t.lo[a]), std::fabs(t.hi[a]));
    low[a] = t.lo[a] - s.frame.eye[a];
    high[a] = t.hi[a] - s.frame.eye[a];
    t.eye_relative[c] = std::max(std::fabs(low[a]), std::fabs(high[a]));
  }
  // Each clip row's least and largest value over the box, widened by the rounding slack.
  const glm::dmat4& m = s.frame.projection_rotation;
  Vec4 least{}, most{};
  for (int r = 0; r < 4; ++r) {
    const size_t row = static_cast<size_t>(r);
    double lower = m[3][r], upper = m[3][r], size = std::fabs(m[3][r]);
    for (int a = 0; a < 3; ++a) {
      const double x = m[a][r] * low[a], y = m[a][r] * high[a];
      lower += std::min(x, y);
      upper += std::max(x, y);
      size += std::fabs(m[a][r]) * t.eye_relative[static_cast<size_t>(a)];
    }
    least[row] = lower - kBoxSlack * size;
    most[row] = upper + kBoxSlack * size;
  }
  // Outside the view volume (w − x, w + x, w − y, w + y, z, w − z ≥ 0) when one of these is
  // negative all over the box; written so that a NaN leaves the box in view.
  t.in_view = !(most[3] - least[0] < 0.0 || most[3] + most[0] < 0.0 || most[3] - least[1] < 0.0 ||
                most[3] + most[1] < 0.0 || most[2] < 0.0 || most[3] - least[2] < 0.0 || most[3] <= 0.0);
  const double w_most = most[3];
  for (size_t r = 0; r < 3; ++r) t.clip_abs[r] = std::min(std::max(std::fabs(least[r]), std::fabs(most[r])), w_most);
  t.clip_abs[3] = w_most;
  t.w_least = std::max(least[3], least_w);  // NaN stays NaN (std::max keeps its first operand)
  t.x_share = std::min(t.clip_abs[0] / t.w_least, 1.0);
  t.y_share = std::min(t.clip_abs[1] / t.w_least, 1.0);
  return t;
}

// One mode's largest squared pixel distance over the box (batch b: the box's batch).
using BoxBound = double (*)(const Setup& s, const ModeState& own, const BoxTerms& t, size_t b, const Camera& camera);

// pixelsSquared over the box, for a clip error of at most a_r + k_r·|c_r| in row r (the clip
// position's own float rounding is the k part). Per point, δ(x/w) ≤ (δx + |x/w|·δw) / (w − δw) is
//   (a_x/w + k_x·|x/w| + |x/w|·(a_w/w + k_w)) / (1 − a_w/w − k_w),
// which grows with |x/w| ≤ x_share and 1/w ≤ 1/w_least: taken there, it bounds every point of the
// box (+inf where a_w/w + k_w could reach a half, or the box reaches the eye's plane).
double boxPixels(const BoxTerms& t, const Clip<double>& a, const Clip<double>& k, const Camera& camera) {
  const double w = t.w_least;
  const double w_share = a[3] / w + k[3];  // δw / w at most
  if (!(w > 0.0) || !(w_share < 0.5)) return kInf;
  const double ex = 0.5 * camera.width * (a[0] / w + k[0] * t.x_share + t.x_share * w_share) / (1.0 - w_share);
  const double ey = 0.5 * camera.height * (a[1] / w + k[1] * t.y_share + t.y_share * w_share) / (1.0 - w_share);
  if (!(std::max(ex, ey) < 1e150)) return kInf;
  return ex * ex + ey * ey;
}
// The same for an error with no part proportional to the clip position.
inline double boxPixels(const BoxTerms& t, const Clip<double>& a, const Camera& camera) {
  return boxPixels(t, a, Clip<double>{}, camera);
}

// fp32 and split: the stored float's error at the largest |p| (below FLT_MIN a flush of up to
// FLT_MIN, else u·|p|: the larger of the two where the box holds both).
double fp32Box(const Setup& s, const ModeState&, const BoxTerms& t, size_t, const Camera& camera) {
  Coords<double> dv;
  for (size_t a = 0; a < 3; ++a) dv[a] = std::max(kU * t.stored[a], std::min(t.stored[a], kFloatMin));
  return boxPixels(t, floatAffine(s.world_rows, t.stored, dv), camera);
}
double splitBox(const Setup& s, const ModeState&, const BoxTerms& t, size_t, const Camera& camera) {
  Coords<double> dv;
  for (size_t a = 0; a < 3; ++a) dv[a] = 1.01 * kU * t.stored[a] + 2.0 * kFloatMin;
  return boxPixels(t, floatAffine(s.world_rows, t.stored, dv), camera);
}

// Sterbenz's lemma over the box: x − y is exact in float for every float x in [x_lo, x_hi] when
// y/2 ≤ x ≤ 2y (y > 0; mirrored for y < 0) holds at both ends, or when every x is y.
inline bool exactOver(double x_lo, double x_hi, double y) {
  if (x_lo == y && x_hi == y) return true;
  if (y > 0.0) return x_lo >= 0.5 * y && x_hi <= 2.0 * y;
  if (y < 0.0) return x_hi <= 0.5 * y && x_lo >= 2.0 * y;
  return false;
}

// rte: d_hi = hi_p − hi_e, exact where Sterbenz holds over the whole box and else taken as
// inexact (u·|d_hi|), at its largest (hi_p = fl32(p') is monotone in p'); |lo_p| ≤ u(1 + 2u)|p'| +
// 2^-148 (half an ulp of hi_p, rounded to float). The sum v = d_hi + d_lo is p' − e' but for the
// roundings of lo_p and lo_e: no more than |p' − e'| and those, however large d_hi and d_lo are
// (a deep zoom's hi parts differ by whole float ulps that the lo parts take back).
double rteBox(const Setup& s, const ModeState&, const BoxTerms& t, size_t, const Camera& camera) {
  for (size_t a = 0; a < 3; ++a)
    if (!(t.scaled[a] <= kFloatMax)) return kInf;  // beyond float: refused by its position check anyway
  Coords<double> v, dv;
  for (size_t a = 0; a < 3; ++a) {
    const glm::length_t axis = static_cast<glm::length_t>(a);
    const FloatPair& pe = s.eye_split[a];
    const double hi_lo = double(static_cast<float>(t.lo[axis])), hi_hi = double(static_cast<float>(t.hi[axis]));
    const double dh = largestOffset(hi_lo, hi_hi, double(pe.hi));
    const double lo_p = kU * (1.0 + 2.0 * kU) * t.scaled[a] + 0x1p-148, lo_e = std::fabs(double(pe.lo));
    const double dl = lo_p + lo_e;
    const double ddh = (exactOver(hi_lo, hi_hi, double(pe.hi)) ? 0.0 : kU * dh) + kFloatMin;
    const double ddl = kU * dl + 3.0 * kFloatMin;
    const double dsum = kU * (dh + dl) * (1.0 + kU) + kFloatMin;
    const double representation = kU * (lo_p + lo_e) * (1.0 + kU) + 2.0 * kFloatMin;
    const double near_eye = (t.eye_relative[a] + kU * (1.0 + 2.0 * kU) * (lo_p + lo_e) + 0x1p-148) * (1.0 + 8.0 * kUd);
    v[a] = std::min(dh + dl, near_eye);
    dv[a] = ddh + ddl + dsum + representation;
  }
  return boxPixels(t, floatAffine(s.projection_rows, v, dv), camera);
}

double df64Box(const Setup& s, const ModeState&, const BoxTerms& t, size_t, const Camera& camera) {
  for (size_t a = 0; a < 3; ++a)
    if (!(t.scaled[a] <= kDekkerMax)) return kInf;
  Clip<double> out;
  for (int r = 0; r < 4; ++r) {
    const size_t row = static_cast<size_t>(r);
    double terms = std::fabs(s.df64_mvp[3][r]);
    for (int c = 0; c < 3; ++c) terms += std::fabs(s.df64_mvp[c][r]) * t.scaled[static_cast<size_t>(c)];
    if (!(terms <= 0.5 * kFloatMax)) return kInf;
    out[row] = (20.0 * kU2 + 4.0 * kUd) * terms + 32.0 * kFloatMin;
  }
  return boxPixels(t, out, Clip<double>{kU * (1.0 + kU), kU * (1.0 + kU), 0.0, kU * (1.0 + kU)}, camera);
}

double nativeBox(const Setup& s, const ModeState&, const BoxTerms& t, size_t, const Camera& camera) {
  const FloatRows& m = s.projection_rows;
  Clip<double> out, cast{};  // cast: the final float rounding, u·|c_r|
  for (size_t r = 0; r < 4; ++r) {
    if (m.constant[r]) {
      out[r] = m.constant_error[r];
      continue;
    }
    double sum = m.magnitude[3][r], input = 0.0;
    for (size_t c = 0; c < 3; ++c) {
      const double dd = kUd * t.eye_relative[c];
      sum += m.magnitude[c][r] * (t.eye_relative[c] + dd);
      input += m.magnitude[c][r] * dd;
    }
    const double in_double = input + (gamma(4, kUd) + 4.0 * kUd) * sum + 8.0 * DBL_MIN;
    out[r] = in_double + kU * in_double + kFloatMin;
    cast[r] = kU;
  }
  return boxPixels(t, out, cast, camera);
}

// The per-batch modes: each axis's largest |offset| in steps, fl(p' − origin) / extent · steps at
// the box's min or max (the division and product are by powers of two).
Coords<double> largestSteps(const BatchFrame& frame, const BoxTerms& t, double steps) {
  Coords<double> out;
  for (int a = 0; a < 3; ++a)
    out[static_cast<size_t>(a)] = largestOffset(t.lo[a], t.hi[a], frame.origin[a]) / frame.extent * steps;
  return out;
}

// b: the box's index in BatchBoxes (kBoxPoints points); its batch is the one holding them.
size_t batchOfBox(const ModeState& own, size_t b) { return b * kBoxPoints / own.encoding.batchSize(); }

// The batch matrix's terms are worked out per box (batchMatrixError): 244k batches' rows are not kept.
double batchBox(const Setup&, const ModeState& own, const BoxTerms& t, size_t box, const Camera& camera) {
  const size_t b = batchOfBox(own, box);
  const Coords<double> steps = largestSteps(own.encoding.batches[b], t, kBatchSteps);
  Coords<double> dv;
  for (size_t a = 0; a < 3; ++a) dv[a] = batchOffsetError(steps[a]);
  return boxPixels(t, batchMatrixError(own.encoding, b, steps, dv), camera);
}

// adaptive: the tiers its plan chose for the batch (a culled batch holds no point the view shows),
// and no more than the plan's own box bound for them (adaptiveBoxBoundPx: the batch's whole cube).
double adaptiveBox(const Setup&, const ModeState& own, const BoxTerms& t, size_t box, const Camera& camera) {
  const size_t b = batchOfBox(own, box);
  const uint32_t tiers = own.encoding.batch_plan[b];
  if (tiers == 0) return 0.0;
  const Coords<double> steps = largestSteps(own.encoding.batches[b], t, kAdaptiveSteps);
  Coords<double> dv;
  for (size_t a = 0; a < 3; ++a) dv[a] = adaptiveOffsetError(tiers, steps[a]);
  const double plan_px = adaptiveBoxBoundPx(own.encoding, b, tiers);
  return std::min(boxPixels(t, batchMatrixError(own.encoding, b, steps, dv), camera), plan_px * plan_px);
}

// By modeIndex, beside the per-point bounds' rows (viewer/modes.cpp).
constexpr BoxBound kBoxBounds[] = {fp32Box, splitBox, rteBox, df64Box, nativeBox, batchBox, adaptiveBox};
static_assert(std::size(kBoxBounds) == kModeCount, "every mode needs a box bound");

// What bounding the boxes reads besides each box: the setup, the per-batch modes' state, the modes
// bounded, the least w of a point drawn, and the view volume's axis-aligned box in the scene frame
// (every point the view shows lies in it).
struct BoxPass {
  const Setup& s;
  const std::array<ModeState, kModeCount>& own;
  const std::vector<size_t>& bounded;
  const Camera& camera;
  double least_w = -kInf;
  glm::dvec3 view_lo{-kInf}, view_hi{kInf};
  // Perspective: the view volume is a pyramid from the eye (x, y and w have no constant term), so
  // the points it shows with w ≤ W lie within W·[cone_lo, cone_hi] of the eye: the box of the eye
  // and the far plane's corners (w = 1), relative to the eye.
  bool pyramid = false;
  glm::dvec3 cone_lo{0.0}, cone_hi{0.0};
  double cone_size = 0.0;
};

// The view volume's corners (x, y = ±w, z = 0 and w) taken back to the scene frame, their box
// widened by 2^-20 of its size (the inverse's rounding, however ill-conditioned a near plane makes
// it, is far below that) and a few ud of the eye (the sums' rounding); unbounded if any is not finite.
void setViewBox(BoxPass& pass) {
  const glm::dmat4 inverse = glm::inverse(pass.s.frame.projection_rotation);
  glm::dvec3 lo(kInf), hi(-kInf), cone_lo(0.0), cone_hi(0.0);
  double size = 0.0;
  for (int i = 0; i < 8; ++i) {
    const bool far = !(i & 4);  // z = 0: the far plane (reversed Z)
    const glm::dvec4 d = inverse * glm::dvec4((i & 1) ? 1.0 : -1.0, (i & 2) ? 1.0 : -1.0, far ? 0.0 : 1.0, 1.0);
    const glm::dvec3 corner = glm::dvec3(d) / d.w;
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite(corner[a])) return;
    lo = glm::min(lo, corner), hi = glm::max(hi, corner);
    if (far) cone_lo = glm::min(cone_lo, corner), cone_hi = glm::max(cone_hi, corner);
    size = std::max({size, std::fabs(corner.x), std::fabs(corner.y), std::fabs(corner.z)});
  }
  const glm::dvec3& eye = pass.s.frame.eye;
  for (int a = 0; a < 3; ++a) {
    const double pad = 0x1p-20 * size + 4.0 * kUd * std::fabs(eye[a]);
    pass.view_lo[a] = eye[a] + lo[a] - pad;
    pass.view_hi[a] = eye[a] + hi[a] + pad;
  }
  const glm::dmat4& m = pass.s.frame.projection_rotation;
  pass.pyramid = m[3][0] == 0.0 && m[3][1] == 0.0 && m[3][3] == 0.0;
  pass.cone_lo = cone_lo, pass.cone_hi = cone_hi, pass.cone_size = size;
}

// A piece cut down to where a pyramid view shows points of w ≤ w_most (BoxPass::cone_lo): nothing
// of it is lost that the view shows.
void cutToCone(const BoxPass& pass, double w_most, glm::dvec3& lo, glm::dvec3& hi) {
  const glm::dvec3& eye = pass.s.frame.eye;
  for (int a = 0; a < 3; ++a) {
    const double pad = 0x1p-20 * w_most * pass.cone_size + 4.0 * kUd * std::fabs(eye[a]);
    lo[a] = std::max(lo[a], eye[a] + w_most * pass.cone_lo[a] - pad);
    hi[a] = std::min(hi[a], eye[a] + w_most * pass.cone_hi[a] + pad);
  }
}

// Pieces a box may be cut into, in halves, where the depth of its points in view varies more than
// twofold: a box's bound pairs its largest eye-relative offsets with its least w, so a box reaching
// from near the eye to far off is split until each piece's depths are alike (six cuts: at most 64
// pieces, only for boxes that deep).
constexpr int kMostCuts = 6;

// Bounds every mode over the points of the view in the scene-frame box [lo, hi] of batch b into
// `worst` (squared pixels); whether any of it is in view.
bool boundPiece(const BoxPass& pass, glm::dvec3 lo, glm::dvec3 hi, const Coords<double>& stored, size_t b,
                int cuts_left, std::array<double, kModeCount>& worst) {
  BoxTerms t = boxTerms(pass.s, lo, hi, stored, pass.least_w);
  if (!t.in_view) return false;
  if (pass.pyramid && t.clip_abs[3] > 0.0) {
    // Near the eye, the pyramid is narrower than the piece: its points in view are nearer the eye.
    const glm::dvec3 was_lo = lo, was_hi = hi;
    cutToCone(pass, t.clip_abs[3], lo, hi);
    if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) return false;
    if (lo != was_lo || hi != was_hi) {
      t = boxTerms(pass.s, lo, hi, stored, pass.least_w);
      if (!t.in_view) return false;
    }
  }
  if (cuts_left > 0 && !(t.w_least >= 0.5 * t.clip_abs[3])) {
    // Cut across the axis along which w varies most.
    const glm::dmat4& m = pass.s.frame.projection_rotation;
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (std::fabs(m[a][3]) * (hi[a] - lo[a]) > std::fabs(m[axis][3]) * (hi[axis] - lo[axis])) axis = a;
    glm::dvec3 middle_hi = hi, middle_lo = lo;
    middle_hi[axis] = middle_lo[axis] = lo[axis] * 0.5 + hi[axis] * 0.5;  // the halves share it: they cover the box
    const bool near = boundPiece(pass, lo, middle_hi, stored, b, cuts_left - 1, worst);
    const bool far = boundPiece(pass, middle_lo, hi, stored, b, cuts_left - 1, worst);
    return near || far;
  }
  for (size_t m : pass.bounded)
    worst[m] = std::max(worst[m], kBoxBounds[m](pass.s, pass.own[m], t, b, pass.camera));
  return true;
}

}  // namespace

ErrorBounds predictErrorBounds(const PointSet& points, const Camera& camera, std::span<const PrecisionMode> modes,
                               double tolerance_px) {
  Pass pass = makePass(points, camera, modes, tolerance_px);
  const Setup& s = pass.setup;
  std::vector<size_t> bounded;  // the wanted modes whose bounds the points decide
  for (size_t m = 0; m < kModeCount; ++m)
    if (s.wanted[m] && !s.unbounded[m]) bounded.push_back(m);
  // A chunk is a work item; within it a block of points is projected once, and every mode bounds
  // the block's visible points while they are in L1 (kBlock · sizeof(SeenPoint) = 18 KiB). The
  // bounds are maxima, so neither the blocks nor the modes' order changes a bit of them.
  constexpr size_t kChunk = 1 << 15, kBlock = 256;
  const size_t chunks = (points.size() + kChunk - 1) / kChunk;
  const unsigned threads = resolveThreads(0);
  std::vector<std::array<double, kModeCount>> worst(threads, std::array<double, kModeCount>{});
  std::vector<size_t> visible(threads, 0);
  std::vector<std::vector<char>> beyond(threads, std::vector<char>(pass.checks.size(), 0));  // by check
  // The checks as locals of the hot loop (no store in it may alias them).
  const size_t check_count = pass.checks.size();
  std::array<bool, kModeCount> check_scene_frame{};
  std::array<double, kModeCount> check_limit{};
  for (size_t c = 0; c < check_count; ++c)
    check_scene_frame[c] = pass.checks[c].scene_frame, check_limit[c] = pass.checks[c].limit;
  parallelFor(chunks, threads, [&](size_t chunk, unsigned worker) {
    const size_t first = chunk * kChunk, end = std::min(points.size(), first + kChunk);
    std::array<double, kModeCount> chunk_worst{};
    size_t chunk_visible = 0;
    std::array<SeenPoint, kBlock> seen;
    std::array<bool, kModeCount> chunk_beyond{};  // by check (at most one per mode)
    for (size_t block = first; block < end; block += kBlock) {
      size_t count = 0;
      for (size_t i = block, block_end = std::min(end, block + kBlock); i < block_end; ++i) {
        const glm::dvec3& p = points.positions[i];
        seen[count] = {i, project(s.frame, p)};
        for (size_t c = 0; c < check_count; ++c)
          chunk_beyond[c] |= !withinLimit(check_scene_frame[c] ? seen[count].q.ps : p, check_limit[c]);
        count += seen[count].q.visible;
      }
      chunk_visible += count;
      if (count == 0) continue;
      const std::span<const SeenPoint> block_seen(seen.data(), count);
      for (size_t m : bounded)
        chunk_worst[m] = std::max(chunk_worst[m], modeInfo(kAllModes[m]).bound(s, pass.own[m], points, block_seen, camera));
    }
    visible[worker] += chunk_visible;
    for (size_t c = 0; c < check_count; ++c) beyond[worker][c] |= chunk_beyond[c];
    for (size_t m : bounded) worst[worker][m] = std::max(worst[worker][m], chunk_worst[m]);
  });
  ErrorBounds out;
  std::array<bool, kModeCount> beyond_limit{};  // a position past what the mode's encoding holds
  for (unsigned t = 0; t < threads; ++t) {
    out.visible += visible[t];
    for (size_t m = 0; m < kModeCount; ++m) out.px[m] = std::max(out.px[m], worst[t][m]);
    for (size_t c = 0; c < pass.checks.size(); ++c)
      if (beyond[t][c])
        for (size_t m = 0; m < kModeCount; ++m) beyond_limit[m] = beyond_limit[m] || pass.checks[c].modes[m];
  }
  for (size_t m = 0; m < kModeCount; ++m) {
    out.px[m] = std::sqrt(out.px[m]) * (1.0 + 1e-9);
    out.computed[m] = s.wanted[m];
    // Nothing of a refused mode reaches the picture; with no point in view every bound is 0, but
    // a mode whose encoding cannot hold a position draws nothing at all (renderPoints refuses the
    // set), so auto must not take it even then (points at ±1e308 seen from where none is in view).
    if (beyond_limit[m] || (s.unbounded[m] && out.visible > 0)) out.px[m] = kInf;
    // The encoding renderPoints would make: built here (per-batch modes), or the frame alone with
    // every position checked as prepareEncoding checks them (the pass's checks are its test).
    if (s.wanted[m] && !pass.refused[m] && !beyond_limit[m])
      out.encodings[m] = std::make_shared<const ModeEncoding>(std::move(pass.own[m].encoding));
  }
  out.float_floor_px = kU * 0.5 * std::max(camera.width, camera.height);
  return out;
}

void addBatchBoxes(BatchBoxes& boxes, const PositionArray& positions) {
  assert(!positions.empty() && boxes.count % kBoxPoints == 0 && boxes.count == boxes.boxes.size() * kBoxPoints);
  const size_t first = boxes.boxes.size(), added = (positions.size() + kBoxPoints - 1) / kBoxPoints;
  boxes.boxes.resize(first + added);
  parallelFor(added, 0, [&](size_t k, unsigned) {
    boxes.boxes[first + k] = boundingBox(positions, k * kBoxPoints, std::min(positions.size(), (k + 1) * kBoxPoints));
  });
  boxes.count += positions.size();
}

ErrorBounds predictBoxBounds(const BatchBoxes& boxes, const Camera& camera, std::span<const PrecisionMode> modes,
                             double tolerance_px) {
  if (modes.empty()) modes = kAllModes;
  Setup s = makeSetup(camera, modes);
  std::array<ModeState, kModeCount> own;
  std::vector<PositionCheck> checks;
  for (PrecisionMode mode : modes) {
    const size_t i = modeIndex(mode);
    if (modeInfo(mode).batch_points == 0) {
      addPositionCheck(checks, mode);
      continue;
    }
    own[i].encoding = beginEncoding(mode, camera, tolerance_px);
    if (!addBoxes(own[i].encoding, boxes.boxes)) s.unbounded[i] = true;  // refuses the set
  }
  std::vector<size_t> bounded;
  for (size_t m = 0; m < kModeCount; ++m)
    if (s.wanted[m] && !s.unbounded[m]) bounded.push_back(m);
  BoxPass pass{s, own, bounded, camera};
  // In perspective the least w of a point drawn is near/far (a nearer one has z > w).
  if (!camera.ortho && camera.near_plane > 0.0 && camera.far_plane > camera.near_plane)
    pass.least_w = camera.near_plane / camera.far_plane * (1.0 - kNearPlaneSlack);
  setViewBox(pass);
  constexpr size_t kChunk = 1024;
  const size_t chunks = (boxes.boxes.size() + kChunk - 1) / kChunk;
  const unsigned threads = resolveThreads(0);
  std::vector<std::array<double, kModeCount>> worst(threads, std::array<double, kModeCount>{});
  std::vector<size_t> visible(threads, 0);
  std::vector<std::vector<char>> beyond(threads, std::vector<char>(checks.size(), 0));  // by check
  parallelFor(chunks, threads, [&](size_t chunk, unsigned worker) {
    for (size_t b = chunk * kChunk, end = std::min(boxes.boxes.size(), b + kChunk); b < end; ++b) {
      const Box& box = boxes.boxes[b];
      const glm::dvec3 lo = scaleBy(box.min, s.frame), hi = scaleBy(box.max, s.frame);
      Coords<double> stored, scaled;
      for (int a = 0; a < 3; ++a) {
        stored[static_cast<size_t>(a)] = std::max(std::fabs(box.min[a]), std::fabs(box.max[a]));
        scaled[static_cast<size_t>(a)] = std::max(std::fabs(lo[a]), std::fabs(hi[a]));
      }
      // The position checks see every point; the bounds only the part of the box the view can show.
      for (size_t c = 0; c < checks.size(); ++c) {
        const Coords<double>& largest = checks[c].scene_frame ? scaled : stored;
        if (!(largest[0] <= checks[c].limit && largest[1] <= checks[c].limit && largest[2] <= checks[c].limit))
          beyond[worker][c] = 1;
      }
      const glm::dvec3 view_lo = glm::max(lo, pass.view_lo), view_hi = glm::min(hi, pass.view_hi);
      if (view_lo.x > view_hi.x || view_lo.y > view_hi.y || view_lo.z > view_hi.z) continue;
      if (boundPiece(pass, view_lo, view_hi, stored, b, kMostCuts, worst[worker]))
        visible[worker] += std::min<size_t>(kBoxPoints, boxes.count - b * kBoxPoints);
    }
  });
  ErrorBounds out;
  out.from_boxes = true;
  std::array<bool, kModeCount> beyond_limit{};
  for (unsigned t = 0; t < threads; ++t) {
    out.visible += visible[t];
    for (size_t m = 0; m < kModeCount; ++m) out.px[m] = std::max(out.px[m], worst[t][m]);
    for (size_t c = 0; c < checks.size(); ++c)
      if (beyond[t][c])
        for (size_t m = 0; m < kModeCount; ++m) beyond_limit[m] = beyond_limit[m] || checks[c].modes[m];
  }
  for (size_t m = 0; m < kModeCount; ++m) {
    out.px[m] = std::sqrt(out.px[m]) * (1.0 + kBoxMargin);
    out.computed[m] = s.wanted[m];
    if (beyond_limit[m] || (s.unbounded[m] && out.visible > 0)) out.px[m] = kInf;  // as predictErrorBounds
    // A mode that is not per batch encodes the frame alone: the boxes' position checks (every
    // coordinate's magnitude is largest at a box's min or max) stand for the encoder's, as a
    // point pass's checks do (predictErrorBounds).
    if (s.wanted[m] && modeInfo(kAllModes[m]).batch_points == 0 && !beyond_limit[m])
      out.encodings[m] = std::make_shared<const ModeEncoding>(beginEncoding(kAllModes[m], camera, tolerance_px));
  }
  out.float_floor_px = kU * 0.5 * std::max(camera.width, camera.height);
  return out;
}

ModeChoice chooseMode(std::span<const PrecisionMode> order, const std::function<bool(PrecisionMode)>& usable,
                      const BoundsOf& bounds_of, const BoundsOf& box_bounds_of) {
  ModeChoice choice;
  // The box's bounds of the modes that are not per batch, asked once, when first needed.
  std::optional<ErrorBounds> box;
  auto boxWithin = [&](PrecisionMode mode) {
    if (!box_bounds_of || modeInfo(mode).batch_points != 0) return false;
    if (!box) {
      std::vector<PrecisionMode> modes;
      for (PrecisionMode m : order)
        if (modeInfo(m).batch_points == 0) modes.push_back(m);
      box = box_bounds_of(modes);
    }
    return box->computed[modeIndex(mode)] && box->px[modeIndex(mode)] <= kAutoBoundPx;
  };
  // One pass for all of `modes`: a point (or box) is read and projected once, whichever modes are
  // bounded (each mode's bound is the same to the bit as from a pass of its own).
  auto compute = [&](std::span<const PrecisionMode> modes) {
    ErrorBounds b = bounds_of(modes);
    for (PrecisionMode mode : modes) {
      choice.bounds.px[modeIndex(mode)] = b.px[modeIndex(mode)];
      choice.bounds.computed[modeIndex(mode)] = true;
      choice.bounds.encodings[modeIndex(mode)] = std::move(b.encodings[modeIndex(mode)]);
    }
    choice.bounds.visible = b.visible;
    choice.bounds.float_floor_px = b.float_floor_px;
    choice.bounds.from_boxes = b.from_boxes;
  };
  auto bound = [&](PrecisionMode mode) {
    if (!choice.bounds.computed[modeIndex(mode)]) compute(std::span(&mode, 1));
    return choice.bounds.px[modeIndex(mode)];
  };
  // The walk below stops at the second usable mode within the bound, so from order[k] on it looks
  // at the next `certain` usable modes whatever their bounds (2 before the choice, 1 after): those
  // are computed in one pass, and no mode the walk would not look at is computed. A mode the box
  // shows within the limit is taken on the box's bound (as the choice or the runner-up): it needs
  // no place in the pass.
  auto computeAhead = [&](size_t k, size_t certain) {
    std::vector<PrecisionMode> ahead;
    for (; k < order.size() && certain > 0; ++k) {
      if (!usable(order[k])) continue;
      --certain;
      if (!choice.bounds.computed[modeIndex(order[k])] && !boxWithin(order[k])) ahead.push_back(order[k]);
    }
    if (!ahead.empty()) compute(ahead);
  };
  // Each mode ahead of the choice: unusable, or usable with a bound over the limit (computed above).
  auto noteRejected = [&] {
    for (PrecisionMode mode : order) {
      if (mode == choice.mode) break;
      choice.rejected.push_back({mode, usable(mode) ? bound(mode) : std::nan(""), std::string()});
    }
  };
  std::array<bool, kModeCount> from_box{};
  for (size_t k = 0; k < order.size(); ++k) {
    const PrecisionMode mode = order[k];
    if (!usable(mode)) continue;
    if (!choice.bounds.computed[modeIndex(mode)] && boxWithin(mode)) {
      choice.bounds.px[modeIndex(mode)] = box->px[modeIndex(mode)];
      choice.bounds.computed[modeIndex(mode)] = from_box[modeIndex(mode)] = true;
      choice.bounds.encodings[modeIndex(mode)] = box->encodings[modeIndex(mode)];
    }
    if (!choice.bounds.computed[modeIndex(mode)]) computeAhead(k, choice.enough ? 1 : 2);
    if (!(bound(mode) <= kAutoBoundPx)) continue;
    if (!choice.enough) {
      choice.mode = mode;
      choice.bound_px = bound(mode);
      choice.from_box = from_box[modeIndex(mode)];
      choice.enough = true;
    } else {
      choice.runner_up = mode;
      choice.runner_up_bound_px = bound(mode);
      choice.runner_up_from_box = from_box[modeIndex(mode)];
      noteRejected();
      return choice;
    }
  }
  if (choice.enough) {
    noteRejected();
    return choice;
  }
  std::optional<PrecisionMode> best;
  for (PrecisionMode mode : order) {
    if (!usable(mode)) continue;
    if (mode == kFallbackMode || !best || (*best != kFallbackMode && bound(mode) < bound(*best))) best = mode;
  }
  choice.mode = best.value_or(kFallbackMode);
  choice.bound_px = bound(choice.mode);
  noteRejected();
  return choice;
}

ModeChoice chooseMode(const PointSet& points, const Camera& camera, std::span<const PrecisionMode> order,
                      const std::function<bool(PrecisionMode)>& usable, double tolerance_px) {
  return chooseMode(order, usable, [&](std::span<const PrecisionMode> modes) {
    return predictErrorBounds(points, camera, modes, tolerance_px);
  });
}

std::string formatBound(double px) {
  if (!std::isfinite(px)) return "unbounded";
  char text[32];
  std::snprintf(text, sizeof text, "%.2g px", px);
  return text;
}

}  // namespace dpoint
