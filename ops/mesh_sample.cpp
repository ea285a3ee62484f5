#include "ops/mesh_sample.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <glm/glm.hpp>

#include "core/interrupt.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "core/random.h"
#include "core/text.h"

namespace dpoint {
namespace {

constexpr uint64_t kBlock = uint64_t{1} << 16;  // samples per work item

// Where sample i fell: its triangle and the barycentric weights of vertices 1 and 2.
struct Placement {
  uint32_t triangle = 0;
  double b = 0.0, c = 0.0;
};

glm::dvec3 vertex(const PointSet& mesh, uint32_t triangle, size_t k) { return mesh.positions[mesh.triangles[3 * size_t{triangle} + k]]; }

// The area of triangle t, from its edges out of vertex 0 (the differences keep a far-off mesh exact).
double triangleArea(const PointSet& mesh, uint32_t t) {
  const glm::dvec3 p0 = vertex(mesh, t, 0);
  return 0.5 * glm::length(glm::cross(vertex(mesh, t, 1) - p0, vertex(mesh, t, 2) - p0));
}

class Sampler {
 public:
  Sampler(const PointSet& mesh, const SampleOptions& options, const std::string& what)
      : mesh_(mesh), options_(options), what_(what) {}

  Status prepare() {
    const size_t triangles = mesh_.triangles.size() / 3;
    if (triangles == 0) return Error{what_ + ": has no triangles to sample (it is a point set)", ExitCode::kUsage};
    if (options_.count == 0) return Error{"--sample 0: must be at least 1", ExitCode::kUsage};
    if (const MeshTexture* t = options_.texture; t && t->textures()) {
      const bool fits = t->uv.size() == mesh_.size() && t->triangle_image.size() == triangles &&
                        std::all_of(t->triangle_image.begin(), t->triangle_image.end(),
                                    [&](int32_t i) { return i < static_cast<int64_t>(t->images.size()); });
      if (!fits) return Error{what_ + ": its texture coordinates do not match its vertices and triangles", ExitCode::kUsage};
    }
    sums_.resize(triangles);
    double sum = 0.0;
    for (size_t t = 0; t < triangles; ++t) {
      for (size_t k = 0; k < 3; ++k) {
        const glm::dvec3 p = vertex(mesh_, static_cast<uint32_t>(t), k);
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
          return Error{what_ + ": triangle " + std::to_string(t) + " has a vertex that is not finite; it cannot be sampled"};
      }
      sum += triangleArea(mesh_, static_cast<uint32_t>(t));
      sums_[t] = sum;
    }
    if (!(sum > 0.0) || !std::isfinite(sum))
      return Error{what_ + ": its triangles have no area (" + formatNumber(sum) + "); nothing to sample on"};
    total_ = sum;
    buildAliasTable();
    return okStatus();
  }

  // Walker's alias table (Vose's construction): triangle k with probability threshold_[k], else
  // alias_[k], gives each its share of the area in O(1) per sample. (A binary search of the running
  // sums took 42% of sampling 10M points from 121,496 triangles, waiting on memory.)
  void buildAliasTable() {
    const size_t n = sums_.size();
    threshold_.assign(n, 0.0);
    alias_.resize(n);
    std::vector<double> scaled(n);
    std::vector<uint32_t> small, large;
    size_t biggest = 0;
    for (size_t t = 0; t < n; ++t) {
      const double area = sums_[t] - (t ? sums_[t - 1] : 0.0);
      scaled[t] = area / total_ * static_cast<double>(n);
      (scaled[t] < 1.0 ? small : large).push_back(static_cast<uint32_t>(t));
      alias_[t] = static_cast<uint32_t>(t);
      if (area > sums_[biggest] - (biggest ? sums_[biggest - 1] : 0.0)) biggest = t;
    }
    while (!small.empty() && !large.empty()) {
      const uint32_t s = small.back(), l = large.back();
      small.pop_back();
      threshold_[s] = scaled[s];
      alias_[s] = l;
      scaled[l] -= 1.0 - scaled[s];
      if (scaled[l] < 1.0) {
        large.pop_back();
        small.push_back(l);
      }
    }
    for (uint32_t t : large) threshold_[t] = 1.0;
    for (uint32_t t : small) threshold_[t] = 1.0;  // rounding's leftovers
    for (size_t t = 0; t < n; ++t)  // a triangle of no area that rounding left over: its column to the largest
      if (threshold_[t] == 1.0 && sums_[t] == (t ? sums_[t - 1] : 0.0))
        threshold_[t] = 0.0, alias_[t] = static_cast<uint32_t>(biggest);
  }

