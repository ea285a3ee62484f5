// What one COPC file's view needs (issue #35): render and info of a single .copc.laz read only the
// octree's nodes their picture needs, at its resolution, instead of every point.
#pragma once

#include <cstdint>
#include <string>

#include "converters/copc.h"
#include "core/result.h"
#include "viewer/camera.h"

namespace dpoint {

// The nodes down to the level whose spacing is at most a pixel's width, and with an orthographic
// window (--ortho --view-center --view-width) only those that meet it. Without a window, the pixel
// is the octree cube's edge over the picture's larger side: the whole file at the picture's
// resolution. A perspective view the user places (--eye/--target/--up, or --view-center or
// --view-width without --ortho) reads the nodes whose cube meets its frustum, each down to the
// level whose spacing is a pixel at the cube's nearest depth: a view from within the data reads
// the near nodes deep and the far ones shallow. Errors are the file's and its COPC header's and
// makeCamera's, naming the file or the option.
Result<CopcQuery> copcQueryFor(const CameraSpec& camera, const std::string& path, unsigned threads,
                               uint64_t max_memory);

}  // namespace dpoint
