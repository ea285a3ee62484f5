// What each precision mode sends to the GPU (DESIGN §4): the per-point position encoding, the
// colour, and the camera uniforms, all derived from the same double Camera.
//
//   mode    per point (bytes)           shader arithmetic
//   fp32    float xyz (12)              float MVP on absolute coordinates
//   split   hi, lo floats (24)          the study's mvp·(hi + lo): the sum rounds back to hi
//   rte     hi, lo floats (24)          (hi − eye_hi) + (lo − eye_lo) under `precise`, then a float
//                                       projection·rotation with no translation
//   df64    hi, lo floats (24)          double-float MVP (two-sum, split two-prod), splitter at run time
//   native  double xyz (24)             dmat4 MVP in fp64; clip position cast to float at the end
//   batch   float offsets (12)          per-batch float matrix projection·rotation·translate(origin − eye)
// Every mode adds 4 bytes of RGBA8 colour.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/mat4x4.hpp>

#include "core/point_set.h"
#include "core/result.h"
#include "viewer/camera.h"

namespace dpoint {

enum class PrecisionMode { kFp32, kSplit, kRte, kDf64, kNative, kBatch };
inline constexpr PrecisionMode kAllModes[] = {PrecisionMode::kFp32, PrecisionMode::kSplit,
                                              PrecisionMode::kRte,  PrecisionMode::kDf64,
                                              PrecisionMode::kNative, PrecisionMode::kBatch};

std::string_view modeName(PrecisionMode mode);
std::optional<PrecisionMode> parseMode(std::string_view name);

// Bytes of position data per point (colour not included).
uint32_t positionBytes(PrecisionMode mode);
inline uint32_t bytesPerPoint(PrecisionMode mode) { return positionBytes(mode) + 4; }

// Points per batch in `batch` mode: consecutive points share one double origin.
inline constexpr uint32_t kBatchSize = 4096;

// Linear 0..1 colour → RGBA8 (R in the low byte), rounded to nearest, alpha 255. The image is
// UNORM, so the byte goes to the PNG unchanged. Points without colour are white.
uint32_t encodeColor(const glm::vec3& color);
std::vector<uint32_t> encodeColors(const PointSet& points);

// The float hi part and the float remainder: hi = fl32(d), lo = fl32(d − hi). d − hi is exact in
// double, so hi + lo carries 48 bits of d when d is in float's normal range.
struct FloatPair {
  float hi, lo;
};
FloatPair splitDouble(double d);

// Fails (kBadInput, naming the point and coordinate) when the mode's encoding cannot hold a
// position: beyond float range in fp32/split/rte/df64, or a batch offset beyond float range.
// NaN and infinity never reach the GPU: inputs are finite (readers reject the rest), and this
// check keeps every encoded float finite too.
Status checkEncodable(PrecisionMode mode, const PointSet& points, const std::vector<glm::dvec3>& batch_origins);

// Centre of each batch's bounding box (batch mode); empty for the other modes.
std::vector<glm::dvec3> batchOrigins(PrecisionMode mode, const PointSet& points);

// Writes positions [first, first + count) in the mode's layout to `out`
// (count · positionBytes(mode) bytes). Batch offsets are relative to their batch's origin.
void encodePositions(PrecisionMode mode, const PointSet& points, const std::vector<glm::dvec3>& batch_origins,
                     size_t first, size_t count, void* out);

// The mode's uniform block (std140, as declared in shaders/points.vert); empty for batch.
std::vector<uint8_t> cameraUniform(PrecisionMode mode, const Camera& camera);

// Batch mode: one float matrix per batch, projection · rotation · translate(origin − eye), built
// in double so only the final float rounding remains.
std::vector<glm::mat4> batchMatrices(const Camera& camera, const std::vector<glm::dvec3>& batch_origins);

}  // namespace dpoint
