#include "generators/escape_grid.h"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <charconv>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <future>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "core/atomic_file.h"
#include "core/bytes.h"
#include "core/interrupt.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "generators/marching_cubes.h"

namespace dpoint {
namespace {

constexpr double kDefaultLevel = -1.0;
// High bit of a stored count: the count is final (finished past the classification cap).
constexpr uint32_t kExactBit = 0x80000000u;
// Per worker: two planes of counts (4 B) and of above-level flags (1 B, here and in marching
// cubes), one of flags for the counts to finish (1 B), and the vertex ids of marching cubes (two
// planes of y and z edges and one of x edges, 4 B each).
constexpr uint64_t kWorkerBytesPerPoint = 2 * 4 + 2 * 2 + 1 + 5 * 4;
constexpr uint64_t kMeshBytesPerVertex = sizeof(glm::dvec3) + 2 * 3 * sizeof(uint32_t);  // ~2 triangles/vertex

std::string text(double v) {
  char buffer[32];
  const std::to_chars_result r = std::to_chars(buffer, buffer + sizeof buffer, v);  // shortest round trip
  return std::string(buffer, r.ptr);
}

uint64_t squared(int res) { return static_cast<uint64_t>(res) * static_cast<uint64_t>(res); }

double estimatedVertices(int res) { return 0.5 * std::pow(static_cast<double>(res), 2.5); }

// Slabs of `thickness` cell layers; about six per thread so the dynamic hand-out balances the
// heavy middle slabs, at most 32 layers (max_thickness) so a slab's mesh and grid stay small, at
// least 4 so the plane both neighbours compute costs at most a quarter more.
constexpr int kMaxSlabThickness = 32;
struct SlabPlan {
  int thickness;
  int count;
};
SlabPlan planSlabs(int layers, unsigned threads, int max_thickness) {
  const int wanted = static_cast<int>(std::min<unsigned>(threads, 1024)) * 6;
  const int thickness = std::clamp((layers + wanted - 1) / wanted, 4, std::max(4, max_thickness));
  return {thickness, (layers + thickness - 1) / thickness};
}

// With a plane function (a GPU), a slab's planes are computed as one block and held until the slab
// is meshed; a block of about 32 Mi counts (32 MiB at the usual one byte a count) keeps the few in
// flight small and the dispatches large. Each block recomputes the plane it shares with the next:
// at res 2048 (4 Mi counts a plane) 8-plane blocks repeat 1 plane in 8, where blocks of 4 layers
// (the least) repeated 1 in 5.
constexpr uint64_t kGpuBlockCounts = uint64_t{32} << 20;
int gpuSlabThickness(int res) {
  const uint64_t planes = kGpuBlockCounts / squared(res);
  return static_cast<int>(std::clamp<uint64_t>(planes, 5, kMaxSlabThickness + 1)) - 1;
}

// Marching cubes elsewhere (a GPU's mesher) counts and meshes a slab where it holds it, with a
// vertex id a grid point on each axis: slabs of about 128 Mi grid points (at res 2048, 31 cell
// layers; 66 slabs where the plane function's 7-layer blocks made 293, each with its own host round
// trips and its first plane counted again), at least 16 of them (the last one's rows are written
// after the device is done), of 4 to 256 layers.
constexpr uint64_t kMeshSlabCounts = uint64_t{128} << 20;
int meshSlabThickness(int res, int layers) {
  const uint64_t budget = kMeshSlabCounts / squared(res);
  const uint64_t share = (static_cast<uint64_t>(layers) + 15) / 16;
  return static_cast<int>(std::clamp<uint64_t>(std::min(budget > 0 ? budget - 1 : 0, share), 4, 256));
}

// The classification pass iterates to the cap: points at the cap are above the level, since
// min(count, cap) > level exactly when count > level. The grid file needs every count.
int classificationLimit(const EscapeSurfaceParams& p) {
  return p.lazy && p.grid_out.empty() ? static_cast<int>(std::floor(p.level)) + 1 : p.max_iter;
}

// Where a surface's mesh is made and held: by the host's workers (their buffers and the plane
// function's blocks too), by a mesher elsewhere into the mesh in memory (those slabs copied in),
// or by a mesher elsewhere as PLY rows written as they come (the face rows held to the end).
enum class MeshPath { kHost, kElsewhere, kRows };

uint64_t estimateLayerMemory(const EscapeSurfaceParams& params, double share, MeshPath path = MeshPath::kHost) {
  const int res = params.axis.resolution;
  const double vertices = share * estimatedVertices(res);
  if (path != MeshPath::kHost) {
    // The slabs' copies in host memory, two of them, a quarter over a slab's share (the mesher's
    // own thickness), then the mesh, or its face rows: 13 bytes a triangle, two a vertex.
    const double slab = static_cast<double>(meshSlabThickness(res, res - 1)) / (res - 1);
    const double copies = 2.0 * 1.25 * slab * estimatedVertices(res) * static_cast<double>(kMeshBytesPerVertex);
    const double held = vertices * (path == MeshPath::kRows ? 2.0 * 13.0 : static_cast<double>(kMeshBytesPerVertex));
    return static_cast<uint64_t>(std::min(copies + held, 1e19));
  }
  const unsigned threads = resolveThreads(params.threads);
  const SlabPlan plan =
      planSlabs(res - 1, threads, params.planes ? gpuSlabThickness(res) : kMaxSlabThickness);
  uint64_t per_worker = kWorkerBytesPerPoint * squared(res);
  if (!params.grid_out.empty())  // a slab's planes wait for their turn to be written; twice for the stragglers
    per_worker += 2 * static_cast<uint64_t>(plan.thickness) * squared(res) *
                  static_cast<uint64_t>(escapeGridBytesPerCount(params.max_iter));
  uint64_t blocks = 0;  // the plane function's blocks in flight, threads + 2 of them
  if (params.planes)
    blocks = (threads + 2) * static_cast<uint64_t>(plan.thickness + 1) * squared(res) *
             static_cast<uint64_t>(escapeGridBytesPerCount(classificationLimit(params)));
  const double mesh = vertices * static_cast<double>(kMeshBytesPerVertex);
  return threads * per_worker + blocks + static_cast<uint64_t>(std::min(mesh, 1e19));
}

// The plane function's blocks, one per slab, computed in slab order on a thread of their own while
// the workers mesh earlier slabs: at most `ahead` blocks are held (computed and not yet released),
// so memory stays a few slabs whatever the grid. Workers take slabs in increasing order
// (parallelFor), so the block a worker waits for is always among the next ones computed.
class PlaneBlocks {
 public:
  // arena: where the blocks go when it offers memory (EscapeArena), else the heap.
  PlaneBlocks(const EscapePlaneFunction& planes, const EscapeArena& arena, std::vector<std::pair<int, int>> slabs,
              int limit, uint64_t plane_bytes, size_t ahead)
      : planes_(planes), slabs_(std::move(slabs)), limit_(limit), plane_bytes_(plane_bytes), ahead_(ahead),
        blocks_(slabs_.size(), nullptr), ready_(slabs_.size(), false) {
    for (const auto& slab : slabs_)
      block_bytes_ = std::max<uint64_t>(block_bytes_, static_cast<uint64_t>(slab.second) * plane_bytes_);
    stride_ = (block_bytes_ + 4095) / 4096 * 4096;  // whole pages: a block's words never share one
    if (arena) arena_ = arena(stride_ * ahead_);
    thread_ = std::thread([this] { produce(); });
  }
  ~PlaneBlocks() { stop(); }

