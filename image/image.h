// Pictures: the RGBA8 Image every renderer, reference and report draws into, its comparison, and
// PNG output through libpng, written atomically (core/atomic_file.h).
#pragma once

#include <algorithm>
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

// The pixels drawn over a background: those whose RGB is not background_rgba8's. Their count and
// bounding box, found in one pass; share() of all pixels, span() the larger side of the box over
// the picture's smaller side (both 0 when nothing is drawn).
struct DrawnPixels {
  size_t count = 0, pixels = 0;
  uint32_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // inclusive; meaningless when count is 0
  uint32_t min_side = 0;
  double share() const { return pixels == 0 ? 0.0 : double(count) / double(pixels); }
  double span() const {
    return count == 0 ? 0.0 : double(std::max(x1 - x0 + 1, y1 - y0 + 1)) / double(std::max(1u, min_side));
  }
};
DrawnPixels drawnPixels(const Image& image, uint32_t background_rgba8);

// Pixels whose RGBA differs between two images of the same size (asserts equal sizes).
size_t countDifferingPixels(const Image& a, const Image& b);

// Writes an RGBA8 image as PNG. Fails naming the path when it cannot be written.
Status writePng(const std::string& path, const Image& image);
// The PNG file writePng writes, in memory (a notebook's picture); errors name `name`.
Result<std::vector<unsigned char>> pngBytes(const Image& image, const std::string& name);

}  // namespace dpoint
