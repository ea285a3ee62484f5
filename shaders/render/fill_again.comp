#version 450
// Shading pass 2b, the hole filling again (after fill.comp), over the first filling's candidates
// only: an indirect dispatch of one invocation a candidate, in two steps (pc.axis).
//   0: a candidate is filled as fill.comp fills, from the first filling's log distances and
//      colours (4 and 2), when it is now surrounded along at least 3 of the 4 axes. Where several
//      cracks meet, the junction is open along several of them for more than the radius, and its
//      middle stayed a few pixels of the back surface; in a hole a little wider than the radius
//      the first filling fills the middle and leaves 1-px lines at the rims. The smoothing spread
//      each over its square and eye-dome lighting outlined the square (faint ~15-px squares at
//      4K). Nothing open on a side is filled: a silhouette and its corners stay. The result goes
//      to 3 and 1, which no pass reads any more, so that no invocation reads what another writes.
//   1: the results are copied into 4 and 2.
// Over the candidates alone (fill.comp: a pixel left open with a nearer pixel in at least 3
// directions; 6-8% of the pixels of the Mandelbulb's pictures), not the whole picture: on lavapipe
// a second pass over every pixel cost as much as the first, 10-13 ms a frame at 1024x768 and
// 123-132 ms at 4K, where this costs 4-5 and 47-71 ms.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "shade_common.glsl"

layout(local_size_x = 64) in;  // kCandidateGroup

layout(set = 0, binding = 1, r32ui) uniform uimageBuffer picture;          // step 0 writes, 1 reads
layout(set = 0, binding = 2, r32ui) uniform uimageBuffer filled_picture;   // step 0 reads, 1 writes
layout(set = 0, binding = 3, r32f) uniform imageBuffer log_distance;       // step 0 writes, 1 reads
layout(set = 0, binding = 4, r32f) uniform imageBuffer filled_log;         // step 0 reads, 1 writes
layout(set = 0, binding = 7, r32ui) uniform readonly uimageBuffer candidates;

layout(constant_id = 0) const int kFillRadius = 2;  // fill.comp's
#include "fill_search.glsl"

// Candidate n, by step pc.axis.
void candidate(uint n) {
  int i = int(imageLoad(candidates, kCandidateList + int(n)).r);
  // The pixel's row and column without an integer division (a loop over the lanes on lavapipe), as
  // points_resolve.comp finds them: i / width in float is off by at most one row below 2^22 rows.
  int y = int(float(i) * (1.0 / float(pc.width)));
  int x = i - y * int(pc.width);
  y = x < 0 ? y - 1 : (x >= int(pc.width) ? y + 1 : y);
  x = x < 0 ? x + int(pc.width) : (x >= int(pc.width) ? x - int(pc.width) : x);
  ivec2 p = ivec2(x, y);
  int padded = paddedIndex(p);
  if (pc.axis == 1u) {
    imageStore(filled_log, padded, vec4(imageLoad(log_distance, padded).r));
    imageStore(filled_picture, i, uvec4(imageLoad(picture, i).r));
    return;
  }
  // fill.comp's search, over its output.
  float here = imageLoad(filled_log, padded).r;
  FILL_SEARCH(filled_log, filled_picture)
  bool filled = pairs >= 3;
  imageStore(log_distance, padded, vec4(filled ? log_sum / float(covered) : here));
  imageStore(picture, i, uvec4(filled ? packUnorm4x8(vec4(color_sum / float(covered), 1.0)) : imageLoad(filled_picture, i).r));
}

void main() {
  // At most kCandidateGroupsMost workgroups (fill.comp): each invocation takes every so many.
  uint count = imageLoad(candidates, kCandidateCount).r, stride = gl_NumWorkGroups.x * kCandidateGroup;
  [[dont_unroll]] for (uint n = gl_GlobalInvocationID.x; n < count; n += stride) candidate(n);
}
