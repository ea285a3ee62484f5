#version 450
// Compute backend, pass 1 (DESIGN §4): one thread per point projects it with the same code as the
// raster path (project.glsl), finds its pixel as the rasterizer would (top-left rule for a size-1
// point; a larger one covers its square) and keeps the nearest point per pixel with a 64-bit atomicMax of
// (depth bits << 32 | ~index): reversed Z, so the greater depth wins, and on a tie the lower
// index, as the raster depth test GREATER keeps the point drawn first. Only positions are read here
// (colours are fetched per pixel by the resolve), and a point whose key cannot beat the pixel's
// current one skips the atomic (kEarlyDepth): keys only grow, so a stale read never drops a winner.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_atomic_int64 : require
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_KHR_shader_subgroup_vote : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
#include "project.glsl"

layout(constant_id = 0) const bool kProbe = false;
layout(constant_id = 1) const bool kEarlyDepth = true;
// The device has subgroup vote and arithmetic in compute shaders (DeviceFacts::subgroup_merge).
layout(constant_id = 2) const bool kSubgroupMerge = false;
// Batch and adaptive modes keep one key for two consecutive points on one pixel (splatPair).
layout(constant_id = 3) const bool kPairMerge = false;
// Points larger than one pixel may be drawn (pc.point_size); false compiles their loop away. The
// loop's mere presence, never taken, had made lavapipe's 1-px frames 1.4-1.6x slower (issue #38).
layout(constant_id = 4) const bool kLargePoints = true;
// Larger points are discs whose depth falls away towards the rim (push.glsl's roundDepth), the
// raster backend's points_round.frag; false: the rasterizer's squares at one depth.
layout(constant_id = 5) const bool kRound = false;
// Where bit 1 of pc.listed is set, workgroup k does what workgroup n − 1 − k of the chunk's n would
// (RenderOptions::near_end_first: the chunk's nearer end first, so that kEarlyDepth skips more
// atomics; their atomicMax leaves the same keys in any order). Bit 0 is then the batch list's.
layout(constant_id = 6) const bool kNearEndFirst = false;
layout(local_size_x = 256) in;
const uint kPointsPerThread = 4u;  // kSplatPointsPerThread in viewer/pipelines.h

layout(std430, set = 0, binding = 3) writeonly buffer Probe { vec4 probe_clip[]; };
layout(std430, set = 0, binding = 4) buffer Visibility { uint64_t visibility[]; };
// The same keys as words: a key's depth bits are word 2·pixel + 1 (a 64-bit value is stored
// little-endian, as on every device the renderer meets: lavapipe on x86, NVIDIA). A larger
// point's early test reads only them, and skips where the pixel's depth is greater (an equal
// depth does the atomic, which decides by index); so does the pair merge. lavapipe gathers a
// load lane by lane through the stack, a 64-bit one into two registers, and these loads are most
// of its splat of larger points (16.8M points at 3 px, 1920x1080: every mode 3-9% faster; on the
// H200 8-18%; bench/results/2026-11-28/).
layout(std430, set = 0, binding = 4) readonly buffer VisibilityWords { uint visibility_words[]; };
#if defined(MODE_NATIVE_PULL)
layout(std430, set = 0, binding = 1) readonly buffer Positions { double positions[]; };
#elif defined(MODE_BATCH)
// The same buffer seen as single points and as pairs of points (16-byte loads).
layout(std430, set = 0, binding = 1) readonly buffer Positions { uvec2 positions[]; };
layout(std430, set = 0, binding = 1) readonly buffer PositionPairs { uvec4 position_pairs[]; };
#elif defined(MODE_ADAPTIVE)
// Three planes of tier words (viewer/modes.h, planeStride), seen as words and as pairs.
layout(std430, set = 0, binding = 1) readonly buffer Positions { uint words[]; };
layout(std430, set = 0, binding = 1) readonly buffer PositionPairs { uvec2 word_pairs[]; };
#else
layout(std430, set = 0, binding = 1) readonly buffer Positions { float positions[]; };
#endif

#if defined(MODE_BATCH) || defined(MODE_ADAPTIVE)
// The frame's plan (viewer/batch_plan.h): the tiers of every batch (0: culled), then for a chunk
// that culls a batch the list of those it keeps, from list_first on: batch | tiers << 30. A
// workgroup splats 1024 points of one batch: a culled batch is never dispatched and costs nothing.
layout(std430, set = 0, binding = 5) readonly buffer BatchPlan { uint batch_plan[]; };
#endif

