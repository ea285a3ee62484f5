#version 450
// Points are flat squares of the vertex colour; the RGBA8 value written is the one read. Compiled
// with ROUND_POINTS (points_round.frag), a point is a disc whose depth falls away towards its rim
// (push.glsl's roundDepth): the compute splat's round points, pixel for pixel.
#extension GL_GOOGLE_include_directive : require
#include "push.glsl"

layout(location = 0) in vec4 v_color;
layout(location = 0) out vec4 o_color;

void main() {
#if defined(ROUND_POINTS)
  // gl_PointCoord is the pixel centre's place in the point's square, 0..1 on each axis.
  vec2 u = 2.0 * gl_PointCoord - 1.0;
  float r2 = dot(u, u);
  if (r2 > 1.0) discard;
  gl_FragDepth = roundDepth(gl_FragCoord.z, roundSlope(gl_FragCoord.z), r2);
#endif
  o_color = v_color;
}
