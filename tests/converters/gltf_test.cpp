// GLB writer and glTF/GLB reader: round trips at Earth-radius offsets, the file layout seen through
// tinygltf itself, node transforms, malformed input, and the official validator.
#include <gtest/gtest.h>
#include <meshoptimizer.h>
#include <tiny_gltf.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "converters/gltf_read.h"
#include "converters/gltf_write.h"
#include "ops/point_filters.h"
#include "gltf_test_support.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::base64;
using test::expectReadError;
using test::readText;
using test::TempDir;
using test::writeFile;

constexpr double kEarthRadius = 6.378e6;

// 2000 points with millimetre detail in a ~2 m box at Earth radius, with colours.
PointSet offsetCloud() {
  PointSet set;
  for (int i = 0; i < 2000; ++i) {
    set.positions.push_back({kEarthRadius + 0.001 * (i % 1000) + 0.0001 * (i % 7),
                             -kEarthRadius + 0.001 * ((i * 37) % 1500),
                             kEarthRadius * 0.5 + 0.001 * ((i * 11) % 2000) - 0.0003 * (i % 3)});
    set.colors.push_back({float(i % 256) / 255.0f, 0.1f * float(i % 10), 1.0f / float(1 + i)});
  }
  return set;
}

// A tetrahedron far from the origin: 4 vertices, 4 triangles.
PointSet tetrahedron(bool colours) {
  PointSet set;
  const glm::dvec3 base(1e8, -2e7, 3.5e6);
  set.positions = {base, base + glm::dvec3(1, 0, 0), base + glm::dvec3(0, 1, 0),
                   base + glm::dvec3(0, 0, 1)};
  if (colours) set.colors = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.5f, 0.5f, 0.5f}};
  set.triangles = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  return set;
}

double extentOf(const PointSet& set) {
  glm::dvec3 lo = set.positions[0], hi = set.positions[0];
  for (const glm::dvec3& p : set.positions) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  }
  return std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
}

double maxError(const PointSet& a, const PointSet& b) {
  double worst = 0;
  for (size_t i = 0; i < a.size(); ++i)
    for (int k = 0; k < 3; ++k)
      worst = std::max(worst, std::abs(a.positions[i][k] - b.positions[i][k]));
  return worst;
}

tinygltf::Model loadWithTinygltf(const std::string& path) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  EXPECT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, path)) << err;
  return model;
}

TEST(Gltf, glbPointRoundTripWithinFloatOfExtent) {
  TempDir dir;
  const PointSet set = offsetCloud();
  ASSERT_TRUE(writeGlb(dir.file("cloud.glb"), set));
  Result<PointSet> back = readGltf(dir.file("cloud.glb"));
  ASSERT_TRUE(back) << back.error().message;
  ASSERT_EQ(back->size(), set.size());
  EXPECT_FALSE(back->isMesh());

  // Offsets from the box centre are at most extent/2, so float rounding is ≤ extent·2^-25 and
  // the bound below has room for the double arithmetic around it.
  const double extent = extentOf(set);
  const double error = maxError(set, *back);
  EXPECT_LE(error, extent * 0x1p-23);
  // Float rounding of the absolute coordinate would be up to 6.378e6·2^-24 ≈ 0.38 m.
  EXPECT_LT(error, 1e-6 * kEarthRadius * 0x1p-24);

  ASSERT_EQ(back->colors.size(), set.colors.size());
  for (size_t i = 0; i < set.size(); ++i) {
    EXPECT_EQ(std::memcmp(&back->colors[i], &set.colors[i], sizeof(glm::vec3)), 0)
        << "colour " << i;
  }
}

TEST(Gltf, glbMeshKeepsTriangles) {
  for (bool colours : {false, true}) {
    TempDir dir;
    const PointSet set = tetrahedron(colours);
    ASSERT_TRUE(writeGlb(dir.file("mesh.glb"), set));
    Result<PointSet> back = readGltf(dir.file("mesh.glb"));
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->triangles, set.triangles);
    EXPECT_EQ(back->hasColors(), colours);
    ASSERT_EQ(back->size(), set.size());
    // Vertices at ±0.5 from the centre are exact in float: the round trip is exact.
    EXPECT_EQ(maxError(set, *back), 0.0);
    if (colours) {
      for (size_t i = 0; i < set.size(); ++i) EXPECT_EQ(back->colors[i], set.colors[i]);
    }
  }
}

TEST(Gltf, glbMinMaxMatchStoredFloats) {
  TempDir dir;
  const PointSet set = offsetCloud();
  ASSERT_TRUE(writeGlb(dir.file("cloud.glb"), set));
  const tinygltf::Model model = loadWithTinygltf(dir.file("cloud.glb"));
  ASSERT_EQ(model.meshes.size(), 1u);
  ASSERT_EQ(model.meshes[0].primitives.size(), 1u);
  const tinygltf::Primitive& primitive = model.meshes[0].primitives[0];
  EXPECT_EQ(primitive.mode, TINYGLTF_MODE_POINTS);
  EXPECT_EQ(primitive.indices, -1);

  const tinygltf::Accessor& accessor = model.accessors[size_t(primitive.attributes.at("POSITION"))];
  ASSERT_EQ(accessor.componentType, TINYGLTF_COMPONENT_TYPE_FLOAT);
  ASSERT_EQ(accessor.type, TINYGLTF_TYPE_VEC3);
  ASSERT_EQ(accessor.count, set.size());
  const tinygltf::BufferView& view = model.bufferViews[size_t(accessor.bufferView)];
  EXPECT_EQ(view.target, TINYGLTF_TARGET_ARRAY_BUFFER);
  EXPECT_EQ(view.byteOffset % 4, 0u);
  EXPECT_EQ(view.byteLength % 4, 0u);
  const unsigned char* data = model.buffers[0].data.data() + view.byteOffset + accessor.byteOffset;

  float lo[3], hi[3];
  for (int k = 0; k < 3; ++k) {
    lo[k] = std::numeric_limits<float>::infinity();
    hi[k] = -lo[k];
  }
  for (size_t i = 0; i < accessor.count; ++i) {
    float v[3];
    std::memcpy(v, data + 12 * i, sizeof(v));
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], v[k]);
      hi[k] = std::max(hi[k], v[k]);
    }
  }
  ASSERT_EQ(accessor.minValues.size(), 3u);
  ASSERT_EQ(accessor.maxValues.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(accessor.minValues[size_t(k)], double(lo[k])) << "axis " << k;
    EXPECT_EQ(accessor.maxValues[size_t(k)], double(hi[k])) << "axis " << k;
  }
  // The double origin sits in the node translation, the floats are offsets around it.
  ASSERT_EQ(model.nodes.size(), 1u);
  ASSERT_EQ(model.nodes[0].translation.size(), 3u);
  EXPECT_NEAR(model.nodes[0].translation[0], kEarthRadius + 0.5, 0.01);
  EXPECT_EQ(model.asset.generator, "dpoint");
  EXPECT_EQ(model.defaultScene, 0);
}

