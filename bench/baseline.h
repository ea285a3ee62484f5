// A run against a recorded baseline (issue #38): `dpoint bench --baseline FILE` reads an earlier
// run's results.json (bench/results/baselines/DEVICE.json keeps one per device class) and marks
// every row whose GPU median is more than `tolerance` slower than the same case, backend and mode
// there. Rows the baseline lacks, or that have no GPU time on either side, are not compared.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "bench/run.h"
#include "core/result.h"

namespace dpoint {

inline constexpr double kBaselineTolerance = 0.05;  // more than 5% slower is marked

struct BaselineRow {
  std::string case_name, backend, mode;
  double gpu_ms = 0.0;  // the GPU median
};

struct Baseline {
  std::string path;
  std::string device;  // the device the baseline ran on (results.json's device.name)
  std::string date;
  std::vector<BaselineRow> rows;
};

// Reads a results.json of `dpoint bench`. Errors name the file and what is wrong, exit 2.
Result<Baseline> readBaseline(const std::string& path);

struct BaselineComparison {
  std::string case_name, backend, mode;
  double baseline_ms = 0.0, now_ms = 0.0;
  double ratio() const { return now_ms / baseline_ms; }
  bool slower = false;  // ratio > 1 + tolerance
};

struct BaselineReport {
  std::string path, device, date;
  bool same_device = true;  // the run's device has the baseline's name
  std::vector<BaselineComparison> rows;  // in the run's row order
  size_t slower() const;
};

BaselineReport compareToBaseline(const BenchRun& run, const Baseline& baseline, double tolerance = kBaselineTolerance);

// results.json's "baseline" object and report.md's section (empty text when there is no baseline).
std::string baselineJson(const BaselineReport& report);
std::string baselineMarkdown(const BaselineReport& report);

}  // namespace dpoint
