#version 450
// Shading pass 2, twice (rows, then columns): the mean log distance of the drawn pixels in the
// (2·kSmoothRadius + 1)² square around each pixel, as a box filter in two 1D passes. A point is a
// square of one depth, so a surface of points is a staircase of flat squares; eye-dome lighting
// on it outlines every square. Averaged over a point's width the staircase becomes a ramp, and the
// shading follows the surface's slope and its real depth steps instead.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "shade_common.glsl"

layout(std430, set = 0, binding = 3) readonly buffer Filled { float filled_log[]; };
layout(std430, set = 0, binding = 5) buffer Partial { vec2 partial[]; };  // (sum, count) along a row
layout(std430, set = 0, binding = 6) writeonly buffer Smoothed { float smoothed[]; };

// Half-width of the square, pixels (viewer/pipelines.h's shadeRadii): a constant, so the sum unrolls.
layout(constant_id = 0) const int kSmoothRadius = 1;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!inside(p)) return;
  ivec2 step = pc.axis == 0u ? ivec2(1, 0) : ivec2(0, 1);
  vec2 total = vec2(0.0);
  [[unroll]] for (int t = -kSmoothRadius; t <= kSmoothRadius; ++t) {
    ivec2 q = p + t * step;
    if (inside(q)) {
      if (pc.axis == 0u) {
        float l = filled_log[pixelIndex(q)];
        if (l < kEmpty) total += vec2(l, 1.0);
      } else {
        total += partial[pixelIndex(q)];
      }
    }
  }
  if (pc.axis == 0u)
    partial[pixelIndex(p)] = total;
  else
    smoothed[pixelIndex(p)] = total.y > 0.0 ? total.x / total.y : kEmpty;
}
