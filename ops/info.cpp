#include "ops/info.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cfloat>
#include <cmath>
#include <limits>
#include <memory>
#include <span>
#include <tuple>
#include <unordered_map>
#include <utility>

#include <glm/common.hpp>
#include <glm/ext/vector_int3_sized.hpp>

#include "core/interrupt.h"
#include "core/parallel.h"
#include "ops/point_spacing.h"

namespace dpoint {
namespace {

// Squared distance from q to the box [lo, hi] (0 inside it, and where a non-finite coordinate
// makes it undefined: such a box is never passed over, and the sort by distance stays ordered).
double boxDistance2(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& q) {
  const glm::dvec3 outside = glm::max(glm::dvec3(0.0), glm::max(lo - q, q - hi));
  const double d2 = outside.x * outside.x + outside.y * outside.y + outside.z * outside.z;
  return std::isnan(d2) ? 0.0 : d2;
}

// Bounds of points (not empty).
std::pair<glm::dvec3, glm::dvec3> boxOf(std::span<const glm::dvec3> points) {
  glm::dvec3 lo = points[0], hi = points[0];
  for (const glm::dvec3& p : points) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  return {lo, hi};
}

// A k-d tree laid out in place in the points it is given (reordered, not owned): the median of
// each range sits at its middle, split along the axis of largest extent, which is recorded at the
// median's index. Leaves are small ranges. Points with a non-finite coordinate are left out (no
// distance to them counts, and they would break the median's ordering).
class KdTree {
 public:
  explicit KdTree(std::span<glm::dvec3> points) {
    const auto finite = std::partition(points.begin(), points.end(), [](const glm::dvec3& p) { return isFinite(p); });
    pts_ = points.first(static_cast<size_t>(finite - points.begin()));
    axis_.assign(pts_.size(), 0);
    if (pts_.empty()) return;
    std::tie(min_, max_) = boxOf(pts_);
    build(0, pts_.size());
  }

  double boxDistance2(const glm::dvec3& q) const {
    return pts_.empty() ? std::numeric_limits<double>::infinity() : dpoint::boxDistance2(min_, max_, q);
  }

  // Lowers best2 to the smallest squared distance > 0 from q to a point of the tree, if smaller.
  void nearestNonzero(const glm::dvec3& q, double& best2) const {
    if (!pts_.empty()) search(0, pts_.size(), q, best2);
  }

 private:
  static constexpr size_t kLeaf = 8;
  // The axis recorded for a range whose points are all the same point. Without it, a query at a
  // point repeated m times visited all m (none counts: their distance is 0), and `info` of 2M
  // copies of one point beside one other took minutes.
  static constexpr uint8_t kSame = 3;

  void build(size_t lo, size_t hi) {
    if (hi - lo <= kLeaf) return;
    const auto [mn, mx] = boxOf(pts_.subspan(lo, hi - lo));
    if (mn == mx) {  // one point many times over: a search visits it once
      axis_[lo + (hi - lo) / 2] = kSame;
      return;
    }
    const glm::dvec3 size = mx - mn;
    const int axis = size.x >= size.y && size.x >= size.z ? 0 : (size.y >= size.z ? 1 : 2);
    const size_t mid = lo + (hi - lo) / 2;
    std::nth_element(pts_.begin() + static_cast<ptrdiff_t>(lo), pts_.begin() + static_cast<ptrdiff_t>(mid),
                     pts_.begin() + static_cast<ptrdiff_t>(hi),
                     [axis](const glm::dvec3& a, const glm::dvec3& b) { return a[axis] < b[axis]; });
    axis_[mid] = static_cast<uint8_t>(axis);
    build(lo, mid);
    build(mid + 1, hi);
  }

  void visit(const glm::dvec3& p, const glm::dvec3& q, double& best) const {
    const glm::dvec3 d = p - q;
    const double d2 = d.x * d.x + d.y * d.y + d.z * d.z;
    if (d2 > 0.0 && d2 < best) best = d2;
  }

  void search(size_t lo, size_t hi, const glm::dvec3& q, double& best) const {
    if (hi - lo <= kLeaf) {
      for (size_t i = lo; i < hi; ++i) visit(pts_[i], q, best);
      return;
    }
    const size_t mid = lo + (hi - lo) / 2;
    const int axis = axis_[mid];
    visit(pts_[mid], q, best);
    if (axis == kSame) return;
    const double diff = q[axis] - pts_[mid][axis];
    // Points left of mid are <= the median along the axis, points right of it >= it. The far side
    // is searched only where it may hold a point strictly nearer than `best` (visit keeps only
    // those): on a grid of copied points, ties at `best` made most of the visits (a review finding).
    if (diff <= 0.0) {
      search(lo, mid, q, best);
      if (diff * diff < best) search(mid + 1, hi, q, best);
    } else {
      search(mid + 1, hi, q, best);
      if (diff * diff < best) search(lo, mid, q, best);
    }
  }

