// GLB output (tinygltf). Point sets become one POINTS primitive, meshes one TRIANGLES primitive
// with uint32 indices. POSITION is float32 relative to a double origin (the centre of the
// bounding box) stored in the node's translation, so a reader recovers positions to float
// precision of the extent, not of the absolute coordinate. COLOR_0 is float32 VEC3. Accessor
// min/max are computed from the stored float values. Written atomically.
#pragma once

#include <string>

#include "core/point_set.h"
#include "core/result.h"

namespace dpoint {

Status writeGlb(const std::string& path, const PointSet& points);

}  // namespace dpoint