TEST(Gltf, glbMeshUsesUint32ElementArray) {
  TempDir dir;
  ASSERT_TRUE(writeGlb(dir.file("mesh.glb"), tetrahedron(false)));
  const tinygltf::Model model = loadWithTinygltf(dir.file("mesh.glb"));
  const tinygltf::Primitive& primitive = model.meshes.at(0).primitives.at(0);
  EXPECT_EQ(primitive.mode, TINYGLTF_MODE_TRIANGLES);
  ASSERT_GE(primitive.indices, 0);
  const tinygltf::Accessor& indices = model.accessors[size_t(primitive.indices)];
  EXPECT_EQ(indices.componentType, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
  EXPECT_EQ(indices.count, 12u);
  const tinygltf::BufferView& view = model.bufferViews[size_t(indices.bufferView)];
  EXPECT_EQ(view.target, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  EXPECT_EQ(view.byteOffset % 4, 0u);
  EXPECT_EQ(primitive.attributes.count("COLOR_0"), 0u);
}

TEST(Gltf, glbRejectsEmptyPointSet) {
  TempDir dir;
  Status s = writeGlb(dir.file("empty.glb"), PointSet{});
  ASSERT_FALSE(s);
  // glTF cannot hold an empty accessor (count >= 1): said so, and which formats can.
  EXPECT_TRUE(test::contains(s.error().message, "cannot write GLB: the point set is empty"));
  EXPECT_TRUE(test::contains(s.error().message, "at least one element"));
  EXPECT_TRUE(test::contains(s.error().message, "write .csv, .ply or .las"));
  EXPECT_TRUE(dir.entries().empty());
}

TEST(Gltf, glbWriteToMissingFolderLeavesNothing) {
  TempDir dir;
  Status s = writeGlb(dir.file("missing/out.glb"), offsetCloud());
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("missing"), std::string::npos) << s.error().message;
  EXPECT_TRUE(dir.entries().empty());
}

// --- Hand-written .gltf files with an embedded buffer -------------------------------------------

template <typename T>
void append(std::vector<unsigned char>& bytes, std::initializer_list<T> values) {
  for (T v : values) {
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, &v, sizeof(T));
    bytes.insert(bytes.end(), raw, raw + sizeof(T));
  }
}

// Buffer: 3 float VEC3 positions (36 B), 3 normalized ubyte VEC4 colours (12 B), 3 u16 indices.
std::string fixtureBuffer() {
  std::vector<unsigned char> bytes;
  append<float>(bytes, {1, 2, 3, 0, 0, 0, -1, 0.5f, 2});
  append<uint8_t>(bytes, {255, 0, 0, 10, 0, 255, 0, 20, 51, 102, 204, 255});
  append<uint16_t>(bytes, {0, 1, 2, 0});
  return base64(bytes);
}

// Node 0: matrix (scale 2, then translate by Earth radius in x) with the points mesh 1 (material
// colour, no COLOR_0). Node 1, its child: T(0,5,0)·R(90° about z, quaternion not normalized)·
// S(1,1,3) with the triangle mesh 0 (ubyte COLOR_0).
std::string fixtureGltf() {
  return R"({
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0]}],
  "nodes": [
    {"matrix": [2,0,0,0, 0,2,0,0, 0,0,2,0, 6378000,0,0,1], "mesh": 1, "children": [1]},
    {"translation": [0,5,0], "rotation": [0,0,1.4142135623730951,1.4142135623730951],
     "scale": [1,1,3], "mesh": 0}
  ],
  "meshes": [
    {"primitives": [{"attributes": {"POSITION": 0, "COLOR_0": 1}, "indices": 2, "mode": 4}]},
    {"primitives": [{"attributes": {"POSITION": 0}, "material": 0, "mode": 0}]}
  ],
  "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.25, 0.5, 0.75, 1]}}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
     "min": [-1, 0, 0], "max": [1, 2, 3]},
    {"bufferView": 1, "componentType": 5121, "normalized": true, "count": 3, "type": "VEC4"},
    {"bufferView": 2, "componentType": 5123, "count": 3, "type": "SCALAR"}
  ],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 36},
    {"buffer": 0, "byteOffset": 36, "byteLength": 12},
    {"buffer": 0, "byteOffset": 48, "byteLength": 6}
  ],
  "buffers": [{"byteLength": 56, "uri": "data:application/octet-stream;base64,)" +
         fixtureBuffer() + R"("}]
})";
}

