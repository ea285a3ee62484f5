// GLB positions come back bit-exactly through dpoint (issue #24 item 5): POSITION plus the float32
// residuals _POSITION_LOW/_POSITION_LOW2 (converters/gltf_position.h), read whole and streamed;
// other readers' view (POSITION through the node transform) stays within float of the extent;
// what cannot be held exactly is counted, never hidden; malformed residuals are refused.
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "converters/gltf_position.h"
#include "converters/gltf_read.h"
#include "converters/gltf_write.h"
#include "gltf_test_support.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::expectReadError;
using test::TempDir;

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

void expectBitExact(const PointSet& expected, const PointSet& actual) {
  ASSERT_EQ(expected.size(), actual.size());
  for (size_t i = 0; i < expected.size(); ++i)
    for (int k = 0; k < 3; ++k)
      ASSERT_TRUE(sameBits(expected.positions[i][k], actual.positions[i][k]))
          << "point " << i << " axis " << k << ": " << expected.positions[i][k] << " read back as "
          << actual.positions[i][k];
}

class Collect : public GltfPointSink {
 public:
  Status begin(const GltfSummary&) override { return okStatus(); }
  Status points(PointSet& block) override {
    all.positions.insert(all.positions.end(), block.positions.begin(), block.positions.end());
    return okStatus();
  }
  PointSet all;
};

// Written, read whole and streamed: both bit-exact; returns the report.
GlbWriteReport expectRoundTripExact(const PointSet& set) {
  TempDir dir;
  GlbWriteReport report;
  EXPECT_TRUE(writeGlb(dir.file("s.glb"), set, &report));
  EXPECT_EQ(report.inexact_points, 0u);
  Result<PointSet> back = readGltf(dir.file("s.glb"));
  EXPECT_TRUE(back) << back.error().message;
  if (back) expectBitExact(set, *back);
  Collect sink;
  EXPECT_TRUE(streamGltf(dir.file("s.glb"), {}, sink));
  expectBitExact(set, sink.all);
  return report;
}

