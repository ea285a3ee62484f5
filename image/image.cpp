// PNG output: libpng encodes into memory (zlib level 1, run-length matches only, and the Sub
// filter: a 1920×1080 render in a few tens of milliseconds, where stb_image_write took ten times
// as long; opaque pictures as RGB), core/atomic_file.h puts
// the bytes in place, so a failed encode or write leaves no file (and no half-written one) behind.
#include "image/image.h"

#include <png.h>
#include <zlib.h>

#include <algorithm>
#include <cassert>
#include <climits>
#include <csetjmp>
#include <vector>

#include "core/atomic_file.h"

namespace dpoint {
namespace {

void appendToVector(png_structp png, png_bytep data, png_size_t size) {
  auto* bytes = static_cast<std::vector<unsigned char>*>(png_get_io_ptr(png));
  bytes->insert(bytes->end(), data, data + size);
}

void flushNothing(png_structp) {}

// The encoded file, or false when libpng reports an error (it longjmps back here; nothing with a
// destructor lives between the setjmp and the calls that may jump).
bool encodePng(const Image& image, std::vector<unsigned char>& out) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  std::vector<png_bytep> rows(image.height);
  for (uint32_t y = 0; y < image.height; ++y)
    rows[y] = const_cast<png_bytep>(image.rgba.data() + size_t{y} * image.width * 4);
  // An opaque picture (every render's) is written as RGB: a quarter less to compress.
  bool opaque = true;
  for (size_t i = 3; i < image.rgba.size() && opaque; i += 4) opaque = image.rgba[i] == 255;
  out.reserve(image.rgba.size() / 4);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, info ? &info : nullptr);
    return false;
  }
  png_set_write_fn(png, &out, appendToVector, flushNothing);
  png_set_IHDR(png, info, image.width, image.height, 8, opaque ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGBA,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, 1);
  png_set_compression_strategy(png, Z_RLE);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_write_info(png, info);
  if (opaque) png_set_filler(png, 0, PNG_FILLER_AFTER);  // the rows' alpha bytes are dropped
  png_write_image(png, rows.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

Result<std::vector<unsigned char>> pngBytes(const Image& image, const std::string& name) {
  assert(image.rgba.size() == size_t(image.width) * image.height * 4);
  if (image.width == 0 || image.height == 0) {
    return Error{"cannot write '" + name + "': the image is empty (" + std::to_string(image.width) + "x" +
                     std::to_string(image.height) + ")",
                 ExitCode::kUsage};
  }
  // PNG sizes are 31-bit.
  if (image.width > INT_MAX / 4 || image.height > INT_MAX) {
    return Error{"cannot write '" + name + "': " + std::to_string(image.width) + "x" +
                     std::to_string(image.height) + " is too large for PNG encoding",
                 ExitCode::kResourceLimit};
  }
  std::vector<unsigned char> png;
  png.reserve(image.rgba.size() / 4);
  if (!encodePng(image, png)) return Error{"cannot write '" + name + "': PNG encoding failed", ExitCode::kResourceLimit};
  return png;
}

Status writePng(const std::string& path, const Image& image) {
  Result<std::vector<unsigned char>> png = pngBytes(image, path);
  if (!png) return png.error();
  Result<AtomicFile> file = AtomicFile::create(path);
  if (!file) return file.error();
  if (Status status = file->write(png->data(), png->size()); !status) return status;
  return file->commit();
}

size_t countDifferingPixels(const Image& a, const Image& b) {
  assert(a.width == b.width && a.height == b.height);
  assert(a.rgba.size() == size_t(a.width) * a.height * 4 && b.rgba.size() == a.rgba.size());
  size_t differing = 0;
  for (size_t pixel = 0; pixel < a.rgba.size() / 4; ++pixel) {
    if (!std::equal(a.rgba.begin() + static_cast<ptrdiff_t>(pixel * 4),
                    a.rgba.begin() + static_cast<ptrdiff_t>(pixel * 4 + 4),
                    b.rgba.begin() + static_cast<ptrdiff_t>(pixel * 4))) {
      ++differing;
    }
  }
  return differing;
}

DrawnPixels drawnPixels(const Image& image, uint32_t background_rgba8) {
  DrawnPixels d;
  d.pixels = size_t(image.width) * image.height;
  d.min_side = std::min(image.width, image.height);
  d.x0 = image.width, d.y0 = image.height;
  const uint32_t background = background_rgba8 & 0xffffffu;
  for (uint32_t y = 0; y < image.height; ++y) {
    for (uint32_t x = 0; x < image.width; ++x) {
      const uint8_t* p = &image.rgba[4 * (size_t(y) * image.width + x)];
      if ((uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16) == background) continue;
      ++d.count;
      d.x0 = std::min(d.x0, x), d.x1 = std::max(d.x1, x), d.y0 = std::min(d.y0, y), d.y1 = std::max(d.y1, y);
    }
  }
  return d;
}

}  // namespace dpoint
