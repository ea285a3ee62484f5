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
// The pass runs twice (pc.axis 0, then 1 over the first one's output), the second time filling
// only what is now surrounded along at least 3 of the 4 axes. Where three or more cracks meet, the
// junction is open along several of them for more than the radius, and its middle stayed a few
// pixels of the back surface; in a hole a little wider than the radius the first pass fills the
// middle and leaves the rims, 1-px lines. The smoothing spread each over its square, and eye-dome
// lighting outlined the square (faint ~15-px squares at 4K). Nothing open on a side is filled the
// second time either: a silhouette and its corners stay as they were.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "shade_common.glsl"

layout(local_size_x = 16, local_size_y = 16) in;  // kShadeGroupSize

layout(set = 0, binding = 1, r32ui) uniform readonly uimageBuffer picture;
layout(set = 0, binding = 3, r32f) uniform readonly imageBuffer log_distance;
layout(set = 0, binding = 4, r32f) uniform writeonly imageBuffer filled_log;
layout(set = 0, binding = 2, r32ui) uniform writeonly uimageBuffer filled_picture;  // shaded later, in place

// Pixels searched each way (viewer/pipelines.h's shadeRadii): a constant, so the search unrolls.
layout(constant_id = 0) const int kFillRadius = 2;
const ivec2 kDirections[8] = ivec2[8](ivec2(1, 0), ivec2(1, 1), ivec2(0, 1), ivec2(-1, 1), ivec2(-1, 0),
                                      ivec2(-1, -1), ivec2(0, -1), ivec2(1, -1));

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!inside(p)) return;
  int i = pixelIndex(p), padded = paddedIndex(p);
  float here = imageLoad(log_distance, padded).r;
  // A pixel stands in front by more than the threshold when its log distance is under this; where
  // nothing is drawn it is kEmpty (kEmpty less the threshold rounds to kEmpty): any drawn pixel.
  float limit = here - pc.fill_threshold;
  float seen_log[8];
  int seen_index[8];
  float nearest = kEmpty;
  // llvmpipe runs every branch of every lane, so every step below is paid for every pixel: no
  // early exits; one colour load a direction, at the index found.
  [[unroll]] for (int k = 0; k < 8; ++k) {
    // The first pixel this way that stands in front by more than the threshold (from the far end:
    // the nearest hit wins). Counting up: Mesa 22's NIR unrolls no loop that counts down.
    seen_log[k] = kEmpty;
    seen_index[k] = i;
    [[unroll]] for (int u = 0; u < kFillRadius; ++u) {
      int t = kFillRadius - u;
      float l = imageLoad(log_distance, padded + t * paddedStep(kDirections[k])).r;
      bool hit = l < limit;  // never in the margin: kEmpty is not under any limit
      seen_log[k] = hit ? l : seen_log[k];
      seen_index[k] = hit ? i + t * (kDirections[k].y * int(pc.width) + kDirections[k].x) : seen_index[k];
    }
    nearest = min(nearest, seen_log[k]);
  }
  int pairs = 0;
  [[unroll]] for (int k = 0; k < 4; ++k) pairs += (seen_log[k] < kEmpty && seen_log[k + 4] < kEmpty) ? 1 : 0;
  // The hole takes the nearest surface around it (a pixel with nothing drawn may see the front
  // surface one way and a back one another): the pixels within the threshold of the nearest.
  vec3 color_sum = vec3(0.0);
  float log_sum = 0.0;
  int covered = 0;
  [[unroll]] for (int k = 0; k < 8; ++k) {
    vec3 color = unpackUnorm4x8(imageLoad(picture, seen_index[k]).r).rgb;
    bool near = seen_log[k] <= nearest + pc.fill_threshold;
    color_sum += near ? color : vec3(0.0);
    log_sum += near ? seen_log[k] : 0.0;
    covered += near ? 1 : 0;
  }
  // Not surrounded (a silhouette's background, a hole wider than the radius, a surface): copied.
  bool filled = pairs >= (pc.axis == 0u ? 2 : 3);
  imageStore(filled_log, padded, vec4(filled ? log_sum / float(covered) : here));
  imageStore(filled_picture, i, uvec4(filled ? packUnorm4x8(vec4(color_sum / float(covered), 1.0)) : imageLoad(picture, i).r));
}
