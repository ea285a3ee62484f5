#include "cli/cli_options.h"

#include "cli/cli_camera.h"
#include "cli/cli_check.h"
#include "cli/cli_suggest.h"

namespace dpoint {

Status parseOptions(CLI::App& app, const std::vector<std::string>& args) {
  std::vector<const char*> argv = {app.get_name().c_str()};
  for (const std::string& a : args) argv.push_back(a.c_str());
  const int argc = static_cast<int>(argv.size());
  try {
    app.parse(argc, argv.data());
  } catch (const CLI::ParseError& e) {
    if (std::optional<std::string> unknown = unknownOptionMessage(app, argc, argv.data()))
      return Error{*unknown, ExitCode::kUsage};
    return Error{app.get_name() + ": " + e.what(), ExitCode::kUsage};
  }
  return okStatus();
}

Result<CameraRequest> cameraRequestOf(const std::vector<std::string>& args) {
  CLI::App app{"the camera options of render and info", "camera"};
  CameraCliOptions o;
  addCameraOptions(app, o);
  if (Status s = parseOptions(app, args); !s) return s.error();
  Result<CameraSpec> spec = cameraSpec(o);
  if (!spec) return spec.error();
  return CameraRequest{*spec, *parseTolerance(o.tolerance)};
}

}  // namespace dpoint
