// The bench's suites and its report logic on made-up runs (issue #10): the checks catch each broken
// expectation of DESIGN §4–5, results.json carries nulls where nothing was measured, and the suites
// hold the datasets and sweeps the issue lists. The real runs are in external/bench_ci_suite.py.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

#include "bench/bandwidth.h"
#include "bench/report.h"
#include "bench/run.h"
#include "bench/suites.h"
#include "test_support.h"

namespace dpoint {
namespace {

ReportContext testContext() { return ReportContext{"dpoint bench", "2026-11-23T00:00:00Z", "0", std::nullopt}; }

// One case, one backend, every mode measured with `errors` (NaN: every point lost) and `bounds`.
BenchRun madeUpRun(const std::array<double, kModeCount>& errors, const std::array<double, kModeCount>& bounds) {
  BenchRun run;
  BenchCase c;
  c.name = "made up";
  c.family = "offset";
  c.hard = true;
  run.cases.push_back(c);
  for (size_t m = 0; m < kModeCount; ++m) {
    BenchRow row;
    row.bench_case = &run.cases.front();
    row.mode = kAllModes[m];
    row.backend = Backend::kCompute;
    row.points = row.points_visible = 100;
    row.predicted_bound_px = bounds[m];
    row.float_floor_px = 1e-5;
    row.gpu_ms_median = row.gpu_ms_p95 = row.gpu_ms_min = 1.0;
    if (modeInfo(row.mode).batch_points) {  // a plan that culls nothing and loads every tier
      row.plan_bytes_per_point = modeInfo(row.mode).position_bytes;
      row.culled_share = 0.0;
      if (modeInfo(row.mode).tiers) row.tier_share = std::array<double, kAdaptiveTiers>{0.0, 0.0, 1.0};
    }
    if (std::isnan(errors[m])) {
      row.points_lost = 100;
    } else {
      row.error_max_px = row.error_p99_px = row.error_rms_px = errors[m];
    }
    run.rows.push_back(row);
  }
  return run;
}

const double kInf = std::numeric_limits<double>::infinity();
const double kLost = std::nan("");

std::vector<std::string> failedModes(const BenchRun& run) {
  std::vector<std::string> out;
  for (const CheckFailure& f : checkRun(run)) out.push_back(f.mode);
  return out;
}

// A made-up compute frame of `width` × `height` pixels, every mode measured with error 1, and a
// copy bandwidth of 100 GB/s read+write: what the bandwidth-bound tests count by hand.
struct MadeUpFrame {
  BenchRun run;
  CopyBandwidth copy;
};
MadeUpFrame madeUpFrame(uint32_t width, uint32_t height) {
  MadeUpFrame f{madeUpRun({1, 1, 1, 1, 1, 1, 1}, {kInf, kInf, 1, 1, 1, 1, 1}), CopyBandwidth{}};
  f.run.cases.front().width = width;
  f.run.cases.front().height = height;
  f.copy.read_write_gb_per_s = 100.0;
  return f;
}

TEST(BenchReport, checksPassARunThatBehavesAsDesignSays) {
  // fp32 far off, every double mode near the float floor, native best.
  BenchRun run = madeUpRun({30, 30, 2e-5, 3e-5, 1e-5, 2e-5, 2e-5}, {kInf, kInf, 1e-4, 1e-3, 2e-5, 5e-5, 5e-5});
  EXPECT_TRUE(checkRun(run).empty());
}

TEST(BenchReport, checksCatchAnErrorAboveItsBound) {
  BenchRun run = madeUpRun({1e-4, 1e-4, 2e-4, 3e-5, 1e-5, 2e-5, 2e-5}, {1e-3, 1e-3, 1e-4, 1e-3, 2e-5, 5e-5, 5e-5});
  EXPECT_EQ(failedModes(run), std::vector<std::string>{"rte"});
}

TEST(BenchReport, checksCatchEveryPointLostUnderASmallBound) {
  BenchRun run = madeUpRun({1e-4, 1e-4, 2e-5, kLost, 1e-5, 2e-5, 2e-5}, {1e-3, 1e-3, 1e-4, 0.01, 2e-5, 5e-5, 5e-5});
  const std::vector<std::string> failed = failedModes(run);
  EXPECT_EQ(std::set<std::string>(failed.begin(), failed.end()), std::set<std::string>{"df64"});
}

TEST(BenchReport, checksCatchSplitDifferingFromFp32) {
  BenchRun run = madeUpRun({1e-4, 2e-4, 2e-5, 3e-5, 1e-5, 2e-5, 2e-5}, {1e-3, 1e-3, 1e-4, 1e-3, 2e-5, 5e-5, 5e-5});
  EXPECT_EQ(failedModes(run), std::vector<std::string>{"split"});
}

TEST(BenchReport, checksCatchNativeBeatenByMoreThanOneFloatFloor) {
  BenchRun run = madeUpRun({1e-4, 1e-4, 2e-5, 3e-5, 5e-5, 2e-5, 5e-5}, {1e-3, 1e-3, 1e-4, 1e-3, 1e-4, 5e-5, 5e-5});
  EXPECT_EQ(failedModes(run), (std::vector<std::string>{"native", "native", "native"}));
  // Within one floor (1e-5) of the best is no failure.
  BenchRun close = madeUpRun({1e-4, 1e-4, 2e-5, 3e-5, 2.5e-5, 2e-5, 2e-5}, {1e-3, 1e-3, 1e-4, 1e-3, 1e-4, 5e-5, 5e-5});
  EXPECT_TRUE(checkRun(close).empty());
}

TEST(BenchReport, checksCatchADoubleModeNoBetterThanFp32WhereFp32IsOff) {
  BenchRun run = madeUpRun({3, 3, 2e-5, 4, 1e-5, 2e-5, 2e-5}, {kInf, kInf, 1e-4, kInf, 2e-5, 5e-5, 5e-5});
  EXPECT_EQ(failedModes(run), std::vector<std::string>{"df64"});
}

TEST(BenchReport, resultsJsonWritesNullForWhatWasNotMeasured) {
  BenchRun run = madeUpRun({kLost, kLost, 2e-5, 3e-5, 1e-5, 2e-5, 2e-5}, {kInf, kInf, 1e-4, 1e-3, 2e-5, 5e-5, 5e-5});
  run.rows[2].gpu_ms_median.reset();
  const std::string json = resultsJson(run, testContext(), checkRun(run));
  EXPECT_NE(json.find("\"mode\": \"fp32\""), std::string::npos);
  EXPECT_NE(json.find("\"predicted_bound_px\": null"), std::string::npos) << "an unbounded mode has no number";
  EXPECT_NE(json.find("\"error_px\": null"), std::string::npos) << "every point lost: no error";
  EXPECT_NE(json.find("\"gpu_ms\": null"), std::string::npos) << "no timestamps: no GPU time";
  EXPECT_EQ(json.find("inf"), std::string::npos);
  EXPECT_EQ(json.find("nan"), std::string::npos);
}

// A 1000×500 frame of 100 points on the compute backend at 100 GB/s read+write: every byte is
// counted by hand from the passes in viewer/render_compute.cpp.
TEST(BenchReport, bandwidthBoundCountsEveryPassOfAComputeFrame) {
  auto [run, copy] = madeUpFrame(1000, 500);
  for (BenchRow& row : run.rows) {
    row.gpu_ms_median = 0.5;
    setBandwidthBound(row, &copy);
    const uint64_t positions = 100ull * modeInfo(row.mode).position_bytes;
    const uint64_t per_pixel = 500000ull * (8 + 8 + 4);  // clear and read the keys, write the picture
    const uint64_t colors = 100ull * 4;                    // 100 points cover at most 100 pixels
    EXPECT_EQ(row.splat_bytes_per_point, modeInfo(row.mode).position_bytes) << modeName(row.mode);
    EXPECT_EQ(row.loaded_bytes_per_point, double(modeInfo(row.mode).position_bytes)) << modeName(row.mode);
    ASSERT_TRUE(row.bytes_per_frame && row.bandwidth_bound_ms && row.bandwidth_fraction) << modeName(row.mode);
    EXPECT_EQ(*row.bytes_per_frame, positions + per_pixel + colors) << modeName(row.mode);
    const double bound_ms = static_cast<double>(positions + per_pixel + colors) / 100e9 * 1e3;
    EXPECT_NEAR(*row.bandwidth_bound_ms, bound_ms, bound_ms * 1e-12) << modeName(row.mode);
    EXPECT_NEAR(*row.bandwidth_fraction, bound_ms / 0.5, bound_ms * 1e-12) << modeName(row.mode);
  }
  // Modes differ only in the position bytes, read from the mode's row.
  EXPECT_EQ(*run.rows[modeIndex(PrecisionMode::kNative)].bytes_per_frame - *run.rows[modeIndex(PrecisionMode::kFp32)].bytes_per_frame,
            100ull * (positionBytes(PrecisionMode::kNative) - positionBytes(PrecisionMode::kFp32)));
}

TEST(BenchReport, bandwidthBoundCountsEveryPixelOnceWhenPointsOutnumberThem) {
  BenchRun run = madeUpRun({1, 1, 1, 1, 1, 1, 1}, {kInf, kInf, 1, 1, 1, 1, 1});
  run.cases.front().width = 10;
  run.cases.front().height = 10;
  BenchRow& row = run.rows.front();
  row.points = 1000;
  setBandwidthBound(row, nullptr);
  ASSERT_TRUE(row.bytes_per_frame);
  EXPECT_EQ(*row.bytes_per_frame, 1000ull * positionBytes(row.mode) + 100ull * (8 + 8 + 4 + 4));
  EXPECT_FALSE(row.bandwidth_bound_ms) << "no copy bandwidth: no bound";
  EXPECT_FALSE(row.bandwidth_fraction);
}

TEST(BenchReport, bandwidthBoundLeavesRasterSkippedAndUntimedRowsWithoutAFraction) {
  BenchRun run = madeUpRun({1, 1, 1, 1, 1, 1, 1}, {kInf, kInf, 1, 1, 1, 1, 1});
  CopyBandwidth copy;
  copy.read_write_gb_per_s = 100.0;
  BenchRow& raster = run.rows[0];
  raster.backend = Backend::kRaster;
  setBandwidthBound(raster, &copy);
  EXPECT_EQ(raster.splat_bytes_per_point, positionBytes(raster.mode));
  EXPECT_FALSE(raster.bytes_per_frame || raster.bandwidth_bound_ms || raster.bandwidth_fraction);
  BenchRow& skipped = run.rows[1];
  skipped.skipped = "not on this device";
  setBandwidthBound(skipped, &copy);
  EXPECT_TRUE(skipped.bandwidth_bound_ms) << "the bound is the model's, measured or not";
  EXPECT_FALSE(skipped.bandwidth_fraction);
  BenchRow& untimed = run.rows[2];
  untimed.gpu_ms_median.reset();
  setBandwidthBound(untimed, &copy);
  EXPECT_TRUE(untimed.bandwidth_bound_ms);
  EXPECT_FALSE(untimed.bandwidth_fraction) << "no GPU time: no fraction";
}

// The per-batch modes read what their view's plan loads: 1000 points on the compute backend,
// batch with a quarter of its batches culled (6 B a point of the set), adaptive at 4.5 B a point
// (tiers and culling mixed), counted in the frame's bytes and its bound; without a plan (the draw
// did not report one) nothing is counted for them, where every other mode keeps its layout's.
TEST(BenchReport, bandwidthBoundCountsWhatThePerBatchPlanLoaded) {
  auto [run, copy] = madeUpFrame(100, 100);
  BenchRow& batch = run.rows[modeIndex(PrecisionMode::kBatch)];
  BenchRow& adaptive = run.rows[modeIndex(PrecisionMode::kAdaptive)];
  batch.points = adaptive.points = 1000;
  batch.plan_bytes_per_point = 6.0;
  adaptive.plan_bytes_per_point = 4.5;
  const uint64_t frame = 10000ull * (8 + 8 + 4) + 1000ull * 4;  // keys, picture, 1000 colours
  setBandwidthBound(batch, &copy);
  setBandwidthBound(adaptive, &copy);
  EXPECT_EQ(batch.splat_bytes_per_point, 8u) << "the layout's bytes stay";
  EXPECT_EQ(batch.loaded_bytes_per_point, 6.0);
  ASSERT_TRUE(batch.bytes_per_frame && adaptive.bytes_per_frame && adaptive.bandwidth_bound_ms);
  EXPECT_EQ(*batch.bytes_per_frame, 6000 + frame);
  EXPECT_EQ(adaptive.splat_bytes_per_point, positionBytes(PrecisionMode::kAdaptive));
  EXPECT_EQ(adaptive.loaded_bytes_per_point, 4.5);
  EXPECT_EQ(*adaptive.bytes_per_frame, 4500 + frame);
  EXPECT_NEAR(*adaptive.bandwidth_bound_ms, double(4500 + frame) / 100e9 * 1e3, 1e-15);
  // The raster path: adaptive pulls its tier words, so it follows the plan; batch's vertex input
  // fetches every point's 8 B.
  batch.backend = adaptive.backend = Backend::kRaster;
  setBandwidthBound(batch, &copy);
  setBandwidthBound(adaptive, &copy);
  EXPECT_EQ(batch.loaded_bytes_per_point, 8.0);
  EXPECT_EQ(adaptive.loaded_bytes_per_point, 4.5);
  EXPECT_FALSE(batch.bytes_per_frame || adaptive.bytes_per_frame) << "raster: no frame bytes";
  // No plan reported: no loaded bytes, no frame bytes, no bound; fp32 is not affected.
  adaptive.backend = Backend::kCompute;
  adaptive.plan_bytes_per_point.reset();
  setBandwidthBound(adaptive, &copy);
  EXPECT_FALSE(adaptive.loaded_bytes_per_point || adaptive.bytes_per_frame || adaptive.bandwidth_bound_ms);
  BenchRow& fp32 = run.rows[modeIndex(PrecisionMode::kFp32)];
  setBandwidthBound(fp32, &copy);
  EXPECT_EQ(fp32.loaded_bytes_per_point, 12.0);
}

// results.json and report.md show what a per-batch row loaded: its bytes per point, the share of
// batches culled and adaptive's share at each tier count; other modes' plan fields are null.
TEST(BenchReport, reportShowsThePlansLoadedBytesAndAdaptivesTiers) {
  BenchRun run = madeUpRun({1, 1, 1, 1, 1, 1, 1}, {kInf, kInf, 1, 1, 1, 1, 1});
  run.cases.front().hard = false;
  run.cases.front().width = run.cases.front().height = 100;
  BenchRow& batch = run.rows[modeIndex(PrecisionMode::kBatch)];
  BenchRow& adaptive = run.rows[modeIndex(PrecisionMode::kAdaptive)];
  batch.plan_bytes_per_point = 6.0;
  batch.culled_share = 0.25;
  adaptive.plan_bytes_per_point = 4.5;
  adaptive.culled_share = 0.5;
  adaptive.tier_share = std::array<double, kAdaptiveTiers>{0.25, 0.125, 0.125};
  adaptive.warmup_frames = 7;
  adaptive.warmup_ms = 301.5;
  for (BenchRow& row : run.rows) setBandwidthBound(row, nullptr);
  const std::string json = resultsJson(run, testContext(), {});
  EXPECT_NE(json.find("\"loaded_bytes_per_point\": 6, \"culled_share\": 0.25, \"tier_share\": null"), std::string::npos)
      << json;
  EXPECT_NE(json.find("\"loaded_bytes_per_point\": 4.5, \"culled_share\": 0.5, \"tier_share\": [0.25, 0.125, 0.125]"),
            std::string::npos)
      << json;
  EXPECT_NE(json.find("\"warmup\": {\"frames\": 7, \"ms\": 301.5}"), std::string::npos) << json;
  const std::string report = reportMarkdown(run, testContext(), {});
  EXPECT_NE(report.find("; 6 B/pt loaded)"), std::string::npos) << report;
  EXPECT_NE(report.find("; 4.5 B/pt loaded, tiers 25/12.5/12.5%)"), std::string::npos) << report;
  EXPECT_NE(report.find(" | 4.5 | 50% culled, tiers 25/12.5/12.5% | "), std::string::npos) << report;
  EXPECT_NE(report.find(" | 6 | 25% culled | "), std::string::npos) << report;
  EXPECT_NE(report.find("batch (≤ 8 B/pt splat, 12 total)"), std::string::npos) << report;
  EXPECT_NE(report.find(" | 12 | – | "), std::string::npos) << "fp32: its layout's bytes, no plan";
  EXPECT_NE(report.find("rte, df64, native, batch and adaptive all do better"), std::string::npos) << report;
}

TEST(BenchReport, resultsJsonCarriesTheCopyBandwidthAndEachRowsBound) {
  BenchRun run = madeUpRun({1, 1, 1, 1, 1, 1, 1}, {kInf, kInf, 1, 1, 1, 1, 1});
  run.cases.front().width = run.cases.front().height = 100;
  CopyBandwidth copy;
  copy.bytes = 64ull << 20;
  copy.copies = 5;
  copy.copy_ms_median = 2.0;
  copy.copy_gb_per_s = 33.554432;
  copy.read_write_gb_per_s = 67.108864;
  run.copy_bandwidth = copy;
  for (BenchRow& row : run.rows) setBandwidthBound(row, &copy);
  const std::string json = resultsJson(run, testContext(), {});
  EXPECT_NE(json.find("\"copy_bandwidth\": {\"read_write_gb_per_s\": 67.108864, \"copy_gb_per_s\": 33.554432, "
                      "\"copy_bytes\": 67108864, \"copies\": 5"),
            std::string::npos)
      << json;
  EXPECT_NE(json.find("\"bound_uses\": \"read_write_gb_per_s\""), std::string::npos);
  const BenchRow& fp32 = run.rows[modeIndex(PrecisionMode::kFp32)];
  EXPECT_NE(json.find("\"splat_bytes_per_point\": " + std::to_string(positionBytes(PrecisionMode::kFp32)) +
                      ", \"loaded_bytes_per_point\": " + std::to_string(positionBytes(PrecisionMode::kFp32)) +
                      ", \"culled_share\": null, \"tier_share\": null, \"bytes_per_frame\": " +
                      std::to_string(*fp32.bytes_per_frame)),
            std::string::npos)
      << json;
  EXPECT_EQ(json.find("\"bandwidth_fraction\": null"), std::string::npos);
  const std::string report = reportMarkdown(run, testContext(), {});
  EXPECT_NE(report.find("Copy bandwidth: **67.1 GB/s read+write, 33.6 GB/s copied"), std::string::npos) << report;
}

TEST(BenchReport, resultsJsonWritesNullBandwidthWhenNotMeasured) {
  BenchRun run = madeUpRun({1, 1, 1, 1, 1, 1, 1}, {kInf, kInf, 1, 1, 1, 1, 1});
  for (BenchRow& row : run.rows) setBandwidthBound(row, nullptr);
  run.rows[0].backend = Backend::kRaster;
  setBandwidthBound(run.rows[0], nullptr);
  const std::string json = resultsJson(run, testContext(), {});
  EXPECT_NE(json.find("\"copy_bandwidth\": null"), std::string::npos);
  EXPECT_NE(json.find("\"bytes_per_frame\": null"), std::string::npos) << "raster: no frame bytes";
  EXPECT_NE(json.find("\"bandwidth_bound_ms\": null, \"bandwidth_fraction\": null"), std::string::npos);
  EXPECT_EQ(json.find("\"bandwidth_fraction\": 0"), std::string::npos);
  const std::string report = reportMarkdown(run, testContext(), {});
  EXPECT_NE(report.find("Copy bandwidth: not measured"), std::string::npos);
}

// The bench hands its --warmup to every timed `dpoint render` as text: each request reads back
// the same, durations in ms without an exponent; the default warms up by time.
TEST(BenchRun, warmupPassesToRenderAsTextThatReadsBackTheSame) {
  EXPECT_EQ(warmupText(BenchOptions{}.warmup), "300ms");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"auto", "auto"}, {"0", "0"},           {"2", "2"},         {"300ms", "300ms"},     {"0.5s", "500ms"},
      {"1.5ms", "1.5ms"}, {"0.001ms", "0.001ms"}, {"60s", "60000ms"}, {"0.1s", "100ms"}, {"0.0123s", "12.3ms"}};
  for (const auto& [given, text] : cases) {
    const Result<WarmupRequest> parsed = parseWarmup("--warmup", given);
    ASSERT_TRUE(parsed) << given << ": " << parsed.error().message;
    EXPECT_EQ(warmupText(*parsed), text) << given;
    const Result<WarmupRequest> again = parseWarmup("--warmup", warmupText(*parsed));
    ASSERT_TRUE(again) << text;
    EXPECT_TRUE(again->kind == parsed->kind && again->frames == parsed->frames && again->ms == parsed->ms) << given;
  }
}

