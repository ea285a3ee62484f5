// Camera math, all in double on the CPU (DESIGN §4). Every precision mode starts from the same
// Camera; only what each mode sends to the GPU differs (viewer/encode.h).
//
// Conventions: right-handed world, the eye looks down its −z axis. Clip space is Vulkan's:
// x right, y down, depth = z_clip / w_clip in [0, 1] with reversed Z (near plane → 1, far → 0;
// the depth test keeps the greater value). Window coordinates of a clip position c:
//   x_win = (c.x / c.w · 0.5 + 0.5) · width,  y_win = (c.y / c.w · 0.5 + 0.5) · height,
// so pixel (i, j) covers [i, i+1) × [j, j+1) and its centre is (i + 0.5, j + 0.5).
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/point_set.h"
#include "core/result.h"

namespace dpoint {

// The fit frames the data in 1 / kFitMargin of the picture: 1% of it free on each side.
inline constexpr double kFitMargin = 1.02;

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
  // Pixels the fit leaves free on each side beyond its 1% (the radius of large points).
  double fit_margin_px = 0.0;
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
  // Why the view is not the one asked for (the default fit's orthographic fallback); empty when it
  // is. `dpoint render` prints it as a warning and `dpoint info` beside the view.
  std::string note;

  glm::dmat4 view() const;            // rotation · translate(−eye)
  glm::dmat4 viewProjection() const;  // projection · view()
};

struct Bounds {
  glm::dvec3 min{0.0}, max{0.0};
  bool planar = false;  // every z is 0
  // Points whose convex hull holds every point of the set, so that the fit frames the data and
  // not the empty corners of its box (a Mandelbulb's box corners project ~1.3x wider than the
  // bulb). OutlineBuilder makes it; empty: the fit frames the box's eight corners.
  PositionArray outline;
};

// Builds the camera. Fails (kUsage, naming the option) on a zero-size viewport, eye == target,
// up parallel to the view direction, fov outside (0, 180), a non-positive or non-finite view
// width, non-finite vectors, and the combinations refused above. Bounds must be finite with
// min ≤ max (asserted). The fit frames the projected extent of the outline (or of the box's
// corners) so that it spans 1/1.02 of the picture along its limiting side, however small the box
// is against its coordinates: a deep zoom 1e-15 wide at 0.74 (a few ulps) fills the picture.
// Only degenerate bounds (min == max: one point, all points equal) get a floor: a box 1e-10 of
// the largest coordinate (or 1 at the origin) around the point. Near and far planes enclose the bounding box as seen from the eye: with the box wholly
// in front of the eye, every box point has depth in (0, 1]. Perspective near > 0: a box around
// the eye gets near = far·1e-6, and points nearer than that or behind the eye are outside the view
// volume. Ortho near may be < 0 (the slab then reaches behind the eye and holds the whole box).
Result<Camera> makeCamera(const CameraSpec& spec, const Bounds& bounds);

// The bounding box of a non-empty set and whether it is 2D (PointSet::isPlanar); no outline.
Bounds boundsOf(const PointSet& points);

// The outline of a 3D set whose box is known (a second pass over a streamed set, block by block):
// the corners of the boxes of the points in each row along x of a 64×64 grid over the box's y, z
// (at most 8·64² points). Blocks may come in any order and size, on any number of threads: the
// outline is the same. Empty for 2D and degenerate boxes (their box is their extent). Every added
// point must lie in the box given.
class OutlineBuilder {
 public:
  explicit OutlineBuilder(const Bounds& bounds);
  void add(const PositionArray& positions);
  // The points of a box that lies in one row, known by the box alone: their row's box takes its
  // corners, as it would take the points (its min and max along each axis are points' coordinates).
  // False, and nothing added, where the box spans rows: then its points must be added.
  bool addBox(const Box& box);
  PositionArray finish() const;

 private:
  size_t rowOf(const glm::dvec3& p) const;
  struct RowBox {
    glm::dvec3 min{HUGE_VAL}, max{-HUGE_VAL};
  };
  glm::dvec3 min_;
  double per_y_ = 0.0, per_z_ = 0.0;
  std::vector<RowBox> rows_;
};

// boundsOf with the outline, in memory.
Bounds boundsWithOutline(const PointSet& points);

}  // namespace dpoint
