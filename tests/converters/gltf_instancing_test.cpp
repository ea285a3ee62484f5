// EXT_mesh_gpu_instancing: each instance is one more world-space copy of the node's mesh, placed by
// node world matrix · instance T·R·S; missing, short or mistyped instance accessors are refused
// with the node and attribute named.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
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

constexpr const char* kPointer = "/nodes/0/extensions/EXT_mesh_gpu_instancing";

template <typename T>
void append(std::vector<unsigned char>& bytes, std::initializer_list<T> values) {
  for (T v : values) {
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, &v, sizeof(T));
    bytes.insert(bytes.end(), raw, raw + sizeof(T));
  }
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// Buffer: mesh positions (3 float VEC3, 36 B), instance translations (3 float VEC3, 36 B),
// rotations (3 normalized short VEC4, 24 B), scales (3 float VEC3, 36 B).
// Instance 0: identity. Instance 1: T(10,0,0), 90° about z (quaternion components 23170/32767,
// not unit until normalized). Instance 2: T(0,0,-5), S(2,3,4). first_w: instance 0's quaternion w.
std::string instancedGltf(int16_t first_w = 32767) {
  std::vector<unsigned char> bytes;
  append<float>(bytes, {1, 2, 3, 0, 0, 0, -1, 0.5f, 2});
  append<float>(bytes, {0, 0, 0, 10, 0, 0, 0, 0, -5});
  append<int16_t>(bytes, {0, 0, 0, first_w, 0, 0, 23170, 23170, 0, 0, 0, 32767});
  append<float>(bytes, {1, 1, 1, 1, 1, 1, 2, 3, 4});
  return R"({
  "asset": {"version": "2.0"},
  "extensionsUsed": ["EXT_mesh_gpu_instancing"],
  "extensionsRequired": ["EXT_mesh_gpu_instancing"],
  "nodes": [
    {"mesh": 0, "translation": [6378000, 0, 0], "scale": [0.5, 0.5, 0.5], "children": [1],
     "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 1, "ROTATION": 2, "SCALE": 3}}}},
    {"mesh": 0, "translation": [0, 100, 0]}
  ],
  "scenes": [{"nodes": [0]}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "mode": 0}]}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [-1, 0, 0], "max": [1, 2, 3]},
    {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"},
    {"bufferView": 2, "componentType": 5122, "normalized": true, "count": 3, "type": "VEC4"},
    {"bufferView": 3, "componentType": 5126, "count": 3, "type": "VEC3"}
  ],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 36},
    {"buffer": 0, "byteOffset": 36, "byteLength": 36},
    {"buffer": 0, "byteOffset": 72, "byteLength": 24},
    {"buffer": 0, "byteOffset": 96, "byteLength": 36}
  ],
  "buffers": [{"byteLength": 132, "uri": "data:application/octet-stream;base64,)" + base64(bytes) + R"("}]
})";
}

TEST(GltfInstancing, eachInstanceIsAWorldSpaceCopyOfTheMesh) {
  TempDir dir;
  Result<PointSet> set = readText(dir, instancedGltf());
  ASSERT_TRUE(set) << set.error().message;
  // Three instances of the node's mesh, then the child's mesh once (children are not instanced).
  ASSERT_EQ(set->size(), 12u);
  const glm::dvec3 mesh[3] = {{1, 2, 3}, {0, 0, 0}, {-1, 0.5, 2}};
  const auto node = [](glm::dvec3 p) { return glm::dvec3(6378000, 0, 0) + 0.5 * p; };
  PositionArray expected;
  for (const glm::dvec3& p : mesh) expected.push_back(node(p));
  for (const glm::dvec3& p : mesh) expected.push_back(node(glm::dvec3(10 - p.y, p.x, p.z)));  // 90° about z
  for (const glm::dvec3& p : mesh) expected.push_back(node(glm::dvec3(2 * p.x, 3 * p.y, 4 * p.z - 5)));
  for (const glm::dvec3& p : mesh) expected.push_back(node(p + glm::dvec3(0, 100, 0)));
  for (size_t i = 0; i < expected.size(); ++i)
    for (int k = 0; k < 3; ++k)
      // The normalized quaternion is unit to double rounding; the rest is exact.
      EXPECT_NEAR(set->positions[i][k], expected[i][k], 1e-9) << "point " << i << " axis " << k;
}