// Frame times of one row: median, fastest frame, p95.
struct Frames {
  double median, min, p95;
};

// Speed datasets (not hard cases), one compute row per mode: fp32 and native timed as given, the
// other modes as fp32.
BenchRun speedRun(const std::vector<std::pair<Frames, Frames>>& fp32_native) {
  BenchRun run;
  run.cases.reserve(fp32_native.size() + 1);  // rows point into cases: room for one more, added by a test
  for (size_t i = 0; i < fp32_native.size(); ++i) {
    BenchCase c;
    c.name = "set " + std::to_string(i);
    c.family = "2D random";
    run.cases.push_back(c);
  }
  for (size_t i = 0; i < fp32_native.size(); ++i) {
    for (PrecisionMode mode : kAllModes) {
      BenchRow row;
      row.bench_case = &run.cases[i];
      row.mode = mode;
      row.backend = Backend::kCompute;
      row.points = 10000;
      const Frames f = mode == PrecisionMode::kNative ? fp32_native[i].second : fp32_native[i].first;
      row.gpu_ms_median = f.median, row.gpu_ms_min = f.min, row.gpu_ms_p95 = f.p95;
      run.rows.push_back(row);
    }
  }
  return run;
}

std::string markdownOf(const BenchRun& run) {
  return reportMarkdown(run, testContext(), {});
}

