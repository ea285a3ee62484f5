#version 450
// The seed noise colours of a slab's vertices (issue #38 item 4; generators/gpu_mesh.h,
// EscapeSlab::noise_colors): generators/perlin.h's seedColor of each position mesh_slab.comp's
// pass 3 made, one vertex an invocation. A shader of its own: inlined into pass 3's unrolled
// elements, the noise took lavapipe eight minutes to compile.
#extension GL_ARB_gpu_shader_int64 : require

layout(local_size_x = 256) in;

// The noise's permutation (256 words) and its 16 gradients (48 floats as words), after the
// marching cubes cases in mesh_slab.comp's case buffer.
layout(std430, set = 0, binding = 3) readonly buffer Cases { uint cases[]; };
const uint kPermutationAt = 1024u, kGradientsAt = 1280u;
layout(std430, set = 0, binding = 10) readonly buffer Positions { double positions[]; };  // 3 a vertex
layout(std430, set = 0, binding = 12) writeonly buffer Colors { float colors[]; };        // 3 a vertex

// mesh_slab.comp's push constants; this shader reads groups_x and rows.
layout(push_constant) uniform Push {
  double step;
  uint n, plane, planes, first, word_offset, bits, above_at, stride, seed_frame;
  uint vertex_elements, triangle_elements, vertex_group_count, triangle_group_count;
  uint groups_x;  // groups along x of this dispatch (a group is y · groups_x + x)
  uint pad;
  uint rows;      // the vertices
  uint row_bytes, faces, vertex_base;
} pc;

// generators/perlin.cpp's pnoise3 and seedColor, operation for operation: float add, sub and mul
// round correctly in Vulkan, the gradients' products are exact, nothing is fused (`precise`), and
// the conversions between double and float round to nearest. Only the cells of |v| < 1024 (the
// host's fast path; the mesher is not asked for colours past it).
// The permutation and the gradients live in the case buffer (a constant array indexed at run time
// was copied into each invocation's memory on lavapipe, a thousand times slower).
int perm(int index) { return int(cases[kPermutationAt + uint(index & 255)]); }
float gradient(int hash, float x, float y, float z) {
  // The package's 16 gradients: the 12 cube edge midpoints, then 4 of them again.
  uint at = kGradientsAt + 3u * uint(hash & 15);
  vec3 g = vec3(uintBitsToFloat(cases[at]), uintBitsToFloat(cases[at + 1u]), uintBitsToFloat(cases[at + 2u]));
  precise float xy = x * g.x + y * g.y;
  precise float sum = xy + z * g.z;
  return sum;
}
float lerpNoise(float t, float a, float b) {
  precise float d = b - a;
  precise float v = a + t * d;
  return v;
}
float fade(float t) {
  precise float t3 = t * t * t;
  precise float inner = t * (t * 6.0 - 15.0) + 10.0;
  precise float v = t3 * inner;
  return v;
}
// floorSmall: the truncation, one less below a negative non-integer, and v's sign on a zero.
float floorSmall(float v) {
  float t = float(int(v));
  if (t > v) {
    precise float below = t - 1.0;
    return below;
  }
  return uintBitsToFloat((floatBitsToUint(t) & 0x7FFFFFFFu) | (floatBitsToUint(v) & 0x80000000u));
}
// cellIndices for |v| < 1024: hi = (lo + 1) % 1024 as C computes it, lo + 1 lying in [−1023, 1024].
void cellIndices(float v, out int lo, out int hi, out float floor_v) {
  floor_v = floorSmall(v);
  lo = int(floor_v);
  hi = lo + 1 == 1024 ? 0 : lo + 1;
  lo &= 255;
  hi &= 255;
}
float pnoise3(float x, float y, float z) {
  int i, ii, j, jj, k, kk;
  float floor_x, floor_y, floor_z;
  cellIndices(x, i, ii, floor_x);
  cellIndices(y, j, jj, floor_y);
  cellIndices(z, k, kk, floor_z);
  precise float fx0 = x - floor_x, fy0 = y - floor_y, fz0 = z - floor_z;
  float fx = fade(fx0), fy = fade(fy0), fz = fade(fz0);
  int a = perm(i), aa = perm(a + j), ab = perm(a + jj);
  int b = perm(ii), ba = perm(b + j), bb = perm(b + jj);
  precise float x1 = fx0 - 1.0, y1 = fy0 - 1.0, z1 = fz0 - 1.0;
  float near_z = lerpNoise(fy, lerpNoise(fx, gradient(perm(aa + k), fx0, fy0, fz0), gradient(perm(ba + k), x1, fy0, fz0)),
                           lerpNoise(fx, gradient(perm(ab + k), fx0, y1, fz0), gradient(perm(bb + k), x1, y1, fz0)));
  float far_z = lerpNoise(fy, lerpNoise(fx, gradient(perm(aa + kk), fx0, fy0, z1), gradient(perm(ba + kk), x1, fy0, z1)),
                          lerpNoise(fx, gradient(perm(ab + kk), fx0, y1, z1), gradient(perm(bb + kk), x1, y1, z1)));
  return lerpNoise(fz, near_z, far_z);
}
void writeColor(uint id, dvec3 p) {
  for (uint c = 0u; c < 3u; ++c) {
    precise double offset = 100.0lf * double(c);
    precise double px = p.x + offset, py = p.y + offset, pz = p.z + offset;
    double n = double(pnoise3(float(px), float(py), float(pz)));
    precise double color = 0.5lf + 0.5lf * n;
    colors[3u * id + c] = float(color);
  }
}

void main() {
  uint id = (gl_WorkGroupID.y * pc.groups_x + gl_WorkGroupID.x) * 256u + gl_LocalInvocationID.x;
  if (id >= pc.rows) return;
  // Every coordinate + 200 within ±1024 (the host checks).
  writeColor(id, dvec3(positions[3u * id], positions[3u * id + 1u], positions[3u * id + 2u]));
}