TEST(GltfInstancing, translationOnlyAndMaxPoints) {
  TempDir dir;
  const std::string json = replaced(instancedGltf(), R"("TRANSLATION": 1, "ROTATION": 2, "SCALE": 3)", R"("TRANSLATION": 1)");
  Result<PointSet> set = readText(dir, json);
  ASSERT_TRUE(set) << set.error().message;
  ASSERT_EQ(set->size(), 12u);
  EXPECT_EQ(set->positions[3], glm::dvec3(6378000 + 5.5, 1, 1.5));  // (1,2,3) + (10,0,0), halved
  GltfReadOptions options;
  options.max_points = 8;
  Result<PointSet> limited = readGltf(dir.file("scene.gltf"), options);
  ASSERT_FALSE(limited);
  EXPECT_EQ(limited.error().code, ExitCode::kResourceLimit);
}

TEST(GltfInstancing, rejectsMissingAccessor) {
  expectReadError(replaced(instancedGltf(), R"("SCALE": 3)", R"("SCALE": 9)"), {"accessor 9 does not exist"});
  expectReadError(replaced(instancedGltf(), R"("SCALE": 3)", R"("SCALE": "3")"),
                  {std::string(kPointer) + "/attributes/SCALE: must be"});
  expectReadError(replaced(instancedGltf(), R"({"TRANSLATION": 1, "ROTATION": 2, "SCALE": 3})", R"({"_ID": 1})"),
                  {std::string(kPointer) + "/attributes: has none of TRANSLATION, ROTATION, SCALE"});
  expectReadError(replaced(instancedGltf(), R"({"attributes": {"TRANSLATION")", R"({"attribs": {"TRANSLATION")"),
                  {std::string(kPointer) + "/attributes: must be an object"});
}

TEST(GltfInstancing, rejectsShortAccessor) {
  // SCALE with 2 elements where the others have 3.
  expectReadError(replaced(instancedGltf(), R"({"bufferView": 3, "componentType": 5126, "count": 3,)",
                           R"({"bufferView": 3, "componentType": 5126, "count": 2,)"),
                  {std::string(kPointer) + "/attributes/SCALE: accessor 3 has count 2, ROTATION has 3 (all must be equal)"});
  // TRANSLATION claiming more elements than its view holds: the accessor bounds check.
  expectReadError(replaced(instancedGltf(), R"({"bufferView": 1, "componentType": 5126, "count": 3,)",
                           R"({"bufferView": 1, "componentType": 5126, "count": 4,)"),
                  {"/accessors/1: count 4: byteOffset + stride*(count-1) + 12 = 48 exceeds bufferView 1 length 36"});
}

TEST(GltfInstancing, rejectsWrongTypes) {
  expectReadError(replaced(instancedGltf(), R"({"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"})",
                           R"({"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"})"),
                  {std::string(kPointer) + "/attributes/TRANSLATION: accessor 1 must be VEC3"});
  // Rotations as unnormalized shorts are not quaternions.
  expectReadError(replaced(instancedGltf(), R"("componentType": 5122, "normalized": true,)", R"("componentType": 5122,)"),
                  {std::string(kPointer) + "/attributes/ROTATION: accessor 2 must be VEC4 of float or normalized byte/short"});
}

TEST(GltfInstancing, rejectsZeroRotation) {
  expectReadError(instancedGltf(0), {std::string(kPointer) + "/attributes/ROTATION: instance 0 has zero length"});
}

}  // namespace
}  // namespace dpoint
