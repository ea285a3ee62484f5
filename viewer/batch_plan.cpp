#include "viewer/batch_plan.h"

#include <algorithm>
#include <cmath>

#include "core/parallel.h"
#include "viewer/bound_terms.h"

namespace dpoint {
namespace {

using namespace bound;

// Each clip row over batch b's box: its value at the box's centre and how far it moves within the
// box (affine in the point, so the extremes are at corners: centre ± extent · Σ_c |P_rc|).
struct BoxClip {
  Vec4 centre{}, radius{};
};
BoxClip boxClip(const ModeEncoding& e, size_t b) {
  const SceneFrame& frame = e.frame;
  const BatchFrame& batch = e.batches[b];
  const glm::dvec3 relative = batch.origin - frame.eye;
  const glm::dmat4& m = frame.projection_rotation;
  BoxClip box;
  for (int r = 0; r < 4; ++r) {
    const size_t row = static_cast<size_t>(r);
    box.centre[row] = m[0][r] * relative.x + m[1][r] * relative.y + m[2][r] * relative.z + m[3][r];
    box.radius[row] = batch.extent * (std::fabs(m[0][r]) + std::fabs(m[1][r]) + std::fabs(m[2][r]));
  }
  return box;
}

}  // namespace

bool batchBoxVisible(const ModeEncoding& e, size_t b) {
  const SceneFrame& frame = e.frame;
  const BatchFrame& batch = e.batches[b];
  const glm::dvec3 relative = batch.origin - frame.eye;
  const glm::dmat4& m = frame.projection_rotation;
  // The view volume's planes as weights of the clip rows (x, y, z, w), inside where ≥ 0:
  // w − x, w + x, w − y, w + y, z, w − z.
  static constexpr double kPlanes[6][4] = {{-1, 0, 0, 1}, {1, 0, 0, 1}, {0, -1, 0, 1},
                                           {0, 1, 0, 1},  {0, 0, 1, 0}, {0, 0, -1, 1}};
  for (const auto& plane : kPlanes) {
    // The plane's value is affine in the point: at the box's centre, ± extent · Σ_c |its weight of c|.
    double centre = 0.0, slope = 0.0, size = 0.0;
    for (int c = 0; c < 4; ++c) {
      double weight = 0.0;
      for (int r = 0; r < 4; ++r) weight += plane[r] * m[c][r];
      if (c < 3) {
        centre += weight * relative[c];
        slope += std::fabs(weight);
        size += std::fabs(weight * relative[c]);
      } else {
        centre += weight;
        size += std::fabs(weight);
      }
    }
    const double most = centre + batch.extent * slope;
    // The GPU's clip rows are off by a few float roundings of their terms; 2^−16 of the terms'
    // size is far beyond that, and far beyond the double rounding here.
    if (most < -0x1p-16 * (size + batch.extent * slope)) return false;
  }
  return true;
}

double adaptiveBoxBoundPx(const ModeEncoding& e, size_t b, uint32_t tiers) {
  const BoxClip box = boxClip(e, b);
  const double w_min = box.centre[3] - box.radius[3];
  if (!(w_min > 0.0)) return kInf;
  const double largest = kAdaptiveSteps;  // |steps| ≤ 2^29 in the box
  const double dv = adaptiveOffsetError(tiers, largest);
  Clip<double> d = batchMatrixError(e, b, Coords<double>{largest, largest, largest}, Coords<double>{dv, dv, dv});
  // pixelsSquared at the box's worst: the largest |x|, |y| a visible point has (≤ w) and the least w.
  const double w_max = box.centre[3] + box.radius[3];
  Clip<double> c;
  c[0] = std::min(std::fabs(box.centre[0]) + box.radius[0], w_max);
  c[1] = std::min(std::fabs(box.centre[1]) + box.radius[1], w_max);
  c[2] = 0.0;
  c[3] = w_min;
  d[2] = 0.0;
  const double squared = pixelsSquared(c, d, 0.5 * e.width, 0.5 * e.height);
  return std::sqrt(squared) * (1.0 + 1e-9);
}

void planBatches(ModeEncoding& e, size_t first_batch) {
  const uint32_t most = modeInfo(e.mode).tiers;
  e.batch_plan.resize(e.batches.size());
  parallelFor(e.batches.size() - first_batch, 0, [&](size_t k, unsigned) {
    const size_t b = first_batch + k;
    uint8_t plan = 0;
    if (batchBoxVisible(e, b)) {
      plan = 1;
      if (most > 0)
        while (plan < most && !(adaptiveBoxBoundPx(e, b, plan) <= e.tolerance_px)) ++plan;
    }
    e.batch_plan[b] = plan;
  });
}

BatchPlanStats batchPlanStats(const ModeEncoding& e, size_t points) {
  BatchPlanStats stats;
  const ModeInfo& info = modeInfo(e.mode);
  stats.batches = e.batch_plan.size();
  double bytes = 0.0;
  for (size_t b = 0; b < e.batch_plan.size(); ++b) {
    const uint8_t plan = e.batch_plan[b];
    const size_t in_batch = std::min(e.batchSize(), points - std::min(points, b * e.batchSize()));
    if (plan == 0) {
      ++stats.culled;
      continue;
    }
    ++stats.at_tiers[plan - 1];
    bytes += static_cast<double>(in_batch) *
             (info.tiers ? plan * info.layout.element_bytes : info.position_bytes);
  }
  stats.bytes_per_point = points ? bytes / static_cast<double>(points) : 0.0;
  return stats;
}

}  // namespace dpoint
