#version 450
// Escape counts of grid points for `dpoint generate` on a device (issue #14): the quaternion Julia
// set and the trig-free power-8 Mandelbulb (generators/julia.cpp, generators/mandelbulb.cpp), one
// thread per point, the same IEEE fp64 operations in the same order as the CPU, so the same
// counts bit for bit: add, sub and mul round correctly in Vulkan, and nothing may be fused
// (every double is `precise`); the square root and the reciprocal of the Mandelbulb are
// correctly rounded by exact_fp64.glsl; Julia's test sqrt(s) > 2 is replaced by its exact
// equivalent s > 4 + 2^-50 (the threshold comes from the CPU), which needs no square root.
// The kind is a specialization constant.
//
// Compiled again with ESCAPE_REFINE (generators/gpu_generate.h, GpuEscape::escapeInto's `cap`)
// for marching cubes on the device: the counts of a slab made up to a cap only (floor(level) + 1,
// where min(count, cap) > level exactly when count > level) save the Mandelbulb's interior its
// iterations past the cap; pass 0 (kPass) then lists the points at the cap with a neighbour below
// it, the only counts above the level that the mesh reads (an edge's crossing), and pass 1 counts
// those to the limit, so the slab's counts are every count the mesh needs, bit for bit.
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_GOOGLE_include_directive : require
#include "exact_fp64.glsl"

layout(local_size_x = 256) in;
layout(constant_id = 0) const uint kKind = 0;  // 0: Julia, 1: Mandelbulb (fast variant)
layout(constant_id = 1) const uint kPacked = 1;  // 1: counts of `bits` packed; 0: uint32 (lavapipe)
// constant_id 2 is exact_fp64.glsl's kExactFp64Bits: true on a GPU, false on lavapipe.

layout(std430, set = 0, binding = 0) readonly buffer Axis { double values[]; };  // grid axis, res of them
// The counts, `bits` (8, 16 or 32) each, packed little-endian: point t in bits
// [(t % per)·bits, …) of word t / per, per = 32 / bits. A GPU writes a byte a count when the limit
// is at most 255, else two (generators/escape_grid.h): a quarter of the bytes to write and copy
// out at the usual limits. lavapipe writes 32 bits (kPacked = 0, bits = 32), which the host narrows
// as it copies them: a shader with barriers took it a fifth more time, even where none ran.
#ifdef ESCAPE_REFINE
layout(constant_id = 3) const uint kPass = 0;  // 0: list the points to count on, 1: count them
layout(std430, set = 0, binding = 1) buffer Counts { uint counts[]; };
// The points (slab indices) whose counts the mesh needs past the cap, after their number.
layout(std430, set = 0, binding = 2) buffer Refine {
  uint refine_count;
  uint refine[];
};
#else
layout(std430, set = 0, binding = 1) writeonly buffer Counts { uint counts[]; };
#endif

layout(push_constant) uniform Push {
  dvec4 c;            // Julia's constant
  double threshold;   // Julia: sqrt(s) > 2 exactly when s > threshold (the CPU passes 4 + 2^-50)
  double axis_rho2;   // Mandelbulb: x² + y² at or below which φ = 0 (1e-60, as the CPU)
  double trap_c2;     // Mandelbulb: |c|² at or below which the point never escapes (the CPU's 0.42)
  uint res;           // points per axis
  uint first_row;     // rows (plane·res + j) before this dispatch's first point
  uint count;         // points in this dispatch: whole rows, k fastest
  uint limit;         // iterations at most
  uint bits;          // bits a count: 8, 16 or 32
  uint word_offset;   // the words of `counts` before this dispatch's first
#ifdef ESCAPE_REFINE
  uint cap;           // the counts' cap (pass 0: `count` points, the slab's; pass 1: limit is the run's)
#endif
};

shared uint packed[128];  // this group's counts, packed: 256 of 16 bits at most

uint juliaCount(double x0, double y0, double z0) {
  precise double x = x0, y = y0, z = z0, w = 0.0lf;
  for (uint i = 0; i < limit; ++i) {
    precise double x2 = x * x;
    precise double rest = y * y + z * z + w * w;
    precise double s = x2 + rest;
    if (s > threshold) return i;
    precise double nx = x2 - rest + c.x;
    precise double ny = 2.0lf * x * y + c.y;
    precise double nz = 2.0lf * x * z + c.z;
    precise double nw = 2.0lf * x * w + c.w;
    x = nx;
    y = ny;
    z = nz;
    w = nw;
  }
  return limit;
}

