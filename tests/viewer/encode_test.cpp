// Per-mode encodings (viewer/encode.h): what each precision mode sends to the GPU.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "viewer/encode.h"
#include "viewer/ortho_camera.h"

namespace dpoint {
namespace {

TEST(Encode, modeNamesRoundTripAndBytesPerPointMatchDesign) {
  // DESIGN §4 plus 4 bytes of RGBA8, but batch: 3×21-bit integer offsets in 8 bytes (issue #11),
  // and adaptive: three 4-byte tiers of 3×10 bits, of which a frame loads 1 to 3 (issue #25).
  const uint32_t expected[] = {16, 28, 28, 28, 28, 12, 16};
  int i = 0;
  for (PrecisionMode mode : kAllModes) {
    EXPECT_EQ(parseMode(modeName(mode)), mode);
    EXPECT_EQ(bytesPerPoint(mode), expected[i++]) << modeName(mode);
  }
  EXPECT_FALSE(parseMode("emulated").has_value());
}

ModeEncoding encoding(PrecisionMode mode, const PointSet& s, const Camera& camera) {
  Result<ModeEncoding> e = prepareEncoding(mode, s, camera);
  EXPECT_TRUE(e.ok()) << modeName(mode) << ": " << e.error().message;
  return e.ok() ? *e : ModeEncoding{};
}

// hi + lo carries d to 48 bits, and lo is the exact float remainder. Done over arrays because the
// bug this guards against (GCC 12 folding (double)(float)d back to d) appears only when the
// compiler vectorizes several splits together. A view 2 units wide keeps the scene frame at 2^0.
TEST(Encode, encodeRoundTripKeepsLowParts) {
  PointSet s;
  for (int i = 0; i < 257; ++i) s.positions.emplace_back(6.378e6 + 1e-3 * i, -0.7436450 + 1e-11 * i, 0.1318259 * i);
  Camera camera = orthoCamera({-0.7436450, 0.1318259, 6.378e6 + 0.1}, 1.5);
  ModeEncoding rte = encoding(PrecisionMode::kRte, s, camera);
  ASSERT_EQ(rte.frame.exponent, 0);
  std::vector<float> out(6 * s.size());
  encodePositions(rte, s, 0, s.size(), out.data());
  size_t nonzero_lo = 0;
  for (size_t i = 0; i < s.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      const double d = s.positions[i][a];
      const float hi = out[6 * i + a], lo = out[6 * i + 3 + a];
      EXPECT_EQ(hi, static_cast<float>(d));
      EXPECT_EQ(lo, static_cast<float>(d - static_cast<double>(static_cast<float>(d))));
      EXPECT_LE(std::fabs(static_cast<double>(hi) + static_cast<double>(lo) - d), std::fabs(d) * 0x1p-47);
      nonzero_lo += lo != 0.0f;
    }
  }
  EXPECT_GT(nonzero_lo, s.size() * 2);
  std::vector<uint8_t> uniform = cameraUniform(rte, camera);
  ASSERT_EQ(uniform.size(), 96u);  // mat4, vec4 eye_hi, vec4 eye_lo (std140)
  float eye[8];
  std::memcpy(eye, uniform.data() + 64, sizeof(eye));
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(eye[a], splitDouble(camera.eye[a]).hi);
    EXPECT_EQ(eye[4 + a], splitDouble(camera.eye[a]).lo);
  }
  EXPECT_NE(eye[4], 0.0f);
}

// The scene frame scales by a power of two so the view is 1 to 2 units wide: exact, and the same
// exponent for the positions, the eye and (inverted) the matrix.
TEST(Encode, sceneFrameScalesByAPowerOfTwoToTheViewSize) {
  for (double width : {1e-40, 1e-13, 1.0, 3e5, 1e30}) {
    Camera camera = orthoCamera({1e-30, 2e-30, 0.0}, width);
    SceneFrame frame = sceneFrame(PrecisionMode::kNative, camera);
    EXPECT_EQ(frame.scale, std::ldexp(1.0, frame.exponent));
    EXPECT_GE(width * frame.scale, 1.0) << width;
    EXPECT_LT(width * frame.scale, 2.0) << width;
    EXPECT_EQ(frame.eye, camera.eye * frame.scale);
    EXPECT_DOUBLE_EQ(frame.projection_rotation[0][0], 2.0 / (width * frame.scale));
    EXPECT_EQ(sceneFrame(PrecisionMode::kFp32, camera).exponent, 0) << "fp32 stays absolute";
    EXPECT_EQ(sceneFrame(PrecisionMode::kSplit, camera).exponent, 0) << "split stays absolute";
  }
}