  // The counts of slab s's planes; nullptr when the plane function failed (see error()).
  const uint8_t* wait(size_t s) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return ready_[s] || error_.has_value(); });
    return ready_[s] ? blocks_[s] : nullptr;
  }
  void release(size_t s) {
    std::lock_guard<std::mutex> lock(mutex_);
    spare_.push_back(blocks_[s]);  // reused for a later slab: no allocator churn
    blocks_[s] = nullptr;
    ++released_;
    changed_.notify_all();
  }
  void stop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
      changed_.notify_all();
    }
    if (thread_.joinable()) thread_.join();
  }
  std::optional<Error> error() {
    std::lock_guard<std::mutex> lock(mutex_);
    return error_;
  }

 private:
  void produce() {
    for (size_t s = 0; s < slabs_.size(); ++s) {
      uint8_t* block = nullptr;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [&] { return stopping_ || produced_ - released_ < ahead_; });
        if (stopping_) return;
        // At most `ahead` blocks ever exist: taken from the spares once there are some. (Freeing
        // and allocating 32 MiB blocks on different threads grew the heap to several times that.)
        if (!spare_.empty()) {
          block = spare_.back();
          spare_.pop_back();
        } else if (arena_) {
          block = arena_ + created_++ * stride_;
        } else {  // not zeroed: the plane function writes every count
          owned_.push_back(std::make_unique_for_overwrite<uint8_t[]>(block_bytes_));
          block = owned_.back().get();
        }
      }
      const auto [first, planes] = slabs_[s];
      Status status = planes_(first, planes, limit_, block);
      std::lock_guard<std::mutex> lock(mutex_);
      if (!status) {
        error_ = status.error();
        changed_.notify_all();
        return;
      }
      blocks_[s] = block;
      ready_[s] = true;
      ++produced_;
      changed_.notify_all();
    }
  }

  const EscapePlaneFunction& planes_;
  const std::vector<std::pair<int, int>> slabs_;
  const int limit_;
  const uint64_t plane_bytes_;
  const size_t ahead_;
  uint64_t block_bytes_ = 0, stride_ = 0;  // the largest block, and the arena's step between blocks
  uint8_t* arena_ = nullptr;
  size_t created_ = 0;  // blocks taken from the arena
  std::vector<std::unique_ptr<uint8_t[]>> owned_;  // the heap's blocks
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<uint8_t*> blocks_;
  std::vector<uint8_t*> spare_;  // released blocks, for reuse
  std::vector<bool> ready_;
  size_t produced_ = 0, released_ = 0;
  bool stopping_ = false;
  std::optional<Error> error_;
  std::thread thread_;
};

// Faults in, on a thread of its own, the pages just past the ends of arrays that grow by appends
// under a lock (the escape-grid mesh), so the appends copy into pages that are there: with the
// first touch in the append, the other workers waited for the lock (res-2048 Mandelbulb on 16
// cores: 11 thread-seconds even with 2 MiB pages). At most a sixteenth of the capacity and
// `ahead` bytes past each end, so the memory held stays about the mesh's own. A region whose
// array moved is restarted at its new place; a page faulted in where an array no longer is
// changes no byte, so no lock is held while faulting.
class PrefaultAhead {
 public:
  PrefaultAhead(size_t regions, size_t ahead) : regions_(regions), ahead_(ahead) {
    thread_ = std::thread([this] { run(); });
  }
  ~PrefaultAhead() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }
  // Region r now holds `size` of its `capacity` bytes at `base`.
  void grew(size_t r, void* base, size_t size, size_t capacity) {
    std::lock_guard<std::mutex> lock(mutex_);
    Region& region = regions_[r];
    if (region.base != base) {
      region.base = static_cast<char*>(base);
      region.done = 0;
    }
    region.done = std::max(region.done, size);
    region.target = std::min(capacity, size + std::min(ahead_, capacity / 16));
    changed_.notify_all();
  }

 private:
  struct Region {
    char* base = nullptr;
    size_t done = 0, target = 0;  // bytes from base: faulted in (or written), wanted
  };
  void run() {
    constexpr size_t kChunk = size_t{8} << 20;
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      auto pending = std::find_if(regions_.begin(), regions_.end(), [](const Region& r) { return r.done < r.target; });
      if (stopping_) return;
      if (pending == regions_.end()) {
        changed_.wait(lock);
        continue;
      }
      char* base = pending->base;
      const size_t from = pending->done, length = std::min(kChunk, pending->target - from);
      lock.unlock();
      prefaultForWrite(base + from, length, 1);
      lock.lock();
      if (pending->base == base) pending->done = std::max(pending->done, from + length);
    }
  }

  std::vector<Region> regions_;
  const size_t ahead_;
  std::mutex mutex_;
  std::condition_variable changed_;
  bool stopping_ = false;
  std::thread thread_;
};

