// The log distance the shading passes compare and average (shade_common.glsl), written by the
// compute backend's resolve (points_resolve.comp) or, after the raster backend, by log.comp: the
// same function, so either backend gives the same picture.

const float kEmpty = 3.0e38;  // the log distance of a pixel with nothing drawn

// log2 of the eye distance at the reversed-Z depth d, up to a constant (only differences are
// used); kEmpty where nothing is drawn (d = 0). depth_scale: in perspective (far − near) / near,
// so the eye distance is far / (1 + d · depth_scale); 0 for ortho, whose depth is linear (far at
// 0, near at 1) and whose distance is taken from one depth range behind the far plane, so it
// stays positive: 1 + (1 − d).
float logDistance(float d, float depth_scale) {
  float l = depth_scale > 0.0 ? -log2(1.0 + d * depth_scale) : log2(2.0 - d);
  return d > 0.0 ? l : kEmpty;
}
