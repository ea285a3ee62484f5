// Offscreen point rendering (DESIGN §4, §6): uploads a point set in one precision mode, draws it
// with the raster backend (POINT_LIST into RGBA8 + D32, reversed Z) or the compute backend,
// times the GPU work with timestamps, reads the picture back, and with `probe` also reads every
// point's clip position.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec4.hpp>

#include "core/point_set.h"
#include "viewer/camera.h"
#include "vulkan/context.h"
#include "viewer/batch_plan.h"
#include "viewer/encode.h"
#include "viewer/precision.h"
#include "viewer/reference.h"

namespace dpoint {

enum class NativePath { kAuto, kAttribute, kPull };

// raster: graphics pipeline, POINT_LIST, D32 depth (the study's design). compute: one thread per
// point, 64-bit atomicMax into a per-pixel visibility buffer, then a resolve pass (DESIGN §4);
// same projection code, same picture, size-1 points only.
enum class Backend { kRaster, kCompute };

// What is done to the picture after the points are drawn. kEdl: eye-dome lighting
// (shaders/render/edl.comp), a screen-space pass over the depth of the visible points that darkens a
// pixel by how far its neighbours stand in front of it, so a surface of 1-px points reads as one.
enum class Shading { kNone, kEdl };
struct EdlOptions {
  float strength = 1.0f;  // > 0; the shade is exp(−strength · 300 · mean log2 depth step)
  float radius = 1.4f;    // neighbour distance in pixels, ≥ 1 (1.4: the 8 nearest pixels)
  // Depth smoothing and eye-dome lighting in one pass where the radii allow (ShadeRadii::fused;
  // the same picture: tests turn it off to compare with the separate passes).
  bool fuse = true;
};

struct RenderOptions {
  PrecisionMode mode = kFallbackMode;
  Backend backend = Backend::kRaster;
  float point_size = 1.0f;
  // Points larger than a pixel as discs whose depth falls away to the rim, the front of a
  // paraboloid as deep as the sphere of their radius (Potree's "paraboloid" points): of
  // overlapping discs the nearest centre wins, so a point behind a surface never shows a square's
  // edge through it. False: the rasterizer's squares at one depth. Both backends draw the same.
  bool round_points = false;
  uint32_t background_rgba8 = 0xff000000u;  // opaque black, R in the low byte
  // Warm-up: untimed frames before the timed ones, warmup_frames of them, then more until warmup_ms of
  // wall time (submit to fence) have passed since the first began (0: none by time). By time is
  // what a GPU needs after a long upload: its first frames run 2–4× slower in flat steps for up to
  // ~300 ms (clock ramp suspected; docs/performance.md), whatever the frame count.
  uint32_t warmup_frames = 1;
  double warmup_ms = 0.0;
  uint32_t frames = 1;  // timed frames after warm-up (≥ 1)
  bool probe = false;   // also store clip positions (DESIGN §5)
  NativePath native_path = NativePath::kAuto;  // auto: R64G64B64 vertex input where listed, else pull
  // Compute backend: skip the atomic when the pixel's key already wins (same picture; tests turn
  // it off to compare with the plain path).
  bool early_depth = true;
  // Compute backend: the subgroup merge (points_splat.comp; same picture). None: where it pays,
  // on GPUs; not on a CPU device, where lavapipe's 16.7M-point frame took 11% longer with it
  // (bench/results/2026-11-25/lavapipe/native-ab-2026-11-25.tsv). Tests force it on.
  std::optional<bool> subgroup_merge;
  // Compute backend, batch and adaptive modes: two consecutive points of a thread on one pixel test
  // and write one key (points_splat.comp's splatPair; same picture). None: on GPUs (H100, 1e9
  // points: adaptive 5.21 -> 4.45 ms, batch 5.42 -> 4.80; bench/results/2026-11-26/h100/), not on
  // a CPU device, where lavapipe's 16.7M-point frames took 4-8% longer with it. Tests force it on.
  std::optional<bool> pair_merge;
  // Compute backend: each chunk's workgroups run from whichever end of the chunk lies nearer the
  // eye, reversed where its points come nearer along their order (a marching-cubes mesh seen from
  // its last slabs), so that the early depth test skips more atomics. The same picture: the keys'
  // atomicMax leaves one result in any order. The 1.55M-point Mandelbulb's 3-px discs: lavapipe at
  // 1920x1080, fp32 105 -> 93 ms; the H200 at 1024x768, every mode 5-16% shorter (fp32 0.089 ->
  // 0.075 ms); a set whose order has no nearer end (Sierpinski) the same on both. A finer sort,
  // nearest group first, was slower on lavapipe than either end (docs/performance.md). Off
  // whatever it says with the raster backend or without early_depth, where the order saves nothing.
  bool near_end_first = true;
  // Points per draw; 0 takes the most the device allows (maxStorageBufferRange,
  // maxMemoryAllocationSize). Rounded down to whole batches. Tests set it small to cover chunking.
  uint64_t max_chunk_points = 0;
  // Adaptive mode: the error in window pixels its tier choice keeps within (--tolerance).
  double tolerance_px = kDefaultTolerancePx;
  // After the frame, outside its timestamps (gpu_ms times the points alone, in every shading).
  Shading shading = Shading::kNone;
  EdlOptions edl;
};

struct RenderResult {
  Image image;                     // the last frame
  std::vector<double> gpu_ms;      // per timed frame, from timestamps; empty if the queue has none
  std::vector<double> frame_ms;    // per timed frame, submit to fence on the host
  uint32_t warmup_frames = 0;      // untimed frames drawn first (RenderOptions' warm-up)
  double warmup_ms = 0.0;          // their wall time, from the first submit to the last fence
  double upload_ms = 0.0;          // encode + upload of every buffer
  double readback_ms = 0.0;        // copy of the picture to the host
  std::vector<glm::vec4> probe_clip;  // with `probe`: clip position of every point, in input order
  uint32_t chunks = 0;
  bool pulled_positions = false;   // native mode read positions from a storage buffer
  uint32_t reversed_chunks = 0;    // chunks whose splat ran from their last group (near_end_first)
  uint64_t gpu_bytes = 0;          // point data on the GPU (positions + colours)
  // Per-batch modes: what the frame's plan loads (batches culled, at each tier, bytes per point).
  std::optional<BatchPlanStats> batch_plan;
};

// Fails with kBadInput when the set is empty or a position does not fit the mode's encoding,
// kNoDevice when the device cannot run the mode (see modeUsable), kResourceLimit when memory
// runs out. The caller's context collects validation messages.
// Whether the shading passes' texel buffers (the picture and a margin) fit the device's
// maxTexelBufferElements; renderPoints refuses --shade edl where they do not.
bool shadingFits(const DeviceFacts& facts, uint32_t width, uint32_t height, const RenderOptions& options);

// prepared: the mode's encoding for this set, camera and options.tolerance_px, made while its bound
// was predicted (ErrorBounds::encodings, ModeChoice::encoding()); null: made here.
Result<RenderResult> renderPoints(const VulkanContext& context, const PointSet& points, const Camera& camera,
                                  const RenderOptions& options, const ModeEncoding* prepared = nullptr);

// The most draws (chunks) --chunk-points may cut a set into: each has buffers of its own, a few
// allocations of the 4,096 NVIDIA's driver allows.
inline constexpr uint64_t kMaxChunks = 1024;

// A point set read a block at a time, in order: how `dpoint render` draws a file larger than the
// host memory should hold. read(first, n, block) replaces `block` with points [first, first + n)
// (positions, and colours when has_colors); it is called for consecutive ranges from 0 on, each
// from one thread at a time, the next while the last is uploaded.
struct PointStream {
  size_t count = 0;
  bool has_colors = false;
  std::function<Status(size_t first, size_t n, PointSet& block)> read;
};
// Points per block of a stream: with two blocks on the host (36 B a point), about 1.2 GB at most;
// fewer where --max-memory is lower (streamBlockPoints), down to kMinStreamBlockPoints (75 MB).
// Always a multiple of kStreamBlockUnit: whole batches of every mode, whole boxes (kBoxPoints).
inline constexpr uint64_t kStreamBlockPoints = uint64_t{1} << 24;
inline constexpr uint64_t kMinStreamBlockPoints = uint64_t{1} << 20;
inline constexpr uint64_t kStreamBlockUnit = uint64_t{1} << 16;
inline constexpr uint64_t kStreamPointBytes = 36;  // a point's position and colour in a block
// The block a stream is read in under the memory limit `limit` (0: the default, half of RAM): two
// blocks of `point_bytes` a point in at most the limit (more than kStreamPointBytes where a
// dimension comes with each point: render --color NAME); the picture and the report are the same
// whatever the block. On a CPU device, whose memory is the host's, the render pass's blocks take
// half of the limit and the device's buffers the rest (viewer/render_job.cpp's HostMemoryBudget).
uint64_t streamBlockPoints(uint64_t limit, uint64_t point_bytes = kStreamPointBytes);
// The host bytes a stream of `count` points holds in blocks of `block`: two of them in flight.
inline uint64_t streamHeldBytes(uint64_t count, uint64_t block, uint64_t point_bytes) {
  return 2 * std::min(count, block) * point_bytes;
}
// --max-memory against what a stream of `count` points holds on the host, whatever the file's size:
// two blocks (streamBlockPoints) and `held` bytes the stream keeps besides (a tile set's copies,
// an E57 file's packet index: PointInputStream::heldBytes, named by `held_what`), the blocks sized
// in what `held` leaves. The block to read in; render and info refuse a limit that does not hold
// two of the smallest (exit 4, `name` and the need in the message).
Result<uint64_t> checkStreamMemory(const std::string& name, uint64_t count, uint64_t limit,
                                   uint64_t point_bytes = kStreamPointBytes, uint64_t held = 0,
                                   const std::string& held_what = "seam copies");

// renderPoints for a stream (no probe: it keeps every point's clip position). The same picture
// and the same errors as renderPoints of the whole set; the stream's errors end it.
Result<RenderResult> renderStream(const VulkanContext& context, const PointStream& stream, const Camera& camera,
                                  const RenderOptions& options);

// One pass over a stream whose camera is known only once every point has been read (a file
// without bounds in its header): the points are encoded for `provisional` (its scene frame's
// exponent is kept: reframeEncoding) and uploaded; then `settle` gives the camera and options the
// frames are drawn with (options.mode and backend as given). An error from settle ends the render
// with it (the caller's settle may so say that the points as uploaded will not do).
using StreamSettle = std::function<Status(Camera& camera, RenderOptions& options)>;
Result<RenderResult> renderStreamOnce(const VulkanContext& context, const PointStream& stream, const Camera& provisional,
                                      const RenderOptions& options, const StreamSettle& settle);

// --mode auto on this device (viewer/precision.h): the measured speed order of the device's
// class and backend, or its modes by predicted time to the picture (AutoTarget), restricted to the modes the device runs (features, the emulation
// self-test, and with `probe` the probe's needs).
// `target`: what the walk's order minimises (AutoTarget; by default the frames). `box`, where known,
// holds every point (and every coordinate is finite): the choice and the runner-up may be bounded
// over it (chooseMode's box_bounds_of; not with `probe`, whose report compares every bound with
// the error measured).
Result<ModeChoice> chooseModeOnDevice(const VulkanContext& context, const PointSet& points, const Camera& camera,
                                      Backend backend, bool probe, double tolerance_px = kDefaultTolerancePx,
                                      const AutoTarget& target = {}, const std::optional<Box>& box = std::nullopt);
// The same for a streamed set, from the boxes of its batches (predictBoxBounds; no probe).
Result<ModeChoice> chooseModeOnDevice(const VulkanContext& context, const BatchBoxes& boxes, const Camera& camera,
                                      Backend backend, double tolerance_px = kDefaultTolerancePx,
                                      const AutoTarget& target = {});

// Median and 95th percentile (nearest rank) of a sample; 0 for an empty one.
double medianOf(std::vector<double> values);
double percentileOf(std::vector<double> values, double p);

}  // namespace dpoint