// A primitive larger than the reader's chunks (16,384 elements): 40,000 float positions and
// colours and 50,000 triangles of uint32 indices over the even vertices only (the odd ones are
// unused and dropped), read on 1, 2 and 4 cores: the same set, and of two bad indices, positions
// or colours the first is named (a bad colour on an unused vertex is not read).
TEST(Gltf, aLargePrimitiveIsReadOnAllCoresWithTheFirstBadElementNamed) {
  constexpr uint32_t kVertices = 40000, kTriangles = 50000;
  auto gltf = [&](const std::vector<float>& positions, const std::vector<float>& colours,
                  const std::vector<uint32_t>& indices) {
    std::vector<unsigned char> bytes;
    auto add = [&](const void* data, size_t n) {
      const auto* b = static_cast<const unsigned char*>(data);
      bytes.insert(bytes.end(), b, b + n);
    };
    add(positions.data(), positions.size() * 4);
    add(colours.data(), colours.size() * 4);
    add(indices.data(), indices.size() * 4);
    const std::string p = std::to_string(positions.size() * 4), c = std::to_string(colours.size() * 4),
                      pc = std::to_string((positions.size() + colours.size()) * 4), i = std::to_string(indices.size() * 4);
    return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "COLOR_0": 2}, "indices": 1, "mode": 4}]}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": )" + std::to_string(kVertices) + R"(, "type": "VEC3"},
    {"bufferView": 2, "componentType": 5125, "count": )" + std::to_string(indices.size()) + R"(, "type": "SCALAR"},
    {"bufferView": 1, "componentType": 5126, "count": )" + std::to_string(kVertices) + R"(, "type": "VEC3"}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": )" + p + R"(},
                  {"buffer": 0, "byteOffset": )" + p + R"(, "byteLength": )" + c + R"(},
                  {"buffer": 0, "byteOffset": )" + pc + R"(, "byteLength": )" + i + R"(}],
  "buffers": [{"byteLength": )" + std::to_string(bytes.size()) + R"(, "uri": "data:application/octet-stream;base64,)" +
           base64(bytes) + R"("}]})";
  };
  std::vector<float> positions, colours;
  for (uint32_t v = 0; v < kVertices; ++v) {
    positions.insert(positions.end(), {float(v), 0.5f * float(v % 97), -2.0f});
    colours.insert(colours.end(), {float(v % 11) / 10.0f, 0.25f, float(v % 5) / 4.0f});
  }
  std::vector<uint32_t> indices;
  for (uint32_t t = 0; t < kTriangles; ++t)
    for (uint32_t k : {0u, 1u, 5u}) indices.push_back(2 * ((t + k) % (kVertices / 2)));
  PositionArray expected_positions;  // the even vertices, renumbered in order
  ColorArray expected_colours;
  for (uint32_t v = 0; v < kVertices; v += 2) {
    expected_positions.emplace_back(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
    expected_colours.emplace_back(colours[3 * v], colours[3 * v + 1], colours[3 * v + 2]);
  }
  std::vector<uint32_t> expected_triangles;
  for (uint32_t i : indices) expected_triangles.push_back(i / 2);
  TempDir dir;
  auto read = [&](const std::string& name, const std::string& text, unsigned threads) {
    GltfReadOptions options;
    options.threads = threads;
    writeFile(dir.file(name), text);
    return readGltf(dir.file(name), options);
  };
  for (unsigned threads : {1u, 2u, 4u}) {
    Result<PointSet> set = read("big.gltf", gltf(positions, colours, indices), threads);
    ASSERT_TRUE(set.ok()) << set.error().message;
    EXPECT_EQ(set->positions, expected_positions) << threads << " threads";
    EXPECT_EQ(set->colors, expected_colours) << threads << " threads";
    EXPECT_EQ(set->triangles, expected_triangles) << threads << " threads";

    std::vector<uint32_t> bad_indices = indices;
    bad_indices[140000] = kVertices + 5;
    bad_indices[30001] = kVertices;
    Result<PointSet> bad = read("bad.gltf", gltf(positions, colours, bad_indices), threads);
    ASSERT_FALSE(bad.ok());
    EXPECT_NE(bad.error().message.find("/accessors/1: element 30001 is 40000, out of range for 40000 vertices"),
              std::string::npos) << bad.error().message;

    std::vector<float> nan_positions = positions;
    nan_positions[3 * 39000 + 1] = std::numeric_limits<float>::quiet_NaN();
    nan_positions[3 * 25000 + 2] = std::numeric_limits<float>::infinity();
    Result<PointSet> nan = read("nan.gltf", gltf(nan_positions, colours, indices), threads);
    ASSERT_FALSE(nan.ok());
    EXPECT_NE(nan.error().message.find("/accessors/0: POSITION element 25000 is not finite"), std::string::npos)
        << nan.error().message;

    std::vector<float> nan_colours = colours;
    nan_colours[3 * 36000] = std::numeric_limits<float>::quiet_NaN();
    nan_colours[3 * 33001] = std::numeric_limits<float>::quiet_NaN();  // odd: an unused vertex, not read
    nan_colours[3 * 33002 + 2] = std::numeric_limits<float>::quiet_NaN();
    Result<PointSet> dark = read("dark.gltf", gltf(positions, nan_colours, indices), threads);
    ASSERT_FALSE(dark.ok());
    EXPECT_NE(dark.error().message.find("/accessors/2: COLOR_0 element 33002 is not finite"), std::string::npos)
        << dark.error().message;
  }
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST(Gltf, gltfNodeHierarchyComposesMatrixAndTrs) {
  TempDir dir;
  Result<PointSet> set = readText(dir, fixtureGltf());
  ASSERT_TRUE(set) << set.error().message;
  const PositionArray expected = {
      {6378002, 4, 6},   {6378000, 0, 0},  {6377998, 1, 4},   // node 0: M·p
      {6377996, 12, 18}, {6378000, 10, 0}, {6377999, 8, 12},  // node 1: M·T·R·S·p
  };
  ASSERT_EQ(set->size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i)
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(set->positions[i][k], expected[i][k], 1e-9) << "point " << i << " axis " << k;
  EXPECT_EQ(set->triangles, (std::vector<uint32_t>{3, 4, 5}));
}

TEST(Gltf, gltfMissingColoursTakeMaterialColour) {
  TempDir dir;
  Result<PointSet> set = readText(dir, fixtureGltf());
  ASSERT_TRUE(set) << set.error().message;
  const ColorArray expected = {
      {0.25f, 0.5f, 0.75f}, {0.25f, 0.5f, 0.75f}, {0.25f, 0.5f, 0.75f}, {1, 0, 0}, {0, 1, 0},
      {0.2f, 0.4f, 0.8f}};
  EXPECT_EQ(set->colors, expected);
}

// Vertex attributes no dimension holds are named in a note (a review found NORMAL, TEXCOORD_0 and
// a VEC3 `_FOO` dropped without a word); POSITION, COLOR_0 and a SCALAR `_NAME` are read.
TEST(Gltf, attributesNotReadAreNamedInANote) {
  TempDir dir;
  writeFile(dir.file("scene.gltf"),
            replaced(fixtureGltf(), R"({"attributes": {"POSITION": 0}, "material": 0)",
                     R"({"attributes": {"POSITION": 0, "NORMAL": 0, "TEXCOORD_0": 0, "_FOO": 0}, "material": 0)"));
  std::vector<std::string> notices;
  GltfReadOptions options;
  options.notices = &notices;
  Result<PointSet> set = readGltf(dir.file("scene.gltf"), options);
  ASSERT_TRUE(set) << set.error().message;
  ASSERT_EQ(notices.size(), 1u);
  EXPECT_EQ(notices[0], dir.file("scene.gltf") + ": vertex attributes not read (dpoint reads POSITION, COLOR_0 and "
                                                  "SCALAR _NAME attributes): NORMAL, TEXCOORD_0, _FOO");
  notices.clear();
  writeFile(dir.file("plain.gltf"), fixtureGltf());  // only what is read: nothing said
  ASSERT_TRUE(readGltf(dir.file("plain.gltf"), options));
  EXPECT_TRUE(notices.empty());
}

TEST(Gltf, gltfRejectsNodeCycle) {
  expectReadError(replaced(fixtureGltf(), R"("scale": [1,1,3], "mesh": 0})",
                           R"("scale": [1,1,3], "mesh": 0, "children": [0]})"),
                  {"/nodes/0", "cycle"});
}

TEST(Gltf, gltfRejectsNodeWithTwoParents) {
  expectReadError(replaced(fixtureGltf(), R"("children": [1])", R"("children": [1, 1])"),
                  {"/nodes/1", "two parents"});
}

TEST(Gltf, gltfRejectsAccessorPastBuffer) {
  // Four positions in a 36-byte view that holds three.
  expectReadError(replaced(fixtureGltf(), R"("componentType": 5126, "count": 3)",
                           R"("componentType": 5126, "count": 4)"),
                  {"/accessors/0: count 4: byteOffset + stride*(count-1) + 12 = 48 exceeds bufferView 0 length 36"});
  // A stride that walks out of the view.
  expectReadError(replaced(fixtureGltf(), R"("byteOffset": 0, "byteLength": 36})",
                           R"("byteOffset": 0, "byteLength": 36, "byteStride": 16})"),
                  {"/accessors/0", "exceeds bufferView 0 length 36"});
}

TEST(Gltf, gltfRejectsBufferViewPastBuffer) {
  expectReadError(replaced(fixtureGltf(), R"("byteOffset": 48, "byteLength": 6)",
                           R"("byteOffset": 48, "byteLength": 60)"),
                  {"/accessors/2", "bufferView 2", "exceeds buffer 0 length 56"});
}

TEST(Gltf, gltfRejectsIndexOutOfRange) {
  // The colour bytes read as u8 indices: 255 is no vertex.
  expectReadError(replaced(fixtureGltf(), R"({"bufferView": 2, "componentType": 5123,)",
                           R"({"bufferView": 1, "componentType": 5121,)"),
                  {"/accessors/2", "element 0 is 255, out of range for 3 vertices"});
}

TEST(Gltf, gltfRejectsUnsignedIntPosition) {
  expectReadError(replaced(fixtureGltf(), R"("componentType": 5126, "count": 3)",
                           R"("componentType": 5125, "count": 3)"),
                  {"/accessors/0: POSITION must be VEC3"});
}

TEST(Gltf, gltfSparseAccessorReplacesElements) {
  // Sparse index 1 (the second u16 of view 2) takes the first position (1,2,3) as its value.
  TempDir dir;
  Result<PointSet> set = readText(
      dir, replaced(fixtureGltf(), R"("min": [-1, 0, 0], "max": [1, 2, 3]})",
                    R"("min": [-1, 0, 0], "max": [1, 2, 3], "sparse": {"count": 1,
                  "indices": {"bufferView": 2, "byteOffset": 2, "componentType": 5123},
                  "values": {"bufferView": 0}}})"));
  ASSERT_TRUE(set) << set.error().message;
  EXPECT_EQ(set->positions[1], glm::dvec3(6378002, 4, 6));  // node 0: 2·(1,2,3) + (6378000,0,0)
}

