// What a point set needs from a number format: bounds, magnitudes, spacing, and whether float32
// would merge distinct points.
#pragma once

#include <cstddef>

#include "core/point_set.h"

namespace dpoint {

struct PointSetInfo {
  size_t count = 0;
  size_t triangles = 0;
  bool has_colors = false;
  glm::dvec3 min{0.0}, max{0.0}, extent{0.0};
  double max_abs = 0.0;        // largest |coordinate|
  double float_spacing = 0.0;  // distance between adjacent float32 values at max_abs
  // Smallest non-zero distance from a sampled point to its nearest neighbour among all points
  // (0 when every sampled point has only identical copies of itself as neighbours).
  double min_neighbor_distance = 0.0;
  size_t neighbor_sample = 0;  // how many points were sampled
  // Distinct points that become equal to another after rounding to float32 (count of points
  // lost), and coordinates beyond float range. float32 represents the set when both are zero.
  size_t float_merged = 0;
  size_t float_overflow = 0;
  bool floatRepresents() const { return float_merged == 0 && float_overflow == 0; }
};

// Deterministic: the sample is every k-th point. `threads` 0 means all cores.
// Cost: O(n log n) time, about 40 bytes per point of scratch memory.
PointSetInfo computeInfo(const PointSet& points, size_t neighbor_sample = 10000, unsigned threads = 0);

}  // namespace dpoint
