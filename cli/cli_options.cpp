#include "cli/cli_options.h"

#include "cli/cli_camera.h"
#include "cli/cli_check.h"
#include "cli/cli_suggest.h"

namespace dpoint {

Status parseOptions(CLI::App& dpoint, const std::string& command, const std::vector<std::string>& args) {
  std::vector<const char*> argv = {"dpoint", command.c_str()};
  for (const std::string& a : args) argv.push_back(a.c_str());
  const int argc = static_cast<int>(argv.size());
  try {
    dpoint.parse(argc, argv.data());
  } catch (const CLI::ParseError& e) {  // as the executable reports it (cli_run.cpp)
    if (std::optional<std::string> unknown = unknownOptionMessage(dpoint, argc, argv.data()))
      return Error{*unknown, ExitCode::kUsage};
    return Error{usageMessage(e, dpoint, argc, argv.data()), ExitCode::kUsage};
  }
  return okStatus();
}

Result<CameraRequest> cameraRequestOf(const std::vector<std::string>& args) {
  CLI::App dpoint{"", "dpoint"};
  CameraCliOptions o;
  addCameraOptions(*dpoint.add_subcommand("info"), o);
  if (Status s = parseOptions(dpoint, "info", args); !s) return s.error();
  Result<CameraSpec> spec = cameraSpec(o);
  if (!spec) return spec.error();
  return CameraRequest{*spec, *parseTolerance(o.tolerance)};
}

}  // namespace dpoint
