// Colour maps for data without colours (`dpoint render --color elevation`) and for error heat maps.
#pragma once

#include <cstddef>
#include <cstdint>

namespace dpoint {

// RGBA8 packed as image bytes: R in the low byte, alpha 255.
constexpr uint32_t packRgb(uint32_t r, uint32_t g, uint32_t b) { return r | g << 8 | b << 16 | 0xffu << 24; }

// viridis (van der Walt and Smith, matplotlib 1.5) at t in [0, 1] (clamped; NaN gives t = 0), from
// its published 9 stops interpolated linearly in sRGB: perceptually ordered from dark to bright,
// readable in grey print and by the common colour-vision deficiencies. Packed as packRgb.
uint32_t viridis(double t);

// The ASPRS LAS 1.4 standard classes (R15): the colour dpoint draws class c in (packRgb; classes
// above 22, user-defined, in light grey) and its name ("ground", "building"; "class 40" above 22).
uint32_t asprsClassColor(uint8_t c);
const char* asprsClassName(uint8_t c);

// A qualitative palette for categories that are not ASPRS classes: colour k of 12 (cycled),
// distinct in hue and lightness (ColorBrewer's Paired set).
uint32_t categoryColor(size_t k);

}  // namespace dpoint
