// Runs the bench's cases (bench/suites.h) on one Vulkan device: each case's dataset is made once
// into the cache folder by `dpoint generate` and read back, its exact reference projected once,
// then every mode on every backend is drawn twice: timed, by a fresh `dpoint render --json` process
// (GPU timestamps, median of `frames` after warm-up, no probe: what a user's run gets), and probed,
// in this process (clip positions of every point against the reference). One row per (case,
// backend, mode). Before the first case, the device's copy bandwidth is measured once
// (bench/bandwidth.h) for each row's bandwidth bound.
//
// Why a process per timed draw: on the H100 (driver 580.159), once one process had drawn and
// probed a 10M-point set, every later draw of 10M points in that process ran 4–6× slower (0.18 ms
// became 0.7–1.1 ms for the same compute draw), on a second VkDevice too; fresh processes and
// runs without probes were unaffected. Until that is understood (issue #11 keeps buffers across
// frames and will meet it), the bench times what `dpoint render` times.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "bench/bandwidth.h"
#include "bench/suites.h"
#include "vulkan/context.h"
#include "viewer/encode.h"
#include "viewer/render.h"
#include "viewer/render_job.h"

namespace dpoint {

struct BenchRow {
  const BenchCase* bench_case = nullptr;  // into BenchRun::cases
  uint64_t points = 0;
  PrecisionMode mode = PrecisionMode::kFp32;
  Backend backend = Backend::kRaster;
  std::string skipped;  // why the mode did not run (unusable on the device, encoding refused); else empty
  // Speed: GPU timestamps (empty when the queue has none), host frame times, upload and readback.
  std::optional<double> gpu_ms_median, gpu_ms_p95, gpu_ms_min;
  double frame_ms_median = 0.0, upload_ms = 0.0, readback_ms = 0.0;
  double e2e_ms = 0.0;        // upload + one frame (median) + readback, as `dpoint render --json`
  double points_per_s = 0.0;  // from the GPU median (else the host frame median)
  uint32_t warmup_frames = 0;  // untimed frames the timed draw ran first, and their wall time
  double warmup_ms = 0.0;
  uint32_t bytes_per_point = 0;
  // The per-batch modes' plan for the case's view (viewer/batch_plan.h), as the timed draw reported
  // it (`batch_plan` of its --json): position bytes it loads per point of the whole set (a culled
  // batch's points 0; adaptive: 4 B per tier loaded), the share of batches culled, and adaptive's
  // share of batches at 1, 2 and 3 tiers. Empty for the other modes and where the draw did not run.
  std::optional<double> plan_bytes_per_point, culled_share;
  std::optional<std::array<double, kAdaptiveTiers>> tier_share;
  // Bandwidth (bench/bandwidth.h, setBandwidthBound): position bytes per point of the mode's layout
  // (what the splat pass or the vertex fetch reads for a point it loads whole); those the frame
  // loaded per point of the set (the layout's, but for the per-batch modes' plan: FrameTraffic);
  // compute backend only, the bytes a frame must move, the time that takes at the run's read+write
  // copy bandwidth, and bound / GPU median (1: as fast as the memory allows). Empty where the
  // backend has no byte count, the plan, the bandwidth or the GPU time was not measured, or the row
  // did not run.
  uint32_t splat_bytes_per_point = 0;
  std::optional<double> loaded_bytes_per_point;
  std::optional<uint64_t> bytes_per_frame;
  std::optional<double> bandwidth_bound_ms, bandwidth_fraction;
  // Error: the bound predicted before drawing (+inf: unbounded) and what the probe measured.
  double predicted_bound_px = 0.0;
  double float_floor_px = 0.0;
  std::optional<double> error_max_px, error_p99_px, error_rms_px;  // empty when every visible point was lost
  double share_off_half_px = 0.0;
  uint64_t points_visible = 0, points_lost = 0;
  std::optional<uint64_t> pixels_differing;
};

// The montage's view drawn in one mode: the picture and each point's error (NaN: lost).
struct MontageMode {
  PrecisionMode mode = PrecisionMode::kFp32;
  Image picture;
  std::vector<double> error_px;
  std::string caption;
};
struct MontageCapture {
  const BenchCase* bench_case = nullptr;
  Backend backend = Backend::kRaster;
  std::vector<WindowPoint> reference;
  std::vector<MontageMode> modes;
};

struct BenchOptions {
  std::vector<BenchSuite> suites;
  std::vector<Backend> backends;
  std::vector<std::string> sizes;  // paper cases kept by size label (case-insensitive); empty: all
  uint32_t frames = 20;
  // Each timed draw's `dpoint render --warmup`: by time, as a GPU's clocks need (render_job.h).
  WarmupRequest warmup{WarmupRequest::Kind::kTime, 0, kAutoWarmupMs};
  bool measure_error = true;  // false: timed draws only; error columns stay empty
  std::string cache_dir;
  std::string device = "auto";  // passed to every `dpoint render`; the context given must be that device
  bool validate = false;        // --validate for every `dpoint render`
  // The copy bandwidth, measured once at the start; false: not measured (no bound, no fraction).
  bool measure_copy_bandwidth = true;
  CopyBandwidthOptions copy;
  // Runs `dpoint ARGS` (this executable) to its end; fails naming the command and its exit code.
  std::function<Status(const std::vector<std::string>& args)> run_dpoint;
  // One line per step for the user (progress); may be empty.
  std::function<void(const std::string&)> log;
};

struct BenchRun {
  std::vector<BenchCase> cases;  // every case run, in order (rows point into it: not resized after)
  std::vector<BenchRow> rows;
  std::optional<MontageCapture> montage;
  DeviceFacts device;
  std::optional<CopyBandwidth> copy_bandwidth;  // empty: not measured
  double seconds = 0.0;  // wall time of the whole run
};

// Fills the row's bandwidth fields (above) from its case, mode, backend, plan and GPU time, and
// `copy` (null: not measured). Needs row.bench_case.
void setBandwidthBound(BenchRow& row, const CopyBandwidth* copy);

// Fails on a dataset that cannot be made or read, or a copy bandwidth that cannot be measured; a
// mode the device cannot run or a draw that fails becomes a skipped row naming why.
Result<BenchRun> runBench(const VulkanContext& context, const BenchOptions& options);

}  // namespace dpoint
