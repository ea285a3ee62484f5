// Log-log SVG charts (svg_chart.h). The layout is fixed arithmetic, not a layout engine: every
// panel cell has the same size, text widths are estimated from the character count (DejaVu Sans
// averages a little under 0.62 em per character, so the estimate errs wide), and tick labels are
// thinned until the estimate says they fit. That keeps the output deterministic and byte-stable,
// which a report that is diffed between runs wants.

#include "bench/svg_chart.h"

#include <algorithm>
#include <cassert>
#include <charconv>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <string_view>
#include <system_error>
#include <utility>

namespace dpoint {
namespace {

constexpr double kPlotWidth = 420.0, kPlotHeight = 300.0;
constexpr double kPanelLeft = 80.0;    // y tick labels (up to "1e-100") and the rotated y title
constexpr double kPanelRight = 24.0;   // also the gap before the legend
constexpr double kPanelTop = 34.0;     // panel title
constexpr double kPanelBottom = 54.0;  // x tick labels and the x title
constexpr double kCellWidth = kPanelLeft + kPlotWidth + kPanelRight;
constexpr double kCellHeight = kPanelTop + kPlotHeight + kPanelBottom;
constexpr double kMargin = 12.0;
// The range's end decades sit this far inside the frame, so a marker on an end decade (auto ranges
// put the extreme points exactly there when they are powers of ten) is drawn whole, not clipped.
constexpr double kDataInset = 9.0;
constexpr double kRowHeight = 20.0, kRowGap = 8.0;  // the "0" / "lost" rows and the break before them
constexpr double kMarkerRadius = 5.5;
constexpr double kTickLength = 5.0, kMinorTickLength = 3.0;
constexpr double kTickFont = 11.0, kLabelFont = 12.0, kPanelTitleFont = 14.0;
constexpr double kTitleFont = 18.0, kSubtitleFont = 12.0;
constexpr double kLegendRow = 20.0, kLegendSample = 34.0, kLegendPad = 10.0;
constexpr double kCharWidthEm = 0.62;
constexpr int kMaxLabelledSpan = 8;   // at most about this many decade steps carry a label
constexpr double kMinorTickSpan = 5.0;  // minor ticks (2..9) only when the range is this narrow
constexpr const char* kFontFamily = "DejaVu Sans, Arial, sans-serif";
constexpr const char* kGridColor = "#e4e4e4";
constexpr const char* kFrameColor = "#555555";
constexpr const char* kTextColor = "#222222";

// Coordinates with two decimals: finer than any renderer resolves. std::to_chars ignores the
// locale, so the separator is always '.'. Clamped because a point far outside an explicit range
// maps far off the plot (it is clipped anyway) and a fixed-format 1e300 would not fit the buffer.
std::string num(double v) {
  v = std::clamp(v, -1e6, 1e6);
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, 2);
  assert(ec == std::errc());
  std::string s(buf, end);
  while (s.back() == '0') s.pop_back();
  if (s.back() == '.') s.pop_back();
  return s == "-0" ? "0" : s;
}

std::string escapeXml(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default:
        // XML 1.0 forbids these control characters even as character references.
        const bool forbidden = static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n' && c != '\r';
        out += forbidden ? ' ' : c;
    }
  }
  return out;
}

// Estimated advance of `text` (UTF-8: continuation bytes do not count as characters).
double textWidth(std::string_view text, double font_size) {
  double chars = 0.0;
  for (const char c : text) chars += (static_cast<unsigned char>(c) & 0xC0) != 0x80 ? 1.0 : 0.0;
  return chars * kCharWidthEm * font_size;
}

std::string textElement(const std::string& cls, double x, double y, double size, const std::string& anchor,
                        std::string_view text, const std::string& extra = "") {
  return "<text class=\"" + cls + "\" x=\"" + num(x) + "\" y=\"" + num(y) + "\" font-size=\"" + num(size) +
         "\" text-anchor=\"" + anchor + "\"" + extra + ">" + escapeXml(text) + "</text>\n";
}

std::string lineElement(double x0, double y0, double x1, double y1, const std::string& attributes) {
  return "<line x1=\"" + num(x0) + "\" y1=\"" + num(y0) + "\" x2=\"" + num(x1) + "\" y2=\"" + num(y1) + "\" " +
         attributes + "/>\n";
}

