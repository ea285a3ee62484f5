// Pixel checks the picture tests share (tests/image, tests/bench): an RGBA8 pixel packed as
// image/image.h packs it (R in the low byte), a flat image, and a count of one colour's pixels.
#pragma once

#include <cstddef>
#include <cstdint>

#include "image/image.h"

namespace dpoint::test {

inline uint32_t rgba(uint32_t r, uint32_t g, uint32_t b) { return r | g << 8 | b << 16 | 0xffu << 24; }

inline uint32_t pixel(const Image& image, uint32_t x, uint32_t y) {
  const uint8_t* p = &image.rgba[(size_t(y) * image.width + x) * 4];
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

inline Image filled(uint32_t width, uint32_t height, uint32_t color) {
  Image image;
  image.width = width, image.height = height;
  image.rgba.resize(size_t(width) * height * 4);
  for (uint32_t y = 0; y < height; ++y) {
    for (uint32_t x = 0; x < width; ++x) {
      for (int c = 0; c < 4; ++c) image.rgba[(size_t(y) * width + x) * 4 + size_t(c)] = uint8_t(color >> (8 * c));
    }
  }
  return image;
}

inline size_t countColor(const Image& image, uint32_t color) {
  size_t count = 0;
  for (uint32_t y = 0; y < image.height; ++y) {
    for (uint32_t x = 0; x < image.width; ++x) count += pixel(image, x, y) == color;
  }
  return count;
}

}  // namespace dpoint::test
