#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "bench/svg_chart.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::TempDir;

size_t countOf(const std::string& haystack, const std::string& needle) {
  size_t count = 0;
  for (size_t at = haystack.find(needle); at != std::string::npos; at = haystack.find(needle, at + needle.size())) ++count;
  return count;
}

// The text from the first `open` up to the `close` after it (the axis groups hold no nested <g>).
std::string section(const std::string& svg, const std::string& open, const std::string& close = "</g>", size_t from = 0) {
  const size_t begin = svg.find(open, from);
  if (begin == std::string::npos) return "";
  const size_t end = svg.find(close, begin);
  return svg.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
}

// Each panel group's text, in order.
std::vector<std::string> panels(const std::string& svg) {
  std::vector<std::string> out;
  for (size_t at = svg.find("<g class=\"panel\""); at != std::string::npos;) {
    const size_t next = svg.find("<g class=\"panel\"", at + 1);
    out.push_back(svg.substr(at, next == std::string::npos ? std::string::npos : next - at));
    at = next;
  }
  return out;
}

// The contents of every <text class="CLS" ...>...</text> in `svg`, in order.
std::vector<std::string> texts(const std::string& svg, const std::string& cls) {
  std::vector<std::string> out;
  const std::string open = "<text class=\"" + cls + "\"";
  for (size_t at = svg.find(open); at != std::string::npos; at = svg.find(open, at + 1)) {
    const size_t begin = svg.find('>', at) + 1;
    out.push_back(svg.substr(begin, svg.find("</text>", begin) - begin));
  }
  return out;
}

// The numeric value of attribute `name` in the first element at or after `from` (an element's start).
double attribute(const std::string& svg, const std::string& name, size_t from = 0) {
  const size_t at = svg.find(" " + name + "=\"", from);
  if (at == std::string::npos) return NAN;
  return std::stod(svg.substr(at + name.size() + 3));
}

// The numeric attribute `name` of the <text> element whose content is exactly `content`.
double textAttribute(const std::string& svg, const std::string& content, const std::string& name) {
  const size_t at = svg.find(">" + content + "</text>");
  if (at == std::string::npos) return NAN;
  return attribute(svg, name, svg.rfind("<text", at));
}

std::vector<double> attributes(const std::string& svg, const std::string& element, const std::string& name) {
  std::vector<double> out;
  for (size_t at = svg.find(element); at != std::string::npos; at = svg.find(element, at + 1))
    out.push_back(attribute(svg, name, svg.rfind('<', at)));
  return out;
}

// Just enough of an XML checker to catch unbalanced tags, raw '<' in attributes and bare '&'.
std::string xmlProblem(const std::string& xml) {
  std::vector<std::string> open;
  for (size_t i = 0; i < xml.size(); ++i) {
    if (xml[i] == '&') {
      const size_t semi = xml.find(';', i);
      const std::string entity = xml.substr(i, semi == std::string::npos ? 8 : semi - i + 1);
      if (entity != "&amp;" && entity != "&lt;" && entity != "&gt;" && entity != "&quot;" && entity != "&apos;")
        return "bare '&' at " + std::to_string(i);
      continue;
    }
    if (xml[i] == '>') return "bare '>' at " + std::to_string(i);
    if (xml[i] != '<') continue;
    if (xml.compare(i, 2, "<?") == 0) {
      i = xml.find("?>", i) + 1;
      continue;
    }
    size_t end = i + 1;
    for (bool quoted = false; end < xml.size() && (quoted || xml[end] != '>'); ++end) {
      if (xml[end] == '"') quoted = !quoted;
      if (quoted && xml[end] == '<') return "'<' inside an attribute at " + std::to_string(end);
    }
    if (end == xml.size()) return "unterminated tag at " + std::to_string(i);
    const std::string tag = xml.substr(i + 1, end - i - 1);
    const std::string name = tag.substr(tag[0] == '/' ? 1 : 0, tag.find_first_of(" \n/", 1) - (tag[0] == '/' ? 1 : 0));
    if (tag[0] == '/') {
      if (open.empty() || open.back() != name) return "</" + name + "> closes <" + (open.empty() ? "" : open.back()) + ">";
      open.pop_back();
    } else if (tag.back() != '/') {
      open.push_back(name);
    }
    i = end;
  }
  return open.empty() ? "" : "<" + open.back() + "> never closed";
}

