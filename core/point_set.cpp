#include "core/point_set.h"

#include <cassert>
#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <unordered_set>
#include <vector>

#include <glm/common.hpp>

#include "core/parallel.h"
#include "core/text.h"

namespace dpoint {

bool PointSet::isPlanar() const {
  // Blocks on every core; a 3D set usually answers in its first block.
  constexpr size_t kBlock = size_t{1} << 20;
  std::atomic<bool> planar{true};
  parallelFor((positions.size() + kBlock - 1) / kBlock, 0, [&](size_t b, unsigned) {
    const size_t end = std::min(positions.size(), (b + 1) * kBlock);
    for (size_t i = b * kBlock; i < end && planar.load(std::memory_order_relaxed); ++i) {
      uint64_t bits;
      std::memcpy(&bits, &positions[i].z, sizeof bits);
      if (bits != 0) planar.store(false, std::memory_order_relaxed);
    }
  });
  return planar.load();
}

ColorsOffGrid colorsOffGrid(const ColorArray& colors, double full, unsigned threads) {
  constexpr size_t kBlock = size_t{1} << 18;
  // k / full rounded to float is within half an ulp of it (2^-25 below 1, 2^-24 at 1 itself); a
  // channel farther than full · 2^-24 from a step is changed by rounding.
  const double within = full * 0x1p-24;
  std::atomic<uint64_t> rounded{0}, clamped{0};
  parallelFor((colors.size() + kBlock - 1) / kBlock, threads, [&](size_t b, unsigned) {
    const size_t end = std::min(colors.size(), (b + 1) * kBlock);
    uint64_t off = 0, out = 0;
    for (size_t i = b * kBlock; i < end; ++i) {
      bool outside = false, on = true;
      for (int k = 0; k < 3; ++k) {
        const float c = colors[i][k];
        outside = outside || !(c >= 0.0f && c <= 1.0f);  // NaN too
        on = on && std::abs(static_cast<double>(c) * full - static_cast<double>(colorInteger(c, full))) <= within;
      }
      out += outside ? 1 : 0;
      off += !outside && !on ? 1 : 0;
    }
    rounded.fetch_add(off, std::memory_order_relaxed);
    clamped.fetch_add(out, std::memory_order_relaxed);
  });
  return {rounded.load(), clamped.load()};
}

WholeColorScale wholeColorScale(const ColorArray& colors, unsigned threads) {
  constexpr size_t kBlock = size_t{1} << 18;
  const size_t blocks = (colors.size() + kBlock - 1) / kBlock;
  std::vector<float> largest(blocks, 0.0f);  // the largest whole channel
  std::vector<uint64_t> odd(blocks, UINT64_MAX), odd_count(blocks, 0);
  parallelFor(blocks, threads, [&](size_t b, unsigned) {
    const size_t end = std::min(colors.size(), (b + 1) * kBlock);
    float most = 0.0f;
    for (size_t i = b * kBlock; i < end; ++i) {
      bool integers = true;
      for (int k = 0; k < 3; ++k) {
        const float c = colors[i][k];
        const bool whole = isWholeChannel(c, 65535.0f);
        integers = integers && whole;
        if (whole) most = std::max(most, c);
      }
      if (integers) continue;
      if (odd[b] == UINT64_MAX) odd[b] = i;
      ++odd_count[b];
    }
    largest[b] = most;
  });
  WholeColorScale scale;
  const float most = blocks == 0 ? 0.0f : *std::max_element(largest.begin(), largest.end());
  if (!(most > 1.0f)) return scale;
  uint64_t odds = 0;
  for (uint64_t n : odd_count) odds += n;
  if (odds == 0) {
    scale.full = most > 255.0f ? 65535 : 255;
  } else if (odds * 100 <= colors.size()) {  // nearly all whole: 0..255 values with a few odd ones
    scale.odd = *std::min_element(odd.begin(), odd.end());
  }
  return scale;
}

std::string oddColorNote(const glm::vec3& color, uint64_t vertex) {
  return "its float colours are nearly all whole numbers, some above 1 (0..255 values?), but vertex " + std::to_string(vertex) +
         "'s (" + formatNumber(color.r) + ", " + formatNumber(color.g) + ", " + formatNumber(color.b) +
         ") is not a whole number of 0 to 65535 a channel: read as PLY's 0..1 values (above 1 clamped where drawn or "
         "written as integers)";
}

void takeColorsAsIntegers(PointSet& points, uint16_t full, unsigned threads) {
  constexpr size_t kBlock = size_t{1} << 18;
  // Divided, not multiplied by 1/full: k / 255.0f is the float the PLY, LAS and module readers make
  // of k (229 * (1 / 255.0f) is a float above 229 / 255.0f), so a colour is one float whatever file
  // it came from.
  const float divisor = static_cast<float>(full);
  parallelFor((points.colors.size() + kBlock - 1) / kBlock, threads, [&](size_t b, unsigned) {
    const size_t end = std::min(points.colors.size(), (b + 1) * kBlock);
    for (size_t i = b * kBlock; i < end; ++i) points.colors[i] /= divisor;
  });
  points.color_full_scale = full;
  points.colors_read_as_fractions = false;
}

std::vector<SourceRun> pointSourceRuns(const PointSet& points) {
  const std::vector<SourceRun> one = {{0, points.size(), 0.0}};
  const Dimension* source = points.dimensions.find(dim::kPointSourceId);
  if (!source || points.size() == 0) return one;
  // An id as one value: every NaN one (a review finding: NaN != NaN made each point a scan), -0 as 0.
  const auto key = [](double v) { return std::isnan(v) ? ~uint64_t{0} : std::bit_cast<uint64_t>(v + 0.0); };
  std::vector<SourceRun> runs;
  std::unordered_set<uint64_t> seen;
  uint64_t last = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const double id = source->value(i);
    const uint64_t k = key(id);
    if (i != 0 && k == last) continue;
    // An id's points in two places, or more scans than a point source id numbers (the readers
    // number a file's scans in it, up to 65,535): one.
    if (!seen.insert(k).second || runs.size() == 65535) return one;
    if (i != 0) runs.back().end = i;
    runs.push_back({i, points.size(), id});
    last = k;
  }
  return runs.size() == 1 ? one : runs;
}

