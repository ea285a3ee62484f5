#version 450
// Raster backend: one vertex per point, POINT_LIST. The projection is shaders/render/project.glsl; the
// probe (DESIGN §5) is this shader with the specialization constant kProbe set: it also stores
// each clip position for the CPU to judge.
#extension GL_GOOGLE_include_directive : require
#include "project.glsl"

layout(constant_id = 0) const bool kProbe = false;

layout(location = 2) in vec4 a_color;  // RGBA8 UNORM
layout(location = 0) out vec4 v_color;

layout(std430, set = 0, binding = 3) writeonly buffer Probe { vec4 probe_clip[]; };

#if defined(MODE_FP32)
layout(location = 0) in vec3 a_position;
#elif defined(MODE_BATCH)
layout(location = 0) in uvec2 a_packed;  // R32G32_UINT: the 3×21-bit offset
#elif defined(MODE_SPLIT) || defined(MODE_RTE) || defined(MODE_DF64)
layout(location = 0) in vec3 a_hi;
layout(location = 1) in vec3 a_lo;
#elif defined(MODE_NATIVE_ATTR)
layout(location = 0) in dvec3 a_position;  // R64G64B64_SFLOAT, two locations
#elif defined(MODE_NATIVE_PULL)
layout(std430, set = 0, binding = 1) readonly buffer Positions { double positions[]; };
#elif defined(MODE_ADAPTIVE)
// Three planes of tier words (viewer/modes.h, planeStride); the tiers each batch loads, 0 where
// the plan culled it (no point of it is in view: it is sent behind the eye).
layout(std430, set = 0, binding = 1) readonly buffer Positions { uint words[]; };
layout(std430, set = 0, binding = 5) readonly buffer BatchPlan { uint batch_plan[]; };
#endif

void main() {
  PointInput point;
#if defined(MODE_SPLIT) || defined(MODE_RTE) || defined(MODE_DF64)
  point.hi = a_hi;
  point.lo = a_lo;
#elif defined(MODE_NATIVE_PULL)
  uint base = 3u * uint(gl_VertexIndex);
  point.position = dvec3(positions[base], positions[base + 1u], positions[base + 2u]);
#elif defined(MODE_BATCH)
  point.position = unpackOffset(a_packed);
#elif defined(MODE_ADAPTIVE)
  uint i = uint(gl_VertexIndex), stride = (pc.count + 3u) & ~3u;
  uint tiers = batch_plan[(pc.first_index + i) >> pc.batch_shift];
  if (tiers == 0u) {
    gl_Position = vec4(0.0, 0.0, 0.0, -1.0);
    gl_PointSize = pc.point_size;
    v_color = a_color;
    if (kProbe) probe_clip[gl_VertexIndex] = gl_Position;
    return;
  }
  if (tiers == 1u) point.position = rebuildTiers1(words[i]);
  else if (tiers == 2u) point.position = rebuildTiers2(words[i], words[stride + i]);
  else point.position = rebuildTiers3(words[i], words[stride + i], words[2u * stride + i]);
#else
  point.position = a_position;
#endif
  gl_Position = projectPoint(point, pc.first_index + uint(gl_VertexIndex));
  gl_PointSize = pc.point_size;
  v_color = a_color;
  if (kProbe) probe_clip[gl_VertexIndex] = gl_Position;
}