TEST(Encode, nativeIsTheDoublesThemselvesInTheSceneFrame) {
  PointSet s;
  s.positions = {{1.0 / 3.0, -2e300, 6.378e6 + 1e-9}};
  Camera camera = orthoCamera({0.0, 0.0, 0.0}, 1.0);
  double out[3];
  encodePositions(encoding(PrecisionMode::kNative, s, camera), s, 0, 1, out);
  EXPECT_EQ(glm::dvec3(out[0], out[1], out[2]), s.positions[0]);
  Camera tiny = orthoCamera({0.0, 0.0, 0.0}, 1e-40);
  Result<ModeEncoding> overflow = prepareEncoding(PrecisionMode::kNative, s, tiny);
  ASSERT_FALSE(overflow.ok()) << "2e300 is 2e340 views of 1e-40 from the origin";
  EXPECT_NE(overflow.error().message.find("point 0: y = -2e+300 overflows double"), std::string::npos)
      << overflow.error().message;
  s.positions = {{1e-40 / 3.0, -2e-40, 0.0}};
  ModeEncoding e = encoding(PrecisionMode::kNative, s, tiny);
  encodePositions(e, s, 0, 1, out);
  EXPECT_EQ(out[0], std::ldexp(1e-40 / 3.0, e.frame.exponent));
  EXPECT_EQ(out[1], std::ldexp(-2e-40, e.frame.exponent));
  std::vector<uint8_t> uniform = cameraUniform(e, tiny);
  ASSERT_EQ(uniform.size(), 160u);  // dmat4 projection_rotation, dvec4 eye (std140)
}

TEST(Encode, batchOffsetsAreNormalizedToTheirBatchBox) {
  PointSet s;
  for (uint32_t i = 0; i < kBatchSize + 10; ++i) s.positions.emplace_back(1e8 + i * 1e-3, 0.0, i < kBatchSize ? 0.0 : 5.0);
  Camera camera = orthoCamera({1e8, 0.0, 0.0}, 1.0);
  ModeEncoding e = encoding(PrecisionMode::kBatch, s, camera);
  ASSERT_EQ(e.batches.size(), 2u);
  EXPECT_DOUBLE_EQ(e.batches[0].origin.x, 1e8 + (kBatchSize - 1) * 0.5e-3);
  EXPECT_EQ(e.batches[1].origin.z, 5.0);
  EXPECT_EQ(e.batches[0].extent, 4.0) << "half of 4.095 m, up to a power of two";
  EXPECT_EQ(e.batches[1].extent, 0.0078125) << "half of 9 mm, up to a power of two";
  std::vector<uint64_t> out(s.size());
  encodePositions(e, s, 0, s.size(), out.data());
  for (size_t i = 0; i < s.size(); ++i) {
    const BatchFrame& batch = e.batches[i / kBatchSize];
    const glm::ivec3 q = unpackBatchOffset(out[i]);
    const double t = (s.positions[i].x - batch.origin.x) / batch.extent;
    EXPECT_LE(std::fabs(q.x - t * kBatchSteps), 0.5) << i << ": within half a step";
    EXPECT_EQ(q.y, 0);
    EXPECT_EQ(q.z, 0);
  }
  EXPECT_EQ(unpackBatchOffset(out[kBatchSize]).z, 0) << "the second batch's z is its origin";
  ASSERT_EQ(e.batch_matrices.size(), 2u);
  const glm::dmat4& m = e.batch_matrices[1];
  EXPECT_EQ(m[0][0], camera.projection[0][0] * e.batches[1].extent / kBatchSteps)
      << "the extent and the step are folded into the matrix";
}

