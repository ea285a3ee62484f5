// The precision modes' table (viewer/modes.h): per mode, the functions its row points at (the
// position encoder, the uniform builder, the per-point error bound) and the row itself. The
// arithmetic each function does is bit-exact work that tests pin: the encoders against the shaders'
// unpacking (shaders/render/project.glsl), the bounds against the probe's measured error.
#include "viewer/modes.h"

#include <array>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "viewer/bound_terms.h"
#include "viewer/camera.h"
#include "viewer/encode.h"
#include "viewer/precision.h"

#include "shaders/points_adaptive.vert.h"
#include "shaders/points_batch.vert.h"
#include "shaders/points_df64.vert.h"
#include "shaders/points_fp32.vert.h"
#include "shaders/points_native_attr.vert.h"
#include "shaders/points_native_pull.vert.h"
#include "shaders/points_rte.vert.h"
#include "shaders/points_split.vert.h"
#include "shaders/splat_adaptive.comp.h"
#include "shaders/splat_batch.comp.h"
#include "shaders/splat_df64.comp.h"
#include "shaders/splat_fp32.comp.h"
#include "shaders/splat_native.comp.h"
#include "shaders/splat_rte.comp.h"
#include "shaders/splat_split.comp.h"

namespace dpoint {
namespace {

using namespace bound;

#define DPOINT_SPIRV(words) Spirv{words, sizeof(words)}

template <typename Value>
void appendBytes(std::vector<uint8_t>& out, const Value& v) {
  size_t at = out.size();
  out.resize(at + sizeof(Value));
  std::memcpy(out.data() + at, &v, sizeof(Value));
}

// ---- encoders: positions as the shaders read them --------------------------------------------

void encodeFloats(const ModeEncoding&, const glm::dvec3* p, size_t count, void* out, size_t, uint32_t) {
  auto* f = static_cast<float*>(out);
  for (size_t i = 0; i < count; ++i)
    for (int a = 0; a < 3; ++a) f[3 * i + a] = static_cast<float>(p[i][a]);
}

void encodeFloatPairs(const ModeEncoding& e, const glm::dvec3* p, size_t count, void* out, size_t, uint32_t) {
  auto* f = static_cast<float*>(out);
  const SceneFrame& frame = e.frame;
  // Interleaved per point: hi.xyz then lo.xyz (one 24-byte vertex binding).
  for (size_t i = 0; i < count; ++i) {
    for (int a = 0; a < 3; ++a) {
      FloatPair pair = splitDouble(scaleBy(p[i][a], frame));
      f[6 * i + a] = pair.hi;
      f[6 * i + 3 + a] = pair.lo;
    }
  }
}

void encodeDoubles(const ModeEncoding& e, const glm::dvec3* p, size_t count, void* out, size_t, uint32_t) {
  const SceneFrame& frame = e.frame;
  if (frame.exponent == 0) {
    std::memcpy(out, p, count * sizeof(glm::dvec3));
  } else {
    auto* d = static_cast<double*>(out);
    for (size_t i = 0; i < count; ++i)
      for (int a = 0; a < 3; ++a) d[3 * i + a] = scaleBy(p[i][a], frame);
  }
}

void encodeBatchOffsets(const ModeEncoding& e, const glm::dvec3* p, size_t count, void* out, size_t first_index,
                        uint32_t) {
  const SceneFrame& frame = e.frame;
  auto* words = static_cast<uint64_t*>(out);
  for (size_t i = 0; i < count; ++i) {
    const BatchFrame& batch = e.batches[e.batchOf(first_index + i)];
    // p·scale − origin rounds once in double; the division by a power of two is exact.
    words[i] = packBatchOffset((scaleBy(p[i], frame) - batch.origin) / batch.extent);
  }
}

// One plane of adaptive mode's tier words: the point's 30-bit q per axis (viewer/encode.h), then the
// plane's 10 bits of each.
void encodeAdaptiveTier(const ModeEncoding& e, const glm::dvec3* p, size_t count, void* out, size_t first_index,
                        uint32_t plane) {
  const SceneFrame& frame = e.frame;
  auto* words = static_cast<uint32_t*>(out);
  for (size_t i = 0; i < count; ++i) {
    const BatchFrame& batch = e.batches[e.batchOf(first_index + i)];
    const glm::dvec3 t = (scaleBy(p[i], frame) - batch.origin) / batch.extent;  // one rounding, then exact
    const glm::uvec3 q(quantizeAdaptive(t.x), quantizeAdaptive(t.y), quantizeAdaptive(t.z));
    words[i] = adaptiveTierWord(q, plane);
  }
}

// ---- uniform blocks (std140, as shaders/render/project.glsl declares them) --------------------

std::vector<uint8_t> worldMatrixUniform(const ModeEncoding&, const Camera& camera) {
  std::vector<uint8_t> out;
  appendBytes(out, glm::mat4(camera.viewProjection()));
  return out;
}

std::vector<uint8_t> rteUniform(const ModeEncoding& e, const Camera&) {
  std::vector<uint8_t> out;
  const SceneFrame& frame = e.frame;
  // The translation is done in the shader against the eye's hi/lo parts, so the matrix
  // holds only projection · rotation and never sees a large number.
  appendBytes(out, glm::mat4(frame.projection_rotation));
  float eye[8] = {};  // vec4 eye_hi, vec4 eye_lo (std140)
  for (int a = 0; a < 3; ++a) {
    FloatPair pair = splitDouble(frame.eye[a]);
    eye[a] = pair.hi;
    eye[4 + a] = pair.lo;
  }
  appendBytes(out, eye);
  return out;
}

std::vector<uint8_t> df64Uniform(const ModeEncoding& e, const Camera&) {
  std::vector<uint8_t> out;
  const SceneFrame& frame = e.frame;
  glm::dmat4 translate(1.0);
  translate[3] = glm::dvec4(-frame.eye, 1.0);
  const glm::dmat4 mvp = frame.projection_rotation * translate;
  glm::mat4 hi(0.0f), lo(0.0f);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      FloatPair pair = splitDouble(mvp[c][r]);
      hi[c][r] = pair.hi;
      lo[c][r] = pair.lo;
    }
  appendBytes(out, hi);
  appendBytes(out, lo);
  return out;
}

std::vector<uint8_t> nativeUniform(const ModeEncoding& e, const Camera&) {
  std::vector<uint8_t> out;
  const SceneFrame& frame = e.frame;
  // dmat4 projection_rotation, dvec4 eye (std140): the shader subtracts the eye first.
  appendBytes(out, frame.projection_rotation);
  appendBytes(out, glm::dvec4(frame.eye, 0.0));
  return out;
}

// Batch mode's matrices go in a storage buffer (batchMatrices), one per batch: no uniform block.
std::vector<uint8_t> noUniform(const ModeEncoding&, const Camera&) { return {}; }

// ---- error bounds: each mode's arithmetic, step by step (notation in viewer/bound_terms.h) ------

template <class T>
inline Clip<T> fp32Error(const Setup& s, const Coords<T>& p, bool split) {
  Coords<T> dv;
  for (size_t a = 0; a < 3; ++a) {
    // split: hi + lo in float is within u·|p| of p, plus hi's and lo's flushes.
    dv[a] = split ? 1.01 * kU * absOf(p[a]) + 2.0 * kFloatMin : storedFloatError(p[a]);
  }
  return floatAffine(s.world_rows, p, dv);
}

// rte: d_hi = hi_p − hi_e (exact when Sterbenz applies: checked, not assumed), d_lo = lo_p − lo_e
// (u), their sum (u), and the hi/lo representations themselves (u·|lo| each).
Vec4 rteError(const Setup& s, const glm::dvec3& ps) {
  Coords<double> v, dv;
  for (size_t a = 0; a < 3; ++a) {
    const FloatPair pp = splitDouble(ps[static_cast<glm::length_t>(a)]);
    const FloatPair& pe = s.eye_split[a];
    const double dh = double(pp.hi) - double(pe.hi);
    double ddh = double(static_cast<float>(dh)) == dh ? 0.0 : kU * std::fabs(dh);
    if (dh != 0.0 && std::fabs(dh) < kFloatMin) ddh += kFloatMin;
    const double dl = double(pp.lo) - double(pe.lo);
    const double ddl = kU * std::fabs(dl) + 3.0 * kFloatMin;
    const double dsum = kU * (std::fabs(dh) + std::fabs(dl)) * (1.0 + kU) + kFloatMin;
    const double representation = kU * (std::fabs(double(pp.lo)) + std::fabs(double(pe.lo))) * (1.0 + kU) + 2.0 * kFloatMin;
    v[a] = dh + dl;
    dv[a] = ddh + ddl + dsum + representation;
  }
  return floatAffine(s.projection_rows, v, dv);
}

// df64: each hi/lo pair holds its value to u² (point and matrix: 2u² per product); dfMul drops
// lo·lo and rounds the cross terms and their sum (≤ 8u² of the product); each of the three dfAdds
// is off by ≤ 3u² of its operands (≤ 9u² of Σ|terms| in all); the final hi part rounds to u.
Vec4 df64Error(const Setup& s, const glm::dvec3& ps, const Vec4& clip) {
  for (int a = 0; a < 3; ++a)
    if (!(std::fabs(ps[a]) <= kDekkerMax)) return kUnbounded;
  Vec4 out;
  for (int r = 0; r < 4; ++r) {
    double terms = std::fabs(s.df64_mvp[3][r]);
    for (int c = 0; c < 3; ++c) terms += std::fabs(s.df64_mvp[c][r] * ps[c]);
    if (!(terms <= 0.5 * kFloatMax)) return kUnbounded;
    const size_t row = static_cast<size_t>(r);
    out[row] = (20.0 * kU2 + 4.0 * kUd) * terms + kU * std::fabs(clip[row]) * (1.0 + kU) + 32.0 * kFloatMin;
  }
  return out;
}

// native: p' − e' in double (ud), projection·rotation in double (γ_4 in ud), cast to float (u).
template <class T>
inline Clip<T> nativeError(const Setup& s, const Coords<T>& ps, const Clip<T>& clip) {
  Coords<T> d;
  for (size_t c = 0; c < 3; ++c) d[c] = ps[c] - s.frame.eye[static_cast<glm::length_t>(c)];
  const FloatRows& m = s.projection_rows;  // |entries| and constant rows, per camera
  Clip<T> out;
  for (size_t r = 0; r < 4; ++r) {
    if (m.constant[r]) {
      out[r] = broadcast<T>(m.constant_error[r]);
      continue;
    }
    T sum = broadcast<T>(m.magnitude[3][r]), input = broadcast<T>(0.0);
    for (size_t c = 0; c < 3; ++c) {
      const T dd = kUd * absOf(d[c]);
      sum = sum + m.magnitude[c][r] * (absOf(d[c]) + dd);
      input = input + m.magnitude[c][r] * dd;
    }
    const T in_double = input + (gamma(4, kUd) + 4.0 * kUd) * sum + 8.0 * DBL_MIN;
    out[r] = in_double + kU * (absOf(clip[r]) + in_double) + kFloatMin;
  }
  return out;
}

// batch: the offset's error in steps (batchOffsetError); the batch matrix, built in double (its
// translation's rounding is precomputed per batch), is applied in float.
Vec4 batchError(const ModeState& own, const glm::dvec3& ps, size_t index) {
  const size_t b = own.encoding.batchOf(index);
  const BatchFrame& frame = own.encoding.batches[b];
  const glm::dvec3 steps = (ps - frame.origin) / frame.extent * kBatchSteps;
  Coords<double> dv;
  for (size_t a = 0; a < 3; ++a) dv[a] = batchOffsetError(std::fabs(steps[static_cast<glm::length_t>(a)]));
  Vec4 out = floatAffine(own.batch_rows[b], coordsOf(steps), dv);
  for (size_t r = 0; r < 4; ++r) out[r] += own.batch_translation_error[b][r];
  return out;
}

// adaptive: as batch, with the offset error of the tiers the point's batch loads (adaptiveOffsetError).
Vec4 adaptiveError(const ModeState& own, const glm::dvec3& ps, size_t index) {
  const size_t b = own.encoding.batchOf(index);
  const uint32_t tiers = own.encoding.batch_plan[b];
  if (tiers == 0) return kUnbounded;  // never: a culled batch's box holds no visible point
  const BatchFrame& frame = own.encoding.batches[b];
  const glm::dvec3 steps = (ps - frame.origin) / frame.extent * kAdaptiveSteps;
  Coords<double> dv;
  for (size_t a = 0; a < 3; ++a) dv[a] = adaptiveOffsetError(tiers, std::fabs(steps[static_cast<glm::length_t>(a)]));
  Vec4 out = floatAffine(own.batch_rows[b], coordsOf(steps), dv);
  for (size_t r = 0; r < 4; ++r) out[r] += own.batch_translation_error[b][r];
  return out;
}

// df64's split constant times a matrix entry must stay finite (Dekker's split past 8e34).
bool df64MatrixOverflows(const Setup& s) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!(std::fabs(s.df64_mvp[c][r]) <= kDekkerMax)) return true;
  return false;
}