// Count i of counts stored `bytes` each: 1 or 2 (a plane function's, escapeGridBytesPerCount), or
// 4 (the row function's uint32, whose high bit may be kExactBit).
uint32_t countAt(const uint8_t* counts, int bytes, size_t i) {
  switch (bytes) {
    case 1:
      return counts[i];
    case 2:
      return loadUnaligned<uint16_t>(counts + 2 * i);
    default:
      return loadUnaligned<uint32_t>(counts + 4 * i) & ~kExactBit;
  }
}

// counts[i] = countAt(block, bytes, i) for i < n: the switch outside the loops, so each widens in
// vector lanes (a per-count switch had cost as much as classifying the plane on the GPU path).
void widenCounts(const uint8_t* block, int bytes, size_t n, uint32_t* counts) {
  switch (bytes) {
    case 1:
      for (size_t i = 0; i < n; ++i) counts[i] = block[i];
      break;
    case 2:
      for (size_t i = 0; i < n; ++i) counts[i] = loadUnaligned<uint16_t>(block + 2 * i);
      break;
    default:
      for (size_t i = 0; i < n; ++i) counts[i] = loadUnaligned<uint32_t>(block + 4 * i) & ~kExactBit;
  }
}

// above[i] = count i > above_at, for counts of type T, compared in T (16 at a time for bytes).
template <typename T>
void classify(const uint8_t* counts, size_t n, uint32_t above_at, uint8_t* above) {
  if (above_at >= std::numeric_limits<T>::max()) {  // no count of type T is above
    std::fill_n(above, n, uint8_t{0});
    return;
  }
  const T at = static_cast<T>(above_at);
  for (size_t i = 0; i < n; ++i) above[i] = loadUnaligned<T>(counts + i * sizeof(T)) > at;
}

// n counts stored `count_bytes` each (countAt) in the grid file's `bytes` (1 or 2) each.
void encodePlane(const uint8_t* counts, int count_bytes, size_t n, int bytes, uint8_t* out) {
  if (count_bytes == bytes) {  // a plane function's counts are the file's encoding already
    std::memcpy(out, counts, n * static_cast<size_t>(bytes));
    return;
  }
  for (size_t i = 0; i < n; ++i) {
    const uint32_t c = countAt(counts, count_bytes, i);
    if (bytes == 1) {
      out[i] = static_cast<uint8_t>(c);
    } else {
      out[2 * i] = static_cast<uint8_t>(c & 0xFF);
      out[2 * i + 1] = static_cast<uint8_t>(c >> 8);
    }
  }
}

// One slab's worth of streaming: counts of the two planes in flight, finished lazily.
class SlabField {
 public:
  // meshes_last: the slab makes vertices on plane `last`'s in-plane edges (owns them, or copies
  // them for a seam). block: the classification counts of planes first..last (at `cap`, in
  // escapeGridBytesPerCount(cap) bytes each), computed elsewhere; nullptr: computed here by the row
  // function.
  SlabField(const EscapeSurfaceParams& params, const std::vector<double>& values, const EscapeRowFunction& row,
            int first, int last, bool meshes_last, int grid_planes, int grid_bytes, int cap, const uint8_t* block)
      : p_(params), values_(values), row_(row), res_(params.axis.resolution), first_(first), last_(last),
        owns_last_(meshes_last), grid_planes_(grid_planes), grid_bytes_(grid_bytes), cap_(cap), block_(block),
        block_bytes_(escapeGridBytesPerCount(cap)) {
    const size_t plane = squared(res_);
    for (int s = 0; s < 2; ++s) {
      counts_[s].resize(plane);
      above_[s].resize(plane);
    }
    refine_ = cap_ < p_.max_iter;
    plane_bytes_ = block_ && !refine_ ? block_bytes_ : static_cast<int>(sizeof(uint32_t));
    if (refine_) {
      row_z_.resize(static_cast<size_t>(res_));
      row_k_.resize(static_cast<size_t>(res_));
      row_counts_.resize(static_cast<size_t>(res_));
    }
    if (grid_planes_ > 0) grid_.resize(plane * static_cast<size_t>(grid_planes_) * static_cast<size_t>(grid_bytes_));
  }

  void load(int p, uint8_t* above) {
    std::vector<uint32_t>& c = counts_[p & 1];
    std::vector<uint8_t>& a = above_[p & 1];
    const size_t n = static_cast<size_t>(res_);
    const size_t points = c.size();
    const uint8_t* block = block_ ? block_ + static_cast<size_t>(p - first_) * points * block_bytes_ : nullptr;
    if (block && !refine_) {  // the block's counts are final: read in place (a 4 MiB copy a plane at res 2048)
      plane_[p & 1] = block;
    } else {
      if (block) {
        widenCounts(block, block_bytes_, points, c.data());
      } else {
        const double x = values_[static_cast<size_t>(p)];
        for (size_t j = 0; j < n; ++j) row_(x, values_[j], values_.data(), n, cap_, &c[j * n]);
      }
      plane_[p & 1] = reinterpret_cast<const uint8_t*>(c.data());
    }
    // count > level is count > floor(level) for an integer count: a compare of integers, which the
    // compiler does several at a time (the conversion to double it did one by one).
    const uint32_t above_at = p_.level >= 4294967295.0 ? 0xFFFFFFFFu : static_cast<uint32_t>(std::floor(p_.level));
    const uint8_t* counts = plane_[p & 1];
    switch (plane_bytes_) {
      case 1:
        classify<uint8_t>(counts, points, above_at, a.data());
        break;
      case 2:
        classify<uint16_t>(counts, points, above_at, a.data());
        break;
      default:
        classify<uint32_t>(counts, points, above_at, a.data());
    }
    std::copy(a.begin(), a.end(), above);
    if (refine_) finishCrossings(p);
    if (p - first_ < grid_planes_) {
      const size_t plane_bytes = points * static_cast<size_t>(grid_bytes_);
      encodePlane(counts, plane_bytes_, points, grid_bytes_, &grid_[static_cast<size_t>(p - first_) * plane_bytes]);
    }
  }

