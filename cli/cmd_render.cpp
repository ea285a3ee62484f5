// dpoint render IN -o OUT.png: the offscreen Vulkan preview in one precision mode, with GPU
// timing and, with --error, the error against the exact CPU reference (DESIGN §4–6). Parsing and
// printing only: the run, its policies and its JSON report are viewer/render_job.h.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "cli/cli_camera.h"
#include "cli/cli_check.h"
#include "cli/cli_options.h"
#include "cli/cli_output.h"
#include "cli/cli_run.h"
#include "cli/cli_suggest.h"
#include "cli/cli_text.h"
#include "cli/commands.h"
#include "core/atomic_file.h"
#include "core/memory.h"
#include "core/progress.h"
#include "viewer/modes.h"
#include "viewer/render.h"
#include "viewer/render_job.h"

namespace dpoint {
namespace {

struct RenderCliOptions {
  std::vector<std::string> inputs;
  std::string output, mode = "auto", backend = "auto", device = "auto", json, native_path = "auto";
  std::string order = "input", shade = "auto", stream = "auto";
  double edl_strength = 1.0, edl_radius = 1.4;
  uint32_t views = 1;
  std::string color = "auto", max_device_memory;
  std::string up_axis = "auto";
  CameraCliOptions camera;
  std::string background = "0,0,0";
  bool error = false, validate = false;
  std::string point_size = "auto", point_shape = "auto", surface = "auto";
  uint32_t frames = 1;
  std::string warmup = "auto";
  uint64_t chunk_points = 0;
  std::string max_memory;
  std::string columns;
  CommonOptions common;
};

Result<uint32_t> parseBackground(const std::string& text) {
  Result<std::vector<double>> rgb = parseNumbers("--background", text, 3);
  if (!rgb) return rgb.error();
  uint32_t packed = 0xff000000u;
  for (int c = 0; c < 3; ++c) {
    double v = (*rgb)[static_cast<size_t>(c)];
    if (v < 0 || v > 255 || v != std::floor(v))
      return Error{"--background: '" + text + "' must be three integers 0..255", ExitCode::kUsage};
    packed |= static_cast<uint32_t>(v) << (8 * c);
  }
  return packed;
}

// --mode: the library's check, and the nearest name when the value is a typo.
Status checkModeOption(const std::string& value) {
  Status status = checkModeName(value);
  if (status) return status;
  std::vector<std::string> names = {"auto"};
  for (PrecisionMode mode : kAllModes) names.emplace_back(modeName(mode));
  return Error{status.error().message + didYouMean(value, names), ExitCode::kUsage};
}

Result<double> parsePointSize(const std::string& text) {
  Result<std::vector<double>> size = parseNumbers("--point-size", text, 1);
  if (!size) return size.error();
  return size->front();
}

// The options (each value checked by its validator as it was parsed) as a request.
Result<RenderRequest> requestOf(const RenderCliOptions& o) {
  Result<CameraSpec> spec = cameraSpec(o.camera);
  if (!spec) return spec.error();
  RenderRequest request;
  request.inputs = o.inputs;
  request.mode = o.mode;
  if (o.backend != "auto") request.backend = o.backend == "compute" ? Backend::kCompute : Backend::kRaster;
  request.device = o.device;
  request.validate = o.validate;
  request.camera = *spec;
  request.tolerance_px = *parseTolerance(o.camera.tolerance);
  if (o.point_size != "auto") request.point_size = *parsePointSize(o.point_size);
  if (o.point_shape != "auto") request.round_points = o.point_shape == "round";
  request.surface = o.surface == "on" ? SurfaceChoice::kOn : o.surface == "off" ? SurfaceChoice::kOff : SurfaceChoice::kAuto;
  request.background_rgba8 = *parseBackground(o.background);
  if (o.shade != "auto") request.shading = o.shade == "edl" ? Shading::kEdl : Shading::kNone;
  request.edl = EdlOptions{static_cast<float>(o.edl_strength), static_cast<float>(o.edl_radius)};
  request.color = parseRenderColor(o.color);
  request.color_attribute = o.color;
  request.up_axis = o.up_axis == "z" ? UpAxis::kZ : o.up_axis == "y" ? UpAxis::kY : UpAxis::kAuto;
  request.order = *parsePointOrder("--order", o.order);
  request.views = o.views;
  request.error = o.error;
  request.report = !o.json.empty();
  request.frames = o.frames, request.warmup = *parseWarmup("--warmup", o.warmup);
  request.chunk_points = o.chunk_points;
  request.native_path = o.native_path == "attribute" ? NativePath::kAttribute
                        : o.native_path == "pull"    ? NativePath::kPull
                                                     : NativePath::kAuto;
  request.stream = o.stream;
  request.columns = columnsOf(o.columns);
  request.threads = o.common.threads;
  if (Status s = checkRenderRequest(request); !s) return s.error();
  std::vector<std::pair<std::string, std::string>> inputs;
  for (const std::string& input : o.inputs) inputs.push_back({"an input", input});
  if (!o.json.empty()) {  // the report is no input and no picture: neither is replaced by it
    std::vector<std::pair<std::string, std::string>> others = {{"-o", o.output}};
    others.insert(others.end(), inputs.begin(), inputs.end());
    if (Status s = checkNotAlso("--json", o.json, others); !s) return s.error();
  }
  if (Status s = checkNotAlso("-o", o.output, inputs); !s) return s.error();
  Result<uint64_t> device_memory =
      o.max_device_memory.empty() ? uint64_t{0} : parseMemorySize("--max-device-memory", o.max_device_memory);
  if (!device_memory) return device_memory.error();
  request.max_device_memory = *device_memory;
  Result<uint64_t> limit = memoryLimitOf(o.max_memory);
  if (!limit) return limit.error();
  request.max_memory = *limit;
  return request;
}

void printChoice(const ModePrediction& p, const DeviceFacts& f, Backend backend) {
  if (!p.choice) {
    std::printf("mode %s: predicted error bound %s\n", std::string(modeName(p.mode)).c_str(), formatBound(p.bound_px).c_str());
    return;
  }
  const ModeChoice& c = *p.choice;
  // A choice or runner-up bounded over the set's box alone (no pass over the points) is given as at
  // most that.
  std::string runner_up = c.runner_up ? std::string(modeName(*c.runner_up)) + " (" + (c.runner_up_from_box ? "at most " : "") +
                                            formatBound(c.runner_up_bound_px) + (c.runner_up_from_box ? ", from the box" : "") + ")"
                                      : std::string("none within the limit");
  const std::string bound = c.from_box ? "at most " + formatBound(c.bound_px) + " (from the box)" : formatBound(c.bound_px);
  std::printf("mode auto: %s, predicted error bound %s; runner-up %s; the %s within %g px on %s, %s backend\n",
              std::string(modeName(c.mode)).c_str(), bound.c_str(), runner_up.c_str(),
              c.by_picture_time ? "quickest to the picture" : "fastest", kAutoBoundPx,
              std::string(deviceClassName(deviceClassOf(f.type))).c_str(), backendName(backend));
  if (c.by_picture_time) {
    const auto seconds = [](double ms) {
      char text[32];
      std::snprintf(text, sizeof text, ms < 1000.0 ? "%.3g ms" : "%.3g s", ms < 1000.0 ? ms : ms / 1000.0);
      return std::string(text);
    };
    // What the modes themselves cost this picture; its point size and shading add the same to each.
    std::printf("mode auto: predicted encoding, upload and 1-px frame: %s %s%s\n", std::string(modeName(c.mode)).c_str(),
                seconds(c.predicted_ms).c_str(),
                c.runner_up ? (", " + std::string(modeName(*c.runner_up)) + " " + seconds(c.runner_up_predicted_ms)).c_str() : "");
  }
  // Why each faster mode was passed over (its warning, with none enough, is in outcome.warnings).
  std::string passed;
  for (const ModeChoice::Rejected& r : c.rejected) {
    const std::string why = std::isnan(r.bound_px)
                                ? "not usable here" + (r.reason.empty() ? std::string() : ": " + r.reason)
                                : std::isinf(r.bound_px) ? std::string("unbounded error")
                                                         : "bound " + formatBound(r.bound_px) + " > " +
                                                               formatNumber(kAutoBoundPx) + " px";
    passed += (passed.empty() ? "" : "; ") + std::string(modeName(r.mode)) + " (" + why + ")";
  }
  if (!passed.empty()) std::printf("mode auto: faster modes passed over: %s\n", passed.c_str());
}

// The outcome's notes on its input and its warnings, one line each on stderr.
void printWarnings(const RenderOutcome& outcome) {
  for (const std::string& n : outcome.notices) std::fprintf(stderr, "dpoint: note: %s\n", n.c_str());
  for (const std::string& w : outcome.warnings) std::fprintf(stderr, "dpoint: warning: %s\n", w.c_str());
}

void printError(const ErrorReport& error) {
  const ErrorStats& e = error.stats;
  std::string image_check = error.pixels_compared
      ? std::to_string(error.pixels_differing) + " pixels differ from the reference raster"
      : "no image check (the reference raster draws plain --point-size 1 pixels only)";
  if (anyMeasured(e)) {
    std::printf("error: max %.4g px, p99 %.4g px, rms %.4g px, %.4g%% of %zu visible points off by >= 0.5 px, "
                "%zu lost; %s\n",
                e.max_px, e.p99_px, e.rms_px, 100.0 * e.share_off_half_px, e.points, e.lost, image_check.c_str());
  } else {
    std::printf("error: no point measured: %zu of %zu visible points lost; %s\n", e.lost, e.points, image_check.c_str());
  }
}

// The lines of a one-view run: the picture, the mode, the timings, the error.
void printOutcome(const RenderRequest& request, const std::string& output, const RenderOutcome& outcome) {
  const DeviceFacts& f = outcome.device;
  const RenderResult& r = outcome.result;
  const PrecisionMode mode = outcome.prediction.mode;
  std::printf("%s: %zu points%s, mode %s, %s backend, %ux%u, %g px points%s, %s (%s, driver %s)\n", output.c_str(),
              outcome.points, outcome.streamed ? " (streamed)" : "", std::string(modeName(mode)).c_str(),
              backendName(outcome.backend), request.camera.width, request.camera.height, double(outcome.point_size),
              outcome.shading == Shading::kEdl ? ", eye-dome lighting" : "", f.name.c_str(), f.type.c_str(),
              formatDriverVersion(f.vendor_id, f.driver_version).c_str());
  if (const std::optional<CopcReadStats>& c = outcome.copc)
    std::printf("copc: the view read %llu of %llu points, %llu of %llu bytes (%llu nodes)\n",
                static_cast<unsigned long long>(c->points), static_cast<unsigned long long>(c->file_points),
                static_cast<unsigned long long>(c->bytes), static_cast<unsigned long long>(c->file_bytes),
                static_cast<unsigned long long>(c->nodes));
  printChoice(outcome.prediction, f, outcome.backend);
  if (outcome.prediction.from_boxes)
    std::printf("mode bounds: predicted from the bounding box of each batch (a streamed set is read once)\n");
  char warmup[64] = ", no warm-up";
  if (r.warmup_frames)
    std::snprintf(warmup, sizeof warmup, " after %u warm-up frame%s in %.0f ms", r.warmup_frames,
                  r.warmup_frames == 1 ? "" : "s", r.warmup_ms);
  if (!r.gpu_ms.empty())
    std::printf("gpu: %.3f ms/frame median of %zu (p95 %.3f)%s, %.3g points/s, %u B/pt\n", medianOf(r.gpu_ms),
                r.gpu_ms.size(), percentileOf(r.gpu_ms, 95), warmup,
                static_cast<double>(outcome.points) / (medianOf(r.gpu_ms) * 1e-3), bytesPerPoint(mode));
  std::printf("host: upload %.1f ms, frame %.3f ms, readback %.1f ms\n", r.upload_ms, medianOf(r.frame_ms), r.readback_ms);
  std::string steps;
  for (const auto& [name, ms] : outcome.phases.list()) {
    char text[64];
    std::snprintf(text, sizeof text, "%s%s %.1f", steps.empty() ? "" : ", ", name, ms);
    steps += text;
  }
  std::printf("time to picture (ms): %s; peak memory %.0f MB\n", steps.c_str(), peakRssMb());
  if (outcome.error) printError(*outcome.error);
}

void printView(const SheetView& view) {
  const bool from_box = view.prediction.choice && view.prediction.choice->from_box;
  std::printf("view %s: mode %s, predicted error bound %s%s%s", view.label.c_str(),
              std::string(modeName(view.prediction.mode)).c_str(), from_box ? "at most " : "",
              formatBound(view.prediction.bound_px).c_str(), from_box ? " (from the box)" : "");
  if (!view.gpu_ms.empty()) std::printf(", gpu %.3f ms/frame median of %zu", medianOf(view.gpu_ms), view.gpu_ms.size());
  std::printf("\n");
}

// With --validate, any message of the layer fails the run.
int validationResult(const RenderOutcome& outcome) {
  const std::vector<std::string>& messages = outcome.validation_messages;
  if (messages.empty()) return 0;
  for (const std::string& m : messages) std::fprintf(stderr, "dpoint: %s\n", m.c_str());
  return reportError(Error{std::to_string(messages.size()) + " Vulkan validation message(s)", ExitCode::kNoDevice});
}

Status writeReport(const std::string& path, const RenderRequest& request, const RenderOutcome& outcome) {
  Result<AtomicFile> file = AtomicFile::create(path);
  if (!file) return file.error();
  Status status = file->write(renderReportJson(request, outcome));
  if (status) status = file->commit();
  return status;
}

int runRender(const RenderCliOptions& o) {
  Result<RenderRequest> request = requestOf(o);
  if (!request) return reportError(request.error());
  Progress progress(progressSink(o.common.quiet), "render");
  // --quiet: no progress and no report lines; warnings and errors still go to stderr.
  Result<RenderOutcome> outcome =
      runRenderJob(*request, progress, o.common.quiet ? std::function<void(const SheetView&)>() : printView);
  if (!outcome) return reportError(outcome.error());
  if (Status written = writeRenderPicture(o.output, *outcome); !written) return reportError(written.error());
  // Once everything is written and printed, the executable ends here rather than destroy the
  // device and give back the set first: on the NVIDIA driver that teardown took 33-40 ms of a
  // 230-300 ms render (H200), work the kernel does anyway as the process ends. With --validate the
  // layer is shown every object destroyed, as the tests want.
  auto finished = [&] {
    const int code = validationResult(*outcome);
    if (runningAsExecutable() && !request->validate) {
      progress.finish();  // a phase a reader left open ends its line, as ~Progress would
      exitProcessNow(code);
    }
    return code;
  };
  if (request->views == 4) {
    if (!o.common.quiet)
      std::printf("%s: %zu points, 4 views, %ux%u, %s backend, %s\n", o.output.c_str(), outcome->points,
                outcome->image.width, outcome->image.height, backendName(outcome->backend), outcome->device.name.c_str());
    printWarnings(*outcome);
    return finished();
  }
  // The report comes after the picture (it times the PNG's writing): where it cannot be written,
  // the picture goes too, as a failed run leaves nothing (a review finding: a full disk left it).
  if (!o.json.empty())
    if (Status s = writeReport(o.json, *request, *outcome); !s) {
      std::error_code ignored;
      if (std::filesystem::is_regular_file(o.output, ignored)) std::filesystem::remove(o.output, ignored);
      return reportError(s.error());
    }
  if (!o.common.quiet) printOutcome(*request, o.output, *outcome);
  printWarnings(*outcome);
  return finished();
}

// `dpoint render --help`'s description; its list of modes comes from the mode table.
std::string renderDescription() {
  std::string absolute;  // the modes that work on absolute coordinates: the study's baselines
  for (PrecisionMode mode : kAllModes) {
    if (modeInfo(mode).scene_frame) continue;
    absolute += (absolute.empty() ? "" : " and ") + std::string(modeName(mode));
  }
  return "Offscreen Vulkan point renderer: draws IN in one precision mode, writes a PNG, times the GPU, and with\n"
         "--error measures the mode against the exact CPU reference. Works without a GPU (Mesa lavapipe).\n" +
         wrapText("Modes: " + modeListHelp() + "; all but " + absolute +
                      " work in a frame scaled to the view, so they hold at 1e-300 m as at 1 m. Each run prints the "
                      "mode's predicted error bound in pixels; `dpoint info IN` prints every mode's for a view.",
                  kHelpWidth);
}

// Every option of render; with `files`, the input, -o and --json too (the executable's).
void addRenderOptions(CLI::App* cmd, const std::shared_ptr<RenderCliOptions>& o, bool files) {
  if (files) {
    cmd->add_option("input", o->inputs,
                    "Point sets (.csv and text, .ptx, .e57, .ply, .pcd, .las, .laz, .glb, .gltf), drawn as one; the N tiles of `generate --tile` as the\n"
                    "whole. Large binary PLY input is streamed (--stream)")
        ->required();
    cmd->add_option("-o,--output", o->output, "PNG to write")->required()->check(checkStatus(checkPictureOutput));
  }
  cmd->add_option("--mode", o->mode, modeOptionHelp())
      ->check(checkStatus(checkModeOption))
      ->default_val("auto");
  addChoiceOption(*cmd, "--backend", o->backend,
                  "auto (compute where the device runs it, else raster), raster (graphics pipeline, POINT_LIST, the\n"
                  "float-vs-double Vulkan study's design) or compute (a thread per point, 64-bit atomic depth test; the\n"
                  "fast path on lavapipe and on GPUs with a small graphics front end). Both draw the same picture",
                  {"auto", "raster", "compute"});
  addCameraOptions(*cmd, o->camera);
  cmd->add_option("--point-size", o->point_size,
                  "Point size in pixels, or auto: from how far apart the points lie on screen (sampled), up to 8\n"
                  "(more for a sparse set, up to 64); a 2D grid's spacing, so it shows no gaps, and 1.3 times a 3D\n"
                  "set's for round points (at least 3), whose remaining gaps the shading closes; 1 with --error")
      ->check(checkStatus([](const std::string& v) { return v == "auto" ? okStatus() : statusOf(parsePointSize(v)); }))
      ->default_val("auto");
  addChoiceOption(*cmd, "--point-shape", o->point_shape,
                  "Points larger than a pixel: round (discs whose depth falls away to the rim, so the nearest\n"
                  "surface wins where discs overlap and a point behind it shows no edge), square (the rasterizer's\n"
                  "squares at one depth), or auto: round for a 3D set, square for a 2D one (a grid closes exactly)",
                  {"auto", "round", "square"});
  addColumnsOption(*cmd, o->columns);
  addChoiceOption(*cmd, "--surface", o->surface,
                  "A mesh input (glTF, or a PLY with faces): on draws points sampled on its surface, about two per\n"
                  "pixel it covers (each triangle its share, colours and normals interpolated); off its vertices;\n"
                  "auto: its surface when its triangles are long on screen (a CAD part, not a generated fractal)",
                  {"auto", "on", "off"});
  cmd->add_option("--background", o->background, "Background colour R,G,B (0..255)")
      ->check(checkStatus([](const std::string& v) { return statusOf(parseBackground(v)); }))
      ->default_val("0,0,0");
  cmd->add_option("--device", o->device, "auto (a discrete GPU if any, else lavapipe), cpu, or an index from `dpoint devices`")
      ->default_val("auto");
  cmd->add_option("--frames", o->frames, "Timed frames after warm-up (the median is reported)")->default_val(1);
  cmd->add_option("--warmup", o->warmup,
                  "Untimed frames first: a count (2), or a duration (300ms, 0.5s): frames until that much time has\n"
                  "passed, at least one. auto: none for a single frame (the picture comes sooner; its time includes\n"
                  "the first use of the shaders), 300ms with --frames above 1 (a GPU's first frames after an upload\n"
                  "run slower while its clocks come up)")
      ->check(checkStatus([](const std::string& v) { return statusOf(parseWarmup("--warmup", v)); }))
      ->default_val("auto");
  cmd->add_flag("--error", o->error, "Run the probe and the exact CPU reference; report the error in pixels");
  if (files)
    cmd->add_option("--json", o->json, "Write the measurements as one JSON object to this file")
        ->check(checkStatus(AtomicFile::checkTarget));
  cmd->add_flag("--validate", o->validate, "Enable the Khronos validation layer; any message fails the run");
  addChoiceOption(*cmd, "--native-path", o->native_path, "native mode: auto, attribute (R64G64B64 vertex input) or pull",
                  {"auto", "attribute", "pull"});
  cmd->add_option("--chunk-points", o->chunk_points,
                  "Most points per draw (0: as the device allows); at most " + std::to_string(kMaxChunks) +
                      " draws, so at least 1/" + std::to_string(kMaxChunks) + " of the points")
      ->default_val(0);
  cmd->add_option("--order", o->order,
                  std::string(kPointOrderHelp) + "; applied as the set is loaded, before anything else")
      ->check(checkStatus([](const std::string& v) { return statusOf(parsePointOrder("--order", v)); }))
      ->default_val("input");
  addChoiceOption(*cmd, "--shade", o->shade,
                  "auto|none|edl. edl: screen-space passes over the depth of the visible points: gaps between the\n"
                  "front points (and the back surfaces seen through them) are filled from the points around them,\n"
                  "then eye-dome lighting darkens a pixel by how far its neighbours stand in front of it, so a\n"
                  "surface of points reads as a surface (as in Potree and CloudCompare). auto: edl for 3D sets,\n"
                  "none for 2D sets (every z is 0) and with --error, whatever the camera (--ortho, --eye); GPU\n"
                  "timings exclude it",
                  {"auto", "none", "edl"});
  cmd->add_option("--edl-strength", o->edl_strength, "Eye-dome darkening: exp(-strength * 300 * mean log2 depth step)")
      ->check(numberIn("--edl-strength", 0.0, 100.0, true, ""))
      ->default_val(1.0);
  cmd->add_option("--edl-radius", o->edl_radius, "Eye-dome neighbour distance in pixels (1..16)")
      ->check(numberIn("--edl-radius", 1.0, 16.0, false, "pixels"))
      ->default_val(1.4);
  cmd->add_option("--color", o->color,
                  "auto|rgb|elevation|NAME. elevation: a perceptual colour map (viridis) along the up axis\n"
                  "(--up-axis). NAME: any dimension of the set (`dpoint info` lists them: intensity, classification,\n"
                  "gps_time, a PLY property or CSV column), with a legend in the top-right corner: classification in\n"
                  "the ASPRS classes' colours, another integer of at most 12 values one colour each, anything else\n"
                  "viridis from its 1st to its 99th percentile. auto: the set's colours when it has them, else\n"
                  "elevation for 3D sets and white for 2D ones")
      ->default_val("auto");
  cmd->add_option("--max-device-memory", o->max_device_memory,
                  "Refuse (exit 3, a Vulkan fault) to allocate more GPU memory than this, e.g. 2G (default: what the\n"
                  "device has)");
  addChoiceOption(*cmd, "--stream", o->stream,
                  "auto|on|off. on: draw binary PLY, LAS, LAZ or E57 input (a file, or tiles) a block at a time, so a set larger\n"
                  "than memory renders in about 1.2 GB of host memory (two blocks of 16M points; smaller ones under a\n"
                  "lower --max-memory, the same picture); auto: for such input of more than 2^26 points. A streamed\n"
                  "set's bound is predicted from the box of each batch (docs/precision.md); it gets no --error,\n"
                  "--order or --views 4",
                  {"auto", "on", "off"});
  cmd->add_option("--views", o->views,
                  "1, or 4: one PNG of four labelled views (front, side, top, three-quarter), each framed by --fit\n"
                  "in a quarter of --width x --height (3D sets; not with --eye, --ortho, --error or --json)")
      ->check(check([](const std::string& v) {
        uint32_t views = 0;  // text that is no number: CLI11's conversion error follows
        return CLI::detail::lexical_cast(v, views) && !checkViewCount(views) ? checkViewCount(views).error().message
                                                                             : std::string();
      }))
      ->default_val(1);
  addChoiceOption(*cmd, "--up-axis", o->up_axis,
                  "auto|y|z: the data's up for the --fit views. auto: z for LAS (surveys), y otherwise",
                  {"auto", "y", "z"});
  addMaxMemoryOption(*cmd, o->max_memory);
  addCommonOptions(*cmd, o->common);
}

}  // namespace

void addRenderCommand(CLI::App& app, RunCommand& run) {
  auto o = std::make_shared<RenderCliOptions>();
  CLI::App* cmd = app.add_subcommand("render", renderDescription());
  addRenderOptions(cmd, o, true);
  cmd->callback([o, &run]() { run = [o]() { return runRender(*o); }; });
}

Result<RenderRequest> renderRequestOf(const std::vector<std::string>& args) {
  auto o = std::make_shared<RenderCliOptions>();
  CLI::App dpoint{"", "dpoint"};
  addRenderOptions(dpoint.add_subcommand("render", renderDescription()), o, false);
  if (Status s = parseOptions(dpoint, "render", args); !s) return s.error();
  Result<RenderRequest> request = requestOf(*o);
  if (request) request->report = request->views == 1;  // a contact sheet has none
  return request;
}

}  // namespace dpoint
