#include "ops/point_filters.h"

#include <cassert>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "ops/colormap.h"
#include "core/parallel.h"

namespace dpoint {
namespace {

struct PositionHash {
  size_t operator()(const glm::dvec3& p) const {
    // Adding 0.0 maps −0 to +0, so equal values hash equally (NaN never equals itself and stays
    // a separate point, which is the right reading of "exact duplicate").
    const auto bits = [](double v) {
      v += 0.0;
      uint64_t b;
      static_assert(sizeof b == sizeof v);
      std::copy_n(reinterpret_cast<const unsigned char*>(&v), sizeof v, reinterpret_cast<unsigned char*>(&b));
      return b;
    };
    uint64_t h = bits(p.x);
    h = h * 0x9E3779B97F4A7C15ull ^ bits(p.y);
    h = h * 0x9E3779B97F4A7C15ull ^ bits(p.z);
    return size_t(h ^ (h >> 29));
  }
};

}  // namespace

void dropDuplicatePositions(PointSet& points) {
  std::unordered_map<glm::dvec3, uint32_t, PositionHash> first;
  first.reserve(points.positions.size());
  std::vector<uint32_t> remap(points.positions.size());
  size_t kept = 0;
  for (size_t i = 0; i < points.positions.size(); ++i) {
    const auto [it, inserted] = first.try_emplace(points.positions[i], uint32_t(kept));
    remap[i] = it->second;
    if (!inserted) continue;
    points.positions[kept] = points.positions[i];
    if (points.hasColors()) points.colors[kept] = points.colors[i];
    for (Dimension& d : points.dimensions.all()) d.copyFrom(kept, d, i);  // the first point's attributes
    ++kept;
  }
  points.positions.resize(kept);
  if (points.hasColors()) points.colors.resize(kept);
  points.dimensions.resize(kept);
  size_t t = 0;
  for (size_t i = 0; i + 3 <= points.triangles.size(); i += 3) {
    const uint32_t a = remap[points.triangles[i]], b = remap[points.triangles[i + 1]], c = remap[points.triangles[i + 2]];
    if (a == b || b == c || a == c) continue;
    points.triangles[t++] = a;
    points.triangles[t++] = b;
    points.triangles[t++] = c;
  }
  points.triangles.resize(t);
}

void encodeColorsSrgb8(PointSet& points) {
  for (glm::vec3& colour : points.colors)
    for (int k = 0; k < 3; ++k) {
      // Computed in double so the 8-bit rounding is not disturbed by float error near .5 steps.
      const double c = std::clamp(double(colour[k]), 0.0, 1.0);
      const double s = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
      colour[k] = float(std::round(255.0 * s) / 255.0);
    }
}

void colorByElevation(PointSet& points, int axis, unsigned threads) {
  assert(points.size() > 0);
  const Box box = boundingBox(points.positions);
  colorByElevation(points, axis, box.min[axis], box.max[axis], threads);
}

void colorByElevation(PointSet& points, int axis, double low, double high, unsigned threads) {
  assert(axis >= 0 && axis <= 2 && low <= high);
  const double range = high - low;
  points.colors.resize(points.size());
  constexpr size_t kBlock = size_t{1} << 16;
  parallelFor((points.size() + kBlock - 1) / kBlock, threads, [&](size_t block, unsigned) {
    const size_t first = block * kBlock, last = std::min(points.size(), first + kBlock);
    for (size_t i = first; i < last; ++i) {
      const double t = range > 0.0 ? (points.positions[i][axis] - low) / range : 0.5;
      const uint32_t rgba = viridis(t);
      points.colors[i] = glm::vec3(float(rgba & 0xffu), float((rgba >> 8) & 0xffu), float((rgba >> 16) & 0xffu)) / 255.0f;
    }
  });
}

}  // namespace dpoint
