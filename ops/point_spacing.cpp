#include "ops/point_spacing.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include <glm/glm.hpp>

#include "core/parallel.h"
#include "core/random.h"

namespace dpoint {
namespace {

constexpr int kCellBits = 21;  // cell coordinates per axis, packed three to a 64-bit key
constexpr int64_t kMaxCell = (int64_t{1} << kCellBits) - 1;
constexpr double kInf = std::numeric_limits<double>::infinity();

// One mix of the three coordinates' bits, rotated apart (+ 0.0: -0 hashes as 0).
uint64_t positionHash(const glm::dvec3& p) {
  return splitmixMix(std::bit_cast<uint64_t>(p.x + 0.0) ^ std::rotl(std::bit_cast<uint64_t>(p.y + 0.0), 21) ^
             std::rotl(std::bit_cast<uint64_t>(p.z + 0.0), 42));
}

size_t tableIndex(uint64_t key, size_t size) { return size_t(splitmixMix(key)) & (size - 1); }

}  // namespace

namespace {

using Entry = std::pair<uint64_t, glm::dvec3>;

// Keeps `heap` (a max-heap on the hash) at the `wanted` smallest entries, copies of a position
// counted each time (finish() keeps one): the same entries whatever the order they come in, as
// copies share a hash and only equal hashes can tie.
void offer(std::vector<Entry>& heap, size_t wanted, uint64_t h, const glm::dvec3& p) {
  auto less = [](const Entry& a, const Entry& b) { return a.first < b.first; };
  if (heap.size() == wanted && !(h < heap.front().first)) return;
  if (heap.size() == wanted) {
    std::pop_heap(heap.begin(), heap.end(), less);
    heap.pop_back();
  }
  heap.push_back({h, p});
  std::push_heap(heap.begin(), heap.end(), less);
}

}  // namespace

void SpacingSampler::add(std::span<const glm::dvec3> points) {
  if (wanted_ == 0) return;
  // Blocks in parallel, each worker keeping the smallest of all its blocks, then those offered
  // here: the same entries as one pass over the points. A worker's heap, not a block's: a heap
  // started afresh for each block of 65,536 points took in thousands of entries each (most of the
  // pass's time), one kept over a worker's blocks a few thousand in all.
  constexpr size_t kBlock = size_t{1} << 16;
  const size_t blocks = (points.size() + kBlock - 1) / kBlock;
  const unsigned threads = parallelWorkers(blocks, threads_);
  std::vector<std::vector<Entry>> kept(threads);
  // Once `wanted` are kept, a hash not below the largest of them can never be kept (offer's own
  // test, made here before the call): most points of a large set end at this one comparison.
  const uint64_t none = heap_.size() == wanted_ ? heap_.front().first : UINT64_MAX;
  parallelFor(blocks, threads, [&](size_t b, unsigned worker) {
    std::vector<Entry>& heap = kept[worker];
    uint64_t limit = heap.size() == wanted_ ? std::min(none, heap.front().first) : none;
    for (size_t i = b * kBlock, end = std::min(points.size(), i + kBlock); i < end; ++i) {
      const uint64_t h = positionHash(points[i]);
      if (h >= limit && limit != UINT64_MAX) continue;
      offer(heap, wanted_, h, points[i]);
      if (heap.size() == wanted_) limit = std::min(none, heap.front().first);
    }
  });
  for (const std::vector<Entry>& worker : kept)
    for (const Entry& e : worker) offer(heap_, wanted_, e.first, e.second);
}

PositionArray SpacingSampler::finish() const {
  std::vector<std::pair<uint64_t, glm::dvec3>> sorted = heap_;
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  PositionArray out;
  for (size_t k = 0; k < sorted.size(); ++k)
    if (k == 0 || sorted[k].first != sorted[k - 1].first || sorted[k].second != sorted[k - 1].second)
      out.push_back(sorted[k].second);
  return out;
}

SpacingSearch::SpacingSearch(const Box& box, uint64_t count, PositionArray samples, unsigned threads)
    : samples_(std::move(samples)), threads_(resolveThreads(threads)), origin_(box.min) {
  // Volumes and squared distances in units of about the box (lengthUnit).
  unit_ = lengthUnit(std::max({box.max.x - box.min.x, box.max.y - box.min.y, box.max.z - box.min.z}));
  const glm::dvec3 extent = (box.max - box.min) * unit_;
  const double largest = std::max({extent.x, extent.y, extent.z});
  const double n = double(std::max<uint64_t>(count, 1));
  const double volume = extent.x * extent.y * extent.z;
  const double face = std::max({extent.x * extent.y, extent.y * extent.z, extent.x * extent.z});
  cell_ = 2.0 * std::max({std::cbrt(volume / n), std::sqrt(face / n), largest / double(kMaxCell)}) / unit_;
  if (!(cell_ > 0.0) || !std::isfinite(cell_)) samples_.clear();  // all points equal, or not finite
  inverse_cell_ = 1.0 / cell_;

  // The 27 cells around each sample, each listing the samples it is next to.
  size_t capacity = 16;
  while (capacity < 2 * 27 * samples_.size()) capacity *= 2;
  keys_.assign(capacity, 0);
  slots_.assign(capacity, 0);
  std::vector<std::pair<uint32_t, uint32_t>> pairs;  // (slot, sample)
  uint32_t slot_count = 0;
  for (uint32_t s = 0; s < samples_.size(); ++s) {
    glm::i64vec3 c;
    for (int k = 0; k < 3; ++k)
      c[k] = std::clamp<int64_t>(static_cast<int64_t>((samples_[s][k] - origin_[k]) * inverse_cell_), 0, kMaxCell);
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const glm::i64vec3 q = c + glm::i64vec3(dx, dy, dz);
          if (glm::any(glm::lessThan(q, glm::i64vec3(0))) || glm::any(glm::greaterThan(q, glm::i64vec3(kMaxCell))))
            continue;
          const uint64_t key = uint64_t(q.x) | uint64_t(q.y) << kCellBits | uint64_t(q.z) << (2 * kCellBits);
          size_t at = tableIndex(key, capacity);
          while (keys_[at] != 0 && keys_[at] != key + 1) at = (at + 1) & (capacity - 1);
          if (keys_[at] == 0) keys_[at] = key + 1, slots_[at] = slot_count++;
          const uint64_t bit = (splitmixMix(key) >> 40) & (kFilterBits - 1);
          filter_[bit >> 6] |= uint64_t{1} << (bit & 63);
          pairs.push_back({slots_[at], s});
        }
    sample_cells_.push_back(c);
  }
  std::sort(sample_cells_.begin(), sample_cells_.end(), [](const glm::i64vec3& a, const glm::i64vec3& b) { return a.x < b.x; });
  slot_start_.assign(size_t{slot_count} + 1, 0);
  for (const auto& [slot, s] : pairs) ++slot_start_[slot + 1];
  for (size_t k = 1; k < slot_start_.size(); ++k) slot_start_[k] += slot_start_[k - 1];
  slot_samples_.resize(pairs.size());
  std::vector<uint32_t> fill(slot_start_.begin(), slot_start_.end() - 1);
  for (const auto& [slot, s] : pairs) slot_samples_[fill[slot]++] = s;
  best_.assign(1, emptyBest());  // one list for finish() where add() sees no points; add() adds a worker's
}

