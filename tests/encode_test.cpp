// Per-mode encodings (viewer/encode.h): what each precision mode sends to the GPU.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "viewer/encode.h"

namespace dpoint {
namespace {

TEST(Encode, modeNamesRoundTripAndBytesPerPointMatchDesign) {
  const uint32_t expected[] = {16, 28, 28, 28, 28, 16};  // DESIGN §4 plus 4 bytes of RGBA8
  int i = 0;
  for (PrecisionMode mode : kAllModes) {
    EXPECT_EQ(parseMode(modeName(mode)), mode);
    EXPECT_EQ(bytesPerPoint(mode), expected[i++]) << modeName(mode);
  }
  EXPECT_FALSE(parseMode("emulated").has_value());
}

// hi + lo carries d to 48 bits, and lo is the exact float remainder. Done over arrays because the
// bug this guards against (GCC 12 folding (double)(float)d back to d) appears only when the
// compiler vectorizes several splits together.
TEST(Encode, encodeRoundTripKeepsLowParts) {
  PointSet s;
  for (int i = 0; i < 257; ++i) s.positions.emplace_back(6.378e6 + 1e-3 * i, -0.7436450 + 1e-11 * i, 0.1318259 * i);
  std::vector<float> out(6 * s.size());
  encodePositions(PrecisionMode::kRte, s, {}, 0, s.size(), out.data());
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
  Camera camera;
  camera.eye = {-0.7436450, 0.1318259, 6.378e6 + 0.1};
  std::vector<uint8_t> rte = cameraUniform(PrecisionMode::kRte, camera);
  ASSERT_EQ(rte.size(), 96u);  // mat4, vec4 eye_hi, vec4 eye_lo (std140)
  float eye[8];
  std::memcpy(eye, rte.data() + 64, sizeof(eye));
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(eye[a], splitDouble(camera.eye[a]).hi);
    EXPECT_EQ(eye[4 + a], splitDouble(camera.eye[a]).lo);
    EXPECT_NE(eye[4 + a], 0.0f) << "axis " << a;
  }
}

TEST(Encode, nativeIsTheDoublesThemselves) {
  PointSet s;
  s.positions = {{1.0 / 3.0, -2e300, 6.378e6 + 1e-9}};
  double out[3];
  encodePositions(PrecisionMode::kNative, s, {}, 0, 1, out);
  EXPECT_EQ(glm::dvec3(out[0], out[1], out[2]), s.positions[0]);
}

TEST(Encode, batchOffsetsAreRelativeToTheirBatchCentre) {
  PointSet s;
  for (uint32_t i = 0; i < kBatchSize + 10; ++i) s.positions.emplace_back(1e8 + i * 1e-3, 0.0, i < kBatchSize ? 0.0 : 5.0);
  std::vector<glm::dvec3> origins = batchOrigins(PrecisionMode::kBatch, s);
  ASSERT_EQ(origins.size(), 2u);
  EXPECT_DOUBLE_EQ(origins[0].x, 1e8 + (kBatchSize - 1) * 0.5e-3);
  EXPECT_EQ(origins[1].z, 5.0);
  std::vector<float> out(3 * s.size());
  encodePositions(PrecisionMode::kBatch, s, origins, 0, s.size(), out.data());
  for (size_t i = 0; i < s.size(); ++i) {
    const glm::dvec3& origin = origins[i / kBatchSize];
    EXPECT_EQ(out[3 * i], static_cast<float>(s.positions[i].x - origin.x));
    EXPECT_LT(std::fabs(out[3 * i]), 3.0f);
  }
  EXPECT_TRUE(batchOrigins(PrecisionMode::kFp32, s).empty());
}

TEST(Encode, checkEncodableNamesThePointAndCoordinate) {
  PointSet s;
  s.positions = {{0, 0, 0}, {0, -4e38, 0}};
  for (PrecisionMode mode : {PrecisionMode::kFp32, PrecisionMode::kSplit, PrecisionMode::kRte, PrecisionMode::kDf64}) {
    Status status = checkEncodable(mode, s, {});
    ASSERT_FALSE(status.ok()) << modeName(mode);
    EXPECT_NE(status.error().message.find("point 1: y = -4e+38 is beyond float32 range"), std::string::npos) << status.error().message;
    EXPECT_NE(status.error().message.find("--mode native"), std::string::npos);
  }
  EXPECT_TRUE(checkEncodable(PrecisionMode::kNative, s, {}).ok());
  s.positions = {{3e38, 0, 0}, {-3e38, 0, 0}};  // batch: each within float, the offset from the centre too
  EXPECT_TRUE(checkEncodable(PrecisionMode::kBatch, s, batchOrigins(PrecisionMode::kBatch, s)).ok());
}

TEST(Encode, coloursRoundToNearestByteWithOpaqueAlphaAndWhiteWithoutColours) {
  EXPECT_EQ(encodeColor({0.0f, 0.5f, 1.0f}), 0xffff8000u);  // 127.5 rounds away from zero
  EXPECT_EQ(encodeColor({1.0f / 255.0f, 2.0f, -1.0f}), 0xff00ff01u);  // clamped to 0..1
  PointSet s;
  s.positions.resize(3);
  EXPECT_EQ(encodeColors(s), std::vector<uint32_t>(3, 0xffffffffu));
}

TEST(Encode, df64UniformSplitsEveryMatrixEntry) {
  Camera camera;
  camera.eye = {6.378e6 + 0.1, 1.0 / 3.0, 0.0};
  camera.projection[2][3] = -1.0;
  camera.projection[3][3] = 0.0;
  std::vector<uint8_t> bytes = cameraUniform(PrecisionMode::kDf64, camera);
  ASSERT_EQ(bytes.size(), 128u);
  float hi[16], lo[16];
  std::memcpy(hi, bytes.data(), 64);
  std::memcpy(lo, bytes.data() + 64, 64);
  glm::dmat4 mvp = camera.viewProjection();
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      EXPECT_EQ(hi[4 * c + r], splitDouble(mvp[c][r]).hi);
      EXPECT_EQ(lo[4 * c + r], splitDouble(mvp[c][r]).lo);
    }
  EXPECT_NE(lo[12], 0.0f) << "the translation's low part";
}

}  // namespace
}  // namespace dpoint
