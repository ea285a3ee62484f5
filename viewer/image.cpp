// PNG output: stb_image_write encodes into memory, core/atomic_file.h puts the bytes in place, so
// a failed encode or write leaves no file (and no half-written one) behind.
#include "viewer/image.h"

#include <climits>
#include <vector>

#include "core/atomic_file.h"

// stb lives in /usr/include, a system header folder, so GCC keeps its warnings out of ours.
// STB_IMAGE_WRITE_STATIC keeps its symbols in this file, so nothing else linked in can clash.
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

namespace dpoint {
namespace {

void appendToVector(void* context, void* data, int size) {
  auto* bytes = static_cast<std::vector<unsigned char>*>(context);
  const auto* begin = static_cast<const unsigned char*>(data);
  bytes->insert(bytes->end(), begin, begin + size);
}

}  // namespace

Status writePng(const std::string& path, const Image& image) {
  assert(image.rgba.size() == size_t(image.width) * image.height * 4);
  if (image.width == 0 || image.height == 0) {
    return Error{"cannot write '" + path + "': the image is empty (" + std::to_string(image.width) + "x" +
                     std::to_string(image.height) + ")",
                 ExitCode::kUsage};
  }
  // stb takes int sizes and an int row stride in bytes.
  if (image.width > INT_MAX / 4 || image.height > INT_MAX) {
    return Error{"cannot write '" + path + "': " + std::to_string(image.width) + "x" +
                     std::to_string(image.height) + " is too large for PNG encoding",
                 ExitCode::kResourceLimit};
  }
  const int width = static_cast<int>(image.width), height = static_cast<int>(image.height);
  std::vector<unsigned char> png;
  if (stbi_write_png_to_func(appendToVector, &png, width, height, 4, image.rgba.data(), width * 4) == 0) {
    return Error{"cannot write '" + path + "': PNG encoding failed", ExitCode::kResourceLimit};
  }
  Result<AtomicFile> file = AtomicFile::create(path);
  if (!file) return file.error();
  if (Status status = file->write(png.data(), png.size()); !status) return status;
  return file->commit();
}

}  // namespace dpoint
