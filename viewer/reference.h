// The exact picture (DESIGN §5): every point projected on the CPU in long double from the same
// double camera, the per-point error of a GPU probe against it, and the reference raster.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec4.hpp>

#include "core/point_set.h"
#include "image/image.h"
#include "viewer/camera.h"

namespace dpoint {

// Window position of one point: x, y in pixels (see camera.h), depth in [0, 1] (reversed Z).
// `visible` is false for points outside the view volume: w ≤ 0 (behind or at the eye), depth
// outside [0, 1], or x, y outside (0, width] × (0, height]. Invisible points carry no numbers
// (x = y = depth = 0) so nothing downstream meets a NaN.
struct WindowPoint {
  double x = 0.0, y = 0.0, depth = 0.0;
  bool visible = false;
};

// Projects with clip = projection · rotation · (p − eye), every step in long double.
std::vector<WindowPoint> projectReference(const PositionArray& positions, const Camera& camera);

// Window position from a clip position the GPU produced (float), divided by w in double.
// Same visibility rule as above.
WindowPoint windowFromClip(const glm::vec4& clip, const Camera& camera);

struct ErrorStats {
  size_t points = 0;            // points visible in the reference
  size_t lost = 0;              // visible in the reference, invisible (or non-finite) in the probe
  double max_px = 0.0, p99_px = 0.0, rms_px = 0.0;
  double share_off_half_px = 0.0;  // share of `points` off by ≥ 0.5 px or lost (on a wrong pixel)
};

// Error per point = distance in pixels between probe and reference window positions, over the
// points visible in the reference (`reference` and `probe` have the same length; asserted). A
// point lost by the probe lands on a wrong pixel, so it counts in share_off_half_px; its error
// would be infinite, so it is counted in `lost` and left out of max/p99/rms, which cover the
// points the probe kept. p99 is the nearest-rank 99th percentile. Points visible only in the
// probe are not counted anywhere.
ErrorStats compareToReference(const std::vector<WindowPoint>& reference, const std::vector<WindowPoint>& probe);

// The reference raster: RGBA8 image, row-major, top row first, `background` where no point is.
// A point of size 1 covers pixel (ceil x − 1, ceil y − 1): floor except exactly on a pixel
// corner, where the top-left fill rule takes the pixel up and left. Depth test as the renderer's: the greater
// depth wins; on equal depth the point drawn first (lower index) stays. The first visible point
// on a pixel is always drawn, even at depth exactly 0 (a GREATER test against a depth buffer
// cleared to 0 would drop it; makeCamera's far plane keeps every box point above depth 0).
// `colors_rgba8` holds one colour per point, packed as encodeColor in viewer/encode.h packs it:
// R in the low byte (bytes in memory R, G, B, A on a little-endian host); `background_rgba8` too.
Image rasterReference(const std::vector<WindowPoint>& window, const std::vector<uint32_t>& colors_rgba8,
                      uint32_t width, uint32_t height, uint32_t background_rgba8);

}  // namespace dpoint
