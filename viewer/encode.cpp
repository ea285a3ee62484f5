#include "viewer/encode.h"

#include <algorithm>
#include <cassert>
#include <charconv>
#include <cmath>
#include <limits>
#include <optional>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "core/parallel.h"
#include "viewer/batch_plan.h"

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


// The smallest power of two ≥ d (d ≥ 0); 1 for 0.
double powerOfTwoAbove(double d) {
  if (!(d > 0.0)) return 1.0;
  int exponent = 0;
  const double mantissa = std::frexp(d, &exponent);  // d = mantissa · 2^exponent, mantissa in [0.5, 1)
  return mantissa == 0.5 ? d : std::ldexp(1.0, exponent);
}

// A batch's frame from the box of its points: the origin at its centre, the extent the power of
// two at or above the largest |p·scale − origin| of a coordinate as computed (rounded), which
// bounds every stored offset within [−1, 1] whatever the rounding of the centre. Scaling and the
// rounded subtraction are monotone, so that largest is at the box's min or max on some axis, and
// those are coordinates of its points: the frame of the box is the frame of the points, to the bit.
BatchFrame batchFrameOf(const Box& box, const SceneFrame& frame) {
  // min/2 + max/2 cannot overflow where (min + max)/2 could; scaling by 2^exponent is exact.
  const glm::dvec3 origin = scaleBy(box.min * 0.5 + box.max * 0.5, frame);
  const glm::dvec3 low = scaleBy(box.min, frame) - origin, high = scaleBy(box.max, frame) - origin;
  double largest = 0.0;
  for (int a = 0; a < 3; ++a) largest = std::max({largest, std::fabs(low[a]), std::fabs(high[a])});
  return {origin, powerOfTwoAbove(largest)};
}

std::vector<BatchFrame> makeBatchFrames(const PointSet& points, const SceneFrame& frame, size_t batch_size) {
  const size_t batches = (points.size() + batch_size - 1) / batch_size;
  std::vector<BatchFrame> frames(batches);
  parallelFor(batches, 0, [&](size_t b, unsigned) {
    const size_t first = b * batch_size, last = std::min(points.size(), first + batch_size);
    frames[b] = batchFrameOf(boundingBox(points.positions, first, last), frame);
  });
  return frames;
}

// projection · rotation · translate(origin − eye) · extent / steps, in the scene frame.
glm::dmat4 batchMatrix(const SceneFrame& frame, const BatchFrame& b, double steps) {
  glm::dmat4 m = frame.projection_rotation;
  const glm::dvec3 relative = b.origin - frame.eye;  // both in the scene frame
  glm::dvec4 translation = m[3];
  for (int c = 0; c < 3; ++c) translation += m[c] * relative[c];
  for (int c = 0; c < 3; ++c) m[c] *= b.extent / steps;  // powers of two: exact
  m[3] = translation;
  return m;
}

// Appends batches with these frames: their matrices (each checked to fit float) and their plan.
Status appendBatches(ModeEncoding& e, const std::vector<BatchFrame>& frames) {
  const size_t first_batch = e.batches.size();
  e.batches.insert(e.batches.end(), frames.begin(), frames.end());
  e.batch_matrices.reserve(e.batches.size());
  const double steps = modeInfo(e.mode).batch_steps;
  for (size_t b = first_batch; b < e.batches.size(); ++b) {
    const glm::dmat4& m = e.batch_matrices.emplace_back(batchMatrix(e.frame, e.batches[b], steps));
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) {
        if (fitsFloat(m[c][r])) continue;
        const size_t first = b * e.batchSize();
        return Error{"batch " + std::to_string(b) + " (points " + std::to_string(first) + "..): its origin is " +
                         shortest(glm::length(e.batches[b].origin - e.frame.eye)) +
                         " view sizes from the eye, and its float matrix overflows; use --mode native",
                     ExitCode::kBadInput};
      }
  }
  planBatches(e, first_batch);
  return okStatus();
}

Error beyondFloat(PrecisionMode mode, size_t index, int axis, double value, const std::string& how) {
  return Error{"point " + std::to_string(index) + ": " + axisName(axis) + " = " + shortest(value) + how +
                   " is beyond float32 range, which mode " + std::string(modeName(mode)) + " needs; use --mode native",
               ExitCode::kBadInput};
}

