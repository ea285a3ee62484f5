#version 450
// Shading pass 3 in one dispatch where the radii are small (viewer/pipelines.h's
// kMaxFusedSmooth, kMaxFusedReach): the depth smoothing of smooth.comp and the eye-dome lighting
// of edl.comp, with the same arithmetic in the same order. Each invocation shades a strip of
// kStrip rows of kBlock pixels, walking down the rows of log distances around it once: each row's
// sums along the row, then (kept for the 2·kSmoothRadius + 1 rows of a square) their sum down the
// columns, the means for the strip and a ring as wide as the eye-dome neighbours' reach (kept for
// the rows the neighbours reach), and eye-dome lighting of one row of the strip. No buffer of row
// sums or of means between passes, no pass of its own for each (on lavapipe each pass over the
// picture costs more than its loads), and one row's code in a loop: llvmpipe compiles a shader on
// its first use (then caches the machine code on disk) and lavapipe lowers and optimizes its NIR
// whenever the pipeline is made; a 4x4 block unrolled took up to a second to compile at 8-px
// points where this takes 0.1 s, and 8 pixels a row took twice this one's 7-16 ms to make.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "shade_common.glsl"

// Fewer invocations than pixels by kBlock · kStrip: small groups, so the picture still makes
// enough of them to keep every core (or a GPU's multiprocessors) busy.
layout(local_size_x = 8, local_size_y = 8) in;  // kShadeStripGroupSize

layout(set = 0, binding = 4, r32f) uniform readonly imageBuffer filled_log;
layout(set = 0, binding = 2, r32ui) uniform uimageBuffer shaded;  // the filled picture, shaded in place

// Compiled in (viewer/pipelines.cpp), so every array index below is a constant and the arrays
// live in registers: the smoothing's half-width and the eye-dome neighbours' offsets along the
// axes and the diagonals (ShadeRadii's edl_axis and edl_diagonal).
layout(constant_id = 0) const int kSmoothRadius = 1;
layout(constant_id = 1) const int kEdlAxis = 1;
layout(constant_id = 2) const int kEdlDiagonal = 1;
const int kMaxSmooth = 7, kMaxReach = 2;  // viewer/pipelines.h's kMaxFusedSmooth and kMaxFusedReach
const int kBlock = 4, kStrip = 32;         // pixels across and down a strip (kShadeStripWidth, _Height)
const int kReach = kEdlAxis > kEdlDiagonal ? kEdlAxis : kEdlDiagonal;
const int kMargin = kReach + kSmoothRadius;  // of the log distances read around the strip
const int kSquare = 2 * kSmoothRadius + 1;
const int kMeans = kBlock + 2 * kReach;      // means across: the strip's columns and kReach each side
const int kMaxLine = kBlock + 2 * (kMaxReach + kMaxSmooth), kMaxMeans = kBlock + 2 * kMaxReach;
const float kFloor = 0.25;

void main() {
  ivec2 origin = ivec2(gl_GlobalInvocationID.xy) * ivec2(kBlock, kStrip);
  if (!inside(origin)) return;
  // The padded buffers' margin covers the rows and columns a strip past the picture's edge reads.
  int corner = paddedIndex(origin - ivec2(kMargin));
  vec2 row_sums[2 * kMaxSmooth + 1][kMaxMeans];  // of the last kSquare rows read, the newest last
  bool drawn[kMaxSmooth + 1][kMaxMeans];         // of the last kSmoothRadius + 1 rows read
  float means[2 * kMaxReach + 1][kMaxMeans];     // of the last 2·kReach + 1 rows of means
  [[unroll]] for (int y = 0; y < kSquare; ++y)
    [[unroll]] for (int x = 0; x < kMeans; ++x) row_sums[y][x] = vec2(0.0);
  [[dont_unroll]] for (int row = 0; row < kStrip + 2 * kMargin; ++row) {
    float l[kMaxLine];
    [[unroll]] for (int x = 0; x < kBlock + 2 * kMargin; ++x)
      l[x] = imageLoad(filled_log, corner + paddedStep(ivec2(x, row))).r;
    // Along the row (smooth.comp's row pass), then down the columns of the square ending at this
    // row (its column pass), oldest row first.
    [[unroll]] for (int y = 0; y + 1 < kSquare; ++y) row_sums[y] = row_sums[y + 1];
    [[unroll]] for (int y = 0; y < kSmoothRadius; ++y) drawn[y] = drawn[y + 1];
    [[unroll]] for (int y = 0; y < 2 * kReach; ++y) means[y] = means[y + 1];
    [[unroll]] for (int x = 0; x < kMeans; ++x) {
      vec2 total = vec2(0.0);
      [[unroll]] for (int t = 0; t < kSquare; ++t) total += l[x + t] < kEmpty ? vec2(l[x + t], 1.0) : vec2(0.0);
      row_sums[kSquare - 1][x] = total;
      drawn[kSmoothRadius][x] = l[x + kSmoothRadius] < kEmpty;
      vec2 square = vec2(0.0);
      [[unroll]] for (int y = 0; y < kSquare; ++y) square += row_sums[y][x];
      // The mean of the square centred kSmoothRadius rows up; kEmpty where nothing is drawn.
      means[2 * kReach][x] = drawn[0][x] ? square.x / square.y : kEmpty;
    }
    // Eye-dome lighting (edl.comp) of the strip's row centred in the means kept, once they are
    // all real rows of means (the first 2·kMargin rows read only fill the registers).
    ivec2 p = origin + ivec2(0, row - 2 * kMargin);
    if (p.y < origin.y) continue;
    [[unroll]] for (int x = 0; x < kBlock; ++x, ++p.x) {
      float here = means[kReach][x + kReach];
      ivec2 offsets[8] = ivec2[8](ivec2(kEdlAxis, 0), ivec2(kEdlDiagonal, kEdlDiagonal), ivec2(0, kEdlAxis),
                                  ivec2(-kEdlDiagonal, kEdlDiagonal), ivec2(-kEdlAxis, 0),
                                  ivec2(-kEdlDiagonal, -kEdlDiagonal), ivec2(0, -kEdlAxis), ivec2(kEdlDiagonal, -kEdlDiagonal));
      float sum = 0.0;
      [[unroll]] for (int k = 0; k < 8; ++k) {
        float there = means[kReach + offsets[k].y][x + kReach + offsets[k].x];
        sum += there < kEmpty ? max(0.0, here - there) : 0.0;
      }
      float shade = max(exp(-pc.strength * 300.0 * sum / 8.0), kFloor);
      int i = pixelIndex(inside(p) ? p : origin);  // a strip past the picture's edge stores nothing there
      uint color = imageLoad(shaded, i).r;
      vec4 rgba = unpackUnorm4x8(color);
      if (inside(p)) imageStore(shaded, i, uvec4(here < kEmpty ? packUnorm4x8(vec4(rgba.rgb * shade, rgba.a)) : color));
    }
  }
}