// The per-point bounds for bound::worstOf (one point at a time) and bound::worstOfPairs (one point
// or two, T = double or Lanes).
struct Fp32Bound {
  template <class T>
  static Clip<T> error(const Setup& s, const ModeState&, const PointIn<T>& in) {
    return fp32Error(s, in.p, false);
  }
};
struct SplitBound {
  template <class T>
  static Clip<T> error(const Setup& s, const ModeState&, const PointIn<T>& in) {
    return fp32Error(s, in.p, true);
  }
};
struct NativeBound {
  template <class T>
  static Clip<T> error(const Setup& s, const ModeState&, const PointIn<T>& in) {
    return nativeError(s, in.ps, in.clip);
  }
};
Vec4 rteBound(const Setup& s, const ModeState&, const glm::dvec3&, const Projected& q, size_t) {
  return rteError(s, q.ps);
}
Vec4 df64Bound(const Setup& s, const ModeState&, const glm::dvec3&, const Projected& q, size_t) {
  return df64Error(s, q.ps, q.clip);
}
Vec4 batchBound(const Setup&, const ModeState& own, const glm::dvec3&, const Projected& q, size_t i) {
  return batchError(own, q.ps, i);
}
Vec4 adaptiveBound(const Setup&, const ModeState& own, const glm::dvec3&, const Projected& q, size_t i) {
  return adaptiveError(own, q.ps, i);
}

