// How far a mode is from the exact picture (DESIGN §5): the probe's clip positions against the
// long-double reference, and the rendered image against the reference raster.
#pragma once

#include "core/point_set.h"
#include "viewer/reference.h"
#include "viewer/render.h"

namespace dpoint {

struct ErrorReport {
  ErrorStats stats;
  // Rendered picture vs reference raster; the reference draws size-1 points only, so with a
  // larger point size or with shading there is no image check (pixels_compared false).
  bool pixels_compared = false;
  size_t pixels_differing = 0;
  Image reference;              // the reference raster
};

// Each point's window position from the clip position the probe stored, in input order (`render`
// from renderPoints with options.probe set).
std::vector<WindowPoint> probeWindows(const RenderResult& render, const Camera& camera);

// `render` must come from renderPoints with options.probe set, and `options` be those it used.
ErrorReport measureError(const PointSet& points, const Camera& camera, const RenderResult& render,
                         const RenderOptions& options);

}  // namespace dpoint
