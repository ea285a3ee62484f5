// report.md: the bench's tables for a reader (issue #10). The study's figures stand beside ours in
// the speed tables; the hard cases show each mode's measured error against its predicted bound.
#include <cmath>
#include <map>

#include "bench/report.h"
#include "bench/report_internal.h"

namespace dpoint {
namespace {

using namespace report;

std::string withCommas(uint64_t n) {
  std::string digits = std::to_string(n), out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

// Whole frames per second with thousands separated from 100 up (a reader compares magnitudes),
// three digits below.
std::string fpsText(double fps) {
  return fps >= 100 ? withCommas(static_cast<uint64_t>(std::llround(fps))) : g3(fps);
}

std::string msText(double ms) { return ms >= 100 ? withCommas(static_cast<uint64_t>(std::llround(ms))) : g3(ms); }

std::string percentText(const std::optional<double>& fraction) { return fraction ? g3(100.0 * *fraction) + "%" : "–"; }

// Adaptive's share of batches at 1, 2 and 3 tiers: "tiers 80/15/5%".
std::string tiersText(const std::array<double, kAdaptiveTiers>& shares) {
  std::string text = "tiers ";
  for (size_t t = 0; t < shares.size(); ++t) text += (t ? "/" : "") + g3(100.0 * shares[t]);
  return text + "%";
}

// What a per-batch mode's frame loaded (its plan for the view): "4.8 B/pt loaded, tiers 80/15/5%".
std::string loadedText(const BenchRow& row) {
  if (!modeInfo(row.mode).batch_points || !row.loaded_bytes_per_point) return "";
  std::string text = g3(*row.loaded_bytes_per_point) + " B/pt loaded";
  if (row.tier_share) text += ", " + tiersText(*row.tier_share);
  return text;
}

std::string fpsCell(const BenchRow* row) {
  if (!row) return "–";
  if (!row->skipped.empty()) return "did not run";
  const double ms = frameMs(*row);
  std::string cell = fpsText(1000.0 / ms) + " fps (" + msText(ms) + " ms" + (row->gpu_ms_median ? "" : ", host");
  if (row->bandwidth_fraction) cell += ", " + percentText(row->bandwidth_fraction) + " of bound";
  if (const std::string loaded = loadedText(*row); !loaded.empty()) cell += "; " + loaded;
  return cell + ")";
}

// The per-batch modes' plan in the table of every run: the share of batches culled, and adaptive's
// share at each tier count.
std::string planCell(const BenchRow& row) {
  if (!row.culled_share) return "–";
  std::string cell = g3(100.0 * *row.culled_share) + "% culled";
  if (row.tier_share) cell += ", " + tiersText(*row.tier_share);
  return cell;
}

// "rte, df64, native, batch and adaptive": the modes checked against fp32 where it is off.
std::string sceneFrameModes() {
  std::vector<std::string> names;
  for (PrecisionMode mode : kAllModes)
    if (modeInfo(mode).scene_frame) names.push_back(modeText(mode));
  std::string text;
  for (size_t i = 0; i < names.size(); ++i) text += (i == 0 ? "" : i + 1 == names.size() ? " and " : ", ") + names[i];
  return text;
}

std::string errorCell(const BenchRow* row) {
  if (!row) return "–";
  if (!row->skipped.empty()) return "did not run";
  std::string measured = row->error_max_px ? g3(*row->error_max_px) : "all lost";
  std::string bound = std::isfinite(row->predicted_bound_px) ? g3(row->predicted_bound_px) : "unbounded";
  std::string cell = measured + " / " + bound;
  if (row->error_max_px && row->points_lost) cell += " (" + withCommas(row->points_lost) + " lost)";
  return cell;
}

// One path of the study's figures, both columns as printed ("9.71 ms, 729 fps"; "–" for a column
// the paper leaves empty), with where they come from when it is not the tables.
std::string studyCell(const BenchCase& c, bool native) {
  if (!c.study) return "–";
  const StudyCells& cells = native ? c.study->native : c.study->emulated;
  if (cells.empty()) return "–";
  std::string cell = (cells.rendering_time_ms.empty() ? "–" : cells.rendering_time_ms + " ms") + ", " +
                     (cells.fps.empty() ? "–" : cells.fps + " fps");
  if (c.study->source != "Tables 2 and 3") cell += " (" + c.study->source + ")";
  return cell;
}

std::string modeHeader(bool with_bytes) {
  std::string h;
  for (PrecisionMode mode : kAllModes) {
    h += ' ';
    h += modeText(mode);
    // A per-batch mode loads at most its layout's bytes: its plan culls and (adaptive) picks tiers.
    if (with_bytes)
      h += std::string(" (") + (modeInfo(mode).batch_points ? "≤ " : "") + std::to_string(positionBytes(mode)) +
           " B/pt splat, " + std::to_string(bytesPerPoint(mode)) + " total)";
    h += " |";
  }
  return h;
}

std::string modeRule() {
  std::string rule;
  for (size_t i = 0; i < kModeCount; ++i) rule += " --- |";
  return rule;
}

std::vector<const BenchCase*> casesWhere(const BenchRun& run, bool hard) {
  std::vector<const BenchCase*> out;
  for (const BenchCase& c : run.cases)
    if (c.hard == hard) out.push_back(&c);
  return out;
}

// The speed datasets a summary is taken over: those of a million points or more when the run has
// any (small sets time the launch, not the points), else all of them.
std::vector<const BenchCase*> summaryCases(const BenchRun& run) {
  std::vector<const BenchCase*> speed = casesWhere(run, false), big;
  for (const BenchCase* c : speed) {
    const ModeRows rows = rowsFor(run, c, backendsOf(run).front());
    if (rows[0] && rows[0]->points >= 1000000) big.push_back(c);
  }
  return big.empty() ? speed : big;
}

// Ratios of frame times over several datasets, each pair classed by compareFrames.
struct RatioSummary {
  std::vector<double> ratios;
  size_t faster = 0, slower = 0;  // pairs beyond noise; the rest are within it or have no span
};

void addRatio(RatioSummary& summary, const BenchRow& row, const BenchRow& base) {
  summary.ratios.push_back(frameMs(row) / frameMs(base));
  const FrameComparison c = compareFrames(row, base);
  summary.faster += c == FrameComparison::kFaster;
  summary.slower += c == FrameComparison::kSlower;
}

// The median ratio is called a speed-up (below 1) or a slow-down (above 1) only when more than half
// of the pairs differ beyond noise in that direction; otherwise it is "≈": the datasets do not
// show a difference larger than their frames' own spread (compareFrames says why).
bool beyondNoise(const RatioSummary& summary, double median) {
  const size_t agreeing = median < 1.0 ? summary.faster : median > 1.0 ? summary.slower : 0;
  return 2 * agreeing > summary.ratios.size();
}

std::string noiseCount(const RatioSummary& summary) {
  const size_t n = summary.ratios.size();
  return std::to_string(summary.faster) + " of " + std::to_string(n) + " faster, " + std::to_string(summary.slower) +
         " slower beyond noise";
}

void glanceCost(const BenchRun& run, std::string& s) {
  const std::vector<const BenchCase*> cases = summaryCases(run);
  if (cases.empty()) return;
  bool any_within = false;
  for (Backend backend : backendsOf(run)) {
    std::string line;
    for (PrecisionMode mode : kAllModes) {
      if (mode == PrecisionMode::kFp32) continue;
      RatioSummary summary;
      for (const BenchCase* c : cases) {
        const ModeRows rows = rowsFor(run, c, backend);
        const BenchRow *base = rowOf(rows, PrecisionMode::kFp32), *row = rowOf(rows, mode);
        if (ran(base) && ran(row)) addRatio(summary, *row, *base);
      }
      if (summary.ratios.empty()) continue;
      const double median = medianOf(summary.ratios);
      line += line.empty() ? "" : ", ";
      if (beyondNoise(summary, median)) {
        line += modeText(mode) + " " + g3(median) + "× (" + noiseCount(summary) + ")";
      } else {
        line += modeText(mode) + " ≈ fp32 (within noise: median " + g3(median) + "×, " + noiseCount(summary) + ")";
        any_within = true;
      }
    }
    if (!line.empty())
      s += "- **Cost of precision, " + backendText(backend) + " backend**: GPU time per frame against fp32's, median over " +
           std::to_string(cases.size()) + " dataset(s): " + line + ".\n";
  }
  RatioSummary speedups;  // compute against raster: below 1 is compute faster
  for (const BenchCase* c : cases) {
    const ModeRows raster = rowsFor(run, c, Backend::kRaster), compute = rowsFor(run, c, Backend::kCompute);
    for (size_t m = 0; m < kModeCount; ++m)
      if (ran(raster[m]) && ran(compute[m])) addRatio(speedups, *compute[m], *raster[m]);
  }
  if (!speedups.ratios.empty()) {
    std::vector<double> as_fast;  // raster time / compute time: how many times as fast compute is
    for (double r : speedups.ratios) as_fast.push_back(1.0 / r);
    const double median = medianOf(as_fast);
    const std::string range = "from " + g3(*std::min_element(as_fast.begin(), as_fast.end())) + "× to " +
                              g3(*std::max_element(as_fast.begin(), as_fast.end())) + "×; compute " +
                              noiseCount(speedups) + ")";
    if (beyondNoise(speedups, medianOf(speedups.ratios))) {
      s += "- **Backends**: the compute backend draws the same picture " + g3(median) +
           "× as fast as the raster backend (raster GPU time / compute GPU time, median over datasets and modes; " + range +
           ".\n";
    } else {
      s += "- **Backends**: compute ≈ raster (within noise: raster GPU time / compute GPU time " + g3(median) +
           "×, median over datasets and modes; " + range + ".\n";
      any_within = true;
    }
  }
  if (any_within)
    s += "- *≈ (within noise)*: a ratio is called faster or slower only when more than half of its datasets differ "
         "beyond run-to-run noise, i.e. one row's p95 frame time is below the other's fastest frame; otherwise the "
         "frames' spreads overlap and the median ratio says nothing (docs/performance.md).\n";
}

// Where each mode first puts points on a wrong pixel along a sweep: max error ≥ 0.5 px or points lost.
void glanceBreak(const BenchRun& run, Sweep sweep, const std::string& what, std::string& s) {
  const Backend backend = figureBackend(run);
  std::map<size_t, std::pair<double, double>> breaks;  // mode → (first x that breaks, last x seen)
  std::vector<const BenchCase*> steps;
  for (const BenchCase& c : run.cases)
    if (c.sweep == sweep) steps.push_back(&c);
  if (steps.empty()) return;
  std::string line;
  for (size_t m = 0; m < kModeCount; ++m) {
    std::string where;
    for (const BenchCase* c : steps) {
      const BenchRow* row = rowsFor(run, c, backend)[m];
      if (!ran(row)) continue;
      if (!row->error_max_px || *row->error_max_px >= 0.5 || row->points_lost) {
        where = "from " + g3(c->sweep_x) + " on";
        break;
      }
    }
    if (where.empty()) where = "never, to " + g3(steps.back()->sweep_x);
    line += (line.empty() ? "" : "; ") + modeText(kAllModes[m]) + " " + where;
  }
  s += "- **Where each mode breaks, " + what + "** (max error ≥ 0.5 px or points lost, " + backendText(backend) +
       " backend): " + line + ".\n";
}

}  // namespace

std::string reportMarkdown(const BenchRun& run, const ReportContext& context, const std::vector<CheckFailure>& failures) {
  const DeviceFacts& d = run.device;
  std::string s = "# dpoint bench: speed against error\n\n";
  s += "- Device: **" + d.name + "** (" + d.type + "), driver " + d.driver_name + " " + d.driver_info + " (" +
       formatDriverVersion(d.vendor_id, d.driver_version) + "), Vulkan " + formatApiVersion(d.api_version) + "\n";
  s += run.copy_bandwidth ? "- Copy bandwidth: **" + copyBandwidthText(*run.copy_bandwidth) +
                                "**; *% of bound* divides by the read+write rate\n"
                          : std::string("- Copy bandwidth: not measured (--no-copy-bandwidth): no bandwidth bound\n");
  s += "- Command: `" + context.command + "` (dpoint " + context.version + ", " + context.date + "; whole run " +
       withCommas(static_cast<uint64_t>(std::llround(run.seconds))) + " s)\n";
  s += "- Speed: GPU timestamps around the draw (raster) or the splat and resolve passes (compute), median of the timed "
       "frames after warm-up (untimed frames, as `--warmup` in the command says; each row's count and time are in "
       "results.json); p95, min and the end-to-end time (upload, one frame, readback) are in results.json. "
       "Absolute times count on a GPU; on lavapipe (a CPU) compare modes as ratios.\n";
  s += "- Error: each point's window position from the probe (the same shader storing its clip position) against the "
       "exact one (long double, same camera), in pixels; a mode's *bound* is predicted before drawing from its "
       "arithmetic (viewer/precision.h). Cells read *measured max / bound*.\n\n";

  s += "## At a glance\n\n";
  glanceCost(run, s);
  glanceBreak(run, Sweep::kDeepZoom, "zooming in (view width)", s);
  glanceBreak(run, Sweep::kOffset, "moving away from the origin (offset in m, 1 mm detail, 0.1 m away)", s);
  s += failures.empty() ? "- **Checks**: all passed (below).\n" : "- **Checks**: " + std::to_string(failures.size()) + " failed (below).\n";
  if (context.baseline)
    s += "- **Against the baseline**: " + std::to_string(context.baseline->slower()) + " of " +
         std::to_string(context.baseline->rows.size()) + " rows more than 5% slower (below).\n";
  if (context.baseline) s += "\n" + baselineMarkdown(*context.baseline);

  const std::vector<const BenchCase*> speed = casesWhere(run, false), hard = casesWhere(run, true);
  if (!speed.empty()) {
    s += "\n## Speed\n\nFrames per second from the median GPU time. The study's figures were measured on an NVIDIA RTX "
         "3090 with 48 B/pt (dvec3 position + dvec3 colour), at a resolution it does not give. Its Tables 2 (emulated "
         "double) and 3 (native double) print a rendering time and a frame rate for every 3D dataset; both columns "
         "are shown as printed, though they disagree with each other (695.76 ms is not 330 fps) and the paper does "
         "not say what its rendering time covers: compare our frame rate with its fps only. For the 2D sets it prints "
         "one figure, in a caption. Headers give the bytes per point the splat pass (raster: the vertex fetch) reads for "
         "positions, and in total with the colour. The per-batch modes (batch, adaptive) load less: per view, their "
         "plan skips batches outside it and adaptive loads 1, 2 or 3 tiers of 4 B per batch, the fewest its tolerance "
         "allows; their cells give the position bytes the frame loaded per point of the set and adaptive's share of "
         "batches at each tier count (batch's raster path fetches every point's 8 B). *% of bound* (compute "
         "backend): the time the frame's bytes take at the copy bandwidth, against the GPU time; the bytes are "
         "points × loaded B/pt + pixels × 20 B (clear, read and resolve the 8 B keys, write the picture) + 4 B of "
         "colour per covered pixel, every point taken to cover a pixel of its own (bench/bandwidth.h).\n";
    for (Backend backend : backendsOf(run)) {
      s += "\n### " + backendText(backend) + " backend\n\n| dataset | points | resolution | "
           "study, RTX 3090 (48 B/pt), emulated (Table 2): time, frame rate | study, native (Table 3): time, frame rate |" +
           modeHeader(true) + "\n| --- | --- | --- | --- | --- |" + modeRule() + "\n";
      for (const BenchCase* c : speed) {
        const ModeRows rows = rowsFor(run, c, backend);
        s += "| " + c->name + " | " + withCommas(rows[0] ? rows[0]->points : 0) + " | " + std::to_string(c->width) + "×" +
             std::to_string(c->height) + " | " + studyCell(*c, false) + " | " + studyCell(*c, true) + " |";
        for (const BenchRow* row : rows) s += " " + fpsCell(row) + " |";
        s += "\n";
      }
    }
    const Backend backend = figureBackend(run);
    s += "\n### Error on these datasets (" + backendText(backend) + " backend, px: measured max / predicted bound)\n\n"
         "| dataset |" + modeHeader(false) + "\n| --- |" + modeRule() + "\n";
    for (const BenchCase* c : speed) {
      s += "| " + c->name + " |";
      for (const BenchRow* row : rowsFor(run, c, backend)) s += " " + errorCell(row) + " |";
      s += "\n";
    }
  }
  if (!hard.empty()) {
    s += "\n## Hard cases\n\nThe views where fp32 and the emulated modes break (docs/precision.md, *The hard cases*). "
         "Max error in pixels: measured / predicted bound; \"all lost\": no visible point was drawn on screen. The "
         "offset sets are a Menger sponge with 1 mm cubes seen from 0.1 m; the deep-zoom sets one mandelbrot2d point "
         "per pixel centre.\n";
    for (Backend backend : backendsOf(run)) {
      s += "\n### " + backendText(backend) + " backend\n\n| case | points | resolution |" + modeHeader(false) +
           "\n| --- | --- | --- |" + modeRule() + "\n";
      for (const BenchCase* c : hard) {
        const ModeRows rows = rowsFor(run, c, backend);
        s += "| " + c->name + " | " + withCommas(rows[0] ? rows[0]->points : 0) + " | " + std::to_string(c->width) + "×" +
             std::to_string(c->height) + " |";
        for (const BenchRow* row : rows) s += " " + errorCell(row) + " |";
        s += "\n";
      }
    }
  }
  s += "\n## Checks\n\nWhat each mode's arithmetic predicts (docs/precision.md).\n\n";
  if (failures.empty()) {
    s += "All passed: every measured error is within its predicted bound; split equals fp32; native is the most "
         "accurate mode within one float floor; where fp32 is off by more than a pixel, " + sceneFrameModes() +
         " all do better.\n";
  } else {
    s += std::to_string(failures.size()) + " failed:\n\n| case | backend | mode | what |\n| --- | --- | --- | --- |\n";
    for (const CheckFailure& f : failures) s += "| " + f.case_name + " | " + f.backend + " | " + f.mode + " | " + f.what + " |\n";
  }
  s += "\n## Every run\n\n| suite | case | backend | mode | points | GPU ms (median / p95) | e2e ms | points/s | B/pt | "
       "B/pt (splat) | B/pt loaded | plan | % of bound | bound px | max px | p99 px | rms px | off ≥ 0.5 px | lost | "
       "pixels differing |\n"
       "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- "
       "| --- |\n";
  for (const BenchRow& r : run.rows) {
    s += "| " + std::string(suiteName(r.bench_case->suite)) + " | " + r.bench_case->name + " | " + backendText(r.backend) +
         " | " + modeText(r.mode) + " | " + withCommas(r.points) + " | ";
    if (!r.skipped.empty()) {
      s += "did not run: " + r.skipped + " | | | | | | | | | | | | | | |\n";
      continue;
    }
    s += (r.gpu_ms_median ? g3(*r.gpu_ms_median) + " / " + g3(r.gpu_ms_p95.value_or(0)) : "–") + " | " + g3(r.e2e_ms) +
         " | " + g3(r.points_per_s) + " | " + std::to_string(r.bytes_per_point) + " | " +
         std::to_string(r.splat_bytes_per_point) + " | " +
         (r.loaded_bytes_per_point ? g3(*r.loaded_bytes_per_point) : "–") + " | " + planCell(r) + " | " +
         percentText(r.bandwidth_fraction) + " | " +
         (std::isfinite(r.predicted_bound_px) ? g3(r.predicted_bound_px) : "unbounded") + " | " +
         (r.error_max_px ? g3(*r.error_max_px) + " | " + g3(r.error_p99_px.value_or(0)) + " | " + g3(r.error_rms_px.value_or(0))
                         : "all lost | – | –") +
         " | " + g3(100.0 * r.share_off_half_px) + "% | " + withCommas(r.points_lost) + " | " +
         (r.pixels_differing ? withCommas(*r.pixels_differing) : "–") + " |\n";
  }
  return s;
}

}  // namespace dpoint
