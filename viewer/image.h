// PNG output through stb_image_write, written atomically (core/atomic_file.h).
#pragma once

#include <string>

#include "core/result.h"
#include "viewer/reference.h"

namespace dpoint {

// Writes an RGBA8 image as PNG. Fails naming the path when it cannot be written.
Status writePng(const std::string& path, const Image& image);

}  // namespace dpoint