std::string pathFrom(double cx, double cy, std::initializer_list<std::pair<double, double>> offsets) {
  std::string d;
  for (const auto& [dx, dy] : offsets) d += (d.empty() ? "M" : " L") + num(cx + dx) + "," + num(cy + dy);
  return d + " Z";
}

// One marker centred on (cx, cy) in the enclosing group's colour. Filled shapes are translucent
// with a solid outline, so markers on top of each other stay visible as overlapping outlines.
// Sizes are chosen so the shapes look about equally heavy.
std::string markerElement(Marker marker, double cx, double cy) {
  const double r = kMarkerRadius;
  const std::string filled = " fill-opacity=\"0.35\" stroke-width=\"1.5\"/>\n";
  const std::string open = " fill=\"none\" stroke-width=\"2\"/>\n";
  switch (marker) {
    case Marker::kNone: return "";
    case Marker::kCircle:
      return "<circle cx=\"" + num(cx) + "\" cy=\"" + num(cy) + "\" r=\"" + num(r) + "\"" + filled;
    case Marker::kSquare:
      return "<rect x=\"" + num(cx - 0.9 * r) + "\" y=\"" + num(cy - 0.9 * r) + "\" width=\"" + num(1.8 * r) +
             "\" height=\"" + num(1.8 * r) + "\"" + filled;
    case Marker::kTriangle:
      return "<path d=\"" + pathFrom(cx, cy, {{0, -1.25 * r}, {1.1 * r, 0.7 * r}, {-1.1 * r, 0.7 * r}}) + "\"" + filled;
    case Marker::kTriangleDown:
      return "<path d=\"" + pathFrom(cx, cy, {{0, 1.25 * r}, {1.1 * r, -0.7 * r}, {-1.1 * r, -0.7 * r}}) + "\"" + filled;
    case Marker::kDiamond:
      return "<path d=\"" + pathFrom(cx, cy, {{0, -1.2 * r}, {1.2 * r, 0}, {0, 1.2 * r}, {-1.2 * r, 0}}) + "\"" + filled;
    case Marker::kStar: {
      std::string d;
      for (int i = 0; i < 10; ++i) {
        const double radius = (i % 2 == 0 ? 1.3 : 0.55) * r, angle = 3.14159265358979 * (i / 5.0 - 0.5);
        d += (i == 0 ? "M" : " L") + num(cx + radius * std::cos(angle)) + "," + num(cy + radius * std::sin(angle));
      }
      return "<path d=\"" + d + " Z\"" + filled;
    }
    case Marker::kCross: {
      const double a = 0.85 * r;
      return "<path d=\"M" + num(cx - a) + "," + num(cy - a) + " L" + num(cx + a) + "," + num(cy + a) + " M" +
             num(cx - a) + "," + num(cy + a) + " L" + num(cx + a) + "," + num(cy - a) + "\"" + open;
    }
    case Marker::kPlus:
      return "<path d=\"M" + num(cx - r) + "," + num(cy) + " L" + num(cx + r) + "," + num(cy) + " M" + num(cx) + "," +
             num(cy - r) + " L" + num(cx) + "," + num(cy + r) + "\"" + open;
  }
  return "";
}

// A log10 axis from `lo` to `hi` (exponents, not necessarily whole) drawn from pixel `from` to `to`.
struct LogAxis {
  double lo = 0.0, hi = 1.0, from = 0.0, to = 1.0;
  double pixelOfExponent(double e) const { return from + (e - lo) / (hi - lo) * (to - from); }
  double pixel(double value) const { return pixelOfExponent(std::log10(value)); }
  int firstDecade() const { return static_cast<int>(std::ceil(lo - 1e-9)); }
  int lastDecade() const { return static_cast<int>(std::floor(hi + 1e-9)); }
};

bool given(double range_end) { return std::isfinite(range_end) && range_end > 0.0; }

