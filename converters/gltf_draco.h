// KHR_draco_mesh_compression (internal to converters/): Draco-compressed primitives decoded
// through Debian's libdraco into plain accessors.
//
// The decoded POSITION, COLOR_0 and indices of a primitive each become a new accessor (a copy of
// the primitive's own, with its count, type and componentType) over a new buffer holding the
// data in exactly that layout, and the primitive is pointed at them; the rest of the reader then
// reads a plain primitive through the one bounds-checked accessor decoder (gltf_accessor.h).
// Other attributes the extension lists are only checked to exist in the Draco data: the reader
// never reads them.
#pragma once

#include <tiny_gltf.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "converters/gltf_json.h"
#include "core/result.h"

namespace dpoint {

// The `indices` of a primitive with KHR_draco_mesh_compression, taken out of the JSON.
struct DracoIndices {
  size_t mesh = 0, primitive = 0;
  int accessor = -1;
};

// tinygltf 2.7.0 refuses a primitive whose indices accessor has no bufferView, which is what
// every Draco primitive without uncompressed fallback data has. Removes `indices` from each
// primitive of `root` (the pre-parsed document, pre-checked: indices are integers below 2^31)
// that carries the extension, and returns them; the caller hands writeJson(root) to tinygltf
// and decodeDracoPrimitives puts them back.
std::vector<DracoIndices> detachDracoIndices(JsonValue& root);

// Puts `detached` back, then decodes every primitive with KHR_draco_mesh_compression. Before
// libdraco sees a byte: the extension's fields, the primitive mode (TRIANGLES or TRIANGLE_STRIP,
// as the extension allows), the compressed bufferView inside its buffer, each listed attribute
// present on the primitive, and the decoded size of the accessors it fills within what is left of
// max_decoded_bytes (else ExitCode::kResourceLimit). After decoding: each attribute found by its
// unique id, accessor count = Draco points, components and componentType equal to the Draco
// attribute's, every mapped value and face corner in range, indices count = 3 · faces and each
// index representable in the indices componentType. A primitive without indices gets uint32
// ones (Draco always stores faces); TRIANGLE_STRIP becomes TRIANGLES, since Draco decodes a
// triangle list. Errors: "PATH: /meshes/M/primitives/P/extensions/KHR_draco_mesh_compression...: what".
Status decodeDracoPrimitives(const std::string& path, tinygltf::Model& model,
                             const std::vector<DracoIndices>& detached, uint64_t max_decoded_bytes);

}  // namespace dpoint
