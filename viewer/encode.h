// What each precision mode sends to the GPU (DESIGN §4): the per-point position encoding, the
// colour, and the camera uniforms, all derived from the same double Camera. The modes themselves
// (their layouts, encoders and uniform blocks) are rows of viewer/modes.h; this file holds what
// they share and the entry points that dispatch to the row.
//
// The scene frame (DESIGN §4): every mode but fp32 and split (the study's absolute baselines) sees
// positions multiplied by 2^exponent, chosen so the view's size is in [1, 2). Scaling by a power
// of two is exact, and 2^−exponent is folded into the projection, so no window position changes;
// what changes is that no intermediate of any mode underflows or overflows float, whether the
// scene is 1e-300 m or 1e300 m across. A mode's error then depends only on its significand.
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "core/point_set.h"
#include "core/result.h"
#include "viewer/camera.h"
#include "viewer/modes.h"

namespace dpoint {

// Points per batch in `batch` mode: consecutive points share one double origin and scale.
inline constexpr uint32_t kBatchShift = 12;
inline constexpr uint32_t kBatchSize = 1u << kBatchShift;
// And in `adaptive` mode: a quarter as many, so a batch's box is about half as wide on screen and
// its points need fewer tiers; one batch is one workgroup of the compute splat.
inline constexpr uint32_t kAdaptiveBatchShift = 10;
inline constexpr uint32_t kAdaptiveBatchSize = 1u << kAdaptiveBatchShift;

// Linear 0..1 colour → RGBA8 (R in the low byte), rounded to nearest, alpha 255. The image is
// UNORM, so the byte goes to the PNG unchanged. Points without colour are white.
uint32_t encodeColor(const glm::vec3& color);
std::vector<uint32_t> encodeColors(const PointSet& points);
// Colours of points [first, first + count) to `out`.
void encodeColors(const PointSet& points, size_t first, size_t count, uint32_t* out);

// The float hi part and the float remainder: hi = fl32(d), lo = fl32(d − hi). d − hi is exact in
// double, so hi + lo carries 48 bits of d when d is in float's normal range.
struct FloatPair {
  float hi, lo;
};
FloatPair splitDouble(double d);

// The frame a mode's GPU arithmetic works in (see the top of this file). For fp32 and split it is
// the world itself (exponent 0).
struct SceneFrame {
  int exponent = 0;
  double scale = 1.0;                   // 2^exponent
  glm::dvec3 eye{0.0};                  // camera.eye · scale, exact
  glm::dmat4 projection_rotation{1.0};  // projection · rotation · 2^−exponent (x, y, z columns)
};
SceneFrame sceneFrame(PrecisionMode mode, const Camera& camera);
// The scaled scene frame of the camera, whatever the mode (what every scene_frame mode gets).
SceneFrame sceneFrame(const Camera& camera);
// The same at a given exponent: every mode's arithmetic is the same scaled by a power of two (exact
// while nothing under- or overflows), so its pixels are the same; reframeEncoding keeps the
// exponent a stream was encoded at before its camera was known.
SceneFrame sceneFrame(const Camera& camera, int exponent);

// x · 2^exponent, correctly rounded (exact unless it over- or underflows): a multiplication by the
// power of two where that is a normal double, ldexp beyond.
inline double scaleBy(double x, const SceneFrame& frame) {
  return frame.exponent >= -1022 && frame.exponent <= 1023 ? x * frame.scale : std::ldexp(x, frame.exponent);
}
inline glm::dvec3 scaleBy(const glm::dvec3& p, const SceneFrame& frame) {
  return {scaleBy(p.x, frame), scaleBy(p.y, frame), scaleBy(p.z, frame)};
}

// Batch mode: t = (p·scale − origin) / extent in the scene frame, each within [−1, 1] (extent is a
// power of two, so the division is exact), stored as q = round(t·2^20) clamped to
// [−2^20, 2^20 − 1]: within one step (2^−20 of the extent) of t, half a step but at t = 1.
inline constexpr int kBatchOffsetBits = 21;
inline constexpr double kBatchSteps = 0x1p20;  // integer steps per extent
// Packs q (x in bits 0–20, y in 21–41, z in 42–62, two's complement) as shaders/render/project.glsl
// unpacks it; unpackBatchOffset is the inverse, for tests.
uint64_t packBatchOffset(const glm::dvec3& t);
glm::ivec3 unpackBatchOffset(uint64_t word);

struct BatchFrame {
  glm::dvec3 origin{0.0};  // centre of the batch's box, in the scene frame
  double extent = 1.0;     // power of two ≥ every |p·scale − origin| of the batch (1 if all equal)
};

// Adaptive mode (issue #25): t as in batch mode, stored as q = round(t·2^29) + 2^29 clamped to
// [0, 2^30 − 1], 30 bits per axis, split into three tiers of 10 bits (coarse: bits 29–20,
// medium: 19–10, fine: 9–0). A tier's word holds x | y << 10 | z << 20; a chunk's positions are
// three planes of such words (viewer/modes.h, PositionLayout::planes), so loading k tiers reads
// 4·k bytes a point. With k tiers loaded the shader rebuilds q as the centre of the cell the
// loaded bits name (k = 3: q itself) and maps q − 2^29 to clip space with the batch matrix.
inline constexpr int kAdaptiveTierBits = 10;
inline constexpr uint32_t kAdaptiveTiers = 3;
inline constexpr double kAdaptiveSteps = 0x1p29;  // integer steps per extent
// The tolerance adaptive mode chooses its tiers for (--tolerance), in window pixels.
inline constexpr double kDefaultTolerancePx = 0.05;
// q of one coordinate t in [−1, 1] (t = 1 is the one value clamped).
uint32_t quantizeAdaptive(double t);
// The word of tier `tier` (0 coarse, 1 medium, 2 fine) of a point's three q.
inline uint32_t adaptiveTierWord(const glm::uvec3& q, uint32_t tier) {
  const uint32_t shift = kAdaptiveTierBits * (kAdaptiveTiers - 1 - tier);
  return ((q.x >> shift) & 1023u) | ((q.y >> shift) & 1023u) << 10 | ((q.z >> shift) & 1023u) << 20;
}
// q rebuilt from its `tiers` loaded tiers as project.glsl rebuilds it, minus 2^29 (what the batch
// matrix multiplies), for tests.
int32_t adaptiveRebuilt(uint32_t q, uint32_t tiers);
// The largest distance in steps between the stored value rebuilt from `tiers` tiers and t·2^29
// (before the float conversion): half a cell of the bits not loaded, half a step of rounding, one
// step at the clamped edge t = 1, and t's own rounding.
double adaptiveStepError(uint32_t tiers);

// Everything the encoders and uniform builders need for one mode, one camera and one set.
struct ModeEncoding {
  PrecisionMode mode = kFallbackMode;
  SceneFrame frame;
  std::vector<BatchFrame> batches;  // per-batch modes (ModeInfo::batch_points) only
  // Per-batch modes, one per batch, in double: projection · rotation · translate(origin − eye) ·
  // extent / steps (2^20 in batch mode, 2^29 in adaptive), all in the scene frame: it takes the
  // integer offsets to clip space. The GPU gets them cast to float (batchMatrices); the error
  // bound uses them as they are.
  std::vector<glm::dmat4> batch_matrices;
  // Per batch, for this camera (viewer/batch_plan.h): 0 where its box shows no point (the compute
  // backend skips it), else the tiers adaptive mode loads (1 to 3; batch mode: 1).
  std::vector<uint8_t> batch_plan;
  double tolerance_px = kDefaultTolerancePx;  // adaptive mode's tier choice
  uint32_t width = 0, height = 0;             // the camera's picture, for the tier choice
  uint32_t batch_shift = 0;                   // log2 of the mode's points per batch (ModeInfo::batch_points)
  size_t batchOf(size_t index) const { return index >> batch_shift; }
  size_t batchSize() const { return size_t{1} << batch_shift; }
};

// The largest |coordinate| in its frame that the mode's encoding holds: FLT_MAX where it stores
// floats, DBL_MAX else. addPoints refuses a point with a coordinate beyond it (or NaN).
double positionLimit(PrecisionMode mode);

// Builds the encoding. Fails (kBadInput, naming the point, the coordinate and the way out) when
// the mode cannot hold the set: a coordinate beyond float range in fp32/split, or beyond it in the
// scene frame in rte/df64 (a point ~1e38 view sizes from the origin); a batch whose origin is so
// far from the eye that its float matrix overflows. NaN and infinity never reach the GPU: inputs
// are finite (readers reject the rest), and these checks keep every encoded value finite too.
Result<ModeEncoding> prepareEncoding(PrecisionMode mode, const PointSet& points, const Camera& camera,
                                     double tolerance_px = kDefaultTolerancePx);

// The same a block at a time, for a set streamed from a file: the encoding before any point is
// seen, then each block in order (first_index: its first point's index in the whole set; in batch
// per-batch modes a multiple of the batch size), checked as prepareEncoding checks the whole set, with errors
// naming whole-set indices, and in batch mode its batches' frames and matrices appended.
ModeEncoding beginEncoding(PrecisionMode mode, const Camera& camera, double tolerance_px = kDefaultTolerancePx);
Status addPoints(ModeEncoding& encoding, const PointSet& block, size_t first_index);
// A stream encoded in one pass before its camera was known (beginEncoding with a provisional
// camera): the encoding for `camera`, at the exponent its points were encoded at, its batches'
// matrices and plan made again. The per-point data stays valid: fp32's and split's are the world's,
// the scene-frame modes' are scaled by the kept exponent, and the per-batch modes' offsets are
// relative to a batch frame that scales with it (docs/rendering.md: one pass over a stream).
Status reframeEncoding(ModeEncoding& encoding, const Camera& camera);
// Per-batch modes, for a set known only by the bounding box of every kBoxPoints consecutive points
// (boxes[k]: points k·kBoxPoints on from the next batch, as viewer/precision.h's BatchBoxes keeps
// them; a batch is the union of batchSize() / kBoxPoints of them): the frames, matrices and plan
// addPoints makes of the points themselves, to the bit (a batch's frame depends on its points only
// through their box), after the same checks, the errors naming the batch.
inline constexpr uint32_t kBoxPoints = kAdaptiveBatchSize;  // the smallest batch of any mode
Status addBoxes(ModeEncoding& encoding, std::span<const Box> boxes);

// Writes positions [first, first + count) of `points` in the mode's layout to `out`
// (count · positionBytes(mode) bytes; a planar layout: count words of plane `plane`), with the
// mode's encoder (ModeInfo::encode). index_base: the index of points[0] in the whole set when
// `points` is a block of it (batch modes look up batches by whole-set index).
void encodePositions(const ModeEncoding& encoding, const PointSet& points, size_t first, size_t count, void* out,
                     size_t index_base = 0, uint32_t plane = 0);

// The mode's uniform block (std140, as declared in shaders/render/project.glsl; ModeInfo::uniform);
// empty for batch.
std::vector<uint8_t> cameraUniform(const ModeEncoding& encoding, const Camera& camera);

// Batch mode: encoding.batch_matrices cast to float, as the GPU gets them.
std::vector<glm::mat4> batchMatrices(const ModeEncoding& encoding);

}  // namespace dpoint
