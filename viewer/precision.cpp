// Predicted error per mode: the pass over the points, and --mode auto's walk. Each mode's own
// analysis is the bound function beside its row in viewer/modes.cpp; the terms they share (and
// the notation) are in viewer/bound_terms.h.
#include "viewer/precision.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <vector>

#include "core/parallel.h"
#include "viewer/bound_terms.h"

namespace dpoint {
namespace {

using namespace bound;

// The shared setup, and each wanted mode's own state (empty for a mode that refuses the set).
struct Pass {
  Setup setup;
  std::array<ModeState, kModeCount> own;
};

Pass makePass(const PointSet& points, const Camera& camera, std::span<const PrecisionMode> modes) {
  Pass pass;
  Setup& s = pass.setup;
  s.frame = sceneFrame(camera);
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
    pass.own[i].encoding = std::move(*encoding);
  }
  for (PrecisionMode mode : modes) {
    const BoundRefusal refuses = modeInfo(mode).bound_refuses;
    if (refuses && refuses(s)) s.unbounded[modeIndex(mode)] = true;
  }
  for (ModeState& own : pass.own) {
    for (size_t b = 0; b < own.encoding.batches.size(); ++b) {
      const glm::dvec3 relative = own.encoding.batches[b].origin - s.frame.eye;
      Vec4 error{};
      for (int r = 0; r < 4; ++r) {
        double sum = std::fabs(s.frame.projection_rotation[3][r]);
        for (int c = 0; c < 3; ++c) sum += std::fabs(s.frame.projection_rotation[c][r] * relative[c]);
        error[static_cast<size_t>(r)] = 4.0 * kUd * sum;
      }
      own.batch_translation_error.push_back(error);
    }
  }
  return pass;
}

}  // namespace

ErrorBounds predictErrorBounds(const PointSet& points, const Camera& camera, std::span<const PrecisionMode> modes) {
  const Pass pass = makePass(points, camera, modes);
  const Setup& s = pass.setup;
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
      const Worst w = modeInfo(mode).bound(s, pass.own[m], points, first, end, camera);
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
  // Each mode ahead of the choice: unusable, or usable with a bound over the limit (computed above).
  auto noteRejected = [&] {
    for (PrecisionMode mode : order) {
      if (mode == choice.mode) break;
      choice.rejected.push_back({mode, usable(mode) ? bound(mode) : std::nan(""), std::string()});
    }
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

std::string formatBound(double px) {
  if (!std::isfinite(px)) return "unbounded";
  char text[32];
  std::snprintf(text, sizeof text, "%.2g px", px);
  return text;
}

}  // namespace dpoint
