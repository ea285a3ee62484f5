// dpoint render IN -o OUT.png: the offscreen Vulkan preview in one precision mode, with GPU
// timing and, with --error, the error against the exact CPU reference (DESIGN §4–6).
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <future>
#include <memory>
#include <utility>
#include <vector>

#include "cli/cli_camera.h"
#include "cli/cli_text.h"
#include "cli/commands.h"
#include "ops/point_filters.h"
#include "converters/point_inputs.h"
#include "converters/point_io.h"
#include "converters/ply.h"
#include "core/atomic_file.h"
#include "core/interrupt.h"
#include "core/memory.h"
#include "ops/point_order.h"
#include "core/progress.h"
#include "viewer/camera.h"
#include "image/canvas.h"
#include "vulkan/context.h"
#include "image/image.h"
#include "viewer/probe.h"
#include "viewer/reference.h"
#include "viewer/render.h"

namespace dpoint {
namespace {

struct RenderCliOptions {
  std::vector<std::string> inputs;
  std::string output, mode = "auto", backend = "raster", device = "auto", json, native_path = "auto";
  std::string order = "input", shade = "auto", stream = "auto";
  double edl_strength = 1.0, edl_radius = 1.4;
  uint32_t views = 1;
  std::string color = "auto", max_device_memory;
  std::string up_axis = "auto";
  CameraCliOptions camera;
  std::string background = "0,0,0";
  bool error = false, validate = false;
  std::string point_size = "auto";
  uint32_t frames = 1, warmup = 1;
  uint64_t chunk_points = 0;
  std::string max_memory;
  CommonOptions common;
};

// Host and device bytes per pixel at most: colour and depth (or the compute backend's 64-bit key
// and packed picture), the readback buffer, the host image and, with --error, the reference raster.
constexpr uint64_t kPictureBytesPerPixel = 32;

// `path` ends with `extension` (lower case, with its dot), in any case.
bool hasExtension(const std::string& path, const std::string& extension) {
  if (path.size() < extension.size()) return false;
  std::string tail = path.substr(path.size() - extension.size());
  std::transform(tail.begin(), tail.end(), tail.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return tail == extension;
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

std::string jsonReport(const RenderCliOptions& o, const VulkanContext& context, size_t count,
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
  s += "  \"points\": " + std::to_string(count) + ",\n";
  s += "  \"width\": " + std::to_string(o.camera.width) + ",\n  \"height\": " + std::to_string(o.camera.height) + ",\n";
  s += "  \"frames\": " + std::to_string(r.frame_ms.size()) + ",\n";
  if (r.gpu_ms.empty()) {
    s += "  \"gpu_ms\": null,\n";
  } else {
    s += "  \"gpu_ms\": {\"median\": " + num(gpu_median) + ", \"p95\": " + num(percentileOf(r.gpu_ms, 95)) +
         ", \"min\": " + num(*std::min_element(r.gpu_ms.begin(), r.gpu_ms.end())) + "},\n";
    // Every timed frame in order: a slow start (the first frames after a large upload) shows here.
    s += "  \"gpu_ms_each\": [";
    for (size_t i = 0; i < r.gpu_ms.size(); ++i) s += (i ? ", " : "") + num(r.gpu_ms[i]);
    s += "],\n";
  }
  s += "  \"frame_ms\": {\"median\": " + num(frame_median) + ", \"p95\": " + num(percentileOf(r.frame_ms, 95)) + "},\n";
  s += "  \"upload_ms\": " + num(r.upload_ms) + ",\n  \"readback_ms\": " + num(r.readback_ms) + ",\n";
  s += "  \"e2e_ms\": " + num(r.upload_ms + frame_median + r.readback_ms) + ",\n";
  s += "  \"phases_ms\": {";
  for (size_t i = 0; i < phases.list().size(); ++i)
    s += std::string(i ? ", " : "") + jsonString(phases.list()[i].first) + ": " + num(phases.list()[i].second);
  s += "},\n  \"peak_rss_mb\": " + num(Phases::peakRssMb()) + ",\n";
  s += "  \"points_per_s\": " + num(static_cast<double>(count) / (per_frame_ms * 1e-3)) + ",\n";
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

// --shade auto: eye-dome lighting for a 3D set, none for a 2D one (every z is 0) and with --error
// (whose image check compares plain pixels with the reference raster). It keys on the data, not
// the camera: a survey seen from above with --ortho still has the relief EDL brings out, and a
// flat set seen in perspective has no relief, only the depth ramp of a tilted plane.
Shading shadingFor(const RenderCliOptions& o, const Bounds& bounds) {
  if (o.shade == "edl") return Shading::kEdl;
  if (o.shade == "none" || o.error) return Shading::kNone;
  return bounds.planar ? Shading::kNone : Shading::kEdl;
}

// A view of --views: its label and the fit's direction (target to eye) and up.
struct View {
  const char* label;
  glm::dvec3 direction, up;
};

// --up-axis auto: z for LAS (surveys are z-up), y otherwise (the generators' and glTF's up).
bool zUp(const RenderCliOptions& o) {
  if (o.up_axis != "auto") return o.up_axis == "z";
  return std::all_of(o.inputs.begin(), o.inputs.end(), [](const std::string& path) { return hasExtension(path, ".las"); });
}

// One view: the three-quarter one; four: front, side, top, three-quarter. Directions are in the
// up axis's frame: with z up, "front" looks along +y and the oblique view sits in front, above.
std::vector<View> viewsFor(uint32_t count, bool z_up) {
  const View three_quarter = z_up ? View{"three-quarter", {0.6, -1.0, 0.5}, {0, 0, 1}}
                                  : View{"three-quarter", {0.6, 0.5, 1.0}, {0, 1, 0}};
  if (count == 1) return {three_quarter};
  if (z_up)
    return {{"front", {0, -1, 0}, {0, 0, 1}}, {"side", {1, 0, 0}, {0, 0, 1}}, {"top", {0, 0, 1}, {0, 1, 0}}, three_quarter};
  return {{"front", {0, 0, 1}, {0, 1, 0}}, {"side", {1, 0, 0}, {0, 1, 0}}, {"top", {0, 1, 0}, {0, 0, -1}}, three_quarter};
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

// --point-size auto: 1 px, unless the points are too few to cover the set's outline on screen:
// then about the spacing of a quarter of them (a closed surface shows its front half, and a folded
// one like a fractal's hides about half of that behind its own folds) over the
// ellipse inside the bounding box's screen rectangle, rounded up, at most 4 px. Always 1 for 2D
// (ortho) views, the compute backend (size-1 points only) and with --error (the reference raster
// draws 1-px points).
float pointSizeFor(const RenderCliOptions& o, size_t count, const Bounds& box, const Camera& camera, Backend backend,
                   const DeviceFacts& facts) {
  if (o.point_size != "auto") return static_cast<float>(std::stod(o.point_size));
  if (o.error || backend == Backend::kCompute || camera.ortho || !facts.large_points) return 1.0f;
  std::vector<glm::dvec3> corners;
  for (int i = 0; i < 8; ++i)
    corners.push_back({(i & 1) ? box.max.x : box.min.x, (i & 2) ? box.max.y : box.min.y, (i & 4) ? box.max.z : box.min.z});
  double x0 = camera.width, y0 = camera.height, x1 = 0.0, y1 = 0.0;
  for (const WindowPoint& w : projectReference(corners, camera)) {
    if (!w.visible) return 1.0f;  // the eye is inside or near the box: no outline to fill
    x0 = std::min(x0, std::max(w.x, 0.0)), x1 = std::max(x1, std::min(w.x, double(camera.width)));
    y0 = std::min(y0, std::max(w.y, 0.0)), y1 = std::max(y1, std::min(w.y, double(camera.height)));
  }
  const double area = std::max(0.0, x1 - x0) * std::max(0.0, y1 - y0) * 0.25 * 3.14159265358979;
  const double spacing = std::sqrt(area / std::max(1.0, 0.25 * static_cast<double>(count)));
  return static_cast<float>(std::clamp(std::ceil(spacing), 1.0, std::min(4.0, double(facts.max_point_size))));
}

// What every view of one run shares: the set's size and bounds, the parsed options.
struct RunFacts {
  size_t count = 0;
  Bounds bounds;
  Backend backend = Backend::kRaster;
  uint32_t background = 0;
  NativePath native_path = NativePath::kAuto;
};

RenderOptions renderOptions(const RenderCliOptions& o, const RunFacts& run, PrecisionMode mode, const Camera& camera,
                            const DeviceFacts& facts) {
  RenderOptions options;
  options.mode = mode;
  options.backend = run.backend;
  options.point_size = pointSizeFor(o, run.count, run.bounds, camera, run.backend, facts);
  options.background_rgba8 = run.background;
  options.frames = o.frames;
  options.warmup_frames = o.warmup;
  options.probe = o.error;
  options.native_path = run.native_path;
  options.max_chunk_points = o.chunk_points;
  options.shading = shadingFor(o, run.bounds);
  options.edl = EdlOptions{static_cast<float>(o.edl_strength), static_cast<float>(o.edl_radius)};
  return options;
}

// --views 4: each view rendered in its own mode (--mode auto decides per view), one labelled sheet.
int renderViews(const RenderCliOptions& o, const VulkanContext& context, const PointSet& points,
                const std::vector<View>& views, const std::vector<Camera>& cameras, const RunFacts& run) {
  std::vector<LabelledView> sheet;
  for (size_t i = 0; i < views.size(); ++i) {
    Result<Prediction> prediction = predict(o, context, points, cameras[i], run.backend);
    if (!prediction) return reportError(prediction.error());
    const RenderOptions options = renderOptions(o, run, prediction->mode, cameras[i], context.facts);
    Result<RenderResult> rendered = renderPoints(context, points, cameras[i], options);
    if (!rendered) return reportError(rendered.error());
    const std::string mode(modeName(prediction->mode));
    sheet.push_back({std::string(views[i].label) + " (" + mode + ")", std::move(rendered->image)});
    std::printf("view %s: mode %s, predicted error bound %s", views[i].label, mode.c_str(),
                formatBound(prediction->bound_px).c_str());
    if (!rendered->gpu_ms.empty()) std::printf(", gpu %.3f ms/frame median of %zu", medianOf(rendered->gpu_ms), rendered->gpu_ms.size());
    std::printf("\n");
  }
  const Image picture = composeContactSheet(sheet, 2);
  if (Status written = writePng(o.output, picture); !written) return reportError(written.error());
  std::printf("%s: %zu points, 4 views, %ux%u, %s backend, %s\n", o.output.c_str(), points.size(), picture.width,
              picture.height, o.backend.c_str(), context.facts.name.c_str());
  for (const std::string& m : context.validationMessages()) std::fprintf(stderr, "dpoint: %s\n", m.c_str());
  if (!context.validationMessages().empty())
    return reportError(Error{std::to_string(context.validationMessages().size()) + " Vulkan validation message(s)",
                             ExitCode::kNoDevice});
  return 0;
}

// The bounds and planarity of a streamed set: one pass over it, a block at a time.
Result<Bounds> streamBounds(const std::string& path, PointInputStream& ply, Progress& progress) {
  Bounds bounds{glm::dvec3(HUGE_VAL), glm::dvec3(-HUGE_VAL), true};
  PointSet block;
  progress.start("bounds of " + path + " (points)", ply.count());
  for (uint64_t first = 0; first < ply.count(); first += kStreamBlockPoints) {
    const uint64_t n = std::min(kStreamBlockPoints, ply.count() - first);
    if (interrupted()) return interruptedError();
    if (Status status = ply.read(first, n, block); !status) return status.error();
    progress.advance(n);
    const Box box = boundingBox(block.positions);
    bounds.min = glm::min(bounds.min, box.min), bounds.max = glm::max(bounds.max, box.max);
    bounds.planar = bounds.planar && block.isPlanar();
  }
  progress.finish();
  return bounds;
}

// A streamed set is read once, so no bound is predicted from its points: --mode auto takes native,
// which holds to well under 0.1 px wherever the study's hard cases reach.
Result<Prediction> streamPrediction(const RenderCliOptions& o) {
  Prediction p;
  p.mode = o.mode == "auto" ? PrecisionMode::kNative : *parseMode(o.mode);
  p.bound_px = std::nan("");
  return p;
}

int runRender(const RenderCliOptions& o) {
  if (o.mode != "auto" && !parseMode(o.mode))
    return reportError(Error{"--mode must be auto, fp32, split, rte, df64, native or batch, got '" + o.mode + "'", ExitCode::kUsage});
  if (o.backend != "raster" && o.backend != "compute")
    return reportError(Error{"--backend must be raster or compute, got '" + o.backend + "'", ExitCode::kUsage});
  Result<PointOrder> order = parsePointOrder("--order", o.order);
  if (!order) return reportError(order.error());
  if (!hasExtension(o.output, ".png") && o.output.rfind("/dev/", 0) != 0)
    return reportError(Error{"-o " + o.output + ": the picture is written as PNG; name it .png", ExitCode::kUsage});
  NativePath native_path = NativePath::kAuto;
  if (o.native_path == "attribute") native_path = NativePath::kAttribute;
  else if (o.native_path == "pull") native_path = NativePath::kPull;
  else if (o.native_path != "auto")
    return reportError(Error{"--native-path must be auto, attribute or pull, got '" + o.native_path + "'", ExitCode::kUsage});
  if (o.shade != "auto" && o.shade != "none" && o.shade != "edl")
    return reportError(Error{"--shade must be auto, none or edl, got '" + o.shade + "'", ExitCode::kUsage});
  if (!(o.edl_strength > 0.0 && o.edl_strength <= 100.0))
    return reportError(Error{"--edl-strength must be in (0, 100], got " + formatNumber(o.edl_strength, true), ExitCode::kUsage});
  if (!(o.edl_radius >= 1.0 && o.edl_radius <= 16.0))
    return reportError(Error{"--edl-radius must be in [1, 16] pixels, got " + formatNumber(o.edl_radius, true), ExitCode::kUsage});
  if (o.color != "auto" && o.color != "rgb" && o.color != "elevation" && o.color != "intensity" &&
      o.color != "classification")
    return reportError(Error{"--color must be auto, rgb, elevation, intensity or classification, got '" + o.color + "'",
                             ExitCode::kUsage});
  if (o.point_size != "auto") {
    Result<std::vector<double>> size = parseNumbers("--point-size", o.point_size, 1);
    if (!size) return reportError(size.error());
  }
  if (o.stream != "auto" && o.stream != "on" && o.stream != "off")
    return reportError(Error{"--stream must be auto, on or off, got '" + o.stream + "'", ExitCode::kUsage});
  if (o.views != 1 && o.views != 4) return reportError(Error{"--views must be 1 or 4, got " + std::to_string(o.views), ExitCode::kUsage});
  if (o.up_axis != "auto" && o.up_axis != "y" && o.up_axis != "z")
    return reportError(Error{"--up-axis must be auto, y or z, got '" + o.up_axis + "'", ExitCode::kUsage});
  Result<CameraSpec> spec = cameraSpec(o.camera);
  if (!spec) return reportError(spec.error());
  if (o.views == 4) {
    if (spec->eye || spec->ortho.value_or(false))
      return reportError(Error{"--views 4 frames each view with --fit in perspective; drop --eye/--target/--up and --ortho",
                               ExitCode::kUsage});
    if (o.error || !o.json.empty())
      return reportError(Error{"--views 4 makes a contact sheet; --error and --json measure one view (use --views 1)",
                               ExitCode::kUsage});
  }
  Result<uint32_t> background = parseBackground(o.background);
  if (!background) return reportError(background.error());
  Result<uint64_t> device_memory =
      o.max_device_memory.empty() ? uint64_t{0} : parseMemorySize("--max-device-memory", o.max_device_memory);
  if (!device_memory) return reportError(device_memory.error());

  Result<uint64_t> limit = memoryLimitOf(o.max_memory);
  if (!limit) return reportError(limit.error());
  // Before the input is read: --width 1000000 should not wait for a large file to load first.
  const uint64_t pixels = uint64_t{o.camera.width} * o.camera.height;
  if (Status s = checkMemory("a " + std::to_string(o.camera.width) + "x" + std::to_string(o.camera.height) + " picture",
                             pixels * kPictureBytesPerPixel, *limit);
      !s)
    return reportError(s.error());

  Phases phases;
  // The Vulkan device is made while the input is read: creating it takes 150 ms or more on the
  // NVIDIA driver, a good part of a 16.7M-point render's second. Its errors wait until the input
  // has been read, so a bad file is still reported first.
  std::future<Result<std::unique_ptr<VulkanContext>>> device_made = std::async(std::launch::async, [&o, &device_memory] {
    return VulkanContext::create(ContextOptions{o.device, o.validate, *device_memory});
  });
  Progress progress(progressSink(o.common.quiet), "render");
  // Large binary PLY input (one file, or tiles) is drawn a block at a time (a set larger than
  // memory); anything else is read whole.
  const std::string inputs = describeInputs(o.inputs);
  Result<std::unique_ptr<PointInputStream>> opened = openPointStream(o.inputs, o.stream, o.common.threads);
  if (!opened) return reportError(opened.error());
  std::unique_ptr<PointInputStream> ply = std::move(*opened);
  if (ply && (o.color == "intensity" || o.color == "classification"))
    return reportError(Error{inputs + ": --color " + o.color + " needs LAS input", ExitCode::kBadInput});
  if (ply && (o.error || *order != PointOrder::kInput || o.views != 1))
    return reportError(Error{inputs + ": a streamed set (" + std::to_string(ply->count()) + " points) is read once: "
                             "--error, --order morton and --views 4 need it in memory (--stream off)", ExitCode::kUsage});
  std::optional<PointSet> points;
  RunFacts run;
  bool has_colors = false;
  if (ply) {
    if (ply->count() == 0) return reportError(Error{inputs + ": no points to render", ExitCode::kBadInput});
    Result<Bounds> bounds = streamBounds(inputs, *ply, progress);
    if (!bounds) return reportError(bounds.error());
    run.count = ply->count(), run.bounds = *bounds, has_colors = ply->hasColors();
    phases.mark("bounds");
  } else {
    ReadOptions read_options{o.common.threads, false, &progress, true};
    read_options.max_memory = *limit;
    // LAS fields as colours; elevation replaces whatever the file holds.
    read_options.las_color = o.color == "intensity"        ? LasColorSource::kIntensity
                             : o.color == "classification" ? LasColorSource::kClassification
                             : o.color == "elevation"      ? LasColorSource::kNone
                                                           : LasColorSource::kAuto;
    Result<PointSet> read = readPointInputs(o.inputs, read_options);
    if (!read) return reportError(read.error());
    points = std::move(*read);
    phases.mark("read");
    if (points->size() == 0) return reportError(Error{inputs + ": no points to render", ExitCode::kBadInput});
    run.count = points->size(), has_colors = points->hasColors();
  }
  if (o.color == "rgb" && !has_colors)
    return reportError(Error{inputs + ": --color rgb: the set has no colours (try --color elevation)", ExitCode::kBadInput});
  const bool z_up = zUp(o);
  if (points) run.bounds = boundsOf(*points);
  const Bounds& bounds = run.bounds;
  // A 2D set has no elevation: without colours its points stay white.
  const bool elevation = o.color == "elevation" || (o.color == "auto" && !has_colors && !bounds.planar);
  if (points) {
    if (elevation) colorByElevation(*points, z_up ? 2 : 1, o.common.threads);
    reorderPoints(*points, *order, o.common.threads, &progress);
    phases.mark("order");
  }
  if (o.views == 4 && bounds.planar)
    return reportError(Error{inputs + ": --views 4 shows a 3D set from four sides; this set is 2D (every z is 0)",
                             ExitCode::kUsage});
  std::vector<View> views = viewsFor(o.views, z_up);
  std::vector<Camera> cameras;
  for (const View& view : views) {
    CameraSpec view_spec = *spec;
    // One y-up view is makeCamera's own default fit.
    if (!spec->eye && (o.views == 4 || z_up)) view_spec.fit_direction = view.direction, view_spec.fit_up = view.up;
    // Four views share the picture: each gets a quarter, so the sheet keeps about --width x --height.
    if (o.views == 4) view_spec.width = std::max(1u, spec->width / 2), view_spec.height = std::max(1u, spec->height / 2);
    Result<Camera> camera = makeCamera(view_spec, bounds);
    if (!camera) return reportError(camera.error());
    cameras.push_back(*camera);
  }
  phases.mark("camera");

  Result<std::unique_ptr<VulkanContext>> context = device_made.get();
  if (!context) return reportError(context.error());
  phases.mark("device");  // what is left of making it once the input is in
  run.backend = o.backend == "compute" ? Backend::kCompute : Backend::kRaster;
  run.background = *background;
  run.native_path = native_path;
  const Backend backend = run.backend;
  if (o.views == 4) return renderViews(o, **context, *points, views, cameras, run);
  const Camera* camera = &cameras[0];
  Result<Prediction> prediction = ply ? streamPrediction(o) : predict(o, **context, *points, *camera, backend);
  if (!prediction) return reportError(prediction.error());
  phases.mark("mode");
  const RenderOptions options = renderOptions(o, run, prediction->mode, *camera, (*context)->facts);
  Result<RenderResult> rendered = [&]() -> Result<RenderResult> {
    if (!ply) return renderPoints(**context, *points, *camera, options);
    PointStream stream;
    stream.count = run.count;
    stream.has_colors = has_colors || elevation;
    const int axis = z_up ? 2 : 1;
    stream.read = [&](size_t first, size_t n, PointSet& block) -> Status {
      if (Status status = ply->read(first, n, block); !status) return status;
      if (elevation) colorByElevation(block, axis, bounds.min[axis], bounds.max[axis], o.common.threads);
      progress.advance(n);
      return okStatus();
    };
    progress.start("streaming " + inputs + " to the GPU (points)", run.count);
    Result<RenderResult> streamed = renderStream(**context, stream, *camera, options);
    progress.finish();
    return streamed;
  }();
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
    Status status = file->write(jsonReport(o, **context, run.count, *rendered, *prediction, error ? &*error : nullptr, phases));
    if (status) status = file->commit();
    if (!status) return reportError(status.error());
  }

  const DeviceFacts& f = (*context)->facts;
  const RenderResult& r = *rendered;
  const PrecisionMode mode = prediction->mode;
  std::printf("%s: %zu points%s, mode %s, %s backend, %ux%u, %g px points%s, %s (%s, driver %s)\n", o.output.c_str(),
              run.count, ply ? " (streamed)" : "", std::string(modeName(mode)).c_str(), o.backend.c_str(), o.camera.width, o.camera.height,
              double(options.point_size), options.shading == Shading::kEdl ? ", eye-dome lighting" : "", f.name.c_str(),
              f.type.c_str(), formatDriverVersion(f.vendor_id, f.driver_version).c_str());
  if (ply)
    std::printf("mode %s: no bound predicted (a streamed set is read once)%s\n", std::string(modeName(mode)).c_str(),
                o.mode == "auto" ? "; --mode auto takes native for it" : "");
  else
    printChoice(*prediction, f, backend);
  if (!r.gpu_ms.empty())
    std::printf("gpu: %.3f ms/frame median of %zu (p95 %.3f), %.3g points/s, %u B/pt\n", medianOf(r.gpu_ms),
                r.gpu_ms.size(), percentileOf(r.gpu_ms, 95),
                static_cast<double>(run.count) / (medianOf(r.gpu_ms) * 1e-3), bytesPerPoint(mode));
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
        : "no image check (the reference raster draws plain --point-size 1 pixels only)";
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
  cmd->add_option("input", o->inputs,
                  "Point sets (.csv, .ply, .las, .glb, .gltf), drawn as one; the N tiles of `generate --tile` as the\n"
                  "whole. Large binary PLY input is streamed (--stream)")
      ->required();
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
  cmd->add_option("--point-size", o->point_size,
                  "Point size in pixels, or auto: 1, or larger (up to 4) when a 3D set has too few points to\n"
                  "cover its outline at this size; 1 for 2D sets, --backend compute and --error")
      ->default_val("auto");
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
  cmd->add_option("--shade", o->shade,
                  "auto|none|edl. edl: eye-dome lighting, a screen-space pass over the depth of the visible points\n"
                  "that darkens a pixel by how far its neighbours stand in front of it, so a surface of 1-px points\n"
                  "reads as a surface (as in Potree and CloudCompare). auto: edl for 3D sets, none for 2D sets\n"
                  "(every z is 0) and with --error, whatever the camera (--ortho, --eye); GPU timings exclude it")
      ->default_val("auto");
  cmd->add_option("--edl-strength", o->edl_strength, "Eye-dome darkening: exp(-strength * 300 * mean log2 depth step)")
      ->default_val(1.0);
  cmd->add_option("--edl-radius", o->edl_radius, "Eye-dome neighbour distance in pixels (1..16)")->default_val(1.4);
  cmd->add_option("--color", o->color,
                  "auto|rgb|elevation|intensity|classification. elevation: a perceptual colour map (viridis) along\n"
                  "the up axis (--up-axis); intensity (grey) and classification (the ASPRS classes' colours): LAS\n"
                  "only. auto: the set's colours when it has them, else elevation for 3D sets and white for 2D ones")
      ->default_val("auto");
  cmd->add_option("--max-device-memory", o->max_device_memory,
                  "Refuse (exit 3, a Vulkan fault) to allocate more GPU memory than this, e.g. 2G (default: what the\n"
                  "device has)");
  cmd->add_option("--stream", o->stream,
                  "auto|on|off. on: draw binary PLY input (a file, or tiles) a block at a time, so a set larger\n"
                  "than memory renders in about 1.2 GB of host memory (two blocks of 16M points); auto: for binary\n"
                  "PLY input of more than 2^26 points. A streamed set gets no predicted bound (--mode auto takes\n"
                  "native), no --error, --order or --views 4")
      ->default_val("auto");
  cmd->add_option("--views", o->views,
                  "1, or 4: one PNG of four labelled views (front, side, top, three-quarter), each framed by --fit\n"
                  "in a quarter of --width x --height (3D sets; not with --eye, --ortho, --error or --json)")
      ->default_val(1);
  cmd->add_option("--up-axis", o->up_axis,
                  "auto|y|z: the data's up for the --fit views. auto: z for LAS (surveys), y otherwise")
      ->default_val("auto");
  addMaxMemoryOption(*cmd, o->max_memory);
  addCommonOptions(*cmd, o->common);
  cmd->callback([o, &run]() { run = [o]() { return runRender(*o); }; });
}

}  // namespace dpoint
