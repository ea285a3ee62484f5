#include "bench/run.h"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>

#include "bench/report_internal.h"  // backendText, figureBackend, g3
#include "converters/gltf_json.h"
#include "converters/point_io.h"
#include "core/atomic_file.h"
#include "core/input_file.h"
#include "core/interrupt.h"
#include "core/text.h"
#include "viewer/precision.h"
#include "viewer/probe.h"
#include "viewer/reference.h"
#include "viewer/selftest.h"

namespace dpoint {
namespace {

using report::g3;

bool keptBySizes(const BenchCase& c, const std::vector<std::string>& sizes) {
  if (sizes.empty() || c.suite != BenchSuite::kPaper) return true;
  return std::any_of(sizes.begin(), sizes.end(), [&](const std::string& s) { return hasSizeLabel(c, s); });
}

std::string cachePath(const BenchOptions& options, const std::string& name) {
  return (std::filesystem::path(options.cache_dir) / name).string();
}

// The case's dataset from the cache, made first when it is not there.
Result<PointSet> loadDataset(const BenchCase& c, const BenchOptions& options) {
  const std::string path = cachePath(options, cacheFileName(c));
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    if (options.log) options.log("making " + path);
    if (c.generate.empty()) {
      Result<AtomicFile> file = AtomicFile::create(path);
      if (!file) return file.error();
      Status status = file->write(c.literal_csv);
      if (status) status = file->commit();
      if (!status) return status.error();
    } else {
      std::vector<std::string> args = {"generate"};
      args.insert(args.end(), c.generate.begin(), c.generate.end());
      args.insert(args.end(), {"-o", path, "--quiet"});
      Status made = options.run_dpoint(args);
      if (!made) return made.error();
    }
  }
  return readPoints(path);
}

double distancePx(const WindowPoint& a, const WindowPoint& b) { return std::hypot(a.x - b.x, a.y - b.y); }

// Everything a case's rows share: the data, the camera, the reference and the bounds.
struct Prepared {
  PointSet points;
  CameraSpec spec;  // what the timed `dpoint render` is given
  Camera camera;
  std::vector<WindowPoint> reference;
  Image reference_raster;
  ErrorBounds bounds;
};

Result<Prepared> prepare(const BenchCase& c, const BenchOptions& options) {
  Result<PointSet> points = loadDataset(c, options);
  if (!points) return points.error();
  if (points->size() == 0) return Error{c.name + ": the dataset is empty", ExitCode::kBadInput};
  const Bounds bounds = boundsOf(*points);
  Prepared p;
  p.spec = cameraSpecFor(c, bounds);
  Result<Camera> camera = makeCamera(p.spec, bounds);
  if (!camera) return Error{c.name + ": " + camera.error().message, camera.error().code};
  p.points = std::move(*points);
  p.camera = *camera;
  if (options.measure_error) {
    p.reference = projectReference(p.points.positions, p.camera);
    p.reference_raster = rasterReference(p.reference, encodeColors(p.points), p.camera.width, p.camera.height, 0xff000000u);
  }
  p.bounds = predictErrorBounds(p.points, p.camera);
  return p;
}

// `dpoint render` flags for the case's camera, every number in shortest round-trip form (exact).
std::vector<std::string> cameraFlags(const CameraSpec& spec) {
  auto vec = [](const glm::dvec3& v) { return formatNumber(v.x) + "," + formatNumber(v.y) + "," + formatNumber(v.z); };
  std::vector<std::string> flags = {"--width", std::to_string(spec.width), "--height", std::to_string(spec.height)};
  if (spec.eye) flags.insert(flags.end(), {"--eye", vec(*spec.eye), "--target", vec(*spec.target), "--up", vec(*spec.up)});
  if (spec.view_center) flags.insert(flags.end(), {"--view-center", vec(*spec.view_center)});
  if (spec.view_width) flags.insert(flags.end(), {"--view-width", formatNumber(*spec.view_width)});
  return flags;
}

double numberAt(const JsonValue& object, std::string_view key) {
  const JsonValue* v = object.find(key);
  return v && v->kind == JsonValue::Kind::kNumber ? v->number : 0.0;
}

// A per-batch mode's plan from the timed draw's report (its `batch_plan`); other modes have none.
Status readPlan(const JsonValue& json, const std::string& json_path, BenchRow& row) {
  if (!modeInfo(row.mode).batch_points) return okStatus();
  const JsonValue* plan = json.find("batch_plan");
  const JsonValue* loaded = plan ? plan->find("loaded_bytes_per_point") : nullptr;
  const JsonValue* batches = plan ? plan->find("batches") : nullptr;
  if (!loaded || loaded->kind != JsonValue::Kind::kNumber || !batches || batches->kind != JsonValue::Kind::kNumber)
    return Error{json_path + ": " + std::string(modeName(row.mode)) + " mode's report has no batch_plan", ExitCode::kBadInput};
  row.plan_bytes_per_point = loaded->number;
  row.culled_share = batches->number > 0 ? numberAt(*plan, "culled") / batches->number : 0.0;
  if (!modeInfo(row.mode).tiers) return okStatus();
  const JsonValue* shares = plan->find("tier_share");
  if (!shares || shares->kind != JsonValue::Kind::kArray || shares->items.size() != kAdaptiveTiers)
    return Error{json_path + ": adaptive mode's batch_plan has no tier_share of " + std::to_string(kAdaptiveTiers),
                 ExitCode::kBadInput};
  std::array<double, kAdaptiveTiers> tiers{};
  for (size_t t = 0; t < kAdaptiveTiers; ++t) tiers[t] = shares->items[t].number;
  row.tier_share = tiers;
  return okStatus();
}

// A timed draw's picture and report: gone when the draw has been read, and on a stop (SIGINT,
// SIGTERM) too, which the interrupt watcher deletes (a stopped bench had left them in the cache).
struct ScratchFiles {
  std::vector<std::string> paths;
  explicit ScratchFiles(std::vector<std::string> p) : paths(std::move(p)) {
    for (const std::string& path : paths) registerTemporaryFile(path);
  }
  ~ScratchFiles() {
    for (const std::string& path : paths) {
      std::error_code ec;
      std::filesystem::remove(path, ec);
      unregisterTemporaryFile(path);
    }
  }
  ScratchFiles(const ScratchFiles&) = delete;
  ScratchFiles& operator=(const ScratchFiles&) = delete;
};

// The timed draw: a fresh `dpoint render` process without the probe, exactly what a user runs.
Status timeMode(const BenchCase& c, const Prepared& p, const BenchOptions& options, BenchRow& row) {
  const std::string json_path = cachePath(options, "timed-draw.json");
  const ScratchFiles scratch({json_path, cachePath(options, "timed-draw.png")});
  std::vector<std::string> args = {"render", cachePath(options, cacheFileName(c)), "-o", cachePath(options, "timed-draw.png"),
                                   "--mode", std::string(modeName(row.mode)), "--backend",
                                   report::backendText(row.backend), "--device", options.device,
                                   "--frames", std::to_string(std::max<uint32_t>(options.frames, 1)), "--warmup",
                                   warmupText(options.warmup), "--json", json_path, "--quiet"};
  for (const std::string& flag : cameraFlags(p.spec)) args.push_back(flag);
  if (options.validate) args.push_back("--validate");
  if (Status ran = options.run_dpoint(args); !ran) return ran;
  Result<InputFile> file = InputFile::open(json_path);
  if (!file) return file.error();
  std::string text(file->size(), '\0');
  Result<size_t> got = file->readAt(0, text.data(), text.size());
  if (!got) return got.error();
  Result<JsonValue> json = parseJson(text, 8);
  if (!json) return Error{json_path + ": " + json.error().message, ExitCode::kBadInput};
  if (const JsonValue* gpu = json->find("gpu_ms"); gpu && gpu->kind == JsonValue::Kind::kObject) {
    row.gpu_ms_median = numberAt(*gpu, "median");
    row.gpu_ms_p95 = numberAt(*gpu, "p95");
    row.gpu_ms_min = numberAt(*gpu, "min");
  }
  if (const JsonValue* frame = json->find("frame_ms"); frame) row.frame_ms_median = numberAt(*frame, "median");
  row.upload_ms = numberAt(*json, "upload_ms");
  row.readback_ms = numberAt(*json, "readback_ms");
  row.e2e_ms = numberAt(*json, "e2e_ms");
  row.points_per_s = numberAt(*json, "points_per_s");
  if (const JsonValue* warmup = json->find("warmup"); warmup && warmup->kind == JsonValue::Kind::kObject) {
    row.warmup_frames = static_cast<uint32_t>(numberAt(*warmup, "frames"));
    row.warmup_ms = numberAt(*warmup, "ms");
  }
  return readPlan(*json, json_path, row);
}

// The probed draw: every point's clip position against the exact reference, and the picture
// against the reference raster. Fills `montage_errors` (per point, NaN: lost) when asked.
Result<Image> measureMode(const VulkanContext& context, const Prepared& p, BenchRow& row,
                          std::vector<double>* montage_errors) {
  RenderOptions r;
  r.mode = row.mode;
  r.backend = row.backend;
  r.frames = 1;
  r.warmup_frames = 0;
  r.probe = true;
  Result<RenderResult> probed = renderPoints(context, p.points, p.camera, r);
  if (!probed) return probed.error();
  const std::vector<WindowPoint> probe = probeWindows(*probed, p.camera);
  const ErrorStats e = compareToReference(p.reference, probe);
  if (e.points > e.lost) {
    row.error_max_px = e.max_px;
    row.error_p99_px = e.p99_px;
    row.error_rms_px = e.rms_px;
  }
  row.share_off_half_px = e.share_off_half_px;
  row.points_visible = e.points;
  row.points_lost = e.lost;
  row.pixels_differing = countDifferingPixels(probed->image, p.reference_raster);
  if (montage_errors) {
    montage_errors->assign(probe.size(), 0.0);
    for (size_t i = 0; i < probe.size(); ++i) {
      if (!p.reference[i].visible) continue;
      (*montage_errors)[i] = probe[i].visible ? distancePx(p.reference[i], probe[i]) : std::nan("");
    }
  }
  return std::move(probed->image);
}

std::string montageCaption(const BenchRow& row) {
  if (!row.skipped.empty()) return "did not run";
  if (!row.error_max_px) return "all " + std::to_string(row.points_lost) + " lost";
  std::string text = "max " + g3(*row.error_max_px) + " px";
  if (row.points_lost) text += ", " + std::to_string(row.points_lost) + " lost";
  return text;
}

}  // namespace

