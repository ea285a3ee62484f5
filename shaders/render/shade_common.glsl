// The push constants and buffers of the shading passes after either backend (fill.comp,
// smooth.comp, edl.comp; viewer/render_shade.cpp records them in that order). Bindings:
//   0 depth (float per pixel, 0 = nothing drawn), 1 picture (RGBA8): what the backend drew;
//   3 log distance, 4 picture: after hole filling (kEmpty where nothing is drawn);
//   5 (sum, count) of the log distances along each row's window, 6 their mean over the square;
//   2 the shaded picture that is read back.
layout(local_size_x = 16, local_size_y = 16) in;
layout(push_constant) uniform Push {
  uint width;
  uint height;
  // Perspective: (far − near) / near, so the eye distance is far / (1 + depth · depth_scale) for the
  // reversed-Z depth in (0, 1]; 0 for ortho, whose depth is linear (far at 0, near at 1).
  float depth_scale;
  float strength;        // eye-dome darkening
  float radius;          // eye-dome neighbour distance, pixels
  float fill_threshold;  // hole filling: how much nearer (log2 eye distance) a surrounding pixel must stand
  uint axis;             // smooth.comp: 0 rows, 1 columns
} pc;

const float kEmpty = 3.0e38;  // the log distance of a pixel with nothing drawn

bool inside(ivec2 q) { return q.x >= 0 && q.y >= 0 && q.x < int(pc.width) && q.y < int(pc.height); }
uint pixelIndex(ivec2 q) { return uint(q.y) * pc.width + uint(q.x); }

// log2 of the eye distance up to a constant (only differences are used). Ortho's distance is
// taken from one depth range behind the far plane, so it stays positive: 1 + (1 − depth).
float logDistance(float d) { return pc.depth_scale > 0.0 ? -log2(1.0 + d * pc.depth_scale) : log2(2.0 - d); }
// Its inverse: the depth at log distance l (both decrease with distance, so comparisons carry over).
float depthAt(float l) { return pc.depth_scale > 0.0 ? (exp2(-l) - 1.0) / pc.depth_scale : 2.0 - exp2(l); }
