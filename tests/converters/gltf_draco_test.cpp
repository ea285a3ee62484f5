// KHR_draco_mesh_compression: glTF files whose primitives are encoded by libdraco itself, decoded
// back in world space, and broken ones (truncated view, wrong attribute id, counts and types that
// do not match the Draco data) refused with a message naming the primitive and the field.
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <string>
#include <tuple>
#include <vector>

#include "converters/gltf_read.h"
#include "gltf_test_support.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::base64;
using test::expectReadError;
using test::readText;
using test::TempDir;

constexpr const char* kDracoPointer = "/meshes/0/primitives/0/extensions/KHR_draco_mesh_compression";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// `from` replaced after the first `anchor`: edits inside the extension, not the primitive's own
// attributes, which come first and read alike.
std::string replacedAfter(std::string text, const std::string& anchor, const std::string& from, const std::string& to) {
  const size_t base = text.find(anchor);
  EXPECT_NE(base, std::string::npos) << anchor;
  const size_t at = base == std::string::npos ? base : text.find(from, base);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}
constexpr const char* kExtensionStart = R"("KHR_draco_mesh_compression": {)";

// A tetrahedron: 4 points, 4 faces, unorm8 RGBA colours.
const float kPositions[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 2, 0}, {0, 0, 3}};
const uint8_t kColours[4][4] = {{255, 0, 0, 255}, {0, 255, 0, 255}, {0, 0, 255, 255}, {51, 102, 204, 255}};
const uint32_t kFaces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};

struct Encoded {
  std::vector<unsigned char> bytes;
  uint32_t position_id = 0, colour_id = 0;
};

// Encodes the tetrahedron with libdraco. position_bits 0: lossless floats, sequential connectivity
// (points keep their order); else quantized positions and edgebreaker, as glTF tools write them.
Encoded encodeTetrahedron(int position_bits) {
  draco::Mesh mesh;
  mesh.set_num_points(4);
  draco::GeometryAttribute position;
  position.Init(draco::GeometryAttribute::POSITION, nullptr, 3, draco::DT_FLOAT32, false, 12, 0);
  const int position_att = mesh.AddAttribute(position, true, 4);
  draco::GeometryAttribute colour;
  colour.Init(draco::GeometryAttribute::COLOR, nullptr, 4, draco::DT_UINT8, true, 4, 0);
  const int colour_att = mesh.AddAttribute(colour, true, 4);
  for (uint32_t i = 0; i < 4; ++i) {
    mesh.attribute(position_att)->SetAttributeValue(draco::AttributeValueIndex(i), kPositions[i]);
    mesh.attribute(colour_att)->SetAttributeValue(draco::AttributeValueIndex(i), kColours[i]);
  }
  for (const auto& f : kFaces)
    mesh.AddFace({draco::PointIndex(f[0]), draco::PointIndex(f[1]), draco::PointIndex(f[2])});
  draco::Encoder encoder;
  if (position_bits > 0) {
    encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, position_bits);
    encoder.SetEncodingMethod(draco::MESH_EDGEBREAKER_ENCODING);
  } else {
    encoder.SetEncodingMethod(draco::MESH_SEQUENTIAL_ENCODING);
  }
  draco::EncoderBuffer out;
  const draco::Status status = encoder.EncodeMeshToBuffer(mesh, &out);
  EXPECT_TRUE(status.ok()) << status.error_msg_string();
  Encoded e;
  e.bytes.assign(out.data(), out.data() + out.size());
  e.position_id = mesh.attribute(position_att)->unique_id();
  e.colour_id = mesh.attribute(colour_att)->unique_id();
  return e;
}

// Draco-only data (no fallback): accessors without bufferView, as gltf-transform writes them.
// The node is far from the origin so the world transform is done in double.
std::string dracoGltf(const Encoded& e) {
  const std::string length = std::to_string(e.bytes.size());
  return R"({
  "asset": {"version": "2.0"},
  "extensionsUsed": ["KHR_draco_mesh_compression"],
  "extensionsRequired": ["KHR_draco_mesh_compression"],
  "nodes": [{"mesh": 0, "translation": [6378000, 0, 0.5]}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "COLOR_0": 1}, "indices": 2, "mode": 4,
    "extensions": {"KHR_draco_mesh_compression": {"bufferView": 0,
      "attributes": {"POSITION": )" + std::to_string(e.position_id) + R"(, "COLOR_0": )" + std::to_string(e.colour_id) + R"(}}}}]}],
  "accessors": [
    {"componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 2, 3]},
    {"componentType": 5121, "normalized": true, "count": 4, "type": "VEC4"},
    {"componentType": 5123, "count": 12, "type": "SCALAR"}
  ],
  "bufferViews": [{"buffer": 0, "byteLength": )" + length + R"(}],
  "buffers": [{"byteLength": )" + length + R"(, "uri": "data:application/octet-stream;base64,)" + base64(e.bytes) + R"("}]
})";
}

