#version 450
// Eye-dome lighting (Boucheny, "Interactive scientific visualization of large datasets", 2009; the
// shading Potree and CloudCompare give point clouds): a screen-space pass over the depth of the
// visible points. Each drawn pixel looks at 8 neighbours on a circle of `radius` pixels and sums
// by how much each stands in front of it in log depth; the colour is scaled by
// exp(−strength · 300 · sum / 8). Log depth makes the shading independent of the scene's scale
// and distance: a step of 1% in depth darkens alike at 1 m and at 10^6 m. Pixels with no point
// (depth 0) are left as they are and do not darken their neighbours, so gaps between sparse
// points do not turn into outlines.
layout(local_size_x = 16, local_size_y = 16) in;
layout(push_constant) uniform Push {
  uint width;
  uint height;
  // Perspective: (far − near) / near, so the eye distance is far / (1 + depth · depth_scale) for the
  // reversed-Z depth in (0, 1]; 0 for ortho, whose depth is linear (far at 0, near at 1).
  float depth_scale;
  float strength;
  float radius;
} pc;
layout(std430, set = 0, binding = 0) readonly buffer Depth { float depth[]; };
layout(std430, set = 0, binding = 1) readonly buffer Picture { uint picture[]; };
layout(std430, set = 0, binding = 2) writeonly buffer Shaded { uint shaded[]; };

// log2 of the eye distance up to a constant (only differences are used). Ortho's distance is
// taken from one depth range behind the far plane, so it stays positive: 1 + (1 − depth).
float logDistance(float d) { return pc.depth_scale > 0.0 ? -log2(1.0 + d * pc.depth_scale) : log2(2.0 - d); }

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= int(pc.width) || p.y >= int(pc.height)) return;
  uint i = uint(p.y) * pc.width + uint(p.x);
  uint color = picture[i];
  float d = depth[i];
  if (!(d > 0.0)) {
    shaded[i] = color;
    return;
  }
  float here = logDistance(d);
  float sum = 0.0;
  for (int k = 0; k < 8; ++k) {
    float angle = float(k) * 0.78539816;  // π/4
    ivec2 q = p + ivec2(round(pc.radius * vec2(cos(angle), sin(angle))));
    if (q.x < 0 || q.y < 0 || q.x >= int(pc.width) || q.y >= int(pc.height)) continue;
    float neighbour = depth[uint(q.y) * pc.width + uint(q.x)];
    if (neighbour > 0.0) sum += max(0.0, here - logDistance(neighbour));
  }
  float shade = exp(-pc.strength * 300.0 * sum / 8.0);
  vec4 rgba = unpackUnorm4x8(color);
  shaded[i] = packUnorm4x8(vec4(rgba.rgb * shade, rgba.a));
}
