#version 450
// mandelbrot2d's pixel counts on a device (issue #14): the perturbation deltas of
// generators/mandelbrot2d.cpp (perturbedCount) in fp64 against the reference orbit the CPU
// computed, one thread per pixel, the same operations in the same order (add, sub and mul only,
// each correctly rounded in Vulkan, none fused: every double is `precise`), so the same counts.
// Also each escaped pixel's tail (issue #24): the same steps on past the escape until
// |z|² > tail_radius2, whose |z|² and step count the CPU turns into the smooth count and colour
// (log2 stays on the CPU: GLSL's is not libm's).
layout(local_size_x = 256) in;

struct Tail {  // generators/mandelbrot2d.h EscapeTail
  double z2;
  uint steps;
  uint unused;
};

layout(std430, set = 0, binding = 0) readonly buffer Orbit { dvec2 orbit[]; };  // Z_0, Z_1, ..., Z_last
layout(std430, set = 0, binding = 1) readonly buffer Dcx { double dcx[]; };    // per column
layout(std430, set = 0, binding = 2) readonly buffer Dcy { double dcy[]; };    // per row
layout(std430, set = 0, binding = 3) writeonly buffer Counts { uint counts[]; };
layout(std430, set = 0, binding = 4) writeonly buffer Tails { Tail tails[]; };

layout(push_constant) uniform Push {
  double tail_radius2;  // kTailRadius2
  uint cols;            // pixels per row
  uint first_row;       // rows before this dispatch's first pixel
  uint count;           // pixels in this dispatch: whole rows
  uint max_iter;
  uint last;            // index of the orbit's last point
  uint tail_steps;      // kMaxTailSteps
};

// δ ← (2·Z_m + δ)·δ + δc
void step(uint m, double cx, double cy, inout double dx, inout double dy) {
  precise double tx = 2.0lf * orbit[m].x + dx;
  precise double ty = 2.0lf * orbit[m].y + dy;
  precise double ndx = tx * dx - ty * dy + cx;
  precise double ndy = tx * dy + ty * dx + cy;
  dx = ndx;
  dy = ndy;
}

uint perturbedCount(double cx, double cy, out Tail tail) {
  uint m = 0u;
  precise double dx = 0.0lf, dy = 0.0lf;
  for (uint n = 0u; n < max_iter; ++n) {
    step(m, cx, cy, dx, dy);
    ++m;
    precise double zx = orbit[m].x + dx;
    precise double zy = orbit[m].y + dy;
    precise double z2 = zx * zx + zy * zy;
    if (z2 > 4.0lf) {
      uint steps = 0u;
      for (; z2 <= tail_radius2 && steps < tail_steps; ++steps) {
        precise double d2 = dx * dx + dy * dy;
        if (z2 < d2 || m == last) {  // the rebase test the escape skipped comes first
          dx = zx;
          dy = zy;
          m = 0u;
        }
        step(m, cx, cy, dx, dy);
        ++m;
        zx = orbit[m].x + dx;
        zy = orbit[m].y + dy;
        z2 = zx * zx + zy * zy;
      }
      tail = Tail(z2, steps, 0u);
      return n;
    }
    precise double d2 = dx * dx + dy * dy;
    if (z2 < d2 || m == last) {  // rebase onto Z_0 = 0
      dx = zx;
      dy = zy;
      m = 0u;
    }
  }
  tail = Tail(0.0lf, 0u, 0u);
  return max_iter;
}

void main() {
  const uint t = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * 256u + gl_LocalInvocationID.x;
  if (t >= count) return;
  const uint row = first_row + t / cols;
  Tail tail;
  counts[t] = perturbedCount(dcx[t % cols], dcy[row], tail);
  tails[t] = tail;
}
