#version 450
// Start-up self-test (DESIGN §4): runs the df64 building blocks on inputs read from a buffer.
// A compiler that ignores `precise` (reassociates, or fuses into FMA) returns zero low parts,
// and the CPU then marks rte and df64 unusable on this device.
#extension GL_GOOGLE_include_directive : require
#include "df64.glsl"

layout(local_size_x = 1) in;
layout(std430, set = 0, binding = 0) buffer Data {
  float a, b, c, splitter;  // inputs: 1, 2^-30, 1 + 2^-12, 4097
  float results[8];
};

void main() {
  vec2 sum = twoSum(a, b);             // (1, 2^-30)
  vec2 product = twoProd(c, c, splitter);  // (1 + 2^-11, 2^-24)
  vec2 df = dfAdd(vec2(a, 0.0), vec2(b, 0.0));  // (1, 2^-30)
  results[0] = sum.x;
  results[1] = sum.y;
  results[2] = product.x;
  results[3] = product.y;
  results[4] = df.x;
  results[5] = df.y;
  results[6] = 0.0;
  results[7] = 0.0;
}