TEST(BenchReport, ratioWithinTheFramesSpreadIsNotCalledFaster) {
  // lavapipe's 10K-point frames (bench/results/2026-11-23/lavapipe): native's median 0.75× of fp32's,
  // but each spans the other's median.
  const BenchRun run = speedRun({{{2.16, 0.98, 3.18}, {1.62, 0.84, 2.72}}, {{2.0, 1.0, 3.0}, {1.8, 0.9, 2.9}}});
  const std::string report = markdownOf(run);
  EXPECT_NE(report.find("native ≈ fp32 (within noise: median 0.8"), std::string::npos) << report;
  EXPECT_EQ(report.find("native 0."), std::string::npos) << report;
  EXPECT_NE(report.find("*≈ (within noise)*"), std::string::npos) << "the rule is stated";
}

TEST(BenchReport, ratioBeyondTheFramesSpreadKeepsItsNumber) {
  // The H100's Sierpinski 16.7M, compute: native 1.13× of fp32, spans 1-2% wide and apart.
  const BenchRun run = speedRun({{{0.1625, 0.1589, 0.1643}, {0.1834, 0.1814, 0.185}},
                                 {{0.1625, 0.1589, 0.1643}, {0.1834, 0.1814, 0.185}}});
  const std::string report = markdownOf(run);
  EXPECT_NE(report.find("native 1.13× (0 of 2 faster, 2 slower beyond noise)"), std::string::npos) << report;
  EXPECT_EQ(report.find("native ≈"), std::string::npos);
}

