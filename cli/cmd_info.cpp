// dpoint info FILE [--json]: counts, bounds and the precision the data needs.
#include <cstdio>
#include <memory>

#include "cli/cli_camera.h"
#include "cli/cli_check.h"
#include "cli/commands.h"
#include "viewer/info_report.h"

namespace dpoint {
namespace {

struct InfoCliOptions {
  std::vector<std::string> inputs;
  bool json = false;
  bool allow_nonfinite = false;
  size_t sample = 10000;
  CameraCliOptions camera;
  std::string max_memory;
  std::string stream = "auto";
  std::string up_axis = "auto";
  int scene = -1;
  bool all_scenes = false;
  std::string columns;
  CommonOptions common;
};

int runInfo(const InfoCliOptions& o) {
  Progress progress(progressSink(o.common.quiet || o.json), "info");
  Result<uint64_t> limit = memoryLimitOf(o.max_memory);
  if (!limit) return reportError(limit.error());
  Result<CameraSpec> spec = cameraSpec(o.camera);
  if (!spec) return reportError(spec.error());
  InfoInputs inputs{o.inputs, o.stream, o.allow_nonfinite, *limit};
  inputs.scene = o.scene;
  inputs.all_scenes = o.all_scenes;
  inputs.columns = columnsOf(o.columns);
  InfoOptions options{*spec, o.sample, *parseTolerance(o.camera.tolerance), o.common.threads, std::nullopt};
  if (o.up_axis != "auto") options.z_up = o.up_axis == "z";
  Result<InfoReport> report = describeFiles(inputs, options, progress);
  if (!report) return reportError(report.error());
  for (const std::string& notice : report->notices) std::fprintf(stderr, "dpoint: note: %s\n", notice.c_str());
  const std::string text = o.json ? infoReportJson(*report) : infoReportText(*report);
  std::fwrite(text.data(), 1, text.size(), stdout);
  return 0;
}

}  // namespace

void addInfoCommand(CLI::App& app, RunCommand& run) {
  auto o = std::make_shared<InfoCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "info",
      "Counts, bounds, whether float32 can hold the data, and each render mode's predicted error in pixels for a\n"
      "view: the --fit view by default, or the one the camera options (as for `dpoint render`) describe");
  cmd->add_option("input", o->inputs,
                  "Input files (.csv and text, .ptx, .e57, .ply, .pcd, .las, .laz, .glb, .gltf), taken as one set; the N tiles of `generate --tile`\n"
                  "as the whole. Large binary PLY, LAS, LAZ and E57 input is streamed (--stream)")
      ->required();
  cmd->add_flag("--json", o->json, "Print JSON instead of text");
  cmd->add_option("--sample", o->sample, "Points sampled for the nearest-neighbour distance")
      ->default_val(10000)
      ->check(CLI::Range(size_t{1}, size_t{100000000}));
  cmd->add_flag("--allow-nonfinite", o->allow_nonfinite, "Accept nan/inf coordinates instead of rejecting them");
  // The same choice of glTF scene as `dpoint convert`.
  auto* scene = cmd->add_option("--scene", o->scene, "glTF: describe scene N instead of the default scene (else scene 0)")
                    ->check(nonNegativeNumber("--scene"));
  cmd->add_flag("--all-scenes", o->all_scenes, "glTF: every scene, one after the other, as one set")->excludes(scene);
  addColumnsOption(*cmd, o->columns);
  addCameraOptions(*cmd, o->camera);
  addChoiceOption(*cmd, "--up-axis", o->up_axis,
                  "auto|y|z: the data's up for the --fit view, as `dpoint render` takes it. auto: z for LAS (surveys), y otherwise",
                  {"auto", "y", "z"});
  addMaxMemoryOption(*cmd, o->max_memory);
  cmd->add_option("--stream", o->stream,
                  "auto|on|off. on: read binary PLY, LAS, LAZ or E57 input (a file, or tiles) a block at a time, twice, so a set\n"
                  "larger than memory is described in about 1.2 GB, or in smaller blocks under a lower --max-memory (no\n"
                  "float32 merge count, which needs every point at once, and error bounds from the box of every 1024\n"
                  "points); auto: for such input of more than 2^26 points")
      ->check(oneOf("--stream", {"auto", "on", "off"}))
      ->default_val("auto");
  addCommonOptions(*cmd, o->common);
  cmd->callback([o, &run] { run = [o] { return runInfo(*o); }; });
}

}  // namespace dpoint