ChartSeries series(const std::string& name, std::vector<ChartPoint> points, Marker marker = Marker::kCircle) {
  ChartSeries s;
  s.name = name;
  s.marker = marker;
  s.points = std::move(points);
  return s;
}

Chart onePanel(std::vector<ChartSeries> all, std::vector<ReferenceLine> lines = {}) {
  Chart chart;
  chart.panels.resize(1);
  chart.panels[0].series = std::move(all);
  chart.panels[0].lines = std::move(lines);
  return chart;
}

// The speed-against-error chart as the bench report draws it: one panel per family, a marker
// per mode, a colour per backend, exact zeros and lost runs included.
Chart speedVsErrorChart(int panel_count) {
  const char* families[] = {"2D random", "Mandelbulb", "Menger", "Sierpinski", "Julia", "hard cases"};
  const char* modes[] = {"fp32", "split", "rte", "df64", "native", "batch"};
  const Marker markers[] = {Marker::kCircle, Marker::kSquare, Marker::kTriangle,
                            Marker::kDiamond, Marker::kStar, Marker::kTriangleDown};
  const double errors[] = {3e9, 2e-2, 3e-6, 1e-13, 0.0, 4e-5};
  Chart chart;
  chart.title = "Speed against error";
  chart.subtitle = "GPU: test device, 1920x1080";
  chart.columns = 3;
  for (int f = 0; f < panel_count; ++f) {
    ChartPanel panel;
    panel.title = families[f];
    panel.x_label = "GPU time per frame (ms)";
    panel.y_label = "max error (px)";
    panel.lines = {{0.5, "0.5 px"}, {1e-5, "float floor"}};
    for (int m = 0; m < 6; ++m) {
      for (int backend = 0; backend < 2; ++backend) {
        ChartSeries s = series(std::string(modes[m]) + (backend ? " compute" : " raster"), {}, markers[m]);
        s.color = backend ? "#d62728" : "#1f77b4";
        for (int d = 0; d < 3; ++d) {
          ChartPoint p{1e-3 * std::pow(10.0, m + d + backend), errors[m] * std::pow(10.0, d)};
          if (errors[m] == 0.0) p.kind = PointKind::kZero;
          if (f == 5 && m == 0 && d == 2) p.kind = PointKind::kLost;
          s.points.push_back(p);
        }
        panel.series.push_back(s);
      }
    }
    chart.panels.push_back(panel);
  }
  for (int m = 0; m < 6; ++m) chart.legend.push_back({modes[m], "#444444", markers[m]});
  chart.legend.push_back({"raster", "#1f77b4", Marker::kNone, true});
  chart.legend.push_back({"compute", "#d62728", Marker::kNone, true});
  return chart;
}

// The breakdown chart: error against view width (zooming in, descending) and against offset,
// a solid measured series and a dashed predicted bound per mode.
Chart breakdownChart() {
  Chart chart;
  chart.title = "Precision breakdown";
  for (int panel_index = 0; panel_index < 2; ++panel_index) {
    ChartPanel panel;
    panel.title = panel_index == 0 ? "error vs view width" : "error vs offset";
    panel.x_label = panel_index == 0 ? "view width" : "offset";
    panel.y_label = "max error (px)";
    panel.x_descending = panel_index == 0;
    panel.lines = {{0.5, "0.5 px"}};
    for (int m = 0; m < 6; ++m) {
      ChartSeries measured = series("mode " + std::to_string(m), {}), bound = series("bound " + std::to_string(m), {}, Marker::kNone);
      measured.line = bound.line = bound.dashed = true;
      for (int k = 0; k <= 14; ++k) {
        const double x = panel_index == 0 ? std::pow(10.0, -1 - k) : std::pow(10.0, k * 8 / 14.0);
        const double error = std::pow(10.0, k - 3 * m);
        measured.points.push_back({x, error / 2, m == 4 && k < 3 ? PointKind::kZero : PointKind::kValue});
        if (m == 0 && k > 11) measured.points.back().kind = PointKind::kLost;
        bound.points.push_back({x, error});
      }
      panel.series.push_back(measured);
      panel.series.push_back(bound);
    }
    chart.panels.push_back(panel);
  }
  chart.legend = {{"measured", "#000000", Marker::kCircle, true, false}, {"bound", "#000000", Marker::kNone, true, true}};
  return chart;
}

