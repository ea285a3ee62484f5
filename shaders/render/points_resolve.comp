#version 450
// Compute backend, pass 2: one thread per pixel turns the winning key into the point's colour, and
// sets the key back to 0 (nothing drawn) for the next frame, which saves a clearing pass. With
// kWriteLog it also writes the pixel's log distance for the shading passes (shade_common.glsl),
// which would otherwise read back the depth to take it: one pass over the picture fewer.
#extension GL_EXT_shader_atomic_int64 : require
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_GOOGLE_include_directive : require
#include "log_distance.glsl"

layout(constant_id = 0) const bool kWriteLog = false;
layout(local_size_x = 256) in;
layout(push_constant) uniform Push {
  uint pixels;
  uint background;  // RGBA8, R in the low byte
  // kWriteLog: the picture's width, the log distances' rows (width + 2 · margin) and margin, and
  // the depth's scale (viewer/pipelines.h's EdlPush).
  uint width;
  uint padded_width;
  uint margin;
  float depth_scale;
} pc;
layout(std430, set = 0, binding = 0) buffer Visibility { uint64_t visibility[]; };
layout(std430, set = 0, binding = 1) readonly buffer Colors { uint colors[]; };
layout(std430, set = 0, binding = 2) writeonly buffer Picture { uint picture[]; };
layout(std430, set = 0, binding = 3) writeonly buffer LogDistance { float log_distance[]; };

void main() {
  uint p = gl_GlobalInvocationID.x;
  if (p >= pc.pixels) return;
  uint64_t key = visibility[p];
  if (key != 0ul) visibility[p] = 0ul;  // most of a picture is often background: no write there
  picture[p] = key == 0ul ? pc.background : colors[~uint(key & 0xffffffffu)];
  if (kWriteLog) {
    // The pixel's row and column without an integer division (a loop over the lanes on lavapipe):
    // p / width in float is off by at most one row below 2^22 rows, which the remainder corrects.
    uint y = uint(float(p) * (1.0 / float(pc.width)));
    int x = int(p) - int(y * pc.width);
    y = x < 0 ? y - 1u : (x >= int(pc.width) ? y + 1u : y);
    x = x < 0 ? x + int(pc.width) : (x >= int(pc.width) ? x - int(pc.width) : x);
    log_distance[(y + pc.margin) * pc.padded_width + uint(x) + pc.margin] =
        logDistance(uintBitsToFloat(uint(key >> 32)), pc.depth_scale);
  }
}
