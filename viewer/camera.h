// Camera math, all in double on the CPU (DESIGN §4). Every precision mode starts from the same
// Camera; only what each mode sends to the GPU differs (viewer/encode.h).
//
// Conventions: right-handed world, the eye looks down its −z axis. Clip space is Vulkan's:
// x right, y down, depth = z_clip / w_clip in [0, 1] with reversed Z (near plane → 1, far → 0;
// the depth test keeps the greater value). Window coordinates of a clip position c:
//   x_win = (c.x / c.w · 0.5 + 0.5) · width,  y_win = (c.y / c.w · 0.5 + 0.5) · height,
// so pixel (i, j) covers [i, i+1) × [j, j+1) and its centre is (i + 0.5, j + 0.5).
#pragma once

#include <cstdint>
#include <optional>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/point_set.h"
#include "core/result.h"

namespace dpoint {

struct CameraSpec {
  uint32_t width = 1024, height = 768;
  // Perspective look-at when eye, target and up are all set (orthographic if ortho is true);
  // setting only some of them is a usage error. Otherwise --fit (the default): the bounding box
  // is framed whole, from a fixed oblique direction for 3D data and straight down the z axis for
  // 2D data (all z = 0), which defaults to orthographic. Ortho always looks straight down −z.
  std::optional<glm::dvec3> eye, target, up;
  double fov_degrees = 45.0;  // vertical field of view (perspective)
  // Orthographic. view_center/view_width pick the window (height follows the aspect ratio);
  // without them the fit frames the bounding box. Either may be given alone (the other comes from
  // the fit). Ortho ignores view_center.z (the eye sits above the box). With perspective they
  // zoom the fit: the eye looks at view_center (z included: set it to the bounds' centre z when
  // the user gives only x, y) from the fit's direction, at the distance where the window is
  // view_width wide at view_center. Not allowed with eye/target/up.
  std::optional<bool> ortho;  // unset: ortho for 2D data, perspective for 3D
  std::optional<glm::dvec3> view_center;
  std::optional<double> view_width;
  // The perspective fit of 3D data: the direction from the target to the eye and the picture's up
  // (not parallel; neither need be unit length). Unset: an oblique direction, (0.6, 0.5, 1)
  // normalized, with +y up. Not allowed with eye/target/up; ignored by ortho and for 2D data.
  std::optional<glm::dvec3> fit_direction, fit_up;
};

struct Camera {
  uint32_t width = 0, height = 0;
  bool ortho = false;
  glm::dvec3 eye{0.0};         // world position of the eye
  glm::dmat4 rotation{1.0};    // world directions → eye space (view = rotation · translate(−eye))
  // eye space → clip space (Vulkan y-down, reversed Z); perspective is scaled by 1/far (clip is
  // homogeneous, so no window position changes) to keep clip values near 1 at any scene scale.
  glm::dmat4 projection{1.0};
  double near_plane = 0.0, far_plane = 0.0;

  glm::dmat4 view() const;            // rotation · translate(−eye)
  glm::dmat4 viewProjection() const;  // projection · view()
};

struct Bounds {
  glm::dvec3 min{0.0}, max{0.0};
  bool planar = false;  // every z is 0
};

// Builds the camera. Fails (kUsage, naming the option) on a zero-size viewport, eye == target,
// up parallel to the view direction, fov outside (0, 180), a non-positive or non-finite view
// width, non-finite vectors, and the combinations refused above. Bounds must be finite with
// min ≤ max (asserted). Degenerate bounds (one point, all points equal) still give a usable
// camera: the framing never uses a box smaller than 1e-10 of the largest coordinate (or 1 at the
// origin). Near and far planes enclose the bounding box as seen from the eye: with the box wholly
// in front of the eye, every box point has depth in (0, 1]. Perspective near > 0: a box around
// the eye gets near = far·1e-6, and points nearer than that or behind the eye are outside the view
// volume. Ortho near may be < 0 (the slab then reaches behind the eye and holds the whole box).
Result<Camera> makeCamera(const CameraSpec& spec, const Bounds& bounds);

// The bounding box of a non-empty set, and whether it is 2D (PointSet::isPlanar).
Bounds boundsOf(const PointSet& points);

}  // namespace dpoint
