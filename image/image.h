// Pictures: the RGBA8 Image every renderer, reference and report draws into, its comparison, and
// PNG output through libpng, written atomically (core/atomic_file.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/result.h"

namespace dpoint {

// RGBA8, row-major, top row first; R in the low byte of each pixel's 32 bits (bytes in memory R,
// G, B, A on a little-endian host).
struct Image {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgba;  // width · height · 4
};

// Pixels whose RGBA differs between two images of the same size (asserts equal sizes).
size_t countDifferingPixels(const Image& a, const Image& b);

// Writes an RGBA8 image as PNG. Fails naming the path when it cannot be written.
Status writePng(const std::string& path, const Image& image);

}  // namespace dpoint