  std::span<glm::dvec3> pts_;
  std::vector<uint8_t> axis_;
  glm::dvec3 min_{0.0}, max_{0.0};
};

// Points in one k-d tree of a Forest: small enough that a set's trees build in parallel, large
// enough that the box tests stay few.
constexpr size_t kTreePoints = size_t{1} << 20;

// Points on each side of a sampled point, in file order, that give the first bound on its nearest
// distance in a streamed set.
constexpr size_t kFileNeighbors = 8;

// k-d trees over consecutive ranges of a set of points (reordered within each range), built in
// parallel; the smallest distance over the trees is the one over the set, whatever the ranges.
// At Ctrl-C the trees left are not built, and a search passes over them (its caller checks
// interrupted()): 12M points on one core took 4 s to stop before.
class Forest {
 public:
  Forest(std::span<glm::dvec3> points, unsigned threads) {
    const size_t n = points.size();
    trees_.resize((n + kTreePoints - 1) / kTreePoints);
    parallelFor(trees_.size(), threads, [&](size_t t, unsigned) {
      if (interrupted()) return;
      const size_t first = t * kTreePoints;
      trees_[t] = std::make_unique<KdTree>(points.subspan(first, std::min(kTreePoints, n - first)));
    });
  }

  // Lowers each best2[k] to the smallest squared distance > 0 from queries[k] to the points. The
  // trees are searched nearest box first, and only while their box is within the best distance:
  // a query far from a tree (a thin slab of a file in slab order) would visit much of it.
  void nearestNonzero(std::span<const glm::dvec3> queries, std::span<double> best2, unsigned threads) const {
    parallelFor(queries.size(), threads, [&](size_t k, unsigned) {
      if (interrupted()) return;  // its caller checks (describePoints): Ctrl-C within a query's time
      std::vector<std::pair<double, size_t>> order(trees_.size());
      for (size_t t = 0; t < trees_.size(); ++t)
        order[t] = {trees_[t] ? trees_[t]->boxDistance2(queries[k]) : std::numeric_limits<double>::infinity(), t};
      std::sort(order.begin(), order.end());
      for (const auto& [distance2, t] : order) {
        if (distance2 >= best2[k]) break;  // no point there is strictly nearer
        trees_[t]->nearestNonzero(queries[k], best2[k]);
      }
    });
  }

