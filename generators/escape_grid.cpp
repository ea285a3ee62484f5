#include "generators/escape_grid.h"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <charconv>
#include <cmath>
#include <mutex>
#include <optional>

#include "core/atomic_file.h"
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
// heavy middle slabs, at most 32 layers so a slab's mesh and grid stay small, at least 4 so the
// plane both neighbours compute costs at most a quarter more.
struct SlabPlan {
  int thickness;
  int count;
};
SlabPlan planSlabs(int res, unsigned threads) {
  const int layers = res - 1;
  const int wanted = static_cast<int>(std::min<unsigned>(threads, 1024)) * 6;
  const int thickness = std::clamp((layers + wanted - 1) / wanted, 4, 32);
  return {thickness, (layers + thickness - 1) / thickness};
}

void encodePlane(const uint32_t* counts, size_t n, int bytes, uint8_t* out) {
  for (size_t i = 0; i < n; ++i) {
    const uint32_t c = counts[i] & ~kExactBit;
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
  SlabField(const EscapeSurfaceParams& params, const std::vector<double>& values, const EscapeRowFunction& row,
            int first, int last, bool owns_last, int grid_planes, int grid_bytes)
      : p_(params), values_(values), row_(row), res_(params.axis.resolution), first_(first), last_(last),
        owns_last_(owns_last), grid_planes_(grid_planes), grid_bytes_(grid_bytes) {
    const size_t plane = squared(res_);
    for (int s = 0; s < 2; ++s) {
      counts_[s].resize(plane);
      above_[s].resize(plane);
    }
    // Points at the cap are above the level: min(count, cap) > level exactly when count > level.
    cap_ = p_.lazy && p_.grid_out.empty() ? static_cast<int>(std::floor(p_.level)) + 1 : p_.max_iter;
    refine_ = cap_ < p_.max_iter;
    if (refine_) {
      need_.resize(plane);
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
    const double x = values_[static_cast<size_t>(p)];
    for (size_t j = 0; j < n; ++j) row_(x, values_[j], values_.data(), n, cap_, &c[j * n]);
    for (size_t i = 0; i < c.size(); ++i) a[i] = static_cast<double>(c[i]) > p_.level;
    std::copy(a.begin(), a.end(), above);
    if (refine_) finishCrossings(p);
    if (p - first_ < grid_planes_) {
      const size_t plane_bytes = c.size() * static_cast<size_t>(grid_bytes_);
      encodePlane(c.data(), c.size(), grid_bytes_, &grid_[static_cast<size_t>(p - first_) * plane_bytes]);
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
  // above-level points of p − 1 with a below-level neighbour in p.
  void finishCrossings(int p) {
    const size_t n = static_cast<size_t>(res_);
    const uint8_t* a = above_[p & 1].data();
    const bool in_plane = p < last_ || owns_last_;
    const bool has_previous = p > first_;
    const uint8_t* prev = above_[(p + 1) & 1].data();
    std::fill(need_.begin(), need_.end(), 0);
    for (size_t j = 0; j < n; ++j) {
      for (size_t k = 0; k < n; ++k) {
        const size_t pt = j * n + k;
        if (!unfinished(p, pt)) continue;
        bool crossed = has_previous && !prev[pt];
        if (in_plane)
          crossed = crossed || (j > 0 && !a[pt - n]) || (j + 1 < n && !a[pt + n]) || (k > 0 && !a[pt - 1]) ||
                    (k + 1 < n && !a[pt + 1]);
        need_[pt] = crossed;
      }
    }
    finishMarked(p);
    if (!has_previous) return;
    for (size_t pt = 0; pt < need_.size(); ++pt) need_[pt] = unfinished(p - 1, pt) && !a[pt];
    finishMarked(p - 1);
  }

  void finishMarked(int p) {
    const size_t n = static_cast<size_t>(res_);
    std::vector<uint32_t>& c = counts_[p & 1];
    for (size_t j = 0; j < n; ++j) {
      size_t m = 0;
      for (size_t k = 0; k < n; ++k) {
        if (!need_[j * n + k]) continue;
        row_k_[m] = k;
        row_z_[m++] = values_[k];
      }
      if (m == 0) continue;
      row_(values_[static_cast<size_t>(p)], values_[j], row_z_.data(), m, p_.max_iter, row_counts_.data());
      for (size_t i = 0; i < m; ++i) c[j * n + row_k_[i]] = row_counts_[i] | kExactBit;
    }
  }

  // The exact count at a point of a plane in flight. Below the cap the classification count is
  // already exact; at the cap the point is above the level and finishCrossings has finished it.
  // Finishing here too keeps the mesh right should that selection ever miss a point.
  double count(const glm::ivec3& q) {
    uint32_t& c = counts_[q.x & 1][static_cast<size_t>(q.y) * static_cast<size_t>(res_) + static_cast<size_t>(q.z)];
    if ((c & kExactBit) == 0 && refine_ && c >= static_cast<uint32_t>(cap_)) {
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
  bool refine_ = false;
  std::vector<uint32_t> counts_[2];
  std::vector<uint8_t> above_[2];
  std::vector<uint8_t> need_;
  std::vector<double> row_z_;
  std::vector<size_t> row_k_;
  std::vector<uint32_t> row_counts_;
  std::vector<uint8_t> grid_;
};

}  // namespace

Status validateEscapeParams(int resolution, int max_iter, double lo, double hi, double level) {
  // Too large is a resource limit (exit 4), like the memory estimate it would otherwise fail.
  if (resolution < 2 || resolution > kMaxGridResolution)
    return Error{"--resolution: " + std::to_string(resolution) + " is outside 2.." + std::to_string(kMaxGridResolution),
                 resolution < 2 ? ExitCode::kUsage : ExitCode::kResourceLimit};
  if (max_iter < 1 || max_iter > kMaxEscapeIterations)
    return Error{"--max-iter: " + std::to_string(max_iter) + " is outside 1.." + std::to_string(kMaxEscapeIterations),
                 ExitCode::kUsage};
  if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi))
    return Error{"--bounds: " + text(lo) + "," + text(hi) + " must be finite with LO < HI", ExitCode::kUsage};
  if (level != kDefaultLevel && !(level > 0.0 && level < static_cast<double>(max_iter)))
    return Error{"--level: " + text(level) + " is outside the escape counts' range (0, " + std::to_string(max_iter) +
                     ") (exclusive; --max-iter is " + std::to_string(max_iter) + ")",
                 ExitCode::kUsage};
  return okStatus();
}

double resolveLevel(int max_iter, double level) {
  // The seed's level, max_iter / 4 in Python's true division.
  return level == kDefaultLevel ? static_cast<double>(max_iter) / 4.0 : level;
}

int escapeGridBytesPerCount(int max_iter) { return max_iter <= 255 ? 1 : 2; }

uint64_t estimateEscapeSurfaceMemory(const EscapeSurfaceParams& params) {
  const int res = params.axis.resolution;
  const unsigned threads = resolveThreads(params.threads);
  const SlabPlan plan = planSlabs(res, threads);
  uint64_t per_worker = kWorkerBytesPerPoint * squared(res);
  if (!params.grid_out.empty())  // a slab's planes wait for their turn to be written; twice for the stragglers
    per_worker += 2 * static_cast<uint64_t>(plan.thickness) * squared(res) *
                  static_cast<uint64_t>(escapeGridBytesPerCount(params.max_iter));
  const double mesh = estimatedVertices(res) * static_cast<double>(kMeshBytesPerVertex);
  return threads * per_worker + static_cast<uint64_t>(std::min(mesh, 1e19));
}

Result<PointSet> generateEscapeSurface(const EscapeSurfaceParams& params, const EscapeRowFunction& row) {
  const int res = params.axis.resolution;
  assert(res >= 2 && params.level > 0.0 && params.level < params.max_iter);
  const std::string what = params.name + " at resolution " + std::to_string(res);
  if (Status s = checkMemory(what, estimateEscapeSurfaceMemory(params), params.max_memory); !s) return s.error();
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

  const unsigned threads = resolveThreads(params.threads);
  const SlabPlan plan = planSlabs(res, threads);
  PointSet mesh;
  // Reserving only claims address space; the pages are touched as the mesh grows, so an
  // estimate on the high side costs nothing and saves the copy of a reallocation.
  const double reserve = std::min(1.25 * estimatedVertices(res), static_cast<double>(limit / kMeshBytesPerVertex));
  mesh.positions.reserve(static_cast<size_t>(reserve));
  mesh.triangles.reserve(static_cast<size_t>(reserve) * 6);

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

  // Appends finished slabs in slab order: the output is the same for any thread count.
  auto commitReady = [&] {
    while (next_commit < pending.size() && pending[next_commit].ready) {
      Pending& done = pending[next_commit];
      if (!failed) {
        assert(next_commit == 0 || done.mesh.first_plane_vertices == previous_last_plane_vertices);
        previous_last_plane_vertices = done.mesh.last_plane_vertices;
        const uint64_t offset = mesh.positions.size();
        const uint64_t vertices = offset + done.mesh.positions.size() + done.mesh.last_plane_vertices;
        const uint64_t bytes = vertices * sizeof(glm::dvec3) +
                               (mesh.triangles.size() + done.mesh.triangles.size()) * sizeof(uint32_t);
        if (vertices > UINT32_MAX) {
          fail(Error{what + ": more than 2^32 vertices", ExitCode::kResourceLimit});
        } else if (bytes > limit) {
          fail(Error{what + ": the mesh grew past " + formatBytes(bytes) + ", more than the limit of " +
                         formatBytes(limit) + " (--max-memory)",
                     ExitCode::kResourceLimit});
        } else {
          mesh.positions.insert(mesh.positions.end(), done.mesh.positions.begin(), done.mesh.positions.end());
          for (uint32_t id : done.mesh.triangles) mesh.triangles.push_back(static_cast<uint32_t>(offset + id));
          if (grid_file)
            if (Status s = grid_file->write(done.grid.data(), done.grid.size()); !s) fail(s.error());
        }
      }
      done = Pending{true, {}, {}};  // frees the slab
      ++next_commit;
    }
  };

  if (params.progress) params.progress->start(params.name, static_cast<uint64_t>(res - 1));
  parallelFor(static_cast<size_t>(plan.count), threads, [&](size_t s, unsigned) {
    const int first = static_cast<int>(s) * plan.thickness;
    const int last = std::min(first + plan.thickness, res - 1);
    const bool last_slab = last == res - 1;
    Pending result;
    if (!failed) {
      const int grid_planes = grid_file ? last - first + (last_slab ? 1 : 0) : 0;
      SlabField field(params, values, row, first, last, last_slab, grid_planes, grid_bytes);
      McSlabCallbacks callbacks;
      callbacks.load_plane = [&](int p, uint8_t* above) { field.load(p, above); };
      callbacks.edge_vertex = [&](int p, int j, int k, int axis) { return field.vertex(p, j, k, axis); };
      callbacks.plane_done = [&](int p) {
        if (p > first && params.progress) params.progress->advance(1);
        // An interrupt stops every slab at its next plane; nothing more is committed.
        if (interrupted()) failed = true;
        return !failed.load(std::memory_order_relaxed);
      };
      result.mesh = marchingCubesSlab(res, res, first, last, last_slab, callbacks);
      result.grid = field.takeGrid();
    }
    std::lock_guard<std::mutex> lock(mutex);
    result.ready = true;
    pending[s] = std::move(result);
    commitReady();
  });
  if (params.progress) params.progress->finish();
  if (interrupted()) return interruptedError();
  if (failure) return *failure;
  if (grid_file)
    if (Status s = grid_file->commit(); !s) return s.error();
  return mesh;
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
  encodePlane(counts.data(), counts.size(), bytes, encoded.data());
  if (Status s = file->write(encoded.data(), encoded.size()); !s) return s;
  return file->commit();
}

}  // namespace dpoint