// (re + i·im)^8 by three complex squarings.
void power8(inout double re, inout double im) {
  for (int s = 0; s < 3; ++s) {
    precise double r2 = re * re - im * im;
    precise double i2 = 2.0lf * re * im;
    re = r2;
    im = i2;
  }
}

uint mandelbulbCount(double cx, double cy, double cz) {
  // Inside the ball that traps every orbit (generators/mandelbulb.cpp): no iteration to run.
  precise double c2 = cx * cx + cy * cy + cz * cz;
  if (c2 <= trap_c2) return limit;
  precise double x = cx, y = cy, z = cz;
  for (uint i = 0; i < limit; ++i) {
    precise double rho2 = x * x + y * y;
    precise double r2 = rho2 + z * z;
    if (r2 > 4.0lf) return i;
    precise double wr = z;
    precise double wi = sqrtRn(rho2);
    precise double cp = x, sp = y;
    power8(cp, sp);
    if (rho2 > axis_rho2) {
      precise double q = rho2 * rho2;
      precise double q2 = q * q;
      precise double inv = recipRn(q2);
      precise double ncp = cp * inv;
      precise double nsp = sp * inv;
      cp = ncp;
      sp = nsp;
    } else {
      cp = 1.0lf;
      sp = 0.0lf;
    }
    power8(wr, wi);
    precise double nx = wi * cp + cx;
    precise double ny = wi * sp + cy;
    precise double nz = wr + cz;
    x = nx;
    y = ny;
    z = nz;
  }
  return limit;
}

#ifdef ESCAPE_REFINE
// Count t of the slab, capped.
uint countAt(uint t) {
  if (kPacked == 0u) return counts[word_offset + t];
  const uint per = 32u / bits;
  return (counts[word_offset + t / per] >> ((t % per) * bits)) & ((1u << bits) - 1u);
}

void main() {
  const uint id = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * 256u + gl_LocalInvocationID.x;
  if (kPass == 0u) {
    // Point t (plane p, row j, column k of the slab's `count` points) at the cap, with a neighbour
    // along an axis below it: the edge between them crosses the level.
    if (id >= count || countAt(id) < cap) return;
    const uint t = id, plane = res * res;
    const uint k = t % res, j = (t / res) % res, p = t / plane;
    const bool crossing = (k > 0u && countAt(t - 1u) < cap) || (k + 1u < res && countAt(t + 1u) < cap) ||
                          (j > 0u && countAt(t - res) < cap) || (j + 1u < res && countAt(t + res) < cap) ||
                          (p > 0u && countAt(t - plane) < cap) || (p + 1u < count / plane && countAt(t + plane) < cap);
    if (crossing) refine[atomicAdd(refine_count, 1u)] = t;
    return;
  }
  // The listed points counted to the limit, the threads striding over the list; a count grows by
  // its excess over the cap in its bits (no other thread writes them).
  const uint n = refine_count, stride = gl_NumWorkGroups.x * gl_NumWorkGroups.y * 256u;
  for (uint i = id; i < n; i += stride) {
    const uint t = refine[i];
    const uint row = first_row + t / res;
    const double x = values[row / res], y = values[row % res], z = values[t % res];
    const uint value = kKind == 0u ? juliaCount(x, y, z) : mandelbulbCount(x, y, z);
    if (kPacked == 0u) {
      counts[word_offset + t] = value;
    } else {
      const uint per = 32u / bits;
      atomicAdd(counts[word_offset + t / per], (value - cap) << ((t % per) * bits));
    }
  }
}
#else
void main() {
  const uint lid = gl_LocalInvocationID.x;
  const uint base = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * 256u;
  const uint t = base + lid;
  uint value = 0u;
  if (t < count) {
    const uint row = first_row + t / res;
    const uint k = t % res;
    const double x = values[row / res], y = values[row % res], z = values[k];
    value = kKind == 0u ? juliaCount(x, y, z) : mandelbulbCount(x, y, z);
  }
  if (kPacked == 0u) {  // no barrier in this pipeline
    if (t < count) counts[word_offset + t] = value;
    return;
  }
  // Every invocation reaches the barriers (none returned early).
  const uint per = 32u / bits, words = 256u / per;
  if (lid < words) packed[lid] = 0u;
  barrier();
  atomicOr(packed[lid / per], value << ((lid % per) * bits));
  barrier();
  const uint word = base / per + lid;
  if (lid < words && word < (count + per - 1u) / per) counts[word_offset + word] = packed[lid];
}
#endif
