// How far apart a set's points lie: for sampled points, the distance to their kSpacingNeighbors-th
// nearest neighbour, fast enough to run before every render (the default point size follows it,
// viewer/render_job). Two passes over the points, each in any order and in blocks, so a set
// streamed from a file a block at a time gets the same samples and distances as the set in memory.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/ext/vector_int3_sized.hpp>
#include <glm/vec3.hpp>

#include "core/point_set.h"

namespace dpoint {

// The 4th nearest: on a surface or a grid, the spacing of its points, where the nearest alone
// finds the near-duplicates a mesh's vertices have.
inline constexpr size_t kSpacingNeighbors = 4;

struct SpacingSample {
  glm::dvec3 position{0.0};  // the sampled point
  double distance = 0.0;     // to its kSpacingNeighbors-th nearest point at another position
};

// Pass 1: the positions with the `samples` smallest hashes of their coordinates' bits (a position
// given twice counts twice, and is sampled once): a spread over the set that depends on the points,
// not on their order or on how they are split.
class SpacingSampler {
 public:
  explicit SpacingSampler(size_t samples, unsigned threads = 0) : wanted_(samples), threads_(threads) {}
  void add(std::span<const glm::dvec3> points);
  PositionArray finish() const;  // ordered by hash

 private:
  size_t wanted_;
  unsigned threads_;
  std::vector<std::pair<uint64_t, glm::dvec3>> heap_;  // max-heap on the hash
};

// Pass 2: each sample's distance, on a uniform grid over `box` (the set's bounding box) whose cell
// is twice the spacing `count` points would have filling the box's volume or its largest face;
// only the cells next to a sample's are kept, and any point within a cell of a sample lies in them,
// so a distance up to a cell is exact. finish() gives the samples whose distance is within a cell,
// or none when that is fewer than half of them (points far sparser than their box suggests).
class SpacingSearch {
 public:
  SpacingSearch(const Box& box, uint64_t count, PositionArray samples, unsigned threads = 0);
  void add(std::span<const glm::dvec3> points);
  // Whether a point in `box` may lie in a kept cell: false means add() would pass over every one of
  // them, so a streamed set's batch with that box need not be read (true for a box over many cells).
  bool mayUse(const Box& box) const;
  std::vector<SpacingSample> finish() const;

 private:
  using Best = std::array<double, kSpacingNeighbors>;  // squared distances, ascending
  uint64_t cellKey(const glm::dvec3& p) const;
  uint32_t findSlot(uint64_t key) const;
  std::vector<Best> emptyBest() const;  // a worker's lists before it has seen a point

  PositionArray samples_;
  std::vector<glm::i64vec3> sample_cells_;  // each sample's cell, ordered by x (mayUse)
  unsigned threads_;
  glm::dvec3 origin_{0.0};
  double cell_ = 0.0, inverse_cell_ = 0.0;
  double unit_ = 1.0;  // distances are squared in this many per unit of length (a power of two)
  // A bit per hash of the kept cells' keys: 64 KiB, which L2 holds, so that a few percent of the
  // points that lie in no kept cell pass it (2^16 bits let a fifth of them through to the table).
  static constexpr size_t kFilterBits = size_t{1} << 19;
  std::vector<uint64_t> filter_ = std::vector<uint64_t>(kFilterBits / 64, 0);
  std::vector<uint64_t> keys_;              // open addressing: cell key + 1, 0 = empty
  std::vector<uint32_t> slots_;             // the slot of keys_[i]
  std::vector<uint32_t> slot_start_;        // slot s lists samples slot_samples_[start[s], start[s + 1])
  std::vector<uint32_t> slot_samples_;
  std::vector<std::vector<Best>> best_;     // per worker, per sample
};

// A power of two near 1 / `extent` (1 where that is 0 or not finite): lengths of about the extent
// are measured in it, so that their squares and volumes neither overflow at 1e200 nor underflow at
// 1e-200; exact, as it moves only the exponent. With `largest_coordinate`, no larger than keeps
// coordinates up to it finite, for a caller that scales the points themselves.
double lengthUnit(double extent, double largest_coordinate = 0.0);

// Both passes over a set in memory: up to `samples` samples. Empty when the set has fewer than 2
// distinct positions or SpacingSearch finds too few. About 10 ms for 1.55M points on 2 cores.
std::vector<SpacingSample> sampleSpacing(const PositionArray& positions, const Box& box, size_t samples,
                                         unsigned threads = 0);

}  // namespace dpoint
