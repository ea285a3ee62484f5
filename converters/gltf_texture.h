// glTF base-colour textures for the mesh sampler (internal to converters/; ops/mesh_texture.h is
// what they become). A primitive's material names its pbrMetallicRoughness.baseColorTexture: a
// texture (its image and sampler) and the TEXCOORD_n set, perhaps moved by KHR_texture_transform.
// Images are PNG or JPEG, decoded by Debian's libstb (stb_image) when first used, 8-bit sRGB to
// linear; an image in another format (KTX2, WebP), or one that does not decode, leaves its
// primitives untextured, with a note in MeshTexture::notes, never an error.
#pragma once

#include <tiny_gltf.h>

#include <glm/glm.hpp>

#include <cstdint>
#include <map>
#include <string>

#include "core/result.h"
#include "ops/mesh_texture.h"

namespace dpoint {

// How a primitive is textured: its image in MeshTexture::images (-1: none), the TEXCOORD set and
// the transform of its coordinates (KHR_texture_transform; identity without).
struct GltfTextureUse {
  int32_t image = -1;
  int tex_coord = 0;
  glm::dmat3 transform{1.0};
};

class GltfTextures {
 public:
  // Decoded images go to `out.images` (and notes to `out.notes`); together they stay under
  // memory_limit bytes, else the next is refused (kResourceLimit).
  GltfTextures(const std::string& path, const tinygltf::Model& model, uint64_t memory_limit, MeshTexture& out)
      : path_(path), model_(model), memory_limit_(memory_limit), out_(out) {}

  // The primitive's base-colour texture, decoded on first use. Errors: a material, texture, image
  // or sampler index out of range, a bad KHR_texture_transform (each naming its JSON pointer).
  Result<GltfTextureUse> use(const tinygltf::Primitive& primitive, const std::string& pointer);

 private:
  Result<int32_t> image(int texture);
  void note(const std::string& what);

  const std::string& path_;
  const tinygltf::Model& model_;
  uint64_t memory_limit_, memory_used_ = 0;
  MeshTexture& out_;
  std::map<int, int32_t> decoded_;  // glTF texture index: its image in out_.images, or -1
};

}  // namespace dpoint