uint64_t splitmix(uint64_t& state) {
  uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
double unit(uint64_t& state) { return double(splitmix(state) >> 11) * 0x1p-53; }  // [0, 1), 53 bits

TEST(GltfExact, earthRadiusMillimetresRoundTripBitExactly) {
  PointSet set;
  for (int i = 0; i < 3000; ++i)
    set.positions.push_back({6378137.0 + 0.001 * (i % 1000), -6378137.0 + 0.001 * ((i * 37) % 1500),
                             0.001 * ((i * 11) % 2000)});
  expectRoundTripExact(set);
}

TEST(GltfExact, fullPrecisionDataNearZeroRoundTripsBitExactly) {
  uint64_t state = 1;
  PointSet set;
  for (int i = 0; i < 5000; ++i) set.positions.push_back({2 * unit(state) - 1, unit(state) * 1e-3, unit(state) - 0.5});
  expectRoundTripExact(set);
}

TEST(GltfExact, tinyAndHugeMagnitudesRoundTripThroughANodeScale) {
  uint64_t state = 2;
  PointSet set;
  for (int i = 0; i < 1000; ++i)
    set.positions.push_back({(2 * unit(state) - 1) * 1e-300, (1 + unit(state)) * 1e-300, unit(state) * 1e300});
  expectRoundTripExact(set);
}

TEST(GltfExact, mixedMagnitudesOnOneAxisRoundTripBitExactly) {
  uint64_t state = 3;
  PointSet set;
  for (int i = 0; i < 1000; ++i)
    set.positions.push_back({(2 * unit(state) - 1) * std::ldexp(1.0, i % 80 - 40), 6378137.0 + unit(state),
                             unit(state) * 1e-3 + 1e-9 * (i % 3)});
  expectRoundTripExact(set);
}

TEST(GltfExact, offsetsBeyondFloatRangeOnOneAxisAreCountedNotHidden) {
  PointSet set;
  set.positions = {{1e-300, 0, 0}, {1.0, 1, 1}, {0.5, 2, 2}};
  TempDir dir;
  GlbWriteReport report;
  ASSERT_TRUE(writeGlb(dir.file("s.glb"), set, &report));
  EXPECT_EQ(report.inexact_points, 1u);  // 1e-300 next to 1: 2^997 apart, beyond float's 2^-149..2^128
  Result<PointSet> back = readGltf(dir.file("s.glb"));
  ASSERT_TRUE(back);
  EXPECT_TRUE(sameBits(back->positions[1].x, 1.0));
  EXPECT_TRUE(sameBits(back->positions[2].x, 0.5));
  EXPECT_NEAR(back->positions[0].x, 1e-300, 1e-7);
}

TEST(GltfExact, otherReadersSeePositionThroughTheNodeWithinFloatOfExtent) {
  PointSet set;
  for (int i = 0; i < 1000; ++i) set.positions.push_back({6378137.0 + 0.001 * i, 0.25 * i, -3.0});
  TempDir dir;
  ASSERT_TRUE(writeGlb(dir.file("s.glb"), set));
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, dir.file("s.glb"))) << err;
  const tinygltf::Primitive& primitive = model.meshes[0].primitives[0];
  ASSERT_EQ(primitive.attributes.count(kGltfPositionLow), 1u);
  const tinygltf::Node& node = model.nodes[0];
  EXPECT_TRUE(node.scale.empty());  // a plain translation, as before the residuals
  const tinygltf::Accessor& accessor = model.accessors[size_t(primitive.attributes.at("POSITION"))];
  const tinygltf::BufferView& view = model.bufferViews[size_t(accessor.bufferView)];
  const float* hi = reinterpret_cast<const float*>(model.buffers[0].data.data() + view.byteOffset);
  const double extent[3] = {0.999, 249.75, 0.0};
  for (size_t i = 0; i < set.size(); ++i)
    for (int k = 0; k < 3; ++k)
      EXPECT_LE(std::fabs(node.translation[size_t(k)] + double(hi[3 * i + size_t(k)]) - set.positions[i][k]),
                extent[k] * 0x1p-24 + 1e-300)
          << i << " " << k;
}

// A one-point GLB whose attributes the test chooses (accessor 0: POSITION float VEC3).
std::string residualGltf(const std::string& attributes, const std::string& extra_accessors) {
  return R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":24,"uri":"data:application/octet-stream;base64,)" +
         test::base64(std::vector<unsigned char>(24, 0)) + R"("}],"bufferViews":[{"buffer":0,"byteLength":24}],
    "accessors":[{"bufferView":0,"componentType":5126,"count":1,"type":"VEC3","min":[0,0,0],"max":[0,0,0]})" +
         extra_accessors + R"(],"meshes":[{"primitives":[{"attributes":{"POSITION":0)" + attributes +
         R"(},"mode":0}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]})";
}

TEST(GltfExact, residualWithWrongTypeOrCountIsRefusedByName) {
  expectReadError(residualGltf(R"(,"_POSITION_LOW":1)", R"(,{"bufferView":0,"componentType":5126,"count":2,"type":"VEC3"})"),
                  {"/accessors/1", "_POSITION_LOW count 2 differs from POSITION count 1"});
  expectReadError(residualGltf(R"(,"_POSITION_LOW":1)", R"(,{"bufferView":0,"componentType":5126,"count":1,"type":"VEC2"})"),
                  {"/accessors/1", "_POSITION_LOW must be VEC3 of float"});
  expectReadError(residualGltf(R"(,"_POSITION_LOW2":1)", R"(,{"bufferView":0,"componentType":5126,"count":1,"type":"VEC3"})"),
                  {"_POSITION_LOW2: present without _POSITION_LOW"});
}

}  // namespace
}  // namespace dpoint
