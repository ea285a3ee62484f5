// A mesh's base-colour textures, for the points sampled on its surface (ops/mesh_sample.h): glTF's
// pbrMetallicRoughness.baseColorTexture, which converters/gltf_read.h reads when asked
// (GltfReadOptions::texture). It travels beside the PointSet, not in it: a texture coordinate
// means something only with its image, and only until the set's vertices are renumbered, so the
// sampler takes the two straight from the reader.
//
// A sample's colour is its triangle's vertex colours interpolated (white where the mesh has none)
// times the texel at its interpolated texture coordinate (glTF 2.0 §3.9.2: baseColorFactor ·
// texture · COLOR_0), looked up as the texture's sampler says: wrapS/wrapT REPEAT,
// MIRRORED_REPEAT or CLAMP_TO_EDGE, magFilter NEAREST or else bilinear (a sample is a point, so
// the minification filter's mipmaps do not apply).
#pragma once

#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace dpoint {

enum class TextureWrap { kRepeat, kMirroredRepeat, kClampToEdge };

struct TextureImage {
  uint32_t width = 0, height = 0;
  // Linear 0..1 RGB, 3 floats a texel, rows from the image's top: texture coordinate (0, 0) is the
  // first texel's top-left corner (glTF 2.0 §3.8.4.6).
  std::vector<float> rgb;
  TextureWrap wrap_s = TextureWrap::kRepeat, wrap_t = TextureWrap::kRepeat;
  bool nearest = false;  // magFilter NEAREST; else bilinear
};

struct MeshTexture {
  std::vector<TextureImage> images;
  // Per vertex of the mesh: its texture coordinate (KHR_texture_transform applied); (0, 0) for a
  // vertex of an untextured primitive.
  std::vector<glm::vec2> uv;
  // Per triangle of the mesh: its image in `images`, or -1 for none.
  std::vector<int32_t> triangle_image;
  // What the reader could not use (an image in a format it cannot decode), one line each.
  std::vector<std::string> notes;

  // True when some triangle has an image: the sample then has colours.
  bool textures() const;
};

// The texel colour at `uv`, as the image's sampler says.
glm::vec3 textureColour(const TextureImage& image, glm::dvec2 uv);

// The sRGB transfer function's inverse (IEC 61966-2-1) of an 8-bit value: a texel's linear value.
float srgb8ToLinear(uint8_t value);

}  // namespace dpoint