// The exponent range of an axis: explicit ends where given, else the decades enclosing the data
// (log10 values in [data_lo, data_hi]). The 1e-9 tolerance keeps an exact power of ten, whose
// log10 may land an ulp off, on its own decade instead of widening the range by one.
LogAxis axisRange(double explicit_min, double explicit_max, double data_lo, double data_hi) {
  LogAxis axis;
  axis.lo = given(explicit_min) ? std::log10(explicit_min) : std::floor(data_lo + 1e-9);
  axis.hi = given(explicit_max) ? std::log10(explicit_max) : std::ceil(data_hi - 1e-9);
  if (axis.hi - axis.lo < 1.0 && !given(explicit_max)) axis.hi = std::ceil(axis.lo + 1.0 - 1e-9);
  if (axis.hi - axis.lo < 1.0 && !given(explicit_min)) axis.lo = std::floor(axis.hi - 1.0 + 1e-9);
  assert(axis.hi > axis.lo && "explicit axis range must have min < max");
  // Without this a release build would divide by zero and write "nan" coordinates.
  if (axis.hi <= axis.lo) axis.hi = axis.lo + 1.0;
  return axis;
}

// Every `step`-th decade carries a label: few enough that at most ~kMaxLabelledSpan steps are
// labelled, and far enough apart on screen that `extent` pixels of label fit between them.
int labelStep(const LogAxis& axis, double extent) {
  const double span = axis.hi - axis.lo, pixels_per_decade = std::abs(axis.to - axis.from) / span;
  int step = 1;
  while (span / step > kMaxLabelledSpan || step * pixels_per_decade < extent) ++step;
  return step;
}

bool isLabelled(int exponent, int step) { return ((exponent % step) + step) % step == 0; }

bool drawable(const ChartPoint& p) {
  if (!std::isfinite(p.x) || p.x <= 0.0) return false;
  return p.kind != PointKind::kValue || (std::isfinite(p.y) && p.y > 0.0);
}

// Geometry of one panel in its own coordinates (the panel group is translated into place).
struct PanelLayout {
  double x0 = kPanelLeft, x1 = kPanelLeft + kPlotWidth, y0 = kPanelTop, y1 = kPanelTop + kPlotHeight;
  double log_y0 = y0, log_y1 = y1;  // the frame of the log range, without the rows
  bool zero_row = false, lost_row = false;
  LogAxis x, y;
  double rowY(PointKind kind) const { return kind == PointKind::kZero ? y1 - kRowHeight / 2 : y0 + kRowHeight / 2; }
  double pointY(const ChartPoint& p) const { return p.kind == PointKind::kValue ? y.pixel(p.y) : rowY(p.kind); }
};

PanelLayout layoutPanel(const ChartPanel& panel) {
  PanelLayout l;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double x_lo = kInf, x_hi = -kInf, y_lo = kInf, y_hi = -kInf;
  for (const ChartSeries& s : panel.series) {
    for (const ChartPoint& p : s.points) {
      if (!drawable(p)) continue;
      x_lo = std::min(x_lo, std::log10(p.x));
      x_hi = std::max(x_hi, std::log10(p.x));
      if (p.kind == PointKind::kValue) {
        y_lo = std::min(y_lo, std::log10(p.y));
        y_hi = std::max(y_hi, std::log10(p.y));
      }
      l.zero_row = l.zero_row || p.kind == PointKind::kZero;
      l.lost_row = l.lost_row || p.kind == PointKind::kLost;
    }
  }
  for (const ReferenceLine& r : panel.lines) {
    if (!std::isfinite(r.y) || r.y <= 0.0) continue;
    y_lo = std::min(y_lo, std::log10(r.y));
    y_hi = std::max(y_hi, std::log10(r.y));
  }
  if (x_lo > x_hi) {  // nothing to enclose: the decade above 1
    x_lo = 0.0;
    x_hi = 1.0;
  }
  if (y_lo > y_hi) {
    y_lo = 0.0;
    y_hi = 1.0;
  }
  l.x = axisRange(panel.x_min, panel.x_max, x_lo, x_hi);
  l.y = axisRange(panel.y_min, panel.y_max, y_lo, y_hi);
  if (l.lost_row) l.log_y0 = l.y0 + kRowHeight + kRowGap;
  if (l.zero_row) l.log_y1 = l.y1 - kRowHeight - kRowGap;
  l.x.from = panel.x_descending ? l.x1 - kDataInset : l.x0 + kDataInset;
  l.x.to = panel.x_descending ? l.x0 + kDataInset : l.x1 - kDataInset;
  l.y.from = l.log_y1 - kDataInset;
  l.y.to = l.log_y0 + kDataInset;
  return l;
}

std::string rectElement(double x, double y, double w, double h, const std::string& attributes) {
  return "<rect x=\"" + num(x) + "\" y=\"" + num(y) + "\" width=\"" + num(w) + "\" height=\"" + num(h) + "\" " +
         attributes + "/>\n";
}

