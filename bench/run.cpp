#include "bench/run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>

#include "converters/point_io.h"
#include "core/atomic_file.h"
#include "viewer/precision.h"
#include "viewer/reference.h"
#include "viewer/selftest.h"

namespace dpoint {
namespace {

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

bool keptBySizes(const BenchCase& c, const std::vector<std::string>& sizes) {
  if (sizes.empty() || c.suite != BenchSuite::kPaper) return true;
  return std::any_of(sizes.begin(), sizes.end(), [&](const std::string& s) { return lower(s) == lower(c.size_label); });
}

// The case's dataset from the cache, made first when it is not there.
Result<PointSet> loadDataset(const BenchCase& c, const BenchOptions& options) {
  const std::string path = (std::filesystem::path(options.cache_dir) / cacheFileName(c)).string();
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
      Status made = options.make_dataset(c.generate, path);
      if (!made) return made.error();
    }
  }
  return readPoints(path);
}

double distancePx(const WindowPoint& a, const WindowPoint& b) { return std::hypot(a.x - b.x, a.y - b.y); }

std::string backendText(Backend backend) { return backend == Backend::kCompute ? "compute" : "raster"; }

std::string shortNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

// Everything a case's rows share: the data, the camera, the reference and the bounds.
struct Prepared {
  PointSet points;
  Camera camera;
  std::vector<WindowPoint> reference;
  Image reference_raster;
  ErrorBounds bounds;
};

Result<Prepared> prepare(const BenchCase& c, const BenchOptions& options) {
  Result<PointSet> points = loadDataset(c, options);
  if (!points) return points.error();
  if (points->size() == 0) return Error{c.name + ": the dataset is empty", ExitCode::kBadInput};
  Result<Camera> camera = makeCamera(cameraSpecFor(c, boundsOf(*points)), boundsOf(*points));
  if (!camera) return Error{c.name + ": " + camera.error().message, camera.error().code};
  Prepared p;
  p.points = std::move(*points);
  p.camera = *camera;
  p.reference = projectReference(p.points.positions, p.camera);
  p.reference_raster = rasterReference(p.reference, encodeColors(p.points), p.camera.width, p.camera.height, 0xff000000u);
  p.bounds = predictErrorBounds(p.points, p.camera);
  return p;
}

// The timed draw: no probe, so the GPU does exactly what `dpoint render` does.
void timeMode(const VulkanContext& context, const Prepared& p, const BenchOptions& options, BenchRow& row) {
  RenderOptions r;
  r.mode = row.mode;
  r.backend = row.backend;
  r.frames = std::max<uint32_t>(options.frames, 1);
  r.warmup_frames = options.warmup;
  Result<RenderResult> timed = renderPoints(context, p.points, p.camera, r);
  if (!timed) {
    row.skipped = timed.error().message;
    return;
  }
  if (!timed->gpu_ms.empty()) {
    row.gpu_ms_median = medianOf(timed->gpu_ms);
    row.gpu_ms_p95 = percentileOf(timed->gpu_ms, 95);
    row.gpu_ms_min = *std::min_element(timed->gpu_ms.begin(), timed->gpu_ms.end());
  }
  row.frame_ms_median = medianOf(timed->frame_ms);
  row.upload_ms = timed->upload_ms;
  row.readback_ms = timed->readback_ms;
  row.e2e_ms = row.upload_ms + row.frame_ms_median + row.readback_ms;
  const double per_frame_ms = row.gpu_ms_median.value_or(row.frame_ms_median);
  row.points_per_s = per_frame_ms > 0 ? static_cast<double>(row.points) / (per_frame_ms * 1e-3) : 0.0;
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
  std::vector<WindowPoint> probe(p.points.size());
  for (size_t i = 0; i < probe.size(); ++i) probe[i] = windowFromClip(probed->probe_clip[i], p.camera);
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
  std::string text = "max " + shortNumber(*row.error_max_px) + " px";
  if (row.points_lost) text += ", " + std::to_string(row.points_lost) + " lost";
  return text;
}

}  // namespace

Result<BenchRun> runBench(const VulkanContext& context, const BenchOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  BenchRun run;
  run.device = context.facts;
  for (BenchSuite suite : options.suites) {
    for (BenchCase& c : suiteCases(suite))
      if (keptBySizes(c, options.sizes)) run.cases.push_back(std::move(c));
  }
  std::error_code ec;
  std::filesystem::create_directories(options.cache_dir, ec);
  if (ec) return Error{"cannot create the dataset cache " + options.cache_dir + ": " + ec.message(), ExitCode::kBadInput};

  Result<SelfTest> self_test = runPrecisionSelfTest(context);
  if (!self_test) return self_test.error();
  const size_t total = run.cases.size() * options.backends.size() * kModeCount;
  size_t done = 0;
  for (const BenchCase& c : run.cases) {
    Result<Prepared> prepared = prepare(c, options);
    if (!prepared) return prepared.error();
    const Prepared& p = *prepared;
    const bool wants_montage = c.montage && !run.montage;
    const Backend montage_backend = std::find(options.backends.begin(), options.backends.end(), Backend::kCompute) !=
                                            options.backends.end() ? Backend::kCompute : options.backends.front();
    if (wants_montage) run.montage = MontageCapture{&c, montage_backend, p.reference, {}};
    for (Backend backend : options.backends) {
      for (size_t m = 0; m < kModeCount; ++m) {
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
        if (row.skipped.empty()) timeMode(context, p, options, row);
        const bool capture = wants_montage && backend == montage_backend;
        MontageMode shot;
        shot.mode = row.mode;
        if (row.skipped.empty()) {
          Result<Image> picture = measureMode(context, p, row, capture ? &shot.error_px : nullptr);
          if (picture) shot.picture = std::move(*picture);
          else row.skipped = picture.error().message;
        }
        if (capture) {
          shot.caption = montageCaption(row);
          run.montage->modes.push_back(std::move(shot));
        }
        ++done;
        if (options.log) {
          std::string line = '[' + std::to_string(done) + '/' + std::to_string(total) + "] " + std::string(suiteName(c.suite)) +
                             " " + c.name + ", " + backendText(backend) + " " + std::string(modeName(row.mode)) + ": ";
          if (!row.skipped.empty()) line += "skipped (" + row.skipped + ")";
          else {
            line += row.gpu_ms_median ? shortNumber(*row.gpu_ms_median) + " ms" : shortNumber(row.frame_ms_median) + " ms (host)";
            line += row.error_max_px ? ", max error " + shortNumber(*row.error_max_px) + " px" : ", every point lost";
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