  glm::dvec3 vertex(int p, int j, int k, int axis) {
    const glm::ivec3 a(p, j, k);
    glm::ivec3 b = a;
    b[axis] += 1;
    const double v1 = count(a), v2 = count(b);
    // skimage's formula, from the lower-index end; the endpoints straddle the level, so v1 ≠ v2.
    const double t = (p_.level - v1) / (v2 - v1);
    glm::dvec3 out;
    const double step = p_.axis.step();
    for (int d = 0; d < 3; ++d) {
      const size_t i = static_cast<size_t>(a[d]);
      if (p_.frame == GridFrame::kSeed) {
        // skimage interpolates in index units and scales by the spacing.
        out[d] = (static_cast<double>(a[d]) + (d == axis ? t : 0.0)) * step;
      } else {
        out[d] = d == axis ? values_[i] + t * (values_[i + 1] - values_[i]) : values_[i];
      }
    }
    return out;
  }

  std::vector<uint8_t> takeGrid() { return std::move(grid_); }

 private:
  bool unfinished(int p, size_t pt) const {
    return above_[p & 1][pt] != 0 && (counts_[p & 1][pt] & kExactBit) == 0;
  }

  // Finishes, row by row (so a row function can keep several points in flight), the counts that
  // the vertices of plane p will need: above-level points of p with a below-level neighbour in p
  // (in-plane edges; not for a last plane the next slab meshes) or in p − 1 (x edges), and
  // above-level points of p − 1 with a below-level neighbour in p. Eight points are passed over at
  // once where their flags show none of them can need it: none above, or all above with every
  // neighbour above (most of a plane; a test per point had been a fifth of the meshing's time).
  void finishCrossings(int p) {
    const size_t n = static_cast<size_t>(res_);
    const uint8_t* a = above_[p & 1].data();
    const bool in_plane = p < last_ || owns_last_;
    const bool has_previous = p > first_;
    const uint8_t* prev = above_[(p + 1) & 1].data();
    for (size_t j = 0; j < n; ++j) {
      size_t m = 0;
      for (size_t k = 0; k < n; ++k) {
        const size_t pt = j * n + k;
        if (k > 0 && k + 9 <= n) {  // pt − 1 .. pt + 8 lie in the row
          const uint64_t w = mcFlagWord(a + pt);
          if (w == kMcNoneAbove ||
              (w == kMcAllAbove && (!has_previous || mcFlagWord(prev + pt) == kMcAllAbove) &&
               (!in_plane || ((j == 0 || mcFlagWord(a + pt - n) == kMcAllAbove) &&
                              (j + 1 == n || mcFlagWord(a + pt + n) == kMcAllAbove) && mcFlagWord(a + pt - 1) == kMcAllAbove &&
                              mcFlagWord(a + pt + 1) == kMcAllAbove)))) {
            k += 7;
            continue;
          }
        }
        if (!unfinished(p, pt)) continue;
        bool crossed = has_previous && !prev[pt];
        if (in_plane)
          crossed = crossed || (j > 0 && !a[pt - n]) || (j + 1 < n && !a[pt + n]) || (k > 0 && !a[pt - 1]) ||
                    (k + 1 < n && !a[pt + 1]);
        if (crossed) mark(m, k);
      }
      finishRow(p, j, m);
    }
    if (!has_previous) return;
    for (size_t j = 0; j < n; ++j) {
      size_t m = 0;
      for (size_t k = 0; k < n; ++k) {
        const size_t pt = j * n + k;
        // None of p − 1 above, or all of p above: no x edge from p − 1 crossed.
        if (k + 8 <= n && (mcFlagWord(prev + pt) == kMcNoneAbove || mcFlagWord(a + pt) == kMcAllAbove)) {
          k += 7;
          continue;
        }
        if (unfinished(p - 1, pt) && !a[pt]) mark(m, k);
      }
      finishRow(p - 1, j, m);
    }
  }

  // Adds point k of the row in hand to the points to finish (m of them so far).
  void mark(size_t& m, size_t k) {
    row_k_[m] = k;
    row_z_[m++] = values_[k];
  }

  // Finishes the m marked points of row j of plane p.
  void finishRow(int p, size_t j, size_t m) {
    if (m == 0) return;
    const size_t n = static_cast<size_t>(res_);
    std::vector<uint32_t>& c = counts_[p & 1];
    row_(values_[static_cast<size_t>(p)], values_[j], row_z_.data(), m, p_.max_iter, row_counts_.data());
    for (size_t i = 0; i < m; ++i) c[j * n + row_k_[i]] = row_counts_[i] | kExactBit;
  }

  // The exact count at a point of a plane in flight. Below the cap the classification count is
  // already exact; at the cap the point is above the level and finishCrossings has finished it.
  // Finishing here too keeps the mesh right should that selection ever miss a point.
  double count(const glm::ivec3& q) {
    const size_t pt = static_cast<size_t>(q.y) * static_cast<size_t>(res_) + static_cast<size_t>(q.z);
    if (!refine_) return static_cast<double>(countAt(plane_[q.x & 1], plane_bytes_, pt));
    uint32_t& c = counts_[q.x & 1][pt];
    if ((c & kExactBit) == 0 && c >= static_cast<uint32_t>(cap_)) {
      assert(false && "finishCrossings missed a point");
      uint32_t full = 0;
      row_(values_[static_cast<size_t>(q.x)], values_[static_cast<size_t>(q.y)], &values_[static_cast<size_t>(q.z)], 1,
           p_.max_iter, &full);
      c = full | kExactBit;
    }
    return static_cast<double>(c & ~kExactBit);
  }

  const EscapeSurfaceParams& p_;
  const std::vector<double>& values_;
  const EscapeRowFunction& row_;
  int res_, first_, last_;
  bool owns_last_;
  int grid_planes_, grid_bytes_;
  int cap_ = 0;
  const uint8_t* block_ = nullptr;
  int block_bytes_ = 1;
  bool refine_ = false;
  // The counts of the planes in flight, by p & 1, plane_bytes_ each: in block_ when it holds them
  // final, else counts_ (uint32).
  const uint8_t* plane_[2] = {nullptr, nullptr};
  int plane_bytes_ = 4;
  // The planes in flight and the row buffers, kept by the thread from slab to slab (fresh ones
  // cost a page fault per 4 KiB: at res 2048 that was most of the meshing's time). load() writes
  // a plane's counts and flags whole before any is read.
  struct Scratch {
    std::vector<uint32_t> counts[2];
    std::vector<uint8_t> above[2];
    std::vector<double> row_z;
    std::vector<size_t> row_k;
    std::vector<uint32_t> row_counts;
  };
  static Scratch& scratch() {
    thread_local Scratch s;
    return s;
  }
  std::vector<uint32_t> (&counts_)[2] = scratch().counts;
  std::vector<uint8_t> (&above_)[2] = scratch().above;
  std::vector<double>& row_z_ = scratch().row_z;
  std::vector<size_t>& row_k_ = scratch().row_k;
  std::vector<uint32_t>& row_counts_ = scratch().row_counts;
  std::vector<uint8_t> grid_;
};

}  // namespace

