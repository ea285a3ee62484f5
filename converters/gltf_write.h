// GLB output (tinygltf). Point sets become one POINTS primitive, meshes one TRIANGLES primitive
// with uint32 indices. POSITION is float32 relative to a double origin (the centre of the
// bounding box, or 0 where offsets from the centre would not be exact) stored in the node's
// translation, so any reader recovers positions to float precision of the extent, not of the
// absolute coordinate. The application-specific attributes _POSITION_LOW (always) and
// _POSITION_LOW2 (when needed) hold float32 residuals with which gltf_read rebuilds the doubles
// exactly (gltf_position.h says when). COLOR_0 is float32 VEC3. Accessor min/max are computed
// from the stored float values. Written atomically.
#pragma once

#include <cstdint>
#include <string>

#include "core/point_set.h"
#include "core/result.h"

namespace dpoint {

struct GlbWriteReport {
  // Points that gltf_read will not rebuild bit-exactly (offsets on one axis spanning more than
  // float32's exponent range, or a -0.0); 0 for every realistic set.
  uint64_t inexact_points = 0;
};

// `report`, when not null, is filled before the file is written.
Status writeGlb(const std::string& path, const PointSet& points, GlbWriteReport* report = nullptr);

}  // namespace dpoint