TEST(BenchReport, ratioIsCalledOnlyWhenMostDatasetsAgreeBeyondNoise) {
  // One of three datasets clearly faster, two overlapping: the median is not a speed-up.
  const BenchRun run = speedRun({{{1.0, 0.99, 1.01}, {0.5, 0.49, 0.51}},
                                 {{1.0, 0.8, 1.2}, {0.9, 0.7, 1.1}},
                                 {{1.0, 0.8, 1.2}, {0.95, 0.75, 1.15}}});
  EXPECT_NE(markdownOf(run).find("native ≈ fp32 (within noise: median 0.9×, 1 of 3 faster, 0 slower beyond noise)"),
            std::string::npos)
      << markdownOf(run);
}

TEST(BenchReport, hostFrameTimesHaveNoSpreadAndAreNeverCalledFaster) {
  BenchRun run = speedRun({{{1.0, 1.0, 1.0}, {0.5, 0.5, 0.5}}});
  for (BenchRow& row : run.rows) {
    row.frame_ms_median = *row.gpu_ms_median;
    row.gpu_ms_median.reset(), row.gpu_ms_min.reset(), row.gpu_ms_p95.reset();
  }
  EXPECT_NE(markdownOf(run).find("native ≈ fp32"), std::string::npos) << markdownOf(run);
}