TEST(SvgChart, decadeLabelsArePlainNearOneAndScientificOutside) {
  EXPECT_EQ(decadeLabel(-3), "0.001");
  EXPECT_EQ(decadeLabel(-1), "0.1");
  EXPECT_EQ(decadeLabel(0), "1");
  EXPECT_EQ(decadeLabel(3), "1000");
  EXPECT_EQ(decadeLabel(-4), "1e-04");
  EXPECT_EQ(decadeLabel(4), "1e+04");
  EXPECT_EQ(decadeLabel(-14), "1e-14");
  EXPECT_EQ(decadeLabel(100), "1e+100");
  // Outside 1e-3..1e3 the labels read exactly as printf writes the power of ten with "%.0e".
  for (int k = -30; k <= 30; ++k) {
    if (k >= -3 && k <= 3) continue;
    char expected[32];
    std::snprintf(expected, sizeof expected, "%.0e", std::pow(10.0, k));
    EXPECT_EQ(decadeLabel(k), expected) << "exponent " << k;
  }
}

TEST(SvgChart, documentIsWellFormedSelfContainedSvg) {
  for (const Chart& chart : {speedVsErrorChart(6), breakdownChart(), Chart{}}) {
    const std::string svg = renderChartSvg(chart);
    EXPECT_EQ(svg.rfind("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\"", 0), 0u);
    EXPECT_EQ(xmlProblem(svg), "");
    const double width = attribute(svg, "width", svg.find("<svg")), height = attribute(svg, "height", svg.find("<svg"));
    EXPECT_GT(width, 0.0);
    EXPECT_GT(height, 0.0);
    EXPECT_NE(svg.find("viewBox=\"0 0 " + std::to_string(int(width)) + " " + std::to_string(int(height)) + "\""),
              std::string::npos);
    EXPECT_EQ(svg.find("<script"), std::string::npos);
    EXPECT_EQ(svg.find("href"), std::string::npos);
    EXPECT_EQ(svg.find("<style"), std::string::npos);
    EXPECT_NE(svg.find("font-family=\"DejaVu Sans"), std::string::npos);
  }
}

TEST(SvgChart, chartHasOnePanelGroupPerPanel) {
  EXPECT_EQ(countOf(renderChartSvg(speedVsErrorChart(2)), "<g class=\"panel\""), 2u);
  const std::string six = renderChartSvg(speedVsErrorChart(6));
  EXPECT_EQ(countOf(six, "<g class=\"panel\""), 6u);
  for (const std::string& panel : panels(six)) {
    EXPECT_EQ(countOf(panel, "<g class=\"x-axis\">"), 1u);
    EXPECT_EQ(countOf(panel, "<g class=\"y-axis\">"), 1u);
  }
  EXPECT_EQ(countOf(renderChartSvg(Chart{}), "<g class=\"panel\""), 0u);
}