  double total() const { return total_; }

  // Sample i of the stream: a triangle by area (its alias-table column and threshold), a point uniform in it.
  Placement place(uint64_t i) const {
    const uint64_t base = 4 * i;
    const uint64_t column = static_cast<uint64_t>(
        (static_cast<unsigned __int128>(splitmix64At(options_.seed, base)) * threshold_.size()) >> 64);
    const double u = unitInterval(splitmix64At(options_.seed, base + 1));
    const uint32_t t = u < threshold_[column] ? static_cast<uint32_t>(column) : alias_[column];
    const double s = std::sqrt(unitInterval(splitmix64At(options_.seed, base + 2)));
    const double r2 = unitInterval(splitmix64At(options_.seed, base + 3));
    return {t, s * (1.0 - r2), s * r2};
  }

  // Sample i of `count`, stratified (mesh_sample.h).
  Placement placeStratified(uint64_t i, uint64_t count) const {
    const double shift = unitInterval(splitmix64At(options_.seed, 0));
    const double r = (static_cast<double>(i) + shift) / static_cast<double>(count) * total_;
    size_t t = static_cast<size_t>(std::upper_bound(sums_.begin(), sums_.end(), r) - sums_.begin());
    if (t == sums_.size()) t = sums_.size() - 1;  // r rounded up to the total
    while (t > 0 && sums_[t] == sums_[t - 1]) --t;  // never a triangle of no area
    constexpr double kA1 = 0.7548776662466927, kA2 = 0.5698402909980532;  // 1/g, 1/g² (g: the plastic number)
    const double x = static_cast<double>(i);
    const double u1 = 0.5 + x * kA1, u2 = 0.5 + x * kA2;
    // The unit square folded onto the triangle (a point past the diagonal reflected through its
    // centre): both halves map affinely, so the pattern stays as even as R2's. (The sqrt mapping of
    // the uniform draws squeezes it into rows near vertex 0, and the far side of a box showed
    // through the gaps between them.) A reflected R2 point is R2's point −i: no two coincide.
    double b = u1 - std::floor(u1), c = u2 - std::floor(u2);
    if (b + c > 1.0) b = 1.0 - b, c = 1.0 - c;
    return {static_cast<uint32_t>(t), b, c};
  }

  glm::dvec3 position(const Placement& p) const {
    const glm::dvec3 p0 = vertex(mesh_, p.triangle, 0);
    return p0 + p.b * (vertex(mesh_, p.triangle, 1) - p0) + p.c * (vertex(mesh_, p.triangle, 2) - p0);
  }

  // Placements [0, count) and their positions, on all cores.
  void placeAll(uint64_t count, std::vector<Placement>& placements, PositionArray& positions) const {
    placements.resize(static_cast<size_t>(count));
    resizePrefaulted(positions, static_cast<size_t>(count), options_.threads);
    const uint64_t blocks = (count + kBlock - 1) / kBlock;
    parallelFor(static_cast<size_t>(blocks), options_.threads, [&](size_t b, unsigned) {
      if (interrupted()) return;  // the caller checks: the placements are not all made
      const uint64_t first = b * kBlock, last = std::min(count, first + kBlock);
      for (uint64_t i = first; i < last; ++i) {
        placements[i] = options_.method == SampleMethod::kStratified ? placeStratified(i, count) : place(i);
        positions[i] = position(placements[i]);
      }
    });
  }