// The frames (the log range, and the rows as separate boxes: the gap between them is the axis
// break), with the decade grid inside.
std::string drawFrames(const PanelLayout& l) {
  struct Box {
    double top, bottom;
    bool row;
  };
  std::vector<Box> boxes = {{l.log_y0, l.log_y1, false}};
  if (l.zero_row) boxes.push_back({l.y1 - kRowHeight, l.y1, true});
  if (l.lost_row) boxes.push_back({l.y0, l.y0 + kRowHeight, true});
  std::string out;
  for (const auto& [top, bottom, row] : boxes) {
    out += rectElement(l.x0, top, l.x1 - l.x0, bottom - top, row ? "fill=\"#f3f3f3\"" : "fill=\"#ffffff\"");
    for (int e = l.x.firstDecade(); e <= l.x.lastDecade(); ++e) {
      const double px = l.x.pixelOfExponent(e);
      out += lineElement(px, top, px, bottom, std::string("stroke=\"") + kGridColor + "\"");
    }
  }
  for (int e = l.y.firstDecade(); e <= l.y.lastDecade(); ++e) {
    const double py = l.y.pixelOfExponent(e);
    out += lineElement(l.x0, py, l.x1, py, std::string("stroke=\"") + kGridColor + "\"");
  }
  for (const Box& b : boxes)
    out += rectElement(l.x0, b.top, l.x1 - l.x0, b.bottom - b.top, std::string("fill=\"none\" stroke=\"") + kFrameColor + "\"");
  return out;
}

// Major ticks on every decade, minor ticks (2..9) on narrow ranges, labels on every step-th decade.
// `at(pixel, length)` draws one tick; `label(pixel, exponent)` one label.
template <typename Tick, typename Label>
std::string drawTicks(const LogAxis& axis, int step, Tick at, Label label) {
  std::string out;
  if (axis.hi - axis.lo <= kMinorTickSpan) {
    for (int e = static_cast<int>(std::floor(axis.lo)); e < axis.hi; ++e) {
      for (int m = 2; m <= 9; ++m) {
        const double exponent = e + std::log10(m);
        if (exponent >= axis.lo && exponent <= axis.hi) out += at(axis.pixelOfExponent(exponent), kMinorTickLength, "minor-tick");
      }
    }
  }
  for (int e = axis.firstDecade(); e <= axis.lastDecade(); ++e) {
    out += at(axis.pixelOfExponent(e), kTickLength, "tick");
    if (isLabelled(e, step)) out += label(axis.pixelOfExponent(e), e);
  }
  return out;
}

std::string drawAxes(const ChartPanel& panel, const PanelLayout& l) {
  const std::string tick_style = std::string("\" stroke=\"") + kFrameColor + "\"";
  std::string out = "<g class=\"x-axis\">\n";
  double widest = 0.0;
  for (int e = l.x.firstDecade(); e <= l.x.lastDecade(); ++e) widest = std::max(widest, textWidth(decadeLabel(e), kTickFont));
  out += drawTicks(
      l.x, labelStep(l.x, widest + 10.0),
      [&](double px, double length, const char* cls) {
        return lineElement(px, l.y1, px, l.y1 + length, std::string("class=\"") + cls + tick_style);
      },
      [&](double px, int e) { return textElement("tick-label", px, l.y1 + kTickLength + 13.0, kTickFont, "middle", decadeLabel(e)); });
  out += textElement("axis-title", (l.x0 + l.x1) / 2, l.y1 + 42.0, kLabelFont, "middle", panel.x_label);
  out += "</g>\n<g class=\"y-axis\">\n";
  const double label_x = l.x0 - kTickLength - 3.0;
  out += drawTicks(
      l.y, labelStep(l.y, kTickFont + 4.0),
      [&](double py, double length, const char* cls) {
        return lineElement(l.x0 - length, py, l.x0, py, std::string("class=\"") + cls + tick_style);
      },
      [&](double py, int e) { return textElement("tick-label", label_x, py + 4.0, kTickFont, "end", decadeLabel(e)); });
  for (const PointKind kind : {PointKind::kZero, PointKind::kLost}) {
    if (!(kind == PointKind::kZero ? l.zero_row : l.lost_row)) continue;
    out += lineElement(l.x0 - kTickLength, l.rowY(kind), l.x0, l.rowY(kind), "class=\"row-tick" + tick_style);
    out += textElement("row-label", label_x, l.rowY(kind) + 4.0, kTickFont, "end", kind == PointKind::kZero ? "0" : "lost");
  }
  const double mid = (l.y0 + l.y1) / 2;
  out += "<text class=\"axis-title\" transform=\"translate(16," + num(mid) + ") rotate(-90)\" font-size=\"" +
         num(kLabelFont) + "\" text-anchor=\"middle\">" + escapeXml(panel.y_label) + "</text>\n";
  return out + "</g>\n";
}