// The encoders round without libm calls; they must round as lround (colours) and nearbyint
// (batch offsets) do, at and around every tie.
TEST(Encode, colourAndOffsetRoundingMatchLroundAndNearbyint) {
  for (int k = 0; k <= 256; ++k) {
    float v = std::min(1.0f, (static_cast<float>(k) - 0.5f) / 255.0f);
    for (int step = 0; step < 64 && v >= 0.0f; ++step, v = std::nextafter(v, 0.0f)) {
      for (float c : {v, std::nextafter(v, 2.0f)}) {
        const uint32_t expected = 0xff000000u | static_cast<uint32_t>(std::lround(std::min(c, 1.0f) * 255.0f));
        EXPECT_EQ(encodeColor(glm::vec3(c, 0.0f, 0.0f)) & 0xff0000ffu, expected) << c;
      }
    }
  }
  const double step = 1.0 / kBatchSteps;
  for (double t : {0.5 * step, 1.5 * step, 2.5 * step, -0.5 * step, -1.5 * step, 0.49999999999 * step,
                   (1 << 19) * step + 0.5 * step, -0.75 + 0.5 * step, 0.999 + 0.5 * step, 0.3, -0.7}) {
    const int expected = static_cast<int>(std::nearbyint(t * kBatchSteps));
    EXPECT_EQ(unpackBatchOffset(packBatchOffset({t, -t, t})), glm::ivec3(expected, -expected, expected)) << t;
  }
}

// shaders/render/project.glsl turns a 21-bit field into a float without an int-to-float conversion: the
// field with its sign bit flipped, placed in the significand of 1.5·2^23, less 13631488. The same
// float arithmetic here gives exactly float(q) for every field the encoder writes.
TEST(Encode, batchOffsetFieldsBecomeExactFloatsWithoutAConversion) {
  for (int q = -(1 << 20); q < (1 << 20); ++q) {
    const uint32_t field = static_cast<uint32_t>(q) & 0x1FFFFFu;
    const uint32_t bits = 0x4B400000u | (field ^ 0x100000u);
    float biased;
    std::memcpy(&biased, &bits, sizeof biased);
    const float value = biased - 13631488.0f;
    if (value != static_cast<float>(q)) FAIL() << "field of " << q << " gives " << value;
  }
}

// The 21-bit fields hold every step from −2^20 to 2^20 − 1 and round half to even; t = 1 (the box's
// edge, where the extent is exactly the largest offset) clamps one step short.
TEST(Encode, batchOffsetsPackThreeSignedTwentyOneBitIntegers) {
  const double step = 1.0 / kBatchSteps;
  struct Case {
    glm::dvec3 t;
    glm::ivec3 q;
  } cases[] = {
      {{0.0, 0.0, 0.0}, {0, 0, 0}},
      {{-1.0, 1.0, -0.0}, {-(1 << 20), (1 << 20) - 1, 0}},
      {{step, -step, 0.5}, {1, -1, 1 << 19}},
      {{2.5 * step, -2.5 * step, 3.5 * step}, {2, -2, 4}},
      {{1.0 - step, -1.0 + step, 0.49 * step}, {(1 << 20) - 1, -(1 << 20) + 1, 0}},
  };
  for (const Case& c : cases) {
    const uint64_t word = packBatchOffset(c.t);
    EXPECT_EQ(unpackBatchOffset(word), c.q) << c.t.x << " " << c.t.y << " " << c.t.z;
    EXPECT_EQ(word >> 63, 0u) << "bit 63 stays clear";
  }
  // Fields do not bleed into each other: the all-ones field next to zeros.
  EXPECT_EQ(packBatchOffset({-step, 0.0, 0.0}), (uint64_t{1} << 21) - 1);
  EXPECT_EQ(packBatchOffset({0.0, -step, 0.0}), ((uint64_t{1} << 21) - 1) << 21);
  EXPECT_EQ(packBatchOffset({0.0, 0.0, -step}), ((uint64_t{1} << 21) - 1) << 42);
}

TEST(Encode, prepareEncodingNamesThePointAndCoordinateBeyondFloat) {
  PointSet s;
  s.positions = {{0, 0, 0}, {0, -4e38, 0}};
  Camera camera = orthoCamera({0.0, 0.0, 0.0}, 1.0);
  for (PrecisionMode mode : {PrecisionMode::kFp32, PrecisionMode::kSplit, PrecisionMode::kRte, PrecisionMode::kDf64}) {
    Result<ModeEncoding> e = prepareEncoding(mode, s, camera);
    ASSERT_FALSE(e.ok()) << modeName(mode);
    EXPECT_NE(e.error().message.find("point 1: y = -4e+38"), std::string::npos) << e.error().message;
    EXPECT_NE(e.error().message.find("beyond float32 range"), std::string::npos) << e.error().message;
    EXPECT_NE(e.error().message.find("--mode native"), std::string::npos);
  }
  EXPECT_TRUE(prepareEncoding(PrecisionMode::kNative, s, camera).ok());
  // In a view as wide as the set, the scene frame brings rte and df64 back into range; batch's
  // normalized offsets never leave it.
  Camera wide = orthoCamera({0.0, -2e38, 0.0}, 8e38);
  for (PrecisionMode mode : {PrecisionMode::kRte, PrecisionMode::kDf64, PrecisionMode::kBatch})
    EXPECT_TRUE(prepareEncoding(mode, s, wide).ok()) << modeName(mode);
  EXPECT_FALSE(prepareEncoding(PrecisionMode::kFp32, s, wide).ok());
}

