// The bench report's montage (issue #10): one hard-case view rendered in every precision mode side
// by side, each labelled, and under each its per-point error as a heat map with a colour bar.
// Drawn into an RGBA8 Image (viewer/reference.h) that image/image.h writes as PNG. Text is
// image/canvas.h's.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "image/canvas.h"
#include "viewer/reference.h"

namespace dpoint {

// Per-point error as a picture of the reference's size: each point visible in the reference is
// drawn at its reference pixel (ceil − 1, as rasterReference places it) in the colour of its
// error on a log scale from lo_px (dark) to hi_px (bright) through a perceptual map (viridis-like,
// from its published stops); NaN means the probe lost the point and is drawn magenta. Errors of 0
// or below lo_px take the lowest colour; above hi_px the highest. Where several points share a
// pixel, the largest error wins. Background black. `error_px` has one value per reference point
// (asserted); invisible points are skipped. 0 < lo_px < hi_px (asserted).
Image errorHeatMap(const std::vector<WindowPoint>& reference, const std::vector<double>& error_px, uint32_t width,
                   uint32_t height, double lo_px, double hi_px);

// The colour errorHeatMap and the montage's colour bar give an error (packed as Image bytes: R in
// the low byte, alpha 255): magenta for NaN, else the map at t = (log10 e − log10 lo) /
// (log10 hi − log10 lo) clamped to [0, 1]. 0 < lo_px < hi_px (asserted).
uint32_t errorColor(double error_px, double lo_px, double hi_px);

struct MontageTile {
  std::string label;    // first line over the picture, e.g. "fp32"
  std::string caption;  // second line, e.g. "max 105 px, 0 lost"
  Image picture;        // the rendered frame
  Image heat;           // errorHeatMap of the same view (same size as `picture`)
};

// Tiles in one row, each picture above its heat map, separated by a few pixels, on a dark grey
// background; a title line on top; under the row, a colour bar for the heat maps from lo_px to
// hi_px with labelled decades and a magenta "lost" swatch. Every picture of every tile must have
// the same size (asserted). Text scale chosen so labels are legible at the tile width; a label or
// caption wider than its tile breaks after a comma or a space and never runs into the next tile.
Image composeMontage(const std::string& title, const std::vector<MontageTile>& tiles, double lo_px, double hi_px);

}  // namespace dpoint
