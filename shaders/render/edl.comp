#version 450
// Shading pass 3, eye-dome lighting (Boucheny, "Interactive scientific visualization of large
// datasets", 2009; the shading Potree and CloudCompare give point clouds) over the filled and
// smoothed log distances of the visible points. Each drawn pixel looks at 8 neighbours on a
// circle of `radius` pixels and sums by how much each stands in front of it in log distance; the
// colour is scaled by exp(−strength · 300 · sum / 8), never below kFloor, so a deep crease stays
// a dark shade of its colour and not a black hole that reads as background. Log distance makes
// the shading independent of the scene's scale and distance: a step of 1% in depth darkens alike
// at 1 m and at 10^6 m. Pixels with nothing drawn are left as they are and do not darken their
// neighbours, so the background around a silhouette does not turn into an outline.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "shade_common.glsl"

layout(std430, set = 0, binding = 3) readonly buffer Filled { float filled_log[]; };
layout(std430, set = 0, binding = 4) readonly buffer FilledPicture { uint filled_picture[]; };
layout(std430, set = 0, binding = 6) readonly buffer Smoothed { float smoothed[]; };
layout(std430, set = 0, binding = 2) writeonly buffer Shaded { uint shaded[]; };

const float kFloor = 0.25;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!inside(p)) return;
  uint i = pixelIndex(p);
  uint color = filled_picture[i];
  if (!(filled_log[i] < kEmpty)) {
    shaded[i] = color;
    return;
  }
  float here = smoothed[i];
  float sum = 0.0;
  [[unroll]] for (int k = 0; k < 8; ++k) {
    float angle = float(k) * 0.78539816;  // π/4
    ivec2 q = p + ivec2(round(pc.radius * vec2(cos(angle), sin(angle))));
    if (!inside(q)) continue;
    uint j = pixelIndex(q);
    if (filled_log[j] < kEmpty) sum += max(0.0, here - smoothed[j]);
  }
  float shade = max(exp(-pc.strength * 300.0 * sum / 8.0), kFloor);
  vec4 rgba = unpackUnorm4x8(color);
  shaded[i] = packUnorm4x8(vec4(rgba.rgb * shade, rgba.a));
}