TEST(Gltf, gltfRejectsSparseIndicesNotIncreasing) {
  // View 2's bytes read as u8 indices: 0, 0, 1; the second does not increase.
  expectReadError(replaced(fixtureGltf(), R"("min": [-1, 0, 0], "max": [1, 2, 3]})",
                           R"("min": [-1, 0, 0], "max": [1, 2, 3], "sparse": {"count": 3,
                  "indices": {"bufferView": 2, "byteOffset": 0, "componentType": 5121},
                  "values": {"bufferView": 0}}})"),
                  {"/accessors/0/sparse/indices: element 1"});
}

TEST(Gltf, gltfRefusesBufferOutsideFolder) {
  TempDir dir;
  test::writeFile(dir.file("outside.bin"), std::string(56, '\0'));
  const std::string sub = dir.file("model");
  ASSERT_TRUE(std::filesystem::create_directory(sub));
  std::string json = fixtureGltf();
  const size_t uri = json.find("data:application");
  json.replace(uri, json.find('"', uri) - uri, "../outside.bin");
  test::writeFile(sub + "/scene.gltf", json);
  Result<PointSet> set = readGltf(sub + "/scene.gltf");
  ASSERT_FALSE(set);
  EXPECT_NE(set.error().message.find("outside.bin"), std::string::npos) << set.error().message;
}

TEST(Gltf, gltfReportsMalformedJsonOnOneLine) { expectReadError("{ \"asset\": ", {}); }

// A review finding: tinygltf quotes a data URI it cannot decode whole, and a 2 MB one made a 2.7 MB
// error line. The message keeps the URI's first 80 bytes and says how long it was.
TEST(Gltf, aDataUriInAnErrorIsShortened) {
  TempDir dir;
  // 300,000 bytes of zeros as base64, where the buffer claims 400,000: tinygltf cannot decode it.
  const std::string uri = "data:application/octet-stream;base64," + std::string(400000, 'A');
  test::writeFile(dir.file("long.gltf"),
                  R"({"asset": {"version": "2.0"}, "buffers": [{"byteLength": 400000, "uri": ")" + uri +
                      R"("}], "bufferViews": [{"buffer": 0, "byteLength": 36}], "accessors": [{"bufferView": 0,
                      "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]}],
                      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}], "nodes": [{"mesh": 0}],
                      "scenes": [{"nodes": [0]}], "scene": 0})");
  Result<PointSet> set = readGltf(dir.file("long.gltf"));
  ASSERT_FALSE(set);
  EXPECT_LT(set.error().message.size(), 400u) << set.error().message.substr(0, 400);
  EXPECT_NE(set.error().message.find("data:application/octet-stream;base64,AAAA"), std::string::npos)
      << set.error().message.substr(0, 400);
  EXPECT_NE(set.error().message.find("… (" + std::to_string(uri.size()) + " bytes)"), std::string::npos)
      << set.error().message.substr(0, 400);
}

