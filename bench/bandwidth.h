// The bench's bandwidth bound (issue #11): how fast the device moves bytes between two of its own
// buffers (vkCmdCopyBuffer, GPU timestamps), and how many bytes a frame of the compute backend
// must move, so that each row can say what fraction of the memory-bound speed it reaches.
//
// Why a copy: it is the one transfer every driver runs at its best without our shaders in the way,
// so it stands for what the memory can do. A copy of B bytes reads B and writes B; the bound
// divides a frame's bytes (reads and writes alike) by the read + write rate, 2·B / time.
#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>

#include "vulkan/context.h"
#include "viewer/encode.h"
#include "viewer/render.h"

namespace dpoint {

struct CopyBandwidthOptions {
  uint64_t bytes = 0;    // of one copy; 0: defaultCopyBytes(context)
  uint32_t copies = 10;  // timed copies; the median is reported (≥ 1)
  uint32_t warmup = 1;   // untimed copies first
};

struct CopyBandwidth {
  uint64_t bytes = 0;   // copied by each vkCmdCopyBuffer
  uint32_t copies = 0;  // timed copies the median is taken over
  double copy_ms_median = 0.0;
  double copy_gb_per_s = 0.0;        // bytes / median time (1 GB = 1e9 B): the copy rate
  double read_write_gb_per_s = 0.0;  // 2 · bytes / median time
  // The same bytes copied by a compute shader (shaders/bench/copy.comp, 16-byte loads and stores); 0 when
  // the device could not run it.
  double shader_copy_ms_median = 0.0;
  double shader_read_write_gb_per_s = 0.0;
  bool gpu_timestamps = true;        // false: host wall time around each submission (the queue has none)
  // What the bandwidth bound divides by: the faster of the two read + write rates.
  bool shaderCopyFaster() const { return shader_read_write_gb_per_s > read_write_gb_per_s; }
  double boundRate() const { return shaderCopyFaster() ? shader_read_write_gb_per_s : read_write_gb_per_s; }
};

// 1 GiB on a GPU; 256 MiB on a CPU device (lavapipe copies with memcpy: that is past any cache, and
// more only costs time). Either way at most maxMemoryAllocationSize and a quarter of the largest
// device-local heap (two buffers, and room for whatever else the device holds).
uint64_t defaultCopyBytes(const VulkanContext& context);

// Copies one device-local buffer into another `warmup + copies` times, each in its own submission
// timed by timestamps around the copy (or by the host around the submission where the queue has no
// timestamps). The source is filled first, so that no copy reads pages that were never written (on
// a CPU device those all map one zero page and read from cache). Fails naming the size when it is
// above maxMemoryAllocationSize or the buffers cannot be made, or the Vulkan call that failed.
Result<CopyBandwidth> measureCopyBandwidth(const VulkanContext& context, const CopyBandwidthOptions& options);

// "2.9 TB/s read+write, 1.45 TB/s copied (1.00 GiB vkCmdCopyBuffer, median of 10, GPU timestamps)"
std::string copyBandwidthText(const CopyBandwidth& copy);
// 3 significant digits in GB/s below 1000, TB/s from there.
std::string rateText(double gb_per_s);

// Bytes that one frame must move between the device's memory and its cores.
struct FrameTraffic {
  uint32_t splat_bytes_per_point = 0;  // the mode's position bytes: what is read for a point loaded whole
  // Position bytes the frame reads per point of the set: splat_bytes_per_point, but for a
  // per-batch mode that follows its plan (below) the plan's; empty where that plan is not known.
  std::optional<double> loaded_bytes_per_point;
  std::optional<uint64_t> bytes_per_frame;  // compute backend only
};

// The compute backend (viewer/render_compute.cpp, shaders/render/points_splat.comp and
// points_resolve.comp), at point size 1:
//   points · loaded_bytes_per_point        the splat pass reads positions only
//   + pixels · (8 + 8 + 4)                 clear the 8 B key per pixel, read it in the resolve, write
//                                          the 4 B picture
//   + min(points, pixels) · 4              the resolve reads the winner's colour per covered pixel;
//                                          coverage is not measured, so every point is taken to win
//                                          a pixel of its own, at most every pixel (an upper bound)
// Positions: the per-batch modes (batch, adaptive) read what their per-camera plan loads
// (viewer/batch_plan.h), `plan_bytes_per_point` (BatchPlanStats::bytes_per_point: no byte of a culled
// batch, which the splat never dispatches; adaptive 4, 8 or 12 B a point by the tiers its batch
// loads); every other mode its whole layout, positionBytes(mode), for every point. The raster path
// follows the plan only where its vertex shader pulls positions (adaptive: a culled batch's points
// are sent behind the eye unread); batch's vertex input fetches every point's 8 B whatever the plan.
// A plan's own reads (one 4 B word per drawn batch, and its 4096 points share one batch matrix) are
// under 0.02 B a point and not counted.
// The 8 B atomicMax per visible point is not counted: it lands on the keys the clear and the
// resolve already count, in the last-level cache on a GPU (a 1920×1080 frame's keys are 16.6 MB).
// The raster backend gets splat bytes but no frame bytes: its colour and depth attachments go
// through compressed, cached render targets whose traffic is no byte count we can write down.
FrameTraffic frameTraffic(Backend backend, PrecisionMode mode, uint64_t points, uint32_t width, uint32_t height,
                          std::optional<double> plan_bytes_per_point = std::nullopt);

// Milliseconds that moving `bytes` takes at `read_write_gb_per_s` (> 0).
double bandwidthBoundMs(uint64_t bytes, double read_write_gb_per_s);

}  // namespace dpoint
