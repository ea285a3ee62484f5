// The order points are stored in. The GPU compute backend (DESIGN §4) draws faster when points
// that follow one another in memory lie close together on screen: a workgroup then touches few
// cache lines of the visibility buffer. `morton` lays the points out along a Morton curve in
// blocks shown in shuffled order (Schütz, Kerbl, Wimmer, "Rendering Point Clouds with Compute
// Shaders and Vertex Order Optimization", EGSR 2021); point_order.cpp says why the shuffle.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/memory.h"
#include "core/point_set.h"
#include "core/result.h"

namespace dpoint {

class Progress;

enum class PointOrder {
  kInput,   // leave the points as they are
  kMorton,  // Morton curve, whole blocks of kOrderBlock points in a fixed shuffled order
};

// Points per block of the Morton order. Must equal kBatchSize in viewer/encode.h (the `batch`
// mode's batch, and the unit the GPU backends work in), so that every batch the renderer forms
// is one spatially compact block. Core does not include viewer headers; a static_assert in
// tests/ops/point_order_test.cpp ties the two.
inline constexpr size_t kOrderBlock = 4096;

// "input" or "morton". The error (kUsage) names `flag` and quotes the text.
Result<PointOrder> parsePointOrder(const std::string& flag, const std::string& text);
const char* pointOrderName(PointOrder order);
// What the orders are for, as the --help of every subcommand that takes --order says it.
inline constexpr const char* kPointOrderHelp =
    "input|morton. input: the order as read or generated; morton: sort points along a Morton curve in\n"
    "4096-point blocks shown in shuffled order; faster on the GPU compute backend; the picture is the\n"
    "same except which of two points at the same depth on one pixel wins";

// Puts the points in `order`. Colours move with their positions and triangle indices are
// renumbered, so a mesh stays the same mesh. kMorton: a stable sort by mortonCode in the set's
// own frame (equal codes keep their input order), then the sorted sequence cut into blocks of
// kOrderBlock points, the whole blocks laid out in the order shuffledBlocks gives and a last
// partial block kept last. The result does not depend on `threads` (0: all cores).
// Non-finite coordinates are allowed (they sort to an end of their axis). At most 2^32 - 1
// points (asserted; triangles are 32-bit anyway). Extra memory at the peak: reorderExtraBytes.
// `progress`, when given, shows the work as one step, "morton order".
void reorderPoints(PointSet& points, PointOrder order, unsigned threads = 0, Progress* progress = nullptr);

// Bytes reorderPoints allocates on top of the set at its peak: for kMorton 28 per point (24 for
// the sort's code and index arrays and their scratch copies; then 4 for the sorted indices and
// 24 for one gathered copy of the positions), 0 for kInput.
uint64_t reorderExtraBytes(size_t points, PointOrder order);
// Refuses (kResourceLimit) more points than an order holds: 2^32 - 1 (the indices are 32-bit).
Status checkOrderable(uint64_t points);
// Refuses (kResourceLimit, "ordering N points needs …", core/memory.h) an order whose peak — the
// set's positions, colours and triangles plus reorderExtraBytes — is over `limit` (0: half of RAM),
// or of more points than checkOrderable allows.
Status checkReorderMemory(const PointSet& points, PointOrder order, uint64_t limit);

// Where output block b of the Morton order comes from in the code-sorted sequence: whole block
// blocks[b] (blocks = shuffledBlocks), or, past them, the last partial block in place.
inline size_t mortonSourceBlock(const std::vector<uint32_t>& blocks, size_t b) {
  return b < blocks.size() ? blocks[b] : b;
}

// The Morton order as rows rather than moved points: row r of the ordered set is point source(r)
// of the set in its order before. Holds 4 bytes a point.
class MortonRows {
 public:
  size_t size() const { return n_; }
  uint32_t source(size_t r) const {
    return sorted_[mortonSourceBlock(blocks_, r / kOrderBlock) * kOrderBlock + r % kOrderBlock];
  }

 private:
  friend MortonRows mortonRows(size_t, const std::function<glm::dvec3(uint64_t)>&, unsigned, Progress*);
  LargeBuffer buffer_;
  const uint32_t* sorted_ = nullptr;  // the indices in code order, in buffer_
  std::vector<uint32_t> blocks_;      // shuffledBlocks(n / kOrderBlock)
  size_t n_ = 0;
};

// The order reorderPoints(kMorton) gives a set of `n` points (at most 2^32 - 1) whose point i is
// at(i), made on demand instead of held: for a generator whose points are a function of their
// index (random2d), the rows of a file written in that order with no array of positions. Each point
// is made twice (for the frame, then its code), so `at` should be cheap; it is called from
// several threads at once. The same rows for any `threads` (0: all cores). Memory at the peak:
// mortonRowsBytes. `progress`, when given, shows the work as one step, "morton order".
MortonRows mortonRows(size_t n, const std::function<glm::dvec3(uint64_t)>& at, unsigned threads = 0,
                      Progress* progress = nullptr);
// 24 bytes a point: 4 for the rows, 20 while sorting.
inline uint64_t mortonRowsBytes(size_t n) { return uint64_t{24} * n; }

// The frame Morton codes are taken in: the box of the finite coordinates, kept as halves
// (min/2 and (max - min)/2 computed as max/2 - min/2) so that no extent overflows, however far
// apart the coordinates are.
struct MortonFrame {
  glm::dvec3 half_min{0.0};
  glm::dvec3 half_extent{0.0};  // 0 on a flat axis (or an axis with no finite coordinate)
};
MortonFrame mortonFrame(const PositionArray& positions, unsigned threads = 0);

// Each coordinate quantized to 21 bits within the frame (the box's minimum maps to 0, its
// maximum to 2^21 - 1, 0 on a flat axis, NaN and -inf to 0, +inf to 2^21 - 1), the bits
// interleaved x, y, z from the lowest: bit 3k of the code is bit k of x, 3k+1 of y, 3k+2 of z.
// Monotone in each coordinate. The top bit (63) is always 0.
uint64_t mortonCode(const MortonFrame& frame, const glm::dvec3& p);

// The order the `count` whole blocks are laid out in: a permutation of 0..count-1 from a
// Fisher-Yates shuffle driven by std::mt19937_64 with a fixed seed (both fully specified by the
// standard, unlike std::shuffle), so every build and machine gives the same order.
std::vector<uint32_t> shuffledBlocks(size_t count);

// The low 21 bits of x, y and z interleaved (bit k of x to bit 3k, of y to 3k + 1, of z to 3k + 2):
// a Morton code, the order `--order morton` sorts by and COPC's writer orders a node's points by.
uint64_t mortonInterleave(uint32_t x, uint32_t y, uint32_t z);

}  // namespace dpoint