#if !defined(MODE_BATCH) && !defined(MODE_ADAPTIVE)
// Clip position of point i of this dispatch (batch mode: main, with the thread's matrix).
vec4 clipOf(uint i) {
  PointInput point;
#if defined(MODE_SPLIT) || defined(MODE_RTE) || defined(MODE_DF64)
  uint base = 6u * i;
  point.hi = vec3(positions[base], positions[base + 1u], positions[base + 2u]);
  point.lo = vec3(positions[base + 3u], positions[base + 4u], positions[base + 5u]);
#elif defined(MODE_NATIVE_PULL)
  uint base = 3u * i;
  point.position = dvec3(positions[base], positions[base + 1u], positions[base + 2u]);
#else
  uint base = 3u * i;
  point.position = vec3(positions[base], positions[base + 1u], positions[base + 2u]);
#endif
  return projectPoint(point, pc.first_index + i);
}
#endif

// Keeps point i of this dispatch, at `clip`, if it is the nearest on its pixel so far.
void splat(uint i, vec4 clip) {
  uint index = pc.first_index + i;
  if (kProbe) probe_clip[i] = clip;
  // The view volume as the rasterizer clips it: w > 0, 0 ≤ z ≤ w, and |x|, |y| ≤ w for a 1-px
  // point. A larger one is kept while its square reaches into the picture, as the rasterizer draws
  // a point whose centre lies just outside (its guard band): the pixel loops below clip it to the
  // picture, and only a centre beyond twice the view (a point no larger than the picture cannot
  // reach in from there; nor overflow the pixel coordinates) is left out here. Clipped by its
  // centre, the points along the picture's edges were missing, and compute and raster differed.
  // (The pipeline of larger points draws no 1-px ones: render.cpp. One max, and a product only in
  // that pipeline: the two sides tested apart, each with a size read, cost the H200's 16.7M-point
  // 3-px frame 1.6%.)
  const float reach = kLargePoints ? 2.0 : 1.0;
  if (!(clip.w > 0.0) || clip.z < 0.0 || clip.z > clip.w || max(abs(clip.x), abs(clip.y)) > reach * clip.w) return;
  float depth = clip.z / clip.w;
  float x = (clip.x / clip.w * 0.5 + 0.5) * float(pc.width);
  float y = (clip.y / clip.w * 0.5 + 0.5) * float(pc.height);
  if (!kLargePoints || pc.point_size == 1.0) {
    int px = int(ceil(x)) - 1, py = int(ceil(y)) - 1;
    if (px < 0 || py < 0 || px >= int(pc.width) || py >= int(pc.height)) return;
    uint64_t key = (uint64_t(floatBitsToUint(depth)) << 32) | uint64_t(~index);
    uint pixel = uint(py) * pc.width + uint(px);
    // Where every active lane of the subgroup lands on one pixel (dense sets in Morton order: 1e9
    // points put about 500 on a pixel), one lane tests and writes the largest key of them: the
    // same key the lanes' own atomics would have left, with one load and one atomic for all.
    if (kSubgroupMerge && subgroupAllEqual(pixel)) {
      uint depth_bits = floatBitsToUint(depth);
      uint best_depth = subgroupMax(depth_bits);
      uint best_index = subgroupMax(depth_bits == best_depth ? ~index : 0u);
      if (!subgroupElect()) return;
      key = (uint64_t(best_depth) << 32) | uint64_t(best_index);
    }
    if (kEarlyDepth && visibility[pixel] >= key) return;
    atomicMax(visibility[pixel], key);
    return;
  }
  // A larger point is the rasterizer's square: the pixels whose centres lie in [x − s/2, x + s/2) ×
  // [y − s/2, y + s/2), each tested at the point's one depth, as the raster depth test does, so the
  // depth test stays exact (a key per pixel) and the picture is the raster one; with kRound, the
  // disc inscribed in that square, each pixel at its own depth. Clipped where its square leaves
  // the picture (above), then to the picture. s² atomics a point at most: the sizes pointSizeFor picks are small
  // where the points are many, and kEarlyDepth skips most of them on a closed surface.
  uint64_t key = (uint64_t(floatBitsToUint(depth)) << 32) | uint64_t(~index);
  float half_size = 0.5 * pc.point_size;
  int x0 = max(int(ceil(x - half_size - 0.5)), 0), x1 = min(int(ceil(x + half_size - 0.5)) - 1, int(pc.width) - 1);
  int y0 = max(int(ceil(y - half_size - 0.5)), 0), y1 = min(int(ceil(y + half_size - 0.5)) - 1, int(pc.height) - 1);
  if (kRound) {
    // A disc: the pixels whose centres lie within it, as gl_PointCoord places a pixel's centre in
    // the square (r2 ≤ 1), each at its own depth. A row's pixels are found from the row's chord.
    float inv_half = 1.0 / half_size, slope = roundSlope(depth);
    for (int py = y0; py <= y1; ++py) {
      float dy = (float(py) + 0.5 - y) * inv_half, dy2 = dy * dy;
      if (dy2 > 1.0) continue;
      float chord = half_size * sqrt(1.0 - dy2);
      int row_x0 = max(x0, int(ceil(x - chord - 0.5)) - 1), row_x1 = min(x1, int(floor(x + chord - 0.5)) + 1);
      for (int px = row_x0; px <= row_x1; ++px) {
        float dx = (float(px) + 0.5 - x) * inv_half, r2 = dx * dx + dy2;
        if (r2 > 1.0) continue;
        uint pixel_depth = floatBitsToUint(roundDepth(depth, slope, r2));
        uint pixel = uint(py) * pc.width + uint(px);
        if (kEarlyDepth && visibility_words[2u * pixel + 1u] > pixel_depth) continue;
        atomicMax(visibility[pixel], (uint64_t(pixel_depth) << 32) | uint64_t(~index));
      }
    }
    return;
  }
  for (int py = y0; py <= y1; ++py)
    for (int px = x0; px <= x1; ++px) {
      uint pixel = uint(py) * pc.width + uint(px);
      if (kEarlyDepth && visibility_words[2u * pixel + 1u] > uint(key >> 32)) continue;
      atomicMax(visibility[pixel], key);
    }
}