TEST(Gltf, gltfReportsMissingFile) {
  TempDir dir;
  Result<PointSet> set = readGltf(dir.file("absent.glb"));
  ASSERT_FALSE(set);
  EXPECT_EQ(set.error().message, dir.file("absent.glb") + ": file not found");
}

TEST(Gltf, gltfReportsEmptyFile) {
  TempDir dir;
  test::writeFile(dir.file("empty.glb"), "");
  Result<PointSet> set = readGltf(dir.file("empty.glb"));
  ASSERT_FALSE(set);
  EXPECT_EQ(set.error().message, dir.file("empty.glb") + ": file is empty");
}

TEST(Gltf, glbTruncatedFileIsAnError) {
  TempDir dir;
  ASSERT_TRUE(writeGlb(dir.file("cloud.glb"), offsetCloud()));
  const std::string bytes = test::readFile(dir.file("cloud.glb"));
  test::writeFile(dir.file("cut.glb"), bytes.substr(0, bytes.size() / 2));
  Result<PointSet> set = readGltf(dir.file("cut.glb"));
  ASSERT_FALSE(set);
  EXPECT_EQ(set.error().message.rfind(dir.file("cut.glb") + ": ", 0), 0u) << set.error().message;
  EXPECT_EQ(set.error().message.find('\n'), std::string::npos) << set.error().message;
}

// --- Accessor forms, primitive modes, options ---------------------------------------------------

// The validator's decoding oracles (corpus README): every component of each accessor, exactly.
TEST(Gltf, accessorOraclesGiveValidatorValues) {
  const std::string dir = std::string(DPOINT_CORPUS_DIR) + "/gltf-validator/base/data/accessor_data/";
  ASSERT_TRUE(test::fileExists(dir + "get_elements.gltf")) << "corpus not found at " << dir << ": the shared corpus must sit beside the checkout";
  const auto expect = [&](const std::string& file, int index, const std::vector<double>& values) {
    Result<std::vector<double>> got = readGltfAccessor(dir + file, index);
    ASSERT_TRUE(got) << got.error().message;
    EXPECT_EQ(*got, values) << file << " accessor " << index;
  };
  expect("get_elements.gltf", 0, {0, -5, 27, -0.0, 10.5, 0.5});
  expect("get_elements.gltf", 1, {1000, 0.25});                                    // stride 8
  expect("get_elements.gltf", 2, {50 / 65535.0, 45 / 65535.0, 12345 / 65535.0, 0});  // normalized ushort
  expect("get_elements.gltf", 3, {1 / 127.0, 126 / 127.0, -1, 0, 50 / 127.0, -125 / 127.0});  // -127 → -1
  expect("get_elements.gltf", 4,
         {50 / 32767.0, 45 / 32767.0, 12345 / 32767.0, 0, -1 / 32767.0, 45 / 32767.0, 12345 / 32767.0, 0});
  expect("get_elements_sparse.gltf", 0, {0, 0});            // no bufferView: zeros
  expect("get_elements_sparse.gltf", 1, {0.125, 1024});     // sparse over zeros
  expect("get_elements_sparse.gltf", 2, {70000, 100001, 54321, 200002});  // partial sparse
  // MAT2 of bytes: each 2-byte column padded to 4 bytes.
  Result<std::vector<double>> matrix = readGltfAccessor(dir + "get_elements_matrix.gltf", 0);
  ASSERT_TRUE(matrix) << matrix.error().message;
  EXPECT_EQ(*matrix, (std::vector<double>{1, 2, -3, -4, 5, 6, -7, -8}));
}

TEST(Gltf, gltfDecodesQuantizedPositions) {
  // KHR_mesh_quantization: POSITION as normalized signed bytes read from the colour bytes
  // (255 → -1/127, 0, 0 → ...): check one element against max(c/127, -1).
  TempDir dir;
  std::string json = replaced(fixtureGltf(), R"({"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
     "min": [-1, 0, 0], "max": [1, 2, 3]})",
                              R"({"bufferView": 1, "componentType": 5120, "normalized": true, "count": 3, "type": "VEC3", "byteOffset": 0})");
  json = replaced(json, R"("byteOffset": 36, "byteLength": 12})", R"("byteOffset": 36, "byteLength": 12, "byteStride": 4})");
  json = replaced(json, R"("asset": {"version": "2.0"},)",
                  R"("asset": {"version": "2.0"}, "extensionsUsed": ["KHR_mesh_quantization"],
                     "extensionsRequired": ["KHR_mesh_quantization"],)");
  // Colours then share view 1 with stride 4: fine for the reader.
  Result<PointSet> set = readText(dir, json);
  ASSERT_TRUE(set) << set.error().message;
  // Node 0 (scale 2): element 0 bytes (255, 0, 0) = (-1/127, 0, 0).
  EXPECT_EQ(set->positions[0], glm::dvec3(6378000 + 2 * (-1 / 127.0), 0, 0));
  // Element 2 bytes (51, 102, -52): (51/127, 102/127, -52/127).
  EXPECT_EQ(set->positions[2], glm::dvec3(6378000 + 2 * (51 / 127.0), 2 * (102 / 127.0), 2 * (-52 / 127.0)));
}

