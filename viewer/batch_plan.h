// The per-camera plan of the per-batch modes (batch, adaptive; issue #25): for each batch of 4096
// Morton-ordered points, whether its box can hold a point the view shows (where it cannot, the
// compute backend never dispatches it, so a view of 1% of a set costs about 1% of the set) and,
// in adaptive mode, the fewest tiers whose predicted error over the whole box is within the
// tolerance. The encoding makes the plan as batches are added (viewer/encode.h, addPoints); the
// per-point bound of viewer/modes.cpp then follows the tiers chosen, so the bound reported for
// the view covers the choice.
#pragma once

#include <array>
#include <cstddef>

#include "viewer/encode.h"

namespace dpoint {

// Fills encoding.batch_plan for batches [first_batch, end): 0 culled, else the tiers to load
// (batch mode: 1).
void planBatches(ModeEncoding& encoding, size_t first_batch);

// Whether batch b's box (origin ± extent) can hold a point of the view volume. Conservative: a
// batch is culled only when its whole box lies outside one clip plane by a margin far above the
// GPU's float rounding of the clip position, so no point the GPU could draw is in it.
bool batchBoxVisible(const ModeEncoding& encoding, size_t b);

// Adaptive mode's predicted error in window pixels of any point in batch b's box when `tiers`
// tiers are loaded (viewer/bound_terms.h's terms with every offset at its largest and the box's
// extreme clip positions); +inf where the box reaches the eye's plane. The plan takes the fewest
// tiers with this ≤ tolerance_px (all three when none is).
double adaptiveBoxBoundPx(const ModeEncoding& encoding, size_t b, uint32_t tiers);

// What a frame of the plan reads: batches culled and at each tier count (batch mode: drawn ones
// at [0]), and position bytes loaded per point of the whole set (a culled batch's points count 0).
struct BatchPlanStats {
  size_t batches = 0, culled = 0;
  std::array<size_t, kAdaptiveTiers> at_tiers{};
  double bytes_per_point = 0.0;
};
BatchPlanStats batchPlanStats(const ModeEncoding& encoding, size_t points);

}  // namespace dpoint