TEST(BenchReport, reportCitesNothingOutsideTheRepository) {
  // Speed cases, a hard case and a failed check: every section of report.md is written.
  BenchRun run = speedRun({{{1.0, 0.9, 1.1}, {1.2, 1.15, 1.3}}});
  BenchRun hard = madeUpRun({1e-4, 2e-4, 2e-5, 3e-5, 1e-5, 2e-5, 2e-5}, {1e-3, 1e-3, 1e-4, 1e-3, 2e-5, 5e-5, 5e-5});
  ASSERT_GT(run.cases.capacity(), run.cases.size()) << "rows point into cases";
  run.cases.push_back(hard.cases.front());
  run.cases.back().sweep = Sweep::kOffset;
  run.cases.back().sweep_x = 1e6;
  for (BenchRow row : hard.rows) {
    row.bench_case = &run.cases.back();
    run.rows.push_back(row);
  }
  const std::vector<CheckFailure> failures = checkRun(run);
  ASSERT_FALSE(failures.empty()) << "split differs from fp32";
  test::TempDir dir;
  Result<std::vector<std::string>> written =
      writeReport(run, testContext(), failures, dir.path());
  ASSERT_TRUE(written) << written.error().message;
  size_t text_files = 0;
  for (const std::string& path : *written) {
    if (path.ends_with(".png")) continue;
    ++text_files;
    const std::string text = test::readFile(path);
    for (const char* outside : {"DESIGN", "../", "shared/", "/work/", "/tmp/"})
      EXPECT_EQ(text.find(outside), std::string::npos) << path << " names " << outside;
  }
  EXPECT_GE(text_files, 3u) << "results.json, report.md, speed_vs_error.svg";
  const std::string report = test::readFile(dir.file("report.md"));
  EXPECT_NE(report.find("## Hard cases"), std::string::npos);
  EXPECT_NE(report.find("docs/precision.md"), std::string::npos) << "the checks cite the repository's own page";
}

