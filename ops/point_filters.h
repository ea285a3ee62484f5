// Post-processing of a read point set, for `dpoint convert` and `dpoint render`: dropping
// duplicate positions and re-encoding colours. Pure functions on a PointSet; they never fail.
#pragma once

#include "core/point_set.h"

namespace dpoint {

// Keeps the first point at each exact position (x, y, z compared as values, so −0 equals +0),
// in first-occurrence order, with its colour. Triangles are renumbered; those that lose a corner
// to a merge (two corners now the same point) are dropped, since they have no area.
void dropDuplicatePositions(PointSet& points);

// Replaces each linear colour channel c by round(255·srgb(clamp(c, 0, 1)))/255: the sRGB-encoded
// 8-bit value (IEC 61966-2-1 transfer function), stored back as a 0..1 float. CSV then holds
// display-ready values; PLY uchar output writes exactly that byte.
void encodeColorsSrgb8(PointSet& points);

// Replaces the colours by elevation: viridis (ops/colormap.h) of each point's coordinate along
// `axis` (0 x, 1 y, 2 z) from the set's lowest (dark purple) to its highest (yellow), stored as
// the map's sRGB bytes / 255, the values the renderer shows. A flat set takes the map's middle.
// Needs a non-empty set (asserted); runs on `threads` cores (0: all), same result on any number.
void colorByElevation(PointSet& points, int axis, unsigned threads = 0);
// The same with the range given (low ≤ high): for a block of a larger set, coloured as the whole.
void colorByElevation(PointSet& points, int axis, double low, double high, unsigned threads);

}  // namespace dpoint