Status validateEscapeParams(int resolution, int max_iter, double lo, double hi, double level) {
  // A fixed range: outside it is a usage error (exit 1) either way; a resolution inside it that
  // needs more memory than there is fails the memory estimate (exit 4) later.
  if (resolution < 2 || resolution > kMaxGridResolution)
    return Error{"--resolution " + std::to_string(resolution) + ": must be 2.." + std::to_string(kMaxGridResolution),
                 ExitCode::kUsage};
  if (max_iter < 1 || max_iter > kMaxEscapeIterations)
    return Error{"--max-iter " + std::to_string(max_iter) + ": must be 1.." + std::to_string(kMaxEscapeIterations),
                 ExitCode::kUsage};
  if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi))
    return Error{"--bounds: " + text(lo) + "," + text(hi) + " must be finite with LO < HI", ExitCode::kUsage};
  if (level != kDefaultLevel && !(level > 0.0 && level < static_cast<double>(max_iter)))
    return Error{"--level " + text(level) + ": must lie inside the escape counts' range (0, " + std::to_string(max_iter) +
                     ") (exclusive; --max-iter is " + std::to_string(max_iter) + ")",
                 ExitCode::kUsage};
  return okStatus();
}

double resolveLevel(int max_iter, double level) {
  // The seed's level, max_iter / 4 in Python's true division.
  return level == kDefaultLevel ? static_cast<double>(max_iter) / 4.0 : level;
}

int escapeGridBytesPerCount(int max_iter) { return max_iter <= 255 ? 1 : 2; }

uint64_t estimateEscapeSurfaceMemory(const EscapeSurfaceParams& params) { return estimateLayerMemory(params, 1.0); }