// A run into the folder of an earlier one leaves one run's report: the earlier run's breakdown.svg,
// which this run does not draw, goes (a paper run kept a ci run's chart beside its own report).
TEST(BenchReport, aRunIntoAnEarlierRunsFolderLeavesOneRunsReport) {
  BenchRun swept = madeUpRun({1e-4, 2e-4, 2e-5, 3e-5, 1e-5, 2e-5, 2e-5}, {1e-3, 1e-3, 1e-4, 1e-3, 2e-5, 5e-5, 5e-5});
  swept.cases.front().sweep = Sweep::kOffset;
  swept.cases.front().sweep_x = 1e6;
  test::TempDir dir;
  ASSERT_TRUE(writeReport(swept, testContext(), checkRun(swept), dir.path()));
  ASSERT_TRUE(test::fileExists(dir.file("breakdown.svg"))) << "the swept run draws it";
  const BenchRun speed = speedRun({{{1.0, 0.9, 1.1}, {1.2, 1.15, 1.3}}});
  Result<std::vector<std::string>> written = writeReport(speed, testContext(), checkRun(speed), dir.path());
  ASSERT_TRUE(written) << written.error().message;
  EXPECT_FALSE(test::fileExists(dir.file("breakdown.svg")));
  for (const std::string& path : *written) EXPECT_NE(path, dir.file("breakdown.svg"));
  EXPECT_TRUE(test::fileExists(dir.file("report.md")));
}

TEST(BenchSuites, paperSuiteHoldsTheStudysDatasetsWithItsFigures) {
  const std::vector<BenchCase> paper = suiteCases(BenchSuite::kPaper);
  std::vector<std::string> labels;
  for (const BenchCase& c : paper) labels.push_back(c.size_label);
  EXPECT_EQ(labels, (std::vector<std::string>{"10K", "100K", "1M", "10M", "200K", "2M", "200K", "1.85M", "5M", "11.9M",
                                              "1M", "16.7M", "1.4M"}));
  for (const BenchCase& c : paper) {
    EXPECT_EQ(c.width, 1920u);
    EXPECT_EQ(c.height, 1080u);
    EXPECT_FALSE(c.hard);
  }
}