TEST(SvgChart, panelsFillColumnsLeftToRightThenRows) {
  const std::string svg = renderChartSvg(speedVsErrorChart(6));  // 3 columns
  std::vector<double> xs, ys;
  for (const std::string& panel : panels(svg)) {
    const size_t at = panel.find("translate(") + 10;
    xs.push_back(std::stod(panel.substr(at)));
    ys.push_back(std::stod(panel.substr(panel.find(',', at) + 1)));
  }
  ASSERT_EQ(xs.size(), 6u);
  EXPECT_LT(xs[0], xs[1]);
  EXPECT_LT(xs[1], xs[2]);
  EXPECT_EQ(xs[3], xs[0]);
  EXPECT_EQ(ys[2], ys[0]);
  EXPECT_GE(ys[3] - ys[0], 300.0);  // a whole plot height below: rows do not overlap
  EXPECT_GE(xs[1] - xs[0], 420.0);
}

TEST(SvgChart, fewerPanelsThanColumnsLeaveNoEmptyCells) {
  Chart one = onePanel({series("a", {{1, 1}})});
  one.legend = {{"a"}};
  one.columns = 1;
  const std::string narrow = renderChartSvg(one);
  one.columns = 4;
  EXPECT_EQ(renderChartSvg(one), narrow);
}

TEST(SvgChart, seriesAreNamedGroups) {
  const std::string svg = renderChartSvg(speedVsErrorChart(2));
  EXPECT_EQ(countOf(svg, "<g class=\"series\""), 2u * 12u);
  for (const std::string& panel : panels(svg)) {
    for (const char* name : {"fp32 raster", "fp32 compute", "batch raster", "native compute"})
      EXPECT_EQ(countOf(panel, std::string("data-series=\"") + name + "\""), 1u) << name;
  }
  // A series group holds one marker per drawable point.
  const std::string group = section(svg, "data-series=\"fp32 raster\"");
  EXPECT_EQ(countOf(group, "<circle"), 3u);
  EXPECT_EQ(countOf(section(svg, "data-series=\"split raster\""), "<rect"), 3u);
}

TEST(SvgChart, xmlSpecialCharactersAreEscaped) {
  const std::string evil = "a<b & \"c\" 'd' >e";
  const std::string escaped = "a&lt;b &amp; &quot;c&quot; &apos;d&apos; &gt;e";
  Chart chart = onePanel({series(evil, {{1, 1}})}, {{0.5, evil}});
  chart.title = chart.subtitle = evil;
  chart.panels[0].title = chart.panels[0].x_label = chart.panels[0].y_label = evil;
  chart.legend = {{evil}};
  const std::string svg = renderChartSvg(chart);
  EXPECT_EQ(xmlProblem(svg), "");
  EXPECT_EQ(svg.find(evil), std::string::npos);
  // Title, subtitle, panel title, both axis titles, the reference label, the legend label, the series name.
  EXPECT_EQ(countOf(svg, escaped), 8u);
  // Control characters are not allowed in XML 1.0 at all, not even escaped.
  chart.title = std::string("bell\x07") + "tab\t";
  const std::string with_control = renderChartSvg(chart);
  EXPECT_EQ(with_control.find('\x07'), std::string::npos);
  EXPECT_NE(with_control.find("bell tab\t"), std::string::npos);
}

TEST(SvgChart, zeroAndLostRowsAppearOnlyWhenUsed) {
  const std::string plain = renderChartSvg(onePanel({series("a", {{1, 1}, {10, 1e-3}})}));
  EXPECT_TRUE(texts(plain, "row-label").empty());

  const std::string zero = renderChartSvg(onePanel({series("a", {{1, 1}, {10, 0, PointKind::kZero}})}));
  EXPECT_EQ(texts(zero, "row-label"), std::vector<std::string>{"0"});

  const std::string lost = renderChartSvg(onePanel({series("a", {{1, 1}, {10, 0, PointKind::kLost}})}));
  EXPECT_EQ(texts(lost, "row-label"), std::vector<std::string>{"lost"});

  // The rows sit outside the log range: "0" below its lowest tick, "lost" above its highest.
  const std::string both = renderChartSvg(
      onePanel({series("a", {{1, 1}, {10, 0, PointKind::kZero}, {100, 0, PointKind::kLost}})}));
  const std::string y_axis = section(both, "<g class=\"y-axis\">");
  const std::vector<double> tick_y = attributes(y_axis, "class=\"tick\"", "y1");
  const double zero_y = textAttribute(y_axis, "0", "y"), lost_y = textAttribute(y_axis, "lost", "y");
  ASSERT_FALSE(tick_y.empty());
  for (double y : tick_y) {
    EXPECT_LT(y + 10.0, zero_y);  // label baselines are 4 px under their tick: 14 px clear
    EXPECT_GT(y - 10.0, lost_y);
  }
  EXPECT_EQ(countOf(both, "<circle"), 3u);  // the row points have their markers too
}

