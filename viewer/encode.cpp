#include "viewer/encode.h"

#include <algorithm>
#include <cmath>
#include <charconv>
#include <cstring>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>

namespace dpoint {
namespace {

constexpr double kFloatMax = static_cast<double>(std::numeric_limits<float>::max());

std::string shortest(double v) {
  char text[32];
  auto r = std::to_chars(text, text + sizeof text, v);
  return std::string(text, r.ptr);
}

const char* axisName(int axis) { return axis == 0 ? "x" : axis == 1 ? "y" : "z"; }

// A double rounds to a finite float when it is below FLT_MAX plus half an ulp; stay strictly
// under FLT_MAX to keep the test simple and safe.
bool fitsFloat(double d) { return std::fabs(d) <= kFloatMax; }

template <typename Matrix>
void appendBytes(std::vector<uint8_t>& out, const Matrix& m) {
  size_t at = out.size();
  out.resize(at + sizeof(Matrix));
  std::memcpy(out.data() + at, &m, sizeof(Matrix));
}

glm::mat4 toFloat(const glm::dmat4& m) { return glm::mat4(m); }

}  // namespace

std::string_view modeName(PrecisionMode mode) {
  switch (mode) {
    case PrecisionMode::kFp32: return "fp32";
    case PrecisionMode::kSplit: return "split";
    case PrecisionMode::kRte: return "rte";
    case PrecisionMode::kDf64: return "df64";
    case PrecisionMode::kNative: return "native";
    case PrecisionMode::kBatch: return "batch";
  }
  return "?";
}

std::optional<PrecisionMode> parseMode(std::string_view name) {
  for (PrecisionMode mode : kAllModes)
    if (modeName(mode) == name) return mode;
  return std::nullopt;
}

uint32_t positionBytes(PrecisionMode mode) {
  switch (mode) {
    case PrecisionMode::kFp32:
    case PrecisionMode::kBatch: return 12;
    case PrecisionMode::kSplit:
    case PrecisionMode::kRte:
    case PrecisionMode::kDf64:
    case PrecisionMode::kNative: return 24;
  }
  return 0;
}

uint32_t encodeColor(const glm::vec3& color) {
  uint32_t packed = 0xff000000u;
  for (int c = 0; c < 3; ++c) {
    float v = std::clamp(color[c], 0.0f, 1.0f);  // NaN never gets here: readers reject it
    packed |= static_cast<uint32_t>(std::lround(v * 255.0f)) << (8 * c);
  }
  return packed;
}

std::vector<uint32_t> encodeColors(const PointSet& points) {
  if (!points.hasColors()) return std::vector<uint32_t>(points.size(), 0xffffffffu);
  std::vector<uint32_t> out(points.size());
  for (size_t i = 0; i < points.size(); ++i) out[i] = encodeColor(points.colors[i]);
  return out;
}

FloatPair splitDouble(double d) {
  // GCC 12's SLP vectorizer folds (double)(float)d back to d when it packs two of these side by
  // side (seen at -O2: `subpd %xmm0, %xmm0`), which zeroes every lo part; the volatile read of
  // hi keeps the rounding. encodeRoundTripKeepsLowParts (tests/encode_test.cpp) guards it.
  volatile float hi = static_cast<float>(d);
  float hi_value = hi;
  float lo = static_cast<float>(d - static_cast<double>(hi_value));  // d − hi is exact in double
  return {hi_value, lo};
}

Status checkEncodable(PrecisionMode mode, const PointSet& points, const std::vector<glm::dvec3>& batch_origins) {
  if (mode == PrecisionMode::kNative) return okStatus();
  const bool batch = mode == PrecisionMode::kBatch;
  for (size_t i = 0; i < points.size(); ++i) {
    glm::dvec3 p = points.positions[i];
    if (batch) p -= batch_origins[i / kBatchSize];
    for (int axis = 0; axis < 3; ++axis) {
      if (fitsFloat(p[axis])) continue;
      std::string what = std::string(axisName(axis)) + " = " + shortest(points.positions[i][axis]);
      if (batch) what += " (" + shortest(p[axis]) + " from its batch's centre)";
      return Error{"point " + std::to_string(i) + ": " + what + " is beyond float32 range, which mode " +
                       std::string(modeName(mode)) + " needs; use --mode native",
                   ExitCode::kBadInput};
    }
  }
  return okStatus();
}

std::vector<glm::dvec3> batchOrigins(PrecisionMode mode, const PointSet& points) {
  std::vector<glm::dvec3> origins;
  if (mode != PrecisionMode::kBatch) return origins;
  size_t batches = (points.size() + kBatchSize - 1) / kBatchSize;
  origins.resize(batches);
  for (size_t b = 0; b < batches; ++b) {
    const size_t first = b * kBatchSize;
    const Box box = boundingBox(points.positions, first, std::min(points.size(), first + kBatchSize));
    // min/2 + max/2 cannot overflow where (min + max)/2 could.
    origins[b] = box.min * 0.5 + box.max * 0.5;
  }
  return origins;
}

void encodePositions(PrecisionMode mode, const PointSet& points, const std::vector<glm::dvec3>& batch_origins,
                     size_t first, size_t count, void* out) {
  assert(first + count <= points.size());
  auto* f = static_cast<float*>(out);
  const glm::dvec3* p = points.positions.data() + first;
  switch (mode) {
    case PrecisionMode::kFp32:
      for (size_t i = 0; i < count; ++i)
        for (int a = 0; a < 3; ++a) f[3 * i + a] = static_cast<float>(p[i][a]);
      break;
    case PrecisionMode::kSplit:
    case PrecisionMode::kRte:
    case PrecisionMode::kDf64:
      // Interleaved per point: hi.xyz then lo.xyz (one 24-byte vertex binding).
      for (size_t i = 0; i < count; ++i) {
        for (int a = 0; a < 3; ++a) {
          FloatPair pair = splitDouble(p[i][a]);
          f[6 * i + a] = pair.hi;
          f[6 * i + 3 + a] = pair.lo;
        }
      }
      break;
    case PrecisionMode::kNative: std::memcpy(out, p, count * sizeof(glm::dvec3)); break;
    case PrecisionMode::kBatch:
      for (size_t i = 0; i < count; ++i) {
        const glm::dvec3& origin = batch_origins[(first + i) / kBatchSize];
        for (int a = 0; a < 3; ++a) f[3 * i + a] = static_cast<float>(p[i][a] - origin[a]);
      }
      break;
  }
}

std::vector<uint8_t> cameraUniform(PrecisionMode mode, const Camera& camera) {
  std::vector<uint8_t> out;
  switch (mode) {
    case PrecisionMode::kFp32:
    case PrecisionMode::kSplit: appendBytes(out, toFloat(camera.viewProjection())); break;
    case PrecisionMode::kRte: {
      // The translation is done in the shader against the eye's hi/lo parts, so the matrix
      // holds only projection · rotation and never sees a large number.
      appendBytes(out, toFloat(camera.projection * camera.rotation));
      // vec4 eye_hi, vec4 eye_lo (std140).
      float eye[8] = {};
      for (int a = 0; a < 3; ++a) {
        FloatPair pair = splitDouble(camera.eye[a]);
        eye[a] = pair.hi;
        eye[4 + a] = pair.lo;
      }
      appendBytes(out, eye);
      break;
    }
    case PrecisionMode::kDf64: {
      glm::dmat4 mvp = camera.viewProjection();
      glm::mat4 hi(0.0f), lo(0.0f);
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) {
          FloatPair pair = splitDouble(mvp[c][r]);
          hi[c][r] = pair.hi;
          lo[c][r] = pair.lo;
        }
      appendBytes(out, hi);
      appendBytes(out, lo);
      break;
    }
    case PrecisionMode::kNative: appendBytes(out, camera.viewProjection()); break;
    case PrecisionMode::kBatch: break;
  }
  return out;
}

std::vector<glm::mat4> batchMatrices(const Camera& camera, const std::vector<glm::dvec3>& batch_origins) {
  std::vector<glm::mat4> out(batch_origins.size());
  glm::dmat4 projection_rotation = camera.projection * camera.rotation;
  for (size_t b = 0; b < batch_origins.size(); ++b)
    out[b] = toFloat(glm::translate(projection_rotation, batch_origins[b] - camera.eye));
  return out;
}

}  // namespace dpoint
