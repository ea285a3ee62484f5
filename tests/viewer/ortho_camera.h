// The camera the encoding and mode-table tests share: orthographic, 64×64 pixels, `width` across,
// centred on `centre` (the fit of a one-point set, so the depth range is the default one).
#pragma once

#include <gtest/gtest.h>

#include <glm/vec3.hpp>

#include "core/point_set.h"
#include "viewer/camera.h"

namespace dpoint {

inline Camera orthoCamera(const glm::dvec3& centre, double width) {
  CameraSpec spec;
  spec.width = spec.height = 64;
  spec.view_center = centre;
  spec.view_width = width;
  PointSet s;
  s.positions = {centre};
  Result<Camera> camera = makeCamera(spec, boundsOf(s));
  EXPECT_TRUE(camera.ok()) << camera.error().message;
  return *camera;
}

// The same for the set `fit` (its depth range), `side`² pixels.
inline Camera orthoCamera(const PointSet& fit, const glm::dvec3& centre, double width, uint32_t side) {
  CameraSpec spec;
  spec.width = spec.height = side;
  spec.view_center = centre;
  spec.view_width = width;
  Result<Camera> camera = makeCamera(spec, boundsOf(fit));
  EXPECT_TRUE(camera.ok()) << camera.error().message;
  return *camera;
}

// Orthographic whatever the set (a 3D one too), straight down −z, `side`² pixels, `width` across,
// centred on the origin: points at one x, y share a pixel whatever their z.
inline Camera topDownCamera(const PointSet& fit, double width, uint32_t side) {
  CameraSpec spec;
  spec.width = spec.height = side;
  spec.ortho = true;
  spec.view_center = glm::dvec3(0.0);
  spec.view_width = width;
  Result<Camera> camera = makeCamera(spec, boundsOf(fit));
  EXPECT_TRUE(camera.ok()) << camera.error().message;
  return *camera;
}

}  // namespace dpoint
