// The precision modes (DESIGN §4), one row each: everything the renderer, the error analysis, the
// CLI and the bench ask about a mode is in its ModeInfo, so no other file switches on the mode.
//
//   mode    per point (bytes)           shader arithmetic
//   fp32    float xyz (12)              float MVP on absolute coordinates
//   split   hi, lo floats (24)          the study's mvp·(hi + lo): the sum rounds back to hi
//   rte     hi, lo floats (24)          (hi − eye_hi) + (lo − eye_lo) under `precise`, then a float
//                                       projection·rotation with no translation
//   df64    hi, lo floats (24)          double-float MVP (two-sum, split two-prod), splitter at run time
//   native  double xyz (24)             p − eye in double, then projection·rotation in double; the clip
//                                       position is cast to float at the end
//   batch   integer offsets (8)         per batch of 4096 points: a double origin and power-of-two
//                                       extent; each offset coordinate a 21-bit integer (2^−20 of the
//                                       extent per step), three in one 64-bit word; a float matrix built
//                                       in double maps them to clip space
//   adaptive  tier words (4, 8 or 12)   as batch, with 30-bit offsets (2^−29 of the extent) split into
//                                       three planes of 10 bits an axis; per frame and batch, the
//                                       fewest tiers whose bound is within --tolerance are loaded
//                                       (viewer/batch_plan.h), and batches outside the view are skipped
// Every mode adds 4 bytes of RGBA8 colour (the compute backend reads it only in the resolve).
//
// Adding a mode:
//   1. its enumerator at the end of PrecisionMode below (kAllModes lists them; rows are in this order);
//   2. its row at the end of kModes in viewer/modes.cpp, with the functions the row points at
//      beside it: the position encoder, the uniform builder (std140, as project.glsl declares it)
//      and the per-point error bound (bound::worstOf<itsBound>, or bound::worstOfPairs<ItsBound>
//      for a bound written for one point or two in lanes; the shared terms are in
//      viewer/bound_terms.h, and a per-camera term no mode has yet goes in bound::Setup there),
//      plus its speed ranks (kNoRank until measured), and its bound over a box of points in
//      kBoxBounds (viewer/precision.cpp: what a streamed set is predicted from);
//   3. its arithmetic in shaders/render/project.glsl under a MODE_… define, and its dpoint_shader
//      lines in CMakeLists.txt (raster vertex, compute splat; a pull variant where the raster path
//      may read positions from a storage buffer), whose headers modes.cpp includes for the row.
// Nothing else switches on a mode: --mode's names and help, `dpoint devices`, `dpoint info`, the
// bench's columns and charts, the pipelines, the encoder and --mode auto all walk this table.
// (bench/report.cpp's checks name the modes whose relations they check: split equals fp32, native
// meets the float floor.) tests/viewer/modes_test.cpp checks each row against its encoder, its
// uniform block, its layout and the speed orders.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>
#include <vulkan/vulkan.h>

