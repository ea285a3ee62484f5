#version 450
// Test of exact_fp64.glsl (tests/generators/gpu_generate_test.cpp): sqrtRn and recipRn of every input, for
// comparison with the CPU's IEEE sqrt and 1/x, with the built-in first guesses moved kSkew ulps
// up or down (alternating by invocation), as a device with a less accurate sqrt or division would;
// in either of the two forms (exact_fp64.glsl's kExactFp64Bits, constant_id 2).
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_GOOGLE_include_directive : require

layout(constant_id = 0) const int kSkew = 0;

double skew(double guess) {
  const int64_t step = (gl_GlobalInvocationID.x & 1u) == 0u ? int64_t(kSkew) : -int64_t(kSkew);
  return int64BitsToDouble(doubleBitsToInt64(guess) + step);
}
#define EXACT_FP64_GUESS(guess) skew(guess)
#include "exact_fp64.glsl"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) buffer Data { double values[]; };  // n inputs, then 2n outputs

layout(push_constant) uniform Push { uint n; };

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= n) return;
  precise double x = values[i];
  values[n + 2u * i] = sqrtRn(x);
  values[n + 2u * i + 1u] = recipRn(x);
}