namespace {

// The vertices and triangles of cell layers [first_layer, last_layer) (planes first_layer ..
// last_layer), in canonical order; triangle indices ≥ mesh.size() are the in-plane vertices of
// plane last_layer, which the layers own only when it is the grid's last plane; otherwise `seam`
// holds copies of their positions.
struct LayerMesh {
  PointSet mesh;
  PositionArray seam;
  // Where the rows went to params.rows instead (the mesh and seam then empty): the vertex rows the
  // layers own, and the seam's copies that followed them.
  bool streamed = false;
  uint64_t row_vertices = 0, seam_rows = 0;
};

Result<LayerMesh> meshLayers(const EscapeSurfaceParams& params, const EscapeRowFunction& row, int first_layer,
                             int last_layer) {
  const int res = params.axis.resolution;
  assert(res >= 2 && params.level > 0.0 && params.level < params.max_iter);
  assert(0 <= first_layer && first_layer < last_layer && last_layer <= res - 1);
  const int layers = last_layer - first_layer;
  const double share = static_cast<double>(layers) / (res - 1);
  const std::string what = params.name + " at resolution " + std::to_string(res) +
                           (layers < res - 1 ? " (planes " + std::to_string(first_layer) + ".." +
                                                   std::to_string(last_layer) + ")"
                                             : "");
  const unsigned threads = resolveThreads(params.threads);
  SlabPlan plan = planSlabs(layers, threads, params.planes ? gpuSlabThickness(res) : kMaxSlabThickness);
  const int cap = classificationLimit(params);
  // Marching cubes elsewhere (a GPU) makes the slabs' counts and meshes, in slab order, in slabs of
  // its own thickness where it takes them; else the plane function's blocks of counts feed the
  // workers, or the workers count with the row function.
  bool elsewhere = params.planes && params.mesher.mesh && cap == params.max_iter && params.grid_out.empty();
  if (elsewhere) {
    const int thickness = std::min(layers, meshSlabThickness(res, layers));
    if (params.mesher.takes(res, thickness + 1, cap))
      plan = {thickness, (layers + thickness - 1) / thickness};
    else
      elsewhere = params.mesher.takes(res, plan.thickness + 1, cap);
  }
  // The mesher's noise covers the cells of |v| < 1024 (perlin.cpp's fast path): every coordinate,
  // plus the colours' offsets of up to 200, well inside it.
  const double reach = params.frame == GridFrame::kSeed
                           ? params.axis.hi - params.axis.lo
                           : std::max(std::fabs(params.axis.lo), std::fabs(params.axis.hi));
  const bool noise_fits = elsewhere && params.noise_colors && reach + 200.0 < 1000.0;
  // The mesh as PLY rows, written as they come, where the mesher makes all of it.
  const bool rows = elsewhere && params.rows.slab && (!params.rows.colors || noise_fits);
  // As rows, the colours where the sink's rows have them (the rows' size is theirs); returned, only
  // for the whole grid, since a part's seam copies then hold positions only.
  const bool noise_elsewhere = noise_fits && (rows ? params.rows.colors : first_layer == 0 && last_layer == res - 1);
  // What the path holds in memory, checked before anything is made or written.
  const MeshPath path = rows ? MeshPath::kRows : elsewhere ? MeshPath::kElsewhere : MeshPath::kHost;
  if (Status s = checkMemory(what, estimateLayerMemory(params, share, path), params.max_memory); !s) return s.error();
  const uint64_t limit = params.max_memory == 0 ? defaultMemoryLimit() : params.max_memory;

  std::optional<AtomicFile> grid_file;
  if (!params.grid_out.empty()) {
    Result<AtomicFile> f = AtomicFile::create(params.grid_out);
    if (!f) return f.error();
    grid_file.emplace(std::move(f).value());
  }
  const int grid_bytes = escapeGridBytesPerCount(params.max_iter);

  std::vector<double> values(static_cast<size_t>(res));
  for (int i = 0; i < res; ++i) values[static_cast<size_t>(i)] = params.axis.value(i);
  LayerMesh out;
  PointSet& mesh = out.mesh;
  // Reserving only claims address space; the pages are touched as the mesh grows, so an
  // estimate on the high side costs nothing and saves the copy of a reallocation.
  const double reserve =
      rows ? 0.0 : std::min(1.25 * share * estimatedVertices(res), static_cast<double>(limit / kMeshBytesPerVertex));
  mesh.positions.reserve(static_cast<size_t>(reserve));
  mesh.triangles.reserve(static_cast<size_t>(reserve) * 6);
  // The slabs are appended one at a time under a lock while the other workers wait for it: with
  // 4 KiB pages the faults of that first touch took most of the appending (res-2048 Mandelbulb on
  // 16 cores: 4.6 s of it, and the workers 41 thread-seconds waiting for the lock).
  adviseHugePages(mesh.positions.data(), mesh.positions.capacity() * sizeof(glm::dvec3));
  adviseHugePages(mesh.triangles.data(), mesh.triangles.capacity() * sizeof(uint32_t));
  PrefaultAhead prefault(2, size_t{128} << 20);
  auto grew = [&] {
    prefault.grew(0, mesh.positions.data(), mesh.positions.size() * sizeof(glm::dvec3),
                  mesh.positions.capacity() * sizeof(glm::dvec3));
    prefault.grew(1, mesh.triangles.data(), mesh.triangles.size() * sizeof(uint32_t),
                  mesh.triangles.capacity() * sizeof(uint32_t));
  };
  grew();

  struct Pending {
    bool ready = false;
    McSlabMesh mesh;
    std::vector<uint8_t> grid;
  };
  std::vector<Pending> pending(static_cast<size_t>(plan.count));
  std::mutex mutex;
  size_t next_commit = 0;
  uint32_t previous_last_plane_vertices = 0;
  std::atomic<bool> failed{false};
  std::optional<Error> failure;
  auto fail = [&](Error e) {  // with the mutex held
    if (!failure) failure = std::move(e);
    failed = true;
  };

  size_t color_bytes = 0;  // a vertex's colour, where the mesher makes the colours too
  // Appends slab `index`'s mesh (marchingCubesSlab's McSlabMesh, or a view of one made elsewhere)
  // to the mesh, copying on `copiers` threads; false when it would pass a limit (then `fail` has
  // the error).
  auto appendSlab = [&](size_t index, std::span<const glm::dvec3> positions, std::span<const uint32_t> triangles,
                        uint32_t first_plane_vertices, uint32_t last_plane_vertices, unsigned copiers) {
    assert(index == 0 || first_plane_vertices == previous_last_plane_vertices);
    (void)index, (void)first_plane_vertices;
    previous_last_plane_vertices = last_plane_vertices;
    const uint64_t offset = mesh.positions.size();
    const uint64_t vertices = offset + positions.size() + last_plane_vertices;
    const uint64_t bytes = vertices * (sizeof(glm::dvec3) + color_bytes) +
                           (mesh.triangles.size() + triangles.size()) * sizeof(uint32_t);
    if (vertices > UINT32_MAX) {
      fail(Error{what + ": more than 2^32 vertices", ExitCode::kResourceLimit});
      return false;
    }
    if (bytes > limit) {
      fail(Error{what + ": the mesh grew past " + formatBytes(bytes) + ", more than the limit of " +
                     formatBytes(limit) + " (--max-memory)",
                 ExitCode::kResourceLimit});
      return false;
    }
    const size_t first_index = mesh.triangles.size();
    mesh.positions.resize(offset + positions.size());  // not zeroed (DefaultInitAllocator)
    mesh.triangles.resize(first_index + triangles.size());
    // Pieces of 256 Ki values (2–6 MiB); the ids shifted as they are copied.
    constexpr size_t kPiece = size_t{1} << 18;
    const size_t position_pieces = (positions.size() + kPiece - 1) / kPiece;
    const size_t pieces = position_pieces + (triangles.size() + kPiece - 1) / kPiece;
    parallelFor(pieces, copiers, [&](size_t piece, unsigned) {
      if (piece < position_pieces) {
        const size_t at = piece * kPiece, n = std::min(kPiece, positions.size() - at);
        std::copy_n(positions.begin() + static_cast<std::ptrdiff_t>(at), n,
                    mesh.positions.begin() + static_cast<std::ptrdiff_t>(offset + at));
        return;
      }
      const size_t at = (piece - position_pieces) * kPiece, n = std::min(kPiece, triangles.size() - at);
      std::transform(triangles.begin() + static_cast<std::ptrdiff_t>(at),
                     triangles.begin() + static_cast<std::ptrdiff_t>(at + n),
                     mesh.triangles.begin() + static_cast<std::ptrdiff_t>(first_index + at),
                     [offset](uint32_t id) { return static_cast<uint32_t>(offset + id); });
    });
    grew();
    return true;
  };

  // Appends finished slabs in slab order: the output is the same for any thread count.
  auto commitReady = [&] {
    while (next_commit < pending.size() && pending[next_commit].ready) {
      Pending& done = pending[next_commit];
      if (!failed &&
          appendSlab(next_commit, done.mesh.positions, done.mesh.triangles, done.mesh.first_plane_vertices,
                     done.mesh.last_plane_vertices, 1)) {
        if (next_commit + 1 == pending.size()) out.seam = std::move(done.mesh.seam_positions);
        if (grid_file)
          if (Status s = grid_file->write(done.grid.data(), done.grid.size()); !s) fail(s.error());
      }
      done = Pending{true, {}, {}};  // frees the slab
      ++next_commit;
    }
  };

  auto slabFirst = [&](size_t s) { return first_layer + static_cast<int>(s) * plan.thickness; };
  auto slabLast = [&](size_t s) { return std::min(slabFirst(s) + plan.thickness, last_layer); };
  if (noise_elsewhere) {
    color_bytes = sizeof(glm::vec3);
    mesh.colors.reserve(mesh.positions.capacity());
  }
  std::optional<PlaneBlocks> blocks;
  if (params.planes && !elsewhere) {
    std::vector<std::pair<int, int>> planes;  // first plane and plane count of each slab
    for (size_t s = 0; s < pending.size(); ++s) planes.emplace_back(slabFirst(s), slabLast(s) - slabFirst(s) + 1);
    blocks.emplace(params.planes, params.arena, std::move(planes), cap,
                   squared(res) * static_cast<uint64_t>(escapeGridBytesPerCount(cap)), threads + 2);
  }

  auto slabAt = [&](int first, int last) {
    EscapeSlab slab;
    slab.res = res;
    slab.first = first;
    slab.last = last;
    slab.owns_last_plane = slab.last == res - 1;
    slab.seam_positions = slab.last == last_layer && !slab.owns_last_plane;
    slab.limit = cap;
    slab.level = params.level;
    slab.frame = params.frame;
    slab.values = &values;
    slab.step = params.axis.step();
    slab.noise_colors = noise_elsewhere;
    slab.float_colors = params.rows.float_colors;
    return slab;
  };
  // Slab s meshed elsewhere, with the next slab named so that its counts are made meanwhile.
  auto meshSlab = [&](size_t s, const EscapeSlab& slab) {
    const bool more = s + 1 < pending.size();
    const EscapeSlab next = more ? slabAt(slabFirst(s + 1), slabLast(s + 1)) : EscapeSlab{};
    return params.mesher.mesh(slab, more ? &next : nullptr);
  };
  if (rows) {
    // The header's counts from 16 cell layers spread over the grid (the middle of each sixteenth),
    // meshed as slabs of their own: each costs host round trips (32 of them took 0.2–0.5 s on an
    // H200), and the estimate only has to have the real counts' digits.
    const int samples = std::min(layers, 16);
    double sampled_vertices = 0.0, sampled_triangles = 0.0;
    uint64_t most_vertices = 0, most_triangles = 0, most_plane = 0;  // of a sampled layer
    auto sampled = [&](int i) {
      const int layer = first_layer + static_cast<int>((i + 0.5) * layers / samples);
      EscapeSlab slab = slabAt(layer, layer + 1);
      slab.noise_colors = false;
      return slab;
    };
    for (int i = 0; i < samples && !interrupted(); ++i) {
      // Then the first slab's counts are made while the last sampled layer is meshed.
      const EscapeSlab next = i + 1 < samples ? sampled(i + 1) : slabAt(slabFirst(0), slabLast(0));
      Result<McSlabView> view = params.mesher.mesh(sampled(i), pending.empty() ? nullptr : &next);
      if (!view) return view.error();
      sampled_vertices += static_cast<double>(view->positions.size());
      sampled_triangles += static_cast<double>(view->triangles.size() / 3);
      most_vertices = std::max<uint64_t>(most_vertices, view->positions.size());
      most_triangles = std::max<uint64_t>(most_triangles, view->triangles.size() / 3);
      most_plane = std::max<uint64_t>(most_plane, view->last_plane_vertices);
    }
    // The largest slab's buffers at once, a quarter over the sample's densest layers: growing them
    // slab by slab cost 0.56 s of host-visible allocations at res 2048 on an H200.
    if (params.mesher.reserve) {
      const double slab_layers = 1.25 * plan.thickness;
      if (Status s = params.mesher.reserve(
              static_cast<uint64_t>(slab_layers * static_cast<double>(most_vertices)) + 2 * most_plane,
              static_cast<uint64_t>(slab_layers * static_cast<double>(most_triangles)), noise_elsewhere,
              slabAt(first_layer, last_layer).rowBytes());
          !s)
        return s.error();
    }
    if (interrupted()) return interruptedError();
    const double scale = static_cast<double>(layers) / samples;
    if (Status s = params.rows.start(static_cast<uint64_t>(std::llround(sampled_vertices * scale)),
                                     static_cast<uint64_t>(std::llround(sampled_triangles * scale)));
        !s)
      return s.error();
  }

  if (params.progress) params.progress->start(params.name, static_cast<uint64_t>(layers));
  if (rows) {
    // Each slab's rows go to the sink on a thread of their own while the next is made.
    std::future<Status> writing;
    uint64_t vertices = 0;
    for (size_t s = 0; s < pending.size() && !failed; ++s) {
      if (interrupted()) break;
      EscapeSlab slab = slabAt(slabFirst(s), slabLast(s));
      slab.ply_rows = true;
      slab.vertex_base = static_cast<uint32_t>(vertices);
      assert(slab.noise_colors == params.rows.colors);  // the rows' size is the sink's
      Result<McSlabView> view = meshSlab(s, slab);
      if (writing.valid())
        if (Status w = writing.get(); !w) fail(w.error());
      if (!view) fail(view.error());
      if (failed) break;
      // The slab's ids are below its vertices plus the next plane's: all within uint32.
      if (vertices + view->row_vertices + view->last_plane_vertices > UINT32_MAX) {
        fail(Error{what + ": more than 2^32 vertices", ExitCode::kResourceLimit});
        break;
      }
      vertices += view->row_vertices;
      if (slab.seam_positions) out.seam_rows = view->last_plane_vertices;
      writing = std::async(std::launch::async, [&, s, v = *view] {
        Status w = v.ready ? v.ready() : okStatus();
        if (w) w = params.rows.slab(v.vertex_rows, v.face_rows);
        if (w && params.progress) params.progress->advance(static_cast<uint64_t>(slabLast(s) - slabFirst(s)));
        return w;
      });
    }
    if (writing.valid())
      if (Status w = writing.get(); !w) fail(w.error());
    out.streamed = true;
    out.row_vertices = vertices;
  } else if (elsewhere) {
    // Each slab's mesh is copied into the mesh on a thread of its own while the next is made.
    std::future<void> appending;
    for (size_t s = 0; s < pending.size(); ++s) {
      if (interrupted()) break;
      const EscapeSlab slab = slabAt(slabFirst(s), slabLast(s));
      Result<McSlabView> view = meshSlab(s, slab);
      if (appending.valid()) appending.get();
      if (!view) fail(view.error());
      if (failed) break;
      appending = std::async(std::launch::async, [&, s, v = *view] {
        // The host's cores are free while the device meshes: the copy runs on most of them.
        if (!appendSlab(s, v.positions, v.triangles, v.first_plane_vertices, v.last_plane_vertices,
                        std::max(1u, std::min(8u, threads)))) return;
        if (noise_elsewhere) {
          assert(v.colors.size() >= v.positions.size());
          mesh.colors.insert(mesh.colors.end(), v.colors.begin(),
                             v.colors.begin() + static_cast<std::ptrdiff_t>(v.positions.size()));
        }
        if (s + 1 == pending.size()) out.seam.assign(v.seam_positions.begin(), v.seam_positions.end());
        if (params.progress) params.progress->advance(static_cast<uint64_t>(slabLast(s) - slabFirst(s)));
      });
    }
    if (appending.valid()) appending.get();
  } else {
    parallelFor(static_cast<size_t>(plan.count), threads, [&](size_t s, unsigned) {
      const int first = slabFirst(s);
      const int last = slabLast(s);
      const bool owns_last = last == res - 1;
      const bool seam = last == last_layer && !owns_last;
      Pending result;
      const uint8_t* block = nullptr;
      if (!failed && blocks) {
        block = blocks->wait(s);
        if (!block) failed = true;  // the plane function failed; blocks holds the error
      }
      if (!failed) {
        const int grid_planes = grid_file ? last - first + (owns_last ? 1 : 0) : 0;
        SlabField field(params, values, row, first, last, owns_last || seam, grid_planes, grid_bytes, cap, block);
        McSlabCallbacks callbacks;
        callbacks.load_plane = [&](int p, uint8_t* above) { field.load(p, above); };
        callbacks.edge_vertex = [&](int p, int j, int k, int axis) { return field.vertex(p, j, k, axis); };
        callbacks.plane_done = [&](int p) {
          if (p > first && params.progress) params.progress->advance(1);
          // An interrupt stops every slab at its next plane; nothing more is committed.
          if (interrupted()) failed = true;
          return !failed.load(std::memory_order_relaxed);
        };
        result.mesh = marchingCubesSlab(res, res, first, last, owns_last, callbacks, seam);
        result.grid = field.takeGrid();
      }
      if (block) blocks->release(s);
      std::lock_guard<std::mutex> lock(mutex);
      result.ready = true;
      pending[s] = std::move(result);
      commitReady();
    });
  }
  if (blocks) {
    blocks->stop();
    if (std::optional<Error> e = blocks->error(); e && !failure) failure = std::move(e);
  }
  if (params.progress) params.progress->finish();
  if (interrupted()) return interruptedError();
  if (failure) return *failure;
  if (grid_file)
    if (Status s = grid_file->commit(); !s) return s.error();
  return out;
}

}  // namespace

