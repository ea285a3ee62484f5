// Loading a glTF/GLB file into a tinygltf::Model safely (internal to converters/).
//
// Before tinygltf sees the bytes we check what it gets wrong on hostile input (see
// ../shared/corpus/README.md, "Known traps"): the file size, the GLB header and every chunk
// header, JSON nesting depth, asset.version (2.x only), extensionsRequired, integer fields that
// tinygltf would silently wrap or clamp, and buffer URIs. tinygltf then loads with an image
// loader that decodes nothing and file-system callbacks that only read regular files inside the model's folder.
#pragma once

#include <tiny_gltf.h>

#include <cstdint>
#include <string>

#include "converters/gltf_read.h"  // kGltfDefaultMaxFileBytes
#include "core/input_file.h"
#include "core/result.h"

namespace dpoint {

// Deeper nesting than any real glTF (the schema itself nests about 8 levels).
constexpr int kGltfMaxJsonDepth = 64;

// Errors are one line: "PATH: /json/pointer: what" (PATH: input.path()). Files (and external
// buffers) larger than max_file_bytes fail with ExitCode::kResourceLimit, and so does a model
// whose file, external buffers and decoded meshopt and Draco data together pass max_memory
// (0: defaultMemoryLimit()), checked before each is allocated. External files are read from the
// input's folder; an input in memory has none, so its external URIs fail. With keep_images, the
// encoded bytes of each image given by uri (a data URI or a file) are kept in its Image::image
// (undecoded, as far as max_memory allows); images in bufferViews are in their buffers. Never throws.
Result<tinygltf::Model> loadGltfModel(const InputFile& input, uint64_t max_file_bytes, uint64_t max_memory,
                                      bool keep_images = false);

// Extensions listed in extensionsRequired that we accept: those we decode (KHR_mesh_quantization,
// EXT_meshopt_compression, KHR_draco_mesh_compression, EXT_mesh_gpu_instancing) and those that do
// not change geometry (materials, textures, lights).
bool gltfRequiredExtensionSupported(const std::string& name);

}  // namespace dpoint
