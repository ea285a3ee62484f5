// Morton order in shuffled blocks, after Schütz, Kerbl, Wimmer, "Rendering Point Clouds with
// Compute Shaders and Vertex Order Optimization" (EGSR 2021), §5.
//
// Why Morton: the compute backend runs one thread per point, and a workgroup's atomics into the
// visibility buffer are cheap when its points land on few cache lines. Points sorted along a
// Morton curve are close in space when close in memory, so each workgroup (and each kOrderBlock
// batch of the `batch` mode) covers a small part of the screen.
// Why shuffled blocks: in pure Morton order, the workgroups running at the same time all draw the
// same small region and queue on the same pixels' atomics. The paper shuffles batches: each
// block stays compact, while the blocks in flight together are spread over the whole set.
//
// The sort: each point's 63-bit code is computed once, then an out-of-place MSD radix sort of
// (code, index) runs over only the bits in which the codes differ, with 11-bit digits at the top
// (parallel over contiguous chunks for large ranges) and narrower ones as ranges shrink, so all
// levels below the first run in cache; ranges of 32 or fewer are insertion-sorted. Every pass is
// a stable counting sort, so the result is the one stable order of the codes, whatever the
// threads and chunks were. The gather then moves positions, colours and triangle indices once;
// mortonRows moves nothing and hands the order back as rows instead, for points made on demand.
#include "ops/point_order.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <new>
#include <random>
#include <type_traits>

#include "core/memory.h"
#include "core/parallel.h"
#include "core/progress.h"

namespace dpoint {
namespace {

constexpr unsigned kAxisBits = 21;
constexpr uint32_t kAxisMax = (1u << kAxisBits) - 1;
// std::mt19937_64's own default seed: fixed, so every run lays the blocks out the same way.
constexpr uint64_t kShuffleSeed = 5489;
constexpr size_t kChunk = size_t{1} << 16;        // points per work item of the linear passes
constexpr size_t kParallelMin = size_t{1} << 20;  // ranges this long are sorted over all threads
constexpr size_t kInsertionMax = 32;
constexpr unsigned kMaxDigitBits = 11;  // 2048 buckets: one pass's write streams stay in L1/L2

// One coordinate → 0 .. 2^21 - 1. d = v/2 - min/2 is monotone in v (each rounding is), and for
// v = max it is the very expression that gave half_extent, so t = d / half_extent lies in
// [0, 1] for every finite v in the box with t = 1 exactly at the maximum. t < 1 scaled by 2^21
// (exact) is below 2^21. The comparisons send NaN and -inf to 0 and +inf to the top.
inline uint32_t quantize(double v, double half_min, double half_extent) {
  if (!(half_extent > 0.0)) return 0;
  const double t = (v * 0.5 - half_min) / half_extent;
  if (t >= 1.0) return kAxisMax;
  if (!(t > 0.0)) return 0;
  return static_cast<uint32_t>(t * 0x1p21);
}

// Bit k of the low 21 bits → bit 3k.
inline uint64_t spreadBits(uint32_t v) {
  uint64_t x = v & kAxisMax;
  x = (x | x << 32) & 0x001f00000000ffffull;
  x = (x | x << 16) & 0x001f0000ff0000ffull;
  x = (x | x << 8) & 0x100f00f00f00f00full;
  x = (x | x << 4) & 0x10c30c30c30c30c3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

}  // namespace

uint64_t mortonInterleave(uint32_t x, uint32_t y, uint32_t z) {
  return spreadBits(x) | spreadBits(y) << 1 | spreadBits(z) << 2;
}

namespace {

inline uint64_t codeOf(const MortonFrame& f, const glm::dvec3& p) {
  return mortonInterleave(quantize(p.x, f.half_min.x, f.half_extent.x), quantize(p.y, f.half_min.y, f.half_extent.y),
                          quantize(p.z, f.half_min.z, f.half_extent.z));
}

// Bit k of the low 21 bits → bit 2k.
inline uint64_t spreadBits2(uint32_t v) {
  uint64_t x = v & kAxisMax;
  x = (x | x << 16) & 0x0000ffff0000ffffull;
  x = (x | x << 8) & 0x00ff00ff00ff00ffull;
  x = (x | x << 4) & 0x0f0f0f0f0f0f0f0full;
  x = (x | x << 2) & 0x3333333333333333ull;
  x = (x | x << 1) & 0x5555555555555555ull;
  return x;
}

// The key the sort uses: the Morton code without the bits of flat axes (no extent: every point's
// coordinate there quantizes to 0). Those bits are 0 in every code, so dropping them keeps every
// comparison and the order is the same; but a 2D set's codes then vary in every bit, so each
// radix digit splits the points 2^width ways instead of a third of the digit being constant (at
// 1e9 points the top level's ranges had all stayed above kParallelMin and were sorted one at a
// time: 5.5 of the H200's 11 s).
class SortCode {
 public:
  explicit SortCode(const MortonFrame& f) : frame_(f) {
    for (int a = 0; a < 3; ++a)
      if (f.half_extent[a] > 0.0) axes_[live_++] = a;
  }
  uint64_t operator()(const glm::dvec3& p) const {
    switch (live_) {
      case 3: return codeOf(frame_, p);
      case 2: return spreadBits2(axis(p, 0)) | spreadBits2(axis(p, 1)) << 1;
      case 1: return axis(p, 0);
      default: return 0;
    }
  }

