#version 450
// Shading pass 3 in one dispatch where the radii are small (viewer/pipelines.h's
// kMaxFusedSmooth, kMaxFusedReach): the depth smoothing of smooth.comp and the eye-dome lighting
// of edl.comp, with the same arithmetic in the same order, each invocation a kBlock² block of
// pixels held in registers. It reads the filled log distances around its block once, sums them
// along rows and then columns for the block and a ring as wide as the eye-dome neighbours' reach,
// and shades the block from those means: no buffer of row sums or of means between passes, and
// no pass of its own for each (on lavapipe each pass over the picture costs more than its loads).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "shade_common.glsl"

layout(set = 0, binding = 4, r32f) uniform readonly imageBuffer filled_log;
layout(set = 0, binding = 5, r32ui) uniform readonly uimageBuffer filled_picture;
layout(set = 0, binding = 2, r32ui) uniform writeonly uimageBuffer shaded;

// Compiled in (viewer/pipelines.cpp), so every index below is a constant and the arrays live in
// registers: the smoothing's half-width and the eye-dome neighbours' offsets along the axes and
// the diagonals (edlPush's edl_axis and edl_diagonal).
layout(constant_id = 0) const int kSmoothRadius = 1;
layout(constant_id = 1) const int kEdlAxis = 1;
layout(constant_id = 2) const int kEdlDiagonal = 1;
const int kMaxSmooth = 7, kMaxReach = 2;  // viewer/pipelines.h's kMaxFusedSmooth and kMaxFusedReach
const int kBlock = 4;                      // pixels each way an invocation shades (kShadeBlock)
const int kReach = kEdlAxis > kEdlDiagonal ? kEdlAxis : kEdlDiagonal;
const int kMargin = kReach + kSmoothRadius;  // of the window of log distances around the block
const int kMaxWindow = kBlock + 2 * (kMaxReach + kMaxSmooth);
const int kMaxMeans = kBlock + 2 * kMaxReach;
const float kFloor = 0.25;

void main() {
  ivec2 origin = ivec2(gl_GlobalInvocationID.xy) * kBlock;
  if (!inside(origin)) return;
  // The padded buffer's margin covers the window of the block's last pixels too (edlPush).
  int corner = paddedIndex(origin - ivec2(kMargin));
  // Row sums: (sum, count) of the drawn log distances over 2·kSmoothRadius + 1 pixels, for every
  // row of the window and every column of the means (the block and kReach around it).
  vec2 row_sum[kMaxWindow][kMaxMeans];
  bool drawn[kMaxMeans][kMaxMeans];
  [[unroll]] for (int y = 0; y < kBlock + 2 * kMargin; ++y) {
    float l[kMaxWindow];
    [[unroll]] for (int x = 0; x < kBlock + 2 * kMargin; ++x) l[x] = imageLoad(filled_log, corner + paddedStep(ivec2(x, y))).r;
    [[unroll]] for (int x = 0; x < kBlock + 2 * kReach; ++x) {
      vec2 total = vec2(0.0);
      [[unroll]] for (int t = 0; t <= 2 * kSmoothRadius; ++t) total += l[x + t] < kEmpty ? vec2(l[x + t], 1.0) : vec2(0.0);
      row_sum[y][x] = total;
      if (y >= kSmoothRadius && y < kSmoothRadius + kBlock + 2 * kReach)
        drawn[y - kSmoothRadius][x] = l[x + kSmoothRadius] < kEmpty;
    }
  }
  // Column sums of the row sums: the mean over the square, kEmpty where nothing is drawn.
  float smoothed[kMaxMeans][kMaxMeans];
  [[unroll]] for (int y = 0; y < kBlock + 2 * kReach; ++y) {
    [[unroll]] for (int x = 0; x < kBlock + 2 * kReach; ++x) {
      vec2 total = vec2(0.0);
      [[unroll]] for (int t = 0; t <= 2 * kSmoothRadius; ++t) total += row_sum[y + t][x];
      smoothed[y][x] = drawn[y][x] ? total.x / total.y : kEmpty;
    }
  }
  // Eye-dome lighting of the block, as edl.comp.
  ivec2 offsets[8] = ivec2[8](ivec2(kEdlAxis, 0), ivec2(kEdlDiagonal, kEdlDiagonal), ivec2(0, kEdlAxis),
                              ivec2(-kEdlDiagonal, kEdlDiagonal), ivec2(-kEdlAxis, 0), ivec2(-kEdlDiagonal, -kEdlDiagonal),
                              ivec2(0, -kEdlAxis), ivec2(kEdlDiagonal, -kEdlDiagonal));
  [[unroll]] for (int y = 0; y < kBlock; ++y) {
    [[unroll]] for (int x = 0; x < kBlock; ++x) {
      ivec2 p = origin + ivec2(x, y);
      float here = smoothed[y + kReach][x + kReach];
      float sum = 0.0;
      [[unroll]] for (int k = 0; k < 8; ++k) {
        float l = smoothed[y + kReach + offsets[k].y][x + kReach + offsets[k].x];
        sum += l < kEmpty ? max(0.0, here - l) : 0.0;
      }
      float shade = max(exp(-pc.strength * 300.0 * sum / 8.0), kFloor);
      int i = pixelIndex(inside(p) ? p : origin);  // a block past the picture's edge stores nothing there
      uint color = imageLoad(filled_picture, i).r;
      vec4 rgba = unpackUnorm4x8(color);
      if (inside(p)) imageStore(shaded, i, uvec4(here < kEmpty ? packUnorm4x8(vec4(rgba.rgb * shade, rgba.a)) : color));
    }
  }
}
