#version 450
// One vertex shader for every precision mode (DESIGN §4); the mode is a compile-time define
// (MODE_FP32, MODE_SPLIT, MODE_RTE, MODE_DF64, MODE_NATIVE_ATTR, MODE_NATIVE_PULL, MODE_BATCH),
// each built into its own SPIR-V at build time. The probe (DESIGN §5) is the same code with the
// specialization constant kProbe set: it also stores each clip position for the CPU to judge.
#extension GL_GOOGLE_include_directive : require

layout(constant_id = 0) const bool kProbe = false;

layout(push_constant) uniform Push {
  float splitter;    // 2^12 + 1, at run time so the split cannot be folded
  float point_size;
  uint first_index;  // index of this draw's first point in the whole set (batch mode)
  uint batch_size;
} pc;

layout(location = 2) in vec4 a_color;  // RGBA8 UNORM
layout(location = 0) out vec4 v_color;

layout(std430, set = 0, binding = 3) writeonly buffer Probe { vec4 probe_clip[]; };

#if defined(MODE_FP32) || defined(MODE_SPLIT)
layout(std140, set = 0, binding = 0) uniform CameraBlock { mat4 mvp; } cam;
#elif defined(MODE_RTE)
layout(std140, set = 0, binding = 0) uniform CameraBlock { mat4 projection_rotation; vec4 eye_hi; vec4 eye_lo; } cam;
#elif defined(MODE_DF64)
#include "df64.glsl"
layout(std140, set = 0, binding = 0) uniform CameraBlock { mat4 mvp_hi; mat4 mvp_lo; } cam;
#elif defined(MODE_NATIVE_ATTR) || defined(MODE_NATIVE_PULL)
layout(std140, set = 0, binding = 0) uniform CameraBlock { dmat4 mvp; } cam;
#elif defined(MODE_BATCH)
layout(std430, set = 0, binding = 2) readonly buffer Batches { mat4 batch_mvp[]; };
#else
#error "no MODE_* defined"
#endif

#if defined(MODE_FP32) || defined(MODE_BATCH)
layout(location = 0) in vec3 a_position;
#elif defined(MODE_SPLIT) || defined(MODE_RTE) || defined(MODE_DF64)
layout(location = 0) in vec3 a_hi;
layout(location = 1) in vec3 a_lo;
#elif defined(MODE_NATIVE_ATTR)
layout(location = 0) in dvec3 a_position;  // R64G64B64_SFLOAT, two locations
#elif defined(MODE_NATIVE_PULL)
layout(std430, set = 0, binding = 1) readonly buffer Positions { double positions[]; };
#endif

void main() {
#if defined(MODE_FP32)
  gl_Position = cam.mvp * vec4(a_position, 1.0);
#elif defined(MODE_SPLIT)
  // The study's listing: hi + lo rounds back to hi, so this is fp32 with twice the bytes.
  gl_Position = cam.mvp * vec4(a_hi + a_lo, 1.0);
#elif defined(MODE_RTE)
  // (hi − eye_hi) is exact when the point is near the eye (Sterbenz); adding the low parts'
  // difference keeps the eye-relative vector to float rounding.
  precise vec3 d_hi = a_hi - cam.eye_hi.xyz;
  precise vec3 d_lo = a_lo - cam.eye_lo.xyz;
  precise vec3 relative = d_hi + d_lo;
  gl_Position = cam.projection_rotation * vec4(relative, 1.0);
#elif defined(MODE_DF64)
  vec2 p[4] = vec2[4](vec2(a_hi.x, a_lo.x), vec2(a_hi.y, a_lo.y), vec2(a_hi.z, a_lo.z), vec2(1.0, 0.0));
  vec4 clip;
  for (int r = 0; r < 4; ++r) {
    vec2 sum = vec2(cam.mvp_hi[3][r], cam.mvp_lo[3][r]);
    for (int c = 0; c < 3; ++c)
      sum = dfAdd(sum, dfMul(vec2(cam.mvp_hi[c][r], cam.mvp_lo[c][r]), p[c], pc.splitter));
    clip[r] = sum.x;  // hi is the float nearest the double-float value
  }
  gl_Position = clip;
#elif defined(MODE_NATIVE_ATTR)
  gl_Position = vec4(cam.mvp * dvec4(a_position, 1.0));
#elif defined(MODE_NATIVE_PULL)
  uint base = 3u * uint(gl_VertexIndex);
  dvec3 position = dvec3(positions[base], positions[base + 1u], positions[base + 2u]);
  gl_Position = vec4(cam.mvp * dvec4(position, 1.0));
#elif defined(MODE_BATCH)
  gl_Position = batch_mvp[(pc.first_index + uint(gl_VertexIndex)) / pc.batch_size] * vec4(a_position, 1.0);
#endif
  gl_PointSize = pc.point_size;
  v_color = a_color;
  if (kProbe) probe_clip[gl_VertexIndex] = gl_Position;
}
