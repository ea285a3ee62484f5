#version 450
// Shading pass 1, hole filling: a screen-space visibility test after Pintus, Gobbetti and Agus
// ("Real-time rendering of massive unstructured raw point clouds using screen-space operators",
// 2011), reduced to 8 directions. A pixel that shows nothing, or a point far behind the surface
// around it (a back surface seen through the gaps between the front surface's points), is a hole
// when in both directions of at least 2 of the 4 axes (horizontal, vertical, two diagonals) a
// drawn pixel within kFillRadius stands nearer than it by more than `fill_threshold`: a crack
// between two rows of points is open along its length, and the crossing of two cracks along both
// of theirs, but each is closed across. A hole takes the mean colour and log distance of the
// first such pixel each way that lies on the nearest surface found; every other pixel is copied. Gaps narrower than the radius close;
// the background beside a silhouette (surface on one side only) and holes wider than the radius
// (a Menger sponge's) stay open.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "shade_common.glsl"

layout(std430, set = 0, binding = 0) readonly buffer Depth { float depth[]; };
layout(std430, set = 0, binding = 1) readonly buffer Picture { uint picture[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Filled { float filled_log[]; };
layout(std430, set = 0, binding = 4) writeonly buffer FilledPicture { uint filled_picture[]; };

// Pixels searched each way (viewer/pipelines.h's shadeRadii): a constant, so the search unrolls.
layout(constant_id = 0) const int kFillRadius = 2;
const ivec2 kDirections[8] = ivec2[8](ivec2(1, 0), ivec2(1, 1), ivec2(0, 1), ivec2(-1, 1), ivec2(-1, 0),
                                      ivec2(-1, -1), ivec2(0, -1), ivec2(1, -1));

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!inside(p)) return;
  uint i = pixelIndex(p);
  float d = depth[i];
  float here = d > 0.0 ? logDistance(d) : kEmpty;
  float limit = here - pc.fill_threshold;
  // A pixel stands in front by more than the threshold when its depth is over this (depth grows
  // nearer the eye): one exp2 a pixel instead of a log2 a pixel searched.
  float front_depth = d > 0.0 ? depthAt(limit) : 0.0;
  bool seen[8];
  float seen_log[8];
  uint seen_color[8];
  float nearest = kEmpty;
  [[unroll]] for (int k = 0; k < 8; ++k) {
    // The first pixel this way that stands in front by more than the threshold.
    seen[k] = false;
    seen_log[k] = kEmpty;
    seen_color[k] = 0u;
    // Unrolled (no loop to branch on): the nearest hit wins.
    uint hit = 0xffffffffu;
    float hit_depth = 0.0;
    [[unroll]] for (int t = kFillRadius; t >= 1; --t) {
      ivec2 q = p + t * kDirections[k];
      if (inside(q)) {
        uint j = pixelIndex(q);
        float e = depth[j];
        if (e > front_depth) {
          hit = j;
          hit_depth = e;
        }
      }
    }
    if (hit != 0xffffffffu) {
      seen[k] = true;
      seen_log[k] = logDistance(hit_depth);
      seen_color[k] = picture[hit];
      nearest = min(nearest, seen_log[k]);
    }
  }
  int pairs = 0;
  [[unroll]] for (int k = 0; k < 4; ++k) pairs += (seen[k] && seen[k + 4]) ? 1 : 0;
  if (pairs < 2) {  // not surrounded: a silhouette's background, a hole wider than the radius, a surface
    filled_log[i] = here;
    filled_picture[i] = picture[i];
    return;
  }
  // The hole takes the nearest surface around it (a pixel with nothing drawn may see the front
  // surface one way and a back one another): the pixels within the threshold of the nearest.
  vec3 color_sum = vec3(0.0);
  float log_sum = 0.0;
  int covered = 0;
  [[unroll]] for (int k = 0; k < 8; ++k) {
    if (seen_log[k] <= nearest + pc.fill_threshold) {
      color_sum += unpackUnorm4x8(seen_color[k]).rgb;
      log_sum += seen_log[k];
      ++covered;
    }
  }
  filled_log[i] = log_sum / float(covered);
  filled_picture[i] = packUnorm4x8(vec4(color_sum / float(covered), 1.0));
}
