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

// Everything the encoders and uniform builders need for one mode, one camera and one set.
struct ModeEncoding {
  PrecisionMode mode = kFallbackMode;
  SceneFrame frame;
  std::vector<BatchFrame> batches;  // per-batch modes (ModeInfo::batch_points) only
  // Batch mode, one per batch, in double: projection · rotation · translate(origin − eye) ·
  // extent · 2^−20, all in the scene frame: it takes the integer offsets to clip space. The GPU gets them cast to float (batchMatrices); the error bound
  // uses them as they are.
  std::vector<glm::dmat4> batch_matrices;
};

// The largest |coordinate| in its frame that the mode's encoding holds: FLT_MAX where it stores
// floats, DBL_MAX else. addPoints refuses a point with a coordinate beyond it (or NaN).
double positionLimit(PrecisionMode mode);

// Builds the encoding. Fails (kBadInput, naming the point, the coordinate and the way out) when
// the mode cannot hold the set: a coordinate beyond float range in fp32/split, or beyond it in the
// scene frame in rte/df64 (a point ~1e38 view sizes from the origin); a batch whose origin is so
// far from the eye that its float matrix overflows. NaN and infinity never reach the GPU: inputs
// are finite (readers reject the rest), and these checks keep every encoded value finite too.
Result<ModeEncoding> prepareEncoding(PrecisionMode mode, const PointSet& points, const Camera& camera);

// The same a block at a time, for a set streamed from a file: the encoding before any point is
// seen, then each block in order (first_index: its first point's index in the whole set; in batch
// mode a multiple of kBatchSize), checked as prepareEncoding checks the whole set, with errors
// naming whole-set indices, and in batch mode its batches' frames and matrices appended.
ModeEncoding beginEncoding(PrecisionMode mode, const Camera& camera);
Status addPoints(ModeEncoding& encoding, const PointSet& block, size_t first_index);

// Writes positions [first, first + count) of `points` in the mode's layout to `out`
// (count · positionBytes(mode) bytes), with the mode's encoder (ModeInfo::encode). index_base: the
// index of points[0] in the whole set when `points` is a block of it (batch mode looks up batches
// by whole-set index).
void encodePositions(const ModeEncoding& encoding, const PointSet& points, size_t first, size_t count, void* out,
                     size_t index_base = 0);

// The mode's uniform block (std140, as declared in shaders/render/project.glsl; ModeInfo::uniform);
// empty for batch.
std::vector<uint8_t> cameraUniform(const ModeEncoding& encoding, const Camera& camera);

// Batch mode: encoding.batch_matrices cast to float, as the GPU gets them.
std::vector<glm::mat4> batchMatrices(const ModeEncoding& encoding);

}  // namespace dpoint