std::vector<SpacingSearch::Best> SpacingSearch::emptyBest() const {
  Best none;
  none.fill(kInf);
  return std::vector<Best>(samples_.size(), none);
}

uint64_t SpacingSearch::cellKey(const glm::dvec3& p) const {
  uint64_t key = 0;
  for (int k = 0; k < 3; ++k) {
    const double c = (p[k] - origin_[k]) * inverse_cell_;
    if (!(c >= 0.0) || c > double(kMaxCell)) return UINT64_MAX;  // outside the box (or NaN): no sample's cell
    key |= uint64_t(static_cast<int64_t>(c)) << (k * kCellBits);  // the signed conversion is one instruction
  }
  return key;
}

uint32_t SpacingSearch::findSlot(uint64_t key) const {
  if (key == UINT64_MAX) return UINT32_MAX;
  const uint64_t bit = (splitmixMix(key) >> 40) & (kFilterBits - 1);
  if (!(filter_[bit >> 6] >> (bit & 63) & 1)) return UINT32_MAX;  // most points: no kept cell, one L2 read
  for (size_t at = tableIndex(key, keys_.size());; at = (at + 1) & (keys_.size() - 1)) {
    if (keys_[at] == key + 1) return slots_[at];
    if (keys_[at] == 0) return UINT32_MAX;
  }
}

