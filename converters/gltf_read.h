// glTF/GLB input (tinygltf parses; decoding and every bounds check are ours).
// World-space positions in double: node matrices / TRS composed in double over the default scene.
// This first version reads float POSITION, float/unorm COLOR_0 and u8/u16/u32 indices;
// the full accessor coverage, hostile-input hardening and compressed data are issue #4.
#pragma once

#include <string>

#include "core/point_set.h"
#include "core/result.h"

namespace dpoint {

Result<PointSet> readGltf(const std::string& path);

}  // namespace dpoint
