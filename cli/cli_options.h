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

// Parses `args` (options only, as on the command line) with `app`; CLI11's refusals and dpoint's own
// validators' come back as kUsage errors naming the option, with the nearest known option for an
// unknown one.
Status parseOptions(CLI::App& app, const std::vector<std::string>& args);

// `dpoint render`'s options less the input, -o and --json: the request they make (report on).
Result<RenderRequest> renderRequestOf(const std::vector<std::string>& args);

// The camera options render and info share (--width … --tolerance).
struct CameraRequest {
  CameraSpec spec;
  double tolerance_px = 0.0;
};
Result<CameraRequest> cameraRequestOf(const std::vector<std::string>& args);

}  // namespace dpoint
