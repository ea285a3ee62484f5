#include "cli/cli_camera.h"

#include "cli/cli_text.h"

#include <cmath>

namespace dpoint {

void addCameraOptions(CLI::App& cmd, CameraCliOptions& o) {
  cmd.add_option("--width", o.width, "Picture width in pixels")->default_val(1024);
  cmd.add_option("--height", o.height, "Picture height in pixels")->default_val(768);
  cmd.add_option("--eye", o.eye, "Camera position X,Y,Z (with --target)");
  cmd.add_option("--target", o.target, "Point looked at X,Y,Z");
  cmd.add_option("--up", o.up, "Up direction X,Y,Z (default 0,1,0)");
  cmd.add_flag("--fit", o.fit, "Frame the bounding box (the default without --eye)");
  cmd.add_option("--fov", o.fov, "Vertical field of view in degrees")->default_val(45.0);
  cmd.add_flag("--ortho", o.ortho, "Orthographic projection (the default for 2D data, z = 0)");
  cmd.add_option("--view-center", o.view_center, "Orthographic window centre X,Y[,Z]");
  cmd.add_option("--view-width", o.view_width, "Orthographic window width (height follows the aspect)");
  cmd.add_option("--tolerance", o.tolerance,
                 "adaptive mode: the error in pixels its per-batch choice of tiers keeps within, wherever its three\n"
                 "tiers (30 bits) can")
      ->check([](const std::string& v) {
        Result<double> px = parseTolerance(v);
        return px ? std::string() : px.error().message;
      })
      ->default_val("0.05");
}

Result<double> parseTolerance(const std::string& text) {
  Result<std::vector<double>> px = parseNumbers("--tolerance", text, 1);
  if (!px) return px.error();
  if (!((*px)[0] > 0.0) || !std::isfinite((*px)[0]))
    return Error{"--tolerance " + text + ": must be a number of pixels above 0", ExitCode::kUsage};
  return (*px)[0];
}

Result<CameraSpec> cameraSpec(const CameraCliOptions& o) {
  CameraSpec spec;
  spec.width = o.width;
  spec.height = o.height;
  spec.fov_degrees = o.fov;
  bool look_at = !o.eye.empty() || !o.target.empty() || !o.up.empty();
  if (look_at) {
    if (o.fit) return Error{"--fit and --eye/--target/--up exclude each other", ExitCode::kUsage};
    if (o.eye.empty() || o.target.empty())
      return Error{"--eye and --target go together (and --up, default 0,1,0)", ExitCode::kUsage};
    Result<glm::dvec3> eye = parseVec3("--eye", o.eye);
    if (!eye) return eye.error();
    Result<glm::dvec3> target = parseVec3("--target", o.target);
    if (!target) return target.error();
    Result<glm::dvec3> up = parseVec3("--up", o.up.empty() ? "0,1,0" : o.up);
    if (!up) return up.error();
    spec.eye = *eye;
    spec.target = *target;
    spec.up = *up;
  }
  if (o.ortho) spec.ortho = true;
  if (!o.view_center.empty()) {
    Result<std::vector<double>> c = parseNumbers("--view-center", o.view_center, 2, 3);
    if (!c) return c.error();
    spec.view_center = glm::dvec3((*c)[0], (*c)[1], c->size() == 3 ? (*c)[2] : 0.0);
    spec.ortho = true;
  }
  if (o.view_width) {
    spec.view_width = *o.view_width;
    spec.ortho = true;
  }
  return spec;
}

}  // namespace dpoint