TEST(Gltf, gltfStripAndFanBecomeTriangleLists) {
  TempDir dir;
  // Indices 0,1,2 in mode 5 (strip): one triangle; mode 6 (fan): one triangle (1, 2, 0).
  Result<PointSet> strip = readText(dir, replaced(fixtureGltf(), R"("indices": 2, "mode": 4)", R"("indices": 2, "mode": 5)"));
  ASSERT_TRUE(strip) << strip.error().message;
  EXPECT_EQ(strip->triangles, (std::vector<uint32_t>{3, 4, 5}));
  Result<PointSet> fan = readText(dir, replaced(fixtureGltf(), R"("indices": 2, "mode": 4)", R"("indices": 2, "mode": 6)"));
  ASSERT_TRUE(fan) << fan.error().message;
  EXPECT_EQ(fan->triangles, (std::vector<uint32_t>{4, 5, 3}));
  // Lines (1): the referenced vertices as points, no triangles.
  Result<PointSet> lines = readText(dir, replaced(fixtureGltf(), R"("indices": 2, "mode": 4)", R"("indices": 2, "mode": 1)"));
  ASSERT_TRUE(lines) << lines.error().message;
  EXPECT_EQ(lines->size(), 6u);
  EXPECT_TRUE(lines->triangles.empty());
}

TEST(Gltf, gltfIndexedPrimitiveEmitsReferencedVerticesOnce) {
  // Index accessor of count 2 over (0, 1): vertex 2 is not referenced and not emitted.
  TempDir dir;
  Result<PointSet> set = readText(dir, replaced(fixtureGltf(), R"({"bufferView": 2, "componentType": 5123, "count": 3,)",
                                                R"({"bufferView": 2, "componentType": 5123, "count": 2,)"));
  ASSERT_TRUE(set) << set.error().message;
  EXPECT_EQ(set->size(), 5u);  // 3 points of node 0, 2 referenced vertices of node 1
  EXPECT_TRUE(set->triangles.empty());  // 2 indices make no triangle
}

TEST(Gltf, gltfPointsOnlyReadSkipsTrianglesNotPoints) {
  // What `convert` asks for when writing CSV, which stores no triangles.
  TempDir dir;
  test::writeFile(dir.file("scene.gltf"), fixtureGltf());
  Result<PointSet> full = readGltf(dir.file("scene.gltf"));
  GltfReadOptions options;
  options.triangles = false;
  Result<PointSet> points = readGltf(dir.file("scene.gltf"), options);
  ASSERT_TRUE(full) << full.error().message;
  ASSERT_TRUE(points) << points.error().message;
  EXPECT_FALSE(full->triangles.empty());
  EXPECT_TRUE(points->triangles.empty());
  EXPECT_EQ(points->positions, full->positions);
  EXPECT_EQ(points->colors, full->colors);
}

TEST(Gltf, gltfMeshUsedByTwoNodesIsEmittedTwice) {
  TempDir dir;
  Result<PointSet> set = readText(dir, replaced(fixtureGltf(), R"("scale": [1,1,3], "mesh": 0})", R"("scale": [1,1,3], "mesh": 1})"));
  ASSERT_TRUE(set) << set.error().message;
  EXPECT_EQ(set->size(), 6u);
  EXPECT_NE(set->positions[0], set->positions[3]);  // the second instance has its own transform
}

TEST(Gltf, gltfSceneSelection) {
  TempDir dir;
  test::writeFile(dir.file("scene.gltf"), replaced(fixtureGltf(), R"("scenes": [{"nodes": [0]}],)",
                                                   R"("scenes": [{"nodes": [0]}, {"nodes": [1]}],)"));
  GltfReadOptions options;
  options.scene = 1;  // node 1 alone: T·R·S without node 0's matrix
  Result<PointSet> one = readGltf(dir.file("scene.gltf"), options);
  ASSERT_TRUE(one) << one.error().message;
  ASSERT_EQ(one->size(), 3u);
  EXPECT_NEAR(one->positions[0].x, -2, 1e-12);
  EXPECT_NEAR(one->positions[0].y, 6, 1e-12);
  EXPECT_NEAR(one->positions[0].z, 9, 1e-12);
  options.scene = -1;
  options.all_scenes = true;
  Result<PointSet> all = readGltf(dir.file("scene.gltf"), options);
  ASSERT_TRUE(all) << all.error().message;
  EXPECT_EQ(all->size(), 9u);
  options.all_scenes = false;
  options.scene = 5;
  Result<PointSet> missing = readGltf(dir.file("scene.gltf"), options);
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("--scene: scene 5 does not exist"), std::string::npos) << missing.error().message;
  // A file without scenes is read as scene 0 (its root nodes): another does not exist (a review
  // finding: --scene 9 read scene 0 in silence).
  test::writeFile(dir.file("none.gltf"), replaced(fixtureGltf(), R"("scenes": [{"nodes": [0]}],)", ""));
  options.scene = 0;
  Result<PointSet> zero = readGltf(dir.file("none.gltf"), options);
  ASSERT_TRUE(zero) << zero.error().message;
  options.scene = 9;
  Result<PointSet> nine = readGltf(dir.file("none.gltf"), options);
  ASSERT_FALSE(nine);
  EXPECT_NE(nine.error().message.find("--scene: scene 9 does not exist (the file has no scene"), std::string::npos)
      << nine.error().message;
}

TEST(Gltf, gltfRefusesGltf1) {
  expectReadError(replaced(fixtureGltf(), R"("version": "2.0")", R"("version": "1.0")"),
                  {"/asset/version: '1.0' is not supported; only glTF 2.x"});
  expectReadError(R"({"asset": {}, "meshes": {}})", {"/asset/version: missing"});
}

TEST(Gltf, gltfRefusesRequiredCompressionByName) {
  // Draco and GPU instancing are decoded (gltf_draco_test, gltf_instancing_test); Draco's draft
  // name and the retired glTF 1.0 techniques are not.
  for (const char* name : {"KHR_draco_geometry_compression", "KHR_technique_webgl"})
    expectReadError(replaced(fixtureGltf(), R"("asset": {"version": "2.0"},)",
                             std::string(R"("asset": {"version": "2.0"}, "extensionsRequired": [")") + name + "\"],"),
                    {"/extensionsRequired/0: requires extension " + std::string(name)});
}