 private:
  std::vector<std::unique_ptr<KdTree>> trees_;
};

// The smallest of the sampled nearest distances (best2: squared), 0 when none is finite.
double smallestDistance(const std::vector<double>& best2) {
  const double smallest = *std::min_element(best2.begin(), best2.end());
  return std::isfinite(smallest) ? std::sqrt(smallest) : 0.0;
}

// Counts distinct points that float32 rounding merges with another distinct point (of the finite
// ones: a NaN would break the sort's ordering): in each run of equal float32 points, each distinct
// double point past the first. The points are dealt into buckets by a hash of their float32 point
// (a run is never split), each bucket sorted on its own, on all cores; at Ctrl-C the buckets left
// are passed over (the caller checks interrupted()).
size_t countFloatMerges(const PositionArray& positions, unsigned threads) {
  const size_t n = positions.size();
  // Points a worker deals at once: 65,536, or more where there would be over 1024 pieces (each
  // piece keeps a count and a place per bucket).
  const size_t piece_points = std::max<size_t>(size_t{1} << 16, (n + 1023) / 1024);
  const size_t pieces = (n + piece_points - 1) / piece_points;
  const unsigned buckets = static_cast<unsigned>(std::bit_ceil(std::clamp<size_t>(n / 4096, 1, 4096)));
  const auto as_float = [&](uint32_t i) { return glm::vec3(positions[i]) + 0.0f; };  // -0 as +0: they are equal
  const auto bucketOf = [&](const glm::vec3& f) {
    uint64_t h = 0;
    for (int k = 0; k < 3; ++k) h = (h ^ std::bit_cast<uint32_t>(f[k])) * 0x9E3779B97F4A7C15ull;
    return static_cast<unsigned>((h >> 40) & (buckets - 1));
  };
  // Each piece's count per bucket, then where its points of each bucket go.
  std::vector<uint32_t> counts(pieces * buckets, 0);
  parallelFor(pieces, threads, [&](size_t piece, unsigned) {
    uint32_t* c = counts.data() + piece * buckets;
    for (size_t i = piece * piece_points, end = std::min(n, i + piece_points); i < end; ++i)
      if (isFinite(positions[i])) ++c[bucketOf(as_float(static_cast<uint32_t>(i)))];
  });
  std::vector<size_t> bucket_begin(buckets + 1, 0), at(pieces * buckets);
  size_t total = 0;
  for (unsigned b = 0; b < buckets; ++b) {
    bucket_begin[b] = total;
    for (size_t piece = 0; piece < pieces; ++piece) at[piece * buckets + b] = total, total += counts[piece * buckets + b];
  }
  bucket_begin[buckets] = total;
  std::vector<uint32_t> order(total);
  parallelFor(pieces, threads, [&](size_t piece, unsigned) {
    size_t* a = at.data() + piece * buckets;
    for (size_t i = piece * piece_points, end = std::min(n, i + piece_points); i < end; ++i)
      if (isFinite(positions[i])) order[a[bucketOf(as_float(static_cast<uint32_t>(i)))]++] = static_cast<uint32_t>(i);
  });
  const auto less_float = [](const glm::vec3& a, const glm::vec3& b) {
    return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
  };
  const auto less_double = [](const glm::dvec3& a, const glm::dvec3& b) {
    return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
  };
  const auto less_point = [&](uint32_t x, uint32_t y) {
    const glm::vec3 fx = as_float(x), fy = as_float(y);
    if (less_float(fx, fy)) return true;
    if (less_float(fy, fx)) return false;
    return less_double(positions[x], positions[y]);
  };
  // A bucket of more than a core's share (points that round to a few float32 points: a small
  // extent far from the origin, a deep zoom) is sorted on all cores: its pieces at once, then
  // merged pair by pair. As one bucket it took one core (10M such points: info 9.0 s, now 6.3 s on
  // this VM's two; bench/results/2026-12-02/cpu/info-copies.md).
  const unsigned workers = resolveThreads(threads);
  const size_t big = std::max<size_t>(size_t{1} << 16, total / (2 * workers) + 1);
  std::vector<uint8_t> sorted(buckets, 0);
  for (unsigned b = 0; b < buckets && workers > 1; ++b) {
    const size_t size = bucket_begin[b + 1] - bucket_begin[b];
    if (size < big || interrupted()) continue;
    const size_t pieces_of = workers, step = (size + pieces_of - 1) / pieces_of;
    const auto edge = [&](size_t k) { return order.begin() + static_cast<ptrdiff_t>(bucket_begin[b] + std::min(size, k * step)); };
    parallelFor(pieces_of, threads, [&](size_t k, unsigned) {
      if (!interrupted()) std::sort(edge(k), edge(k + 1), less_point);
    });
    for (size_t width = 1; width < pieces_of && !interrupted(); width *= 2)
      parallelFor((pieces_of + 2 * width - 1) / (2 * width), threads, [&](size_t pair, unsigned) {
        const size_t k = pair * 2 * width;
        if (k + width < pieces_of) std::inplace_merge(edge(k), edge(k + width), edge(std::min(pieces_of, k + 2 * width)), less_point);
      });
    sorted[b] = 1;
  }
  std::vector<size_t> merged(buckets, 0);
  parallelFor(buckets, threads, [&](size_t b, unsigned) {
    if (interrupted()) return;
    const auto first = order.begin() + static_cast<ptrdiff_t>(bucket_begin[b]);
    const auto last = order.begin() + static_cast<ptrdiff_t>(bucket_begin[b + 1]);
    if (!sorted[b]) std::sort(first, last, less_point);
    // Within a run of equal floats, every change of the double value is one more merged point.
    for (auto k = first + (first != last); k < last; ++k)
      if (as_float(k[-1]) == as_float(*k) && positions[k[-1]] != positions[*k]) ++merged[b];
  });
  size_t sum = 0;
  for (size_t m : merged) sum += m;
  return sum;
}

// Bounds and float overflow of `positions` into `info` (min and max start empty: noBounds). A NaN
// coordinate has no place in them: it is passed over (with --allow-nonfinite it made the bounds
// NaN or not by the points' order).
void addBounds(PointSetInfo& info, const PositionArray& positions) {
  for (const glm::dvec3& p : positions) {
    info.nonfinite += !isFinite(p);
    for (int k = 0; k < 3; ++k) {
      if (std::isnan(p[k])) continue;
      info.min[k] = std::min(info.min[k], p[k]);
      info.max[k] = std::max(info.max[k], p[k]);
      if (std::fabs(p[k]) > static_cast<double>(FLT_MAX)) ++info.float_overflow;
    }
  }
}

// Empty bounds, which any coordinate widens.
void noBounds(PointSetInfo& info) {
  info.min = glm::dvec3(std::numeric_limits<double>::infinity());
  info.max = glm::dvec3(-std::numeric_limits<double>::infinity());
}

// Extent, largest magnitude and float32's spacing there, from the bounds (an axis of NaNs only: NaN).
void finishBounds(PointSetInfo& info) {
  for (int k = 0; k < 3; ++k)
    if (info.min[k] > info.max[k]) info.min[k] = info.max[k] = std::numeric_limits<double>::quiet_NaN();
  info.extent = info.max - info.min;
  info.max_abs = std::max({std::fabs(info.min.x), std::fabs(info.min.y), std::fabs(info.min.z),
                           std::fabs(info.max.x), std::fabs(info.max.y), std::fabs(info.max.z)});
  // The spacing of float32 at max_abs: the gap above the float nearest to it.
  const float f = static_cast<float>(info.max_abs);
  info.float_spacing = std::isfinite(f)
      ? static_cast<double>(std::nextafter(f, std::numeric_limits<float>::infinity())) - static_cast<double>(f)
      : std::numeric_limits<double>::infinity();
}

// out[i] = in[i] · unit for every point, on `threads` cores (out may be in): the points in a unit of
// length (lengthUnit).
void scalePositions(const PositionArray& in, PositionArray& out, double unit, unsigned threads) {
  const size_t n = in.size();
  out.resize(n);
  parallelFor((n + (size_t{1} << 16) - 1) >> 16, threads, [&](size_t b, unsigned) {
    for (size_t i = b << 16, end = std::min(n, (b + 1) << 16); i < end; ++i) out[i] = in[i] * unit;
  });
}

// The difference from points[at] to the nearest of points[from..to] apart from it (0 where none
// is, or none at a finite difference): the first bound on a sampled point's nearest distance in a
// streamed set. Compared in a unit of their own (a power of two, exact), as the set's unit is not
// known yet: squares of raw differences at 1e-200 are 0 and at 1e200 infinite.
glm::dvec3 nearestBeside(const PositionArray& points, size_t from, size_t to, size_t at) {
  double largest = 0.0;
  for (size_t j = from; j <= to; ++j) {
    const glm::dvec3 d = points[j] - points[at];
    if (std::isfinite(d.x) && std::isfinite(d.y) && std::isfinite(d.z))
      largest = std::max({largest, std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
  }
  if (largest == 0.0) return glm::dvec3(0.0);
  const double local = std::ldexp(1.0, -std::ilogb(largest));
  double best2 = std::numeric_limits<double>::infinity();
  glm::dvec3 nearest(0.0);
  for (size_t j = from; j <= to; ++j) {
    const glm::dvec3 d = points[j] - points[at], s = d * local;
    const double d2 = s.x * s.x + s.y * s.y + s.z * s.z;  // NaN where d is not finite: passed over
    if (d2 > 0.0 && d2 < best2) best2 = d2, nearest = d;
  }
  return nearest;
}

// Boxes without queries that a run of boxes read again may span.
constexpr size_t kJoinBoxes = 16;

// The sampled points' balls (radius² best2) on a grid over the set's box, for the boxes and points
// that may hold a point nearer a sample than its bound. The grid's cell is the median box's longest
// side, so most boxes span a cell or two along each axis. A ball is listed in the cells its box
// spans and one more each side (a coordinate's cell is rounded; the slack covers that), or, where
// that is many cells, with every query.
class SampleBalls {
 public:
  SampleBalls(const PositionArray& samples, const std::vector<double>& best2, const glm::dvec3& min,
              const glm::dvec3& max, const std::vector<Box>& boxes)
      : samples_(samples), best2_(best2), min_(min) {
    const glm::dvec3 extent = max - min;
    const double largest = std::max({extent.x, extent.y, extent.z});
    std::vector<double> sides;
    const size_t step = std::max<size_t>(1, boxes.size() / 4096);
    for (size_t b = 0; b < boxes.size(); b += step) {
      const glm::dvec3 side = boxes[b].max - boxes[b].min;
      sides.push_back(std::max({side.x, side.y, side.z}));
    }
    std::nth_element(sides.begin(), sides.begin() + static_cast<ptrdiff_t>(sides.size() / 2), sides.end());
    const double median = sides.empty() ? 0.0 : sides[sides.size() / 2];
    compact_ = median <= largest / 16.0;
    cell_ = std::max(median, largest / kCells);
    if (!(cell_ > 0.0) || !std::isfinite(cell_)) cell_ = 1.0;
    for (uint32_t k = 0; k < samples.size(); ++k) {
      const double r = std::sqrt(best2[k]);
      glm::i64vec3 lo, hi;
      if (!cellRange(samples[k] - r, samples[k] + r, lo, hi, 1)) {
        everywhere_.push_back(k);
        continue;
      }
      for (int64_t z = lo.z; z <= hi.z; ++z)
        for (int64_t y = lo.y; y <= hi.y; ++y)
          for (int64_t x = lo.x; x <= hi.x; ++x) cells_[key(x, y, z)].push_back(k);
    }
  }

  // Whether the median box spans at most a 16th of the set (a file in some spatial order).
  bool compact() const { return compact_; }

  // The samples whose ball reaches the box [lo, hi], into `out`; false (out empty) where the box
  // spans too many cells to look up: then each of its points is looked up (pointQueries).
  bool near(const glm::dvec3& lo, const glm::dvec3& hi, std::vector<uint32_t>& out) const {
    out.clear();
    glm::i64vec3 a, b;
    if (!cellRange(lo, hi, a, b, 0)) return false;
    for (int64_t z = a.z; z <= b.z; ++z)
      for (int64_t y = a.y; y <= b.y; ++y)
        for (int64_t x = a.x; x <= b.x; ++x)
          if (auto it = cells_.find(key(x, y, z)); it != cells_.end())
            out.insert(out.end(), it->second.begin(), it->second.end());
    out.insert(out.end(), everywhere_.begin(), everywhere_.end());
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    std::erase_if(out, [&](uint32_t k) { return !(boxDistance2(lo, hi, samples_[k]) <= best2_[k]); });
    return true;
  }

  // Lowers found[k] to the smallest squared distance > 0 from sample k to the points, for the
  // samples listed in each point's cell.
  void pointQueries(std::span<const glm::dvec3> points, std::vector<double>& found) const {
    for (const glm::dvec3& p : points) {
      glm::i64vec3 c, same;
      if (!cellRange(p, p, c, same, 0)) continue;  // not finite: no distance
      const auto visit = [&](uint32_t k) {
        const glm::dvec3 d = p - samples_[k];
        const double d2 = d.x * d.x + d.y * d.y + d.z * d.z;
        if (d2 > 0.0 && d2 < found[k]) found[k] = d2;
      };
      if (auto it = cells_.find(key(c.x, c.y, c.z)); it != cells_.end())
        for (uint32_t k : it->second) visit(k);
      for (uint32_t k : everywhere_) visit(k);
    }
  }

 private:
  static constexpr double kCells = double(1 << 20);  // at most, along the set's longest side
  static constexpr int64_t kMostCells = 64;  // a box or ball over more is not looked up by cell
  static uint64_t key(int64_t x, int64_t y, int64_t z) { return uint64_t(x) | uint64_t(y) << 21 | uint64_t(z) << 42; }
  bool cellRange(const glm::dvec3& lo, const glm::dvec3& hi, glm::i64vec3& a, glm::i64vec3& b, int64_t slack) const {
    int64_t cells = 1;
    for (int k = 0; k < 3; ++k) {
      const double from = std::floor((lo[k] - min_[k]) / cell_), to = std::floor((hi[k] - min_[k]) / cell_);
      if (!std::isfinite(from) || !std::isfinite(to)) return false;
      a[k] = std::max<int64_t>(static_cast<int64_t>(std::clamp(from, 0.0, kCells)) - slack, 0);
      b[k] = std::min<int64_t>(static_cast<int64_t>(std::clamp(to, 0.0, kCells)) + slack, int64_t(kCells));
      cells *= b[k] - a[k] + 1;
      if (cells > kMostCells) return false;
    }
    return true;
  }

  const PositionArray& samples_;
  const std::vector<double>& best2_;
  glm::dvec3 min_;
  double cell_ = 1.0;
  bool compact_ = false;
  std::unordered_map<uint64_t, std::vector<uint32_t>> cells_;
  std::vector<uint32_t> everywhere_;
};

// Pass 2 of computeStreamedInfo on a file whose boxes are compact (Morton or slab order): the boxes
// within some sampled point's bound are read again, each against those samples, and the boxes
// too wide to look up point by point; every point nearer a sample than its bound lies in one.
Status nearestByBoxes(uint64_t count, const BlockReader& read, uint64_t block_points, uint64_t box_points,
                      const PositionArray& sampled,
                      std::vector<double>& best2, const SampleBalls& balls, const std::vector<uint8_t>& wide,
                      const std::vector<std::vector<uint32_t>>& near, unsigned workers, PointSet& block,
                      uint64_t& read_again) {
  std::vector<std::vector<double>> found(workers, std::vector<double>(sampled.size(), std::numeric_limits<double>::infinity()));
  const auto wanted = [&](size_t b) { return wide[b] || !near[b].empty(); };
  for (uint64_t first = 0; first < count; first += block_points) {
    const uint64_t n = std::min(block_points, count - first);
    const size_t to = static_cast<size_t>((first + n + box_points - 1) / box_points);
    size_t b = static_cast<size_t>(first / box_points);
    // Runs of wanted boxes, joined across short gaps, read a run at a time.
    while (b < to) {
      while (b < to && !wanted(b)) ++b;
      if (b == to) break;
      size_t end = b + 1;
      for (size_t gap = 0; end < to && gap <= kJoinBoxes; ++end) gap = wanted(end) ? 0 : gap + 1;
      while (!wanted(end - 1)) --end;
      const uint64_t run_first = uint64_t{b} * box_points;
      const uint64_t run_end = std::min<uint64_t>(count, uint64_t{end} * box_points);
      if (Status s = read(run_first, run_end - run_first, block); !s) return s;
      read_again += run_end - run_first;
      // A short run's few boxes cost microseconds: on one thread, not a thread start each.
      parallelFor(end - b, end - b >= 64 ? workers : 1, [&](size_t k, unsigned worker) {
        const size_t lo = static_cast<size_t>(k * box_points), hi = std::min<size_t>(block.positions.size(), lo + box_points);
        const std::span<const glm::dvec3> points = std::span(block.positions).subspan(lo, hi - lo);
        std::vector<double>& mine = found[worker];
        if (wide[b + k]) return balls.pointQueries(points, mine);
        for (uint32_t q : near[b + k]) {
          double smallest = mine[q];
          for (const glm::dvec3& p : points) {
            const glm::dvec3 d = p - sampled[q];
            const double d2 = d.x * d.x + d.y * d.y + d.z * d.z;
            if (d2 > 0.0 && d2 < smallest) smallest = d2;
          }
          mine[q] = smallest;
        }
      });
      b = end;
    }
  }
  for (const std::vector<double>& mine : found)
    for (size_t k = 0; k < best2.size(); ++k) best2[k] = std::min(best2[k], mine[k]);
  return okStatus();
}

// Pass 2 on a file in no spatial order: each block whose box lies within some sampled point's
// bound, read again whole into k-d trees (Forest), searched nearest first.
Status nearestByBlocks(uint64_t count, const BlockReader& read, uint64_t block_points, uint64_t box_points,
                       const std::vector<Box>& boxes, const PositionArray& sampled,
                       std::vector<double>& best2, unsigned threads, PointSet& block, uint64_t& read_again) {
  const size_t per_block = static_cast<size_t>(block_points / box_points);
  std::vector<size_t> near;
  PositionArray queries;
  std::vector<double> query_best2;
  for (uint64_t first = 0; first < count; first += block_points) {
    const size_t from = static_cast<size_t>(first / box_points), to = std::min(boxes.size(), from + per_block);
    glm::dvec3 lo = boxes[from].min, hi = boxes[from].max;
    for (size_t b = from; b < to; ++b) lo = glm::min(lo, boxes[b].min), hi = glm::max(hi, boxes[b].max);
    near.clear();
    for (size_t k = 0; k < sampled.size(); ++k)
      if (boxDistance2(lo, hi, sampled[k]) <= best2[k]) near.push_back(k);
    if (near.empty()) continue;
    const uint64_t n = std::min(block_points, count - first);
    if (Status s = read(first, n, block); !s) return s;
    read_again += n;
    queries.resize(near.size());
    query_best2.resize(near.size());
    for (size_t j = 0; j < near.size(); ++j) {
      queries[j] = sampled[near[j]];
      query_best2[j] = best2[near[j]];
    }
    Forest(block.positions, threads).nearestNonzero(queries, query_best2, threads);
    for (size_t j = 0; j < near.size(); ++j) best2[near[j]] = query_best2[j];
  }
  return okStatus();
}

}  // namespace

PointSetInfo computeInfo(const PointSet& points, size_t neighbor_sample, unsigned threads) {
  PointSetInfo info;
  info.count = points.size();
  info.triangles = points.triangles.size() / 3;
  info.has_colors = points.hasColors();
  if (points.positions.empty()) return info;

  noBounds(info);
  addBounds(info, points.positions);
  finishBounds(info);

  // The merge count needs 32-bit indices; larger sets are beyond the renderer anyway.
  if (info.float_overflow == 0 && points.size() <= UINT32_MAX) info.float_merged = countFloatMerges(points.positions, threads);
  if (interrupted()) return info;  // unfinished: the caller checks (the trees below would run on)

  const size_t n = points.size();
  const size_t sample = std::min(n, std::max<size_t>(neighbor_sample, 1));
  if (n >= 2) {
    // The points scaled to units of about the set's extent (lengthUnit): squared distances at
    // 1e-200 underflowed, and the nearest was found to be none.
    const double unit = lengthUnit(std::max({info.extent.x, info.extent.y, info.extent.z}), info.max_abs);
    const size_t step = n / sample;
    PositionArray sampled(sample);
    for (size_t k = 0; k < sample; ++k) sampled[k] = points.positions[k * step] * unit;
    std::vector<double> best2(sample, std::numeric_limits<double>::infinity());
    PositionArray scratch;  // the trees reorder it
    scalePositions(points.positions, scratch, unit, threads);
    Forest(scratch, threads).nearestNonzero(sampled, best2, threads);
    info.min_neighbor_distance = smallestDistance(best2) / unit;
    info.neighbor_sample = sample;
  }
  return info;
}

Result<StreamedInfo> computeStreamedInfo(uint64_t count, bool has_colors, uint64_t triangles, const BlockReader& read,
                                         uint64_t block_points, size_t neighbor_sample, unsigned threads) {
  StreamedInfo out;
  PointSetInfo& info = out.info;
  info.count = static_cast<size_t>(count);
  info.triangles = static_cast<size_t>(triangles);
  info.has_colors = has_colors;
  if (count == 0) return out;
  // The sample computeInfo takes: every step-th point from the first.
  const uint64_t sample = std::min<uint64_t>(count, std::max<size_t>(neighbor_sample, 1));
  const uint64_t step = count / sample;
  // Pass 1: bounds, the sample, and for each sampled point a first bound on its nearest distance:
  // the points beside it in the file (near in space when the file is in slab or Morton order);
  // the box of every kStreamedInfoBoxPoints consecutive points, on all cores.
  // Boxes that tile the blocks: 1024 points, or a block where blocks are not whole boxes (tests).
  const uint64_t box_points = block_points % kStreamedInfoBoxPoints == 0 ? kStreamedInfoBoxPoints : block_points;
  PositionArray sampled;
  sampled.reserve(static_cast<size_t>(sample));
  // Each sampled point's difference to the nearest point beside it in the file, kept until the
  // unit of length is known (below).
  PositionArray beside;
  beside.reserve(static_cast<size_t>(sample));
  std::vector<Box>& boxes = out.boxes;
  boxes.reserve(static_cast<size_t>((count + box_points - 1) / box_points));
  PointSet block;
  const unsigned workers = resolveThreads(threads);
  for (uint64_t first = 0; first < count; first += block_points) {
    const uint64_t n = std::min(block_points, count - first);
    if (Status s = read(first, n, block); !s) return s.error();
    const size_t from = boxes.size(), added = static_cast<size_t>((n + box_points - 1) / box_points);
    boxes.resize(from + added);
    std::vector<size_t> overflow(workers, 0), nonfinite(workers, 0);
    std::vector<Box> finite(added);  // each box's of its finite points (the box where all are)
    parallelFor(added, workers, [&](size_t k, unsigned worker) {
      const size_t lo = static_cast<size_t>(k * box_points), hi = std::min<size_t>(static_cast<size_t>(n), lo + box_points);
      boxes[from + k] = boundingBox(block.positions, lo, hi);
      size_t over = 0, bad = 0;  // counted here: workers' adjacent counters would share a cache line
      for (size_t i = lo; i < hi; ++i)
        for (int a = 0; a < 3; ++a) {
          over += std::fabs(block.positions[i][a]) > static_cast<double>(FLT_MAX);
          bad += !std::isfinite(block.positions[i][a]);
        }
      overflow[worker] += over, nonfinite[worker] += bad;
      finite[k] = boxes[from + k];
      if (bad == 0) return;
      finite[k] = Box{glm::dvec3(HUGE_VAL), glm::dvec3(-HUGE_VAL)};
      for (size_t i = lo; i < hi; ++i)
        if (const glm::dvec3& p = block.positions[i]; isFinite(p))
          finite[k].min = glm::min(finite[k].min, p), finite[k].max = glm::max(finite[k].max, p);
    });
    for (const Box& box : finite)
      out.finite.min = glm::min(out.finite.min, box.min), out.finite.max = glm::max(out.finite.max, box.max);
    if (first == 0) noBounds(info);
    if (std::all_of(nonfinite.begin(), nonfinite.end(), [](size_t c) { return c == 0; })) {
      // min and max of finite values in any grouping: the boxes' are the points'.
      for (size_t k = from; k < boxes.size(); ++k)
        info.min = glm::min(info.min, boxes[k].min), info.max = glm::max(info.max, boxes[k].max);
      for (size_t o : overflow) info.float_overflow += o;
    } else {
      addBounds(info, block.positions);  // in order, as computeInfo takes them
    }
    // Sample indices k·step in [first, first + n), k < sample.
    for (uint64_t k = (first + step - 1) / step; k < sample && k * step < first + n; ++k) {
      const size_t at = static_cast<size_t>(k * step - first);
      sampled.push_back(block.positions[at]);
      beside.push_back(nearestBeside(block.positions, at - std::min<size_t>(at, kFileNeighbors),
                                     std::min<size_t>(at + kFileNeighbors, n - 1), at));
    }
  }
  finishBounds(info);
  if (count < 2) return out;
  // Pass 2 measures in units of about the set's extent (lengthUnit, as computeInfo): squared
  // distances at 1e-200 underflowed, and at 1e200 overflowed, so that none was found. The unit
  // moves only exponents, so the distances are the same bits; where squares of the extent are far
  // from either end of double's range it is 1, and the points read again are not scaled.
  double unit = lengthUnit(std::max({info.extent.x, info.extent.y, info.extent.z}), info.max_abs);
  if (unit >= 0x1p-300 && unit <= 0x1p300) unit = 1.0;
  std::vector<double> best2(sampled.size(), std::numeric_limits<double>::infinity());
  for (size_t k = 0; k < sampled.size(); ++k) {
    sampled[k] *= unit;
    const glm::dvec3 d = beside[k] * unit;
    if (const double d2 = d.x * d.x + d.y * d.y + d.z * d.z; d2 > 0.0) best2[k] = d2;
  }
  std::vector<Box> scaled_boxes;
  if (unit != 1.0) {
    scaled_boxes.resize(boxes.size());
    for (size_t b = 0; b < boxes.size(); ++b) scaled_boxes[b] = {boxes[b].min * unit, boxes[b].max * unit};
  }
  const std::vector<Box>& pass_boxes = unit != 1.0 ? scaled_boxes : boxes;
  const BlockReader scaled_read = [&](uint64_t first, uint64_t n, PointSet& into) {
    Status s = read(first, n, into);
    if (s && unit != 1.0) scalePositions(into.positions, into.positions, unit, workers);
    return s;
  };
  // By boxes where most are compact enough to look up; else by blocks.
  const SampleBalls balls(sampled, best2, info.min * unit, info.max * unit, pass_boxes);
  std::vector<std::vector<uint32_t>> near(balls.compact() ? pass_boxes.size() : 0);
  std::vector<uint8_t> wide(near.size(), 0);
  parallelFor(near.size(), workers, [&](size_t b, unsigned) {
    wide[b] = !balls.near(pass_boxes[b].min, pass_boxes[b].max, near[b]);
  });
  const size_t wide_boxes = static_cast<size_t>(std::count(wide.begin(), wide.end(), uint8_t{1}));
  Status second = balls.compact() && 4 * wide_boxes <= pass_boxes.size()
      ? nearestByBoxes(count, scaled_read, block_points, box_points, sampled, best2, balls, wide, near, workers, block, out.points_read_again)
      : nearestByBlocks(count, scaled_read, block_points, box_points, pass_boxes, sampled, best2, threads, block, out.points_read_again);
  if (!second) return second.error();
  if (interrupted()) return interruptedError();  // the searches stop at Ctrl-C, leaving best2 unfinished
  info.min_neighbor_distance = smallestDistance(best2) / unit;
  info.neighbor_sample = sampled.size();
  return out;
}

}  // namespace dpoint
