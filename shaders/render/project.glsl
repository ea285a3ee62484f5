// The per-mode projection (DESIGN §4), shared by the raster vertex shader (points.vert) and the
// compute splat (points_splat.comp), so both backends and the probe run the same arithmetic.
// Every mode but fp32 and split works in the scene frame (viewer/encode.h): positions, eye and
// matrices arrive scaled by a power of two so no intermediate leaves float's range.
// The mode is a define: MODE_FP32, MODE_SPLIT, MODE_RTE, MODE_DF64, MODE_NATIVE_ATTR,
// MODE_NATIVE_PULL (native reading a storage buffer), MODE_BATCH or MODE_ADAPTIVE.

#include "push.glsl"

#if defined(MODE_FP32) || defined(MODE_SPLIT)
layout(std140, set = 0, binding = 0) uniform CameraBlock { mat4 mvp; } cam;
#elif defined(MODE_RTE)
layout(std140, set = 0, binding = 0) uniform CameraBlock { mat4 projection_rotation; vec4 eye_hi; vec4 eye_lo; } cam;
#elif defined(MODE_DF64)
#include "df64.glsl"
layout(std140, set = 0, binding = 0) uniform CameraBlock { mat4 mvp_hi; mat4 mvp_lo; } cam;
#elif defined(MODE_NATIVE_ATTR) || defined(MODE_NATIVE_PULL)
layout(std140, set = 0, binding = 0) uniform CameraBlock { dmat4 projection_rotation; dvec4 eye; } cam;
#elif defined(MODE_BATCH) || defined(MODE_ADAPTIVE)
layout(std430, set = 0, binding = 2) readonly buffer Batches { mat4 batch_mvp[]; };
// A point's offset in its batch (viewer/encode.h): three 21-bit two's-complement integers in one
// 64-bit word, x in bits 0–20, y in 21–41, z in 42–62; each is exact as a float.
// A field f becomes a float without an int-to-float conversion (lavapipe's batch splat 5% faster;
// no change on the H100, whose splat waits on memory): f ^ 2^20 is n + 2^20 in [0, 2^21), which
// placed in the significand of 1.5·2^23 gives the float 1.5·2^23 + 2^20 + n exactly; subtracting
// 1.5·2^23 + 2^20 = 13631488 (the same binade) is exact too, so the result is n, as float(n) is.
float offsetField(uint f) {
  precise float n = uintBitsToFloat(0x4B400000u | ((f & 0x1FFFFFu) ^ 0x100000u)) - 13631488.0;
  return n;
}
vec3 unpackOffset(uvec2 word) {
  return vec3(offsetField(word.x), offsetField((word.x >> 21) | (word.y << 11)), offsetField(word.y >> 10));
}
// Offsets are integers in the batch's box; the matrix carries origin, extent and 2^−20. The
// compute splat calls this directly with a matrix it loads once for all of a thread's points.
vec4 projectBatchOffset(vec3 offset, mat4 batch) { return batch * vec4(offset, 1.0); }
#if defined(MODE_ADAPTIVE)
// Adaptive mode (viewer/encode.h): a tier word holds 10 bits of x | y << 10 | z << 20 of the 30-bit
// q = round(t·2^29) + 2^29. With fewer than three tiers loaded, q is rebuilt as the centre of the
// cell its loaded bits name; the batch matrix takes q − 2^29 (in steps of 2^−29 of the extent) to
// clip space. One or two tiers give at most 21 significant bits, which convert to float exactly.
uvec3 tierFields(uint word) { return uvec3(word, word >> 10, word >> 20) & 1023u; }
vec3 adaptiveOffset(uvec3 q) { return vec3(ivec3(q) - (1 << 29)); }
vec3 rebuildTiers1(uint coarse) { return adaptiveOffset((tierFields(coarse) << 20) | (1u << 19)); }
vec3 rebuildTiers2(uint coarse, uint medium) {
  return adaptiveOffset((tierFields(coarse) << 20) | (tierFields(medium) << 10) | (1u << 9));
}
vec3 rebuildTiers3(uint coarse, uint medium, uint fine) {
  return adaptiveOffset((tierFields(coarse) << 20) | (tierFields(medium) << 10) | tierFields(fine));
}
#endif
#else
#error "no MODE_* defined"
#endif

// What one point carries, per mode.
#if defined(MODE_FP32) || defined(MODE_BATCH) || defined(MODE_ADAPTIVE)
struct PointInput { vec3 position; };
#elif defined(MODE_SPLIT) || defined(MODE_RTE) || defined(MODE_DF64)
struct PointInput { vec3 hi; vec3 lo; };
#else
struct PointInput { dvec3 position; };
#endif

// Clip position of point `index` (its index in the whole set: batch mode needs it).
vec4 projectPoint(PointInput point, uint index) {
#if defined(MODE_FP32)
  return cam.mvp * vec4(point.position, 1.0);
#elif defined(MODE_SPLIT)
  // The study's listing: hi + lo rounds back to hi, so this is fp32 with twice the bytes.
  return cam.mvp * vec4(point.hi + point.lo, 1.0);
#elif defined(MODE_RTE)
  // (hi − eye_hi) is exact when the point is near the eye (Sterbenz); adding the low parts'
  // difference keeps the eye-relative vector to float rounding.
  precise vec3 d_hi = point.hi - cam.eye_hi.xyz;
  precise vec3 d_lo = point.lo - cam.eye_lo.xyz;
  precise vec3 relative = d_hi + d_lo;
  return cam.projection_rotation * vec4(relative, 1.0);
#elif defined(MODE_DF64)
  vec2 p[4] = vec2[4](vec2(point.hi.x, point.lo.x), vec2(point.hi.y, point.lo.y), vec2(point.hi.z, point.lo.z),
                      vec2(1.0, 0.0));
  vec4 clip;
  for (int r = 0; r < 4; ++r) {
    vec2 sum = vec2(cam.mvp_hi[3][r], cam.mvp_lo[3][r]);
    for (int c = 0; c < 3; ++c)
      sum = dfAdd(sum, dfMul(vec2(cam.mvp_hi[c][r], cam.mvp_lo[c][r]), p[c], pc.splitter));
    clip[r] = sum.x;  // hi is the float nearest the double-float value
  }
  return clip;
#elif defined(MODE_NATIVE_ATTR) || defined(MODE_NATIVE_PULL)
  // The eye first: p − eye is exact when p is near the eye (Sterbenz), so the translation's
  // rounding never reaches the picture (a folded MVP would add half an ulp of |eye|). Only the
  // final clip position is rounded to float.
  dvec3 relative = point.position - cam.eye.xyz;
  return vec4(cam.projection_rotation * dvec4(relative, 1.0));
#elif defined(MODE_BATCH) || defined(MODE_ADAPTIVE)
  return projectBatchOffset(point.position, batch_mvp[index >> pc.batch_shift]);
#endif
}