  // Colours and normals of the kept placements, interpolated over their triangles.
  void finish(const std::vector<Placement>& placements, PointSet& out) const {
    const size_t n = placements.size();
    const MeshTexture* texture = options_.texture && options_.texture->textures() ? options_.texture : nullptr;
    const bool vertex_colors = mesh_.hasColors(), colors = vertex_colors || texture;
    if (colors) out.colors.resize(n);
    const Dimension* vn[3] = {mesh_.dimensions.find(dim::kNormalX), mesh_.dimensions.find(dim::kNormalY),
                              mesh_.dimensions.find(dim::kNormalZ)};
    const bool vertex_normals = vn[0] && vn[1] && vn[2];
    PositionArray normals;  // the vertices' normals, read once out of their columns
    if (vertex_normals) {
      normals.resize(mesh_.size());
      for (size_t v = 0; v < mesh_.size(); ++v) normals[v] = glm::dvec3(vn[0]->value(v), vn[1]->value(v), vn[2]->value(v));
    }
    for (const char* name : {dim::kNormalX, dim::kNormalY, dim::kNormalZ}) out.dimensions.add(name, DimType::kF32, n);
    Dimension* normal[3] = {out.dimensions.find(dim::kNormalX), out.dimensions.find(dim::kNormalY),
                            out.dimensions.find(dim::kNormalZ)};  // found after adding all three: add may move them
    const uint64_t blocks = (n + kBlock - 1) / kBlock;
    parallelFor(static_cast<size_t>(blocks), options_.threads, [&](size_t b, unsigned) {
      const size_t first = b * kBlock, last = std::min<size_t>(n, first + kBlock);
      for (size_t i = first; i < last; ++i) {
        const Placement& p = placements[i];
        const uint32_t* v = &mesh_.triangles[3 * size_t{p.triangle}];
        const double w[3] = {1.0 - p.b - p.c, p.b, p.c};
        if (colors) {
          glm::dvec3 c(1.0);  // white where only the texture colours
          if (vertex_colors) {
            c = glm::dvec3(0.0);
            for (int k = 0; k < 3; ++k) c += w[k] * glm::dvec3(mesh_.colors[v[k]]);
          }
          if (const int32_t image = texture ? texture->triangle_image[p.triangle] : -1; image >= 0) {
            glm::dvec2 uv(0.0);
            for (int k = 0; k < 3; ++k) uv += w[k] * glm::dvec2(texture->uv[v[k]]);
            c *= glm::dvec3(textureColour(texture->images[static_cast<size_t>(image)], uv));
          }
          out.colors[i] = glm::vec3(c);
        }
        glm::dvec3 nrm(0.0);
        if (vertex_normals) {
          for (int k = 0; k < 3; ++k) nrm += w[k] * normals[v[k]];
        }
        if (!vertex_normals || !(glm::length(nrm) > 0.0)) {
          const glm::dvec3 p0 = mesh_.positions[v[0]];
          nrm = glm::cross(mesh_.positions[v[1]] - p0, mesh_.positions[v[2]] - p0);
        }
        const double length = glm::length(nrm);
        if (length > 0.0) nrm /= length;
        for (int k = 0; k < 3; ++k) normal[k]->set<float>(i, static_cast<float>(nrm[k]));
      }
    });
  }