bool SpacingSearch::mayUse(const Box& box) const {
  if (samples_.empty()) return false;
  // The cells the box spans, as cellKey finds them (monotonic in each coordinate); beyond the grid
  // a point has no cell.
  glm::i64vec3 lo, hi;
  for (int k = 0; k < 3; ++k) {
    const double a = (box.min[k] - origin_[k]) * inverse_cell_, b = (box.max[k] - origin_[k]) * inverse_cell_;
    if (!(b >= 0.0) || !(a <= double(kMaxCell))) return false;
    lo[k] = static_cast<int64_t>(std::max(a, 0.0));
    hi[k] = static_cast<int64_t>(std::min(b, double(kMaxCell)));
  }
  // A kept cell is one of the 3³ around a sample's: the box needs its points where its cells
  // reach within one cell of a sample's (sample_cells_, by x).
  auto at = std::lower_bound(sample_cells_.begin(), sample_cells_.end(), lo.x - 1,
                             [](const glm::i64vec3& c, int64_t x) { return c.x < x; });
  for (; at != sample_cells_.end() && at->x <= hi.x + 1; ++at)
    if (at->y >= lo.y - 1 && at->y <= hi.y + 1 && at->z >= lo.z - 1 && at->z <= hi.z + 1) return true;
  return false;
}

void SpacingSearch::add(std::span<const glm::dvec3> points) {
  if (samples_.empty()) return;
  constexpr size_t kBlock = size_t{1} << 16;
  const size_t blocks = (points.size() + kBlock - 1) / kBlock;
  // A list for each worker that runs, not each thread asked for (--threads 1000000 on 2050 points
  // made 16 GB of them).
  const unsigned workers = parallelWorkers(blocks, threads_);
  while (best_.size() < workers) best_.push_back(emptyBest());
  parallelFor(blocks, workers, [&](size_t b, unsigned worker) {
    std::vector<Best>& best = best_[worker];
    for (size_t i = b * kBlock, end = std::min(points.size(), i + kBlock); i < end; ++i) {
      const uint32_t slot = findSlot(cellKey(points[i]));
      if (slot == UINT32_MAX) continue;
      for (uint32_t k = slot_start_[slot]; k < slot_start_[slot + 1]; ++k) {
        const uint32_t s = slot_samples_[k];
        const glm::dvec3 d = (points[i] - samples_[s]) * unit_;
        const double d2 = d.x * d.x + d.y * d.y + d.z * d.z;
        Best& b2 = best[s];
        if (!(d2 > 0.0) || d2 >= b2.back()) continue;
        size_t at = kSpacingNeighbors - 1;
        for (; at > 0 && b2[at - 1] > d2; --at) b2[at] = b2[at - 1];
        b2[at] = d2;
      }
    }
  });
}

std::vector<SpacingSample> SpacingSearch::finish() const {
  std::vector<SpacingSample> out;
  for (size_t s = 0; s < samples_.size(); ++s) {
    // Each point was seen by one worker: the smallest of the workers' lists together.
    std::vector<double> all;
    for (const std::vector<Best>& worker : best_) all.insert(all.end(), worker[s].begin(), worker[s].end());
    std::nth_element(all.begin(), all.begin() + (kSpacingNeighbors - 1), all.end());
    const double distance = std::sqrt(all[kSpacingNeighbors - 1]) / unit_;
    if (distance <= cell_) out.push_back({samples_[s], distance});
  }
  if (2 * out.size() < samples_.size()) out.clear();
  return out;
}

double lengthUnit(double extent, double largest_coordinate) {
  if (!(extent > 0.0) || !std::isfinite(extent)) return 1.0;
  int exponent = std::clamp(-std::ilogb(extent), -1000, 1000);
  if (largest_coordinate > 0.0 && std::isfinite(largest_coordinate))
    exponent = std::min(exponent, 1000 - std::ilogb(largest_coordinate));
  return std::ldexp(1.0, exponent);
}

std::vector<SpacingSample> sampleSpacing(const PositionArray& positions, const Box& box, size_t samples,
                                         unsigned threads) {
  if (positions.size() < 2 || samples == 0) return {};
  SpacingSampler sampler(samples, threads);
  sampler.add(positions);
  SpacingSearch search(box, positions.size(), sampler.finish(), threads);
  search.add(positions);
  return search.finish();
}

}  // namespace dpoint
