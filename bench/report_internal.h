// Helpers the report's parts share (report.cpp: JSON and checks; report_md.cpp: Markdown;
// figures.cpp: the charts and the montage). Not part of the bench library's interface.
#pragma once

#include <algorithm>
#include <array>
#include <cstdio>
#include <string>
#include <vector>

#include "bench/run.h"

namespace dpoint::report {

using ModeRows = std::array<const BenchRow*, kModeCount>;  // by modeIndex; null: not in the run

inline std::string backendText(Backend backend) { return backend == Backend::kCompute ? "compute" : "raster"; }
inline std::string modeText(PrecisionMode mode) { return std::string(modeName(mode)); }

// Three significant digits, as the tables print numbers.
inline std::string g3(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

inline bool ran(const BenchRow* row) { return row && row->skipped.empty(); }

// The backends in the run, in the order they ran.
inline std::vector<Backend> backendsOf(const BenchRun& run) {
  std::vector<Backend> out;
  for (const BenchRow& row : run.rows)
    if (std::find(out.begin(), out.end(), row.backend) == out.end()) out.push_back(row.backend);
  return out;
}

inline ModeRows rowsFor(const BenchRun& run, const BenchCase* c, Backend backend) {
  ModeRows out{};
  for (const BenchRow& row : run.rows)
    if (row.bench_case == c && row.backend == backend) out[modeIndex(row.mode)] = &row;
  return out;
}

inline const BenchRow* rowOf(const ModeRows& rows, PrecisionMode mode) { return rows[modeIndex(mode)]; }

// GPU time per frame, or the host's frame time where the queue has no timestamps.
inline double frameMs(const BenchRow& row) { return row.gpu_ms_median.value_or(row.frame_ms_median); }

// Whether `row` draws faster or slower than `base` beyond run-to-run noise. Each row's timed frames
// span [min, p95] of their GPU times; `row` is faster only when its p95 is below `base`'s min (19 of
// 20 of its frames beat the other's best frame), slower only when its min is above `base`'s p95, and
// within noise when the two spans overlap. Why the whole span and not the medians alone: a median
// of 20 frames moves between runs by about the frames' spread, which on lavapipe's 2 shared cores
// is 2–3× at 10K points ([0.98, 3.18] ms around a 2.16 ms median), so a 0.75× ratio of two such
// medians came out either way from run to run; on the H100 the spans are 1–3% wide and a 13%
// difference is outside them. Rows without GPU timestamps (host frame times only) carry no span:
// kNoSpread, never called faster or slower.
enum class FrameComparison { kFaster, kSlower, kWithinNoise, kNoSpread };
inline FrameComparison compareFrames(const BenchRow& row, const BenchRow& base) {
  if (!row.gpu_ms_median || !row.gpu_ms_min || !row.gpu_ms_p95 || !base.gpu_ms_median || !base.gpu_ms_min ||
      !base.gpu_ms_p95)
    return FrameComparison::kNoSpread;
  if (*row.gpu_ms_p95 < *base.gpu_ms_min) return FrameComparison::kFaster;
  if (*row.gpu_ms_min > *base.gpu_ms_p95) return FrameComparison::kSlower;
  return FrameComparison::kWithinNoise;
}

// The backend the sweeps and the montage are drawn from: compute when it ran (the fast path).
inline Backend figureBackend(const std::vector<Backend>& backends) {
  return std::find(backends.begin(), backends.end(), Backend::kCompute) != backends.end() || backends.empty()
             ? Backend::kCompute
             : backends.front();
}
inline Backend figureBackend(const BenchRun& run) { return figureBackend(backendsOf(run)); }

}  // namespace dpoint::report