// Point i of this dispatch at `clip` as a size-1 point: its pixel and key; false where it lies
// outside the view volume or the picture. The same tests and arithmetic as splat's.
bool pixelKey(uint i, vec4 clip, out uint pixel, out uint64_t key) {
  uint index = pc.first_index + i;
  if (kProbe) probe_clip[i] = clip;
  pixel = 0u;
  key = 0ul;
  if (!(clip.w > 0.0) || abs(clip.x) > clip.w || abs(clip.y) > clip.w || clip.z < 0.0 || clip.z > clip.w) return false;
  float depth = clip.z / clip.w;
  float x = (clip.x / clip.w * 0.5 + 0.5) * float(pc.width);
  float y = (clip.y / clip.w * 0.5 + 0.5) * float(pc.height);
  int px = int(ceil(x)) - 1, py = int(ceil(y)) - 1;
  if (px < 0 || py < 0 || px >= int(pc.width) || py >= int(pc.height)) return false;
  pixel = uint(py) * pc.width + uint(px);
  key = (uint64_t(floatBitsToUint(depth)) << 32) | uint64_t(~index);
  return true;
}

// Points i and i + 1, consecutive in the set. With kPairMerge, where both land on one pixel (a
// dense set in Morton order: 16.7M points put tens on a pixel, 1e9 about 500) only the larger of
// their keys is tested and written: the key the two would have left, with one load and one atomic
// for both. (pixelKey repeats splat's arithmetic rather than splat calling it: on the H200 the
// shared form made the batch and adaptive frames 20-30% slower, bench/results/2026-11-26/.)
void splatPair(uint i, vec4 a, vec4 b) {
  if (!kPairMerge || pc.point_size != 1.0) {
    splat(i, a);
    splat(i + 1u, b);
    return;
  }
  uint pixel_a, pixel_b;
  uint64_t key_a, key_b;
  bool in_a = pixelKey(i, a, pixel_a, key_a), in_b = pixelKey(i + 1u, b, pixel_b, key_b);
  if (in_a && in_b && pixel_a == pixel_b) {
    key_a = max(key_a, key_b);
    in_b = false;
  }
  // The depth words, as larger points test (on the H200 batch and adaptive frames 2-3% faster; on
  // lavapipe, where the pair merge is off, the word test made 1-px frames no faster).
  if (in_a && !(kEarlyDepth && visibility_words[2u * pixel_a + 1u] > uint(key_a >> 32))) atomicMax(visibility[pixel_a], key_a);
  if (in_b && !(kEarlyDepth && visibility_words[2u * pixel_b + 1u] > uint(key_b >> 32))) atomicMax(visibility[pixel_b], key_b);
}