TEST(SvgChart, autoRangeEnclosesEveryPoint) {
  ChartSeries s = series("a", {{1e-3, 3e-5}, {1e4, 2e2}, {5, 1}});
  const std::string svg = renderChartSvg(onePanel({s}));
  const std::vector<std::string> x_labels = texts(section(svg, "<g class=\"x-axis\">"), "tick-label");
  const std::vector<std::string> y_labels = texts(section(svg, "<g class=\"y-axis\">"), "tick-label");
  // Exact powers of ten stay on their own decade (log10 of 1e-3 is not exactly -3).
  EXPECT_EQ(x_labels, (std::vector<std::string>{"0.001", "0.01", "0.1", "1", "10", "100", "1000", "1e+04"}));
  EXPECT_EQ(y_labels, (std::vector<std::string>{"1e-05", "1e-04", "0.001", "0.01", "0.1", "1", "10", "100", "1000"}));
  // Every marker lies whole inside the plot frame.
  const size_t clip = svg.find("<clipPath");
  const double left = attribute(svg, "x", clip), top = attribute(svg, "y", clip);
  const double right = left + attribute(svg, "width", clip), bottom = top + attribute(svg, "height", clip);
  const std::string group = section(svg, "<g class=\"series\"");
  const std::vector<double> cx = attributes(group, "<circle", "cx"), cy = attributes(group, "<circle", "cy");
  const std::vector<double> r = attributes(group, "<circle", "r");
  ASSERT_EQ(cx.size(), 3u);
  for (size_t i = 0; i < cx.size(); ++i) {
    EXPECT_GE(cx[i] - r[i], left);
    EXPECT_LE(cx[i] + r[i], right);
    EXPECT_GE(cy[i] - r[i], top);
    EXPECT_LE(cy[i] + r[i], bottom);
  }
}

TEST(SvgChart, autoRangeIncludesReferenceLinesAndIsAtLeastOneDecade) {
  const std::string with_line = renderChartSvg(onePanel({series("a", {{1, 0.5}, {2, 3}})}, {{1e-5, "floor"}}));
  EXPECT_EQ(texts(section(with_line, "<g class=\"y-axis\">"), "tick-label").front(), "1e-05");
  EXPECT_EQ(countOf(with_line, "class=\"reference-line\""), 1u);

  const std::string single = renderChartSvg(onePanel({series("a", {{3, 5}})}));
  EXPECT_EQ(texts(section(single, "<g class=\"y-axis\">"), "tick-label"), (std::vector<std::string>{"1", "10"}));
  const std::string on_decade = renderChartSvg(onePanel({series("a", {{10, 10}})}));
  EXPECT_EQ(texts(section(on_decade, "<g class=\"x-axis\">"), "tick-label"), (std::vector<std::string>{"10", "100"}));
}

TEST(SvgChart, explicitRangeOverridesTheData) {
  Chart chart = onePanel({series("a", {{1e-5, 1}, {1e5, 10}})});
  chart.panels[0].x_min = 1e-2;
  chart.panels[0].x_max = 1e2;
  const std::string svg = renderChartSvg(chart);
  EXPECT_EQ(texts(section(svg, "<g class=\"x-axis\">"), "tick-label"),
            (std::vector<std::string>{"0.01", "0.1", "1", "10", "100"}));
  EXPECT_NE(svg.find("clip-path=\"url(#plot-clip-0)\""), std::string::npos);  // the points outside are clipped
}