// The fixture's triangle mesh with EXT_meshopt_compression: positions (stride 12) and indices
// (u16) encoded by meshoptimizer itself, behind a one-byte fallback buffer that has no data.
std::string meshoptGltf() {
  const float positions[9] = {1, 2, 3, 0, 0, 0, -1, 0.5f, 2};
  const uint16_t indices[3] = {0, 1, 2};
  std::vector<unsigned char> vertex_bytes(meshopt_encodeVertexBufferBound(3, 12));
  vertex_bytes.resize(meshopt_encodeVertexBuffer(vertex_bytes.data(), vertex_bytes.size(), positions, 3, 12));
  std::vector<unsigned char> index_bytes(meshopt_encodeIndexBufferBound(3, 3));
  const unsigned int index_source[3] = {indices[0], indices[1], indices[2]};
  index_bytes.resize(meshopt_encodeIndexBuffer(index_bytes.data(), index_bytes.size(), index_source, 3));
  std::vector<unsigned char> blob = vertex_bytes;
  blob.insert(blob.end(), index_bytes.begin(), index_bytes.end());
  const std::string vertex_length = std::to_string(vertex_bytes.size());
  return R"({
  "asset": {"version": "2.0"},
  "extensionsUsed": ["EXT_meshopt_compression"],
  "extensionsRequired": ["EXT_meshopt_compression"],
  "nodes": [{"mesh": 0, "translation": [10, 0, 0]}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [-1, 0, 0], "max": [1, 2, 3]},
    {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}
  ],
  "bufferViews": [
    {"buffer": 1, "byteLength": 36, "byteStride": 12, "extensions": {"EXT_meshopt_compression":
      {"buffer": 0, "byteLength": )" + vertex_length + R"(, "byteStride": 12, "count": 3, "mode": "ATTRIBUTES"}}},
    {"buffer": 1, "byteOffset": 36, "byteLength": 6, "extensions": {"EXT_meshopt_compression":
      {"buffer": 0, "byteOffset": )" + vertex_length + ", \"byteLength\": " + std::to_string(index_bytes.size()) +
         R"(, "byteStride": 2, "count": 3, "mode": "TRIANGLES"}}}
  ],
  "buffers": [
    {"byteLength": )" + std::to_string(blob.size()) + R"(, "uri": "data:application/octet-stream;base64,)" +
         base64(blob) + R"("},
    {"byteLength": 44, "extensions": {"EXT_meshopt_compression": {"fallback": true}}}
  ]
})";
}

TEST(Gltf, gltfDecodesMeshoptViewsBehindFallbackBuffer) {
  TempDir dir;
  Result<PointSet> set = readText(dir, meshoptGltf());
  ASSERT_TRUE(set) << set.error().message;
  const PositionArray expected = {{11, 2, 3}, {10, 0, 0}, {9, 0.5, 2}};
  EXPECT_EQ(set->positions, expected);
  EXPECT_EQ(set->triangles, (std::vector<uint32_t>{0, 1, 2}));
}

TEST(Gltf, gltfMeshoptRejectsCountTimesStrideNotViewLength) {
  expectReadError(replaced(meshoptGltf(), R"("byteStride": 12, "count": 3)", R"("byteStride": 12, "count": 4)"),
                  {"/bufferViews/0/extensions/EXT_meshopt_compression: count 4 * byteStride 12 = 48 differs from "
                   "the view's byteLength 36"});
}

TEST(Gltf, gltfMeshoptRejectsBadStrideAndMode) {
  expectReadError(replaced(meshoptGltf(), R"("byteStride": 12, "count": 3)", R"("byteStride": 6, "count": 6)"),
                  {"/bufferViews/0/extensions/EXT_meshopt_compression/byteStride: 6 is not a multiple of 4"});
  expectReadError(replaced(meshoptGltf(), R"("mode": "TRIANGLES")", R"("mode": "STRIPS")"),
                  {"/bufferViews/1/extensions/EXT_meshopt_compression/mode: 'STRIPS' is not ATTRIBUTES"});
  expectReadError(replaced(meshoptGltf(), R"("mode": "TRIANGLES")", R"("mode": "TRIANGLES", "filter": "OCTAHEDRAL")"),
                  {"/filter: 'OCTAHEDRAL' is only allowed with mode ATTRIBUTES"});
}

TEST(Gltf, gltfMeshoptRejectsSourcePastBufferAndCorruptData) {
  expectReadError(replaced(meshoptGltf(), R"("buffer": 0, "byteLength": )", R"("buffer": 0, "byteOffset": 1000, "byteLength": )"),
                  {"/bufferViews/0/extensions/EXT_meshopt_compression: byteOffset 1000 + byteLength"});
  // The index data decoded as vertices: meshoptimizer's own checks must refuse it.
  std::string json = meshoptGltf();
  json.insert(json.find("\"mode\": \"ATTRIBUTES\""), R"("byteOffset": 1, )");
  expectReadError(json, {"/bufferViews/0/extensions/EXT_meshopt_compression: meshoptimizer could not decode"});
}

TEST(Gltf, gltfMeshoptRejectsFieldTinygltfWouldWrap) {
  expectReadError(replaced(meshoptGltf(), R"("byteStride": 12, "count": 3)", R"("byteStride": 12, "count": 4294967299)"),
                  {"/bufferViews/0/extensions/EXT_meshopt_compression/count: must be an integer"});
}

TEST(Gltf, gltfRejectsDeepNesting) {
  const std::string deep = R"({"asset": {"version": "2.0"}, "extras": )" + std::string(200000, '[') +
                           std::string(200000, ']') + "}";
  expectReadError(deep, {"JSON nested deeper than 64 levels"});
}

TEST(Gltf, gltfRejectsIntegersTinygltfWouldMangle) {
  expectReadError(replaced(fixtureGltf(), R"("byteOffset": 48, "byteLength": 6)", R"("byteOffset": -4, "byteLength": 6)"),
                  {"/bufferViews/2/byteOffset: must be an integer"});
  expectReadError(replaced(fixtureGltf(), R"("indices": 2,)", R"("indices": 4294967298,)"),
                  {"/meshes/0/primitives/0/indices: must be an integer"});
}

TEST(Gltf, gltfRefusesUriThatIsAFolder) {
  for (const char* uri : {".", "..", "/etc/passwd", "sub/../../x.bin"}) {
    std::string json = fixtureGltf();
    const size_t at = json.find("data:application");
    json.replace(at, json.find('"', at) - at, uri);
    expectReadError(json, {"/buffers/0/uri"});
  }
}

