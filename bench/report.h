// What `dpoint bench` leaves in its output folder (issue #10): results.json (one row per run),
// report.md (the tables, the study's figures beside ours, the checks), speed_vs_error.svg,
// breakdown.svg and montage.png. Everything here is computed from a BenchRun; nothing is measured.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "bench/baseline.h"
#include "bench/run.h"
#include "bench/svg_chart.h"
#include "viewer/reference.h"

namespace dpoint {

struct ReportContext {
  std::string command;  // the command line as the user typed it
  std::string date;     // UTC, ISO 8601
  std::string version;  // dpoint's
  std::optional<BaselineReport> baseline;  // --baseline: the run against it (bench/baseline.h)
};

// A broken expectation of the modes' arithmetic (docs/precision.md): a measured error above its predicted bound, split not equal
// to fp32, native not the most accurate (within one float floor), or a mode no better than fp32
// where fp32 is off by more than a pixel.
struct CheckFailure {
  std::string case_name, backend, mode, what;
};
std::vector<CheckFailure> checkRun(const BenchRun& run);

std::string resultsJson(const BenchRun& run, const ReportContext& context, const std::vector<CheckFailure>& failures);
std::string reportMarkdown(const BenchRun& run, const ReportContext& context, const std::vector<CheckFailure>& failures);

// x = GPU ms/frame, y = max error in pixels, one panel per dataset family.
Chart speedVsErrorChart(const BenchRun& run);
// Max error against view width (deep-zoom sweep) and offset (offset sweep), one line per mode with
// its predicted bound dashed; empty when the run had neither sweep.
std::optional<Chart> breakdownChart(const BenchRun& run);
// The montage case in every mode with its error heat maps; empty when the run had no montage case.
std::optional<Image> montageImage(const BenchRun& run);

// Writes every file above into `dir` (created if missing); the SVGs and the PNG only when there is
// something to draw. All are written in full before any replaces an earlier run's, and an earlier
// run's optional file this run does not make is removed: the folder holds one run's report, or on
// an error the last one's. `failures` is checkRun(run). Returns the paths written.
Result<std::vector<std::string>> writeReport(const BenchRun& run, const ReportContext& context,
                                             const std::vector<CheckFailure>& failures, const std::string& dir);

}  // namespace dpoint