namespace dpoint {

enum class PrecisionMode { kFp32, kSplit, kRte, kDf64, kNative, kBatch, kAdaptive };
inline constexpr PrecisionMode kAllModes[] = {PrecisionMode::kFp32, PrecisionMode::kSplit,
                                              PrecisionMode::kRte,  PrecisionMode::kDf64,
                                              PrecisionMode::kNative, PrecisionMode::kBatch,
                                              PrecisionMode::kAdaptive};
inline constexpr size_t kModeCount = std::size(kAllModes);
inline size_t modeIndex(PrecisionMode mode) { return static_cast<size_t>(mode); }

// The mode that holds everywhere double can: --mode auto's choice when no mode is within its
// bound, and the default of every options struct.
inline constexpr PrecisionMode kFallbackMode = PrecisionMode::kNative;

// Devices whose measured speed order `auto` knows: lavapipe (a CPU) and GPUs. The order for GPUs
// was measured on an NVIDIA H100 (bench/results/render-h100-2026-11-22.md, 1M–16.7M points); for
// lavapipe on this project's 2-core machine (render-lavapipe-2026-11-22.md).
enum class DeviceClass { kCpu, kGpu };
inline constexpr size_t kDeviceClassCount = 2;
std::string_view deviceClassName(DeviceClass device_class);
// From DeviceFacts::type ("cpu" for lavapipe).
inline DeviceClass deviceClassOf(std::string_view device_type) {
  return device_type == "cpu" ? DeviceClass::kCpu : DeviceClass::kGpu;
}

struct ModeEncoding;  // viewer/encode.h
struct Camera;        // viewer/camera.h
struct PointSet;      // core/point_set.h
namespace bound {     // viewer/bound_terms.h
struct Setup;
struct ModeState;
struct SeenPoint;
}  // namespace bound

// What the position buffer holds per point: `elements` values of one type, each `element_bytes`
// long and aligned (the buffer's alignment too).
enum class PositionElement { kFloat32, kFloat64, kUint32, kUint64 };
struct PositionLayout {
  PositionElement element;
  uint32_t elements;
  uint32_t element_bytes;
  std::string_view what;  // e.g. "hi.xyz, lo.xyz floats", interleaved per point
  // 1: the elements interleaved per point. More: each element in a plane of its own, one after the
  // other in a chunk's buffer, each starting at a multiple of 16 bytes (planeStride).
  uint32_t planes = 1;
};
// Elements of one plane of a chunk of `count` points: count rounded up to 4 (16-byte loads).
inline size_t planeStride(size_t count) { return (count + 3) & ~size_t{3}; }

// SPIR-V words compiled at build time (a header in the build tree per variant).
struct Spirv {
  const uint32_t* code = nullptr;
  size_t bytes = 0;
};
// One vertex attribute of the raster path's position binding (binding 0).
struct PositionAttribute {
  uint32_t location;
  VkFormat format;
  uint32_t offset;
};
struct ModeShaders {
  Spirv vertex;       // raster vertex shader, positions from vertex input
  Spirv vertex_pull;  // raster vertex shader reading positions from a storage buffer; none: no such path
  Spirv splat;        // compute backend splat (always pulls)
  PositionAttribute attributes[2];
  uint32_t attribute_count;
};

// Writes `count` positions, p[0 .. count), in the mode's layout to `out` (count · position_bytes
// bytes; a planar layout: the `count` elements of plane `plane`). first_index: the whole-set index
// of p[0] (per-batch modes look their batch up by it).
using PositionEncoder = void (*)(const ModeEncoding& encoding, const glm::dvec3* p, size_t count, void* out,
                                 size_t first_index, uint32_t plane);
// The mode's uniform block (std140, as declared in shaders/render/project.glsl); empty when it has none.
using UniformBuilder = std::vector<uint8_t> (*)(const ModeEncoding& encoding, const Camera& camera);
// The largest squared per-point error bound in pixels over the points of a block the camera sees
// (viewer/precision.h explains the analysis; viewer/bound_terms.h holds the shared terms).
using BoundFunction = double (*)(const bound::Setup& setup, const bound::ModeState& own, const PointSet& points,
                                 std::span<const bound::SeenPoint> seen, const Camera& camera);
// Whether the mode's arithmetic overflows for this camera whatever the points (nullptr: never).
using BoundRefusal = bool (*)(const bound::Setup& setup);

// Position in the measured speed order (0: fastest), by [DeviceClass][compute backend];
// kNoRank: --mode auto never takes it.
inline constexpr int kNoRank = -1;
using SpeedRanks = int[kDeviceClassCount][2];

// One row per mode: the facts every part of the renderer asks about.
struct ModeInfo {
  PrecisionMode mode;
  std::string_view name;
  std::string_view help;    // one line: what the mode is, as `dpoint render --help` lists it
  uint32_t position_bytes;  // per point, colour not included
  PositionLayout layout;
  bool scene_frame;         // works in the scaled scene frame (all but the absolute baselines)
  bool needs_self_test;     // emulated double: unusable where the compiler folds low parts away
  bool needs_shader_float64;        // the device feature shaderFloat64
  bool attribute_needs_r64_vertex;  // its raster vertex-input path needs R64G64B64_SFLOAT (else it pulls)
  uint32_t batch_points;    // points sharing one origin and scale (0: none); chunks and blocks hold whole batches
  uint32_t chunk_multiple;  // a chunk's first point is a multiple of this (the compute splat reads pairs)
  ModeShaders shaders;
  PositionEncoder encode;
  UniformBuilder uniform;
  BoundFunction bound;
  BoundRefusal bound_refuses;
  SpeedRanks speed_rank;
  double batch_steps = 0.0;  // per-batch modes: integer steps per batch extent (the offsets' resolution)
  uint32_t tiers = 0;        // adaptive: the tiers a batch may load (planes of the layout); 0: all, always
};
const ModeInfo& modeInfo(PrecisionMode mode);

inline std::string_view modeName(PrecisionMode mode) { return modeInfo(mode).name; }
std::optional<PrecisionMode> parseMode(std::string_view name);

// log2 of the points per batch of a per-batch mode (0 for the others).
inline uint32_t batchShift(PrecisionMode mode) {
  return static_cast<uint32_t>(std::bit_width(modeInfo(mode).batch_points | 1u)) - 1u;
}

// Bytes of position data per point (colour not included), and with the RGBA8 colour.
inline uint32_t positionBytes(PrecisionMode mode) { return modeInfo(mode).position_bytes; }
// Bytes of a chunk of `count` points' position buffer (planes padded to 16 bytes).
inline size_t positionBufferBytes(PrecisionMode mode, size_t count) {
  const PositionLayout& layout = modeInfo(mode).layout;
  return layout.planes == 1 ? count * modeInfo(mode).position_bytes
                            : layout.planes * planeStride(count) * layout.element_bytes;
}
inline uint32_t bytesPerPoint(PrecisionMode mode) { return positionBytes(mode) + 4; }

// Fastest first; modes without a rank (split: fp32's bound at a higher cost) never appear.
// raster: graphics pipeline.
std::span<const PrecisionMode> measuredSpeedOrder(DeviceClass device_class, bool compute_backend);

// What a picture costs each mode (issue #38 item 3), measured by bench/scripts/mode_rates.sh on the
// 16.7M-point Sierpinski set at 1920x1080, 1-px points: the host's encoding and upload in core
// nanoseconds a point (the median over the machines and backends measured: the same code on any
// host), and one frame in nanoseconds a point, by [DeviceClass][compute backend].
struct ModeCosts {
  double host_core_ns;
  double frame_ns[kDeviceClassCount][2];
};
const ModeCosts& modeCosts(PrecisionMode mode);
// The predicted time to the picture: `points` encoded and uploaded on `threads` cores, then
// `frames` frames (ms).
double predictedPictureMs(PrecisionMode mode, DeviceClass device_class, bool compute_backend, uint64_t points,
                          unsigned threads, uint32_t frames);
// --mode auto's order: for one picture (frames 1) the modes the speed order ranks, by predicted
// time to the picture (ties in speed order); for more frames, what they wait for is the frames:
// measuredSpeedOrder.
std::vector<PrecisionMode> autoOrder(DeviceClass device_class, bool compute_backend, uint64_t points, unsigned threads,
                                     uint32_t frames);

// `dpoint render --mode`: the values it takes ("auto" then every mode's name), the text an error
// lists them with ("auto, fp32, split, rte, df64, native, batch or adaptive"), and its --help text.
std::vector<std::string> modeOptionNames();
std::string modeOptionChoices();
std::string modeOptionHelp();
// "fp32 (float positions), split (…), …": every mode with its one-line help.
std::string modeListHelp();

}  // namespace dpoint
