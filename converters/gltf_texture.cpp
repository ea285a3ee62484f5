#include "converters/gltf_texture.h"

#include <stb_image.h>

#include <cmath>
#include <cstdint>
#include <cstring>

#include "core/memory.h"

namespace dpoint {
namespace {

constexpr int kNearest = 9728, kClampToEdge = 33071, kMirroredRepeat = 33648;  // glTF sampler enums

TextureWrap wrapOf(int mode) {
  if (mode == kClampToEdge) return TextureWrap::kClampToEdge;
  if (mode == kMirroredRepeat) return TextureWrap::kMirroredRepeat;
  return TextureWrap::kRepeat;  // 10497, the default
}

bool finiteNumber(const tinygltf::Value& v) { return v.IsNumber() && std::isfinite(v.GetNumberAsDouble()); }

// A KHR_texture_transform pair (offset, scale): 2 finite numbers.
bool readPair(const tinygltf::Value& v, double& a, double& b) {
  if (!v.IsArray() || v.ArrayLen() != 2 || !finiteNumber(v.Get(0)) || !finiteNumber(v.Get(1))) return false;
  a = v.Get(0).GetNumberAsDouble();
  b = v.Get(1).GetNumberAsDouble();
  return true;
}

// Whether every chunk of a PNG lies within its bytes, up to IEND (true for what is no PNG: stb_image
// judges it). stb_image grows its buffer to an IDAT's declared length before reading it: a fuzz
// finding's 2.4 KB image declaring 1.7 GB took 1.4 s under the sanitizers (a timeout), refused now
// as the bad image it is.
bool pngChunksFit(const unsigned char* bytes, size_t size) {
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (size < 8 || std::memcmp(bytes, kSignature, 8) != 0) return true;
  for (size_t at = 8; at + 8 <= size;) {
    const uint64_t length = (uint64_t{bytes[at]} << 24) | (uint64_t{bytes[at + 1]} << 16) |
                            (uint64_t{bytes[at + 2]} << 8) | uint64_t{bytes[at + 3]};
    if (length + 12 > size - at) return false;  // length, type, data, CRC
    if (std::memcmp(bytes + at + 4, "IEND", 4) == 0) return true;
    at += 12 + length;
  }
  return true;  // no IEND: stb_image says what it makes of that
}

}  // namespace

Result<GltfTextureUse> GltfTextures::use(const tinygltf::Primitive& primitive, const std::string& pointer) {
  GltfTextureUse use;
  if (primitive.material == -1) return use;  // tinygltf's "no material"
  if (primitive.material < 0 || size_t(primitive.material) >= model_.materials.size())
    return Error{path_ + ": " + pointer + "/material: material " + std::to_string(primitive.material) + " does not exist"};
  const std::string at = "/materials/" + std::to_string(primitive.material) + "/pbrMetallicRoughness/baseColorTexture";
  const tinygltf::TextureInfo& info = model_.materials[size_t(primitive.material)].pbrMetallicRoughness.baseColorTexture;
  if (info.index == -1) return use;
  if (info.index < 0 || size_t(info.index) >= model_.textures.size())
    return Error{path_ + ": " + at + "/index: texture " + std::to_string(info.index) + " does not exist"};
  if (info.texCoord < 0) return Error{path_ + ": " + at + "/texCoord: " + std::to_string(info.texCoord) + " is below 0"};
  use.tex_coord = info.texCoord;
  if (auto ext = info.extensions.find("KHR_texture_transform"); ext != info.extensions.end()) {
    const std::string in = at + "/extensions/KHR_texture_transform";
    const tinygltf::Value& t = ext->second;
    if (!t.IsObject()) return Error{path_ + ": " + in + ": must be an object"};
    double ox = 0, oy = 0, sx = 1, sy = 1, rotation = 0;
    if (t.Has("offset") && !readPair(t.Get("offset"), ox, oy))
      return Error{path_ + ": " + in + "/offset: must be 2 finite numbers"};
    if (t.Has("scale") && !readPair(t.Get("scale"), sx, sy)) return Error{path_ + ": " + in + "/scale: must be 2 finite numbers"};
    if (t.Has("rotation")) {
      if (!finiteNumber(t.Get("rotation"))) return Error{path_ + ": " + in + "/rotation: must be a finite number"};
      rotation = t.Get("rotation").GetNumberAsDouble();
    }
    if (t.Has("texCoord")) {
      const tinygltf::Value& set = t.Get("texCoord");
      if (!finiteNumber(set) || set.GetNumberAsDouble() < 0 || set.GetNumberAsDouble() > 65535 ||
          set.GetNumberAsDouble() != std::floor(set.GetNumberAsDouble()))
        return Error{path_ + ": " + in + "/texCoord: must be a whole number from 0"};
      use.tex_coord = int(set.GetNumberAsDouble());
    }
    // The extension's matrix, translation · rotation · scale, on (u, v, 1); glm is column-major.
    glm::dmat3 translate(1.0), rotate(1.0), scale(1.0);
    translate[2][0] = ox, translate[2][1] = oy;
    rotate[0][0] = std::cos(rotation), rotate[1][0] = std::sin(rotation);
    rotate[0][1] = -std::sin(rotation), rotate[1][1] = std::cos(rotation);
    scale[0][0] = sx, scale[1][1] = sy;
    use.transform = translate * rotate * scale;
  }
  Result<int32_t> decoded = image(info.index);
  if (!decoded) return decoded.error();
  use.image = *decoded;
  return use;
}

void GltfTextures::note(const std::string& what) {
  out_.notes.push_back(path_ + ": " + what + "; its triangles are sampled without it");
}

Result<int32_t> GltfTextures::image(int texture) {
  if (auto found = decoded_.find(texture); found != decoded_.end()) return found->second;
  decoded_[texture] = -1;  // a texture that cannot be used is noted once
  const std::string at = "/textures/" + std::to_string(texture);
  const tinygltf::Texture& t = model_.textures[size_t(texture)];
  if (t.source == -1) {
    note(at + " has no PNG or JPEG source (a KTX2 or WebP image is not decoded)");
    return -1;
  }
  if (t.source < 0 || size_t(t.source) >= model_.images.size())
    return Error{path_ + ": " + at + "/source: image " + std::to_string(t.source) + " does not exist"};
  if (t.sampler != -1 && (t.sampler < 0 || size_t(t.sampler) >= model_.samplers.size()))
    return Error{path_ + ": " + at + "/sampler: sampler " + std::to_string(t.sampler) + " does not exist"};
  const std::string image_at = "/images/" + std::to_string(t.source);
  const tinygltf::Image& image = model_.images[size_t(t.source)];
  const unsigned char* bytes = nullptr;
  size_t size = 0;
  if (image.bufferView >= 0) {
    if (size_t(image.bufferView) >= model_.bufferViews.size())
      return Error{path_ + ": " + image_at + "/bufferView: bufferView " + std::to_string(image.bufferView) + " does not exist"};
    const tinygltf::BufferView& view = model_.bufferViews[size_t(image.bufferView)];
    if (view.buffer < 0 || size_t(view.buffer) >= model_.buffers.size() ||
        view.byteOffset > model_.buffers[size_t(view.buffer)].data.size() ||
        view.byteLength > model_.buffers[size_t(view.buffer)].data.size() - view.byteOffset)
      return Error{path_ + ": " + image_at + ": its bufferView lies outside its buffer"};
    bytes = model_.buffers[size_t(view.buffer)].data.data() + view.byteOffset;
    size = view.byteLength;
  } else {
    bytes = image.image.data();
    size = image.image.size();
  }
  if (size == 0) {
    note(image_at + " was not read (a missing file, or beyond --max-memory)");
    return -1;
  }
  if (size > size_t(INT32_MAX)) {
    note(image_at + " is larger than 2 GiB");
    return -1;
  }
  if (!pngChunksFit(bytes, size)) {
    note(image_at + " (a PNG) did not decode (a chunk's length runs past the image's bytes)");
    return -1;
  }
  int width = 0, height = 0, channels = 0;
  if (!stbi_info_from_memory(bytes, int(size), &width, &height, &channels) || width <= 0 || height <= 0) {
    note(image_at + " (" + (image.mimeType.empty() ? std::string("no mimeType") : image.mimeType) +
         ") is not a PNG or JPEG image that can be decoded");
    return -1;
  }
  // stb_image's 8-bit texels, then ours as floats.
  const uint64_t texels = uint64_t(width) * uint64_t(height);
  const uint64_t needed = texels * 3 * (1 + sizeof(float));
  if (Status s = checkMemory(path_ + ": " + image_at + " (" + std::to_string(width) + "x" + std::to_string(height) + ")",
                             memory_used_ + needed, memory_limit_);
      !s)
    return s.error();
  stbi_uc* pixels = stbi_load_from_memory(bytes, int(size), &width, &height, &channels, 3);
  if (!pixels) {
    note(image_at + " did not decode (" + std::string(stbi_failure_reason() ? stbi_failure_reason() : "no reason") + ")");
    return -1;
  }
  memory_used_ += needed;
  TextureImage decoded;
  decoded.width = uint32_t(width);
  decoded.height = uint32_t(height);
  decoded.rgb.resize(size_t(texels) * 3);
  for (size_t i = 0; i < decoded.rgb.size(); ++i) decoded.rgb[i] = srgb8ToLinear(pixels[i]);
  stbi_image_free(pixels);
  if (t.sampler != -1) {
    const tinygltf::Sampler& sampler = model_.samplers[size_t(t.sampler)];
    decoded.wrap_s = wrapOf(sampler.wrapS);
    decoded.wrap_t = wrapOf(sampler.wrapT);
    decoded.nearest = sampler.magFilter == kNearest;
  }
  out_.images.push_back(std::move(decoded));
  decoded_[texture] = int32_t(out_.images.size() - 1);
  return decoded_[texture];
}

}  // namespace dpoint