// Points with their colours, in a canonical order (Draco may reorder points).
std::vector<std::pair<glm::dvec3, glm::vec3>> sortedPoints(const PointSet& set) {
  std::vector<std::pair<glm::dvec3, glm::vec3>> out;
  for (size_t i = 0; i < set.size(); ++i) out.emplace_back(set.positions[i], set.colors[i]);
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
    return std::tie(a.first.x, a.first.y, a.first.z) < std::tie(b.first.x, b.first.y, b.first.z);
  });
  return out;
}

TEST(GltfDraco, decodesPositionsColoursAndTrianglesExactly) {
  TempDir dir;
  Result<PointSet> set = readText(dir, dracoGltf(encodeTetrahedron(0)));
  ASSERT_TRUE(set) << set.error().message;
  ASSERT_EQ(set->size(), 4u);
  ASSERT_TRUE(set->hasColors());
  const auto points = sortedPoints(*set);
  // Sorted by x, then y, z: (0,0,0), (0,0,3), (0,2,0), (1,0,0) plus the translation.
  const int order[4] = {0, 3, 2, 1};
  for (int i = 0; i < 4; ++i) {
    const float* p = kPositions[order[i]];
    EXPECT_EQ(points[size_t(i)].first, glm::dvec3(6378000.0 + p[0], p[1], 0.5 + p[2])) << i;
    const uint8_t* c = kColours[order[i]];
    EXPECT_EQ(points[size_t(i)].second, glm::vec3(float(c[0] / 255.0), float(c[1] / 255.0), float(c[2] / 255.0))) << i;
  }
  // Four faces over the four points, each naming three distinct points.
  ASSERT_EQ(set->triangles.size(), 12u);
  for (size_t t = 0; t < 12; t += 3) {
    EXPECT_NE(set->triangles[t], set->triangles[t + 1]);
    EXPECT_NE(set->triangles[t + 1], set->triangles[t + 2]);
    EXPECT_NE(set->triangles[t], set->triangles[t + 2]);
  }
}

TEST(GltfDraco, quantizedPositionsWithinHalfAStep) {
  TempDir dir;
  Result<PointSet> set = readText(dir, dracoGltf(encodeTetrahedron(11)));
  ASSERT_TRUE(set) << set.error().message;
  ASSERT_EQ(set->size(), 4u);
  // Draco quantizes over the largest side of the box (3) in 2^11 − 1 steps.
  const double half_step = 0.5 * 3.0 / 2047.0;
  for (const glm::dvec3& p : set->positions) {
    double nearest = 1e300;
    for (const auto& q : kPositions)
      nearest = std::min(nearest, std::max({std::abs(p.x - 6378000.0 - q[0]), std::abs(p.y - q[1]),
                                            std::abs(p.z - 0.5 - q[2])}));
    EXPECT_LE(nearest, half_step * (1 + 1e-6)) << p.x << "," << p.y << "," << p.z;
  }
}

TEST(GltfDraco, primitiveWithoutIndicesGetsTheDracoFaces) {
  TempDir dir;
  const std::string json = replaced(dracoGltf(encodeTetrahedron(0)), R"("indices": 2, )", "");
  Result<PointSet> set = readText(dir, json);
  ASSERT_TRUE(set) << set.error().message;
  EXPECT_EQ(set->size(), 4u);
  EXPECT_EQ(set->triangles.size(), 12u);
}

TEST(GltfDraco, sameFileAsGlbDecodes) {
  // The GLB path rewrites the JSON chunk (indices are detached for tinygltf); points must survive it.
  TempDir dir;
  const Encoded e = encodeTetrahedron(0);
  std::string json = dracoGltf(e);
  const size_t uri = json.find(R"(, "uri": ")");
  json.erase(uri, json.find("\"}]", uri) + 1 - uri);
  json.append((4 - json.size() % 4) % 4, ' ');
  std::vector<unsigned char> bin = e.bytes;
  bin.resize((bin.size() + 3) / 4 * 4, 0);
  std::string glb;
  const auto u32 = [&](uint32_t v) { glb.append(reinterpret_cast<const char*>(&v), 4); };
  u32(0x46546C67);
  u32(2);
  u32(uint32_t(12 + 8 + json.size() + 8 + bin.size()));
  u32(uint32_t(json.size()));
  u32(0x4E4F534A);
  glb += json;
  u32(uint32_t(bin.size()));
  u32(0x004E4942);
  glb.append(bin.begin(), bin.end());
  test::writeFile(dir.file("scene.glb"), glb);
  Result<PointSet> set = readGltf(dir.file("scene.glb"));
  ASSERT_TRUE(set) << set.error().message;
  EXPECT_EQ(set->size(), 4u);
  EXPECT_EQ(set->triangles.size(), 12u);
}