// The first problem of point i, if it has one.
std::optional<Error> positionProblem(const ModeEncoding& e, const PointSet& points, size_t i, size_t index_base) {
  const ModeInfo& info = modeInfo(e.mode);
  const bool floats = info.layout.element == PositionElement::kFloat32;  // each coordinate stored as float(s)
  for (int axis = 0; axis < 3; ++axis) {
    const double value = points.positions[i][axis];
    const double in_frame = scaleBy(value, e.frame);
    if (floats && !fitsFloat(in_frame)) {
      std::string how = info.scene_frame
          ? " (" + shortest(in_frame) + " view sizes from the origin)" : std::string();
      return beyondFloat(e.mode, index_base + i, axis, value, how);
    }
    if (!std::isfinite(in_frame)) {
      return Error{"point " + std::to_string(index_base + i) + ": " + axisName(axis) + " = " + shortest(value) +
                       " overflows double when scaled to the view (" + shortest(in_frame) + ")",
                   ExitCode::kBadInput};
    }
  }
  return std::nullopt;
}

// Every position checked on every core; the error names the first bad point whatever the thread count.
// The test positionProblem makes, without building its message: a coordinate in the mode's frame
// is finite and, where the mode stores floats, within float range.
Status checkPositions(const ModeEncoding& e, const PointSet& points, size_t index_base) {
  constexpr size_t kBlock = 1 << 16;
  const size_t blocks = (points.size() + kBlock - 1) / kBlock;
  std::vector<size_t> first_bad(blocks, SIZE_MAX);
  const double limit = positionLimit(e.mode);
  parallelFor(blocks, 0, [&](size_t b, unsigned) {
    for (size_t i = b * kBlock, end = std::min(points.size(), i + kBlock); i < end; ++i) {
      const glm::dvec3 in_frame = scaleBy(points.positions[i], e.frame);
      for (int axis = 0; axis < 3; ++axis)
        if (!std::isfinite(in_frame[axis]) || !(std::fabs(in_frame[axis]) <= limit)) {
          first_bad[b] = i;
          return;
        }
    }
  });
  for (size_t i : first_bad)
    if (i != SIZE_MAX) return *positionProblem(e, points, i, index_base);
  return okStatus();
}

// t in [−1, 1] as a whole number of steps (a power of two per extent) in [−steps, steps − 1]: t·steps
// is exact, rounded half to even without nearbyint's libm call (adding and taking away 1.5·2^52
// leaves an |x| ≤ 2^51 rounded to an integer in the current round-to-nearest mode; -ffp-contract=off
// and no -ffast-math keep the two operations as written); t = 1 is the one value clamped.
double roundToStep(double t, double steps) {
  constexpr double kRound = 0x1.8p52;
  return std::clamp((t * steps + kRound) - kRound, -steps, steps - 1.0);
}

// lround(v · 255) of v clamped to 0..1, without lround's libm call (the upload's cost at 16.7M
// points): the float product plus 0.5 is exact in double, so truncating it rounds half away from
// zero as lround does. NaN never gets here: readers reject it.
inline uint32_t colourByte(float v) {
  const float scaled = std::min(std::max(v, 0.0f), 1.0f) * 255.0f;  // std::clamp's order: -0 stays -0
  return static_cast<uint32_t>(static_cast<int32_t>(static_cast<double>(scaled) + 0.5));
}

}  // namespace

uint32_t encodeColor(const glm::vec3& color) {
  return 0xff000000u | colourByte(color.r) | colourByte(color.g) << 8 | colourByte(color.b) << 16;
}

std::vector<uint32_t> encodeColors(const PointSet& points) {
  std::vector<uint32_t> out(points.size());
  encodeColors(points, 0, points.size(), out.data());
  return out;
}

void encodeColors(const PointSet& points, size_t first, size_t count, uint32_t* out) {
  assert(first + count <= points.size());
  if (!points.hasColors()) {
    std::fill(out, out + count, 0xffffffffu);
    return;
  }
  // The channels as one flat array of floats, a block at a time, so that the conversions run in
  // SIMD lanes (a point at a time they took 7 ns a point of lavapipe's 16.7M-point upload on 2
  // cores); then the bytes packed with the alpha.
  static_assert(sizeof(glm::vec3) == 3 * sizeof(float));
  if (count == 0) return;  // first may be the end
  constexpr size_t kBlock = 1024;
  uint8_t bytes[3 * kBlock];
  const float* channels = &points.colors[first].x;
  for (size_t done = 0; done < count; done += kBlock) {
    const size_t n = std::min(kBlock, count - done);
    const float* in = channels + 3 * done;
    size_t j = 0;
#if defined(__SSE2__)
    // colourByte of 16 channels at once, the same steps in SSE2 lanes (x86-64's baseline): a clamp,
    // the float product, its double plus 0.5 truncated; the bytes from two saturating packs (the
    // values lie in 0..255).
    const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f), k255 = _mm_set1_ps(255.0f);
    const __m128d half = _mm_set1_pd(0.5);
    const auto four = [&](const float* f) {
      const __m128 v = _mm_mul_ps(_mm_min_ps(_mm_max_ps(_mm_loadu_ps(f), zero), one), k255);
      const __m128i lo = _mm_cvttpd_epi32(_mm_add_pd(_mm_cvtps_pd(v), half));
      const __m128i hi = _mm_cvttpd_epi32(_mm_add_pd(_mm_cvtps_pd(_mm_movehl_ps(v, v)), half));
      return _mm_unpacklo_epi64(lo, hi);
    };
    for (; j + 16 <= 3 * n; j += 16) {
      const __m128i words = _mm_packs_epi32(four(in + j), four(in + j + 4));
      const __m128i words2 = _mm_packs_epi32(four(in + j + 8), four(in + j + 12));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(bytes + j), _mm_packus_epi16(words, words2));
    }
