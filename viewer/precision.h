// Predicted error of each precision mode (DESIGN §4, §5), and `--mode auto`'s choice.
//
// For one point set and one camera, each mode gets a bound in pixels on the distance between the
// window position its probe reports and the exact one (the reference of viewer/reference.h). The
// bound follows each mode's arithmetic step by step with standard floating-point error analysis
// (Higham, "Accuracy and Stability of Numerical Algorithms", ch. 2–3: |fl(a ∘ b) − a ∘ b| ≤ u·|a ∘ b|,
// a dot product of n terms is off by at most γ_n·Σ|a_i b_i|, γ_n = n·u / (1 − n·u)), with u = 2^-24
// for float, 2^-48 for a hi/lo float pair, 2^-53 for double, plus FLT_MIN wherever a GPU may flush a
// subnormal to zero. It is evaluated per point from that point's own coordinates and clip position
// and maximised over the points the camera sees; no term is fitted to measurements. A mode whose
// encoding or arithmetic overflows on the set (fp32 past 3.4e38, Dekker's split past 8e34) is
// unbounded (+inf): points may be lost.
//
// The floor every mode meets is the float rounding of the final clip position: about 2^-24 of the
// viewport's half-size in pixels.
//
// A set streamed from a file is known before it is drawn only by the box of every 1024 points
// (BatchBoxes, as many as adaptive mode's batch; batch mode's are unions of four); predictBoxBounds bounds every point such a box may hold, so --mode auto
// chooses for it as for a set in memory (docs/precision.md says why the box bound is an upper bound).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/point_set.h"
#include "viewer/camera.h"
#include "viewer/encode.h"

