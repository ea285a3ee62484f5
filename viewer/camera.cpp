// Camera construction: look-at rotation, reversed-Z Vulkan projections, the --fit framing, and
// near/far planes chosen from the bounding box as seen from the eye.
//
// Everything is double. The eye and the rotation are kept apart (no folded view matrix) because
// the eye-relative modes (rte, batch) subtract the eye themselves; the translation part of view()
// loses digits at large offsets and is only there for the modes that use it as is.
#include "viewer/camera.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <numbers>
#include <string>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "core/parallel.h"

namespace dpoint {
namespace {

// Framing margins (kFitMargin in camera.h: the fit leaves 2% around the box); far sits 1% beyond
// the farthest corner and near 1% before the nearest one, so no box point is clipped by the
// rounding of the planes.
constexpr double kFarMargin = 1.01;
constexpr double kNearMargin = 0.99;
// A perspective near plane never closer than far · 1e-6: with reversed Z in float, depth keeps
// about 2^-24 relative precision everywhere, so a large far/near ratio costs nothing, but near
// must stay positive when the eye is inside the box (points behind it are simply outside).
constexpr double kNearFloor = 1e-6;
// The extent a degenerate box (one point, all points equal) is framed as, relative to the largest
// coordinate: the point at 6.4e6 still gets an eye far enough from it that eye − target is many
// ulps long and the view direction is accurate (to ~1e-6). Boxes of any other size are framed as
// they are: the fit takes its view direction from the spec, not from the rounded eye − target.
constexpr double kMinRelativeExtent = 1e-10;
// Rounds of the perspective fit's correction for the eye's rounding (see fitPerspective).
constexpr int kFitRounds = 4;
// The share of its distance from the target by which rounding may move the fitted perspective eye
// before the default view gives up on perspective: a box 9 ulps wide (1e-15 at 0.74) moves it by
// ~5%, still the view asked for; a set 2 wide at x = 1e18 (double's step 128) by ~45%, edge-on.
constexpr double kMaxEyeDrift = 0.2;
// The outline's grid: rows along x on kOutlineGrid² cells over y, z (OutlineBuilder).
constexpr int kOutlineGrid = 64;

std::string shortest(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

std::string shortest(const glm::dvec3& v) {
  // Appended piece by piece: GCC 12's -Wrestrict misfires on "(" + std::string under -O2.
  std::string out = "(";
  out += shortest(v.x);
  out += ", ";
  out += shortest(v.y);
  out += ", ";
  out += shortest(v.z);
  out += ")";
  return out;
}

using dpoint::isFinite;  // core/point_set.h's, for a vector, beside this one for a matrix
bool isFinite(const glm::dmat4& m) {
  for (int c = 0; c < 4; ++c)
    if (!isFinite(glm::dvec3(m[c])) || !std::isfinite(m[c].w)) return false;
  return true;
}

double maxAbs(const glm::dvec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); }

// glm::length and glm::normalize square the components, which underflows for a scene at 1e-300 m
// (and overflows at 1e200 m); dividing by the largest component first keeps every square in range.
double safeLength(const glm::dvec3& v) {
  const double largest = maxAbs(v);
  return largest > 0.0 && std::isfinite(largest) ? largest * glm::length(v / largest) : largest;
}
glm::dvec3 safeNormalize(const glm::dvec3& v) { return glm::normalize(v / maxAbs(v)); }

// Half-extent floor for framing around `position`; 1 near the origin, where no relative scale exists.
double minHalfExtent(const glm::dvec3& position) {
  const double relative = kMinRelativeExtent * maxAbs(position);
  return relative > 0.0 ? relative : 1.0;
}

bool isDegenerate(const Bounds& bounds) { return bounds.min == bounds.max; }

Error usage(std::string message) { return Error{std::move(message), ExitCode::kUsage}; }

// World → eye rotation: rows are right, up and −forward (the eye looks down its −z).
// The caller has checked that forward and up are non-zero and not parallel.
glm::dmat4 lookAtRotation(const glm::dvec3& forward, const glm::dvec3& up) {
  const glm::dvec3 f = safeNormalize(forward);
  const glm::dvec3 s = safeNormalize(glm::cross(f, safeNormalize(up)));
  const glm::dvec3 u = glm::cross(s, f);
  glm::dmat4 rotation(1.0);  // glm is column-major: rotation[column][row]
  for (int i = 0; i < 3; ++i) {
    rotation[i][0] = s[i];
    rotation[i][1] = u[i];
    rotation[i][2] = -f[i];
  }
  return rotation;
}

std::array<glm::dvec3, 8> corners(const Bounds& bounds) {
  std::array<glm::dvec3, 8> out;
  for (int i = 0; i < 8; ++i) {
    out[static_cast<size_t>(i)] = {(i & 1) ? bounds.max.x : bounds.min.x, (i & 2) ? bounds.max.y : bounds.min.y,
                                   (i & 4) ? bounds.max.z : bounds.min.z};
  }
  return out;
}

// The points the fit frames: the outline when there is one, else the box's corners.
PositionArray framedPoints(const Bounds& bounds) {
  if (!bounds.outline.empty()) return bounds.outline;
  const std::array<glm::dvec3, 8> box = corners(bounds);
  return {box.begin(), box.end()};
}

// The perspective fit: the eye's distance from `target` along `direction` (unit), for a camera
// with `rotation`. Every framed point p must lie inside the frustum shrunk by kFitMargin: with
// q = p − eye in eye space, |q.x| ≤ depth·tan_x and |q.y| ≤ depth·tan_y (depth = −q.z). For an eye
// at target + d·direction this is linear in d: d ≥ z + max(|x|/tan_x, |y|/tan_y), where x, y, z are
// p − target along right, up and direction, so the smallest such d frames the projected extent
// exactly (not the bounding sphere, which leaves a box's projection 55–80% of the picture).
// Perspective makes that extent lopsided (the near side looks larger), so when `recentre` the
// target moves sideways to the middle of the projected extent, a few rounds, and d is found again.
// The eye is then rounded to doubles: on a box a few ulps wide that moves it sideways by a share
// of the box, so the condition is checked again from the rounded eye and d grows by what is
// missing (a few rounds; each misses by at most the rounding). d is at least kFitMargin times the
// farthest point's distance from the target, so the eye is outside the data and every depth > 0.
double fitPerspective(const PositionArray& points, glm::dvec3& target, const glm::dvec3& direction,
                      const glm::dmat4& rotation, double tan_x, double tan_y, bool recentre) {
  const glm::dvec3 right(rotation[0][0], rotation[1][0], rotation[2][0]);
  const glm::dvec3 up(rotation[0][1], rotation[1][1], rotation[2][1]);
  const auto closedForm = [&](const glm::dvec3& t) {
    double d = 0.0, reach = 0.0;
    for (const glm::dvec3& p : points) {
      const glm::dvec3 q = p - t;
      const double need = std::max(std::abs(glm::dot(q, right)) / tan_x, std::abs(glm::dot(q, up)) / tan_y);
      d = std::max(d, glm::dot(q, direction) + need);
      reach = std::max(reach, safeLength(q));
    }
    return std::max(d, kFitMargin * reach);
  };
  double distance = closedForm(target);
  for (int round = 0; recentre && round < kFitRounds; ++round) {
    double lo_x = HUGE_VAL, hi_x = -HUGE_VAL, lo_y = HUGE_VAL, hi_y = -HUGE_VAL;
    for (const glm::dvec3& p : points) {  // each point's direction from the eye, in tangent units
      const glm::dvec3 q = p - target;
      const double depth = distance - glm::dot(q, direction);
      const double x = glm::dot(q, right) / depth, y = glm::dot(q, up) / depth;
      lo_x = std::min(lo_x, x), hi_x = std::max(hi_x, x), lo_y = std::min(lo_y, y), hi_y = std::max(hi_y, y);
    }
    // The middle ray meets the target's plane (depth = distance) this far off the target.
    target += (0.5 * (lo_x + hi_x) * distance) * right + (0.5 * (lo_y + hi_y) * distance) * up;
    distance = closedForm(target);
  }
  for (int round = 0; round < kFitRounds; ++round) {
    const glm::dvec3 eye = target + distance * direction;
    double missing = 0.0;
    for (const glm::dvec3& p : points) {
      const glm::dvec3 q = p - eye;
      const double need = std::max(std::abs(glm::dot(q, right)) / tan_x, std::abs(glm::dot(q, up)) / tan_y);
      missing = std::max(missing, need + glm::dot(q, direction));  // need − depth
    }
    if (!(missing > 0.0)) break;
    distance += 2.0 * missing;
  }
  return distance;
}

// Near and far planes enclosing the box. Depth along the view axis is linear, so its extremes over
// the box are at corners; corner − eye is computed before rotating so large offsets cancel first.
void choosePlanes(Camera& camera, const Bounds& bounds) {
  double nearest = HUGE_VAL, farthest = -HUGE_VAL, farthest_distance = 0.0;
  for (const glm::dvec3& corner : corners(bounds)) {
    const glm::dvec3 relative = corner - camera.eye;
    const double along = -(camera.rotation[0][2] * relative.x + camera.rotation[1][2] * relative.y +
                           camera.rotation[2][2] * relative.z);
    nearest = std::min(nearest, along);
    farthest = std::max(farthest, along);
    farthest_distance = std::max(farthest_distance, safeLength(relative));
  }
  if (camera.ortho) {
    // Any slab works for ortho. Near = 0 when the box is wholly in front keeps z_clip = z_e/far + 1
    // well conditioned; an eye inside the box gets a near plane behind it.
    double pad = 0.01 * (farthest - nearest);
    if (!(pad > 0.0)) pad = 0.01 * std::max(std::abs(nearest), std::abs(farthest));
    if (!(pad > 0.0)) pad = minHalfExtent(camera.eye);
    camera.near_plane = nearest >= 0.0 ? 0.0 : nearest - pad;
    camera.far_plane = farthest + pad;
  } else {
    // All corners at the eye (one point, looked at from itself) still needs a usable frustum. Only
    // then: a floor relative to the coordinates would clip a set 2 wide seen from 3 away at 1e18.
    camera.far_plane = farthest_distance > 0.0 ? farthest_distance * kFarMargin : minHalfExtent(camera.eye);
    camera.near_plane = std::max(nearest * kNearMargin, camera.far_plane * kNearFloor);
  }
}

// Vulkan clip: y down, reversed Z (depth = z_c/w_c: near → 1, far → 0), the whole matrix scaled by
// 1/far. Clip space is homogeneous, so the scale changes no x/w, y/w or z/w, but it keeps clip
// coordinates near 1 whatever the scene's scale: without it a scene at 1e-37 m gives clip values
// below float's normal range, which a GPU flushes to zero. Each entry is formed so that no
// intermediate leaves double's range either: near·far would underflow for a scene at 1e-300 m.
glm::dmat4 perspectiveProjection(double fov_radians, double aspect, double near_plane, double far_plane) {
  const double focal = 1.0 / std::tan(fov_radians / 2.0);
  const double near_share = near_plane / (far_plane - near_plane);  // near/(far − near), O(1)
  glm::dmat4 p(0.0);
  p[0][0] = focal / aspect / far_plane;
  p[1][1] = -focal / far_plane;
  p[2][2] = near_share / far_plane;
  p[3][2] = near_share;
  p[2][3] = -1.0 / far_plane;
  return p;
}

glm::dmat4 orthoProjection(double view_width, double view_height, double near_plane, double far_plane) {
  glm::dmat4 p(0.0);
  p[0][0] = 2.0 / view_width;
  p[1][1] = -2.0 / view_height;
  p[2][2] = 1.0 / (far_plane - near_plane);
  p[3][2] = far_plane / (far_plane - near_plane);
  p[3][3] = 1.0;
  return p;
}

// An ortho fit's window width: `fitted` unless the box projects to nothing (a degenerate box, or a
// segment along the view axis), where it is the degenerate floor or the box's largest side.
double fitWidth(double fitted, const Bounds& bounds) {
  if (fitted > 0.0) return fitted;
  return isDegenerate(bounds) ? 2.0 * minHalfExtent(bounds.min)
                              : kFitMargin * maxAbs(bounds.max - bounds.min);
}

// An ortho window centred on the eye's view axis, wide enough for every corner of the box.
double windowAround(const Camera& camera, const Bounds& bounds, double margin, double aspect) {
  double half_x = 0.0, half_y = 0.0;
  for (const glm::dvec3& corner : corners(bounds)) {
    const glm::dvec4 e = camera.rotation * glm::dvec4(corner - camera.eye, 0.0);
    half_x = std::max(half_x, std::abs(e.x));
    half_y = std::max(half_y, std::abs(e.y));
  }
  return fitWidth(2.0 * margin * std::max(half_x, half_y * aspect), bounds);
}

Status checkSpec(const CameraSpec& spec) {
  if (spec.width == 0 || spec.height == 0) {
    return usage(spec.width == 0 ? "--width 0: must be at least 1" : "--height 0: must be at least 1");
  }
  if (!(spec.fov_degrees > 0.0 && spec.fov_degrees < 180.0)) {
    return usage("--fov " + shortest(spec.fov_degrees) + ": must be in (0, 180)");
  }
  if (spec.view_width && !(std::isfinite(*spec.view_width) && *spec.view_width > 0.0)) {
    return usage("--view-width " + shortest(*spec.view_width) + ": must be a finite number above 0");
  }
  if (spec.view_center && !isFinite(*spec.view_center)) {
    return usage("--view-center " + shortest(*spec.view_center) + ": must be finite");
  }
  const int given = int(spec.eye.has_value()) + int(spec.target.has_value()) + int(spec.up.has_value());
  if (spec.fit_direction || spec.fit_up) {
    const glm::dvec3 direction = spec.fit_direction.value_or(glm::dvec3(0.6, 0.5, 1.0));
    const glm::dvec3 up = spec.fit_up.value_or(glm::dvec3(0.0, 1.0, 0.0));
    if (given) return usage("a fit direction cannot be combined with --eye/--target/--up");
    if (!isFinite(direction) || maxAbs(direction) == 0.0)
      return usage("the fit direction must be a finite non-zero vector, got " + shortest(direction));
    if (!isFinite(up) || maxAbs(up) == 0.0) return usage("the fit's up must be a finite non-zero vector, got " + shortest(up));
    if (glm::length(glm::cross(safeNormalize(direction), safeNormalize(up))) < 1e-9)
      return usage("the fit's up " + shortest(up) + " is parallel to its direction " + shortest(direction));
  }
  if (given == 0) return okStatus();
  if (given != 3) {
    return usage(std::string("--eye, --target and --up go together; missing") + (spec.eye ? "" : " --eye") +
                 (spec.target ? "" : " --target") + (spec.up ? "" : " --up"));
  }
  if (spec.view_center) return usage("--view-center cannot be combined with --eye/--target/--up");
  const glm::dvec3 eye = *spec.eye, target = *spec.target, up = *spec.up;
  if (!isFinite(eye)) return usage("--eye " + shortest(eye) + ": must be finite");
  if (!isFinite(target)) return usage("--target " + shortest(target) + ": must be finite");
  if (!isFinite(up) || maxAbs(up) == 0.0) return usage("--up " + shortest(up) + ": must be a finite non-zero vector");
  if (eye == target) return usage("--eye and --target are the same point " + shortest(eye));
  // Parallel when the sine of the angle between them is below 1e-9: the right vector would be noise.
  const glm::dvec3 forward = safeNormalize(target - eye);
  if (glm::length(glm::cross(forward, safeNormalize(up))) < 1e-9) {
    return usage("--up " + shortest(up) + " is parallel to the view direction " + shortest(forward));
  }
  return okStatus();
}

}  // namespace

glm::dmat4 Camera::view() const {
  glm::dmat4 translate(1.0);
  translate[3] = glm::dvec4(-eye, 1.0);
  return rotation * translate;
}

glm::dmat4 Camera::viewProjection() const { return projection * view(); }

Result<Camera> makeCamera(const CameraSpec& spec, const Bounds& bounds) {
  assert(isFinite(bounds.min) && isFinite(bounds.max));
  assert(bounds.min.x <= bounds.max.x && bounds.min.y <= bounds.max.y && bounds.min.z <= bounds.max.z);
  if (Status status = checkSpec(spec); !status) return status.error();

  Camera camera;
  camera.width = spec.width;
  camera.height = spec.height;
  camera.ortho = spec.ortho.value_or(bounds.planar);
  const double aspect = double(spec.width) / double(spec.height);
  const double half_fov = spec.fov_degrees * std::numbers::pi / 360.0;
  const double half_fov_x = std::atan(std::tan(half_fov) * aspect);
  // Halves first: the same bits as (min + max) / 2 (halving is exact), which overflowed past 9e307.
  const glm::dvec3 centre = 0.5 * bounds.min + 0.5 * bounds.max;
  const glm::dvec3 extent = bounds.max - bounds.min;
  const glm::dvec3 up_y(0.0, 1.0, 0.0);
  double view_width = 0.0;  // ortho only
  // The fit's margin, widened by fit_margin_px on each side.
  const double margin = kFitMargin * (1.0 + 2.0 * spec.fit_margin_px / double(std::min(spec.width, spec.height)));

  if (spec.eye) {
    camera.eye = *spec.eye;
    camera.rotation = lookAtRotation(*spec.target - *spec.eye, *spec.up);
    if (camera.ortho) view_width = spec.view_width.value_or(windowAround(camera, bounds, margin, aspect));
  } else if (camera.ortho) {
    // Straight down −z; the eye's x, y are the window centre, its height only sets the depth slab.
    view_width = spec.view_width.value_or(fitWidth(margin * std::max(extent.x, extent.y * aspect), bounds));
    const glm::dvec3 window = spec.view_center.value_or(centre);
    const double height = std::max({extent.z, view_width, isDegenerate(bounds) ? 2.0 * minHalfExtent(centre) : 0.0});
    camera.eye = {window.x, window.y, bounds.max.z + height};
    camera.rotation = lookAtRotation({0.0, 0.0, -1.0}, up_y);
  } else {
    // Perspective fit: 2D data straight down −z, 3D data from a fixed oblique direction.
    const glm::dvec3 direction = bounds.planar      ? glm::dvec3(0.0, 0.0, 1.0)
                                 : spec.fit_direction ? safeNormalize(*spec.fit_direction)
                                                      : glm::normalize(glm::dvec3(0.6, 0.5, 1.0));
    const glm::dvec3 up = bounds.planar ? up_y : spec.fit_up.value_or(up_y);
    glm::dvec3 target = spec.view_center.value_or(centre);
    // From the direction asked for, not from the rounded eye − target, which is only a few ulps
    // long when the box is.
    camera.rotation = lookAtRotation(-direction, up);
    double distance = 0.0;
    if (spec.view_width) {
      distance = 0.5 * *spec.view_width / std::tan(half_fov_x);  // the window is view_width wide at target
    } else if (!isDegenerate(bounds)) {
      distance = fitPerspective(framedPoints(bounds), target, direction, camera.rotation,
                                std::tan(half_fov_x) / margin, std::tan(half_fov) / margin,
                                !spec.view_center);
    } else if (bounds.planar) {
      // One point: framed as a square 2e-10 of its coordinates wide (kMinRelativeExtent).
      distance = kFitMargin * minHalfExtent(centre) / std::tan(half_fov_x);
    } else {
      // One point: framed as a sphere of radius 1e-10 of its coordinates (kMinRelativeExtent).
      distance = kFitMargin * minHalfExtent(centre) / std::sin(std::min(half_fov, half_fov_x));
    }
    camera.eye = target + distance * direction;
    // Coordinates near the largest double: the fitted eye lies past it (a review finding, which was
    // blamed on --view-center/--view-width though neither was given).
    auto too_large = [&](const std::string& why) {
      return Error{"the data's coordinates (up to " + shortest(std::max(maxAbs(bounds.min), maxAbs(bounds.max))) +
                       ") are too large " + why + "; try --ortho",
                   ExitCode::kBadInput};
    };
    if (!isFinite(camera.eye) && isFinite(bounds.min) && isFinite(bounds.max)) {  // (--allow-nonfinite's data aside)
      // A field of view so narrow that the distance alone overflows is the option's (a review
      // finding: --fov 1e-300 blamed coordinates of 0.99).
      if (std::tan(half_fov) < 1e-10 && !std::isfinite(distance))
        return Error{"--fov " + shortest(spec.fov_degrees) + ": so narrow a view puts the fitted eye past the largest "
                         "double; give a wider --fov, or --ortho",
                     ExitCode::kUsage};
      return too_large("to view in perspective: its eye would lie past the largest double");
    }
    // A set small against its coordinates (2 wide at x = 1e18, where double's step is 128): the
    // eye rounds a large share of its distance away from where the fit put it, and sees the data
    // edge-on or not at all (a blank picture, exit 0). The default view then draws them orthographic
    // along the same direction, which needs no eye off the data's plane, and says so.
    const double drift = safeLength((camera.eye - target) - distance * direction) / distance;
    if (!spec.ortho && !spec.view_width && !spec.view_center && !isDegenerate(bounds) && !(drift <= kMaxEyeDrift)) {
      camera.ortho = true;
      camera.eye = centre;
      view_width = windowAround(camera, bounds, margin, aspect);
      camera.note = "the data span " + shortest(extent) + " at coordinates up to " +
                    shortest(std::max(maxAbs(bounds.min), maxAbs(bounds.max))) +
                    ": too little for double to place a perspective eye near them; drawn orthographic from the "
                    "same direction (--eye/--target/--up choose another view)";
    } else {
      // A tiny --fov puts the fitted eye so far off that point − eye, in double, no longer places the
      // points within half a pixel: its step at the eye's distance against a pixel there, whatever the
      // scale (--fov 1e-15: the eye 1e17 of the data's sizes away, a blank picture and a bound of 0 px).
      const double pixel = 2.0 * distance * std::tan(half_fov_x) / double(spec.width);
      const double step = std::nextafter(distance, HUGE_VAL) - distance;
      if (isFinite(camera.eye) && !(step <= 0.5 * pixel))
        return usage("--fov " + shortest(spec.fov_degrees) + ": too narrow for double: the eye that frames the data lies " +
                     shortest(distance) + " from it, where double's step (" + shortest(step) +
                     ") is more than half a pixel there (" + shortest(0.5 * pixel) + "); use a wider --fov, or --ortho");
      if (camera.eye == target) {
        if (!spec.view_width && !spec.view_center) return too_large("for a perspective eye that does not round onto them");
        return usage("--view-center/--view-width: the perspective eye rounds onto the target " + shortest(target) +
                     "; the window is too small for coordinates this large");
      }
      // One point stays exactly at the picture's centre: its eye is far enough (kMinRelativeExtent)
      // for the rounded eye − target to give an accurate direction.
      if (isDegenerate(bounds) && !spec.view_width) camera.rotation = lookAtRotation(target - camera.eye, up);
    }
  }

  choosePlanes(camera, bounds);
  if (camera.ortho) {
    // The aspect first: width · height alone overflows for a view over 2e305 wide (a blank picture).
    const double view_height = view_width * (double(spec.height) / double(spec.width));
    if (!std::isfinite(view_height) && isFinite(bounds.min) && isFinite(bounds.max))  // (--allow-nonfinite's aside)
      return Error{"the view " + shortest(view_width) + " wide is " + shortest(view_height) + " high at " +
                       std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                       ", beyond the largest double: the data are too large to view at this aspect",
                   ExitCode::kBadInput};
    camera.projection = orthoProjection(view_width, view_height, camera.near_plane, camera.far_plane);
  } else {
    camera.projection = perspectiveProjection(2.0 * half_fov, aspect, camera.near_plane, camera.far_plane);
  }
  // Data too small for double's normal range (an extent of 1e-309: 2 / width overflows) or a view
  // whose planes overflow draw nothing: refused, where the picture was blank with a bound of 0 px.
  const bool finite = std::isfinite(camera.near_plane) && std::isfinite(camera.far_plane) && isFinite(camera.projection);
  if (!finite && isFinite(bounds.min) && isFinite(bounds.max))  // (--allow-nonfinite's data aside)
    return Error{"the view of the data (from " + shortest(bounds.min) + " to " + shortest(bounds.max) +
                     ") has no finite projection: its extent is below double's smallest normal number (2.2e-308) "
                     "or its depth beyond the largest; scale the data",
                 ExitCode::kBadInput};
  return camera;
}

Bounds boundsOf(const PointSet& points) {
  const Box box = boundingBox(points.positions);
  return Bounds{box.min, box.max, points.isPlanar(), {}};
}

// The boxes of the points of each row along x (a row: one cell of a kOutlineGrid² grid over the
// box's y, z), made of the points' own coordinates, so their corners hold every point whatever
// the rounding of the cell index. Their hull is the set's, widened by at most one cell (1/64 of the
// box) across the rows. min and max do not depend on the order, so blocks in any order and any
// number of threads give the same outline.
OutlineBuilder::OutlineBuilder(const Bounds& bounds)
    : min_(bounds.min), rows_(bounds.planar || isDegenerate(bounds) ? 0 : size_t{kOutlineGrid} * kOutlineGrid) {
  const glm::dvec3 extent = bounds.max - bounds.min;
  per_y_ = extent.y > 0.0 ? kOutlineGrid / extent.y : 0.0;  // cells per unit (0 along a flat axis: one cell)
  per_z_ = extent.z > 0.0 ? kOutlineGrid / extent.z : 0.0;
}

size_t OutlineBuilder::rowOf(const glm::dvec3& p) const {
  // floor(offset · per) clamped to the grid (offset ≥ 0 inside the box), by truncation, which is
  // the floor from 0 up: std::floor is a call to libm on the baseline x86-64 this builds for.
  const auto cellOf = [](double offset, double per) -> size_t {
    const double cell = offset * per;
    if (!(cell >= 0.0)) return 0;  // below the box (or NaN)
    if (cell >= double(kOutlineGrid - 1)) return kOutlineGrid - 1;
    return static_cast<size_t>(static_cast<int64_t>(cell));
  };
  return cellOf(p.y - min_.y, per_y_) * kOutlineGrid + cellOf(p.z - min_.z, per_z_);
}

void OutlineBuilder::add(const PositionArray& positions) {
  if (rows_.empty()) return;
  constexpr size_t kBlock = size_t{1} << 18;
  const size_t blocks = (positions.size() + kBlock - 1) / kBlock;
  // A worker's rows over all its blocks. Consecutive points mostly share a row (a set's order is
  // mostly local): a run of them is kept in registers and written to its row once, where a store
  // and load of the row for every point made each wait for the last.
  const unsigned threads = parallelWorkers(blocks, 0);
  std::vector<std::vector<RowBox>> partial(threads, std::vector<RowBox>(rows_.size()));
  parallelFor(blocks, threads, [&](size_t b, unsigned worker) {
    std::vector<RowBox>& rows = partial[worker];
    const size_t end = std::min(positions.size(), (b + 1) * kBlock);
    size_t run_row = SIZE_MAX;
    RowBox run;
    const auto flush = [&] {
      if (run_row == SIZE_MAX) return;
      rows[run_row].min = glm::min(rows[run_row].min, run.min);
      rows[run_row].max = glm::max(rows[run_row].max, run.max);
    };
    for (size_t i = b * kBlock; i < end; ++i) {
      const glm::dvec3& p = positions[i];
      const size_t row = rowOf(p);
      if (row != run_row) {
        flush();
        run_row = row;
        run = RowBox{};
      }
      run.min = glm::min(run.min, p);
      run.max = glm::max(run.max, p);
    }
    flush();
  });
  for (const std::vector<RowBox>& rows : partial) {
    for (size_t cell = 0; cell < rows_.size(); ++cell) {
      rows_[cell].min = glm::min(rows_[cell].min, rows[cell].min);
      rows_[cell].max = glm::max(rows_[cell].max, rows[cell].max);
    }
  }
}

bool OutlineBuilder::addBox(const Box& box) {
  if (rows_.empty()) return true;
  // The row index is monotonic in y and in z, so corners in one row hold every point between.
  const size_t row = rowOf(box.min);
  if (rowOf(box.max) != row) return false;
  rows_[row].min = glm::min(rows_[row].min, box.min);
  rows_[row].max = glm::max(rows_[row].max, box.max);
  return true;
}

PositionArray OutlineBuilder::finish() const {
  PositionArray outline;
  for (const RowBox& row : rows_) {
    if (!(row.min.x <= row.max.x)) continue;  // no point in this row
    const std::array<glm::dvec3, 8> box_corners = corners(Bounds{row.min, row.max, false, {}});
    outline.insert(outline.end(), box_corners.begin(), box_corners.end());
  }
  return outline;
}

Bounds boundsWithOutline(const PointSet& points) {
  Bounds bounds = boundsOf(points);
  OutlineBuilder builder(bounds);
  builder.add(points.positions);
  bounds.outline = builder.finish();
  return bounds;
}

}  // namespace dpoint