 private:
  const PointSet& mesh_;
  const SampleOptions& options_;
  const std::string& what_;
  std::vector<double> sums_;  // running sums of the triangles' areas
  double total_ = 0.0;
  std::vector<double> threshold_;  // the alias table
  std::vector<uint32_t> alias_;
};

// A grid of cubes twice `radius` on a side over the candidates, for the neighbours within the radius. The
// candidates are renumbered in Morton order of their cells, so a neighbourhood's points lie close
// together in memory (sorted by a hash, the queries of 500,000 candidates were 3× slower, waiting on
// memory); an open-addressing table maps a cell's key to its run.
class CellGrid {
 public:
  CellGrid(const PositionArray& points, double radius, unsigned threads) : radius_(radius), cell_(2.0 * radius) {
    const size_t n = points.size();
    origin_ = points.empty() ? glm::dvec3(0.0) : points[0];
    for (const glm::dvec3& p : points) origin_ = glm::min(origin_, p);
    Keyed keyed(n);
    parallelFor((n + kBlock - 1) / kBlock, threads, [&](size_t b, unsigned) {
      for (size_t i = b * kBlock; i < std::min<size_t>(n, (b + 1) * kBlock); ++i)
        keyed[i] = {keyOf(cellOf(points[i])), static_cast<uint32_t>(i)};
    });
    if (!sortByKey(keyed)) return;  // interrupted: the caller checks
    original_.resize(n);
    points_.resize(n);
    size_t runs = 0;
    for (size_t i = 0; i < n; ++i) {
      original_[i] = keyed[i].second;
      points_[i] = points[keyed[i].second];
      runs += i == 0 || keyed[i].first != keyed[i - 1].first;
    }
    size_t capacity = 16;
    while (capacity < 2 * runs) capacity *= 2;
    mask_ = capacity - 1;
    table_.assign(capacity, Slot{});
    for (size_t i = 0; i < n;) {
      size_t j = i;
      while (j < n && keyed[j].first == keyed[i].first) ++j;
      size_t s = splitmixMix(keyed[i].first) & mask_;
      while (table_[s].end != 0) s = (s + 1) & mask_;
      table_[s] = {keyed[i].first, static_cast<uint32_t>(i), static_cast<uint32_t>(j)};
      i = j;
    }
  }

  size_t size() const { return points_.size(); }
  // The index in the caller's vector of the grid's point k.
  uint32_t original(size_t k) const { return original_[k]; }

  // fn(j, d²) for every grid point j ≠ i within the radius of grid point i that `alive` admits, in a fixed order.
  template <typename Alive, typename Fn>
  void neighbours(uint32_t i, const Alive& alive, const Fn& fn) const {
    const glm::dvec3& p = points_[i];
    // Cells of twice the radius: the ball around p meets at most two of them along each axis, eight
    // in all, where cells of the radius take 27 lookups, each a miss in the table.
    const glm::i64vec3 lo = cellOf(p - radius_), hi = cellOf(p + radius_);
    const double r2 = radius_ * radius_;
    for (int64_t x = lo.x; x <= hi.x; ++x)
      for (int64_t y = lo.y; y <= hi.y; ++y)
        for (int64_t z = lo.z; z <= hi.z; ++z) {
          const glm::i64vec3 n(x, y, z);
          if (n.x < 0 || n.y < 0 || n.z < 0) continue;
          const uint64_t key = keyOf(n);
          for (size_t s = splitmixMix(key) & mask_; table_[s].end != 0; s = (s + 1) & mask_) {
            if (table_[s].key != key) continue;
            for (uint32_t j = table_[s].begin; j < table_[s].end; ++j) {
              if (j == i || !alive(j)) continue;
              const glm::dvec3 d = points_[j] - p;
              const double d2 = glm::dot(d, d);
              if (d2 <= r2) fn(j, d2);
            }
            break;
          }
        }
  }