#endif
    for (; j < 3 * n; ++j) bytes[j] = static_cast<uint8_t>(colourByte(in[j]));
    for (size_t i = 0; i < n; ++i)
      out[done + i] = 0xff000000u | bytes[3 * i] | uint32_t{bytes[3 * i + 1]} << 8 | uint32_t{bytes[3 * i + 2]} << 16;
  }
}

uint64_t packBatchOffset(const glm::dvec3& t) {
  constexpr uint64_t kMask = (uint64_t{1} << kBatchOffsetBits) - 1;
  uint64_t word = 0;
  for (int a = 0; a < 3; ++a) {
    const double q = roundToStep(t[a], kBatchSteps);
    word |= (static_cast<uint64_t>(static_cast<int64_t>(q)) & kMask) << (kBatchOffsetBits * a);
  }
  return word;
}

glm::ivec3 unpackBatchOffset(uint64_t word) {
  glm::ivec3 q;
  for (int a = 0; a < 3; ++a) {
    // Shift the field to the top, then arithmetic-shift back: the sign extends.
    const auto field = static_cast<int64_t>(word << (64 - kBatchOffsetBits * (a + 1)));
    q[a] = static_cast<int>(field >> (64 - kBatchOffsetBits));
  }
  return q;
}

uint32_t quantizeAdaptive(double t) {
  return static_cast<uint32_t>(static_cast<int32_t>(roundToStep(t, kAdaptiveSteps)) + (int32_t{1} << 29));
}

int32_t adaptiveRebuilt(uint32_t q, uint32_t tiers) {
  const uint32_t dropped = kAdaptiveTierBits * (kAdaptiveTiers - tiers);
  const uint32_t rebuilt = dropped == 0 ? q : ((q >> dropped) << dropped) | (1u << (dropped - 1));
  return static_cast<int32_t>(rebuilt) - (int32_t{1} << 29);
}

double adaptiveStepError(uint32_t tiers) {
  const uint32_t dropped = kAdaptiveTierBits * (kAdaptiveTiers - tiers);
  const double half_cell = dropped == 0 ? 0.0 : std::ldexp(1.0, static_cast<int>(dropped) - 1);
  return half_cell + 1.0 + 0x1p-20;
}

FloatPair splitDouble(double d) {
  // GCC 12's SLP vectorizer folds (double)(float)d back to d when it packs two of these side by
  // side (seen at -O2: `subpd %xmm0, %xmm0`), which zeroes every lo part; the volatile read of
  // hi keeps the rounding. encodeRoundTripKeepsLowParts (tests/viewer/encode_test.cpp) guards it.
  volatile float hi = static_cast<float>(d);
  float hi_value = hi;
  float lo = static_cast<float>(d - static_cast<double>(hi_value));  // d − hi is exact in double
  return {hi_value, lo};
}

SceneFrame sceneFrame(PrecisionMode mode, const Camera& camera) {
  if (modeInfo(mode).scene_frame) return sceneFrame(camera);
  SceneFrame frame;
  frame.eye = camera.eye;
  frame.projection_rotation = camera.projection * camera.rotation;
  return frame;
}

SceneFrame sceneFrame(const Camera& camera) {
  // The view's size: the window for ortho; for perspective the far plane, which bounds every
  // eye-relative distance of a visible point (the projection is already scaled by 1/far).
  double size = camera.far_plane;
  if (camera.ortho)
    size = std::max(2.0 / std::fabs(camera.projection[0][0]), 2.0 / std::fabs(camera.projection[1][1]));
  assert(std::isfinite(size) && size > 0.0);
  return sceneFrame(camera, -std::ilogb(size));  // size · 2^exponent in [1, 2)
}

SceneFrame sceneFrame(const Camera& camera, int exponent) {
  SceneFrame frame;
  frame.projection_rotation = camera.projection * camera.rotation;
  frame.exponent = exponent;
  frame.scale = std::ldexp(1.0, frame.exponent);
  frame.eye = scaleBy(camera.eye, frame);
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 4; ++r)
      frame.projection_rotation[c][r] = std::ldexp(frame.projection_rotation[c][r], -frame.exponent);
  return frame;
}

