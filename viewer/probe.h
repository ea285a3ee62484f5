// How far a mode is from the exact picture (DESIGN §5): the probe's clip positions against the
// long-double reference, and the rendered image against the reference raster.
#pragma once

#include "core/point_set.h"
#include "viewer/reference.h"
#include "viewer/render.h"

namespace dpoint {

struct ErrorReport {
  ErrorStats stats;
  size_t pixels_differing = 0;  // rendered picture vs reference raster (point size 1)
  Image reference;              // the reference raster
};

// `render` must come from renderPoints with options.probe set.
ErrorReport measureError(const PointSet& points, const Camera& camera, const RenderResult& render,
                         uint32_t background_rgba8);

}  // namespace dpoint
