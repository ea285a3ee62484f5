#version 450
// Compute backend, pass 2: one thread per pixel turns the winning key into the point's colour, and
// sets the key back to 0 (nothing drawn) for the next frame, which saves a clearing pass. With
// kWriteDepth it also writes the pixel's depth (0 where nothing was drawn) for eye-dome lighting.
#extension GL_EXT_shader_atomic_int64 : require
#extension GL_ARB_gpu_shader_int64 : require

layout(constant_id = 0) const bool kWriteDepth = false;
layout(local_size_x = 256) in;
layout(push_constant) uniform Push {
  uint pixels;
  uint background;  // RGBA8, R in the low byte
} pc;
layout(std430, set = 0, binding = 0) buffer Visibility { uint64_t visibility[]; };
layout(std430, set = 0, binding = 1) readonly buffer Colors { uint colors[]; };
layout(std430, set = 0, binding = 2) writeonly buffer Picture { uint picture[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Depth { float depth[]; };

void main() {
  uint p = gl_GlobalInvocationID.x;
  if (p >= pc.pixels) return;
  uint64_t key = visibility[p];
  if (key != 0ul) visibility[p] = 0ul;  // most of a picture is often background: no write there
  picture[p] = key == 0ul ? pc.background : colors[~uint(key & 0xffffffffu)];
  if (kWriteDepth) depth[p] = uintBitsToFloat(uint(key >> 32));
}
