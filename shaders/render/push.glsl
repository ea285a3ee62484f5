// The push constants of both point backends (viewer/pipelines.h's PushConstants): the projection
// (project.glsl), the compute splat and the raster fragment shader of round points read them.

layout(push_constant) uniform Push {
  float splitter;    // 2^12 + 1, at run time so the split cannot be folded
  float point_size;
  uint first_index;  // index of this draw's first point in the whole set (batch mode, compute)
  uint batch_shift;  // log2 of the points per batch
  uint width, height, count;  // compute backend: target size; points in this chunk (both backends)
  uint list_first;  // compute backend, per-batch modes: this chunk's first entry of the batch list
  uint listed;      // bit 0: workgroups take their batches from the list (else the chunk's in order); bit 1: from the chunk's end
  // Round points (RenderOptions::round_points): the perspective depth's (far − near) / near, 0 in
  // ortho; and how far the rim of a point's disc lies behind its centre: a share of the eye
  // distance in perspective, of the depth range in ortho (viewer/render.cpp's roundPointPush).
  float depth_scale;
  float bulge;
} pc;

// How far a round point's depth falls per unit of r2 = (distance from its centre / its radius)^2,
// for a point at depth d: its disc is the front of a paraboloid whose rim lies `bulge` behind its
// centre (Potree's "paraboloid" points), so of overlapping discs the nearest centre wins and a
// point behind a surface shows no square edge through it. Perspective depth is n(f − t) / (t(f − n))
// at eye distance t, so 1 + d · depth_scale is f / t; t grows by the factor 1 + bulge · r2, which
// to first order in bulge (a few thousandths) lowers the depth by (1 + d · depth_scale) · bulge /
// depth_scale · r2. Ortho depth falls linearly. Both backends compute it once a point and subtract
// it per pixel (roundDepth), with the same arithmetic.
float roundSlope(float d) {
  return pc.depth_scale > 0.0 ? (1.0 + d * pc.depth_scale) * pc.bulge / pc.depth_scale : pc.bulge;
}
// The depth at r2 ≤ 1; never 0, the depth of an empty pixel.
float roundDepth(float d, float slope, float r2) { return max(d - slope * r2, 1.0e-30); }
