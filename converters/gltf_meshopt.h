// EXT_meshopt_compression (internal to converters/): compressed bufferViews decoded in place.
//
// A view carrying the extension gets a new buffer holding its decoded bytes and is pointed at it
// (byteOffset 0), so accessors read decoded data through the one bounds-checked decoder
// (gltf_accessor.h) whether or not the file also has a fallback buffer (gltfpack -cf).
#pragma once

#include <tiny_gltf.h>

#include <cstdint>
#include <string>

#include "converters/gltf_json.h"
#include "core/result.h"

namespace dpoint {

// Decodes every bufferView with EXT_meshopt_compression. Checks each field (mode, filter,
// byteStride and count as the extension allows, the source range inside its buffer, count ·
// byteStride equal to the view's byteLength) before meshoptimizer sees a byte. Decoded bytes over
// max_decoded_bytes in all are ExitCode::kResourceLimit. Errors: "PATH: /bufferViews/I/...: what".
// tinygltf 2.7.0 refuses a buffer without uri whose byteLength exceeds the GLB BIN chunk (or any
// uri-less buffer in a .gltf), which is exactly what an EXT_meshopt_compression fallback buffer
// (`"fallback": true`, data never stored) is. Makes each such buffer of `root` (the depth-capped
// pre-parse of the document) a one-byte placeholder (in a .gltf through a data: URI) and returns
// whether there was one; the caller hands writeJson(root) to tinygltf then. Views into a fallback
// buffer are replaced by decodeMeshoptViews; any other view into one fails the accessor bounds
// check.
bool emptyMeshoptFallbackBuffers(JsonValue& root, bool binary);

Status decodeMeshoptViews(const std::string& path, tinygltf::Model& model, uint64_t max_decoded_bytes);

}  // namespace dpoint