Result<PointSet> generateEscapeSurface(const EscapeSurfaceParams& params, const EscapeRowFunction& row) {
  Result<LayerMesh> whole = meshLayers(params, row, 0, params.axis.resolution - 1);
  if (!whole) return whole.error();
  assert(whole->seam.empty());
  return std::move(whole->mesh);
}

Result<PointTile> generateEscapeSurfaceTile(const EscapeSurfaceParams& params, const EscapeRowFunction& row,
                                            TileSpec tile) {
  const uint64_t layers = static_cast<uint64_t>(params.axis.resolution - 1);
  const TileRange range = tileRange(layers, tile);
  PointTile out;
  out.tile = tile;
  if (range.empty()) {  // more tiles than cell layers: nothing to own, an empty grid piece
    if (!params.grid_out.empty()) {
      Result<AtomicFile> f = AtomicFile::create(params.grid_out);
      if (!f) return f.error();
      if (Status s = f->commit(); !s) return s.error();
    }
    return out;
  }
  Result<LayerMesh> part = meshLayers(params, row, static_cast<int>(range.begin), static_cast<int>(range.end));
  if (!part) return part.error();
  const uint64_t owned = part->streamed ? part->row_vertices : part->mesh.size();
  const uint64_t copies = part->streamed ? part->seam_rows : part->seam.size();
  if (owned + copies > UINT32_MAX)
    return Error{params.name + ": more than 2^32 vertices in tile " + std::to_string(tile.index), ExitCode::kResourceLimit};
  out.points = std::move(part->mesh);
  out.owned = static_cast<uint32_t>(owned);
  // The seam plane's vertices open the next non-empty tile's own (canonical order: a plane's
  // in-plane edges come first).
  const uint32_t next = nextNonEmptyTile(layers, tile);
  assert(copies == 0 || next < tile.count);
  for (uint64_t i = 0; i < copies; ++i) {
    if (!part->streamed) out.points.positions.push_back(part->seam[i]);
    out.foreign.push_back({next, static_cast<uint32_t>(i)});
  }
  return out;
}