// encodeColors converts the channels a block at a time as one flat array: every channel of every
// point rounds as lround, across block edges, from any first point.
TEST(Encode, encodeColorsOfManyPointsRoundEachChannelAsLround) {
  std::vector<float> values = {-1.0f, -0.0f, 0.0f, 2.0f, 1.0f, 0.5f};
  for (int k = 0; k <= 256; ++k) {
    float v = std::min(1.0f, (static_cast<float>(k) - 0.5f) / 255.0f);
    for (int step = 0; step < 4 && v >= 0.0f; ++step, v = std::nextafter(v, 0.0f))
      values.insert(values.end(), {v, std::nextafter(v, 2.0f)});
  }
  std::mt19937 random(5);
  std::uniform_real_distribution<float> unit(-0.1f, 1.1f);
  while (values.size() < 3 * 2500) values.push_back(unit(random));
  PointSet s;
  for (size_t i = 0; i + 3 <= values.size(); i += 3) {
    s.positions.emplace_back(0.0);
    s.colors.emplace_back(values[i + 2], values[i], values[i + 1]);  // each value in each channel somewhere
    s.positions.emplace_back(0.0);
    s.colors.emplace_back(values[i + 1], values[i + 2], values[i]);
  }
  const auto byte = [](float c) { return static_cast<uint32_t>(std::lround(std::clamp(c, 0.0f, 1.0f) * 255.0f)); };
  for (size_t first : {size_t{0}, size_t{7}}) {
    std::vector<uint32_t> out(s.size() - first);
    encodeColors(s, first, out.size(), out.data());
    for (size_t i = 0; i < out.size(); ++i) {
      const glm::vec3& c = s.colors[first + i];
      ASSERT_EQ(out[i], 0xff000000u | byte(c.r) | byte(c.g) << 8 | byte(c.b) << 16) << first + i;
    }
  }
}

TEST(Encode, coloursRoundToNearestByteWithOpaqueAlphaAndWhiteWithoutColours) {
  EXPECT_EQ(encodeColor({0.0f, 0.5f, 1.0f}), 0xffff8000u);  // 127.5 rounds away from zero
  EXPECT_EQ(encodeColor({1.0f / 255.0f, 2.0f, -1.0f}), 0xff00ff01u);  // clamped to 0..1
  PointSet s;
  s.positions.resize(3);
  EXPECT_EQ(encodeColors(s), std::vector<uint32_t>(3, 0xffffffffu));
}

TEST(Encode, df64UniformSplitsEveryMatrixEntry) {
  Camera camera = orthoCamera({6.378e6 + 0.1, 1.0 / 3.0, 0.0}, 1.5);
  ModeEncoding e = encoding(PrecisionMode::kDf64, PointSet{}, camera);
  std::vector<uint8_t> bytes = cameraUniform(e, camera);
  ASSERT_EQ(bytes.size(), 128u);
  float hi[16], lo[16];
  std::memcpy(hi, bytes.data(), 64);
  std::memcpy(lo, bytes.data() + 64, 64);
  glm::dmat4 translate(1.0);
  translate[3] = glm::dvec4(-e.frame.eye, 1.0);
  const glm::dmat4 mvp = e.frame.projection_rotation * translate;  // in the scene frame
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      EXPECT_EQ(hi[4 * c + r], splitDouble(mvp[c][r]).hi);
      EXPECT_EQ(lo[4 * c + r], splitDouble(mvp[c][r]).lo);
    }
  EXPECT_NE(lo[12], 0.0f) << "the translation's low part";
}

}  // namespace
}  // namespace dpoint
