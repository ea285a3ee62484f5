// The push constants and buffers of the shading passes after either backend (log.comp, fill.comp,
// fill_again.comp, smooth.comp, edl.comp; viewer/render_shade.cpp records them in that order).
// Every buffer is a storage texel buffer, one texel a pixel (7: a candidate): on lavapipe an
// imageLoad is a vector gather, about a third of the cost of a storage-buffer load, which llvmpipe
// makes one lane at a time. Bindings:
//   0 depth (float, 0 = nothing drawn), 1 picture (RGBA8 as a uint): what the backend drew;
//   3 log distance (kEmpty where nothing is drawn);
//   4 log distance, 2 picture: after hole filling; 2 is then shaded where it is (each pixel by
//     the invocation that reads it) and read back;
//   5 (sum, count) of the log distances along each row's window, 6 their mean over the square
//     (kEmpty where nothing is drawn);
//   7 the second hole filling's candidates (uint): [kCandidateCount] how many, then at
//     [kCandidateGroups] the (x, y, z) workgroups that pass is dispatched with (the buffer is also
//     its indirect dispatch's; x at most kCandidateGroupsMost, each invocation then taking every
//     so many candidates), then from [kCandidateList] their pixel indices; set to (0, 0, 1, 1)
//     before each first filling. 1 and 3 are free once it has run: the second filling writes its
//     results there, and a last pass copies them into 2 and 4.
// 0, 1 and 2 are the picture's rows; 3, 4, 5 and 6 have a margin of pc.margin pixels all round,
// set once to kEmpty (5: no sum) and never written, so neighbours are read at fixed offsets
// without a test for the picture's edge.
layout(push_constant) uniform Push {
  uint width;
  uint height;
  uint padded_width;  // width + 2 · margin
  uint margin;
  // Perspective: (far − near) / near, so the eye distance is far / (1 + depth · depth_scale) for the
  // reversed-Z depth in (0, 1]; 0 for ortho, whose depth is linear (far at 0, near at 1).
  float depth_scale;
  float strength;        // eye-dome darkening
  int edl_axis;          // eye-dome neighbours: (±edl_axis, 0), (0, ±edl_axis) and (±edl_diagonal, ±edl_diagonal)
  int edl_diagonal;
  float fill_threshold;  // hole filling: how much nearer (log2 eye distance) a surrounding pixel must stand
  uint axis;             // smooth.comp: 0 rows, 1 columns; fill_again.comp: its step
} pc;

#include "log_distance.glsl"

const int kCandidateCount = 0, kCandidateGroups = 1, kCandidateList = 4;  // in binding 7
const uint kCandidateGroup = 64u;  // fill_again.comp's local_size_x
// Its workgroups at most: every device dispatches 65,535 along x (maxComputeWorkGroupCount's least),
// and a picture can hold more than 65,535 · 64 candidates (5120x2880 with 1-px points on black).
const uint kCandidateGroupsMost = 65535u;

bool inside(ivec2 q) { return q.x >= 0 && q.y >= 0 && q.x < int(pc.width) && q.y < int(pc.height); }
int pixelIndex(ivec2 q) { return q.y * int(pc.width) + q.x; }
int paddedIndex(ivec2 q) { return (q.y + int(pc.margin)) * int(pc.padded_width) + q.x + int(pc.margin); }
// The index step to a neighbour `d` away in the padded buffers (the same for every pixel).
int paddedStep(ivec2 d) { return d.y * int(pc.padded_width) + d.x; }
