// What a point set needs from a number format: bounds, magnitudes, spacing, and whether float32
// would merge distinct points.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>

#include "core/point_set.h"
#include "core/result.h"

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
  // Points with a coordinate that is NaN or infinite (read with --allow-nonfinite): their other
  // coordinates count in the bounds; no mode can place them in a picture.
  size_t nonfinite = 0;
  bool floatRepresents() const { return float_merged == 0 && float_overflow == 0; }
};

// What computeInfo gives, for a set read a block at a time (`dpoint info` on input larger than
// memory): `read(first, n, block)` fills `block` with points [first, first + n). Two passes: the
// counts, bounds, the sample and a first bound on each sampled point's nearest distance (the
// points beside it in the file), and the box of every 1024 points; then, where most of those boxes
// are compact (a file in Morton or slab order), the boxes within some sampled point's bound, read
// again, each against the samples it may be nearest to (a few per cent of a 1e8-point Morton file);
// else the blocks whose box lies within some sampled point's bound, read again whole into k-d trees
// of 2^20 points built in parallel, searched nearest first. Either way each sampled distance is
// exact. block_points: a multiple of 1024. float_merged, which needs every point at
// once, is not computed (merged_computed false). Errors are read's.
// Points per box of the first pass (as many as the renderer's batch boxes, viewer/precision.h).
inline constexpr uint64_t kStreamedInfoBoxPoints = 1024;
struct StreamedInfo {
  PointSetInfo info;
  bool merged_computed = false;
  uint64_t points_read_again = 0;  // by the second pass
  // The box of every kStreamedInfoBoxPoints consecutive points, where the blocks are whole boxes
  // (else of every block): what the renderer's bound needs of a stream, for info's advice.
  std::vector<Box> boxes;
  // The box of the points whose coordinates are all finite (min > max where none is): what a view
  // frames where some are not (info.nonfinite), as the set read whole frames it.
  Box finite{glm::dvec3(HUGE_VAL), glm::dvec3(-HUGE_VAL)};
};
using BlockReader = std::function<Status(uint64_t first, uint64_t n, PointSet& block)>;
Result<StreamedInfo> computeStreamedInfo(uint64_t count, bool has_colors, uint64_t triangles, const BlockReader& read,
                                         uint64_t block_points, size_t neighbor_sample = 10000, unsigned threads = 0);

// Deterministic: the sample is every k-th point, its nearest neighbours exact (k-d trees of 2^20
// points, built in parallel). `threads` 0 means all cores.
// Cost: O(n log n) time, about 40 bytes per point of scratch memory.
PointSetInfo computeInfo(const PointSet& points, size_t neighbor_sample = 10000, unsigned threads = 0);

}  // namespace dpoint