namespace dpoint {

struct ErrorBounds {
  std::array<double, kModeCount> px{};      // by modeIndex; +inf: unbounded; only `computed` ones are set
  std::array<bool, kModeCount> computed{};
  // Points inside the view volume (0: every bound is 0). From boxes (predictBoxBounds): the points
  // of every box that may hold a visible point, no fewer than are visible.
  size_t visible = 0;
  double float_floor_px = 0.0;              // 2^-24 · max(width, height) / 2
  bool from_boxes = false;                  // predictBoxBounds: each batch's box stood for its points
  // Per computed mode, its encoding for this camera and tolerance (prepareEncoding's), where the
  // pass built it (per-batch modes) or checked every point against it (the others; from boxes,
  // every box's corners, which hold every coordinate's extremes): renderPoints takes it rather
  // than building it again. Null where the mode refuses the set, and for the per-batch modes from
  // boxes.
  std::array<std::shared_ptr<const ModeEncoding>, kModeCount> encodings;
};

// Bounds of the modes in `modes` (all when empty). One pass over the points per call, on all cores.
// tolerance_px: adaptive mode's (its tier choice, viewer/batch_plan.h, which its bound follows).
ErrorBounds predictErrorBounds(const PointSet& points, const Camera& camera, std::span<const PrecisionMode> modes = {},
                               double tolerance_px = kDefaultTolerancePx);

// A set read a block at a time (a streamed PLY), summarised in the pass that finds its bounds: the
// double bounding box of every kBoxPoints (1024) consecutive points, whose unions are the batches
// of the per-batch modes. 1e9 points: 977k boxes, 47 MB.
struct BatchBoxes {
  size_t count = 0;        // points summarised
  std::vector<Box> boxes;  // boxes[b]: of points [b·kBoxPoints, min(count, (b + 1)·kBoxPoints))
};
// Adds the next points of the set, [boxes.count, boxes.count + positions.size()) (non-empty); every
// call but the last adds whole batches. On all cores.
void addBatchBoxes(BatchBoxes& boxes, const PositionArray& positions);

// predictErrorBounds for a set known by its batch boxes: per mode a guaranteed upper bound of the
// per-point bound of every point each box may hold. The clip position is affine in the point, so
// over a box each row's extremes are at corners; each mode's terms are taken with every input at
// its largest over the box (|p|, |p − eye|, the batch offsets: the terms only grow with them), and
// the pixel distance at the box's largest |x|, |y| a visible point may have and its least w, which
// in perspective is no less than the near plane's (points nearer are not drawn). A box that may
// hold no visible point adds nothing. The per-batch modes' frames, matrices and plan are those
// renderStream makes of the points (encode.h, addBoxes: to the bit); adaptive's bound for a batch is
// also at most that of the tiers its plan chose (adaptiveBoxBoundPx).
ErrorBounds predictBoxBounds(const BatchBoxes& boxes, const Camera& camera, std::span<const PrecisionMode> modes = {},
                             double tolerance_px = kDefaultTolerancePx);

// --mode auto (DESIGN §4): the fastest mode on this kind of device whose bound is ≤ kAutoBoundPx.
inline constexpr double kAutoBoundPx = 0.1;

struct ModeChoice {
  PrecisionMode mode = kFallbackMode;
  double bound_px = 0.0;
  bool enough = false;  // bound_px ≤ kAutoBoundPx
  // bound_px is the bound over the set's box (chooseMode's box_bounds_of), which showed the choice
  // within the limit without a pass over the points: no less than the points' own.
  bool from_box = false;
  std::optional<PrecisionMode> runner_up;  // the next mode in speed order within the bound
  double runner_up_bound_px = 0.0;
  // runner_up_bound_px is the bound over the set's box (chooseMode's box_bounds_of), which showed
  // the runner-up within the limit without a pass over the points: no less than the points' own.
  bool runner_up_from_box = false;
  // Ordered by predicted time to one picture (AutoTarget): the choice's and the runner-up's (ms).
  bool by_picture_time = false;
  double predicted_ms = std::nan(""), runner_up_predicted_ms = std::nan("");
  // Every mode the choice looked at; the choice's and the runner-up's entries are the box's bounds
  // where from_box and runner_up_from_box. visible and float_floor_px are those of the last pass
  // over the points, and 0 where the walk made none (every mode it took came from the box).
  ErrorBounds bounds;
  // The modes ahead of the choice in speed order and why each was passed over: its bound over
  // kAutoBoundPx, or (bound_px NaN) the device cannot run it, `reason` saying why when the caller
  // knows (chooseModeOnDevice fills it in).
  struct Rejected {
    PrecisionMode mode;
    double bound_px;
    std::string reason;
  };
  std::vector<Rejected> rejected;
  // The chosen mode's encoding from the bounds (ErrorBounds::encodings), for renderPoints; or null.
  std::shared_ptr<const ModeEncoding> encoding() const { return bounds.encodings[modeIndex(mode)]; }
};

// What --mode auto minimises (issue #38 item 3): with `points` set and one frame, the predicted
// time to the picture of `points` points encoded on `threads` cores (viewer/modes.h, autoOrder);
// else, or with more frames, the frames (the measured speed order).
struct AutoTarget {
  uint64_t points = 0;
  unsigned threads = 0;  // 0: all cores
  uint32_t frames = 1;
};

// What the walk asks for: the bounds of some modes, in one pass (predictErrorBounds or
// predictBoxBounds with the set, the camera and the tolerance bound in).
using BoundsOf = std::function<ErrorBounds(std::span<const PrecisionMode> modes)>;

// Walks the speed order, skipping modes `usable` refuses, and takes the first whose bound is
// ≤ kAutoBoundPx; when none is, takes native if usable (else the usable mode with the smallest
// bound) with enough = false. Bounds are computed only for the modes it looks at, those it is sure
// to look at together in one pass (the next two usable modes before its choice, one after it).
// box_bounds_of, where given, bounds a mode over a box that holds the set (predictBoxBounds of its
// bounding box: no pass over the points, and no less than bounds_of's): a mode it shows within the
// limit is the choice (from_box) or the runner-up (runner_up_from_box) without a pass of its own,
// and with the box's encoding; the mode drawn is the same as on bounds_of's bounds alone. Every
// mode passed over keeps bounds_of's bound. The per-batch modes are not asked of it (their
// encoding is of the points).
ModeChoice chooseMode(std::span<const PrecisionMode> order, const std::function<bool(PrecisionMode)>& usable,
                      const BoundsOf& bounds_of, const BoundsOf& box_bounds_of = {});
// The walk on the bounds of the points themselves (predictErrorBounds).
ModeChoice chooseMode(const PointSet& points, const Camera& camera, std::span<const PrecisionMode> order,
                      const std::function<bool(PrecisionMode)>& usable, double tolerance_px = kDefaultTolerancePx);

// "1.5e-05 px", "unbounded" for +inf.
std::string formatBound(double px);

}  // namespace dpoint