// The study's Tables 2 and 3 as printed (Sözen, "Double-Precision Floating-Point Data Visualizations
// Using Vulkan API"), typed again from the paper so a slip in bench/suites.cpp shows: case, then
// emulated ms and fps (Table 2), native ms and fps (Table 3).
const std::vector<std::array<std::string, 5>> kStudyRows = {
    {"Mandelbulb 200K", "9.71", "729", "11.87", "842"},     {"Menger 200K", "12.9", "703", "14.88", "804"},
    {"Sierpinski 1M", "32.19", "745", "35.26", "789"},      {"Julia 1.4M", "35.26", "717", "39.26", "802"},
    {"Menger 1.85M", "36.69", "612", "31.12.16", "763"},    {"Mandelbulb 2M", "53.19", "687", "42.68", "854"},
    {"Menger 5M", "239.73", "698", "189.25", "802"},        {"Menger 11.9M", "499.12", "468", "471.29", "593"},
    {"Sierpinski 16.7M", "722.89", "115", "695.76", "330"},
};

TEST(BenchSuites, paperSuiteCarriesEveryRowOfTheStudysTablesTwoAndThree) {
  const std::vector<BenchCase> paper = suiteCases(BenchSuite::kPaper);
  for (const auto& [name, emulated_ms, emulated_fps, native_ms, native_fps] : kStudyRows) {
    auto it = std::find_if(paper.begin(), paper.end(), [&](const BenchCase& c) { return c.name == name; });
    ASSERT_NE(it, paper.end()) << name;
    ASSERT_TRUE(it->study) << name;
    EXPECT_EQ(it->study->emulated.rendering_time_ms, emulated_ms) << name;
    EXPECT_EQ(it->study->emulated.fps, emulated_fps) << name;
    EXPECT_EQ(it->study->native.rendering_time_ms, native_ms) << name;
    EXPECT_EQ(it->study->native.fps, native_fps) << name;
  }
  size_t with_figures = 0;
  for (const BenchCase& c : paper) with_figures += c.study.has_value();
  EXPECT_EQ(with_figures, kStudyRows.size() + 1) << "and the 10M 2D set's caption";
}

TEST(BenchReport, everyPaperRowShowsBothColumnsOfBothStudyTables) {
  BenchRun run;
  run.cases = suiteCases(BenchSuite::kPaper);
  for (const BenchCase& c : run.cases) {
    for (PrecisionMode mode : kAllModes) {
      BenchRow row;
      row.bench_case = &c;
      row.mode = mode;
      row.backend = Backend::kCompute;
      row.points = 1000000;
      row.gpu_ms_median = row.gpu_ms_min = row.gpu_ms_p95 = 1.0;
      run.rows.push_back(row);
    }
  }
  const std::string report = markdownOf(run);
  for (const auto& [name, emulated_ms, emulated_fps, native_ms, native_fps] : kStudyRows) {
    const size_t at = report.find("| " + name + " |");
    ASSERT_NE(at, std::string::npos) << name;
    const std::string line = report.substr(at, report.find('\n', at) - at);
    EXPECT_NE(line.find("| " + emulated_ms + " ms, " + emulated_fps + " fps | " + native_ms + " ms, " + native_fps +
                        " fps |"),
              std::string::npos)
        << line;
  }
  EXPECT_NE(report.find("| 2D random 10M |"), std::string::npos);
  EXPECT_NE(report.find("| –, 218 fps (figure caption) |"), std::string::npos) << report;
  const std::string json = resultsJson(run, testContext(), {});
  EXPECT_NE(json.find("\"native\": {\"rendering_time_ms\": \"31.12.16\", \"fps\": \"763\"}"), std::string::npos);
}

// The hard suite sweeps every decade; the ci suite every other one (its sweeps' child renders were
// half of the test suite's time), from the first decade to the last either way.
TEST(BenchSuites, hardSuiteSweepsEveryDecadeAndCiEveryOther) {
  for (BenchSuite suite : {BenchSuite::kHard, BenchSuite::kCi}) {
    std::set<double> zoom, offset;
    for (const BenchCase& c : suiteCases(suite)) {
      if (c.sweep == Sweep::kDeepZoom) zoom.insert(c.sweep_x);
      if (c.sweep == Sweep::kOffset) offset.insert(c.sweep_x);
    }
    const int step = suite == BenchSuite::kCi ? 2 : 1;
    std::set<double> zoom_expected, offset_expected;
    for (int e = 1; e <= 15; e += step) zoom_expected.insert(std::pow(10.0, -e));
    for (int e = 0; e <= 8; e += step) offset_expected.insert(std::pow(10.0, e));
    EXPECT_EQ(zoom.size(), suite == BenchSuite::kCi ? 8u : 15u);
    EXPECT_EQ(offset.size(), suite == BenchSuite::kCi ? 5u : 9u);
    for (double x : zoom) EXPECT_TRUE(std::any_of(zoom_expected.begin(), zoom_expected.end(), [&](double e) {
      return std::abs(x / e - 1) < 1e-15;
    })) << x;
    for (double x : offset) EXPECT_TRUE(offset_expected.count(x)) << x;
  }
}