 private:
  struct Slot {
    uint64_t key = 0;
    uint32_t begin = 0, end = 0;  // end 0: empty
  };
  struct KeyIndex {  // trivial, so the arrays below are not zeroed before they are written
    uint64_t first;   // the cell's key
    uint32_t second;  // the candidate's index
  };
  using Keyed = std::vector<KeyIndex, DefaultInitAllocator<KeyIndex>>;
  // Sorts (key, index) pairs whose indices ascend, as std::sort would: by key, then index. An LSD
  // radix sort, 11 bits a pass over the bits the keys use (stable, so equal keys keep their indices'
  // order): the grid of 10M candidates took 2.3 -> 1.4 s against std::sort, which could not stop
  // for Ctrl-C in between. False when interrupted.
  static bool sortByKey(Keyed& keyed) {
    constexpr int kBits = 11;
    constexpr size_t kBuckets = size_t{1} << kBits;
    uint64_t used = 0;
    for (const auto& k : keyed) used |= k.first;
    Keyed other(keyed.size());
    for (int shift = 0; shift < 64 && (used >> shift) != 0; shift += kBits) {
      if (interrupted()) return false;
      std::vector<size_t> start(kBuckets + 1, 0);
      for (const auto& k : keyed) ++start[((k.first >> shift) & (kBuckets - 1)) + 1];
      for (size_t b = 0; b < kBuckets; ++b) start[b + 1] += start[b];
      for (const auto& k : keyed) other[start[(k.first >> shift) & (kBuckets - 1)]++] = k;
      keyed.swap(other);
    }
    return true;
  }
  glm::i64vec3 cellOf(const glm::dvec3& p) const {
    return glm::i64vec3(static_cast<int64_t>((p.x - origin_.x) / cell_), static_cast<int64_t>((p.y - origin_.y) / cell_),
                        static_cast<int64_t>((p.z - origin_.z) / cell_));
  }
  // The Morton code of the cell's three coordinates (21 bits each); beyond 2^21 cells on an axis the
  // bits wrap and distinct cells share a key, which costs time only: neighbours() measures every distance.
  static uint64_t spread(uint64_t v) {
    v &= 0x1FFFFF;
    v = (v | v << 32) & 0x1F00000000FFFFull;
    v = (v | v << 16) & 0x1F0000FF0000FFull;
    v = (v | v << 8) & 0x100F00F00F00F00Full;
    v = (v | v << 4) & 0x10C30C30C30C30C3ull;
    return (v | v << 2) & 0x1249249249249249ull;
  }
  static uint64_t keyOf(const glm::i64vec3& c) {
    return spread(static_cast<uint64_t>(c.x)) | spread(static_cast<uint64_t>(c.y)) << 1 | spread(static_cast<uint64_t>(c.z)) << 2;
  }

  double radius_, cell_;
  glm::dvec3 origin_{0.0};
  PositionArray points_;  // in grid order
  std::vector<uint32_t, DefaultInitAllocator<uint32_t>> original_;
  std::vector<Slot, DefaultInitAllocator<Slot>> table_;
  size_t mask_ = 0;
};

// The elimination's max-heap: 4-ary, so a sift down visits half the levels of a binary heap, and
// laid out so that the four children of a node share one 64-byte line (the root at slot 3 of a
// 2 MiB-aligned block, where it is that large). Its 10M entries of a 2M-point sample are far beyond
// the caches, each level a miss: the elimination took 84 -> 65 s against std::priority_queue's
// binary heap (2-core VM, ops/mesh_sample.h).
class EliminationHeap {
 public:
  struct Entry {
    double weight;
    uint32_t original, index;
    // The heavier first; of equal weights, the lower original index.
    bool before(const Entry& e) const { return weight > e.weight || (weight == e.weight && original < e.original); }
  };
  explicit EliminationHeap(size_t n) : slots_(n + kPad), size_(n) {}
  Entry& operator[](size_t k) { return slots_[k + kPad]; }
  void make() {
    for (size_t i = size_ / kWays + 1; i-- > 0;) siftDown(i);
  }
  const Entry& top() const { return slots_[kPad]; }
  void replaceTop(const Entry& e) {
    (*this)[0] = e;
    siftDown(0);
  }
  void pop() {
    (*this)[0] = (*this)[--size_];
    siftDown(0);
  }