TEST(GltfDraco, rejectsTruncatedBufferView) {
  const Encoded e = encodeTetrahedron(11);
  const std::string json = dracoGltf(e);
  const std::string length = std::to_string(e.bytes.size());
  // The view cut short: libdraco runs out of data and says so.
  expectReadError(replaced(json, R"("bufferViews": [{"buffer": 0, "byteLength": )" + length,
                           R"("bufferViews": [{"buffer": 0, "byteLength": )" + std::to_string(e.bytes.size() / 2)),
                  {kDracoPointer, ": libdraco could not decode it"});
  // The view past the end of its buffer: refused before libdraco sees it.
  expectReadError(replaced(json, R"("bufferViews": [{"buffer": 0, "byteLength": )",
                           R"("bufferViews": [{"buffer": 0, "byteOffset": 8, "byteLength": )"),
                  {std::string(kDracoPointer) + "/bufferView: bufferView 0: byteOffset 8 + byteLength " + length +
                   " exceeds buffer 0 length " + length});
  expectReadError(replaced(json, R"("bufferView": 0,)", R"("bufferView": 3,)"),
                  {std::string(kDracoPointer) + "/bufferView: bufferView 3 does not exist"});
  // Not Draco data at all.
  expectReadError(replaced(json, "base64," + base64(e.bytes).substr(0, 8), "base64,AAAAAAAA"),
                  {kDracoPointer, "libdraco cannot read the header"});
}

TEST(GltfDraco, rejectsWrongAttributeId) {
  const Encoded e = encodeTetrahedron(11);
  const std::string position = R"("POSITION": )" + std::to_string(e.position_id);
  const std::string colour = R"("COLOR_0": )" + std::to_string(e.colour_id);
  expectReadError(replacedAfter(dracoGltf(e), kExtensionStart, colour, R"("COLOR_0": 7)"),
                  {std::string(kDracoPointer) + "/attributes/COLOR_0: Draco attribute id 7 is not in the decoded data"});
  // POSITION naming the colour data (4 uint8 components).
  expectReadError(replacedAfter(dracoGltf(e), kExtensionStart, position, R"("POSITION": )" + std::to_string(e.colour_id)),
                  {kDracoPointer, ": POSITION accessor 0: 3 components, but Draco attribute " +
                                      std::to_string(e.colour_id) + " has 4"});
  // An extension attribute the primitive does not have.
  expectReadError(replacedAfter(dracoGltf(e), kExtensionStart, position, R"("NORMAL": 1, )" + position),
                  {std::string(kDracoPointer) + "/attributes/NORMAL: is not an attribute of the primitive"});
}

TEST(GltfDraco, rejectsCountAndTypeMismatch) {
  const std::string json = dracoGltf(encodeTetrahedron(11));
  expectReadError(replaced(json, R"({"componentType": 5126, "count": 4,)", R"({"componentType": 5126, "count": 5,)"),
                  {kDracoPointer, ": POSITION accessor 0: count 5 differs from the 4 points the Draco data decodes to"});
  expectReadError(replaced(json, R"({"componentType": 5123, "count": 12,)", R"({"componentType": 5123, "count": 9,)"),
                  {kDracoPointer, ": indices accessor 2: count 9 differs from 3 x the 4 faces"});
  expectReadError(replaced(json, R"({"componentType": 5126, "count": 4,)", R"({"componentType": 5123, "count": 4,)"),
                  {kDracoPointer, ": POSITION accessor 0: componentType 5123, but Draco attribute 0 holds float32"});
  expectReadError(replaced(json, R"({"componentType": 5123, "count": 12,)", R"({"componentType": 5126, "count": 12,)"),
                  {kDracoPointer, ": indices accessor 2: must be SCALAR unsigned byte, short or int"});
}

TEST(GltfDraco, rejectsModeAndFieldsTinygltfWouldWrap) {
  const std::string json = dracoGltf(encodeTetrahedron(11));
  expectReadError(replaced(json, R"("mode": 4,)", R"("mode": 0,)"),
                  {"/meshes/0/primitives/0/mode: 0 is not allowed with KHR_draco_mesh_compression"});
  expectReadError(replaced(json, R"("bufferView": 0,)", R"("bufferView": 4294967296,)"),
                  {std::string(kDracoPointer) + "/bufferView: must be an integer"});
  expectReadError(replaced(json, R"("bufferView": 0,)", R"("bufferView": "0",)"),
                  {std::string(kDracoPointer) + "/bufferView: must be an integer"});
}

// Corrupted Draco bytes (every 7th byte flipped by three patterns) either decode to a valid point
// set or fail with one line: libdraco's own checks plus ours must keep every read in bounds.
TEST(GltfDraco, corruptedBytesDecodeOrFailCleanly) {
  const Encoded e = encodeTetrahedron(11);
  int decoded = 0, refused = 0;
  for (size_t at = 0; at < e.bytes.size(); at += 7)
    for (int pattern : {0x01, 0xFE, 0x5B}) {
      Encoded bad = e;
      bad.bytes[at] = static_cast<unsigned char>(bad.bytes[at] ^ pattern);
      TempDir dir;
      Result<PointSet> set = readText(dir, dracoGltf(bad));
      if (set) {
        ++decoded;
        for (uint32_t v : set->triangles) EXPECT_LT(v, set->size());
      } else {
        ++refused;
        EXPECT_EQ(set.error().message.find('\n'), std::string::npos) << set.error().message;
      }
    }
  EXPECT_GT(refused, 0);
  std::cout << "corrupted Draco data: " << decoded << " decoded, " << refused << " refused\n";
}

}  // namespace
}  // namespace dpoint
