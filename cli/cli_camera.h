// The camera options `render` and `info` share: one parser, one set of flags.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "core/result.h"
#include "viewer/camera.h"

namespace dpoint {

struct CameraCliOptions {
  uint32_t width = 1024, height = 768;
  std::string eye, target, up, view_center;
  bool fit = false, ortho = false;
  double fov = 45.0;
  std::optional<double> view_width;  // given: ortho at this width (0 or less is refused, as -1 was)
  // Not the camera's, but the view's precision target both commands predict for: adaptive mode's.
  std::string tolerance = "0.05";
};
// --tolerance: a finite number of pixels > 0 (kUsage, naming the flag).
Result<double> parseTolerance(const std::string& text);

void addCameraOptions(CLI::App& command, CameraCliOptions& options);

// Fails (kUsage, naming the flag) on malformed vectors and on --fit with --eye/--target/--up.
Result<CameraSpec> cameraSpec(const CameraCliOptions& options);

}  // namespace dpoint
