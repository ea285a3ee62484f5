#version 450
// The bench's shader copy (bench/bandwidth.cpp): 16-byte loads and stores in a grid-stride loop,
// the access pattern of the splat's position reads. vkCmdCopyBuffer may run on a copy engine that
// is slower than the cores reading memory, so the bandwidth bound takes the faster of the two.
layout(local_size_x = 256) in;
layout(push_constant) uniform Push { uint words; } pc;  // uvec4s to copy
layout(std430, set = 0, binding = 0) readonly buffer Source { uvec4 source[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Target { uvec4 target[]; };

void main() {
  uint stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  for (uint i = gl_GlobalInvocationID.x; i < pc.words; i += stride) target[i] = source[i];
}