// ---- the table -----------------------------------------------------------------------------------

constexpr PositionLayout kFloatXyz{PositionElement::kFloat32, 3, 4, "float x, y, z"};
constexpr PositionLayout kFloatPairs{PositionElement::kFloat32, 6, 4, "float hi.xyz then lo.xyz (hi = fl32(p), lo = fl32(p - hi))"};
constexpr PositionLayout kDoubleXyz{PositionElement::kFloat64, 3, 8, "double x, y, z"};
constexpr PositionLayout kBatchWord{PositionElement::kUint64, 1, 8,
                                    "21-bit offsets x, y, z from the batch's origin in one 64-bit word"};

constexpr PositionLayout kTierWords{PositionElement::kUint32, 3, 4,
                                    "three planes of tier words, 10 bits of x | y << 10 | z << 20 each", 3};

constexpr PositionAttribute kFloatAttribute{0, VK_FORMAT_R32G32B32_SFLOAT, 0};
constexpr PositionAttribute kLoAttribute{1, VK_FORMAT_R32G32B32_SFLOAT, 12};
constexpr PositionAttribute kNone{};

// Speed ranks, [DeviceClass][compute backend], from the orders measured with issue #25's encodings
// (bench/results/2026-11-25/h100/adaptive-final-2026-11-25.tsv, adaptive-modes-2026-11-25.tsv;
// with the pair merge bench/results/2026-11-26/h100/pair-merge/pair-merge.tsv; lavapipe:
// bench/results/2026-11-25/lavapipe/speed-adaptive-2026-11-25.tsv):
// - GPU compute (H100, 1920x1080, Morton order; ms at 16.7M Sierpinski / 16.6M Mandelbulb / 1e9
//   2D, after the pair merge): adaptive 0.1065 / 0.1261 / 4.45, batch 0.1102 / 0.1217 / 4.80,
//   fp32 0.137 / 0.137 / 5.36, rte 0.186 / 0.193, native 0.185 / 0.194 / 8.25, df64 0.346 / 0.345:
//   adaptive, batch, fp32, rte, native, df64 (adaptive faster on two sets of three, 2.5% over the
//   three; rte and native tied, as before).
// - GPU raster: bound by the point rasterizer (all within 0.2% at 16.7M: 19.18–19.22 ms, 19.88–20.93),
//   ties ranked as compute was before the pair merge (a compute splat's only): batch, adaptive, fp32,
//   native, rte, df64.
// - lavapipe compute (16.7M Sierpinski, Morton): fp32 653, native 705, batch 857, rte 968, df64 986,
//   adaptive 1046 ms. Raster: batch 4108 and adaptive 5359 ms, 2× the others (1794–2535 ms, within
//   this machine's run-to-run spread of each other), which keep their earlier order: fp32, native,
//   rte, df64, batch, adaptive.
// split has none: it computes exactly what fp32 does, at twice the bytes.
//                                {{cpu raster, cpu compute}, {gpu raster, gpu compute}}
constexpr ModeInfo kModes[] = {
    {PrecisionMode::kFp32, "fp32", "float positions", 12, kFloatXyz, false, false, false, false, 0, 1,
     {DPOINT_SPIRV(kPointsFp32Vert), {}, DPOINT_SPIRV(kSplatFp32Comp), {kFloatAttribute, kNone}, 1},
     encodeFloats, worldMatrixUniform, worstOfPairs<Fp32Bound>, nullptr, {{0, 0}, {2, 2}}},
    {PrecisionMode::kSplit, "split", "the study's hi+lo, no better than fp32", 24, kFloatPairs, false, false, false,
     false, 0, 1,
     {DPOINT_SPIRV(kPointsSplitVert), {}, DPOINT_SPIRV(kSplatSplitComp), {kFloatAttribute, kLoAttribute}, 2},
     encodeFloatPairs, worldMatrixUniform, worstOfPairs<SplitBound>, nullptr, {{kNoRank, kNoRank}, {kNoRank, kNoRank}}},
    {PrecisionMode::kRte, "rte", "relative to eye", 24, kFloatPairs, true, true, false, false, 0, 1,
     {DPOINT_SPIRV(kPointsRteVert), {}, DPOINT_SPIRV(kSplatRteComp), {kFloatAttribute, kLoAttribute}, 2},
     encodeFloatPairs, rteUniform, worstOf<rteBound>, nullptr, {{2, 3}, {4, 3}}},
    {PrecisionMode::kDf64, "df64", "double-float arithmetic", 24, kFloatPairs, true, true, false, false, 0, 1,
     {DPOINT_SPIRV(kPointsDf64Vert), {}, DPOINT_SPIRV(kSplatDf64Comp), {kFloatAttribute, kLoAttribute}, 2},
     encodeFloatPairs, df64Uniform, worstOf<df64Bound>, df64MatrixOverflows, {{3, 4}, {5, 5}}},
    {PrecisionMode::kNative, "native", "fp64 shaders", 24, kDoubleXyz, true, false, true, true, 0, 1,
     {DPOINT_SPIRV(kPointsNativeAttrVert), DPOINT_SPIRV(kPointsNativePullVert), DPOINT_SPIRV(kSplatNativeComp),
      {{0, VK_FORMAT_R64G64B64_SFLOAT, 0}, kNone}, 1},
     encodeDoubles, nativeUniform, worstOfPairs<NativeBound>, nullptr, {{1, 1}, {3, 4}}},
    // The compute splat reads points in pairs that must share a batch: chunks start at even points.
    {PrecisionMode::kBatch, "batch", "per-batch double origins", 8, kBatchWord, true, false, false, false, kBatchSize, 2,
     {DPOINT_SPIRV(kPointsBatchVert), {}, DPOINT_SPIRV(kSplatBatchComp), {{0, VK_FORMAT_R32G32_UINT, 0}, kNone}, 1},
     encodeBatchOffsets, noUniform, worstOf<batchBound>, nullptr, {{4, 2}, {0, 1}}, kBatchSteps},
    // Pulls its tier words in both backends (no attributes); chunks hold whole batches, so each
    // 1024-point workgroup of the compute splat lies in one batch (a thread loads pairs of points,
    // 8 bytes a tier).
    {PrecisionMode::kAdaptive, "adaptive", "per-batch tiers of 10 bits, as few as --tolerance allows", 12,
     kTierWords, true, false, false, false, kAdaptiveBatchSize, kAdaptiveBatchSize,
     {DPOINT_SPIRV(kPointsAdaptiveVert), DPOINT_SPIRV(kPointsAdaptiveVert), DPOINT_SPIRV(kSplatAdaptiveComp),
      {kNone, kNone}, 0},
     encodeAdaptiveTier, noUniform, worstOf<adaptiveBound>, nullptr, {{5, 5}, {1, 0}}, kAdaptiveSteps, kAdaptiveTiers},
};
static_assert(std::size(kModes) == kModeCount);