std::string dashAttribute(bool dashed) { return dashed ? " stroke-dasharray=\"6 4\"" : ""; }

using Pixel = std::pair<double, double>;

// The series' drawable points in x order: the order its line joins them in.
std::vector<ChartPoint> sortedPoints(const ChartSeries& s) {
  std::vector<ChartPoint> points;
  for (const ChartPoint& p : s.points)
    if (drawable(p)) points.push_back(p);
  std::stable_sort(points.begin(), points.end(), [](const ChartPoint& a, const ChartPoint& b) { return a.x < b.x; });
  return points;
}

// Runs of consecutive values as pixels; a zero or lost point breaks the line (it has no place on
// the log axis). Runs of one point draw nothing and are left out.
std::vector<std::vector<Pixel>> lineRuns(const std::vector<ChartPoint>& points, const PanelLayout& l) {
  std::vector<std::vector<Pixel>> runs(1);
  for (const ChartPoint& p : points) {
    if (p.kind == PointKind::kValue) runs.back().emplace_back(l.x.pixel(p.x), l.y.pixel(p.y));
    else if (!runs.back().empty()) runs.emplace_back();
  }
  std::erase_if(runs, [](const std::vector<Pixel>& run) { return run.size() < 2; });
  return runs;
}

std::string drawSeries(const ChartSeries& s, const PanelLayout& l) {
  const std::vector<ChartPoint> points = sortedPoints(s);
  const std::string color = escapeXml(s.color);
  std::string out = "<g class=\"series\" data-series=\"" + escapeXml(s.name) + "\" fill=\"" + color + "\" stroke=\"" +
                    color + "\">\n";
  if (s.line) {
    for (const std::vector<Pixel>& run : lineRuns(points, l)) {
      std::string coords;
      for (const auto& [px, py] : run) coords += (coords.empty() ? "" : " ") + num(px) + "," + num(py);
      out += "<polyline points=\"" + coords + "\" fill=\"none\" stroke-width=\"1.8\" stroke-linejoin=\"round\"" +
             dashAttribute(s.dashed) + "/>\n";
    }
  }
  for (const ChartPoint& p : points) out += markerElement(s.marker, l.x.pixel(p.x), l.pointY(p));
  return out + "</g>\n";
}

// What the data covers, as sample pixels: marker centres and a sample every few pixels along lines.
std::vector<Pixel> dataFootprint(const ChartPanel& panel, const PanelLayout& l) {
  std::vector<Pixel> footprint;
  for (const ChartSeries& s : panel.series) {
    const std::vector<ChartPoint> points = sortedPoints(s);
    if (s.marker != Marker::kNone)
      for (const ChartPoint& p : points) footprint.emplace_back(l.x.pixel(p.x), l.pointY(p));
    if (!s.line) continue;
    for (const std::vector<Pixel>& run : lineRuns(points, l)) {
      for (size_t i = 1; i < run.size(); ++i) {
        const auto [ax, ay] = run[i - 1];
        const auto [bx, by] = run[i];
        const double steps = std::min(std::ceil(std::hypot(bx - ax, by - ay) / 3.0), 1000.0);
        for (double t = 0.0; t <= steps; ++t) footprint.emplace_back(ax + (bx - ax) * t / steps, ay + (by - ay) * t / steps);
      }
    }
  }
  return footprint;
}

struct LabelBox {
  double left, top, right, bottom;
  bool overlaps(const LabelBox& o) const { return left < o.right && o.left < right && top < o.bottom && o.top < bottom; }
};