void appendPoints(PointSet& out, const PointSet& part) {
  const size_t at = out.size();
  const uint32_t offset = static_cast<uint32_t>(at);
  for (uint32_t index : part.triangles) out.triangles.push_back(offset + index);
  if (part.hasColors()) {
    out.colors_read_as_fractions = out.colors_read_as_fractions || part.colors_read_as_fractions;
    out.colors.resize(at, glm::vec3(1.0f));
    out.colors.insert(out.colors.end(), part.colors.begin(), part.colors.end());
  } else if (out.hasColors()) {
    out.colors.resize(at + part.size(), glm::vec3(1.0f));
  }
  for (const Dimension& d : part.dimensions.all()) {
    Dimension* column = out.dimensions.find(d.name);
    if (!column) column = &out.dimensions.add(d.name, d.type, at);
    if (!dimTypeHolds(column->type, d.type)) {  // float64 for both (0..1 intensities had become 0 or 1 in a uint16 column)
      Dimension wide(column->name, DimType::kF64, at);
      for (size_t i = 0; i < at; ++i) wide.setValue(i, column->value(i));
      *column = std::move(wide);
    }
    column->resize(at + part.size());
    if (column->type == d.type) std::memcpy(column->bytes.data() + at * dimTypeSize(d.type), d.bytes.data(), d.bytes.size());
    else
      for (size_t i = 0; i < part.size(); ++i) column->setValue(at + i, d.value(i));
  }
  out.positions.insert(out.positions.end(), part.positions.begin(), part.positions.end());
  out.dimensions.resize(out.size());
}

uint64_t heldBytes(const PointSet& points) {
  uint64_t bytes = uint64_t{points.positions.capacity()} * sizeof(glm::dvec3) +
                   uint64_t{points.colors.capacity()} * sizeof(glm::vec3) +
                   uint64_t{points.triangles.capacity()} * sizeof(uint32_t);
  for (const Dimension& d : points.dimensions.all()) bytes += d.bytes.capacity();
  return bytes;
}

size_t PointSet::firstBadTriangleIndex(unsigned threads) const {
  constexpr size_t kIndicesPerItem = size_t{1} << 20;
  const size_t n = positions.size();
  std::vector<size_t> bad((triangles.size() + kIndicesPerItem - 1) / kIndicesPerItem, triangles.size());
  parallelFor(bad.size(), threads, [&](size_t item, unsigned) {
    for (size_t i = item * kIndicesPerItem, end = std::min(triangles.size(), i + kIndicesPerItem); i < end; ++i)
      if (triangles[i] >= n) {
        bad[item] = i;
        return;
      }
  });
  for (size_t i : bad)
    if (i < triangles.size()) return i;
  return triangles.size();
}

namespace {

Box serialBox(const PositionArray& positions, size_t first, size_t last) {
  Box box{positions[first], positions[first]};
  for (size_t i = first + 1; i < last; ++i) {
    box.min = glm::min(box.min, positions[i]);
    box.max = glm::max(box.max, positions[i]);
  }
  return box;
}

}  // namespace

Box boundingBox(const PositionArray& positions, size_t first, size_t last) {
  assert(first < last && last <= positions.size());
  // Large ranges on every core, one box per block, merged in block order (min and max do not
  // depend on the order anyway).
  constexpr size_t kBlock = size_t{1} << 20;
  const size_t blocks = (last - first + kBlock - 1) / kBlock;
  if (blocks == 1) return serialBox(positions, first, last);
  std::vector<Box> boxes(blocks);
  parallelFor(blocks, 0, [&](size_t b, unsigned) {
    const size_t begin = first + b * kBlock;
    boxes[b] = serialBox(positions, begin, std::min(last, begin + kBlock));
  });
  Box box = boxes[0];
  for (const Box& b : boxes) {
    box.min = glm::min(box.min, b.min);
    box.max = glm::max(box.max, b.max);
  }
  return box;
}

Box finiteBox(const PositionArray& positions, size_t first, size_t last, unsigned threads, bool* nonfinite) {
  assert(first <= last && last <= positions.size());
  constexpr size_t kBlock = size_t{1} << 16;
  const size_t blocks = (last - first + kBlock - 1) / kBlock;
  const Box none{glm::dvec3(HUGE_VAL), glm::dvec3(-HUGE_VAL)};
  std::vector<Box> boxes(blocks, none);
  std::vector<uint8_t> odd(blocks, 0);
  parallelFor(blocks, threads, [&](size_t b, unsigned) {
    Box box = none;
    for (size_t i = first + b * kBlock, end = std::min(last, i + kBlock); i < end; ++i)
      for (int k = 0; k < 3; ++k) {
        const double v = positions[i][k];
        if (!std::isfinite(v)) {
          odd[b] = 1;
          continue;
        }
        box.min[k] = std::min(box.min[k], v);
        box.max[k] = std::max(box.max[k], v);
      }
    boxes[b] = box;
  });
  Box box = none;
  for (const Box& b : boxes) {
    box.min = glm::min(box.min, b.min);
    box.max = glm::max(box.max, b.max);
  }
  if (nonfinite) *nonfinite = std::find(odd.begin(), odd.end(), uint8_t{1}) != odd.end();
  return box;
}

}  // namespace dpoint
