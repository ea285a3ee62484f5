// The command line's options as library requests, for another front end (the Python module): its
// keyword arguments become the options they name (eye=(0, 0, 5) is --eye 0,0,5) and are parsed,
// checked and defaulted by the very parser the executable uses, with the same messages.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "core/result.h"
#include "viewer/camera.h"
#include "viewer/render_job.h"

namespace dpoint {

// Parses `dpoint COMMAND ARGS` (ARGS: options only, as on the command line) with `dpoint`, an app
// holding COMMAND as a subcommand; CLI11's refusals and dpoint's own validators' come back as the
// executable words them (kUsage, naming the option; the nearest known option for an unknown one).
Status parseOptions(CLI::App& dpoint, const std::string& command, const std::vector<std::string>& args);

// `dpoint render`'s options less the input, -o and --json: the request they make (with the report
// for one view: render --json's).
Result<RenderRequest> renderRequestOf(const std::vector<std::string>& args);

// The camera options render and info share (--width … --tolerance), as info's.
struct CameraRequest {
  CameraSpec spec;
  double tolerance_px = 0.0;
};
Result<CameraRequest> cameraRequestOf(const std::vector<std::string>& args);

}  // namespace dpoint
