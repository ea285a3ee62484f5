// RGBA8 pixels of a PNG that a cli test made (stb_image; its implementation is compiled into
// cli_tests once, in cli_preview_test.cpp).
#pragma once

#include <gtest/gtest.h>

#include <stb/stb_image.h>

#include <cstdint>
#include <string>
#include <vector>

namespace dpoint::test {

// RGBA8 pixels of a PNG, row by row.
struct Pixels {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;
  uint32_t at(int x, int y) const {
    const uint8_t* p = &rgba[(size_t(y) * size_t(width) + size_t(x)) * 4];
    return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
  }
};

inline Pixels decodePng(const std::string& png) {
  Pixels image;
  int channels = 0;
  stbi_uc* data = stbi_load_from_memory(reinterpret_cast<const stbi_uc*>(png.data()), int(png.size()), &image.width,
                                        &image.height, &channels, 4);
  EXPECT_NE(data, nullptr) << stbi_failure_reason();
  if (data == nullptr) return image;
  image.rgba.assign(data, data + size_t(image.width) * size_t(image.height) * 4);
  stbi_image_free(data);
  return image;
}

}  // namespace dpoint::test
