// Log-log charts as plain SVG, written by dpoint's own code (issue #10): the bench report's
// speed-against-error plot and its precision breakdown. Several panels in a grid, each with log
// axes that carry ticks and labelled decades, series drawn as markers and/or lines, horizontal
// reference lines, and one legend for the whole chart (labels never sit next to points, so they
// never overlap). The output is self-contained SVG 1.1 (no scripts, no external fonts or CSS),
// readable by browsers and by rsvg-convert.
#pragma once

#include <string>
#include <vector>

namespace dpoint {

enum class Marker { kNone, kCircle, kSquare, kTriangle, kDiamond, kCross, kPlus, kStar, kTriangleDown };

// A y value that a log axis cannot show. kZero is drawn on a row labelled "0" under the axis's
// lowest decade; kLost (nothing measured: every point lost) on a row labelled "lost" above the
// highest. kValue points must have x > 0 and y > 0 (others are skipped).
enum class PointKind { kValue, kZero, kLost };

struct ChartPoint {
  double x = 0.0, y = 0.0;
  PointKind kind = PointKind::kValue;
};

struct ChartSeries {
  std::string name;               // for the SVG's <g data-series="..."> (tests count series); not drawn
  std::string color = "#000000";  // stroke and fill, any SVG colour
  Marker marker = Marker::kCircle;
  bool line = false;              // join the points in x order (kValue points only; a gap at kZero/kLost)
  bool dashed = false;            // the line is dashed
  std::vector<ChartPoint> points;
};

// A horizontal line across the panel at y (on the log axis), labelled at its right end inside
// the plot area (e.g. "0.5 px", "float floor").
struct ReferenceLine {
  double y = 0.0;
  std::string label;
  std::string color = "#888888";
  bool dashed = true;
};

struct ChartPanel {
  std::string title;
  std::string x_label, y_label;
  std::vector<ChartSeries> series;
  std::vector<ReferenceLine> lines;
  bool x_descending = false;  // largest x on the left (e.g. view width shrinking as one zooms in)
  // Axis ranges in data units; 0 means "from the data": the decades enclosing every kValue point
  // and every reference line, at least one decade wide.
  double x_min = 0.0, x_max = 0.0, y_min = 0.0, y_max = 0.0;
};

// One legend row: a marker (or kNone), an optional line sample (solid or dashed), a colour, text.
struct LegendEntry {
  std::string label;
  std::string color = "#000000";
  Marker marker = Marker::kNone;
  bool line = false, dashed = false;
};

struct Chart {
  std::string title;     // drawn at the top
  std::string subtitle;  // a smaller line under it (device, driver, resolution)
  std::vector<ChartPanel> panels;
  int columns = 2;       // panels per row
  std::vector<LegendEntry> legend;  // drawn once, to the right of the panels
};

// The whole SVG document. Every string is XML-escaped. Each panel is a <g class="panel"> holding
// its axes (<g class="x-axis">, <g class="y-axis"> with one <text class="tick-label"> per labelled
// decade) and one <g class="series" data-series="NAME"> per series; the legend is <g class="legend">.
// Also, for tests: every decade has a <line class="tick"> (labelled or not; narrow ranges add
// <line class="minor-tick">), the "0" and "lost" rows are <text class="row-label"> in the y axis,
// reference lines are <line class="reference-line"> with a <text class="reference-label">, and
// each panel group is placed by transform="translate(X,Y)". A decade's label is left out when
// labels would crowd (more than 8 decades on an axis, or less room than a label needs).
std::string renderChartSvg(const Chart& chart);

// Decade tick label text for 10^k as the axes print it ("0.001", "0.01", …, "1000" inside
// 1e-3..1e3, else "1e-05", "1e+06"); exposed for tests.
std::string decadeLabel(int exponent);

}  // namespace dpoint
