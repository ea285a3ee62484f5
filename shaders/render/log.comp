#version 450
// Shading pass 1 after the raster backend (the compute backend's resolve does it itself): each
// pixel's log distance from its depth, once, so that the passes after it, which read each pixel
// many times, compare and average it without a log2 each (on lavapipe a log2 costs more than a
// load).
#extension GL_GOOGLE_include_directive : require
#include "shade_common.glsl"

layout(local_size_x = 16, local_size_y = 16) in;  // kShadeGroupSize

layout(set = 0, binding = 0, r32f) uniform readonly imageBuffer depth;
layout(set = 0, binding = 3, r32f) uniform writeonly imageBuffer log_distance;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!inside(p)) return;
  imageStore(log_distance, paddedIndex(p), vec4(logDistance(imageLoad(depth, pixelIndex(p)).r, pc.depth_scale)));
}
