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
#pragma once

#include <array>
#include <string>
#include <vector>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>

#include "core/point_set.h"
#include "viewer/camera.h"
#include "viewer/encode.h"

namespace dpoint {

struct ErrorBounds {
  std::array<double, kModeCount> px{};      // by modeIndex; +inf: unbounded; only `computed` ones are set
  std::array<bool, kModeCount> computed{};
  size_t visible = 0;                       // points inside the view volume (0: every bound is 0)
  double float_floor_px = 0.0;              // 2^-24 · max(width, height) / 2
};

// Bounds of the modes in `modes` (all when empty). One pass over the points per call, on all cores.
// tolerance_px: adaptive mode's (its tier choice, viewer/batch_plan.h, which its bound follows).
ErrorBounds predictErrorBounds(const PointSet& points, const Camera& camera, std::span<const PrecisionMode> modes = {},
                               double tolerance_px = kDefaultTolerancePx);

// --mode auto (DESIGN §4): the fastest mode on this kind of device whose bound is ≤ kAutoBoundPx.
inline constexpr double kAutoBoundPx = 0.1;

struct ModeChoice {
  PrecisionMode mode = kFallbackMode;
  double bound_px = 0.0;
  bool enough = false;  // bound_px ≤ kAutoBoundPx
  std::optional<PrecisionMode> runner_up;  // the next mode in speed order within the bound
  double runner_up_bound_px = 0.0;
  ErrorBounds bounds;  // every mode the choice looked at
  // The modes ahead of the choice in speed order and why each was passed over: its bound over
  // kAutoBoundPx, or (bound_px NaN) the device cannot run it, `reason` saying why when the caller
  // knows (chooseModeOnDevice fills it in).
  struct Rejected {
    PrecisionMode mode;
    double bound_px;
    std::string reason;
  };
  std::vector<Rejected> rejected;
};

// Walks the speed order, skipping modes `usable` refuses, and takes the first whose bound is
// ≤ kAutoBoundPx; when none is, takes native if usable (else the usable mode with the smallest
// bound) with enough = false. Bounds are computed only for the modes it looks at, those it is sure
// to look at together in one pass (the next two usable modes before its choice, one after it).
ModeChoice chooseMode(const PointSet& points, const Camera& camera, std::span<const PrecisionMode> order,
                      const std::function<bool(PrecisionMode)>& usable, double tolerance_px = kDefaultTolerancePx);

// "1.5e-05 px", "unbounded" for +inf.
std::string formatBound(double px);

}  // namespace dpoint
