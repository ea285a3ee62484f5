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

#include <glm/geometric.hpp>

namespace dpoint {
namespace {

// Framing margins: the fit leaves 2% around the box; far sits 1% beyond the farthest corner and
// near 1% before the nearest one, so no box point is clipped by the rounding of the planes.
constexpr double kFitMargin = 1.02;
constexpr double kFarMargin = 1.01;
constexpr double kNearMargin = 0.99;
// A perspective near plane never closer than far · 1e-6: with reversed Z in float, depth keeps
// about 2^-24 relative precision everywhere, so a large far/near ratio costs nothing, but near
// must stay positive when the eye is inside the box (points behind it are simply outside).
constexpr double kNearFloor = 1e-6;
// The smallest extent a framing uses, relative to the largest coordinate: a box of one point (or
// narrower than a few ulps) at 6.4e6 still gets an eye far enough from the target that
// eye − target is many ulps long and the view direction is accurate (to ~1e-6).
constexpr double kMinRelativeExtent = 1e-10;

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

bool isFinite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

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
    // All corners at the eye (one point, looked at from itself) still needs a usable frustum.
    camera.far_plane = std::max(farthest_distance * kFarMargin, minHalfExtent(camera.eye));
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

Status checkSpec(const CameraSpec& spec) {
  if (spec.width == 0 || spec.height == 0) {
    return usage("--width and --height must be positive, got " + std::to_string(spec.width) + "x" +
                 std::to_string(spec.height));
  }
  if (!(spec.fov_degrees > 0.0 && spec.fov_degrees < 180.0)) {
    return usage("--fov must be in (0, 180), got " + shortest(spec.fov_degrees));
  }
  if (spec.view_width && !(std::isfinite(*spec.view_width) && *spec.view_width > 0.0)) {
    return usage("--view-width must be positive and finite, got " + shortest(*spec.view_width));
  }
  if (spec.view_center && !isFinite(*spec.view_center)) {
    return usage("--view-center must be finite, got " + shortest(*spec.view_center));
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
  if (!isFinite(eye)) return usage("--eye must be finite, got " + shortest(eye));
  if (!isFinite(target)) return usage("--target must be finite, got " + shortest(target));
  if (!isFinite(up) || maxAbs(up) == 0.0) return usage("--up must be a finite non-zero vector, got " + shortest(up));
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
  const glm::dvec3 centre = 0.5 * (bounds.min + bounds.max);
  const glm::dvec3 extent = bounds.max - bounds.min;
  const glm::dvec3 up_y(0.0, 1.0, 0.0);
  double view_width = 0.0;  // ortho only

  if (spec.eye) {
    camera.eye = *spec.eye;
    camera.rotation = lookAtRotation(*spec.target - *spec.eye, *spec.up);
    if (camera.ortho) {
      // Window centred on the view axis, wide enough for every corner.
      double half_x = 0.0, half_y = 0.0;
      for (const glm::dvec3& corner : corners(bounds)) {
        const glm::dvec4 e = camera.rotation * glm::dvec4(corner - camera.eye, 0.0);
        half_x = std::max(half_x, std::abs(e.x));
        half_y = std::max(half_y, std::abs(e.y));
      }
      view_width = spec.view_width.value_or(
          std::max(2.0 * kFitMargin * std::max(half_x, half_y * aspect), 2.0 * minHalfExtent(centre)));
    }
  } else if (camera.ortho) {
    // Straight down −z; the eye's x, y are the window centre, its height only sets the depth slab.
    const double fit_width = std::max(kFitMargin * std::max(extent.x, extent.y * aspect), 2.0 * minHalfExtent(centre));
    view_width = spec.view_width.value_or(fit_width);
    const glm::dvec3 window = spec.view_center.value_or(centre);
    const double height = std::max({extent.z, view_width, 2.0 * minHalfExtent(centre)});
    camera.eye = {window.x, window.y, bounds.max.z + height};
    camera.rotation = lookAtRotation({0.0, 0.0, -1.0}, up_y);
  } else {
    // Perspective fit: 2D data straight down −z, 3D data from a fixed oblique direction.
    const glm::dvec3 direction = bounds.planar      ? glm::dvec3(0.0, 0.0, 1.0)
                                 : spec.fit_direction ? safeNormalize(*spec.fit_direction)
                                                      : glm::normalize(glm::dvec3(0.6, 0.5, 1.0));
    const glm::dvec3 up = bounds.planar ? up_y : spec.fit_up.value_or(up_y);
    const glm::dvec3 target = spec.view_center.value_or(centre);
    double distance = 0.0;
    if (spec.view_width) {
      distance = 0.5 * *spec.view_width / std::tan(half_fov_x);  // the window is view_width wide at target
    } else if (bounds.planar) {
      // The rectangle lies in a plane facing the eye: fit its half-sizes to the two half-angles.
      const double half_x = std::max(0.5 * extent.x, minHalfExtent(centre));
      distance = kFitMargin * std::max(half_x / std::tan(half_fov_x), 0.5 * extent.y / std::tan(half_fov));
    } else {
      // The bounding sphere fits the narrower of the two half-angles.
      const double radius = std::max(0.5 * safeLength(extent), minHalfExtent(centre));
      distance = kFitMargin * radius / std::sin(std::min(half_fov, half_fov_x));
    }
    camera.eye = target + distance * direction;
    if (camera.eye == target) {
      return usage("--view-center/--view-width: the perspective eye rounds onto the target " + shortest(target) +
                   "; the window is too small for coordinates this large");
    }
    camera.rotation = lookAtRotation(target - camera.eye, up);
  }

  choosePlanes(camera, bounds);
  if (camera.ortho) {
    camera.projection = orthoProjection(view_width, view_width * double(spec.height) / double(spec.width),
                                        camera.near_plane, camera.far_plane);
  } else {
    camera.projection = perspectiveProjection(2.0 * half_fov, aspect, camera.near_plane, camera.far_plane);
  }
  return camera;
}

Bounds boundsOf(const PointSet& points) {
  const Box box = boundingBox(points.positions);
  return Bounds{box.min, box.max, points.isPlanar()};
}

}  // namespace dpoint
