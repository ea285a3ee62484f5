// Exact double positions in a GLB: what gltf_write stores and gltf_read rebuilds (issue #24 item 5).
//
// A point p (per axis) is stored as three float32 parts of its scaled offset from a double origin:
//   d  = p − t                       (t: the node translation)
//   ds = d · 2^-k                    (2^k: the node scale, k = 0 unless the data's magnitude is
//                                     outside float32's range)
//   hi = float(ds)                   POSITION, what every glTF reader uses
//   mid = float(ds − hi)             _POSITION_LOW  (application-specific attribute, glTF 2.0
//   lo  = float(ds − hi − mid)       _POSITION_LOW2  §3.7.2.1: names starting with "_"; other
//                                                    readers ignore them)
// and rebuilt as p' = world · ((hi + mid) + lo), world = T·S, in double.
//
// When p' == p bit for bit:
// 1. d is exact: p − t must be representable. t is the bounding-box centre when that holds for
//    every point (Sterbenz: p/2 ≤ t ≤ 2p, as for data far from the origin), else 0 (d = p).
// 2. ds is exact: multiplying by a power of two is, unless it underflows below 2^-1074.
// 3. The parts hold ds: each residual (ds − hi, then − mid) is exact in double (it is a multiple
//    of ds's last bit and smaller than hi's float ulp), so hi + mid + lo = ds exactly when the
//    last residual fits a float, i.e. when ds needs at most 24·3 = 72 significant bits (always:
//    a double has 53) and its lowest set bit is at least 2^-149 (float's smallest subnormal)
//    while |ds| < 2^128. With k chosen so |ds| < 2, that is: the offsets on one axis span at most
//    2^149 / 2^53 ≈ 2^96 in magnitude. Data with 1e-300 and 1 on one axis cannot be held.
// 4. The sums are exact: hi + mid and then + lo are each a prefix of ds's bits, so representable;
//    ds·2^k = d is exact by 2., and d + t = p is exact because p is a double and d = p − t exactly.
// 5. Signed zeros: −0.0 comes back as +0.0 (x + (−x) is +0 in round-to-nearest).
// The writer checks 1–5 on every point with the reader's own arithmetic (the glm matrix product)
// and reports how many points do not rebuild exactly; two parts suffice (and _POSITION_LOW2 is
// not written) when every point's ds needs at most 48 significant bits.
#pragma once

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace dpoint {

inline constexpr char kGltfPositionLow[] = "_POSITION_LOW";
inline constexpr char kGltfPositionLow2[] = "_POSITION_LOW2";

// The local (node-space) position from its parts, in the one order the writer verifies.
inline double joinGltfPositionParts(double hi, double mid, double lo) { return (hi + mid) + lo; }

// A vertex in world space: the reader's arithmetic, which the writer repeats to verify.
inline glm::dvec3 placeGltfVertex(const glm::dmat4& world, const glm::dvec3& local) {
  return glm::dvec3(world * glm::dvec4(local, 1.0));
}

}  // namespace dpoint
