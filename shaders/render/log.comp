#version 450
// Shading pass 1: each pixel's log2 eye distance (up to a constant: only differences are used),
// once, so that the passes after it, which read each pixel many times, compare and average it
// without a log2 each (on lavapipe a log2 costs more than a load).
#extension GL_GOOGLE_include_directive : require
#include "shade_common.glsl"

layout(local_size_x = 16, local_size_y = 16) in;  // kShadeGroupSize

layout(set = 0, binding = 0, r32f) uniform readonly imageBuffer depth;
layout(set = 0, binding = 3, r32f) uniform writeonly imageBuffer log_distance;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!inside(p)) return;
  int i = pixelIndex(p);
  float d = imageLoad(depth, i).r;
  // Ortho's distance is taken from one depth range behind the far plane, so it stays positive:
  // 1 + (1 − depth).
  float l = pc.depth_scale > 0.0 ? -log2(1.0 + d * pc.depth_scale) : log2(2.0 - d);
  imageStore(log_distance, paddedIndex(p), vec4(d > 0.0 ? l : kEmpty));
}