// A workgroup takes kPointsPerThread · 256 consecutive points. Thread t splats t, t + 256, …, in
// batch mode the pairs 2t, 2t + 1 and 512 + 2t, 513 + 2t: one 16-byte load a pair, so a thread
// keeps as many bytes in flight as fp32 mode does (batch 16.7M points on the H100: 0.120 ms with
// 8-byte loads, 0.095 ms with 16-byte ones). Every load is coalesced either way.
void main() {
#if defined(MODE_BATCH) || defined(MODE_ADAPTIVE)
  // This workgroup's 1024 points: in a chunk splatted whole its 1024 (in one batch: chunks
  // without a list start at a batch), else a part of a listed batch; counted from the chunk's end
  // where it runs from there (kNearEndFirst). group_first is relative to
  // the chunk (negative where a test's small chunk starts inside a batch). The matrix is loaded
  // once for all of a thread's points: 64 B of matrix for every 8 B point had made batch mode
  // slower than fp32.
  const uint kGroupShift = 10u;  // log2(kPointsPerThread · 256)
  int group_first;
  uint batch, tiers;
  uint workgroup = kNearEndFirst && (pc.listed & 2u) != 0u ? gl_NumWorkGroups.x - 1u - gl_WorkGroupID.x : gl_WorkGroupID.x;
  bool listed = (kNearEndFirst ? pc.listed & 1u : pc.listed) != 0u;
  if (!listed) {
    group_first = int(workgroup << kGroupShift);
    batch = (pc.first_index + uint(group_first)) >> pc.batch_shift;
    tiers = batch_plan[batch];
  } else {
    uint entry = batch_plan[pc.list_first + (workgroup >> (pc.batch_shift - kGroupShift))];
    batch = entry & 0x3FFFFFFFu;
    tiers = entry >> 30;
    uint part = workgroup & ((1u << (pc.batch_shift - kGroupShift)) - 1u);
    group_first = int((batch << pc.batch_shift) + (part << kGroupShift)) - int(pc.first_index);
  }
  mat4 matrix = batch_mvp[batch];
#else
  uint group = kNearEndFirst && (pc.listed & 2u) != 0u ? gl_NumWorkGroups.x - 1u - gl_WorkGroupID.x : gl_WorkGroupID.x;
  uint group_first = group * (kPointsPerThread * gl_WorkGroupSize.x);
#endif
#if defined(MODE_ADAPTIVE)
  // Chunks hold whole batches (group_first ≥ 0, even): as batch mode's pairs, thread t splats
  // points 2t, 2t + 1 and 512 + 2t, 513 + 2t of the group, with one 8-byte load a pair per tier
  // its batch's plan asks for. On the H100 (16.7M points, 1920x1080) this is 0.111 ms for the
  // Sierpinski set and 0.130 for the Mandelbulb, where thread t taking 4t to 4t + 3 with one
  // 16-byte load per tier took 0.130 and 0.171 (the warp's pixels lie further apart), and t,
  // t + 256, … with every load made before any splat 0.159 and 0.164 (registers).
  uint stride = (pc.count + 3u) & ~3u;  // even: a pair never straddles two planes
  for (uint k = 0u; k < kPointsPerThread / 2u; ++k) {
    uint i = uint(group_first) + 2u * (gl_LocalInvocationID.x + k * gl_WorkGroupSize.x);
    if (i >= pc.count) break;
    if (i + 1u < pc.count) {
      uvec2 coarse = word_pairs[i >> 1];
      vec3 a, b;
      if (tiers == 1u) {
        a = rebuildTiers1(coarse.x);
        b = rebuildTiers1(coarse.y);
      } else if (tiers == 2u) {
        uvec2 medium = word_pairs[(stride + i) >> 1];
        a = rebuildTiers2(coarse.x, medium.x);
        b = rebuildTiers2(coarse.y, medium.y);
      } else {
        uvec2 medium = word_pairs[(stride + i) >> 1];
        uvec2 fine = word_pairs[(2u * stride + i) >> 1];
        a = rebuildTiers3(coarse.x, medium.x, fine.x);
        b = rebuildTiers3(coarse.y, medium.y, fine.y);
      }
      splatPair(i, projectBatchOffset(a, matrix), projectBatchOffset(b, matrix));
    } else {  // the chunk's last point of an odd count: a pair would read past it
      vec3 offset = tiers == 1u ? rebuildTiers1(words[i])
                  : tiers == 2u ? rebuildTiers2(words[i], words[stride + i])
                                : rebuildTiers3(words[i], words[stride + i], words[2u * stride + i]);
      splat(i, projectBatchOffset(offset, matrix));
    }
  }
#elif defined(MODE_BATCH)
  for (uint k = 0u; k < kPointsPerThread / 2u; ++k) {
    // A point before the chunk (group_first < 0) wraps to a large i and is skipped like one past it.
    uint i = uint(group_first + int(2u * (gl_LocalInvocationID.x + k * gl_WorkGroupSize.x)));
    if (i >= pc.count) continue;
    if (i + 1u < pc.count) {
      uvec4 pair = position_pairs[i >> 1];
      // index is even (chunks start at even points in batch mode: viewer/render.cpp's chunkPoints),
      // so index + 1 lies in the same batch.
      splatPair(i, projectBatchOffset(unpackOffset(pair.xy), matrix), projectBatchOffset(unpackOffset(pair.zw), matrix));
    } else {  // the last point of an odd count: a pair would read past the buffer
      splat(i, projectBatchOffset(unpackOffset(positions[i]), matrix));
    }
  }
#else
  uint first = group_first + gl_LocalInvocationID.x;
  for (uint k = 0u; k < kPointsPerThread; ++k) {
    uint i = first + k * gl_WorkGroupSize.x;
    if (i >= pc.count) break;
    splat(i, clipOf(i));
  }
#endif
}
