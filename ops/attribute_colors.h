// Colours from a dimension (`dpoint render --color NAME`, issue #34). A plan is made once from the
// whole column (or from a streamed set's samples) and applied to any range of points:
// - classification: the ASPRS classes' colours (asprsClassColor);
// - another integer dimension of at most kMaxCategories distinct values (return numbers, flags,
//   a scanner channel): one colour per value (categoryColor), in ascending order;
// - anything else (intensity, GPS time, a float): viridis from the 1st to the 99th percentile, so
//   that a few extreme values do not flatten the picture; NaN draws as the low end.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "core/dimensions.h"

namespace dpoint {

inline constexpr size_t kMaxCategories = 12;
// The percentiles come from at most this many values, evenly strided over the column.
inline constexpr size_t kPercentileSamples = size_t(1) << 20;

struct AttributeColoring {
  std::string name;
  enum class Kind { kClasses, kCategories, kRamp } kind = Kind::kRamp;
  std::vector<double> values;   // kClasses, kCategories: the distinct values present, ascending
  double low = 0.0, high = 1.0;  // kRamp: the 1st and 99th percentiles (high > low)
  uint64_t points = 0;           // the points the plan was made from

  uint32_t colorOf(double value) const;  // packRgb
};

// Makes the plan from a column seen in consecutive pieces (a streamed set's blocks, or one whole
// column): every value for the categories (up to their limit), a strided sample for the ramp.
class AttributeSampler {
 public:
  // `points`: the column's length, which sets the sample's stride.
  AttributeSampler(std::string name, DimType type, uint64_t points);
  // The next values of the column, in order.
  void add(const Dimension& piece);
  AttributeColoring finish();

 private:
  AttributeColoring plan_;
  size_t limit_;                 // categories at most (256 for classes); 0: not categories
  bool overflow_ = false;        // more distinct values than limit_
  std::vector<double> distinct_;  // ascending
  uint64_t stride_, seen_ = 0;
  std::vector<double> sample_;
};

// The plan for a whole column (its NaN ignored; a column of NaN only ramps over [0, 1]).
AttributeColoring planAttributeColoring(const Dimension& d);

// colors[i] = the plan's colour of d's value at first + i, for count points (linear 0..1 bytes / 255,
// as colorByElevation writes them).
void colorByAttribute(const Dimension& d, size_t first, size_t count, const AttributeColoring& plan, glm::vec3* colors,
                      unsigned threads = 0);

// The legend's lines: each category's colour and label ("2 ground", "3"), or for a ramp its two
// ends ("p1 12.5", "p99 830"); at most `max_lines` (the rest summed up as "+N more").
struct LegendLine {
  uint32_t rgba8;
  std::string label;
};
std::vector<LegendLine> legendLines(const AttributeColoring& plan, size_t max_lines = 16);

}  // namespace dpoint