#undef DPOINT_SPIRV

}  // namespace

const ModeInfo& modeInfo(PrecisionMode mode) {
  const ModeInfo& info = kModes[modeIndex(mode)];
  assert(info.mode == mode);
  return info;
}

std::optional<PrecisionMode> parseMode(std::string_view name) {
  for (const ModeInfo& info : kModes)
    if (info.name == name) return info.mode;
  return std::nullopt;
}

std::string_view deviceClassName(DeviceClass device_class) {
  return device_class == DeviceClass::kCpu ? "lavapipe (CPU)" : "GPU (measured on an NVIDIA H100)";
}

// bench/results/2026-11-28/mode_rates.md. Host: the one-pass read, encoding and upload of 1e9 points
// on the device tool's H200 (16 cores: the seconds x 16 / 1e9; the read is the same for every mode).
// Frames: bench/scripts/mode_rates.sh, lavapipe on this 2-core machine and the H200 (its raster
// frame is the same for every mode: the point rate of its rasteriser).
// Per mode: host core-ns a point; frame ns a point {{cpu raster, cpu compute}, {gpu raster, gpu compute}}.
constexpr ModeCosts kModeCosts[] = {
    /* fp32 */ {85.0, {{146.69, 24.90}, {1.1397, 0.0076}}},
    /* split */ {97.6, {{133.62, 39.50}, {1.1397, 0.0094}}},
    /* rte */ {95.0, {{145.55, 39.00}, {1.1397, 0.0093}}},
    /* df64 */ {95.2, {{153.07, 65.78}, {1.1397, 0.0203}}},
    /* native */ {87.4, {{137.82, 32.07}, {1.1397, 0.0093}}},
    /* batch */ {101.8, {{237.70, 37.11}, {1.1397, 0.0062}}},
    /* adaptive */ {172.3, {{295.73, 50.11}, {1.1397, 0.0061}}},
};
static_assert(std::size(kModeCosts) == kModeCount);

