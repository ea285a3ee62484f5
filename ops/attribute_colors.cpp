#include "ops/attribute_colors.h"

#include <algorithm>
#include <cmath>

#include "core/parallel.h"
#include "ops/colormap.h"

namespace dpoint {
namespace {

std::string numberText(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

// The distinct values of the sample, ascending; empty when there are more than `limit`.
std::vector<double> distinctValues(const std::vector<double>& values, size_t limit) {
  std::vector<double> found;
  for (double v : values) {
    if (std::isnan(v)) continue;
    const auto at = std::lower_bound(found.begin(), found.end(), v);
    if (at != found.end() && *at == v) continue;
    if (found.size() == limit) return {};
    found.insert(at, v);
  }
  return found;
}

}  // namespace

uint32_t AttributeColoring::colorOf(double value) const {
  switch (kind) {
    case Kind::kClasses:
      return asprsClassColor(value >= 0.0 && value <= 255.0 ? static_cast<uint8_t>(value) : 255);
    case Kind::kCategories: {
      const auto at = std::lower_bound(values.begin(), values.end(), value);
      return categoryColor(at == values.end() ? values.size() : static_cast<size_t>(at - values.begin()));
    }
    case Kind::kRamp: break;
  }
  return viridis((value - low) / (high - low));
}

AttributeColoring planAttributeColoring(const std::string& name, DimType type, std::vector<double> sample,
                                        uint64_t points) {
  AttributeColoring plan;
  plan.name = name;
  plan.points = points;
  if (name == dim::kClassification) {
    plan.kind = AttributeColoring::Kind::kClasses;
    plan.values = distinctValues(sample, 256);
    return plan;
  }
  if (!dimTypeIsFloat(type)) {
    std::vector<double> distinct = distinctValues(sample, kMaxCategories);
    if (!distinct.empty()) {
      plan.kind = AttributeColoring::Kind::kCategories;
      plan.values = std::move(distinct);
      return plan;
    }
  }
  sample.erase(std::remove_if(sample.begin(), sample.end(), [](double v) { return std::isnan(v); }), sample.end());
  plan.kind = AttributeColoring::Kind::kRamp;
  if (sample.empty()) return plan;
  const size_t last = sample.size() - 1;
  const size_t lo = static_cast<size_t>(std::floor(0.01 * double(last)));
  const size_t hi = static_cast<size_t>(std::ceil(0.99 * double(last)));
  std::nth_element(sample.begin(), sample.begin() + std::ptrdiff_t(lo), sample.end());
  plan.low = sample[lo];
  std::nth_element(sample.begin(), sample.begin() + std::ptrdiff_t(hi), sample.end());
  plan.high = sample[hi];
  if (!(plan.high > plan.low) || !std::isfinite(plan.high - plan.low)) {
    // One value (or an infinite spread): a ramp of width 1 around it, or the finite ends.
    if (!std::isfinite(plan.low)) plan.low = std::isfinite(plan.high) ? plan.high - 1.0 : 0.0;
    if (!(plan.high > plan.low) || !std::isfinite(plan.high)) plan.high = plan.low + 1.0;
  }
  return plan;
}

AttributeColoring planAttributeColoring(const Dimension& d, unsigned threads) {
  const size_t n = d.size();
  // Categories need every value; a ramp's percentiles a strided sample.
  const bool whole = d.name == dim::kClassification || !dimTypeIsFloat(d.type);
  const size_t stride = whole ? 1 : std::max<size_t>(1, n / kPercentileSamples);
  std::vector<double> sample((n + stride - 1) / stride);
  constexpr size_t kBlock = size_t{1} << 16;
  parallelFor((sample.size() + kBlock - 1) / kBlock, threads, [&](size_t b, unsigned) {
    for (size_t k = b * kBlock; k < std::min(sample.size(), (b + 1) * kBlock); ++k) sample[k] = d.value(k * stride);
  });
  if (whole && d.name != dim::kClassification) {
    // Many distinct integers: a ramp from a strided sample, as for floats.
    std::vector<double> distinct = distinctValues(sample, kMaxCategories);
    if (distinct.empty() && n > kPercentileSamples) {
      const size_t s = n / kPercentileSamples;
      std::vector<double> strided;
      for (size_t i = 0; i < n; i += s) strided.push_back(sample[i]);
      sample = std::move(strided);
    }
  }
  return planAttributeColoring(d.name, d.type, std::move(sample), n);
}

void colorByAttribute(const Dimension& d, size_t first, size_t count, const AttributeColoring& plan, glm::vec3* colors,
                      unsigned threads) {
  constexpr size_t kBlock = size_t{1} << 16;
  parallelFor((count + kBlock - 1) / kBlock, threads, [&](size_t b, unsigned) {
    for (size_t i = b * kBlock; i < std::min(count, (b + 1) * kBlock); ++i) {
      const uint32_t rgba = plan.colorOf(d.value(first + i));
      colors[i] = glm::vec3(float(rgba & 0xffu), float((rgba >> 8) & 0xffu), float((rgba >> 16) & 0xffu)) / 255.0f;
    }
  });
}

std::vector<LegendLine> legendLines(const AttributeColoring& plan, size_t max_lines) {
  std::vector<LegendLine> lines;
  if (plan.kind == AttributeColoring::Kind::kRamp) {
    std::string high = "p99 ", low = "p1  ";
    high += numberText(plan.high);
    low += numberText(plan.low);
    lines.push_back({plan.colorOf(plan.high), std::move(high)});
    lines.push_back({plan.colorOf(plan.low), std::move(low)});
    return lines;
  }
  const size_t shown = plan.values.size() > max_lines ? max_lines - 1 : plan.values.size();
  for (size_t k = 0; k < shown; ++k) {
    const double v = plan.values[k];
    std::string label = numberText(v);
    if (plan.kind == AttributeColoring::Kind::kClasses) {
      const char* name = v >= 0.0 && v <= 255.0 ? asprsClassName(static_cast<uint8_t>(v)) : nullptr;
      label += ' ';
      label += name ? name : "user class";
    }
    lines.push_back({plan.colorOf(v), std::move(label)});
  }
  if (shown < plan.values.size()) {
    std::string more = "+";
    more += std::to_string(plan.values.size() - shown);
    more += " more";
    lines.push_back({0xff808080u, std::move(more)});
  }
  return lines;
}

}  // namespace dpoint