TEST(BenchSuites, everyCaseHasItsOwnNameAndCacheFile) {
  for (BenchSuite suite : {BenchSuite::kCi, BenchSuite::kPaper, BenchSuite::kHard}) {
    std::set<std::string> names;
    std::map<std::string, std::vector<std::string>> files;  // a file may be shared only by identical arguments
    size_t montages = 0;
    for (const BenchCase& c : suiteCases(suite)) {
      EXPECT_TRUE(names.insert(c.name).second) << c.name;
      auto [it, fresh] = files.emplace(cacheFileName(c), c.generate);
      EXPECT_TRUE(fresh || it->second == c.generate) << cacheFileName(c);
      EXPECT_EQ(cacheFileName(c).find('/'), std::string::npos);
      montages += c.montage;
    }
    EXPECT_EQ(montages, suite == BenchSuite::kPaper ? 0u : 1u);
  }
}

TEST(BenchSuites, nearViewLooksAtTheBoxCentreFromTheGivenDistance) {
  BenchCase c;
  c.view.kind = BenchView::Kind::kNear;
  c.view.distance = 2.0;
  Bounds b;
  b.min = {6378137.0, -1.0, 0.0};
  b.max = {6378139.0, 1.0, 2.0};
  CameraSpec spec = cameraSpecFor(c, b);
  ASSERT_TRUE(spec.eye && spec.target && spec.up);
  EXPECT_EQ(*spec.target, glm::dvec3(6378138.0, 0.0, 1.0));
  EXPECT_EQ(*spec.eye, glm::dvec3(6378138.2, 0.4, 3.0));
}

// --baseline (issue #38): a run read back from its own results.json is its baseline; a row more
// than 5% slower than there is marked, one 5% slower or less is not, and both reports say so.
TEST(BenchBaseline, aRowMoreThanFivePercentSlowerIsMarked) {
  test::TempDir dir;
  BenchRun before = madeUpRun({1, 1, 1, 1, 1, 1, 1}, {kInf, kInf, 1, 1, 1, 1, 1});
  test::writeFile(dir.file("results.json"), resultsJson(before, testContext(), {}));
  Result<Baseline> baseline = readBaseline(dir.file("results.json"));
  ASSERT_TRUE(baseline) << baseline.error().message;
  EXPECT_EQ(baseline->rows.size(), kModeCount);

  BenchRun after = madeUpRun({1, 1, 1, 1, 1, 1, 1}, {kInf, kInf, 1, 1, 1, 1, 1});
  after.rows[0].gpu_ms_median = 1.06;  // fp32: 6% slower
  after.rows[1].gpu_ms_median = 1.05;  // split: 5%, within the tolerance
  after.rows[2].gpu_ms_median = 0.5;   // rte: faster
  const BaselineReport report = compareToBaseline(after, *baseline);
  ASSERT_EQ(report.rows.size(), kModeCount);
  EXPECT_EQ(report.slower(), 1u);
  EXPECT_TRUE(report.rows[0].slower);
  EXPECT_FALSE(report.rows[1].slower);
  EXPECT_TRUE(report.same_device);

  ReportContext context = testContext();
  context.baseline = report;
  EXPECT_TRUE(test::contains(reportMarkdown(after, context, {}), "1 more than 5% slower"));
  EXPECT_TRUE(test::contains(reportMarkdown(after, context, {}), "| made up | compute | fp32 | 1.0000 | 1.0600 | 1.060 | **slower** |"));
  const std::string json = resultsJson(after, context, {});
  EXPECT_TRUE(test::contains(json, "\"slower\": 1,"));
  EXPECT_TRUE(test::contains(json, "\"mode\": \"fp32\", \"baseline_ms\": 1, \"gpu_ms\": 1.06"));
}

TEST(BenchBaseline, aFileThatIsNoResultsJsonIsRefusedByName) {
  test::TempDir dir;
  test::writeFile(dir.file("other.json"), "{\"asset\": {}}");
  Result<Baseline> baseline = readBaseline(dir.file("other.json"));
  ASSERT_FALSE(baseline);
  EXPECT_TRUE(test::contains(baseline.error().message, "other.json: not a dpoint bench results.json: no \"rows\" array"));
  EXPECT_EQ(baseline.error().code, ExitCode::kBadInput);
  EXPECT_FALSE(readBaseline(dir.file("missing.json")));
}

}  // namespace
}  // namespace dpoint