const ModeCosts& modeCosts(PrecisionMode mode) { return kModeCosts[modeIndex(mode)]; }

double predictedPictureMs(PrecisionMode mode, DeviceClass device_class, bool compute_backend, uint64_t points,
                          unsigned threads, uint32_t frames) {
  const ModeCosts& c = modeCosts(mode);
  const double n = static_cast<double>(points);
  const double host = n * c.host_core_ns / std::max(1u, threads);
  const double frame = n * c.frame_ns[static_cast<size_t>(device_class)][compute_backend ? 1 : 0];
  return (host + frame * std::max(1u, frames)) * 1e-6;
}

std::vector<PrecisionMode> autoOrder(DeviceClass device_class, bool compute_backend, uint64_t points, unsigned threads,
                                     uint32_t frames) {
  const std::span<const PrecisionMode> speed = measuredSpeedOrder(device_class, compute_backend);
  std::vector<PrecisionMode> order(speed.begin(), speed.end());
  if (frames > 1) return order;
  std::stable_sort(order.begin(), order.end(), [&](PrecisionMode a, PrecisionMode b) {
    return predictedPictureMs(a, device_class, compute_backend, points, threads, 1) <
           predictedPictureMs(b, device_class, compute_backend, points, threads, 1);
  });
  return order;
}