 private:
  static constexpr size_t kWays = 4, kPad = kWays - 1;  // children of i: kWays·i + 1 .. kWays·i + kWays
  void siftDown(size_t i) {
    if (i >= size_) return;
    const Entry moving = (*this)[i];
    for (;;) {
      const size_t first = kWays * i + 1;
      if (first >= size_) break;
      // The children's own children: one line each, fetched while these four are compared.
      for (size_t c = first; c < first + kWays && kWays * c + 1 < size_; ++c) __builtin_prefetch(&(*this)[kWays * c + 1]);
      size_t best = first;
      for (size_t c = first + 1; c < std::min(first + kWays, size_); ++c)
        if ((*this)[c].before((*this)[best])) best = c;
      if (!(*this)[best].before(moving)) break;
      (*this)[i] = (*this)[best];
      i = best;
    }
    (*this)[i] = moving;
  }
  std::vector<Entry, DefaultInitAllocator<Entry>> slots_;
  size_t size_;
};

// The indices of the `keep` candidates left by weighted sample elimination, ascending.
std::vector<uint32_t> eliminate(const PositionArray& candidates, uint64_t keep, double area, unsigned threads,
                                Progress* progress) {
  const size_t m = candidates.size();
  const double r_max = 2.0 * std::sqrt(area / static_cast<double>(keep) / (2.0 * std::sqrt(3.0)));
  const double ratio = static_cast<double>(keep) / static_cast<double>(m);
  const double r_min = r_max * 0.5 * (1.0 - std::pow(ratio, 1.5));
  const auto weight = [&](double d2) {
    const double d = std::max(std::sqrt(d2), r_min);
    const double x = 1.0 - d / r_max;
    const double x2 = x * x, x4 = x2 * x2;
    return x4 * x4;  // alpha = 8
  };
  const CellGrid grid(candidates, r_max, threads);
  if (interrupted()) return {};  // the grid is not made; the caller checks
  std::vector<uint8_t, DefaultInitAllocator<uint8_t>> deleted(m, 0);
  const auto alive = [&](uint32_t j) { return deleted[j] == 0; };
  std::vector<double, DefaultInitAllocator<double>> w(m, 0.0);
  parallelFor((m + kBlock - 1) / kBlock, threads, [&](size_t b, unsigned) {
    if (interrupted()) return;  // the caller checks: its weights are not all made
    for (size_t i = b * kBlock; i < std::min<size_t>(m, (b + 1) * kBlock); ++i) {
      double sum = 0.0;
      grid.neighbours(static_cast<uint32_t>(i), alive, [&](uint32_t, double d2) { sum += weight(d2); });
      w[i] = sum;
    }
  });
  if (interrupted()) return {};
  // A max-heap on (weight, then the lower original index), updated lazily: weights only fall, so an
  // entry whose weight is out of date is given its weight when it comes to the top, and the entry
  // removed is always the heaviest point as it is now; (weight, original index) orders every point,
  // so that is one sequence whatever the heap's shape. (Sinking every neighbour's entry at each
  // removal took 85% of the time.)
  EliminationHeap heap(m);
  for (size_t k = 0; k < m; ++k) heap[k] = {w[k], grid.original(k), static_cast<uint32_t>(k)};
  heap.make();
  const uint64_t removals = m - keep;
  if (progress) progress->start("Poisson-disk elimination", removals);
  for (uint64_t r = 0; r < removals;) {
    const EliminationHeap::Entry top = heap.top();
    if (top.weight != w[top.index]) {
      heap.replaceTop({w[top.index], top.original, top.index});
      continue;
    }
    heap.pop();
    deleted[top.index] = 1;
    grid.neighbours(top.index, alive, [&](uint32_t j, double d2) { w[j] -= weight(d2); });
    ++r;
    if (r % kBlock == 0) {
      if (interrupted()) return {};  // Ctrl-C stops a long elimination (41 s for 1M from Python); the caller checks
      if (progress) progress->advance(kBlock);
    }
  }
  std::vector<uint32_t> kept;
  kept.reserve(static_cast<size_t>(keep));
  for (size_t k = 0; k < m; ++k)
    if (!deleted[k]) kept.push_back(grid.original(k));
  std::sort(kept.begin(), kept.end());
  return kept;
}

}  // namespace

Result<SampleMethod> parseSampleMethod(std::string_view text) {
  if (text == "uniform") return SampleMethod::kUniform;
  if (text == "poisson") return SampleMethod::kPoisson;
  if (text == "stratified") return SampleMethod::kStratified;
  return Error{"--sample-method " + quotedExcerpt(text) + ": expected uniform, poisson or stratified", ExitCode::kUsage};
}

double surfaceArea(const PointSet& mesh) {
  double sum = 0.0;
  for (size_t t = 0; t < mesh.triangles.size() / 3; ++t) sum += triangleArea(mesh, static_cast<uint32_t>(t));
  return sum;
}

double medianTriangleEdge(const PointSet& mesh) {
  std::vector<std::pair<double, double>> edges;  // longest edge, area
  edges.reserve(mesh.triangles.size() / 3);
  double total = 0.0;
  for (uint32_t t = 0; t < mesh.triangles.size() / 3; ++t) {
    const glm::dvec3 a = vertex(mesh, t, 0), b = vertex(mesh, t, 1), c = vertex(mesh, t, 2);
    const double area = triangleArea(mesh, t);
    if (!(area > 0.0)) continue;
    edges.emplace_back(std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)}), area);
    total += area;
  }
  std::sort(edges.begin(), edges.end());
  double running = 0.0;
  for (const auto& [edge, area] : edges)
    if ((running += area) >= 0.5 * total) return edge;
  return 0.0;
}

