// The report's pictures (issue #10): speed against error per dataset family, the breakdown of each
// mode along the sweeps with its predicted bound, and the montage of one hard view in every mode.
#include <cmath>
#include <cstdio>
#include <iterator>

#include "bench/montage.h"
#include "bench/report.h"
#include "bench/report_internal.h"

namespace dpoint {
namespace {

using namespace report;

// Okabe–Ito colours (distinguishable with the common colour-vision deficiencies) and markers, taken
// by the mode's place in the table (viewer/modes.h), so a new mode gets the next pair unasked. Black
// before the yellow, which barely shows on the white charts (it was adaptive's).
const char* const kPalette[] = {"#E69F00", "#CC79A7", "#56B4E9", "#009E73", "#0072B2", "#D55E00", "#000000", "#F0E442"};
const Marker kMarkers[] = {Marker::kCircle, Marker::kCross, Marker::kTriangle, Marker::kDiamond,
                           Marker::kSquare, Marker::kStar,  Marker::kPlus,     Marker::kTriangleDown};
const char* modeColor(size_t m) { return kPalette[m % std::size(kPalette)]; }
Marker modeMarker(size_t m) { return kMarkers[m % std::size(kMarkers)]; }
const char* backendColor(Backend backend) { return backend == Backend::kCompute ? "#0072B2" : "#E69F00"; }

ChartPoint errorPoint(double x, const BenchRow& row) {
  if (!row.error_max_px) return {x, 0.0, PointKind::kLost};
  if (*row.error_max_px <= 0.0) return {x, 0.0, PointKind::kZero};
  return {x, *row.error_max_px, PointKind::kValue};
}

std::string deviceLine(const BenchRun& run) {
  const DeviceFacts& d = run.device;
  return d.name + " (" + d.type + "), " + d.driver_name + " " + formatDriverVersion(d.vendor_id, d.driver_version);
}

std::vector<std::string> familiesOf(const BenchRun& run) {
  std::vector<std::string> out;
  for (const BenchCase& c : run.cases)
    if (std::find(out.begin(), out.end(), c.family) == out.end()) out.push_back(c.family);
  return out;
}

}  // namespace

Chart speedVsErrorChart(const BenchRun& run) {
  Chart chart;
  chart.title = "Speed against error: every precision mode on every dataset";
  chart.subtitle = deviceLine(run) + ". x: GPU time per frame (median); y: largest error of any point, in pixels.";
  chart.columns = 3;
  const std::vector<Backend> backends = backendsOf(run);
  for (const std::string& family : familiesOf(run)) {
    ChartPanel panel;
    panel.title = family;
    panel.x_label = "GPU ms per frame";
    panel.y_label = "max error (px)";
    std::vector<double> floors;
    for (Backend backend : backends) {
      for (size_t m = 0; m < kModeCount; ++m) {
        ChartSeries series;
        series.name = modeText(kAllModes[m]) + " " + backendText(backend);
        series.color = backendColor(backend);
        series.marker = modeMarker(m);
        for (const BenchRow& row : run.rows) {
          if (row.bench_case->family != family || row.backend != backend || row.mode != kAllModes[m] || !ran(&row)) continue;
          series.points.push_back(errorPoint(frameMs(row), row));
          floors.push_back(row.float_floor_px);
        }
        panel.series.push_back(std::move(series));
      }
    }
    panel.lines.push_back({0.5, "0.5 px: wrong pixel", "#C00000", true});
    if (!floors.empty()) {
      std::sort(floors.begin(), floors.end());
      panel.lines.push_back({floors[floors.size() / 2], "float floor", "#666666", true});
    }
    chart.panels.push_back(std::move(panel));
  }
  for (size_t m = 0; m < kModeCount; ++m) chart.legend.push_back({modeText(kAllModes[m]), "#444444", modeMarker(m)});
  for (Backend backend : backends) chart.legend.push_back({backendText(backend) + " backend", backendColor(backend), Marker::kSquare});
  chart.legend.push_back({"0.5 px (wrong pixel)", "#C00000", Marker::kNone, true, true});
  chart.legend.push_back({"float floor: 2^-24 of half the view", "#666666", Marker::kNone, true, true});
  return chart;
}

std::optional<Chart> breakdownChart(const BenchRun& run) {
  const Backend backend = figureBackend(run);
  Chart chart;
  chart.title = "Where each mode breaks: measured max error (solid) and predicted bound (dashed)";
  chart.subtitle = deviceLine(run) + ", " + backendText(backend) + " backend.";
  chart.columns = 2;
  const std::pair<Sweep, const char*> sweeps[] = {
      {Sweep::kDeepZoom, "deep zoom: mandelbrot2d, a point per pixel centre"},
      {Sweep::kOffset, "offset: 1 mm Menger cubes seen from 0.1 m"}};
  for (const auto& [sweep, title] : sweeps) {
    ChartPanel panel;
    panel.title = title;
    panel.x_label = sweep == Sweep::kDeepZoom ? "view width" : "offset from the origin (m)";
    panel.y_label = "max error (px)";
    panel.x_descending = sweep == Sweep::kDeepZoom;
    std::vector<double> floors;
    for (size_t m = 0; m < kModeCount; ++m) {
      ChartSeries measured, bound;
      measured.name = modeText(kAllModes[m]) + " measured";
      bound.name = modeText(kAllModes[m]) + " bound";
      measured.color = bound.color = modeColor(m);
      measured.marker = modeMarker(m);
      bound.marker = Marker::kNone;
      measured.line = bound.line = true;
      bound.dashed = true;
      for (const BenchCase& c : run.cases) {
        if (c.sweep != sweep) continue;
        const BenchRow* row = rowsFor(run, &c, backend)[m];
        if (!ran(row)) continue;
        measured.points.push_back(errorPoint(c.sweep_x, *row));
        if (std::isfinite(row->predicted_bound_px) && row->predicted_bound_px > 0)
          bound.points.push_back({c.sweep_x, row->predicted_bound_px, PointKind::kValue});
        floors.push_back(row->float_floor_px);
      }
      panel.series.push_back(std::move(measured));
      panel.series.push_back(std::move(bound));
    }
    if (floors.empty()) continue;
    panel.lines.push_back({0.5, "0.5 px", "#C00000", true});
    panel.lines.push_back({floors.front(), "float floor", "#666666", true});
    chart.panels.push_back(std::move(panel));
  }
  if (chart.panels.empty()) return std::nullopt;
  for (size_t m = 0; m < kModeCount; ++m) chart.legend.push_back({modeText(kAllModes[m]), modeColor(m), modeMarker(m), true});
  chart.legend.push_back({"measured max error", "#444444", Marker::kNone, true, false});
  chart.legend.push_back({"predicted bound", "#444444", Marker::kNone, true, true});
  return chart;
}

std::optional<Image> montageImage(const BenchRun& run) {
  if (!run.montage || run.montage->modes.empty()) return std::nullopt;
  const MontageCapture& m = *run.montage;
  const BenchCase& c = *m.bench_case;
  // From below the float floor of any tile size we draw to the point where a point is far off.
  const double lo_px = 1e-6, hi_px = 100.0;
  std::vector<MontageTile> tiles;
  for (const MontageMode& shot : m.modes) {
    MontageTile tile;
    tile.label = modeText(shot.mode);
    tile.caption = shot.caption;
    if (shot.picture.width == 0) {  // the mode did not run: an empty tile says so through its caption
      tile.picture.width = c.width;
      tile.picture.height = c.height;
      tile.picture.rgba.assign(size_t(c.width) * c.height * 4, 0);
      tile.heat = tile.picture;
    } else {
      tile.picture = shot.picture;
      tile.heat = errorHeatMap(m.reference, shot.error_px, c.width, c.height, lo_px, hi_px);
    }
    tiles.push_back(std::move(tile));
  }
  char centre[96];
  std::snprintf(centre, sizeof centre, "(%.16g, %.16g)", c.view.window_center.x, c.view.window_center.y);
  const std::string title = c.name.substr(c.name.find(':') == std::string::npos ? 0 : c.name.find(':') + 2) + " around " +
                            centre + ", " + std::to_string(c.width) + "x" + std::to_string(c.height) + ", " +
                            backendText(m.backend) + " backend: picture (top), each point's error (bottom)";
  return composeMontage(title, tiles, lo_px, hi_px);
}

}  // namespace dpoint