TEST(SvgChart, nonPositiveValuesAreSkipped) {
  const std::string svg = renderChartSvg(onePanel({series(
      "a", {{0, 1}, {-1, 1}, {1, 0}, {1, -5}, {NAN, 1}, {1, INFINITY}, {0, 0, PointKind::kZero}, {10, 10}})}));
  EXPECT_EQ(countOf(section(svg, "<g class=\"series\""), "<circle"), 1u);
  EXPECT_TRUE(texts(svg, "row-label").empty());  // the kZero point at x = 0 is skipped too
  EXPECT_EQ(texts(section(svg, "<g class=\"x-axis\">"), "tick-label"), (std::vector<std::string>{"10", "100"}));
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  EXPECT_EQ(svg.find("inf"), std::string::npos);
}

TEST(SvgChart, denseAxesTickEveryDecadeButLabelOnlySome) {
  const std::string svg = renderChartSvg(onePanel({series("a", {{1e-15, 1e-14}, {1e-1, 1e10}})}));
  const std::string y_axis = section(svg, "<g class=\"y-axis\">"), x_axis = section(svg, "<g class=\"x-axis\">");
  EXPECT_EQ(countOf(y_axis, "class=\"tick\""), 25u);
  EXPECT_EQ(countOf(x_axis, "class=\"tick\""), 15u);
  const std::vector<std::string> y_labels = texts(y_axis, "tick-label");
  EXPECT_GE(y_labels.size(), 5u);
  EXPECT_LE(y_labels.size(), 10u);
  EXPECT_NE(std::find(y_labels.begin(), y_labels.end(), "1"), y_labels.end());  // 1 is always among them
  // Labels on one axis are at least a label's width (or height) apart.
  const std::vector<double> label_x = attributes(x_axis, "class=\"tick-label\"", "x");
  for (size_t i = 1; i < label_x.size(); ++i) EXPECT_GE(label_x[i] - label_x[i - 1], 40.0);
  const std::vector<double> label_y = attributes(y_axis, "class=\"tick-label\"", "y");
  for (size_t i = 1; i < label_y.size(); ++i) EXPECT_GE(std::abs(label_y[i] - label_y[i - 1]), 14.0);
}

TEST(SvgChart, descendingAxisPutsLargestXOnTheLeft) {
  Chart chart = onePanel({series("a", {{1e-1, 1}, {1e-3, 1}})});
  const auto positions = [&] {
    const std::string x_axis = section(renderChartSvg(chart), "<g class=\"x-axis\">");
    return std::make_pair(textAttribute(x_axis, "0.1", "x"), textAttribute(x_axis, "0.001", "x"));
  };
  const auto [ascending_big, ascending_small] = positions();
  EXPECT_GT(ascending_big, ascending_small);
  chart.panels[0].x_descending = true;
  const auto [descending_big, descending_small] = positions();
  EXPECT_LT(descending_big, descending_small);
}

TEST(SvgChart, linesJoinInXOrderAndBreakAtZeroAndLost) {
  ChartSeries s = series("a", {{3, 1}, {1, 2}, {2, 4}, {4, 0, PointKind::kZero}, {6, 8}, {5, 3}, {7, 0, PointKind::kLost}, {8, 1}});
  s.line = true;
  const std::string group = section(renderChartSvg(onePanel({s})), "<g class=\"series\"");
  ASSERT_EQ(countOf(group, "<polyline"), 2u);  // {1,2,3} and {5,6}; {8} alone draws no line
  const size_t at = group.find("points=\"") + 8;
  const std::string first = group.substr(at, group.find('"', at) - at);
  std::vector<double> xs;
  for (size_t p = 0; p != std::string::npos; p = first.find(' ', p + 1)) xs.push_back(std::stod(first.substr(p == 0 ? 0 : p + 1)));
  ASSERT_EQ(xs.size(), 3u);
  EXPECT_LT(xs[0], xs[1]);
  EXPECT_LT(xs[1], xs[2]);
  EXPECT_EQ(countOf(group, "stroke-dasharray"), 0u);
  s.dashed = true;
  EXPECT_EQ(countOf(section(renderChartSvg(onePanel({s})), "<g class=\"series\""), "stroke-dasharray"), 2u);
}

