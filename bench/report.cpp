#include "bench/report.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "core/atomic_file.h"
#include "core/text.h"
#include "image/image.h"
#include "bench/report_internal.h"

namespace dpoint {
namespace {

using namespace report;

// ---- checks ----------------------------------------------------------------------------------

void checkGroup(const BenchCase& c, Backend backend, const ModeRows& rows, std::vector<CheckFailure>& out) {
  auto fail = [&](PrecisionMode mode, std::string what) {
    out.push_back({c.name, backendText(backend), modeText(mode), std::move(what)});
  };
  for (const BenchRow* row : rows) {
    if (!ran(row) || !std::isfinite(row->predicted_bound_px)) continue;
    // The bound is a rigorous upper bound of each point's error; 1e-9 relative is print slack only.
    if (row->error_max_px && *row->error_max_px > row->predicted_bound_px * (1 + 1e-9))
      fail(row->mode, "max error " + g3(*row->error_max_px) + " px is above its predicted bound " +
                          g3(row->predicted_bound_px) + " px");
    if (!row->error_max_px && row->points_visible > 0 && row->predicted_bound_px < 0.5)
      fail(row->mode, "every visible point was lost, though the bound is " + g3(row->predicted_bound_px) + " px");
  }
  const BenchRow* fp32 = rowOf(rows, PrecisionMode::kFp32);
  const BenchRow* split = rowOf(rows, PrecisionMode::kSplit);
  // The study's hi + lo rounds back to hi in float, so split computes exactly what fp32 does.
  if (ran(fp32) && ran(split) && fp32->error_max_px.has_value() != split->error_max_px.has_value())
    fail(PrecisionMode::kSplit, "split lost a different set of points than fp32");
  else if (ran(fp32) && ran(split) && fp32->error_max_px && *fp32->error_max_px != *split->error_max_px)
    fail(PrecisionMode::kSplit, "split's max error " + g3(*split->error_max_px) + " px differs from fp32's " +
                                    g3(*fp32->error_max_px) + " px");
  // native meets the float floor everywhere: no mode may beat it by more than one floor.
  const BenchRow* native = rowOf(rows, PrecisionMode::kNative);
  if (ran(native)) {
    for (const BenchRow* other : rows) {
      if (!ran(other) || other == native || !other->error_max_px) continue;
      if (!native->error_max_px)
        fail(PrecisionMode::kNative, "native lost every point where " + modeText(other->mode) + " did not");
      else if (*native->error_max_px > *other->error_max_px + native->float_floor_px)
        fail(PrecisionMode::kNative, "native's max error " + g3(*native->error_max_px) + " px is above " +
                                         modeText(other->mode) + "'s " + g3(*other->error_max_px) + " px");
    }
  }
  // Where fp32 is off by more than a pixel, every double-precision mode must do better.
  if (ran(fp32) && (!fp32->error_max_px || *fp32->error_max_px > 1.0)) {
    for (PrecisionMode mode : kAllModes) {
      if (!modeInfo(mode).scene_frame) continue;  // the study's absolute baselines, fp32 and split
      const BenchRow* row = rowOf(rows, mode);
      if (!ran(row) || !fp32->error_max_px) continue;
      if (!row->error_max_px || *row->error_max_px > *fp32->error_max_px)
        fail(mode, modeText(mode) + " is no better than fp32 (" + g3(*fp32->error_max_px) + " px)");
    }
  }
}

// ---- JSON ------------------------------------------------------------------------------------

std::string num(double v) { return formatNumber(v, true); }
std::string optNum(const std::optional<double>& v) { return v ? num(*v) : "null"; }

// Adaptive's share of batches at 1, 2 and 3 tiers; null for the other modes.
std::string tierShareJson(const std::optional<std::array<double, kAdaptiveTiers>>& shares) {
  if (!shares) return "null";
  std::string s;
  for (double share : *shares) s += (s.empty() ? "[" : ", ") + num(share);
  return s + "]";
}

std::string generateCommand(const BenchCase& c) {
  if (c.generate.empty()) return "";
  std::string s = "dpoint generate";
  for (const std::string& arg : c.generate) s += " " + arg;
  return s;
}

std::string sweepName(Sweep sweep) {
  return sweep == Sweep::kDeepZoom ? "deep zoom (view width)" : sweep == Sweep::kOffset ? "offset" : "";
}

// The bound divides by the faster read + write rate; bound_uses says which for a reader of the file alone.
std::string copyBandwidthJson(const std::optional<CopyBandwidth>& copy) {
  if (!copy) return "null";
  return "{\"read_write_gb_per_s\": " + num(copy->read_write_gb_per_s) + ", \"copy_gb_per_s\": " +
         num(copy->copy_gb_per_s) + ", \"copy_bytes\": " + std::to_string(copy->bytes) + ", \"copies\": " +
         std::to_string(copy->copies) + ", \"copy_ms_median\": " + num(copy->copy_ms_median) + ", \"timer\": " +
         jsonString(copy->gpu_timestamps ? "gpu timestamps" : "host wall time") +
         ", \"shader_read_write_gb_per_s\": " + num(copy->shader_read_write_gb_per_s) +
         ", \"shader_copy_ms_median\": " + num(copy->shader_copy_ms_median) + ", \"bound_uses\": " +
         jsonString(copy->shaderCopyFaster() ? "shader_read_write_gb_per_s" : "read_write_gb_per_s") + "}";
}

std::string rowJson(const BenchRun& run, const BenchRow& r) {
  const BenchCase& c = *r.bench_case;
  const DeviceFacts& d = run.device;
  std::string s = "    {\"suite\": " + jsonString(std::string(suiteName(c.suite))) + ", \"case\": " + jsonString(c.name) +
                  ", \"family\": " + jsonString(c.family) + ", \"hard\": " + (c.hard ? "true" : "false") +
                  ",\n     \"dataset\": " + jsonString(c.generate.empty() ? "literal CSV (" + cacheFileName(c) + ")"
                                                                            : generateCommand(c)) +
                  ", \"points\": " + std::to_string(r.points) + ", \"mode\": " + jsonString(modeText(r.mode)) +
                  ", \"backend\": " + jsonString(backendText(r.backend)) + ",\n     \"device\": " + jsonString(d.name) +
                  ", \"driver\": " + jsonString(d.driver_name + " " + formatDriverVersion(d.vendor_id, d.driver_version)) +
                  ", \"resolution\": " + jsonString(std::to_string(c.width) + "x" + std::to_string(c.height)) +
                  ",\n     \"skipped\": " + (r.skipped.empty() ? std::string("null") : jsonString(r.skipped));
  s += ", \"gpu_ms\": " + (r.gpu_ms_median ? "{\"median\": " + num(*r.gpu_ms_median) + ", \"p95\": " + optNum(r.gpu_ms_p95) +
                                                 ", \"min\": " + optNum(r.gpu_ms_min) + "}"
                                           : std::string("null"));
  s += ", \"frame_ms_median\": " + num(r.frame_ms_median) + ", \"e2e_ms\": " + num(r.e2e_ms) +
       ", \"upload_ms\": " + num(r.upload_ms) + ", \"readback_ms\": " + num(r.readback_ms) +
       ", \"warmup\": " + (r.skipped.empty() ? "{\"frames\": " + std::to_string(r.warmup_frames) + ", \"ms\": " +
                                                   num(r.warmup_ms) + "}"
                                             : std::string("null")) +
       ",\n     \"points_per_s\": " + num(r.points_per_s) + ", \"bytes_per_point\": " + std::to_string(r.bytes_per_point) +
       ", \"splat_bytes_per_point\": " + std::to_string(r.splat_bytes_per_point) +
       ", \"loaded_bytes_per_point\": " + optNum(r.loaded_bytes_per_point) + ", \"culled_share\": " + optNum(r.culled_share) +
       ", \"tier_share\": " + tierShareJson(r.tier_share) +
       ", \"bytes_per_frame\": " + (r.bytes_per_frame ? std::to_string(*r.bytes_per_frame) : std::string("null")) +
       ",\n     \"bandwidth_bound_ms\": " + optNum(r.bandwidth_bound_ms) +
       ", \"bandwidth_fraction\": " + optNum(r.bandwidth_fraction) +
       ", \"predicted_bound_px\": " + num(r.predicted_bound_px) + ", \"float_floor_px\": " + num(r.float_floor_px);
  s += ",\n     \"error_px\": " + (r.error_max_px ? "{\"max\": " + num(*r.error_max_px) + ", \"p99\": " + optNum(r.error_p99_px) +
                                                     ", \"rms\": " + optNum(r.error_rms_px) + "}"
                                               : std::string("null"));
  s += ", \"share_off_half_px\": " + num(r.share_off_half_px) + ", \"points_visible\": " + std::to_string(r.points_visible) +
       ", \"points_lost\": " + std::to_string(r.points_lost) +
       ", \"pixels_differing\": " + (r.pixels_differing ? std::to_string(*r.pixels_differing) : std::string("null"));
  s += ",\n     \"sweep\": " + (c.sweep == Sweep::kNone ? std::string("null")
                                                       : "{\"kind\": " + jsonString(sweepName(c.sweep)) + ", \"x\": " +
                                                             num(c.sweep_x) + "}");
  if (c.study) {
    // Text as the paper prints it (one cell is "31.12.16"), null where it prints nothing.
    const auto cell = [](const std::string& text) { return text.empty() ? std::string("null") : jsonString(text); };
    const auto cells = [&](const StudyCells& row) {
      return row.empty() ? std::string("null")
                         : "{\"rendering_time_ms\": " + cell(row.rendering_time_ms) + ", \"fps\": " + cell(row.fps) + "}";
    };
    s += ",\n     \"study_rtx3090\": {\"source\": " + jsonString(c.study->source) +
         ", \"emulated\": " + cells(c.study->emulated) + ", \"native\": " + cells(c.study->native) + "}";
  }
  return s + "}";
}

}  // namespace

std::vector<CheckFailure> checkRun(const BenchRun& run) {
  using namespace report;
  std::vector<CheckFailure> out;
  for (const BenchCase& c : run.cases)
    for (Backend backend : backendsOf(run)) checkGroup(c, backend, rowsFor(run, &c, backend), out);
  return out;
}

std::string resultsJson(const BenchRun& run, const ReportContext& context, const std::vector<CheckFailure>& failures) {
  const DeviceFacts& d = run.device;
  std::string suites;
  for (const BenchCase& c : run.cases) {
    const std::string name = jsonString(std::string(suiteName(c.suite)));
    if (suites.find(name) == std::string::npos) suites += (suites.empty() ? "" : ", ") + name;
  }
  std::string s = "{\n  \"dpoint_version\": " + jsonString(context.version) + ",\n  \"command\": " + jsonString(context.command) +
                  ",\n  \"date\": " + jsonString(context.date) + ",\n  \"suites\": [" + suites + "],\n";
  s += "  \"device\": {\"name\": " + jsonString(d.name) + ", \"type\": " + jsonString(d.type) +
       ", \"driver\": " + jsonString(d.driver_name + " " + d.driver_info) +
       ", \"driver_version\": " + jsonString(formatDriverVersion(d.vendor_id, d.driver_version)) +
       ", \"api_version\": " + jsonString(formatApiVersion(d.api_version)) + "},\n";
  s += "  \"copy_bandwidth\": " + copyBandwidthJson(run.copy_bandwidth) + ",\n";
  s += "  \"seconds\": " + num(run.seconds) + ",\n";
  if (context.baseline) s += "  \"baseline\": " + baselineJson(*context.baseline) + ",\n";
  s += "  \"rows\": [\n";
  for (size_t i = 0; i < run.rows.size(); ++i) s += rowJson(run, run.rows[i]) + (i + 1 < run.rows.size() ? ",\n" : "\n");
  s += "  ],\n  \"check_failures\": [";
  for (size_t i = 0; i < failures.size(); ++i) {
    const CheckFailure& f = failures[i];
    s += std::string(i ? "," : "") + "\n    {\"case\": " + jsonString(f.case_name) + ", \"backend\": " + jsonString(f.backend) +
         ", \"mode\": " + jsonString(f.mode) + ", \"what\": " + jsonString(f.what) + "}";
  }
  return s + (failures.empty() ? "]\n}\n" : "\n  ]\n}\n");
}

Result<std::vector<std::string>> writeReport(const BenchRun& run, const ReportContext& context,
                                             const std::vector<CheckFailure>& failures, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return Error{"cannot create " + dir + ": " + ec.message(), ExitCode::kBadInput};
  // Every file is written in full before any replaces the last run's, and the last run's optional
  // files this run does not make are removed: the folder holds one run's report (a full disk left
  // a new results.json beside the last run's charts; a paper run kept a ci run's breakdown.svg).
  std::vector<std::pair<std::string, AtomicFile>> files;
  auto put = [&](const std::string& name, const void* data, size_t size) -> Status {
    const std::string path = (std::filesystem::path(dir) / name).string();
    Result<AtomicFile> file = AtomicFile::create(path);
    if (!file) return file.error();
    if (Status s = file->checkSpace(size); !s) return s;
    if (Status s = file->write(data, size); !s) return s;
    files.emplace_back(path, std::move(*file));
    return okStatus();
  };
  auto putText = [&](const std::string& name, const std::string& text) { return put(name, text.data(), text.size()); };
  if (Status s = putText("results.json", resultsJson(run, context, failures)); !s) return s.error();
  if (Status s = putText("report.md", reportMarkdown(run, context, failures)); !s) return s.error();
  if (Status s = putText("speed_vs_error.svg", renderChartSvg(speedVsErrorChart(run))); !s) return s.error();
  if (std::optional<Chart> breakdown = breakdownChart(run)) {
    if (Status s = putText("breakdown.svg", renderChartSvg(*breakdown)); !s) return s.error();
  }
  if (std::optional<Image> montage = montageImage(run)) {
    Result<std::vector<unsigned char>> png = pngBytes(*montage, (std::filesystem::path(dir) / "montage.png").string());
    if (!png) return png.error();
    if (Status s = put("montage.png", png->data(), png->size()); !s) return s.error();
  }
  std::vector<std::string> written;
  for (auto& [path, file] : files) {
    if (Status s = file.commit(); !s) return s.error();
    written.push_back(path);
  }
  for (const char* optional : {"breakdown.svg", "montage.png"}) {
    const std::filesystem::path stale = std::filesystem::path(dir) / optional;
    if (std::find(written.begin(), written.end(), stale.string()) == written.end()) std::filesystem::remove(stale, ec);
  }
  return written;
}

}  // namespace dpoint
