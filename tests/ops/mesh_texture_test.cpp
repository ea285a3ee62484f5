// Texture colours on a mesh's surface samples (ops/mesh_texture.h, converters/gltf_texture.h): the
// lookup's wrap modes and filters, a glTF quad whose every sample must take the texel under it
// (with and without KHR_texture_transform), and BoxTextured stored three ways.
#include "ops/mesh_texture.h"

#include <gtest/gtest.h>

#include <stb_image_write.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "converters/gltf_read.h"
#include "ops/mesh_sample.h"
#include "test_support.h"

namespace dpoint {
namespace {

const std::string kModels = "/usr/share/assimp/models/glTF2/";

// A 2x2 texture: red, green (top row), blue, white; exact in linear (0 and 1).
TextureImage quadrants(TextureWrap wrap, bool nearest) {
  TextureImage image;
  image.width = image.height = 2;
  image.rgb = {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
  image.wrap_s = image.wrap_t = wrap;
  image.nearest = nearest;
  return image;
}

const glm::vec3 kRed(1, 0, 0), kGreen(0, 1, 0), kBlue(0, 0, 1), kWhite(1, 1, 1);

TEST(MeshTexture, lookupWrapsAndFiltersAsTheSamplerSays) {
  const TextureImage repeat = quadrants(TextureWrap::kRepeat, true);
  EXPECT_EQ(textureColour(repeat, {0.25, 0.25}), kRed);
  EXPECT_EQ(textureColour(repeat, {0.75, 0.25}), kGreen);
  EXPECT_EQ(textureColour(repeat, {0.25, 0.75}), kBlue);
  EXPECT_EQ(textureColour(repeat, {0.75, 0.75}), kWhite);
  EXPECT_EQ(textureColour(repeat, {1.25, -0.75}), kRed);  // one period on, one back
  EXPECT_EQ(textureColour(repeat, {-0.25, 0.25}), kGreen);
  const TextureImage mirror = quadrants(TextureWrap::kMirroredRepeat, true);
  EXPECT_EQ(textureColour(mirror, {1.25, 0.25}), kGreen);  // the mirrored copy starts with the last column
  EXPECT_EQ(textureColour(mirror, {2.25, 0.25}), kRed);
  EXPECT_EQ(textureColour(mirror, {-0.25, 0.25}), kRed);
  const TextureImage clamp = quadrants(TextureWrap::kClampToEdge, true);
  EXPECT_EQ(textureColour(clamp, {5.0, 0.25}), kGreen);
  EXPECT_EQ(textureColour(clamp, {-3.0, 0.75}), kBlue);
  EXPECT_EQ(textureColour(clamp, {1e300, std::nan("")}), kGreen);  // no overflow: far right, row 0
  // Bilinear: halfway between the centres of red and green, and at a texel's centre exactly.
  const TextureImage linear = quadrants(TextureWrap::kClampToEdge, false);
  const glm::vec3 half = textureColour(linear, {0.5, 0.25});
  EXPECT_FLOAT_EQ(half.r, 0.5f);
  EXPECT_FLOAT_EQ(half.g, 0.5f);
  EXPECT_FLOAT_EQ(half.b, 0.0f);
  EXPECT_EQ(textureColour(linear, {0.75, 0.75}), kWhite);
  EXPECT_EQ(srgb8ToLinear(0), 0.0f);
  EXPECT_EQ(srgb8ToLinear(255), 1.0f);
  EXPECT_NEAR(srgb8ToLinear(188), 0.5029, 1e-4);
}

// A unit quad in z = 0 with texture coordinates (x, 1 − y) and the 2x2 quadrant texture as a PNG
// beside it; `transform` is a KHR_texture_transform object or empty.
std::string writeQuad(const test::TempDir& dir, const std::string& transform, const std::string& image = "tex.png") {
  const unsigned char texels[12] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255};
  EXPECT_TRUE(stbi_write_png(dir.file("tex.png").c_str(), 2, 2, 3, texels, 6));
  const float positions[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  const float uv[8] = {0, 1, 1, 1, 1, 0, 0, 0};
  const uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
  std::string bin(reinterpret_cast<const char*>(positions), sizeof positions);
  bin.append(reinterpret_cast<const char*>(uv), sizeof uv);
  bin.append(reinterpret_cast<const char*>(indices), sizeof indices);
  test::writeFile(dir.file("quad.bin"), bin);
  const std::string info = transform.empty() ? R"({"index": 0})"
                                             : R"({"index": 0, "extensions": {"KHR_texture_transform": )" + transform + "}}";
  const std::string json = R"({"asset": {"version": "2.0"}, "extensionsUsed": ["KHR_texture_transform"],
  "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
  "materials": [{"pbrMetallicRoughness": {"baseColorTexture": )" + info + R"(}}],
  "textures": [{"source": 0, "sampler": 0}], "samplers": [{"magFilter": 9728, "wrapS": 10497, "wrapT": 10497}],
  "images": [{"uri": ")" + image + R"("}],
  "buffers": [{"uri": "quad.bin", "byteLength": 92}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                  {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
    {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
    {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}]})";
  test::writeFile(dir.file("quad.gltf"), json);
  return dir.file("quad.gltf");
}

PointSet sampleWithTexture(const std::string& path, MeshTexture& texture, uint64_t count) {
  GltfReadOptions read;
  read.texture = &texture;
  Result<PointSet> mesh = readGltf(path, read);
  EXPECT_TRUE(mesh.ok()) << (mesh.ok() ? "" : mesh.error().message);
  if (!mesh) return {};
  SampleOptions options;
  options.count = count;
  options.texture = &texture;
  options.threads = 3;
  Result<PointSet> sample = sampleSurface(*mesh, options, path);
  EXPECT_TRUE(sample.ok()) << (sample.ok() ? "" : sample.error().message);
  return sample.ok() ? std::move(*sample) : PointSet{};
}

// The texel under (x, y) of the quad: u = x·scale, v = (1 − y)·scale, repeated; nullopt within
// 1e-9 of a texel's edge, where rounding may take either side.
std::optional<glm::vec3> texelUnder(glm::dvec3 p, double scale) {
  const double u = p.x * scale * 2.0, v = (1.0 - p.y) * scale * 2.0;
  if (std::fabs(u - std::round(u)) < 1e-9 || std::fabs(v - std::round(v)) < 1e-9) return std::nullopt;
  const int column = int(std::floor(u)) % 2, row = int(std::floor(v)) % 2;
  const glm::vec3 texels[2][2] = {{kRed, kGreen}, {kBlue, kWhite}};
  return texels[row][column];
}

TEST(MeshTexture, everySampleOfAGltfQuadTakesTheTexelUnderIt) {
  for (const auto& [transform, scale] : {std::pair<std::string, double>{"", 1.0}, {R"({"scale": [2, 2]})", 2.0}}) {
    SCOPED_TRACE(transform);
    test::TempDir dir;
    MeshTexture texture;
    const PointSet sample = sampleWithTexture(writeQuad(dir, transform), texture, 4000);
    ASSERT_EQ(sample.size(), 4000u);
    ASSERT_TRUE(sample.hasColors());
    EXPECT_TRUE(texture.notes.empty());
    ASSERT_EQ(texture.images.size(), 1u);
    EXPECT_EQ(texture.images[0].width, 2u);
    size_t checked = 0, wrong = 0;
    std::set<std::tuple<float, float, float>> seen;
    for (size_t i = 0; i < sample.size(); ++i) {
      const std::optional<glm::vec3> want = texelUnder(sample.positions[i], scale);
      if (!want) continue;
      ++checked;
      if (sample.colors[i] != *want) ++wrong;
      seen.insert({sample.colors[i].r, sample.colors[i].g, sample.colors[i].b});
    }
    EXPECT_GT(checked, 3990u);
    EXPECT_EQ(wrong, 0u);
    EXPECT_EQ(seen.size(), 4u);
  }
}

TEST(MeshTexture, anImageThatDoesNotDecodeLeavesANoteAndTheVertexColours) {
  test::TempDir dir;
  const std::string path = writeQuad(dir, "", "broken.png");
  test::writeFile(dir.file("broken.png"), "\x89PNG\r\n\x1a\n not a png at all");
  MeshTexture texture;
  const PointSet sample = sampleWithTexture(path, texture, 100);
  ASSERT_EQ(sample.size(), 100u);
  EXPECT_FALSE(sample.hasColors());  // no texture, no vertex colours
  ASSERT_EQ(texture.notes.size(), 1u);
  EXPECT_NE(texture.notes[0].find("/images/0"), std::string::npos) << texture.notes[0];
  EXPECT_NE(texture.notes[0].find("sampled without it"), std::string::npos) << texture.notes[0];
}

// A fuzz finding: a PNG whose IDAT declares 1.7 GB in 2.4 KB made stb_image grow its buffer to that
// first (1.4 s under the sanitizers). Its chunks are checked against its bytes: a note, at once.
TEST(MeshTexture, aPngWhoseChunkRunsPastItsBytesLeavesANote) {
  test::TempDir dir;
  const std::string path = writeQuad(dir, "", "cut.png");
  std::string png("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR\0\0\0\x02\0\0\0\x02\x08\x02\0\0\0\0\0\0\0", 33);
  png += std::string("\x65\x72\x6f\x8b", 4) + "IDAT" + std::string(64, 'x');  // 1.7 GB declared
  test::writeFile(dir.file("cut.png"), png);
  MeshTexture texture;
  const PointSet sample = sampleWithTexture(path, texture, 100);
  ASSERT_EQ(sample.size(), 100u);
  ASSERT_EQ(texture.notes.size(), 1u);
  EXPECT_NE(texture.notes[0].find("a chunk's length runs past the image's bytes"), std::string::npos) << texture.notes[0];
}

// BoxTextured as a GLB (the PNG in a bufferView) and as a .gltf with a data URI: the same samples
// in the same colours, the logo's (several colours, not only white); the .gltf with the PNG beside
// it samples MIRRORED_REPEAT and CLAMP_TO_EDGE, so its colours differ where u passes 1.
TEST(MeshTexture, boxTexturedStoredThreeWaysIsSampledInItsTexturesColours) {
  MeshTexture glb_texture, embedded_texture, file_texture;
  const PointSet glb = sampleWithTexture(kModels + "BoxTextured-glTF-Binary/BoxTextured.glb", glb_texture, 20000);
  const PointSet embedded =
      sampleWithTexture(kModels + "BoxTextured-glTF-Embedded/BoxTextured.gltf", embedded_texture, 20000);
  const PointSet file = sampleWithTexture(kModels + "BoxTextured-glTF/BoxTextured.gltf", file_texture, 20000);
  ASSERT_TRUE(glb.hasColors() && embedded.hasColors() && file.hasColors());
  EXPECT_EQ(glb.positions, embedded.positions);
  EXPECT_EQ(glb.colors, embedded.colors);
  EXPECT_EQ(glb.positions, file.positions);
  EXPECT_NE(glb.colors, file.colors);
  ASSERT_EQ(glb_texture.images.size(), 1u);
  EXPECT_EQ(file_texture.images[0].wrap_s, TextureWrap::kMirroredRepeat);
  EXPECT_EQ(file_texture.images[0].wrap_t, TextureWrap::kClampToEdge);
  std::set<std::tuple<float, float, float>> colours;
  size_t white = 0;
  for (const glm::vec3& c : glb.colors) {
    colours.insert({c.r, c.g, c.b});
    if (c == kWhite) ++white;
  }
  EXPECT_GT(colours.size(), 100u);
  EXPECT_LT(white, glb.size() / 2);
}

}  // namespace
}  // namespace dpoint