void setBandwidthBound(BenchRow& row, const CopyBandwidth* copy) {
  assert(row.bench_case);
  const FrameTraffic traffic = frameTraffic(row.backend, row.mode, row.points, row.bench_case->width,
                                            row.bench_case->height, row.plan_bytes_per_point);
  row.splat_bytes_per_point = traffic.splat_bytes_per_point;
  row.loaded_bytes_per_point = traffic.loaded_bytes_per_point;
  row.bytes_per_frame = traffic.bytes_per_frame;
  row.bandwidth_bound_ms.reset();
  row.bandwidth_fraction.reset();
  if (!copy || !row.bytes_per_frame) return;
  row.bandwidth_bound_ms = bandwidthBoundMs(*row.bytes_per_frame, copy->boundRate());
  if (row.skipped.empty() && row.gpu_ms_median && *row.gpu_ms_median > 0.0)
    row.bandwidth_fraction = *row.bandwidth_bound_ms / *row.gpu_ms_median;
}

Result<BenchRun> runBench(const VulkanContext& context, const BenchOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  BenchRun run;
  run.device = context.facts;
  for (BenchSuite suite : options.suites) {
    for (BenchCase& c : suiteCases(suite))
      if (keptBySizes(c, options.sizes)) run.cases.push_back(std::move(c));
  }
  Result<SelfTest> self_test = runPrecisionSelfTest(context);
  if (!self_test) return self_test.error();
  if (options.measure_copy_bandwidth) {
    Result<CopyBandwidth> copy = measureCopyBandwidth(context, options.copy);
    if (!copy) return copy.error();
    run.copy_bandwidth = *copy;
    if (options.log) options.log("copy bandwidth: " + copyBandwidthText(*copy));
  }
  const CopyBandwidth* copy = run.copy_bandwidth ? &*run.copy_bandwidth : nullptr;
  // Made only once the device has passed its first submissions: a bench that fails there (no
  // feature, a lost device) leaves nothing behind.
  std::error_code ec;
  std::filesystem::create_directories(options.cache_dir, ec);
  if (ec) return Error{"cannot create the dataset cache " + options.cache_dir + ": " + ec.message(), ExitCode::kBadInput};
  const size_t total = run.cases.size() * options.backends.size() * kModeCount;
  size_t done = 0;
  for (const BenchCase& c : run.cases) {
    if (interrupted()) return interruptedError();
    Result<Prepared> prepared = prepare(c, options);
    if (!prepared) return prepared.error();
    const Prepared& p = *prepared;
    const bool wants_montage = c.montage && !run.montage && options.measure_error;
    const Backend montage_backend = report::figureBackend(options.backends);
    if (wants_montage) run.montage = MontageCapture{&c, montage_backend, p.reference, {}};
    for (Backend backend : options.backends) {
      for (size_t m = 0; m < kModeCount; ++m) {
        // A run that failed because of the interrupt would otherwise be recorded as skipped.
        if (interrupted()) return interruptedError();
        BenchRow row;
        row.bench_case = &c;
        row.points = p.points.size();
        row.mode = kAllModes[m];
        row.backend = backend;
        row.bytes_per_point = bytesPerPoint(row.mode);
        row.predicted_bound_px = p.bounds.px[m];
        row.float_floor_px = p.bounds.float_floor_px;
        Status usable = modeUsable(context, row.mode, *self_test, backend == Backend::kRaster);
        if (!usable) row.skipped = usable.error().message;
        if (row.skipped.empty()) {
          if (Status timed = timeMode(c, p, options, row); !timed) row.skipped = timed.error().message;
        }
        const bool capture = wants_montage && backend == montage_backend;
        MontageMode shot;
        shot.mode = row.mode;
        if (row.skipped.empty() && options.measure_error) {
          Result<Image> picture = measureMode(context, p, row, capture ? &shot.error_px : nullptr);
          if (picture) shot.picture = std::move(*picture);
          else row.skipped = picture.error().message;
        }
        if (capture) {
          shot.caption = montageCaption(row);
          run.montage->modes.push_back(std::move(shot));
        }
        setBandwidthBound(row, copy);
        ++done;
        if (options.log) {
          std::string line = '[' + std::to_string(done) + '/' + std::to_string(total) + "] " + std::string(suiteName(c.suite)) +
                             " " + c.name + ", " + report::backendText(backend) + " " + std::string(modeName(row.mode)) + ": ";
          if (!row.skipped.empty()) line += "skipped (" + row.skipped + ")";
          else {
            line += row.gpu_ms_median ? g3(*row.gpu_ms_median) + " ms" : g3(row.frame_ms_median) + " ms (host)";
            if (row.bandwidth_fraction) line += " (" + g3(100.0 * *row.bandwidth_fraction) + "% of the bandwidth bound)";
            if (row.plan_bytes_per_point) line += ", " + g3(*row.loaded_bytes_per_point) + " B/pt loaded";
            line += row.error_max_px ? ", max error " + g3(*row.error_max_px) + " px" : ", every point lost";
          }
          options.log(line);
        }
        run.rows.push_back(std::move(row));
      }
    }
  }
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return run;
}

}  // namespace dpoint
