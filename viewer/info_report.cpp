#include "viewer/info_report.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <utility>

#include "converters/las_crs.h"
#include "converters/point_io.h"
#include "core/interrupt.h"
#include "core/parallel.h"
#include "core/json_writer.h"
#include "core/text.h"
#include "viewer/copc_view.h"
#include "viewer/modes.h"
#include "viewer/render.h"
#include "viewer/render_job.h"

namespace dpoint {
namespace {

// The box and planarity boundsOf gives, from the boxes of a streamed set's batches (non-empty).
Bounds boundsOfBoxes(const BatchBoxes& boxes) {
  Bounds bounds;
  bounds.min = boxes.boxes[0].min, bounds.max = boxes.boxes[0].max, bounds.planar = true;
  for (const Box& box : boxes.boxes) {
    bounds.min = glm::min(bounds.min, box.min), bounds.max = glm::max(bounds.max, box.max);
    bounds.planar = bounds.planar && box.min.z == 0.0 && box.max.z == 0.0;
  }
  return bounds;
}

std::string str(uint64_t v) { return std::to_string(v); }
std::string num(double v) { return formatNumber(v); }
std::string vec(const glm::dvec3& v) { return num(v.x) + " " + num(v.y) + " " + num(v.z); }
std::string jsonVec(const glm::dvec3& v) { return JsonValue::numbers(std::array<double, 3>{v.x, v.y, v.z}).text(); }
std::string jsonBool(bool v) { return v ? "true" : "false"; }

// `text` padded with spaces to `width` characters (printf's %-Ns).
std::string padded(std::string text, size_t width) {
  if (text.size() < width) text.append(width - text.size(), ' ');
  return text;
}

std::string viewName(const Camera& c) {
  return str(c.width) + "x" + str(c.height) + (c.ortho ? " orthographic" : " perspective");
}

std::string lasText(const LasFacts& las) {
  const LasHeader& h = las.header;
  return "LAS:                version " + std::to_string(h.version_major) + "." + std::to_string(h.version_minor) +
         ", point format " + std::to_string(h.point_format) + ", " + str(h.record_length) + "-byte records (" +
         str(h.record_length - lasBaseRecordLength(h.point_format)) + " extra bytes), " + str(h.point_count) +
         " points\n" +
         "LAS scale:          " + vec(h.scale) + "\n" +
         "LAS offset:         " + vec(h.offset) + "\n" +
         "LAS header bounds:  " + vec(h.min) + " .. " + vec(h.max) + " (" +
         (las.bounds_hold ? "hold the points" : "do not hold the points: the header is wrong, the points are used") +
         ")\n" +
         "LAS software:       " + h.generating_software + "\n" +
         "LAS CRS:            " + (las.crs.empty() ? "none (no coordinate system records)" : las.crs) + "\n";
}

// The "las" member, its value over four lines as `dpoint info --json` has always printed it.
std::string lasJson(const LasFacts& las) {
  const LasHeader& h = las.header;
  const std::string indent = ",\n          ";
  return ",\n  \"las\": {\"version\": \"" + std::to_string(h.version_major) + "." + std::to_string(h.version_minor) +
         "\", \"point_format\": " + std::to_string(h.point_format) + ", \"record_length\": " + str(h.record_length) +
         ", \"points\": " + str(h.point_count) + indent + "\"scale\": " + jsonVec(h.scale) +
         ", \"offset\": " + jsonVec(h.offset) + indent + "\"header_min\": " + jsonVec(h.min) +
         ", \"header_max\": " + jsonVec(h.max) + ", \"header_bounds_hold\": " + jsonBool(las.bounds_hold) + indent +
         "\"generating_software\": " + jsonString(h.generating_software) + ", \"crs\": " +
         (las.crs.empty() ? std::string("null") : jsonString(las.crs)) + "}";
}

std::string floatEnoughText(const InfoReport& report) {
  const PointSetInfo& i = report.info;
  if (i.float_overflow > 0) return "no (" + str(i.float_overflow) + " coordinates beyond float range)";
  if (report.streamed)
    return "not decided: a streamed set is read a block at a time, and finding the points\n"
           "                    float32 merges needs all of them at once (--stream off)";
  if (i.floatRepresents()) return "yes (no two distinct points merge)";
  if (i.float_merged == 1) return "no (1 distinct point merges with another)";
  return "no (" + str(i.float_merged) + " distinct points merge with another)";
}

std::string adviceText(const InfoAdvice& advice) {
  const ErrorBounds& b = advice.bounds;
  std::string text =
      b.from_boxes
          ? "error bound by mode, for the view (" + viewName(advice.camera) + ", at most " + str(b.visible) +
                " points visible; float floor " + formatBound(b.float_floor_px) +
                "), from the box of\n"
                "                    every 1024 points (a streamed set; its points give bounds no larger):\n"
          : "error bound by mode, for the view (" + viewName(advice.camera) + ", " + str(b.visible) +
                " points visible; float floor " + formatBound(b.float_floor_px) + "):\n";
  for (PrecisionMode mode : kAllModes) {
    const double px = b.px[modeIndex(mode)];
    const char* verdict = px <= kAutoBoundPx ? "within --mode auto's 0.1 px" : px < 0.5 ? "under half a pixel"
                                                                            : "points leave their pixel";
    text += "  " + padded(std::string(modeName(mode)), 8) + " " + padded(formatBound(px), 12) + " " + verdict + "\n";
  }
  if (!advice.camera.note.empty()) text += "view note:          " + advice.camera.note + "\n";
  return text;
}

std::string adviceJson(const InfoAdvice& advice) {
  const Camera& c = advice.camera;
  const ErrorBounds& b = advice.bounds;
  JsonObject view;
  view.add("width", JsonValue::integer(c.width)).add("height", JsonValue::integer(c.height));
  view.add("ortho", JsonValue::boolean(c.ortho)).add("points_visible", JsonValue::integer(b.visible));
  if (!c.note.empty()) view.add("note", JsonValue::string(c.note));
  JsonObject bounds;  // null: unbounded (the mode may lose points)
  for (PrecisionMode mode : kAllModes) bounds.add(modeName(mode), JsonValue::number(b.px[modeIndex(mode)]));
  return ",\n  \"view\": " + view.line() + ",\n  \"float_floor_px\": " + formatNumber(b.float_floor_px, true) +
         ",\n  \"error_bound_from\": \"" + (b.from_boxes ? "batch_boxes" : "points") +
         "\",\n  \"error_bound_px\": " + bounds.line();
}

// The request render would make of info's view options: its camera, --up-axis and, for auto's
// rule for surveys, the input paths (render_job's zUpFor and viewCameras then decide as for render).
RenderRequest viewRequest(const InfoOptions& options, const std::vector<std::string>& inputs = {}) {
  RenderRequest request;
  request.camera = options.camera;
  request.up_axis = !options.z_up ? UpAxis::kAuto : *options.z_up ? UpAxis::kZ : UpAxis::kY;
  request.inputs = inputs;
  return request;
}

// The one view `dpoint render` draws for the same options (a set in memory framed by its outline,
// boundsWithOutline, as render frames it), so the two print the same bounds.
Result<Camera> renderView(const InfoOptions& options, const Bounds& bounds, bool data_z_up) {
  const RenderRequest request = viewRequest(options);
  const bool z_up = zUpFor(request, data_z_up);
  Result<std::vector<Camera>> cameras = viewCameras(request, viewsFor(1, z_up), bounds, z_up);
  if (!cameras) return cameras.error();
  return cameras->front();
}

// `range` widened to hold the values of `d` (the same name and type), NaN passed over, on all
// cores: each chunk's first least and greatest value, then the chunks' in order, so the result is
// the one a single loop gives (-0 before +0 stays).
template <typename T>
void widenRangeOf(DimensionRange& range, const Dimension& d, unsigned threads) {
  constexpr size_t kChunk = size_t{1} << 16;
  const size_t n = d.size(), chunks = (n + kChunk - 1) / kChunk;
  std::vector<std::pair<double, double>> found(chunks, {HUGE_VAL, -HUGE_VAL});
  parallelFor(chunks, threads, [&](size_t c, unsigned) {
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (size_t i = c * kChunk, end = std::min(n, i + kChunk); i < end; ++i) {
      const double v = static_cast<double>(d.get<T>(i));
      if (v < lo) lo = v;
      if (v > hi) hi = v;
    }
    found[c] = {lo, hi};
  });
  for (const auto& [lo, hi] : found) {
    if (lo < range.min) range.min = lo;
    if (hi > range.max) range.max = hi;
  }
}

void widenRange(DimensionRange& range, const Dimension& d, unsigned threads) {
  switch (d.type) {
    case DimType::kU8: return widenRangeOf<uint8_t>(range, d, threads);
    case DimType::kI8: return widenRangeOf<int8_t>(range, d, threads);
    case DimType::kU16: return widenRangeOf<uint16_t>(range, d, threads);
    case DimType::kI16: return widenRangeOf<int16_t>(range, d, threads);
    case DimType::kU32: return widenRangeOf<uint32_t>(range, d, threads);
    case DimType::kI32: return widenRangeOf<int32_t>(range, d, threads);
    case DimType::kU64: return widenRangeOf<uint64_t>(range, d, threads);
    case DimType::kI64: return widenRangeOf<int64_t>(range, d, threads);
    case DimType::kF32: return widenRangeOf<float>(range, d, threads);
    case DimType::kF64: return widenRangeOf<double>(range, d, threads);
  }
}

// A point with a coordinate nan or inf (--allow-nonfinite) has no place in any mode's picture: every
// mode's bound is unbounded, read whole or streamed (the point passes and the boxes pass its
// coordinates over, and a mode's own checks see an inf but not a nan).
ErrorBounds unboundedWithNonfinite(ErrorBounds bounds, const PointSetInfo& info) {
  for (size_t m = 0; m < kModeCount && info.nonfinite > 0; ++m)
    if (bounds.computed[m]) bounds.px[m] = HUGE_VAL;
  return bounds;
}

// The report's advice for `dpoint render`'s view of `bounds`, each mode's bound by `predict`; where
// the data can have no view (their extent overflows a double: the camera's kBadInput), the report
// says why instead (a review finding: info refused to describe them). The options' errors fail it.
Status adviseFor(InfoReport& report, const InfoOptions& options, const Bounds& bounds, bool data_z_up,
                 const std::function<ErrorBounds(const Camera&)>& predict) {
  Result<Camera> camera = renderView(options, bounds, data_z_up);
  if (camera) report.advice = InfoAdvice{*camera, predict(*camera)};
  else if (camera.error().code == ExitCode::kBadInput) report.no_view = camera.error().message;
  else return camera.error();
  return okStatus();
}

}  // namespace

Result<InfoReport> describePoints(const PointSet& points, const std::string& name, const InfoOptions& options) {
  InfoReport report;
  report.name = name;
  // The text, which every writer takes over a LAS source's records, else theirs (a LAS file's own
  // are its LAS facts': describeFiles).
  report.crs = statedCrs(points).describe();
  report.info = computeInfo(points, options.sample, options.threads);
  if (interrupted()) return interruptedError();  // its search stops at Ctrl-C, leaving its figures unfinished
  for (const Dimension& d : points.dimensions.all()) {
    report.dimensions.push_back({d.name, d.type, HUGE_VAL, -HUGE_VAL});
    widenRange(report.dimensions.back(), d, options.threads);
  }
  // A point with a nan or inf coordinate (--allow-nonfinite) has no place in a view: the view
  // frames the others, as a stream's boxes pass it over (it framed an inf extent, 0 points visible).
  PointSet finite;
  if (report.info.nonfinite > 0) {
    finite.positions.reserve(points.size() - report.info.nonfinite);
    for (const glm::dvec3& p : points.positions)
      if (isFinite(p)) finite.positions.push_back(p);
  }
  const PointSet& framed = report.info.nonfinite > 0 ? finite : points;
  if (framed.size() > 0) {
    if (Status s = adviseFor(report, options, boundsWithOutline(framed), points.z_up, [&](const Camera& camera) {
          return unboundedWithNonfinite(predictErrorBounds(points, camera, {}, options.tolerance_px), report.info);
        });
        !s)
      return s.error();
  }
  return report;
}

// Each mode's bound from the box of every batch, kept as the first pass reads the blocks in order.
Result<InfoReport> describeStream(PointInputStream& stream, const std::string& name, const InfoOptions& options,
                                  Progress& progress) {
  // The first pass shows; the second reads again only what the nearest distances need.
  // The first pass brings the dimensions every file has too, for their ranges; the second reads
  // positions only.
  progress.start("reading " + name + " (points)", stream.count());
  uint64_t first_pass = 0;
  InfoReport report;
  const Dimensions common = stream.commonDimensions();
  for (const Dimension& d : common.all()) report.dimensions.push_back({d.name, d.type, HUGE_VAL, -HUGE_VAL});
  std::vector<std::string> names;
  if (options.stream_ranges)
    for (const DimensionRange& d : report.dimensions) names.push_back(d.name);
  if (Status s = stream.streamDimensions(names); !s) return s.error();
  bool dimensions_streamed = !names.empty();
  const BlockReader read = [&](uint64_t first, uint64_t n, PointSet& block) -> Status {
    if (interrupted()) return interruptedError();
    if (first != first_pass && dimensions_streamed) {
      if (Status s = stream.streamDimensions({}); !s) return s;
      dimensions_streamed = false;
    }
    if (Status s = stream.read(first, n, block); !s) return s;
    if (first == first_pass) {
      for (size_t k = 0; k < names.size(); ++k)  // none where the ranges are not read
        widenRange(report.dimensions[k], block.dimensions.all()[k], options.threads);
      first_pass += n;
      progress.advance(n);
    }
    return okStatus();
  };
  static_assert(kStreamBlockUnit % kStreamedInfoBoxPoints == 0 && kStreamedInfoBoxPoints == kBoxPoints,
                "the first pass's boxes are the batch boxes");
  Result<StreamedInfo> info = computeStreamedInfo(stream.count(), stream.hasColors(), stream.faceCount(), read,
                                                  options.stream_block ? options.stream_block : kStreamBlockPoints,
                                                  options.sample, options.threads);
  if (!info) return info.error();
  progress.finish();
  const BatchBoxes boxes{static_cast<size_t>(stream.count()), std::move(info->boxes)};
  report.name = name;
  report.info = info->info;
  report.streamed = true;
  // A point with a nan or inf coordinate has no place in a view: the finite points' box is framed,
  // as the set read whole frames them (a review finding: an inf framed an inf extent), and a set
  // of none has no view.
  Bounds framed = boxes.count > 0 ? boundsOfBoxes(boxes) : Bounds{};
  if (report.info.nonfinite > 0) {
    framed.min = info->finite.min, framed.max = info->finite.max;
    framed.planar = framed.min.z == 0.0 && framed.max.z == 0.0;
  }
  if (boxes.count > 0 && framed.min.x <= framed.max.x) {
    // Without the outline `dpoint render` reads again for its fit: the boxes' box is framed, so
    // render's bounds of a 3D set may be somewhat larger (a closer fit).
    if (Status s = adviseFor(report, options, framed, false, [&](const Camera& camera) {
          return unboundedWithNonfinite(predictBoxBounds(boxes, camera, {}, options.tolerance_px), report.info);
        });
        !s)
      return s.error();
  }
  return report;
}

// What a single LAS or LAZ file states beside its points, for the report: its header, whether its
// bounds hold the points `info` found, and its CRS records' summary. `vlrs` and `source` are the
// records and frame a whole read kept; null: read here from the file (a streamed read).
Result<std::optional<LasFacts>> lasFactsOf(const std::vector<std::string>& paths, const PointSetInfo& info,
                                           const LasSource* source) {
  const Result<FileFormat> format = paths.size() == 1 ? formatOf(paths[0]) : Result<FileFormat>(Error{""});
  if (!format || (*format != FileFormat::kLas && *format != FileFormat::kLaz)) return std::optional<LasFacts>();
  Result<LasHeader> header = readLasHeader(paths[0]);
  if (!header) return header.error();
  const bool bounds_hold = info.count == 0 || lasBoundsContain(*header, Box{info.min, info.max});
  std::string crs;
  if (source) {
    crs = lasCrsSummary(source->vlrs, lasSaysWkt(*source));
  } else {
    Result<InputFile> file = InputFile::open(paths[0]);
    if (!file) return file.error();
    Result<std::vector<LasVlr>> vlrs = readLasCrsRecords(*file);
    if (!vlrs) return vlrs.error();
    LasSource frame;
    frame.point_format = header->point_format;
    frame.global_encoding = header->global_encoding;
    crs = lasCrsSummary(*vlrs, lasSaysWkt(frame));
  }
  return std::optional<LasFacts>(LasFacts{std::move(*header), bounds_hold, std::move(crs)});
}

Result<InfoReport> describeFiles(const InfoInputs& inputs, const InfoOptions& options, Progress& progress) {
  if (inputs.paths.empty()) return Error{"info: no input files", ExitCode::kUsage};
  Result<std::unique_ptr<PointInputStream>> stream = openPointStream(inputs.paths, inputs.stream, options.threads, inputs.max_memory,
                                                                     inputs.allow_nonfinite);
  if (!stream) return stream.error();
  const std::string name = describeInputs(inputs.paths);
  if (*stream) {
    InfoOptions streamed = options;  // z up for survey files, as render's --up-axis auto takes them
    streamed.z_up = zUpFor(viewRequest(options, inputs.paths));
    uint64_t dimension_bytes = 0;  // the first pass's dimensions, a point
    const Dimensions common = (*stream)->commonDimensions();
    for (const Dimension& d : common.all()) dimension_bytes += dimTypeSize(d.type);
    Result<uint64_t> block = checkStreamMemory(name, (*stream)->count(), inputs.max_memory, kStreamPointBytes + dimension_bytes,
                                                (*stream)->heldBytes(), (*stream)->heldWhat());
    if (!block && block.error().code == ExitCode::kResourceLimit && dimension_bytes > 0) {
      // Their columns do not fit: the dimensions without their ranges, rather than no report (a
      // review finding: 300 extra bytes a point made info refuse a file it described read whole).
      block = checkStreamMemory(name, (*stream)->count(), inputs.max_memory, kStreamPointBytes, (*stream)->heldBytes(),
                                (*stream)->heldWhat());
      streamed.stream_ranges = false;
    }
    if (!block) return block.error();
    streamed.stream_block = *block;
    Result<InfoReport> report = describeStream(**stream, name, streamed, progress);
    if (!report) return report;
    report->notices = (*stream)->notices();
    // What the files state, as the whole read gives it (a set streamed had no CRS and no LAS header
    // facts before the build of 2026-12-02).
    report->crs = (*stream)->crs().describe();
    Result<std::optional<LasFacts>> las = lasFactsOf(inputs.paths, report->info, nullptr);
    if (!las) return las.error();
    report->las = std::move(*las);
    if (report->las && (*stream)->crs().text.empty()) report->crs.clear();  // its LAS CRS line says it
    if (!streamed.stream_ranges)
      report->notices.push_back(name + ": the dimensions' ranges not read: their " + std::to_string(dimension_bytes) +
                                " bytes a point do not fit --max-memory beside the blocks");
    return report;
  }
  std::vector<std::string> notices;
  ReadOptions read{options.threads, inputs.allow_nonfinite, &progress};
  read.max_memory = inputs.max_memory;
  read.notices = &notices;
  read.columns = inputs.columns;
  const bool scenes = inputs.scene >= 0 || inputs.all_scenes;
  if (scenes && inputs.paths.size() != 1)
    return Error{name + ": --scene and --all-scenes apply to one .glb/.gltf input", ExitCode::kUsage};
  GltfReadOptions gltf;
  gltf.scene = inputs.scene;
  gltf.all_scenes = inputs.all_scenes;
  std::optional<CopcReadStats> copc;
  Result<PointSet> points = PointSet{};
  if (inputs.paths.size() == 1 && readsAsCopc(inputs.paths[0]) && !scenes) {
    Result<CopcQuery> query = copcQueryFor(options.camera, inputs.paths[0], options.threads, inputs.max_memory);
    if (!query) return query.error();
    LasReadOptions las{options.threads, &progress, LasColorSource::kAuto, inputs.max_memory, &notices};
    copc.emplace();
    points = readCopcPoints(inputs.paths[0], *query, las, &*copc);
  } else {
    points = scenes ? readInput(inputs.paths[0], read, gltf) : readPointInputs(inputs.paths, read);
  }
  if (!points) return points.error();
  Result<InfoReport> report = describePoints(*points, name, options);
  if (!report) return report;
  report->copc = copc;
  report->notices = std::move(notices);
  const LasSource none;  // a LAS file read whole keeps its records; without them, none
  Result<std::optional<LasFacts>> las = lasFactsOf(inputs.paths, report->info, points->las ? &*points->las : &none);
  if (!las) return las.error();
  report->las = std::move(*las);
  if (report->las && points->crs.empty()) report->crs.clear();  // its LAS CRS line says it
  return report;
}

namespace {

std::string dimensionsJson(const std::vector<DimensionRange>& dimensions) {
  std::string json = "[";
  for (size_t k = 0; k < dimensions.size(); ++k) {
    const DimensionRange& d = dimensions[k];
    const bool any = d.min <= d.max;
    if (k) json += ", ";
    json += "{\"name\": ";
    json += jsonString(d.name);
    json += ", \"type\": ";
    json += jsonString(dimTypeName(d.type));
    json += ", \"min\": ";
    json += any ? formatNumber(d.min, true) : std::string("null");
    json += ", \"max\": ";
    json += any ? formatNumber(d.max, true) : std::string("null");
    json += "}";
  }
  return json + "]";
}

}  // namespace

namespace {

// A COPC file read by view: the points line says the count is of the points read.
std::string copcCount(const InfoReport& report) {
  if (!report.copc) return "";
  return " (read by view, of " + str(report.copc->file_points) + " in the file: COPC)";
}

}  // namespace

std::string infoReportText(const InfoReport& report) {
  const PointSetInfo& i = report.info;
  std::string text = "file:               " + report.name + "\n" +
                     "points:             " + str(i.count) + copcCount(report) + "\n" +
                     "triangles:          " + str(i.triangles) + "\n" +
                     "colours:            " + (i.has_colors ? "yes" : "no") + "\n";
  for (const DimensionRange& d : report.dimensions) {
    text += "dimension:          ";
    text += d.name;
    text += " (";
    text += dimTypeName(d.type);
    text += ")";
    if (d.min <= d.max) {
      text += ' ';
      text += num(d.min);
      text += " .. ";
      text += num(d.max);
    }
    text += "\n";
  }
  if (const std::optional<CopcReadStats>& c = report.copc)
    text += "copc:               the view read " + str(c->points) + " of " + str(c->file_points) + " points, " +
            str(c->bytes) + " of " + str(c->file_bytes) + " bytes (" + str(c->nodes) +
            " nodes); the facts below but the header's are of those points (--stream on reads all)\n";
  if (report.las) text += lasText(*report.las);
  if (!report.crs.empty()) {
    const std::string name = wktName(report.crs);
    text += "CRS:                " + (name.empty() ? oneLineText(report.crs, "") : name + " (WKT)") + "\n";
  }
  if (i.count == 0)
    return text + "bounds:             none (no points)\n" + "float32 enough:     nothing to hold (no points)\n";
  if (i.nonfinite > 0)
    text += "non-finite:         " + countOf(i.nonfinite, "point") + " with a coordinate nan or inf (--allow-nonfinite): " +
            "no mode can place them\n";
  text += "min:                " + vec(i.min) + "\n" +
          "max:                " + vec(i.max) + "\n" +
          "extent:             " + vec(i.extent) + "\n" +
          "largest |coord|:    " + num(i.max_abs) + "\n" +
          "float32 spacing:    " + num(i.float_spacing) + " (at the largest |coordinate|)\n" +
          "nearest neighbour:  " +
          (i.min_neighbor_distance > 0.0
               ? num(i.min_neighbor_distance) + " (smallest non-zero, " + str(i.neighbor_sample) + " points sampled)\n"
               : "none found (no two points apart, or none with finite distances, of " + str(i.neighbor_sample) +
                     " sampled)\n") +
          "float32 enough:     " + floatEnoughText(report) + "\n";
  if (report.advice) text += adviceText(*report.advice);
  if (!report.no_view.empty()) text += "view:               none: " + report.no_view + "\n";
  return text;
}

std::string infoReportJson(const InfoReport& report) {
  const PointSetInfo& i = report.info;
  // A streamed set: merged points not counted (null), and float32 undecided unless it overflows.
  const std::string represents = i.float_overflow > 0 ? "false"
                                 : report.streamed    ? "null"
                                                      : jsonBool(i.floatRepresents());
  std::string json = "{\n  \"file\": " + jsonString(report.name) +
                     ",\n  \"points\": " + str(i.count) +
                     ",\n  \"triangles\": " + str(i.triangles) +
                     ",\n  \"colors\": " + jsonBool(i.has_colors) +
                     ",\n  \"dimensions\": " + dimensionsJson(report.dimensions) +
                     ",\n  \"min\": " + (i.count ? jsonVec(i.min) : "null") +
                     ",\n  \"max\": " + (i.count ? jsonVec(i.max) : "null") +
                     ",\n  \"extent\": " + (i.count ? jsonVec(i.extent) : "null") +
                     ",\n  \"max_abs\": " + formatNumber(i.max_abs, true) +
                     ",\n  \"float32_spacing\": " + formatNumber(i.float_spacing, true) +
                     ",\n  \"min_neighbor_distance\": " + formatNumber(i.min_neighbor_distance, true) +
                     ",\n  \"neighbor_sample\": " + str(i.neighbor_sample) +
                     ",\n  \"streamed\": " + jsonBool(report.streamed) +
                     ",\n  \"float32_merged_points\": " + (report.streamed ? "null" : str(i.float_merged)) +
                     ",\n  \"float32_overflow\": " + str(i.float_overflow) +
                     ",\n  \"float32_represents\": " + represents +
                     ",\n  \"nonfinite_points\": " + str(i.nonfinite);
  if (const std::optional<CopcReadStats>& c = report.copc)
    json += ",\n  \"copc\": {\"points_read\": " + str(c->points) + ", \"bytes_read\": " + str(c->bytes) +
            ", \"nodes_read\": " + str(c->nodes) + ", \"file_points\": " + str(c->file_points) +
            ", \"file_bytes\": " + str(c->file_bytes) + "}";
  if (report.las) json += lasJson(*report.las);
  if (!report.crs.empty()) json += ",\n  \"crs\": " + jsonString(report.crs);
  if (report.advice) json += adviceJson(*report.advice);
  if (!report.no_view.empty()) json += ",\n  \"no_view\": " + jsonString(report.no_view);
  return json + "\n}\n";
}

}  // namespace dpoint