TEST(Gltf, glbRejectsChunkPastTheEnd) {
  TempDir dir;
  ASSERT_TRUE(writeGlb(dir.file("cloud.glb"), offsetCloud()));
  std::string bytes = test::readFile(dir.file("cloud.glb"));
  uint32_t json_length;
  std::memcpy(&json_length, bytes.data() + 12, 4);
  // The BIN chunk claims 4 bytes more than remain (tinygltf would read past the end).
  const size_t bin = 20 + json_length;
  uint32_t bin_length;
  std::memcpy(&bin_length, bytes.data() + bin, 4);
  bin_length += 4;
  std::memcpy(bytes.data() + bin, &bin_length, 4);
  test::writeFile(dir.file("bad.glb"), bytes);
  Result<PointSet> set = readGltf(dir.file("bad.glb"));
  ASSERT_FALSE(set);
  EXPECT_NE(set.error().message.find("GLB: chunk 1 at byte " + std::to_string(bin) + ": length"), std::string::npos)
      << set.error().message;
}

TEST(Gltf, gltfNonFinitePositionIsAnErrorUnlessAllowed) {
  TempDir dir;
  // Scale node 1 by 1e308 twice over: finite input, infinite world position.
  const std::string json = replaced(fixtureGltf(), R"("scale": [1,1,3])", R"("scale": [1e308,1,3])");
  test::writeFile(dir.file("scene.gltf"), json);
  Result<PointSet> set = readGltf(dir.file("scene.gltf"));
  ASSERT_FALSE(set);
  EXPECT_NE(set.error().message.find("/accessors/0: POSITION element 0 is not finite in world space"),
            std::string::npos) << set.error().message;
  GltfReadOptions options;
  options.allow_nonfinite = true;
  EXPECT_TRUE(readGltf(dir.file("scene.gltf"), options));
}

TEST(Gltf, gltfMaxPointsRefusesWithResourceLimit) {
  TempDir dir;
  test::writeFile(dir.file("scene.gltf"), fixtureGltf());
  GltfReadOptions options;
  options.max_points = 5;
  Result<PointSet> set = readGltf(dir.file("scene.gltf"), options);
  ASSERT_FALSE(set);
  EXPECT_EQ(set.error().code, ExitCode::kResourceLimit);
  options.max_points = 6;
  EXPECT_TRUE(readGltf(dir.file("scene.gltf"), options));
}

TEST(Gltf, uniqueKeepsFirstOccurrenceAndRenumbersTriangles) {
  PointSet set;
  set.positions = {{0, 0, 0}, {1, 0, 0}, {-0.0, 0, 0}, {0, 1, 0}, {1, 0, 0}};
  set.colors = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {0, 1, 1}};
  set.triangles = {0, 1, 3, 2, 4, 3, 0, 2, 1};  // the last loses a corner: 0 and 2 merge
  dropDuplicatePositions(set);
  EXPECT_EQ(set.positions, (PositionArray{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));
  EXPECT_EQ(set.colors, (ColorArray{{1, 0, 0}, {0, 1, 0}, {1, 1, 0}}));
  EXPECT_EQ(set.triangles, (std::vector<uint32_t>{0, 1, 2, 0, 1, 2}));
}

TEST(Gltf, srgb8EncodesLinearColours) {
  PointSet set;
  set.positions = {{0, 0, 0}};
  set.colors = {{0.0f, 1.0f, 0.5f}};
  encodeColorsSrgb8(set);
  // linear 0.5 → sRGB 0.7354 → 188/255.
  EXPECT_EQ(set.colors[0], glm::vec3(0.0f, 1.0f, float(188 / 255.0)));
}

// `dpoint render --color elevation`: viridis along the chosen axis, lowest dark purple (its first
// stop #440154), highest yellow (#fde725), whatever the thread count; a flat set in the middle.
TEST(PointFilters, colorByElevationMapsTheAxisRangeOntoViridis) {
  PointSet set;
  for (int i = 0; i <= 200000; ++i) set.positions.push_back({6.378e6, 0.5 * i, -1.0});
  PointSet other = set;
  colorByElevation(set, 1, 1);
  colorByElevation(other, 1, 2);
  ASSERT_EQ(set.colors.size(), set.size());
  EXPECT_EQ(set.colors, other.colors);
  EXPECT_EQ(set.colors.front(), glm::vec3(0x44, 0x01, 0x54) / 255.0f);
  EXPECT_EQ(set.colors.back(), glm::vec3(0xfd, 0xe7, 0x25) / 255.0f);
  for (size_t i = 1; i < set.size(); i += 997) EXPECT_GE(set.colors[i].g, set.colors[i - 1].g) << i;
  colorByElevation(set, 2);  // every z is -1
  EXPECT_EQ(set.colors.front(), set.colors.back());
  EXPECT_EQ(set.colors.front(), glm::vec3(0x21, 0x90, 0x8c) / 255.0f) << "the middle stop";
}

// --- The official Khronos validator --------------------------------------------------------------

TEST(Gltf, glbPassesOfficialValidator) {
  const std::string node = "/usr/bin/node";
  if (!test::fileExists(node) ||
      !test::fileExists(std::string(DPOINT_GLTF_VALIDATOR) + "/package.json"))
    GTEST_SKIP() << "node or the glTF validator is not installed";
  TempDir dir;
  ASSERT_TRUE(writeGlb(dir.file("points.glb"), offsetCloud()));
  ASSERT_TRUE(writeGlb(dir.file("mesh.glb"), tetrahedron(true)));
  ASSERT_TRUE(writeGlb(dir.file("plain.glb"), tetrahedron(false)));
  const std::string script =
      "const v = require(process.argv[1]); const fs = require('fs');"
      "v.validateBytes(new Uint8Array(fs.readFileSync(process.argv[2]))).then(r => {"
      "  console.log(r.issues.numErrors + ' errors ' + r.issues.numWarnings + ' warnings');"
      "  console.log(JSON.stringify(r.issues.messages));"
      "}).catch(e => { console.error(String(e)); process.exit(1); });";
  for (const char* name : {"points.glb", "mesh.glb", "plain.glb"}) {
    test::CommandResult r =
        test::runCommand({node, "-e", script, DPOINT_GLTF_VALIDATOR, dir.file(name)});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out.rfind("0 errors 0 warnings\n", 0), 0u) << name << ": " << r.out;
  }
}

}  // namespace
}  // namespace dpoint
