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

AttributeSampler::AttributeSampler(std::string name, DimType type, uint64_t points)
    : stride_(std::max<uint64_t>(1, points / kPercentileSamples)) {
  plan_.name = std::move(name);
  plan_.points = points;
  limit_ = plan_.name == dim::kClassification ? 256 : dimTypeIsFloat(type) ? 0 : kMaxCategories;
}

void AttributeSampler::add(const Dimension& piece) {
  for (size_t i = 0; i < piece.size(); ++i, ++seen_) {
    const double v = piece.value(i);
    if (seen_ % stride_ == 0) sample_.push_back(v);
    if (overflow_ || limit_ == 0 || std::isnan(v)) continue;
    const auto at = std::lower_bound(distinct_.begin(), distinct_.end(), v);
    if (at != distinct_.end() && *at == v) continue;
    if (distinct_.size() == limit_) {
      overflow_ = true;
      distinct_.clear();
      continue;
    }
    distinct_.insert(at, v);
  }
}

AttributeColoring AttributeSampler::finish() {
  AttributeColoring plan = std::move(plan_);
  if (plan.name == dim::kClassification) {  // a class value is a byte: never more than 256
    plan.kind = AttributeColoring::Kind::kClasses;
    plan.values = std::move(distinct_);
    return plan;
  }
  if (limit_ > 0 && !overflow_ && !distinct_.empty()) {
    plan.kind = AttributeColoring::Kind::kCategories;
    plan.values = std::move(distinct_);
    return plan;
  }
  std::vector<double>& sample = sample_;
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

AttributeColoring planAttributeColoring(const Dimension& d) {
  AttributeSampler sampler(d.name, d.type, d.size());
  sampler.add(d);
  return sampler.finish();
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