double positionLimit(PrecisionMode mode) {
  return modeInfo(mode).layout.element == PositionElement::kFloat32 ? kFloatMax : std::numeric_limits<double>::max();
}

ModeEncoding beginEncoding(PrecisionMode mode, const Camera& camera, double tolerance_px) {
  ModeEncoding e;
  e.mode = mode;
  e.frame = sceneFrame(mode, camera);
  e.tolerance_px = tolerance_px;
  e.width = camera.width;
  e.height = camera.height;
  e.batch_shift = batchShift(mode);
  return e;
}

Status addPoints(ModeEncoding& e, const PointSet& block, size_t first_index) {
  if (Status status = checkPositions(e, block, first_index); !status) return status;
  if (modeInfo(e.mode).batch_points == 0) return okStatus();
  assert(first_index == e.batches.size() * e.batchSize());  // blocks in order, whole batches but the last
  return appendBatches(e, makeBatchFrames(block, e.frame, e.batchSize()));
}

Status reframeEncoding(ModeEncoding& e, const Camera& camera) {
  e.frame = modeInfo(e.mode).scene_frame ? sceneFrame(camera, e.frame.exponent) : sceneFrame(e.mode, camera);
  e.width = camera.width;
  e.height = camera.height;
  std::vector<BatchFrame> frames = std::move(e.batches);
  e.batches.clear();
  e.batch_matrices.clear();
  e.batch_plan.clear();
  if (frames.empty()) return okStatus();
  return appendBatches(e, frames);
}

Status addBoxes(ModeEncoding& e, std::span<const Box> boxes) {
  assert(modeInfo(e.mode).batch_points != 0);
  // checkPositions' test on the boxes: a coordinate's magnitude in the frame is largest at the
  // box's min or max of its axis, which are coordinates of the batch's points.
  const double limit = positionLimit(e.mode);
  for (size_t k = 0; k < boxes.size(); ++k)
    for (const glm::dvec3& corner : {boxes[k].min, boxes[k].max})
      for (int axis = 0; axis < 3; ++axis) {
        const double in_frame = scaleBy(corner[axis], e.frame);
        if (std::isfinite(in_frame) && std::fabs(in_frame) <= limit) continue;
        const size_t b = e.batches.size() + k / (e.batchSize() / kBoxPoints);
        return Error{"batch " + std::to_string(b) + " (points " + std::to_string(b * e.batchSize()) + "..): " +
                         axisName(axis) + " = " + shortest(corner[axis]) + " is beyond what mode " +
                         std::string(modeName(e.mode)) + " holds when scaled to the view (" + shortest(in_frame) + ")",
                     ExitCode::kBadInput};
      }
  // The boxes are of kBoxPoints points; a batch of the mode is the union of batchSize() / kBoxPoints
  // of them (its min and max are its points' as well).
  const size_t per = e.batchSize() / kBoxPoints;
  std::vector<BatchFrame> frames((boxes.size() + per - 1) / per);
  parallelFor(frames.size(), 0, [&](size_t k, unsigned) {
    Box box = boxes[k * per];
    for (size_t j = k * per + 1; j < std::min(boxes.size(), (k + 1) * per); ++j) {
      box.min = glm::min(box.min, boxes[j].min);
      box.max = glm::max(box.max, boxes[j].max);
    }
    frames[k] = batchFrameOf(box, e.frame);
  });
  return appendBatches(e, frames);
}

Result<ModeEncoding> prepareEncoding(PrecisionMode mode, const PointSet& points, const Camera& camera,
                                     double tolerance_px) {
  ModeEncoding e = beginEncoding(mode, camera, tolerance_px);
  if (Status status = addPoints(e, points, 0); !status) return status.error();
  return e;
}

void encodePositions(const ModeEncoding& e, const PointSet& points, size_t first, size_t count, void* out,
                     size_t index_base, uint32_t plane) {
  assert(first + count <= points.size());
  modeInfo(e.mode).encode(e, points.positions.data() + first, count, out, index_base + first, plane);
}

std::vector<uint8_t> cameraUniform(const ModeEncoding& e, const Camera& camera) {
  return modeInfo(e.mode).uniform(e, camera);
}

std::vector<glm::mat4> batchMatrices(const ModeEncoding& e) {
  std::vector<glm::mat4> out(e.batches.size());
  for (size_t b = 0; b < e.batches.size(); ++b) out[b] = glm::mat4(e.batch_matrices[b]);
  return out;
}

}  // namespace dpoint
