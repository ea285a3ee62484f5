#include "bench/baseline.h"

#include <cmath>
#include <cstdio>

#include "bench/report_internal.h"
#include "converters/gltf_json.h"
#include "core/input_file.h"
#include "core/text.h"
#include "viewer/modes.h"

namespace dpoint {
namespace {

Error badBaseline(const std::string& path, const std::string& what) {
  return Error{path + ": not a dpoint bench results.json: " + what, ExitCode::kBadInput};
}

std::string fixed(double v, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, v);
  return text;
}

}  // namespace

Result<Baseline> readBaseline(const std::string& path) {
  Result<InputFile> file = InputFile::open(path);
  if (!file) return file.error();
  std::string text(file->size(), '\0');
  Result<size_t> got = file->readAt(0, text.data(), text.size());
  if (!got) return got.error();
  text.resize(*got);
  Result<JsonValue> json = parseJson(text, 16);
  if (!json) return Error{path + ": " + json.error().message, ExitCode::kBadInput};
  const JsonValue* rows = json->find("rows");
  if (!rows || rows->kind != JsonValue::Kind::kArray) return badBaseline(path, "no \"rows\" array");
  Baseline baseline;
  baseline.path = path;
  if (const JsonValue* device = json->find("device"))
    if (const JsonValue* name = device->find("name"); name && name->kind == JsonValue::Kind::kString)
      baseline.device = name->text;
  if (const JsonValue* date = json->find("date"); date && date->kind == JsonValue::Kind::kString) baseline.date = date->text;
  for (size_t i = 0; i < rows->items.size(); ++i) {
    const JsonValue& row = rows->items[i];
    const JsonValue *name = row.find("case"), *backend = row.find("backend"), *mode = row.find("mode");
    if (!name || !backend || !mode || name->kind != JsonValue::Kind::kString ||
        backend->kind != JsonValue::Kind::kString || mode->kind != JsonValue::Kind::kString)
      return badBaseline(path, "row " + std::to_string(i) + " lacks case, backend or mode");
    const JsonValue* gpu = row.find("gpu_ms");
    const JsonValue* median = gpu ? gpu->find("median") : nullptr;
    // Not timed there (a case that did not run), or not a time (1e999 parses as infinity).
    if (!median || median->kind != JsonValue::Kind::kNumber || !(median->number > 0.0) || !std::isfinite(median->number))
      continue;
    baseline.rows.push_back({name->text, backend->text, mode->text, median->number});
  }
  return baseline;
}

size_t BaselineReport::slower() const {
  size_t n = 0;
  for (const BaselineComparison& c : rows) n += c.slower;
  return n;
}

BaselineReport compareToBaseline(const BenchRun& run, const Baseline& baseline, double tolerance) {
  BaselineReport report{baseline.path, baseline.device, baseline.date, baseline.device == run.device.name, {}};
  for (const BenchRow& row : run.rows) {
    if (!row.gpu_ms_median || !row.skipped.empty()) continue;
    const std::string name = row.bench_case->name, backend = report::backendText(row.backend), mode = report::modeText(row.mode);
    for (const BaselineRow& b : baseline.rows)
      if (b.case_name == name && b.backend == backend && b.mode == mode) {
        BaselineComparison c{name, backend, mode, b.gpu_ms, *row.gpu_ms_median, false};
        c.slower = c.ratio() > 1.0 + tolerance;
        report.rows.push_back(c);
        break;
      }
  }
  return report;
}

std::string baselineJson(const BaselineReport& report) {
  std::string s = "{\"path\": " + jsonString(report.path) + ", \"device\": " + jsonString(report.device) +
                  ", \"date\": " + jsonString(report.date) + ", \"same_device\": " + (report.same_device ? "true" : "false") +
                  ", \"tolerance\": " + formatNumber(kBaselineTolerance, true) + ", \"slower\": " + std::to_string(report.slower()) +
                  ",\n    \"rows\": [";
  for (size_t i = 0; i < report.rows.size(); ++i) {
    const BaselineComparison& c = report.rows[i];
    s += std::string(i ? "," : "") + "\n      {\"case\": " + jsonString(c.case_name) + ", \"backend\": " +
         jsonString(c.backend) + ", \"mode\": " + jsonString(c.mode) + ", \"baseline_ms\": " + formatNumber(c.baseline_ms, true) +
         ", \"gpu_ms\": " + formatNumber(c.now_ms, true) + ", \"ratio\": " + formatNumber(c.ratio(), true) +
         ", \"slower\": " + (c.slower ? "true" : "false") + "}";
  }
  return s + (report.rows.empty() ? "]}" : "\n    ]}");
}

std::string baselineMarkdown(const BaselineReport& report) {
  std::string s = "## Against the baseline\n\n`" + report.path + "` (" + report.device + ", " + report.date + "): " +
                  std::to_string(report.rows.size()) + " rows compared, **" + std::to_string(report.slower()) +
                  " more than " + fixed(100.0 * kBaselineTolerance, 0) + "% slower** (GPU median).\n";
  if (!report.same_device)
    s += "\nThe baseline ran on another device: the ratios compare two machines, not two builds.\n";
  s += "\n| case | backend | mode | baseline ms | now ms | now / baseline | |\n| --- | --- | --- | --- | --- | --- | --- |\n";
  for (const BaselineComparison& c : report.rows)
    s += "| " + c.case_name + " | " + c.backend + " | " + c.mode + " | " + fixed(c.baseline_ms, 4) + " | " +
         fixed(c.now_ms, 4) + " | " + fixed(c.ratio(), 3) + " | " + (c.slower ? "**slower**" : "") + " |\n";
  return s + "\n";
}

}  // namespace dpoint