Result<std::vector<uint32_t>> computeEscapeGrid(const GridAxis& axis, int max_iter, const EscapeRowFunction& row,
                                                unsigned threads, int first_plane, int planes) {
  const int res = axis.resolution;
  assert(first_plane >= 0 && planes >= 0 && first_plane + planes <= res);
  const uint64_t count = static_cast<uint64_t>(planes) * squared(res);
  if (Status s = checkMemory("escape grid", count * sizeof(uint32_t), 0); !s) return s.error();
  std::vector<double> values(static_cast<size_t>(res));
  for (int i = 0; i < res; ++i) values[static_cast<size_t>(i)] = axis.value(i);
  std::vector<uint32_t> grid(count);
  const size_t n = static_cast<size_t>(res);
  parallelFor(static_cast<size_t>(planes) * n, threads, [&](size_t item, unsigned) {
    const size_t i = item / n, j = item % n;
    row(values[static_cast<size_t>(first_plane) + i], values[j], values.data(), n, max_iter, &grid[item * n]);
  });
  return grid;
}

Status writeEscapeGrid(const std::string& path, const std::vector<uint32_t>& counts, int max_iter) {
  Result<AtomicFile> file = AtomicFile::create(path);
  if (!file) return file.error();
  const int bytes = escapeGridBytesPerCount(max_iter);
  std::vector<uint8_t> encoded(counts.size() * static_cast<size_t>(bytes));
  encodePlane(reinterpret_cast<const uint8_t*>(counts.data()), sizeof(uint32_t), counts.size(), bytes, encoded.data());
  if (Status s = file->write(encoded.data(), encoded.size()); !s) return s;
  return file->commit();
}

}  // namespace dpoint
