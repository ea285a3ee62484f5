// dpoint render IN -o OUT.png: the offscreen Vulkan preview in one precision mode, with GPU
// timing and, with --error, the error against the exact CPU reference (DESIGN §4–6).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "cli/cli_text.h"
#include "cli/commands.h"
#include "converters/point_io.h"
#include "core/atomic_file.h"
#include "core/progress.h"
#include "viewer/camera.h"
#include "viewer/context.h"
#include "viewer/image.h"
#include "viewer/probe.h"
#include "viewer/render.h"

namespace dpoint {
namespace {

struct RenderCliOptions {
  std::string input, output, mode = "native", backend = "raster", device = "auto", json, native_path = "auto";
  uint32_t width = 1024, height = 768;
  std::string eye, target, up, view_center, background = "0,0,0";
  bool fit = false, ortho = false, error = false, validate = false;
  double fov = 45.0, view_width = 0.0, point_size = 1.0;
  uint32_t frames = 1, warmup = 1;
  uint64_t chunk_points = 0;
  CommonOptions common;
};

bool endsWithPng(const std::string& path) {
  if (path.size() < 4) return false;
  std::string tail = path.substr(path.size() - 4);
  std::transform(tail.begin(), tail.end(), tail.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return tail == ".png";
}

Result<CameraSpec> cameraSpec(const RenderCliOptions& o) {
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
  if (o.view_width != 0.0) {
    spec.view_width = o.view_width;
    spec.ortho = true;
  }
  return spec;
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

std::string jsonReport(const RenderCliOptions& o, const VulkanContext& context, const PointSet& points,
                       const RenderResult& r, const ErrorReport* error) {
  const DeviceFacts& f = context.facts;
  PrecisionMode mode = *parseMode(o.mode);
  double gpu_median = medianOf(r.gpu_ms), frame_median = medianOf(r.frame_ms);
  double per_frame_ms = r.gpu_ms.empty() ? frame_median : gpu_median;
  auto num = [](double v) { return formatNumber(v, true); };
  std::string s = "{\n";
  s += "  \"mode\": " + jsonString(o.mode) + ",\n  \"backend\": " + jsonString(o.backend) + ",\n";
  s += "  \"device\": " + jsonString(f.name) + ",\n  \"device_type\": " + jsonString(f.type) + ",\n";
  s += "  \"driver\": " + jsonString(f.driver_name + " " + f.driver_info) + ",\n";
  s += "  \"driver_version\": " + jsonString(formatDriverVersion(f.vendor_id, f.driver_version)) + ",\n";
  s += "  \"api_version\": " + jsonString(formatApiVersion(f.api_version)) + ",\n";
  s += "  \"points\": " + std::to_string(points.size()) + ",\n";
  s += "  \"width\": " + std::to_string(o.width) + ",\n  \"height\": " + std::to_string(o.height) + ",\n";
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
  s += "  \"points_per_s\": " + num(static_cast<double>(points.size()) / (per_frame_ms * 1e-3)) + ",\n";
  s += "  \"bytes_per_point\": " + std::to_string(bytesPerPoint(mode)) + ",\n";
  s += "  \"chunks\": " + std::to_string(r.chunks) + ",\n";
  s += "  \"native_path\": " + std::string(mode != PrecisionMode::kNative ? "null" : r.pulled_positions ? "\"pull\"" : "\"attribute\"");
  if (error) {
    const ErrorStats& e = error->stats;
    s += ",\n  \"error_px\": {\"max\": " + num(e.max_px) + ", \"p99\": " + num(e.p99_px) + ", \"rms\": " + num(e.rms_px) + "},\n";
    s += "  \"share_off_half_px\": " + num(e.share_off_half_px) + ",\n";
    s += "  \"points_visible\": " + std::to_string(e.points) + ",\n  \"points_lost\": " + std::to_string(e.lost) + ",\n";
    s += "  \"pixels_differing\": " + (error->pixels_compared ? std::to_string(error->pixels_differing) : "null");
  }
  return s + "\n}\n";
}

int runRender(const RenderCliOptions& o) {
  std::optional<PrecisionMode> mode = parseMode(o.mode);
  if (!mode) return reportError(Error{"--mode must be fp32, split, rte, df64, native or batch, got '" + o.mode + "'", ExitCode::kUsage});
  if (o.backend != "raster" && o.backend != "compute")
    return reportError(Error{"--backend must be raster or compute, got '" + o.backend + "'", ExitCode::kUsage});
  if (!endsWithPng(o.output) && o.output.rfind("/dev/", 0) != 0)
    return reportError(Error{"-o " + o.output + ": the picture is written as PNG; name it .png", ExitCode::kUsage});
  NativePath native_path = NativePath::kAuto;
  if (o.native_path == "attribute") native_path = NativePath::kAttribute;
  else if (o.native_path == "pull") native_path = NativePath::kPull;
  else if (o.native_path != "auto")
    return reportError(Error{"--native-path must be auto, attribute or pull, got '" + o.native_path + "'", ExitCode::kUsage});
  Result<CameraSpec> spec = cameraSpec(o);
  if (!spec) return reportError(spec.error());
  Result<uint32_t> background = parseBackground(o.background);
  if (!background) return reportError(background.error());

  Progress progress(progressSink(o.common.quiet), "render");
  Result<PointSet> points = readPoints(o.input, ReadOptions{o.common.threads, false, &progress});
  if (!points) return reportError(points.error());
  if (points->size() == 0) return reportError(Error{o.input + ": no points to render", ExitCode::kBadInput});
  Result<Camera> camera = makeCamera(*spec, boundsOf(*points));
  if (!camera) return reportError(camera.error());

  Result<std::unique_ptr<VulkanContext>> context = VulkanContext::create(ContextOptions{o.device, o.validate});
  if (!context) return reportError(context.error());
  RenderOptions options;
  options.mode = *mode;
  options.backend = o.backend == "compute" ? Backend::kCompute : Backend::kRaster;
  options.point_size = static_cast<float>(o.point_size);
  options.background_rgba8 = *background;
  options.frames = o.frames;
  options.warmup_frames = o.warmup;
  options.probe = o.error;
  options.native_path = native_path;
  options.max_chunk_points = o.chunk_points;
  Result<RenderResult> rendered = renderPoints(**context, *points, *camera, options);
  if (!rendered) return reportError(rendered.error());
  std::optional<ErrorReport> error;
  if (o.error) error = measureError(*points, *camera, *rendered, options);

  Status written = writePng(o.output, rendered->image);
  if (!written) return reportError(written.error());
  if (!o.json.empty()) {
    Result<AtomicFile> file = AtomicFile::create(o.json);
    if (!file) return reportError(file.error());
    Status status = file->write(jsonReport(o, **context, *points, *rendered, error ? &*error : nullptr));
    if (status) status = file->commit();
    if (!status) return reportError(status.error());
  }

  const DeviceFacts& f = (*context)->facts;
  const RenderResult& r = *rendered;
  std::printf("%s: %zu points, mode %s, %s backend, %ux%u, %s (%s, driver %s)\n", o.output.c_str(), points->size(),
              o.mode.c_str(), o.backend.c_str(), o.width, o.height, f.name.c_str(), f.type.c_str(), formatDriverVersion(f.vendor_id, f.driver_version).c_str());
  if (!r.gpu_ms.empty())
    std::printf("gpu: %.3f ms/frame median of %zu (p95 %.3f), %.3g points/s, %u B/pt\n", medianOf(r.gpu_ms),
                r.gpu_ms.size(), percentileOf(r.gpu_ms, 95),
                static_cast<double>(points->size()) / (medianOf(r.gpu_ms) * 1e-3), bytesPerPoint(*mode));
  std::printf("host: upload %.1f ms, frame %.3f ms, readback %.1f ms\n", r.upload_ms, medianOf(r.frame_ms), r.readback_ms);
  if (error) {
    const ErrorStats& e = error->stats;
    std::string image_check = error->pixels_compared
        ? std::to_string(error->pixels_differing) + " pixels differ from the reference raster"
        : "no image check (the reference raster draws --point-size 1 only)";
    std::printf("error: max %.4g px, p99 %.4g px, rms %.4g px, %.4g%% of %zu visible points off by >= 0.5 px, "
                "%zu lost; %s\n",
                e.max_px, e.p99_px, e.rms_px, 100.0 * e.share_off_half_px, e.points, e.lost, image_check.c_str());
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
      "df64 (double-float arithmetic), native (fp64 shaders), batch (per-batch double origins).");
  cmd->add_option("input", o->input, "Point set: .csv, .ply, .glb or .gltf")->required();
  cmd->add_option("-o,--output", o->output, "PNG to write")->required();
  cmd->add_option("--mode", o->mode, "fp32|split|rte|df64|native|batch")->default_val("native");
  cmd->add_option("--backend", o->backend,
                  "raster (graphics pipeline, POINT_LIST, the study's design) or compute (a thread per point,\n"
                  "64-bit atomic depth test; the fast path on GPUs with a small graphics front end)")
      ->default_val("raster");
  cmd->add_option("--width", o->width, "Picture width in pixels")->default_val(1024);
  cmd->add_option("--height", o->height, "Picture height in pixels")->default_val(768);
  cmd->add_option("--eye", o->eye, "Camera position X,Y,Z (with --target)");
  cmd->add_option("--target", o->target, "Point looked at X,Y,Z");
  cmd->add_option("--up", o->up, "Up direction X,Y,Z (default 0,1,0)");
  cmd->add_flag("--fit", o->fit, "Frame the bounding box (the default without --eye)");
  cmd->add_option("--fov", o->fov, "Vertical field of view in degrees")->default_val(45.0);
  cmd->add_flag("--ortho", o->ortho, "Orthographic projection (the default for 2D data, z = 0)");
  cmd->add_option("--view-center", o->view_center, "Orthographic window centre X,Y[,Z]");
  cmd->add_option("--view-width", o->view_width, "Orthographic window width (height follows the aspect)");
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
  addCommonOptions(*cmd, o->common);
  cmd->callback([o, &run]() { run = [o]() { return runRender(*o); }; });
}

}  // namespace dpoint
