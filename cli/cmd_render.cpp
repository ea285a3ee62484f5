// dpoint render IN -o OUT.png: the offscreen Vulkan preview in one precision mode, with GPU
// timing and, with --error, the error against the exact CPU reference (DESIGN §4–6).
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <utility>
#include <vector>

#include "cli/cli_camera.h"
#include "cli/cli_text.h"
#include "cli/commands.h"
#include "converters/point_io.h"
#include "core/atomic_file.h"
#include "core/memory.h"
#include "core/point_order.h"
#include "core/progress.h"
#include "viewer/camera.h"
#include "viewer/context.h"
#include "viewer/image.h"
#include "viewer/probe.h"
#include "viewer/render.h"

namespace dpoint {
namespace {

struct RenderCliOptions {
  std::string input, output, mode = "auto", backend = "raster", device = "auto", json, native_path = "auto";
  std::string order = "input";
  CameraCliOptions camera;
  std::string background = "0,0,0";
  bool error = false, validate = false;
  double point_size = 1.0;
  uint32_t frames = 1, warmup = 1;
  uint64_t chunk_points = 0;
  std::string max_memory;
  CommonOptions common;
};

// Host and device bytes per pixel at most: colour and depth (or the compute backend's 64-bit key
// and packed picture), the readback buffer, the host image and, with --error, the reference raster.
constexpr uint64_t kPictureBytesPerPixel = 32;

bool endsWithPng(const std::string& path) {
  if (path.size() < 4) return false;
  std::string tail = path.substr(path.size() - 4);
  std::transform(tail.begin(), tail.end(), tail.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return tail == ".png";
}

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

// What the run predicted for its mode: the bound, and with --mode auto the choice made.
struct Prediction {
  PrecisionMode mode = PrecisionMode::kNative;
  double bound_px = 0.0;
  std::optional<ModeChoice> choice;  // --mode auto
};

// Points the probe measured: visible in the reference and not lost.
bool anyMeasured(const ErrorStats& e) { return e.points > e.lost; }

// Where the command's wall time goes, step by step (the time to a picture), and its peak memory.
class Phases {
 public:
  void mark(const char* name) {
    const auto now = std::chrono::steady_clock::now();
    list_.emplace_back(name, std::chrono::duration<double, std::milli>(now - last_).count());
    last_ = now;
  }
  const std::vector<std::pair<const char*, double>>& list() const { return list_; }
  static double peakRssMb() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<double>(usage.ru_maxrss) / 1024.0;  // kilobytes on Linux
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
  std::vector<std::pair<const char*, double>> list_;
};

std::string jsonReport(const RenderCliOptions& o, const VulkanContext& context, const PointSet& points,
                       const RenderResult& r, const Prediction& prediction, const ErrorReport* error,
                       const Phases& phases) {
  const DeviceFacts& f = context.facts;
  const PrecisionMode mode = prediction.mode;
  double gpu_median = medianOf(r.gpu_ms), frame_median = medianOf(r.frame_ms);
  double per_frame_ms = r.gpu_ms.empty() ? frame_median : gpu_median;
  auto num = [](double v) { return formatNumber(v, true); };
  std::string s = "{\n";
  auto bound = [&](double px) { return std::isfinite(px) ? num(px) : std::string("null"); };
  s += "  \"mode\": " + jsonString(std::string(modeName(mode))) + ",\n  \"mode_requested\": " + jsonString(o.mode) + ",\n";
  s += "  \"predicted_bound_px\": " + bound(prediction.bound_px) + ",\n";
  if (prediction.choice) {
    const ModeChoice& c = *prediction.choice;
    s += "  \"auto\": {\"enough\": " + std::string(c.enough ? "true" : "false") + ", \"limit_px\": " + num(kAutoBoundPx) +
         ", \"device_class\": " + jsonString(std::string(deviceClassName(deviceClassOf(f.type)))) + ", \"runner_up\": " +
         (c.runner_up ? "{\"mode\": " + jsonString(std::string(modeName(*c.runner_up))) +
                            ", \"predicted_bound_px\": " + bound(c.runner_up_bound_px) + "}"
                      : std::string("null")) +
         "},\n";
  }
  s += "  \"backend\": " + jsonString(o.backend) + ",\n";
  s += "  \"order\": " + jsonString(o.order) + ",\n";
  s += "  \"device\": " + jsonString(f.name) + ",\n  \"device_type\": " + jsonString(f.type) + ",\n";
  s += "  \"driver\": " + jsonString(f.driver_name + " " + f.driver_info) + ",\n";
  s += "  \"driver_version\": " + jsonString(formatDriverVersion(f.vendor_id, f.driver_version)) + ",\n";
  s += "  \"api_version\": " + jsonString(formatApiVersion(f.api_version)) + ",\n";
  s += "  \"points\": " + std::to_string(points.size()) + ",\n";
  s += "  \"width\": " + std::to_string(o.camera.width) + ",\n  \"height\": " + std::to_string(o.camera.height) + ",\n";
  s += "  \"frames\": " + std::to_string(r.frame_ms.size()) + ",\n";
  if (r.gpu_ms.empty()) {
    s += "  \"gpu_ms\": null,\n";
  } else {
    s += "  \"gpu_ms\": {\"median\": " + num(gpu_median) + ", \"p95\": " + num(percentileOf(r.gpu_ms, 95)) +
         ", \"min\": " + num(*std::min_element(r.gpu_ms.begin(), r.gpu_ms.end())) + "},\n";
  }
  s += "  \"frame_ms\": {\"median\": " + num(frame_median) + ", \"p95\": " + num(percentileOf(r.frame_ms, 95)) + "},\n";
  s += "  \"upload_ms\": " + num(r.upload_ms) + ",\n  \"readback_ms\": " + num(r.readback_ms) + ",\n";
  s += "  \"e2e_ms\": " + num(r.upload_ms + frame_median + r.readback_ms) + ",\n";
  s += "  \"phases_ms\": {";
  for (size_t i = 0; i < phases.list().size(); ++i)
    s += std::string(i ? ", " : "") + jsonString(phases.list()[i].first) + ": " + num(phases.list()[i].second);
  s += "},\n  \"peak_rss_mb\": " + num(Phases::peakRssMb()) + ",\n";
  s += "  \"points_per_s\": " + num(static_cast<double>(points.size()) / (per_frame_ms * 1e-3)) + ",\n";
  s += "  \"bytes_per_point\": " + std::to_string(bytesPerPoint(mode)) + ",\n";
  s += "  \"chunks\": " + std::to_string(r.chunks) + ",\n";
  s += "  \"native_path\": " + std::string(mode != PrecisionMode::kNative ? "null" : r.pulled_positions ? "\"pull\"" : "\"attribute\"");
  if (error) {
    const ErrorStats& e = error->stats;
    // With every visible point lost there is no error to report: null, never a perfect 0.
    if (anyMeasured(e))
      s += ",\n  \"error_px\": {\"max\": " + num(e.max_px) + ", \"p99\": " + num(e.p99_px) + ", \"rms\": " + num(e.rms_px) + "},\n";
    else
      s += ",\n  \"error_px\": null,\n";
    s += "  \"share_off_half_px\": " + num(e.share_off_half_px) + ",\n";
    s += "  \"points_visible\": " + std::to_string(e.points) + ",\n  \"points_lost\": " + std::to_string(e.lost) + ",\n";
    s += "  \"pixels_differing\": " + (error->pixels_compared ? std::to_string(error->pixels_differing) : "null");
  }
  return s + "\n}\n";
}

// --mode auto picks on the device; an explicit mode gets its bound computed for the report.
Result<Prediction> predict(const RenderCliOptions& o, const VulkanContext& context, const PointSet& points,
                           const Camera& camera, Backend backend) {
  Prediction p;
  if (o.mode != "auto") {
    p.mode = *parseMode(o.mode);
    const PrecisionMode one[] = {p.mode};
    p.bound_px = predictErrorBounds(points, camera, one).px[modeIndex(p.mode)];
    return p;
  }
  Result<ModeChoice> choice = chooseModeOnDevice(context, points, camera, backend, o.error);
  if (!choice) return choice.error();
  p.mode = choice->mode;
  p.bound_px = choice->bound_px;
  p.choice = std::move(*choice);
  return p;
}

void printChoice(const Prediction& p, const DeviceFacts& f, Backend backend) {
  if (!p.choice) {
    std::printf("mode %s: predicted error bound %s\n", std::string(modeName(p.mode)).c_str(), formatBound(p.bound_px).c_str());
    return;
  }
  const ModeChoice& c = *p.choice;
  std::string runner_up = c.runner_up ? std::string(modeName(*c.runner_up)) + " (" + formatBound(c.runner_up_bound_px) + ")"
                                      : std::string("none within the limit");
  std::printf("mode auto: %s, predicted error bound %s; runner-up %s; the fastest within %g px on %s, %s backend\n",
              std::string(modeName(c.mode)).c_str(), formatBound(c.bound_px).c_str(), runner_up.c_str(), kAutoBoundPx,
              std::string(deviceClassName(deviceClassOf(f.type))).c_str(), backend == Backend::kCompute ? "compute" : "raster");
  if (!c.enough) {
    std::fprintf(stderr, "dpoint: warning: no mode this device runs stays within %g px for this view; %s is the most "
                 "accurate here (bound %s)\n", kAutoBoundPx, std::string(modeName(c.mode)).c_str(),
                 formatBound(c.bound_px).c_str());
  }
}

int runRender(const RenderCliOptions& o) {
  if (o.mode != "auto" && !parseMode(o.mode))
    return reportError(Error{"--mode must be auto, fp32, split, rte, df64, native or batch, got '" + o.mode + "'", ExitCode::kUsage});
  if (o.backend != "raster" && o.backend != "compute")
    return reportError(Error{"--backend must be raster or compute, got '" + o.backend + "'", ExitCode::kUsage});
  Result<PointOrder> order = parsePointOrder("--order", o.order);
  if (!order) return reportError(order.error());
  if (!endsWithPng(o.output) && o.output.rfind("/dev/", 0) != 0)
    return reportError(Error{"-o " + o.output + ": the picture is written as PNG; name it .png", ExitCode::kUsage});
  NativePath native_path = NativePath::kAuto;
  if (o.native_path == "attribute") native_path = NativePath::kAttribute;
  else if (o.native_path == "pull") native_path = NativePath::kPull;
  else if (o.native_path != "auto")
    return reportError(Error{"--native-path must be auto, attribute or pull, got '" + o.native_path + "'", ExitCode::kUsage});
  Result<CameraSpec> spec = cameraSpec(o.camera);
  if (!spec) return reportError(spec.error());
  Result<uint32_t> background = parseBackground(o.background);
  if (!background) return reportError(background.error());
  Result<uint64_t> limit = memoryLimitOf(o.max_memory);
  if (!limit) return reportError(limit.error());
  // Before the input is read: --width 1000000 should not wait for a large file to load first.
  const uint64_t pixels = uint64_t{o.camera.width} * o.camera.height;
  if (Status s = checkMemory("a " + std::to_string(o.camera.width) + "x" + std::to_string(o.camera.height) + " picture",
                             pixels * kPictureBytesPerPixel, *limit);
      !s)
    return reportError(s.error());

  Phases phases;
  Progress progress(progressSink(o.common.quiet), "render");
  ReadOptions read{o.common.threads, false, &progress, true};
  read.max_memory = *limit;
  Result<PointSet> points = readPoints(o.input, read);
  if (!points) return reportError(points.error());
  phases.mark("read");
  reorderPoints(*points, *order, o.common.threads, &progress);
  phases.mark("order");
  if (points->size() == 0) return reportError(Error{o.input + ": no points to render", ExitCode::kBadInput});
  Result<Camera> camera = makeCamera(*spec, boundsOf(*points));
  if (!camera) return reportError(camera.error());
  phases.mark("camera");

  Result<std::unique_ptr<VulkanContext>> context = VulkanContext::create(ContextOptions{o.device, o.validate});
  if (!context) return reportError(context.error());
  phases.mark("device");
  const Backend backend = o.backend == "compute" ? Backend::kCompute : Backend::kRaster;
  Result<Prediction> prediction = predict(o, **context, *points, *camera, backend);
  if (!prediction) return reportError(prediction.error());
  phases.mark("mode");
  RenderOptions options;
  options.mode = prediction->mode;
  options.backend = backend;
  options.point_size = static_cast<float>(o.point_size);
  options.background_rgba8 = *background;
  options.frames = o.frames;
  options.warmup_frames = o.warmup;
  options.probe = o.error;
  options.native_path = native_path;
  options.max_chunk_points = o.chunk_points;
  Result<RenderResult> rendered = renderPoints(**context, *points, *camera, options);
  if (!rendered) return reportError(rendered.error());
  phases.mark("render");
  std::optional<ErrorReport> error;
  if (o.error) error = measureError(*points, *camera, *rendered, options);
  if (o.error) phases.mark("error");

  Status written = writePng(o.output, rendered->image);
  if (!written) return reportError(written.error());
  phases.mark("png");
  if (!o.json.empty()) {
    Result<AtomicFile> file = AtomicFile::create(o.json);
    if (!file) return reportError(file.error());
    Status status = file->write(jsonReport(o, **context, *points, *rendered, *prediction, error ? &*error : nullptr, phases));
    if (status) status = file->commit();
    if (!status) return reportError(status.error());
  }

  const DeviceFacts& f = (*context)->facts;
  const RenderResult& r = *rendered;
  const PrecisionMode mode = prediction->mode;
  std::printf("%s: %zu points, mode %s, %s backend, %ux%u, %s (%s, driver %s)\n", o.output.c_str(), points->size(),
              std::string(modeName(mode)).c_str(), o.backend.c_str(), o.camera.width, o.camera.height, f.name.c_str(),
              f.type.c_str(), formatDriverVersion(f.vendor_id, f.driver_version).c_str());
  printChoice(*prediction, f, backend);
  if (!r.gpu_ms.empty())
    std::printf("gpu: %.3f ms/frame median of %zu (p95 %.3f), %.3g points/s, %u B/pt\n", medianOf(r.gpu_ms),
                r.gpu_ms.size(), percentileOf(r.gpu_ms, 95),
                static_cast<double>(points->size()) / (medianOf(r.gpu_ms) * 1e-3), bytesPerPoint(mode));
  std::printf("host: upload %.1f ms, frame %.3f ms, readback %.1f ms\n", r.upload_ms, medianOf(r.frame_ms), r.readback_ms);
  std::string steps;
  for (const auto& [name, ms] : phases.list()) {
    char text[64];
    std::snprintf(text, sizeof text, "%s%s %.1f", steps.empty() ? "" : ", ", name, ms);
    steps += text;
  }
  std::printf("time to picture (ms): %s; peak memory %.0f MB\n", steps.c_str(), Phases::peakRssMb());
  if (error) {
    const ErrorStats& e = error->stats;
    std::string image_check = error->pixels_compared
        ? std::to_string(error->pixels_differing) + " pixels differ from the reference raster"
        : "no image check (the reference raster draws --point-size 1 only)";
    if (anyMeasured(e)) {
      std::printf("error: max %.4g px, p99 %.4g px, rms %.4g px, %.4g%% of %zu visible points off by >= 0.5 px, "
                  "%zu lost; %s\n",
                  e.max_px, e.p99_px, e.rms_px, 100.0 * e.share_off_half_px, e.points, e.lost, image_check.c_str());
    } else {
      std::printf("error: no point measured: %zu of %zu visible points lost; %s\n", e.lost, e.points, image_check.c_str());
    }
  }
  const std::vector<std::string>& messages = (*context)->validationMessages();
  if (!messages.empty()) {
    for (const std::string& m : messages) std::fprintf(stderr, "dpoint: %s\n", m.c_str());
    return reportError(Error{std::to_string(messages.size()) + " Vulkan validation message(s)", ExitCode::kNoDevice});
  }
  return 0;
}

}  // namespace

void addRenderCommand(CLI::App& app, RunCommand& run) {
  auto o = std::make_shared<RenderCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "render",
      "Offscreen Vulkan point renderer: draws IN in one precision mode, writes a PNG, times the GPU, and with\n"
      "--error measures the mode against the exact CPU reference. Works without a GPU (Mesa lavapipe).\n"
      "Modes: fp32 (float positions), split (the study's hi+lo, no better than fp32), rte (relative to eye),\n"
      "df64 (double-float arithmetic), native (fp64 shaders), batch (per-batch double origins); all but fp32\n"
      "and split work in a frame scaled to the view, so they hold at 1e-300 m as at 1 m. Each run prints the\n"
      "mode's predicted error bound in pixels; `dpoint info IN` prints every mode's for a view.");
  cmd->add_option("input", o->input, "Point set: .csv, .ply, .glb or .gltf")->required();
  cmd->add_option("-o,--output", o->output, "PNG to write")->required();
  cmd->add_option("--mode", o->mode,
                  "auto|fp32|split|rte|df64|native|batch. auto: the fastest mode on this kind of device (measured\n"
                  "order) whose predicted error bound is <= 0.1 px for this view; native when none is")
      ->default_val("auto");
  cmd->add_option("--backend", o->backend,
                  "raster (graphics pipeline, POINT_LIST, the study's design) or compute (a thread per point,\n"
                  "64-bit atomic depth test; the fast path on GPUs with a small graphics front end)")
      ->default_val("raster");
  addCameraOptions(*cmd, o->camera);
  cmd->add_option("--point-size", o->point_size, "Point size in pixels")->default_val(1.0);
  cmd->add_option("--background", o->background, "Background colour R,G,B (0..255)")->default_val("0,0,0");
  cmd->add_option("--device", o->device, "auto (a discrete GPU if any, else lavapipe), cpu, or an index from `dpoint devices`")
      ->default_val("auto");
  cmd->add_option("--frames", o->frames, "Timed frames after warm-up (the median is reported)")->default_val(1);
  cmd->add_option("--warmup", o->warmup, "Untimed frames first")->default_val(1);
  cmd->add_flag("--error", o->error, "Run the probe and the exact CPU reference; report the error in pixels");
  cmd->add_option("--json", o->json, "Write the measurements as one JSON object to this file");
  cmd->add_flag("--validate", o->validate, "Enable the Khronos validation layer; any message fails the run");
  cmd->add_option("--native-path", o->native_path, "native mode: auto, attribute (R64G64B64 vertex input) or pull")
      ->default_val("auto");
  cmd->add_option("--chunk-points", o->chunk_points, "Most points per draw (0: as the device allows)")->default_val(0);
  cmd->add_option("--order", o->order,
                  std::string(kPointOrderHelp) + "; applied as the set is loaded, before anything else")
      ->default_val("input");
  addMaxMemoryOption(*cmd, o->max_memory);
  addCommonOptions(*cmd, o->common);
  cmd->callback([o, &run]() { run = [o]() { return runRender(*o); }; });
}

}  // namespace dpoint
