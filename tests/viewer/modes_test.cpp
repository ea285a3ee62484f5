// The precision modes' table (viewer/modes.h): each row agrees with itself, with what its
// encoder and uniform builder write, and with the CLI text and measured orders built from it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <set>
#include <vector>

#include "viewer/encode.h"
#include "viewer/ortho_camera.h"
#include "viewer/modes.h"

namespace dpoint {
namespace {

TEST(Modes, rowsAreInEnumOrderAndNamesParseBack) {
  std::set<std::string_view> names;
  for (size_t i = 0; i < kModeCount; ++i) {
    const PrecisionMode mode = kAllModes[i];
    const ModeInfo& info = modeInfo(mode);
    EXPECT_EQ(info.mode, mode);
    EXPECT_EQ(modeIndex(mode), i);
    EXPECT_EQ(parseMode(info.name), mode) << info.name;
    EXPECT_FALSE(info.help.empty()) << info.name;
    EXPECT_EQ(info.help.find('\n'), std::string_view::npos) << info.name << ": help is one line";
    names.insert(info.name);
  }
  EXPECT_EQ(names.size(), kModeCount) << "names are unique";
  EXPECT_FALSE(parseMode("auto").has_value()) << "auto is a choice, not a mode";
  EXPECT_FALSE(parseMode("FP32").has_value());
}

TEST(Modes, layoutAccountsForEveryPositionByte) {
  for (PrecisionMode mode : kAllModes) {
    const ModeInfo& info = modeInfo(mode);
    const PositionLayout& layout = info.layout;
    EXPECT_EQ(layout.elements * layout.element_bytes, info.position_bytes) << info.name;
    const bool four = layout.element == PositionElement::kFloat32 || layout.element == PositionElement::kUint32;
    const uint32_t size = four ? 4 : 8;
    EXPECT_EQ(layout.element_bytes, size) << info.name;
    EXPECT_EQ(bytesPerPoint(mode), info.position_bytes + 4) << info.name;
  }
}

// The encoder writes exactly position_bytes per point: all of the last point's bytes are its own
// (some differ from the fill), and not one byte past them.
TEST(Modes, encoderWritesExactlyTheRowsBytesPerPoint) {
  PointSet s;
  for (int i = 0; i < 5; ++i) s.positions.push_back({0.1 + 0.01 * i, -0.2 + 0.03 * i, 0.3 - 0.02 * i});
  const Camera camera = orthoCamera({0.1, -0.2, 0.3}, 2.0);
  for (PrecisionMode mode : kAllModes) {
    const ModeInfo& info = modeInfo(mode);
    Result<ModeEncoding> e = prepareEncoding(mode, s, camera);
    ASSERT_TRUE(e.ok()) << info.name << ": " << e.error().message;
    constexpr uint8_t kFill = 0xa5;
    // A planar layout writes one plane at a time: element_bytes a point each.
    const size_t point_bytes = info.layout.planes == 1 ? info.position_bytes : info.layout.element_bytes;
    for (uint32_t plane = 0; plane < info.layout.planes; ++plane) {
      const size_t used = s.size() * point_bytes;
      std::vector<uint8_t> out(used + 64, kFill);
      encodePositions(*e, s, 0, s.size(), out.data(), 0, plane);
      EXPECT_TRUE(std::all_of(out.begin() + static_cast<std::ptrdiff_t>(used), out.end(),
                              [](uint8_t b) { return b == kFill; }))
          << info.name << " writes past " << point_bytes << " bytes a point";
      EXPECT_FALSE(std::all_of(out.begin() + static_cast<std::ptrdiff_t>(used - point_bytes),
                               out.begin() + static_cast<std::ptrdiff_t>(used), [](uint8_t b) { return b == kFill; }))
          << info.name << " leaves its last point unwritten";
    }
    EXPECT_EQ(positionBufferBytes(mode, 5), info.layout.planes == 1 ? 5 * info.position_bytes
                                                                    : info.layout.planes * 8 * info.layout.element_bytes)
        << info.name << ": planes start at 16-byte multiples";
  }
}

// The uniform blocks as shaders/render/project.glsl declares them (std140).
TEST(Modes, uniformSizesMatchTheShaderBlocks) {
  PointSet s;
  s.positions = {{1.0, 2.0, 3.0}};
  const Camera camera = orthoCamera({1.0, 2.0, 3.0}, 2.0);
  const size_t expected[] = {
      64,              // fp32: mat4 mvp
      64,              // split: mat4 mvp
      64 + 2 * 16,     // rte: mat4 projection·rotation, vec4 eye_hi, vec4 eye_lo
      2 * 64,          // df64: mat4 hi, mat4 lo
      128 + 32,        // native: dmat4 projection·rotation, dvec4 eye
      0,               // batch: matrices in a storage buffer
      0,               // adaptive: the same
  };
  static_assert(std::size(expected) == kModeCount);
  for (size_t i = 0; i < kModeCount; ++i) {
    Result<ModeEncoding> e = prepareEncoding(kAllModes[i], s, camera);
    ASSERT_TRUE(e.ok());
    EXPECT_EQ(cameraUniform(*e, camera).size(), expected[i]) << modeName(kAllModes[i]);
  }
}

TEST(Modes, shaderVariantsAndAttributesFitTheLayout) {
  for (PrecisionMode mode : kAllModes) {
    const ModeInfo& info = modeInfo(mode);
    const ModeShaders& shaders = info.shaders;
    EXPECT_TRUE(shaders.vertex.code && shaders.vertex.bytes % 4 == 0 && shaders.vertex.bytes > 0) << info.name;
    EXPECT_TRUE(shaders.splat.code && shaders.splat.bytes % 4 == 0 && shaders.splat.bytes > 0) << info.name;
    EXPECT_NE(shaders.vertex.code, shaders.splat.code) << info.name;
    // A mode without vertex attributes pulls its positions in both backends.
    if (shaders.attribute_count == 0) {
      EXPECT_EQ(shaders.vertex.code, shaders.vertex_pull.code) << info.name;
    }
    ASSERT_LE(shaders.attribute_count, 2u) << info.name;
    for (uint32_t a = 0; a < shaders.attribute_count; ++a) {
      EXPECT_NE(shaders.attributes[a].format, VK_FORMAT_UNDEFINED) << info.name;
      EXPECT_LT(shaders.attributes[a].offset, info.position_bytes) << info.name;
      EXPECT_EQ(shaders.attributes[a].offset % info.layout.element_bytes, 0u) << info.name;
    }
    // A mode whose attribute path needs double vertex input has the pull path to fall back on.
    if (info.attribute_needs_r64_vertex) {
      EXPECT_NE(shaders.vertex_pull.code, nullptr) << info.name;
    }
    if (info.needs_shader_float64) {
      EXPECT_EQ(info.layout.element, PositionElement::kFloat64) << info.name;
    }
    EXPECT_GE(info.chunk_multiple, 1u) << info.name;
    if (info.batch_points) {
      EXPECT_EQ(info.batch_points % info.chunk_multiple, 0u) << info.name;
    }
  }
}

// Every speed order holds every mode but split exactly once, and is the order measured (issue #25:
// viewer/modes.cpp names the runs).
TEST(Modes, speedOrdersHoldEveryModeButSplitOnce) {
  using M = PrecisionMode;
  const std::vector<M> gpu_compute = {M::kAdaptive, M::kBatch, M::kFp32, M::kRte, M::kNative, M::kDf64};
  const std::vector<M> gpu_raster = {M::kBatch, M::kAdaptive, M::kFp32, M::kNative, M::kRte, M::kDf64};
  const std::vector<M> cpu_compute = {M::kFp32, M::kNative, M::kBatch, M::kRte, M::kDf64, M::kAdaptive};
  const std::vector<M> cpu_raster = {M::kFp32, M::kNative, M::kRte, M::kDf64, M::kBatch, M::kAdaptive};
  for (DeviceClass device : {DeviceClass::kCpu, DeviceClass::kGpu})
    for (bool compute : {false, true}) {
      const std::span<const PrecisionMode> order = measuredSpeedOrder(device, compute);
      SCOPED_TRACE(std::string(deviceClassName(device)) + (compute ? " compute" : " raster"));
      EXPECT_EQ(order.size(), kModeCount - 1);
      for (PrecisionMode mode : kAllModes)
        EXPECT_EQ(std::count(order.begin(), order.end(), mode), mode == M::kSplit ? 0 : 1) << modeName(mode);
      const std::vector<M>& expected = device == DeviceClass::kCpu ? (compute ? cpu_compute : cpu_raster)
                                                                   : compute ? gpu_compute : gpu_raster;
      EXPECT_EQ(std::vector<M>(order.begin(), order.end()), expected);
    }
  EXPECT_EQ(deviceClassOf("cpu"), DeviceClass::kCpu);
  EXPECT_EQ(deviceClassOf("discrete-gpu"), DeviceClass::kGpu);
}

// The CLI text built from the table is the text `dpoint render --help` printed before the table.
// --mode auto for one picture orders the modes by predicted time to it (issue #38 item 3): on a
// GPU the host's encoding is nearly all of it, so a billion points put fp32 first and adaptive
// (whose frame is the fastest) last; with more frames the frame decides, as the speed order says.
// Every order holds the ranked modes once.
TEST(Modes, autoOrdersOnePictureByItsPredictedTime) {
  const std::span<const PrecisionMode> speed = measuredSpeedOrder(DeviceClass::kGpu, true);
  ASSERT_EQ(speed.front(), PrecisionMode::kAdaptive);
  const std::vector<PrecisionMode> picture = autoOrder(DeviceClass::kGpu, true, 1'000'000'000, 16, 1);
  EXPECT_EQ(picture.front(), PrecisionMode::kFp32);
  EXPECT_EQ(picture.back(), PrecisionMode::kAdaptive);
  std::vector<PrecisionMode> sorted_picture = picture, sorted_speed(speed.begin(), speed.end());
  std::sort(sorted_picture.begin(), sorted_picture.end());
  std::sort(sorted_speed.begin(), sorted_speed.end());
  EXPECT_EQ(sorted_picture, sorted_speed);
  for (size_t k = 1; k < picture.size(); ++k)
    EXPECT_LE(predictedPictureMs(picture[k - 1], DeviceClass::kGpu, true, 1'000'000'000, 16, 1),
              predictedPictureMs(picture[k], DeviceClass::kGpu, true, 1'000'000'000, 16, 1));
  const std::vector<PrecisionMode> frames = autoOrder(DeviceClass::kGpu, true, 1'000'000'000, 16, 50);
  EXPECT_TRUE(std::equal(frames.begin(), frames.end(), speed.begin(), speed.end()));
  // The prediction: the encoding shared by the cores, plus the frames.
  const double one = predictedPictureMs(PrecisionMode::kFp32, DeviceClass::kCpu, true, 1'000'000, 2, 1);
  EXPECT_GT(one, 0.0);
  EXPECT_NEAR(predictedPictureMs(PrecisionMode::kFp32, DeviceClass::kCpu, true, 2'000'000, 2, 1), 2.0 * one, 1e-9 * one);
  EXPECT_LT(predictedPictureMs(PrecisionMode::kFp32, DeviceClass::kCpu, true, 1'000'000, 4, 1), one);
  EXPECT_GT(predictedPictureMs(PrecisionMode::kFp32, DeviceClass::kCpu, true, 1'000'000, 2, 3), one);
}

TEST(Modes, modeOptionTextComesFromTheTable) {
  EXPECT_EQ(modeOptionNames(),
            (std::vector<std::string>{"auto", "fp32", "split", "rte", "df64", "native", "batch", "adaptive"}));
  EXPECT_EQ(modeOptionChoices(), "auto, fp32, split, rte, df64, native, batch or adaptive");
  EXPECT_EQ(modeOptionHelp(),
            "auto|fp32|split|rte|df64|native|batch|adaptive. auto: the mode quickest to the picture on this kind of\n"
            "device (measured rates; with --frames N, the fastest frame) whose\n"
            "predicted error bound is <= 0.1 px for this view; native when none is");
  EXPECT_EQ(modeListHelp(),
            "fp32 (float positions), split (the study's hi+lo, no better than fp32), rte (relative to eye), "
            "df64 (double-float arithmetic), native (fp64 shaders), batch (per-batch double origins), "
            "adaptive (per-batch tiers of 10 bits, as few as --tolerance allows)");
  EXPECT_EQ(modeName(kFallbackMode), "native");
}

}  // namespace
}  // namespace dpoint