std::span<const PrecisionMode> measuredSpeedOrder(DeviceClass device_class, bool compute_backend) {
  using Order = std::vector<PrecisionMode>;
  static const std::array<std::array<Order, 2>, kDeviceClassCount> kOrders = [] {
    std::array<std::array<Order, 2>, kDeviceClassCount> orders;
    for (size_t d = 0; d < kDeviceClassCount; ++d)
      for (size_t b = 0; b < 2; ++b) {
        for (int rank = 0; rank < static_cast<int>(kModeCount); ++rank)
          for (const ModeInfo& info : kModes)
            if (info.speed_rank[d][b] == rank) orders[d][b].push_back(info.mode);
      }
    return orders;
  }();
  return kOrders[static_cast<size_t>(device_class)][compute_backend ? 1 : 0];
}

std::vector<std::string> modeOptionNames() {
  std::vector<std::string> names{"auto"};
  for (const ModeInfo& info : kModes) names.emplace_back(info.name);
  return names;
}

std::string modeOptionChoices() {
  std::string text = "auto";
  for (size_t i = 0; i < kModeCount; ++i) {
    text.append(i + 1 < kModeCount ? ", " : " or ");
    text.append(kModes[i].name);
  }
  return text;
}

std::string modeOptionHelp() {
  std::string text = "auto";
  for (const ModeInfo& info : kModes) text.append("|").append(info.name);
  char bound[32];
  std::snprintf(bound, sizeof bound, "%g", kAutoBoundPx);
  text.append(". auto: the mode quickest to the picture on this kind of\ndevice (measured rates; with --frames N, the fastest frame) whose\npredicted error bound is <= ");
  text.append(bound).append(" px for this view; ").append(modeName(kFallbackMode)).append(" when none is");
  return text;
}

std::string modeListHelp() {
  std::string text;
  for (const ModeInfo& info : kModes) {
    if (!text.empty()) text.append(", ");
    text.append(info.name).append(" (").append(info.help).append(")");
  }
  return text;
}

}  // namespace dpoint
