#version 450
// Shading pass 3, twice (rows, then columns): the mean log distance of the drawn pixels in the
// (2·kSmoothRadius + 1)² square around each pixel, as a box filter in two 1D passes. A point is a
// square of one depth, so a surface of points is a staircase of flat squares; eye-dome lighting
// on it outlines every square. Averaged over a point's width the staircase becomes a ramp, and the
// shading follows the surface's slope and its real depth steps instead. A pixel with nothing drawn
// gets kEmpty, so that eye-dome lighting reads this buffer alone.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "shade_common.glsl"

layout(local_size_x = 16, local_size_y = 16) in;  // kShadeGroupSize

layout(set = 0, binding = 4, r32f) uniform readonly imageBuffer filled_log;
layout(set = 0, binding = 5, rg32f) uniform imageBuffer partial;  // (sum, count) along a row
layout(set = 0, binding = 6, r32f) uniform writeonly imageBuffer smoothed;

// Half-width of the square, pixels (viewer/pipelines.h's shadeRadii): a constant, so the sum unrolls.
layout(constant_id = 0) const int kSmoothRadius = 1;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!inside(p)) return;
  int padded = paddedIndex(p);
  int step = paddedStep(pc.axis == 0u ? ivec2(1, 0) : ivec2(0, 1));
  vec2 total = vec2(0.0);
  [[unroll]] for (int t = -kSmoothRadius; t <= kSmoothRadius; ++t) {
    if (pc.axis == 0u) {
      float l = imageLoad(filled_log, padded + t * step).r;
      total += l < kEmpty ? vec2(l, 1.0) : vec2(0.0);
    } else {
      total += imageLoad(partial, padded + t * step).rg;
    }
  }
  if (pc.axis == 0u)
    imageStore(partial, padded, vec4(total, 0.0, 0.0));
  else
    imageStore(smoothed, padded, vec4(imageLoad(filled_log, padded).r < kEmpty ? total.x / total.y : kEmpty));
}