// Where a reference line's label goes: just above the line at the plot's right end, unless data
// or an earlier label covers that spot; then below the line, then at the left end, whichever
// covers the least. Returns the box; the text's baseline is 3 px above its bottom.
LabelBox placeReferenceLabel(double py, double width, const PanelLayout& l, const std::vector<Pixel>& footprint,
                             const std::vector<LabelBox>& taken) {
  const double height = kTickFont + 2.0, inset = 6.0;
  LabelBox best{};
  double best_cost = std::numeric_limits<double>::infinity();
  for (const bool right : {true, false}) {
    for (const bool above : {true, false}) {
      const double left = right ? l.x1 - inset - width : l.x0 + inset, top = above ? py - 2.0 - height : py + 2.0;
      const LabelBox box{left, top, left + width, top + height};
      if (box.top < l.log_y0 || box.bottom > l.log_y1) continue;  // outside the frame
      double cost = 0.0;
      const LabelBox padded{box.left - kMarkerRadius, box.top - kMarkerRadius, box.right + kMarkerRadius,
                            box.bottom + kMarkerRadius};
      for (const auto& [x, y] : footprint) cost += x > padded.left && x < padded.right && y > padded.top && y < padded.bottom;
      for (const LabelBox& other : taken) cost += other.overlaps(box) ? 1000.0 : 0.0;
      if (cost < best_cost) {
        best = box;
        best_cost = cost;
      }
    }
  }
  if (best_cost == std::numeric_limits<double>::infinity()) best = {l.x1 - inset - width, py - 2.0 - height, l.x1 - inset, py - 2.0};
  return best;
}

std::string drawPanel(const ChartPanel& panel, double left, double top, size_t index) {
  const PanelLayout l = layoutPanel(panel);
  const std::string clip_id = "plot-clip-" + std::to_string(index);
  std::string out = "<g class=\"panel\" transform=\"translate(" + num(left) + "," + num(top) + ")\">\n";
  out += "<defs><clipPath id=\"" + clip_id + "\">" + rectElement(l.x0, l.y0, l.x1 - l.x0, l.y1 - l.y0, "") +
         "</clipPath></defs>\n";
  out += textElement("panel-title", (l.x0 + l.x1) / 2, l.y0 - 12.0, kPanelTitleFont, "middle", panel.title,
                     " font-weight=\"bold\"");
  out += drawFrames(l) + drawAxes(panel, l);
  std::vector<std::pair<double, const ReferenceLine*>> lines;
  for (const ReferenceLine& r : panel.lines) {
    if (!std::isfinite(r.y) || r.y <= 0.0) continue;
    const double py = l.y.pixel(r.y);
    if (py >= l.log_y0 && py <= l.log_y1) lines.emplace_back(py, &r);
  }
  out += "<g class=\"plot\" clip-path=\"url(#" + clip_id + ")\">\n";
  for (const auto& [py, r] : lines)
    out += lineElement(l.x0, py, l.x1, py, "class=\"reference-line\" stroke=\"" + escapeXml(r->color) +
                                               "\" stroke-width=\"1.2\"" + dashAttribute(r->dashed));
  for (const ChartSeries& s : panel.series) out += drawSeries(s, l);
  out += "</g>\n";
  // Labels after the data, with a white halo, so that where data cannot be avoided the label stays readable.
  const std::vector<Pixel> footprint = lines.empty() ? std::vector<Pixel>() : dataFootprint(panel, l);
  std::vector<LabelBox> taken;
  for (const auto& [py, r] : lines) {
    taken.push_back(placeReferenceLabel(py, textWidth(r->label, kTickFont), l, footprint, taken));
    const LabelBox& box = taken.back();
    const bool right = box.right > (l.x0 + l.x1) / 2;  // anchored at the frame it is next to
    out += textElement("reference-label", right ? box.right : box.left, box.bottom - 3.0, kTickFont,
                       right ? "end" : "start", r->label,
                       " fill=\"" + escapeXml(r->color) +
                           "\" stroke=\"#ffffff\" stroke-width=\"3\" stroke-linejoin=\"round\" paint-order=\"stroke\"");
  }
  return out + "</g>\n";
}

