#version 450
// Shading pass 4, eye-dome lighting (Boucheny, "Interactive scientific visualization of large
// datasets", 2009; the shading Potree and CloudCompare give point clouds) over the filled and
// smoothed log distances of the visible points. Each drawn pixel looks at 8 neighbours on a
// circle of `radius` pixels (viewer/render_shade.cpp rounds it to the offsets edl_axis and
// edl_diagonal) and sums by how much each stands in front of it in log distance; the colour is
// scaled by exp(−strength · 300 · sum / 8), never below kFloor, so a deep crease stays a dark
// shade of its colour and not a black hole that reads as background. Log distance makes the
// shading independent of the scene's scale and distance: a step of 1% in depth darkens alike at
// 1 m and at 10^6 m. Pixels with nothing drawn are left as they are and do not darken their
// neighbours, so the background around a silhouette does not turn into an outline.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "shade_common.glsl"

layout(local_size_x = 16, local_size_y = 16) in;  // kShadeGroupSize


layout(set = 0, binding = 6, r32f) uniform readonly imageBuffer smoothed;
layout(set = 0, binding = 2, r32ui) uniform uimageBuffer shaded;  // the filled picture, shaded in place

const float kFloor = 0.25;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!inside(p)) return;
  int i = pixelIndex(p), padded = paddedIndex(p);
  float here = imageLoad(smoothed, padded).r;
  int a = pc.edl_axis, d = pc.edl_diagonal;
  int steps[8] = int[8](paddedStep(ivec2(a, 0)), paddedStep(ivec2(d, d)), paddedStep(ivec2(0, a)), paddedStep(ivec2(-d, d)),
                        paddedStep(ivec2(-a, 0)), paddedStep(ivec2(-d, -d)), paddedStep(ivec2(0, -a)), paddedStep(ivec2(d, -d)));
  float sum = 0.0;
  [[unroll]] for (int k = 0; k < 8; ++k) {
    float l = imageLoad(smoothed, padded + steps[k]).r;
    sum += l < kEmpty ? max(0.0, here - l) : 0.0;
  }
  float shade = max(exp(-pc.strength * 300.0 * sum / 8.0), kFloor);
  uint color = imageLoad(shaded, i).r;
  vec4 rgba = unpackUnorm4x8(color);
  imageStore(shaded, i, uvec4(here < kEmpty ? packUnorm4x8(vec4(rgba.rgb * shade, rgba.a)) : color));
}