TEST(SvgChart, referenceLabelSitsAboveItsLineAtTheRightEnd) {
  const std::string svg = renderChartSvg(onePanel({series("a", {{1, 1e-3}, {10, 1e3}})}, {{0.5, "0.5 px"}}));
  const double line_y = attribute(svg, "y1", svg.rfind('<', svg.find("class=\"reference-line\"")));
  const size_t label = svg.find("<text class=\"reference-label\"");
  ASSERT_NE(label, std::string::npos);
  EXPECT_LT(attribute(svg, "y", label), line_y);
  EXPECT_GT(attribute(svg, "x", label), 80.0 + 420.0 / 2);
  EXPECT_NE(svg.find(">0.5 px</text>"), std::string::npos);
}

TEST(SvgChart, legendIsDrawnOnceRightOfThePanels) {
  const Chart chart = speedVsErrorChart(6);
  const std::string svg = renderChartSvg(chart);
  EXPECT_EQ(countOf(svg, "<g class=\"legend\""), 1u);
  const std::vector<std::string> labels = texts(section(svg, "<g class=\"legend\"", "</svg>"), "legend-label");
  ASSERT_EQ(labels.size(), chart.legend.size());
  for (size_t i = 0; i < labels.size(); ++i) EXPECT_EQ(labels[i], chart.legend[i].label);
  double panels_right = 0.0;
  for (const std::string& panel : panels(svg)) panels_right = std::max(panels_right, std::stod(panel.substr(panel.find("translate(") + 10)) + 500.0);
  const double legend_x = std::stod(svg.substr(svg.find("translate(", svg.find("<g class=\"legend\"")) + 10));
  EXPECT_GE(legend_x, panels_right);
  EXPECT_GE(attribute(svg, "width", svg.find("<svg")), legend_x + 12.0 * 0.6 * 7);  // room for "compute"
  EXPECT_EQ(countOf(renderChartSvg(onePanel({series("a", {{1, 1}})})), "class=\"legend\""), 0u);
}

uint32_t bigEndian32(const std::string& bytes, size_t at) {
  uint32_t v = 0;
  for (size_t i = 0; i < 4; ++i) v = v << 8 | static_cast<unsigned char>(bytes[at + i]);
  return v;
}

TEST(SvgChart, rsvgConvertRendersRepresentativeCharts) {
  const std::string tool = "/usr/bin/rsvg-convert";
  if (!test::fileExists(tool)) GTEST_SKIP() << tool << " is not installed (Debian: librsvg2-bin)";
  TempDir dir;
  const std::vector<std::pair<std::string, Chart>> charts = {
      {"speed2", speedVsErrorChart(2)}, {"speed6", speedVsErrorChart(6)}, {"breakdown", breakdownChart()}};
  for (const auto& [name, chart] : charts) {
    const std::string svg = renderChartSvg(chart);
    test::writeFile(dir.file(name + ".svg"), svg);
    const test::CommandResult r = test::runCommand({tool, "-o", dir.file(name + ".png"), dir.file(name + ".svg")});
    ASSERT_EQ(r.exit_code, 0) << name << ": " << r.err;
    EXPECT_EQ(r.err, "") << name;
    const std::string png = test::readFile(dir.file(name + ".png"));
    ASSERT_GT(png.size(), 24u) << name;
    EXPECT_EQ(png.substr(0, 8), "\x89PNG\r\n\x1a\n") << name;
    // IHDR: the picture has the size the SVG declares.
    EXPECT_EQ(bigEndian32(png, 16), static_cast<uint32_t>(attribute(svg, "width", svg.find("<svg")))) << name;
    EXPECT_EQ(bigEndian32(png, 20), static_cast<uint32_t>(attribute(svg, "height", svg.find("<svg")))) << name;
  }
}

}  // namespace
}  // namespace dpoint
