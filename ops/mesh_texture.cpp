#include "ops/mesh_texture.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace dpoint {
namespace {

// Texel column or row `i` (any integer) of a side of `n` texels, wrapped as the sampler says.
uint32_t wrapped(int64_t i, uint32_t n, TextureWrap wrap) {
  const int64_t size = n;
  switch (wrap) {
    case TextureWrap::kClampToEdge:
      return static_cast<uint32_t>(std::clamp<int64_t>(i, 0, size - 1));
    case TextureWrap::kMirroredRepeat: {
      int64_t m = i % (2 * size);
      if (m < 0) m += 2 * size;
      return static_cast<uint32_t>(m < size ? m : 2 * size - 1 - m);
    }
    case TextureWrap::kRepeat:
      break;
  }
  int64_t m = i % size;
  if (m < 0) m += size;
  return static_cast<uint32_t>(m);
}

glm::vec3 texel(const TextureImage& image, uint32_t x, uint32_t y) {
  const float* t = &image.rgb[3 * (size_t{y} * image.width + x)];
  return {t[0], t[1], t[2]};
}

// A texture coordinate in texels, bounded so that its floor fits an int64 (a coordinate of 1e30
// repeats the texture as often as one of 2^52 does, to double's precision).
double inTexels(double coordinate, uint32_t size) {
  if (!std::isfinite(coordinate)) return 0.0;
  return std::clamp(coordinate * size, -4.5e15, 4.5e15);
}

}  // namespace

bool MeshTexture::textures() const {
  return !images.empty() && std::any_of(triangle_image.begin(), triangle_image.end(), [](int32_t i) { return i >= 0; });
}

glm::vec3 textureColour(const TextureImage& image, glm::dvec2 uv) {
  if (image.width == 0 || image.height == 0) return glm::vec3(1.0f);
  const double x = inTexels(uv.x, image.width), y = inTexels(uv.y, image.height);
  if (image.nearest)
    return texel(image, wrapped(static_cast<int64_t>(std::floor(x)), image.width, image.wrap_s),
                 wrapped(static_cast<int64_t>(std::floor(y)), image.height, image.wrap_t));
  // Bilinear between the four texels whose centres surround the point.
  const double fx = std::floor(x - 0.5), fy = std::floor(y - 0.5);
  const float ax = static_cast<float>(x - 0.5 - fx), ay = static_cast<float>(y - 0.5 - fy);
  const int64_t i = static_cast<int64_t>(fx), j = static_cast<int64_t>(fy);
  const uint32_t x0 = wrapped(i, image.width, image.wrap_s), x1 = wrapped(i + 1, image.width, image.wrap_s);
  const uint32_t y0 = wrapped(j, image.height, image.wrap_t), y1 = wrapped(j + 1, image.height, image.wrap_t);
  const glm::vec3 top = glm::mix(texel(image, x0, y0), texel(image, x1, y0), ax);
  const glm::vec3 bottom = glm::mix(texel(image, x0, y1), texel(image, x1, y1), ax);
  return glm::mix(top, bottom, ay);
}

float srgb8ToLinear(uint8_t value) {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int v = 0; v < 256; ++v) {
      const double c = v / 255.0;
      t[size_t(v)] = static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
    return t;
  }();
  return table[value];
}

}  // namespace dpoint