Result<PointSet> sampleSurface(const PointSet& mesh, const SampleOptions& options, const std::string& what) {
  Sampler sampler(mesh, options, what);
  if (Status s = sampler.prepare(); !s) return s.error();
  const bool poisson = options.method == SampleMethod::kPoisson;
  if (poisson && !(options.poisson_factor >= 1.0))
    return Error{"Poisson sampling needs at least as many candidates as points (factor " +
                     formatNumber(options.poisson_factor) + ")",
                 ExitCode::kUsage};
  const double factor = poisson ? options.poisson_factor : 1.0;
  const double drawn = std::ceil(static_cast<double>(options.count) * factor);
  // Placements and positions of every candidate, the weights, heap and grid of Poisson's.
  const double per_candidate = poisson ? sizeof(Placement) + sizeof(glm::dvec3) + 8 + 8 + 4 * 4 + 16 + 1
                                       : sizeof(Placement) + sizeof(glm::dvec3);
  const bool colors = mesh.hasColors() || (options.texture && options.texture->textures());
  const double per_point = sizeof(glm::dvec3) + (colors ? sizeof(glm::vec3) : 0) + 3 * sizeof(float);
  const double bytes = drawn * per_candidate + static_cast<double>(options.count) * per_point;
  if (!(drawn < 4.0e9) || bytes > 1.8e19)
    return Error{what + ": " + std::to_string(options.count) + " samples are beyond any memory", ExitCode::kResourceLimit};
  if (Status s = checkMemory(what + ": " + std::to_string(options.count) + " samples", static_cast<uint64_t>(bytes),
                             options.max_memory);
      !s)
    return s.error();
  if (poisson && drawn > 4294967295.0)
    return Error{what + ": Poisson sampling takes at most 2^32 candidates", ExitCode::kResourceLimit};

  PointSet out;
  out.z_axis = ZAxis::kPresent;
  out.z_up = mesh.z_up;
  out.color_full_scale = mesh.color_full_scale;
  out.crs = mesh.crs;  // the surface's coordinate system is the points'
  std::vector<Placement> placements;
  sampler.placeAll(static_cast<uint64_t>(drawn), placements, out.positions);
  if (interrupted()) return interruptedError();
  if (poisson) {
    const std::vector<uint32_t> kept = eliminate(out.positions, options.count, sampler.total(), options.threads, options.progress);
    if (interrupted()) return interruptedError();
    std::vector<Placement> chosen(kept.size());
    PositionArray positions(kept.size());
    for (size_t k = 0; k < kept.size(); ++k) {
      chosen[k] = placements[kept[k]];
      positions[k] = out.positions[kept[k]];
    }
    placements = std::move(chosen);
    out.positions = std::move(positions);
  }
  sampler.finish(placements, out);
  if (options.faces) {
    options.faces->resize(placements.size());
    for (size_t i = 0; i < placements.size(); ++i) (*options.faces)[i] = placements[i].triangle;
  }
  return out;
}

}  // namespace dpoint