 private:
  uint32_t axis(const glm::dvec3& p, int i) const {
    const int a = axes_[i];
    return quantize(p[a], frame_.half_min[a], frame_.half_extent[a]);
  }
  MortonFrame frame_;
  int axes_[3] = {0, 0, 0};
  int live_ = 0;
};

// Uniform in [0, bound) by rejection, so the shuffle is the same on every standard library.
uint64_t uniformBelow(std::mt19937_64& rng, uint64_t bound) {
  const uint64_t max = std::numeric_limits<uint64_t>::max();
  // 2^64 mod bound values are left over; taking r only up to this gives each residue equally often.
  const uint64_t limit = max - (max % bound + 1) % bound;
  uint64_t r = rng();
  while (r > limit) r = rng();
  return r % bound;
}

// The sort's arrays live in uninitialized LargeBuffers (core/memory.h: 2 MiB pages where Linux
// gives them): the scatter and the gathers jump all over them, and with 4 KiB pages their TLB
// misses and page faults took 15% of the time at 16.7M points. The passes that first write them
// fault their pages in, over all threads. The scratch: reorderPoints' keys take the first 20 bytes
// a point (code[0] at 0, code[1] at 8n, index[0] at 16n); once sorted, the first 24 take one
// gathered array at a time (the positions, then the colours, then the triangles' renumbering), so
// a fresh allocation, its page faults and std::vector's single-threaded zeroing are paid once, not
// three times. The sorted indices (index[1]) lie in a buffer of their own, which MortonRows keeps.
//
// arrayIn starts the lifetime of `count` objects of type T at byte `offset` of `buffer` and
// returns the first. For the trivial types used here this generates no code.
template <typename T>
T* arrayIn(LargeBuffer& buffer, size_t offset, size_t count) {
  static_assert(std::is_trivially_destructible_v<T>);
  assert(offset % alignof(T) == 0 && offset + count * sizeof(T) <= buffer.size());
  std::uninitialized_default_construct_n(reinterpret_cast<T*>(buffer.data() + offset), count);
  return std::launder(reinterpret_cast<T*>(buffer.data() + offset));
}

struct SortKeys {
  uint64_t* code[2];
  uint32_t* index[2];
};
constexpr int kSorted = 1;

void finishRange(SortKeys& k, size_t first, size_t last, int src) {
  if (src != kSorted) std::copy(k.index[src] + first, k.index[src] + last, k.index[kSorted] + first);
}

// Bits in which the codes of [first, last) differ.
uint64_t varyingBits(const uint64_t* code, size_t first, size_t last) {
  uint64_t all_and = ~uint64_t{0}, any_or = 0;
  for (size_t i = first; i < last; ++i) {
    all_and &= code[i];
    any_or |= code[i];
  }
  return all_and ^ any_or;
}

// Stable counting sort of [first, last) from copy src into copy 1 - src by the digit
// (code >> shift) & (2^width - 1), over contiguous chunks (which chunks does not change the
// result). Returns the 2^width bucket starts and the end.
std::vector<size_t> scatterByDigit(SortKeys& k, int src, size_t first, size_t last, unsigned shift, unsigned width,
                                   unsigned threads) {
  const size_t buckets = size_t{1} << width;
  const uint64_t mask = buckets - 1;
  const size_t n = last - first;
  const size_t chunks = threads <= 1 ? 1 : std::min<size_t>((n + kChunk - 1) / kChunk, size_t{4} * threads);
  auto chunkBegin = [&](size_t c) { return first + n * c / chunks; };
  const uint64_t* code = k.code[src];
  const uint32_t* index = k.index[src];
  uint64_t* code_out = k.code[1 - src];
  uint32_t* index_out = k.index[1 - src];

  std::vector<size_t> offsets(chunks * buckets, 0);
  parallelFor(chunks, threads, [&](size_t c, unsigned) {
    size_t* count = &offsets[c * buckets];
    for (size_t i = chunkBegin(c), end = chunkBegin(c + 1); i < end; ++i) ++count[(code[i] >> shift) & mask];
  });
  std::vector<size_t> starts(buckets + 1);
  size_t at = first;
  for (size_t b = 0; b < buckets; ++b) {
    starts[b] = at;
    for (size_t c = 0; c < chunks; ++c) {
      size_t& offset = offsets[c * buckets + b];
      const size_t count = offset;
      offset = at;
      at += count;
    }
  }
  starts[buckets] = at;
  parallelFor(chunks, threads, [&](size_t c, unsigned) {
    size_t* next = &offsets[c * buckets];
    for (size_t i = chunkBegin(c), end = chunkBegin(c + 1); i < end; ++i) {
      const size_t to = next[(code[i] >> shift) & mask]++;
      code_out[to] = code[i];
      index_out[to] = index[i];
    }
  });
  return starts;
}

// Sorts [first, last) of copy src (stable, by code) into index[kSorted]; `varying` is
// varyingBits of the range. threads > 1 only for ranges of kParallelMin or more. progress, when
// given, advances by the points of each finished part.
void sortRange(SortKeys& k, size_t first, size_t last, int src, uint64_t varying, unsigned threads,
               Progress* progress) {
  const size_t n = last - first;
  if (varying == 0 || n <= kInsertionMax) {
    uint64_t* code = k.code[src];
    uint32_t* index = k.index[src];
    for (size_t i = first + 1; i < last && varying != 0; ++i) {
      const uint64_t c = code[i];
      const uint32_t x = index[i];
      size_t j = i;
      for (; j > first && code[j - 1] > c; --j) {
        code[j] = code[j - 1];
        index[j] = index[j - 1];
      }
      code[j] = c;
      index[j] = x;
    }
    finishRange(k, first, last, src);
    if (progress) progress->advance(n);
    return;
  }
  // Every difference lies in bits [0, top); the digit is the highest `width` of them, fewer
  // for short ranges so that the histogram stays smaller than the range.
  const unsigned top = static_cast<unsigned>(std::bit_width(varying));
  const unsigned width = std::min({top, kMaxDigitBits, static_cast<unsigned>(std::bit_width(n)) - 2});
  const unsigned shift = top - width;
  const std::vector<size_t> starts = scatterByDigit(k, src, first, last, shift, width, threads);
  const int dst = 1 - src;
  const uint64_t* code = k.code[dst];
  if (threads <= 1) {
    for (size_t b = 0; b + 1 < starts.size(); ++b) {
      if (starts[b] == starts[b + 1]) continue;
      sortRange(k, starts[b], starts[b + 1], dst, varyingBits(code, starts[b], starts[b + 1]), 1, nullptr);
      if (progress) progress->advance(starts[b + 1] - starts[b]);
    }
    return;
  }
  std::vector<size_t> small;
  for (size_t b = 0; b + 1 < starts.size(); ++b) {
    const size_t begin = starts[b], end = starts[b + 1];
    if (begin == end) continue;
    if (end - begin >= kParallelMin) {
      // Rare (a cluster much denser than the rest): one range at a time, each over all threads.
      sortRange(k, begin, end, dst, varyingBits(code, begin, end), threads, progress);
    } else {
      small.push_back(b);
    }
  }
  parallelFor(small.size(), threads, [&](size_t i, unsigned) {
    const size_t begin = starts[small[i]], end = starts[small[i] + 1];
    sortRange(k, begin, end, dst, varyingBits(code, begin, end), 1, nullptr);
    if (progress) progress->advance(end - begin);
  });
}

// values[i] becomes values[source of i]: gathered into the scratch, then copied back (both over
// all threads), so the set keeps its own storage.
template <typename T>
void gather(T* values, size_t n, const uint32_t* sorted, const std::vector<uint32_t>& blocks, LargeBuffer& scratch,
            unsigned threads, Progress* progress) {
  const size_t block_count = (n + kOrderBlock - 1) / kOrderBlock;
  T* out = arrayIn<T>(scratch, 0, n);
  parallelFor(block_count, threads, [&](size_t b, unsigned) {
    const size_t to = b * kOrderBlock, from = mortonSourceBlock(blocks, b) * kOrderBlock;
    const size_t count = std::min(kOrderBlock, n - to);
    // The reads jump over the whole set: each misses the caches, so the loads of a few dozen
    // points ahead are started early, keeping more misses in flight than the core would alone.
    constexpr size_t kAhead = 32;
    for (size_t i = 0; i < count; ++i) {
      if (i + kAhead < count) __builtin_prefetch(&values[sorted[from + i + kAhead]]);
      out[to + i] = values[sorted[from + i]];
    }
    if (progress) progress->advance(count);
  });
  parallelFor(block_count, threads, [&](size_t b, unsigned) {
    const size_t first = b * kOrderBlock;
    std::copy(out + first, out + first + std::min(kOrderBlock, n - first), values + first);
  });
}

template <typename T, typename Allocator>
void gather(std::vector<T, Allocator>& values, const uint32_t* sorted, const std::vector<uint32_t>& blocks, LargeBuffer& scratch,
            unsigned threads, Progress* progress) {
  gather(values.data(), values.size(), sorted, blocks, scratch, threads, progress);
}

// A dimension's column, moved as values of its width (core/dimensions.h).
void gatherDimension(Dimension& d, const uint32_t* sorted, const std::vector<uint32_t>& blocks, LargeBuffer& scratch,
                     unsigned threads) {
  const size_t n = d.size();
  switch (dimTypeSize(d.type)) {
    case 1: gather(reinterpret_cast<uint8_t*>(d.bytes.data()), n, sorted, blocks, scratch, threads, nullptr); break;
    case 2: gather(reinterpret_cast<uint16_t*>(d.bytes.data()), n, sorted, blocks, scratch, threads, nullptr); break;
    case 4: gather(reinterpret_cast<uint32_t*>(d.bytes.data()), n, sorted, blocks, scratch, threads, nullptr); break;
    default: gather(reinterpret_cast<uint64_t*>(d.bytes.data()), n, sorted, blocks, scratch, threads, nullptr); break;
  }
}

// The points' positions a chunk at a time: the set's own (HeldPositions), or made by a function of
// the index into a buffer of the calling thread's (MadePositionsAt). chunk(begin, end) returns
// positions [begin, end), valid until the thread's next call.
struct HeldPositions {
  const glm::dvec3* data;
  const glm::dvec3* chunk(size_t begin, size_t) const { return data + begin; }
};
struct MadePositionsAt {
  const std::function<glm::dvec3(uint64_t)>& at;
  const glm::dvec3* chunk(size_t begin, size_t end) const {
    thread_local PositionArray buffer;
    buffer.resize(end - begin);
    for (size_t i = begin; i < end; ++i) buffer[i - begin] = at(i);
    return buffer.data();
  }
};

template <typename Positions>
MortonFrame frameOf(size_t n, const Positions& positions, unsigned threads) {
  const double inf = std::numeric_limits<double>::infinity();
  const size_t chunks = (n + kChunk - 1) / kChunk;
  PositionArray lo(chunks, glm::dvec3(inf)), hi(chunks, glm::dvec3(-inf));
  parallelFor(chunks, threads, [&](size_t c, unsigned) {
    glm::dvec3 chunk_lo(inf), chunk_hi(-inf);  // locals: neighbouring chunks' entries share cache lines
    const size_t begin = c * kChunk, end = std::min(n, begin + kChunk);
    const glm::dvec3* p = positions.chunk(begin, end);
    for (size_t i = 0; i < end - begin; ++i) {
      for (int a = 0; a < 3; ++a) {
        const double v = p[i][a];
        if (!std::isfinite(v)) continue;
        chunk_lo[a] = std::min(chunk_lo[a], v);
        chunk_hi[a] = std::max(chunk_hi[a], v);
      }
    }
    lo[c] = chunk_lo;
    hi[c] = chunk_hi;
  });
  glm::dvec3 min(inf), max(-inf);
  for (size_t c = 0; c < chunks; ++c) {
    for (int a = 0; a < 3; ++a) {
      min[a] = std::min(min[a], lo[c][a]);
      max[a] = std::max(max[a], hi[c][a]);
    }
  }
  // Halves, so that max - min cannot overflow (1e308 - -1e308); halving is exact above 2^-1021,
  // and below it the last bit of a subnormal coordinate is lost to the order, nothing else.
  MortonFrame frame;
  for (int a = 0; a < 3; ++a) {
    if (!(min[a] <= max[a])) continue;  // no finite coordinate on this axis
    frame.half_min[a] = min[a] * 0.5;
    frame.half_extent[a] = max[a] * 0.5 - frame.half_min[a];
  }
  return frame;
}

// The indices of the n points in the stable order of their Morton codes, into `sorted`; the
// codes and the first copy of the indices take the first 20 bytes a point of `scratch`.
// progress advances by 2n.
template <typename Positions>
void sortByCode(size_t n, const Positions& positions, LargeBuffer& scratch, uint32_t* sorted, unsigned threads,
                Progress* progress) {
  const MortonFrame frame = frameOf(n, positions, threads);
  const SortCode sort_code(frame);
  SortKeys k;
  k.code[0] = arrayIn<uint64_t>(scratch, 0, n);
  k.code[1] = arrayIn<uint64_t>(scratch, 8 * n, n);
  k.index[0] = arrayIn<uint32_t>(scratch, 16 * n, n);
  k.index[kSorted] = sorted;
  const size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<uint64_t> chunk_and(chunks), chunk_or(chunks);
  parallelFor(chunks, threads, [&](size_t c, unsigned) {
    uint64_t all_and = ~uint64_t{0}, any_or = 0;
    const size_t begin = c * kChunk, end = std::min(n, begin + kChunk);
    const glm::dvec3* p = positions.chunk(begin, end);
    for (size_t i = begin; i < end; ++i) {
      const uint64_t v = sort_code(p[i - begin]);
      k.code[0][i] = v;
      k.index[0][i] = static_cast<uint32_t>(i);
      all_and &= v;
      any_or |= v;
    }
    chunk_and[c] = all_and;
    chunk_or[c] = any_or;
    if (progress) progress->advance(end - c * kChunk);
  });
  uint64_t all_and = ~uint64_t{0}, any_or = 0;
  for (size_t c = 0; c < chunks; ++c) {
    all_and &= chunk_and[c];
    any_or |= chunk_or[c];
  }
  sortRange(k, 0, n, 0, all_and ^ any_or, threads, progress);
}

}  // namespace

Result<PointOrder> parsePointOrder(const std::string& flag, const std::string& text) {
  if (text == "input") return PointOrder::kInput;
  if (text == "morton") return PointOrder::kMorton;
  return Error{flag + " " + text + ": must be input or morton", ExitCode::kUsage};
}

const char* pointOrderName(PointOrder order) { return order == PointOrder::kMorton ? "morton" : "input"; }

uint64_t reorderExtraBytes(size_t points, PointOrder order) {
  return order == PointOrder::kMorton ? uint64_t{28} * points : 0;
}

Status checkOrderable(uint64_t points) {
  if (points <= std::numeric_limits<uint32_t>::max()) return okStatus();
  return Error{"ordering " + std::to_string(points) + " points: an order holds at most 4294967295 (2^32 - 1); "
               "write them in input order, or in tiles",
               ExitCode::kResourceLimit};
}

Status checkReorderMemory(const PointSet& points, PointOrder order, uint64_t limit) {
  if (order == PointOrder::kInput) return okStatus();
  if (Status s = checkOrderable(points.size()); !s) return s;
  const uint64_t needed = points.size() * (sizeof(glm::dvec3) + (points.hasColors() ? sizeof(glm::vec3) : 0) +
                                           points.dimensions.bytesPerPoint()) +
                          points.triangles.size() * 4 + reorderExtraBytes(points.size(), order);
  return checkMemory("ordering " + std::to_string(points.size()) + " points", needed, limit);
}

MortonFrame mortonFrame(const PositionArray& positions, unsigned threads) {
  return frameOf(positions.size(), HeldPositions{positions.data()}, threads);
}

uint64_t mortonCode(const MortonFrame& frame, const glm::dvec3& p) { return codeOf(frame, p); }

std::vector<uint32_t> shuffledBlocks(size_t count) {
  assert(count <= std::numeric_limits<uint32_t>::max());
  std::vector<uint32_t> order(count);
  std::iota(order.begin(), order.end(), uint32_t{0});
  std::mt19937_64 rng(kShuffleSeed);
  for (size_t i = count; i > 1; --i) std::swap(order[i - 1], order[uniformBelow(rng, i)]);
  return order;
}

void reorderPoints(PointSet& points, PointOrder order, unsigned threads, Progress* progress) {
  const size_t n = points.size();
  if (order == PointOrder::kInput || n < 2) return;
  assert(n <= std::numeric_limits<uint32_t>::max());
  assert(points.colors.empty() || points.colors.size() == n);
  threads = resolveThreads(threads);
  if (progress) progress->start("morton order", 3 * uint64_t{n});

  LargeBuffer scratch(24 * n);
  LargeBuffer sorted_buffer(4 * n);
  uint32_t* sorted = arrayIn<uint32_t>(sorted_buffer, 0, n);
  sortByCode(n, HeldPositions{points.positions.data()}, scratch, sorted, threads, progress);

  const std::vector<uint32_t> blocks = shuffledBlocks(n / kOrderBlock);
  gather(points.positions, sorted, blocks, scratch, threads, progress);
  if (points.hasColors()) gather(points.colors, sorted, blocks, scratch, threads, nullptr);
  for (Dimension& d : points.dimensions.all()) gatherDimension(d, sorted, blocks, scratch, threads);
  if (points.isMesh()) {
    uint32_t* rank = arrayIn<uint32_t>(scratch, 0, n);  // new place of each old point
    parallelFor((n + kOrderBlock - 1) / kOrderBlock, threads, [&](size_t b, unsigned) {
      const size_t to = b * kOrderBlock, from = mortonSourceBlock(blocks, b) * kOrderBlock;
      for (size_t i = 0, count = std::min(kOrderBlock, n - to); i < count; ++i)
        rank[sorted[from + i]] = static_cast<uint32_t>(to + i);
    });
    std::vector<uint32_t>& triangles = points.triangles;
    parallelFor((triangles.size() + kChunk - 1) / kChunk, threads, [&](size_t c, unsigned) {
      for (size_t i = c * kChunk, end = std::min(triangles.size(), i + kChunk); i < end; ++i) {
        assert(triangles[i] < n);
        triangles[i] = rank[triangles[i]];
      }
    });
  }
  if (progress) progress->finish();
}

MortonRows mortonRows(size_t n, const std::function<glm::dvec3(uint64_t)>& at, unsigned threads, Progress* progress) {
  assert(n <= std::numeric_limits<uint32_t>::max());
  threads = resolveThreads(threads);
  if (progress) progress->start("morton order", 2 * uint64_t{n});
  MortonRows rows;
  rows.n_ = n;
  rows.buffer_ = LargeBuffer(4 * n);
  uint32_t* sorted = arrayIn<uint32_t>(rows.buffer_, 0, n);
  rows.sorted_ = sorted;
  if (n == 1) sorted[0] = 0;
  if (n >= 2) {
    LargeBuffer scratch(20 * n);
    sortByCode(n, MadePositionsAt{at}, scratch, sorted, threads, progress);
  }
  rows.blocks_ = shuffledBlocks(n / kOrderBlock);
  if (progress) progress->finish();
  return rows;
}

}  // namespace dpoint
