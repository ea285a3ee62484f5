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

Pass makePass(const PointSet& points, const Camera& camera, std::span<const PrecisionMode> modes, double tolerance_px) {
  Pass pass;
  Setup& s = pass.setup;
  s.frame = sceneFrame(camera);
  s.world_mvp = camera.viewProjection();
  glm::dmat4 translate(1.0);
  translate[3] = glm::dvec4(-s.frame.eye, 1.0);
  s.df64_mvp = s.frame.projection_rotation * translate;
  for (int a = 0; a < 3; ++a) s.eye_split[static_cast<size_t>(a)] = splitDouble(s.frame.eye[a]);
  s.world_rows = floatRows(s.world_mvp);
  s.projection_rows = floatRows(s.frame.projection_rotation);
  if (modes.empty()) modes = kAllModes;
  for (PrecisionMode mode : modes) {
    const size_t i = modeIndex(mode);
    s.wanted[i] = true;
    if (modeInfo(mode).batch_points == 0) {
      pass.own[i].encoding = beginEncoding(mode, camera);
      addPositionCheck(pass.checks, mode);
      continue;
    }
    Result<ModeEncoding> encoding = prepareEncoding(mode, points, camera, tolerance_px);
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
    for (const BatchFrame& batch : own.encoding.batches)
      own.batch_translation_error.push_back(batchTranslationError(s.frame, batch.origin));
    for (const glm::dmat4& m : own.encoding.batch_matrices) own.batch_rows.push_back(floatRows(m));
  }
  return pass;
}

}  // namespace

ErrorBounds predictErrorBounds(const PointSet& points, const Camera& camera, std::span<const PrecisionMode> modes,
                               double tolerance_px) {
  const Pass pass = makePass(points, camera, modes, tolerance_px);
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
  std::array<bool, kModeCount> refused = s.unbounded;  // and the modes whose encoding refuses a point
  for (unsigned t = 0; t < threads; ++t) {
    out.visible += visible[t];
    for (size_t m = 0; m < kModeCount; ++m) out.px[m] = std::max(out.px[m], worst[t][m]);
    for (size_t c = 0; c < pass.checks.size(); ++c)
      if (beyond[t][c])
        for (size_t m = 0; m < kModeCount; ++m) refused[m] = refused[m] || pass.checks[c].modes[m];
  }
  for (size_t m = 0; m < kModeCount; ++m) {
    out.px[m] = std::sqrt(out.px[m]) * (1.0 + 1e-9);
    out.computed[m] = s.wanted[m];
    // Nothing of a refused mode reaches the picture; with no point in view every bound is 0.
    if (refused[m] && out.visible > 0) out.px[m] = kInf;
  }
  out.float_floor_px = kU * 0.5 * std::max(camera.width, camera.height);
  return out;
}

ModeChoice chooseMode(const PointSet& points, const Camera& camera, std::span<const PrecisionMode> order,
                      const std::function<bool(PrecisionMode)>& usable, double tolerance_px) {
  ModeChoice choice;
  // One pass over the points for all of `modes`: a point is read and projected once, whichever
  // modes are bounded (each mode's bound is the same to the bit as from a pass of its own).
  auto compute = [&](std::span<const PrecisionMode> modes) {
    const ErrorBounds b = predictErrorBounds(points, camera, modes, tolerance_px);
    for (PrecisionMode mode : modes) {
      choice.bounds.px[modeIndex(mode)] = b.px[modeIndex(mode)];
      choice.bounds.computed[modeIndex(mode)] = true;
    }
    choice.bounds.visible = b.visible;
    choice.bounds.float_floor_px = b.float_floor_px;
  };
  auto bound = [&](PrecisionMode mode) {
    if (!choice.bounds.computed[modeIndex(mode)]) compute(std::span(&mode, 1));
    return choice.bounds.px[modeIndex(mode)];
  };
  // The walk below stops at the second usable mode within the bound, so from order[k] on it looks
  // at the next `certain` usable modes whatever their bounds (2 before the choice, 1 after): those
  // are computed in one pass, and no mode the walk would not look at is computed.
  auto computeAhead = [&](size_t k, size_t certain) {
    std::vector<PrecisionMode> ahead;
    for (; k < order.size() && certain > 0; ++k) {
      if (!usable(order[k])) continue;
      --certain;
      if (!choice.bounds.computed[modeIndex(order[k])]) ahead.push_back(order[k]);
    }
    compute(ahead);
  };
  // Each mode ahead of the choice: unusable, or usable with a bound over the limit (computed above).
  auto noteRejected = [&] {
    for (PrecisionMode mode : order) {
      if (mode == choice.mode) break;
      choice.rejected.push_back({mode, usable(mode) ? bound(mode) : std::nan(""), std::string()});
    }
  };
  for (size_t k = 0; k < order.size(); ++k) {
    const PrecisionMode mode = order[k];
    if (!usable(mode)) continue;
    if (!choice.bounds.computed[modeIndex(mode)]) computeAhead(k, choice.enough ? 1 : 2);
    if (!(bound(mode) <= kAutoBoundPx)) continue;
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