std::string drawLegend(const std::vector<LegendEntry>& legend, double left, double top, double width) {
  std::string out = "<g class=\"legend\" transform=\"translate(" + num(left) + "," + num(top) + ")\">\n";
  out += rectElement(0, 0, width, 2 * kLegendPad + kLegendRow * static_cast<double>(legend.size()),
                     "fill=\"#ffffff\" stroke=\"#cccccc\"");
  for (size_t i = 0; i < legend.size(); ++i) {
    const LegendEntry& e = legend[i];
    const double cy = kLegendPad + kLegendRow * (static_cast<double>(i) + 0.5);
    const std::string color = escapeXml(e.color);
    out += "<g fill=\"" + color + "\" stroke=\"" + color + "\">\n";
    if (e.line)
      out += lineElement(kLegendPad, cy, kLegendPad + kLegendSample, cy, "stroke-width=\"1.8\"" + dashAttribute(e.dashed));
    out += markerElement(e.marker, kLegendPad + kLegendSample / 2, cy) + "</g>\n";
    out += textElement("legend-label", 2 * kLegendPad + kLegendSample, cy + 4.0, kLabelFont, "start", e.label);
  }
  return out + "</g>\n";
}

}  // namespace

std::string decadeLabel(int exponent) {
  if (exponent >= 0 && exponent <= 3) return "1" + std::string(static_cast<size_t>(exponent), '0');
  if (exponent < 0 && exponent >= -3) return "0." + std::string(static_cast<size_t>(-exponent - 1), '0') + "1";
  // As printf's %g writes 1e-05: a sign and at least two exponent digits.
  const int magnitude = exponent < 0 ? -exponent : exponent;
  return std::string("1e") + (exponent < 0 ? "-" : "+") + (magnitude < 10 ? "0" : "") + std::to_string(magnitude);
}

std::string renderChartSvg(const Chart& chart) {
  assert(chart.columns >= 1);
  const size_t panel_count = chart.panels.size();
  // Fewer panels than columns: no empty cells between the panels and the legend.
  const size_t columns = std::clamp<size_t>(static_cast<size_t>(std::max(chart.columns, 1)), 1, std::max<size_t>(panel_count, 1));
  const size_t rows = (panel_count + columns - 1) / columns;

  double header = kMargin;
  if (!chart.title.empty()) header += kTitleFont + 8.0;
  if (!chart.subtitle.empty()) header += kSubtitleFont + 8.0;
  const double grid_left = kMargin, grid_top = header;
  const double grid_right = grid_left + kCellWidth * static_cast<double>(panel_count == 0 ? 0 : columns);
  const double grid_bottom = grid_top + kCellHeight * static_cast<double>(rows);

  double legend_text = 0.0;
  for (const LegendEntry& e : chart.legend) legend_text = std::max(legend_text, textWidth(e.label, kLabelFont));
  const double legend_width = chart.legend.empty() ? 0.0 : 3 * kLegendPad + kLegendSample + legend_text + kLegendPad;
  const double legend_top = grid_top + (panel_count == 0 ? 0.0 : kPanelTop);
  const double legend_bottom = legend_top + 2 * kLegendPad + kLegendRow * static_cast<double>(chart.legend.size());

  const double title_width = std::max(textWidth(chart.title, kTitleFont), textWidth(chart.subtitle, kSubtitleFont));
  const double width = std::ceil(std::max({grid_right + legend_width, kMargin + title_width}) + kMargin);
  const double height = std::ceil(std::max(grid_bottom, chart.legend.empty() ? 0.0 : legend_bottom) + kMargin);

  std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  out += "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"" + num(width) + "\" height=\"" +
         num(height) + "\" viewBox=\"0 0 " + num(width) + " " + num(height) + "\" font-family=\"" + kFontFamily +
         "\" fill=\"" + kTextColor + "\">\n";
  out += rectElement(0, 0, width, height, "fill=\"#ffffff\"");
  double y = kMargin;
  if (!chart.title.empty()) {
    y += kTitleFont;
    out += textElement("title", kMargin, y, kTitleFont, "start", chart.title, " font-weight=\"bold\"");
    y += 8.0;
  }
  if (!chart.subtitle.empty())
    out += textElement("subtitle", kMargin, y + kSubtitleFont, kSubtitleFont, "start", chart.subtitle, " fill=\"#555555\"");
  for (size_t i = 0; i < panel_count; ++i) {
    const double left = grid_left + kCellWidth * static_cast<double>(i % columns);
    const double top = grid_top + kCellHeight * static_cast<double>(i / columns);
    out += drawPanel(chart.panels[i], left, top, i);
  }
  if (!chart.legend.empty()) out += drawLegend(chart.legend, grid_right, legend_top, legend_width);
  return out + "</svg>\n";
}

}  // namespace dpoint
