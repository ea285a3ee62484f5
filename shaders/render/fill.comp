#version 450
// Shading pass 2, hole filling: a screen-space visibility test after Pintus, Gobbetti and Agus
// ("Real-time rendering of massive unstructured raw point clouds using screen-space operators",
// 2011), reduced to 8 directions. A pixel that shows nothing, or a point far behind the surface
// around it (a back surface seen through the gaps between the front surface's points), is a hole
// when in both directions of at least 2 of the 4 axes (horizontal, vertical, two diagonals) a
// drawn pixel within kFillRadius stands nearer than it by more than `fill_threshold`: a crack
// between two rows of points is open along its length, and the crossing of two cracks along both
// of theirs, but each is closed across. A hole takes the mean colour and log distance of the
// first such pixel each way that lies on the nearest surface found; every other pixel is copied.
// Gaps narrower than the radius close; the background beside a silhouette (surface on one side
// only) and holes wider than the radius (a Menger sponge's) stay open.
// A pixel left open with a nearer pixel in at least 3 directions is a candidate for the second
// filling (fill_again.comp), which fills what is then surrounded: its index is appended to the
// candidates' list, whose count and workgroup count that pass is dispatched by.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "shade_common.glsl"

layout(local_size_x = 16, local_size_y = 16) in;  // kShadeGroupSize

layout(set = 0, binding = 1, r32ui) uniform readonly uimageBuffer picture;
layout(set = 0, binding = 3, r32f) uniform readonly imageBuffer log_distance;
layout(set = 0, binding = 4, r32f) uniform writeonly imageBuffer filled_log;
layout(set = 0, binding = 2, r32ui) uniform writeonly uimageBuffer filled_picture;  // shaded later, in place
layout(set = 0, binding = 7, r32ui) uniform uimageBuffer candidates;  // see shade_common.glsl

// Pixels searched each way (viewer/pipelines.h's shadeRadii): a constant, so the search unrolls.
layout(constant_id = 0) const int kFillRadius = 2;
#include "fill_search.glsl"

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!inside(p)) return;
  int i = pixelIndex(p), padded = paddedIndex(p);
  float here = imageLoad(log_distance, padded).r;
  FILL_SEARCH(log_distance, picture)
  // Not surrounded (a silhouette's background, a hole wider than the radius, a surface): copied.
  bool filled = pairs >= 2;
  if (!filled && sides >= 3) {
    uint at = imageAtomicAdd(candidates, kCandidateCount, 1u);
    if (at % kCandidateGroup == 0u && at / kCandidateGroup < kCandidateGroupsMost)
      imageAtomicAdd(candidates, kCandidateGroups, 1u);
    imageStore(candidates, kCandidateList + int(at), uvec4(uint(i)));
  }
  imageStore(filled_log, padded, vec4(filled ? log_sum / float(covered) : here));
  imageStore(filled_picture, i, uvec4(filled ? packUnorm4x8(vec4(color_sum / float(covered), 1.0)) : imageLoad(picture, i).r));
}
