// dpoint info FILE [--json]: counts, bounds and the precision the data needs.
#include <charconv>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

#include "cli/cli_camera.h"
#include "cli/cli_text.h"
#include "cli/commands.h"
#include "converters/point_inputs.h"
#include "ops/info.h"
#include "core/interrupt.h"
#include "viewer/precision.h"

namespace dpoint {
namespace {

struct InfoOptions {
  std::vector<std::string> inputs;
  bool json = false;
  bool allow_nonfinite = false;
  size_t sample = 10000;
  CameraCliOptions camera;
  std::string max_memory;
  std::string stream = "auto";
  CommonOptions common;
};

constexpr uint64_t kStreamBlockPoints = uint64_t{1} << 24;  // as render's

// Every mode's predicted error for one view (viewer/precision.h), as advice.
struct ViewAdvice {
  Camera camera;
  ErrorBounds bounds;
};

std::string viewName(const Camera& c) {
  return std::to_string(c.width) + "x" + std::to_string(c.height) + (c.ortho ? " orthographic" : " perspective");
}

std::string num(double v, bool json = false) { return formatNumber(v, json); }
std::string vec(const glm::dvec3& v) { return num(v.x) + " " + num(v.y) + " " + num(v.z); }
std::string jsonVec(const glm::dvec3& v) { return "[" + num(v.x, true) + ", " + num(v.y, true) + ", " + num(v.z, true) + "]"; }

// A LAS file's header (converters/las.h), and whether its bounds hold the points read.
struct LasFacts {
  LasHeader header;
  bool bounds_hold = true;
};

void printLasText(const LasFacts& las) {
  const LasHeader& h = las.header;
  std::printf("LAS:                version %d.%d, point format %d, %u-byte records (%u extra bytes), %llu points\n",
              h.version_major, h.version_minor, h.point_format, h.record_length,
              h.record_length - lasBaseRecordLength(h.point_format), static_cast<unsigned long long>(h.point_count));
  std::printf("LAS scale:          %s\n", vec(h.scale).c_str());
  std::printf("LAS offset:         %s\n", vec(h.offset).c_str());
  std::printf("LAS header bounds:  %s .. %s (%s)\n", vec(h.min).c_str(), vec(h.max).c_str(),
              las.bounds_hold ? "hold the points" : "do not hold the points: the header is wrong, the points are used");
  std::printf("LAS software:       %s\n", h.generating_software.c_str());
}

void printLasJson(const LasFacts& las) {
  const LasHeader& h = las.header;
  std::printf(",\n  \"las\": {\"version\": \"%d.%d\", \"point_format\": %d, \"record_length\": %u, \"points\": %llu,\n",
              h.version_major, h.version_minor, h.point_format, h.record_length,
              static_cast<unsigned long long>(h.point_count));
  std::printf("          \"scale\": %s, \"offset\": %s,\n", jsonVec(h.scale).c_str(), jsonVec(h.offset).c_str());
  std::printf("          \"header_min\": %s, \"header_max\": %s, \"header_bounds_hold\": %s,\n", jsonVec(h.min).c_str(),
              jsonVec(h.max).c_str(), las.bounds_hold ? "true" : "false");
  std::printf("          \"generating_software\": %s}", jsonString(h.generating_software).c_str());
}

// `merged`: whether float_merged was computed (not for a streamed set).
void printText(const std::string& path, const PointSetInfo& i, const std::optional<ViewAdvice>& advice,
               const std::optional<LasFacts>& las, bool merged) {
  std::printf("file:               %s\n", path.c_str());
  std::printf("points:             %zu\n", i.count);
  std::printf("triangles:          %zu\n", i.triangles);
  std::printf("colours:            %s\n", i.has_colors ? "yes" : "no");
  if (las) printLasText(*las);
  std::printf("min:                %s\n", vec(i.min).c_str());
  std::printf("max:                %s\n", vec(i.max).c_str());
  std::printf("extent:             %s\n", vec(i.extent).c_str());
  std::printf("largest |coord|:    %s\n", num(i.max_abs).c_str());
  std::printf("float32 spacing:    %s (at the largest |coordinate|)\n", num(i.float_spacing).c_str());
  std::printf("nearest neighbour:  %s (smallest non-zero, %zu points sampled)\n",
              num(i.min_neighbor_distance).c_str(), i.neighbor_sample);
  if (i.float_overflow > 0) {
    std::printf("float32 enough:     no (%zu coordinates beyond float range)\n", i.float_overflow);
  } else if (!merged) {
    std::printf("float32 enough:     not decided: a streamed set is read a block at a time, and finding the points\n"
                "                    float32 merges needs all of them at once (--stream off)\n");
  } else if (i.floatRepresents()) {
    std::printf("float32 enough:     yes (no two distinct points merge)\n");
  } else {
    std::printf("float32 enough:     no (%zu distinct points merge with another)\n", i.float_merged);
  }
  if (!advice) return;
  if (advice->bounds.from_boxes)
    std::printf("error bound by mode, for the view (%s, at most %zu points visible; float floor %s), from the box of\n"
                "                    each 4096-point batch (a streamed set; its points give bounds no larger):\n",
                viewName(advice->camera).c_str(), advice->bounds.visible, formatBound(advice->bounds.float_floor_px).c_str());
  else
    std::printf("error bound by mode, for the view (%s, %zu points visible; float floor %s):\n",
                viewName(advice->camera).c_str(), advice->bounds.visible, formatBound(advice->bounds.float_floor_px).c_str());
  for (PrecisionMode mode : kAllModes) {
    const double px = advice->bounds.px[modeIndex(mode)];
    const char* verdict = px <= kAutoBoundPx ? "within --mode auto's 0.1 px" : px < 0.5 ? "under half a pixel"
                                                                            : "points leave their pixel";
    std::printf("  %-8s %-12s %s\n", std::string(modeName(mode)).c_str(), formatBound(px).c_str(), verdict);
  }
}

void printJson(const std::string& path, const PointSetInfo& i, const std::optional<ViewAdvice>& advice,
               const std::optional<LasFacts>& las, bool merged) {
  std::printf("{\n");
  std::printf("  \"file\": %s,\n", jsonString(path).c_str());
  std::printf("  \"points\": %zu,\n  \"triangles\": %zu,\n  \"colors\": %s,\n", i.count, i.triangles,
              i.has_colors ? "true" : "false");
  std::printf("  \"min\": %s,\n  \"max\": %s,\n  \"extent\": %s,\n", jsonVec(i.min).c_str(), jsonVec(i.max).c_str(),
              jsonVec(i.extent).c_str());
  std::printf("  \"max_abs\": %s,\n  \"float32_spacing\": %s,\n", num(i.max_abs, true).c_str(),
              num(i.float_spacing, true).c_str());
  std::printf("  \"min_neighbor_distance\": %s,\n  \"neighbor_sample\": %zu,\n",
              num(i.min_neighbor_distance, true).c_str(), i.neighbor_sample);
  // A streamed set: merged points not counted (null), and float32 undecided unless it overflows.
  const std::string represents = i.float_overflow > 0 ? "false" : !merged ? "null" : i.floatRepresents() ? "true" : "false";
  std::printf("  \"streamed\": %s,\n", merged ? "false" : "true");
  std::printf("  \"float32_merged_points\": %s,\n  \"float32_overflow\": %zu,\n  \"float32_represents\": %s",
              merged ? std::to_string(i.float_merged).c_str() : "null", i.float_overflow, represents.c_str());
  if (las) printLasJson(*las);
  if (advice) {
    const Camera& c = advice->camera;
    std::printf(",\n  \"view\": {\"width\": %u, \"height\": %u, \"ortho\": %s, \"points_visible\": %zu},\n", c.width,
                c.height, c.ortho ? "true" : "false", advice->bounds.visible);
    std::printf("  \"float_floor_px\": %s,\n  \"error_bound_from\": \"%s\",\n  \"error_bound_px\": {",
                num(advice->bounds.float_floor_px, true).c_str(), advice->bounds.from_boxes ? "batch_boxes" : "points");
    const char* separator = "";
    for (PrecisionMode mode : kAllModes) {  // null: unbounded (the mode may lose points)
      const double px = advice->bounds.px[modeIndex(mode)];
      std::printf("%s\"%s\": %s", separator, std::string(modeName(mode)).c_str(),
                  std::isfinite(px) ? num(px, true).c_str() : "null");
      separator = ", ";
    }
    std::printf("}");
  }
  std::printf("\n}\n");
}

// Large binary PLY input (one file, or tiles) a block at a time: what computeStreamedInfo gives,
// and each mode's bound from the box of every batch, kept as the first pass reads the blocks in
// order (predictBoxBounds, as render predicts a streamed set's).
int runStreamedInfo(const InfoOptions& o, const CameraSpec& spec, PointInputStream& stream, Progress& progress) {
  progress.start("reading " + describeInputs(o.inputs) + " twice (points)", 2 * stream.count());
  BatchBoxes boxes;
  const BlockReader read = [&](uint64_t first, uint64_t n, PointSet& block) -> Status {
    if (interrupted()) return interruptedError();
    if (Status s = stream.read(first, n, block); !s) return s;
    if (first == boxes.count && n > 0) addBatchBoxes(boxes, block.positions);
    progress.advance(n);
    return okStatus();
  };
  Result<StreamedInfo> info = computeStreamedInfo(stream.count(), stream.hasColors(), stream.faceCount(), read,
                                                  kStreamBlockPoints, o.sample, o.common.threads);
  if (!info) return reportError(info.error());
  progress.finish();
  std::optional<ViewAdvice> advice;
  if (boxes.count > 0) {
    // boundsOf's box and planarity, from the batches' boxes.
    Bounds bounds;
    bounds.min = boxes.boxes[0].min, bounds.max = boxes.boxes[0].max, bounds.planar = true;
    for (const Box& box : boxes.boxes) {
      bounds.min = glm::min(bounds.min, box.min), bounds.max = glm::max(bounds.max, box.max);
      bounds.planar = bounds.planar && box.min.z == 0.0 && box.max.z == 0.0;
    }
    Result<Camera> camera = makeCamera(spec, bounds);
    if (!camera) return reportError(camera.error());
    advice = ViewAdvice{*camera, predictBoxBounds(boxes, *camera, {}, *parseTolerance(o.camera.tolerance))};
  }
  const std::string files = describeInputs(o.inputs);
  if (o.json) printJson(files, info->info, advice, std::nullopt, false);
  else printText(files, info->info, advice, std::nullopt, false);
  return 0;
}

int runInfo(const InfoOptions& o) {
  Progress progress(progressSink(o.common.quiet || o.json), "info");
  Result<uint64_t> limit = memoryLimitOf(o.max_memory);
  if (!limit) return reportError(limit.error());
  Result<CameraSpec> spec = cameraSpec(o.camera);
  if (!spec) return reportError(spec.error());
  Result<std::unique_ptr<PointInputStream>> stream = openPointStream(o.inputs, o.stream, o.common.threads);
  if (!stream) return reportError(stream.error());
  if (*stream) return runStreamedInfo(o, *spec, **stream, progress);
  ReadOptions read{o.common.threads, o.allow_nonfinite, &progress};
  read.max_memory = *limit;
  Result<PointSet> points = readPointInputs(o.inputs, read);
  if (!points) return reportError(points.error());
  const PointSetInfo info = computeInfo(*points, o.sample, o.common.threads);
  std::optional<LasFacts> las;
  // One LAS file: its header too.
  if (Result<FileFormat> format = formatOf(o.inputs[0]); o.inputs.size() == 1 && format && *format == FileFormat::kLas) {
    Result<LasHeader> header = readLasHeader(o.inputs[0]);
    if (!header) return reportError(header.error());
    las = LasFacts{*header, info.count == 0 || lasBoundsContain(*header, Box{info.min, info.max})};
  }
  std::optional<ViewAdvice> advice;
  if (points->size() > 0) {
    Result<Camera> camera = makeCamera(*spec, boundsOf(*points));
    if (!camera) return reportError(camera.error());
    advice = ViewAdvice{*camera, predictErrorBounds(*points, *camera, {}, *parseTolerance(o.camera.tolerance))};
  }
  const std::string files = describeInputs(o.inputs);
  if (o.json) printJson(files, info, advice, las, true);
  else printText(files, info, advice, las, true);
  return 0;
}

}  // namespace

void addInfoCommand(CLI::App& app, RunCommand& run) {
  auto o = std::make_shared<InfoOptions>();
  CLI::App* cmd = app.add_subcommand(
      "info",
      "Counts, bounds, whether float32 can hold the data, and each render mode's predicted error in pixels for a\n"
      "view: the --fit view by default, or the one the camera options (as for `dpoint render`) describe");
  cmd->add_option("input", o->inputs,
                  "Input files (.csv, .ply, .las, .glb, .gltf), taken as one set; the N tiles of `generate --tile`\n"
                  "as the whole. Large binary PLY input is streamed (--stream)")
      ->required();
  cmd->add_flag("--json", o->json, "Print JSON instead of text");
  cmd->add_option("--sample", o->sample, "Points sampled for the nearest-neighbour distance")
      ->default_val(10000)
      ->check(CLI::Range(size_t{1}, size_t{100000000}));
  cmd->add_flag("--allow-nonfinite", o->allow_nonfinite, "Accept nan/inf coordinates instead of rejecting them");
  addCameraOptions(*cmd, o->camera);
  addMaxMemoryOption(*cmd, o->max_memory);
  cmd->add_option("--stream", o->stream,
                  "auto|on|off. on: read binary PLY input (a file, or tiles) a block at a time, twice, so a set\n"
                  "larger than memory is described in about 1.2 GB (no float32 merge count, which needs every point\n"
                  "at once, and error bounds from the box of each 4096-point batch); auto: for binary PLY input of\n"
                  "more than 2^26 points")
      ->check(CLI::IsMember({"auto", "on", "off"}))
      ->default_val("auto");
  addCommonOptions(*cmd, o->common);
  cmd->callback([o, &run] { run = [o] { return runInfo(*o); }; });
}

}  // namespace dpoint
