#include "viewer/render_job.h"

#include <sys/resource.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <future>
#include <memory>

#include "converters/point_inputs.h"
#include "converters/point_io.h"
#include "core/atomic_file.h"
#include "core/interrupt.h"
#include "core/json_writer.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "core/text.h"
#include "image/canvas.h"
#include "ops/attribute_colors.h"
#include "ops/mesh_sample.h"
#include "ops/point_filters.h"
#include "viewer/copc_view.h"
#include "viewer/reference.h"

namespace dpoint {
namespace {

// `path` ends with `extension` (lower case, with its dot), in any case.
bool hasExtension(const std::string& path, const std::string& extension) {
  if (path.size() < extension.size()) return false;
  return lowerAscii(path.substr(path.size() - extension.size())) == extension;
}

// The input as the run draws it: in memory, or a stream read a block at a time (a binary PLY
// larger than memory), with what every view shares.
// Points sampled for their nearest neighbour's distance (the default point size): enough for a
// steady median, few enough that the search costs ~10 ms on 1.55M points.
constexpr size_t kSpacingSamples = 512;
// A 3D set's point size as a share of its projected spacing (pointSizeFor): a round point's disc
// (inscribed in its square) a little wider than the spacing, so neighbouring discs overlap and the
// nearest centre wins between them; a square one as wide as the spacing. At 0.65 of it (square) the
// res-200 Mandelbulb at 1024x768 showed the points of its inner shells through the gaps as hollow
// squares (1.9% of the surface's pixels; bench/results/2026-11-28/cpu/default_pictures.md).
constexpr double kRoundShare = 1.3, kSquareShare = 1.0;
// The most point pixels a default size draws, in pictures' worth: a sparse set's points grow up to
// their spacing (a survey of 1,065 points reads as a surface), a dense set's stay at most 8 px.
constexpr double kPointPixelBudget = 32.0;
// The share of the picture's smaller side the fit leaves free on both sides together.
constexpr double kFitMarginShare = 1.0 - 1.0 / kFitMargin;

struct LoadedSet {
  std::string inputs;  // describeInputs: for messages
  std::optional<PointSet> owned;           // read here, or a copy of the request's set to colour or order
  std::shared_ptr<const PointSet> shared;  // else the request's own set (RenderRequest::points)
  // The request's own set may hold a non-finite position (Python's allow_nonfinite), which its box
  // (glm::min and max pass a NaN over) does not show: predictMode checks before it trusts the box.
  // A set read here is finite (the readers refuse the rest).
  bool finite_unknown = false;
  // The set in memory; null: a stream.
  const PointSet* points() const { return owned ? &*owned : shared.get(); }
  std::unique_ptr<PointInputStream> stream;
  uint64_t stream_block = kStreamBlockPoints;  // a stream's points a block (streamBlockPoints)
  uint64_t stream_point_bytes = kStreamPointBytes;  // a stream's host bytes a point in a block
  size_t count = 0;
  Bounds bounds;
  bool has_colors = false;
  bool elevation = false;  // coloured by elevation along the up axis (a stream: block by block)
  std::optional<AttributeColoring> coloring;  // coloured by a dimension (--color NAME): the legend's plan
  bool z_up = false;
  std::vector<SpacingSample> spacing;  // for the default point size
  BatchBoxes boxes;                    // a stream: the box of each batch, for its mode's bound
  uint64_t reread_points = 0;          // a stream: the points its outline and spacing read again
  std::vector<std::string> notices;    // what the readers read past (ReadOptions::notices)
  size_t stream_notices = 0;           // a stream: how many of its notices came with its headers
  // A stream drawn in one pass (renderOnce): its bounds, outline and spacing come with the upload,
  // its provisional camera and mode from `preview`, whole batches spread over the file.
  bool one_pass = false;
  PointSet preview;
  BatchBoxes preview_boxes;
  std::optional<CopcReadStats> copc;   // a COPC input: what its view read
  double surface_spacing = 0.0;        // a sampled mesh surface: its samples' mean spacing (world units)
  MeshTexture texture;                 // a glTF mesh's base-colour textures, for its surface's colours
};

// A view the data cannot have (their extent overflows a double) names the inputs, as every error
// of bad input does (a review finding: "the view inf wide ..." named no file); the options' own
// errors stand as they are.
Error viewErrorOf(const LoadedSet& set, Error error) {
  if (error.code == ExitCode::kBadInput) error.message = set.inputs + ": " + error.message;
  return error;
}

// One pass over a streamed set, `points` a block, showing `what` as progress.
Status forEachBlock(PointInputStream& ply, uint64_t points, Progress& progress, const std::string& what,
                    const std::function<void(const PointSet& block)>& visit) {
  PointSet block;
  progress.start(what, ply.count());
  for (uint64_t first = 0; first < ply.count(); first += points) {
    const uint64_t n = std::min(points, ply.count() - first);
    if (interrupted()) return interruptedError();
    if (Status status = ply.read(first, n, block); !status) return status;
    progress.advance(n);
    visit(block);
  }
  progress.finish();
  return okStatus();
}

// What the bounds pass gathers of a streamed set's next block: its bounds and planarity, the box
// of every batch (the mode's bound is predicted from those once the camera is known:
// predictBoxBounds) and the spacing samples. `bounds` starts as noBounds().
Bounds noBounds() { return Bounds{glm::dvec3(HUGE_VAL), glm::dvec3(-HUGE_VAL), true, {}}; }
void gatherBlock(const PointSet& block, Bounds& bounds, BatchBoxes& boxes, SpacingSampler& sampler) {
  const size_t first = boxes.boxes.size();
  addBatchBoxes(boxes, block.positions);
  for (size_t b = first; b < boxes.boxes.size(); ++b)
    bounds.min = glm::min(bounds.min, boxes.boxes[b].min), bounds.max = glm::max(bounds.max, boxes.boxes[b].max);
  bounds.planar = bounds.planar && block.isPlanar();
  sampler.add(block.positions);
}

// The bounds pass on its own: every block gathered.
Result<Bounds> streamBounds(const std::string& path, PointInputStream& ply, uint64_t points, Progress& progress,
                            SpacingSampler& sampler, BatchBoxes& boxes) {
  Bounds bounds = noBounds();
  Status status = forEachBlock(ply, points, progress, "bounds of " + path + " (points)",
                               [&](const PointSet& block) { gatherBlock(block, bounds, boxes, sampler); });
  if (!status) return status.error();
  return bounds;
}

// Colours by elevation: asked for, or (auto) a 3D set without colours; a 2D set's points stay white.
bool wantsElevation(const RenderRequest& request, bool has_colors, const Bounds& bounds) {
  return request.color == RenderColor::kElevation ||
         (request.color == RenderColor::kAuto && !has_colors && !bounds.planar);
}

// A perspective fit of a 3D set frames its outline (viewer/camera.h); the ortho fit and a camera the
// user placed do not need it, so a streamed set is read a second time only when it is used.
bool needsOutline(const RenderRequest& request, const Bounds& bounds) {
  const CameraSpec& spec = request.camera;
  return !bounds.planar && !spec.eye && !spec.ortho.value_or(false);
}

// Whether the default point size is wanted, which samples the set's spacing.
bool needsSpacing(const RenderRequest& request) { return !request.point_size && !request.error; }

// The outline and the spacing samples of a streamed set, as needed (the same as the set in memory
// gets, whatever the block size and order): a second pass, which reads only the batches whose box
// (set.boxes) leaves their share open: a box in one outline row gives that row its corners, and a box
// clear of every cell the spacing search keeps holds no point it uses. A file in Morton order is
// read again in a few places; one in scan order, whose boxes are long, all through.
Status streamOutlineAndSpacing(const RenderRequest& request, const std::string& path, PointInputStream& ply,
                               PositionArray samples, LoadedSet& set, Progress& progress) {
  const bool outline = needsOutline(request, set.bounds), spacing = needsSpacing(request);
  if (!outline && !spacing) return okStatus();
  OutlineBuilder builder(set.bounds);
  SpacingSearch search(Box{set.bounds.min, set.bounds.max}, set.count, std::move(samples), request.threads);
  const std::vector<Box>& boxes = set.boxes.boxes;
  std::vector<uint8_t> needed(boxes.size(), 0);
  parallelFor(boxes.size(), request.threads, [&](size_t k, unsigned) {
    needed[k] = spacing && search.mayUse(boxes[k]);
  });
  for (size_t k = 0; k < boxes.size(); ++k)  // the builder's rows are one table: one thread
    if (outline && !builder.addBox(boxes[k])) needed[k] = 1;
  // Runs of needed boxes, joined across short gaps (a read's fixed cost against the points skipped).
  constexpr size_t kGapBoxes = 16;
  std::vector<std::pair<uint64_t, uint64_t>> runs;  // points [first, end)
  for (size_t k = 0; k < boxes.size(); ++k) {
    if (!needed[k]) continue;
    const uint64_t first = uint64_t{k} * kBoxPoints, end = std::min<uint64_t>(set.count, first + kBoxPoints);
    if (!runs.empty() && first - runs.back().second <= kGapBoxes * kBoxPoints) runs.back().second = end;
    else runs.push_back({first, end});
  }
  uint64_t reread = 0;
  for (const auto& run : runs) reread += run.second - run.first;
  set.reread_points = reread;
  const std::string what = std::string(outline ? "outline" : "spacing") + " of " + path + " (points read again)";
  progress.start(what, reread);
  PointSet block;
  for (const auto& [from, end] : runs)
    for (uint64_t first = from; first < end; first += set.stream_block) {
      const uint64_t n = std::min(set.stream_block, end - first);
      if (interrupted()) return interruptedError();
      if (Status status = ply.read(first, n, block); !status) return status;
      progress.advance(n);
      if (outline) builder.add(block.positions);
      if (spacing) search.add(block.positions);
    }
  progress.finish();
  if (outline) set.bounds.outline = builder.finish();
  if (spacing) set.spacing = search.finish();
  return okStatus();
}

// The LAS colours to read: none where a colour map replaces them.
LasColorSource lasColorOf(RenderColor color) {
  return color == RenderColor::kElevation || color == RenderColor::kAttribute ? LasColorSource::kNone
                                                                              : LasColorSource::kAuto;
}

// --color NAME of a set without that dimension: a usage error listing those it has.
Error noSuchAttribute(const std::string& inputs, const std::string& name, const Dimensions& dimensions) {
  std::string has;
  for (const Dimension& d : dimensions.all()) {
    has += has.empty() ? "" : ", ";
    has += d.name;
  }
  std::string message = "--color " + name + ": " + inputs + " has no dimension '" + name + "' (";
  message += has.empty() ? std::string("it has none; --color takes auto, rgb, elevation or a dimension)") : "it has " + has + ")";
  return Error{std::move(message), ExitCode::kUsage};
}

// The request's set in memory (RenderRequest::points), drawn as it is: nothing is read.
Result<LoadedSet> takeInMemory(const RenderRequest& request) {
  LoadedSet set;
  set.inputs = request.inputs.empty() ? std::string("points") : describeInputs(request.inputs);
  set.shared = request.points;
  set.finite_unknown = true;
  return set;
}

// Whether every coordinate of the set is finite, on all cores.
bool allPositionsFinite(const PointSet& points, unsigned threads) {
  constexpr size_t kBlock = size_t{1} << 16;
  const size_t blocks = (points.size() + kBlock - 1) / kBlock;
  std::vector<char> finite(blocks, 1);
  parallelFor(blocks, threads, [&](size_t b, unsigned) {
    // x − x is 0 for a finite x and NaN for NaN or ±inf: a sum with no branch, in vector lanes.
    double sum = 0.0;
    for (size_t i = b * kBlock, end = std::min(points.size(), i + kBlock); i < end; ++i) {
      const glm::dvec3& p = points.positions[i];
      sum += (p.x - p.x) + (p.y - p.y) + (p.z - p.z);
    }
    finite[b] = sum == 0.0;
  });
  return std::all_of(finite.begin(), finite.end(), [](char f) { return f != 0; });
}

// Whole batches of a stream spread evenly over it, for a one-pass render's provisional camera and
// mode: kPreviewRuns runs of one batch-mode batch (4096 points) each, their boxes kept as batch
// boxes (predictBoxBounds), or the whole stream when it is no larger.
constexpr uint64_t kPreviewRuns = 64, kPreviewRunPoints = kBatchSize;
Status readPreview(PointInputStream& stream, LoadedSet& set) {
  const uint64_t n = stream.count(), boxes = (n + kBoxPoints - 1) / kBoxPoints;
  const uint64_t run_boxes = kPreviewRunPoints / kBoxPoints;
  PointSet block;
  PointSet& preview = set.preview;
  const auto add = [&](uint64_t first, uint64_t count) -> Status {
    if (Status status = stream.read(first, count, block); !status) return status;
    preview.positions.insert(preview.positions.end(), block.positions.begin(), block.positions.end());
    preview.z_axis = block.z_axis;
    addBatchBoxes(set.preview_boxes, block.positions);
    return okStatus();
  };
  if (boxes <= kPreviewRuns * run_boxes) return add(0, n);
  for (uint64_t k = 0; k < kPreviewRuns; ++k) {
    const uint64_t first = k * ((boxes - run_boxes) / run_boxes) / (kPreviewRuns - 1) * kPreviewRunPoints;
    if (Status status = add(first, std::min(kPreviewRunPoints, n - first)); !status) return status;
  }
  return okStatus();
}

// Opens the input as a stream (large binary PLY, LAS, LAZ or E57), reads a COPC file's view, or reads
// it whole.
Result<LoadedSet> readInput(const RenderRequest& request, Progress& progress, RenderPhases& phases) {
  LoadedSet set;
  set.inputs = describeInputs(request.inputs);
  const std::string& inputs = set.inputs;
  if (request.inputs.size() == 1 && readsAsCopc(request.inputs[0]) && request.stream != "on") {
    Result<CopcQuery> query = copcQueryFor(request.camera, request.inputs[0], request.threads, request.max_memory);
    if (!query) return query.error();
    LasReadOptions las{request.threads, &progress, lasColorOf(request.color), request.max_memory, &set.notices};
    CopcReadStats stats;
    Result<PointSet> read = readCopcPoints(request.inputs[0], *query, las, &stats);
    if (!read) return read.error();
    if (request.color == RenderColor::kAttribute && !read->dimensions.find(request.color_attribute))
      return noSuchAttribute(inputs, request.color_attribute, read->dimensions);
    set.owned = std::move(*read);
    set.copc = stats;
    phases.mark("read");
    return set;
  }
  Result<std::unique_ptr<PointInputStream>> opened = openPointStream(request.inputs, request.stream, request.threads, request.max_memory);
  if (!opened) return opened.error();
  set.stream = std::move(*opened);
  PointInputStream* ply = set.stream.get();
  if (ply) set.notices = ply->notices(), set.stream_notices = ply->notices().size();
  if (ply && request.color == RenderColor::kAttribute && !ply->dimensions().find(request.color_attribute))
    return noSuchAttribute(inputs, request.color_attribute, ply->dimensions());
  if (ply && (request.error || request.order != PointOrder::kInput || request.views != 1))
    return Error{inputs + ": a streamed set (" + std::to_string(ply->count()) + " points) is read once: "
                 "--error, --order morton and --views 4 need it in memory (--stream off)", ExitCode::kUsage};
  // A mesh's surface is sampled in memory: asked for on a stream, it is refused (it was drawn as
  // its vertices without a word).
  if (ply && request.surface == SurfaceChoice::kOn && ply->faceCount() > 0)
    return Error{inputs + ": a streamed mesh (" + std::to_string(ply->count()) + " vertices) is drawn as its "
                 "vertices: --surface on samples its surface in memory (--stream off)", ExitCode::kUsage};
  if (ply) {
    if (ply->count() == 0) return Error{inputs + ": no points to render", ExitCode::kBadInput};
    // --max-memory bounds a stream too (a review finding: 50M let a 5M-point stream peak at 590 MB).
    // --color NAME reads the dimension with every block: at most 8 bytes a point.
    const uint64_t point_bytes = kStreamPointBytes + (request.color == RenderColor::kAttribute ? sizeof(double) : 0);
    Result<uint64_t> stream_block = checkStreamMemory(inputs, ply->count(), request.max_memory, point_bytes, ply->heldBytes(),
                                                      ply->heldWhat());
    if (!stream_block) return stream_block.error();
    set.stream_block = *stream_block;
    set.stream_point_bytes = point_bytes;
    set.count = ply->count(), set.has_colors = ply->hasColors();
    if (request.color == RenderColor::kAuto || request.color == RenderColor::kRgb) {
      if (Status s = readPreview(*ply, set); !s) return s.error();
      // One pass where the colours do not wait for the bounds: the file's own, or none on a 2D
      // set (a 3D one without colours is coloured by elevation, which needs its extent first).
      set.one_pass = set.has_colors || request.color == RenderColor::kRgb || set.preview.isPlanar();
      phases.mark("preview");
      if (set.one_pass) return set;
    }
    SpacingSampler sampler(needsSpacing(request) ? kSpacingSamples : 0, request.threads);
    Result<Bounds> bounds = streamBounds(inputs, *ply, set.stream_block, progress, sampler, set.boxes);
    if (!bounds) return bounds.error();
    set.bounds = *bounds;
    if (Status s = streamOutlineAndSpacing(request, inputs, *ply, sampler.finish(), set, progress); !s) return s.error();
    phases.mark("bounds");
    if (request.color == RenderColor::kAttribute) {  // one more pass: the dimension's classes or percentiles
      const std::string& name = request.color_attribute;
      if (Status s = ply->streamDimensions({name}); !s) return Error{inputs + ": --color " + name + ": " + s.error().message, ExitCode::kUsage};
      AttributeSampler values(name, ply->dimensions().find(name)->type, ply->count());
      Status s = forEachBlock(*ply, set.stream_block, progress, "values of " + name + " in " + inputs + " (points)",
                              [&](const PointSet& block) { values.add(block.dimensions.all().front()); });
      if (!s) return s.error();
      set.coloring = values.finish();
      set.has_colors = true;
      phases.mark("colour");
    }
    return set;
  }
  // A mesh PLY is read with its faces when its surface may be drawn: asked for, or (auto) with few
  // enough vertices that they may lie far apart on screen (a 16th of the pixels; its header says).
  // Several PLY inputs (a complete tile set, whose parts are welded into the whole, or meshes side
  // by side) are one mesh as well: their counts add up.
  const bool may_sample = request.surface != SurfaceChoice::kOff;
  bool points_only = true;
  if (may_sample) {
    uint64_t vertices = 0, faces = 0;
    bool plys = true;
    for (const std::string& input : request.inputs) {
      Result<FileFormat> format = formatOf(input);
      Result<std::unique_ptr<PlyVertexStream>> header =
          format && *format == FileFormat::kPly ? PlyVertexStream::open(input) : Error{"not a PLY"};
      if (!header) {
        plys = false;
        break;
      }
      vertices += (*header)->count(), faces += (*header)->faceCount();
    }
    points_only = !plys || faces == 0 ||
                  (request.surface == SurfaceChoice::kAuto &&
                   vertices >= uint64_t{request.camera.width} * request.camera.height / 16);
  }
  ReadOptions read_options{request.threads, false, &progress, points_only};
  read_options.max_memory = request.max_memory;
  read_options.notices = &set.notices;
  read_options.las_color = lasColorOf(request.color);
  read_options.columns = request.columns;
  if (may_sample && request.inputs.size() == 1) read_options.texture = &set.texture;  // its samples take its texture
  Result<PointSet> read = readPointInputs(request.inputs, read_options);
  if (!read) return read.error();
  set.owned = std::move(*read);
  phases.mark("read");
  return set;
}

// A mesh drawn as its surface: points sampled on its triangles replace its vertices (the request's
// own set stays as it is).
Status sampleMeshSurface(const RenderRequest& request, LoadedSet& set, Progress& progress, RenderPhases& phases) {
  const PointSet& mesh = *set.points();
  if (!mesh.isMesh() || request.surface == SurfaceChoice::kOff) return okStatus();
  const uint64_t count = meshSurfaceSamples(request.surface, mesh, request.camera.width, request.camera.height);
  if (count == 0) return okStatus();
  set.surface_spacing = std::sqrt(surfaceArea(mesh) / static_cast<double>(count));
  SampleOptions options;
  options.count = count;
  options.method = SampleMethod::kStratified;  // no clumps and holes for the far side to show through
  options.threads = request.threads;
  options.max_memory = request.max_memory;
  options.progress = &progress;
  options.texture = &set.texture;
  Result<PointSet> sample = sampleSurface(mesh, options, set.inputs);
  if (!sample) return sample.error();
  set.owned = std::move(*sample);
  set.shared.reset();
  phases.mark("surface");
  return okStatus();
}

// The input, read, streamed or the request's own; its bounds, colours and order.
Result<LoadedSet> loadInput(const RenderRequest& request, Progress& progress, RenderPhases& phases) {
  Result<LoadedSet> loaded = request.points ? takeInMemory(request) : readInput(request, progress, phases);
  if (!loaded) return loaded.error();
  LoadedSet& set = *loaded;
  const std::string& inputs = set.inputs;
  if (set.points()) {
    if (set.points()->size() == 0) return Error{inputs + ": no points to render", ExitCode::kBadInput};
    if (Status s = sampleMeshSurface(request, set, progress, phases); !s) return s.error();
    set.count = set.points()->size(), set.has_colors = set.points()->hasColors();
  }
  if (request.color == RenderColor::kRgb && !set.has_colors)
    return Error{inputs + ": --color rgb: the set has no colours (try --color elevation)", ExitCode::kBadInput};
  set.z_up = zUpFor(request, set.points() && set.points()->z_up);
  // The outline lets a perspective fit frame the data rather than its box's empty corners.
  if (set.points()) set.bounds = boundsWithOutline(*set.points());
  if (set.points() && needsSpacing(request)) {
    set.spacing = sampleSpacing(set.points()->positions, Box{set.bounds.min, set.bounds.max}, kSpacingSamples, request.threads);
    phases.mark("spacing");
  }
  // A stream in one pass has no bounds yet, and one whose colours need them is not read so.
  set.elevation = !set.one_pass && wantsElevation(request, set.has_colors, set.bounds);
  if (request.color == RenderColor::kAttribute && set.points()) {
    const Dimension* d = set.points()->dimensions.find(request.color_attribute);
    if (!d) return noSuchAttribute(inputs, request.color_attribute, set.points()->dimensions);
    set.coloring = planAttributeColoring(*d);
    set.has_colors = true;
  }
  if (set.points()) {
    if (set.elevation || set.coloring || request.order != PointOrder::kInput) {
      if (!set.owned) set.owned = *set.shared;  // the request's own set stays as it is
      if (set.elevation) colorByElevation(*set.owned, set.z_up ? 2 : 1, request.threads);
      if (set.coloring) {
        PointSet& s = *set.owned;
        s.colors.resize(s.size());
        colorByAttribute(*s.dimensions.find(request.color_attribute), 0, s.size(), *set.coloring, s.colors.data(),
                         request.threads);
        phases.mark("colour");
      }
      reorderPoints(*set.owned, request.order, request.threads, &progress);
    }
    phases.mark("order");
  }
  return std::move(set);
}

// What --mode auto minimises for this request: one picture's time, or its frames (--frames N).
AutoTarget autoTargetOf(const RenderRequest& request, uint64_t points) {
  AutoTarget target;
  target.points = points;
  target.threads = request.threads;
  target.frames = request.frames;
  return target;
}

// --mode auto picks on the device; an explicit mode gets its bound computed for the report. From
// the points of a set in memory, or the batch boxes of a streamed one (set.boxes).
Result<ModePrediction> predictMode(const RenderRequest& request, const VulkanContext& context, const LoadedSet& set,
                                   const Camera& camera) {
  const double tolerance = request.tolerance_px;
  auto choose = [&]() -> Result<ModeChoice> {
    const AutoTarget target = autoTargetOf(request, set.count);
    if (set.points()) {
      // The box stands for the points (their bounds and position checks) only where it holds
      // every coordinate: not past a NaN.
      std::optional<Box> box;
      if (!set.finite_unknown || allPositionsFinite(*set.points(), request.threads)) box = Box{set.bounds.min, set.bounds.max};
      return chooseModeOnDevice(context, *set.points(), camera, *request.backend, request.error, tolerance, target, box);
    }
    return chooseModeOnDevice(context, set.boxes, camera, *request.backend, tolerance, target);
  };
  ModePrediction p;
  p.from_boxes = !set.points();
  if (request.mode != "auto") {
    p.mode = *parseMode(request.mode);
    const PrecisionMode one[] = {p.mode};
    ErrorBounds bounds = set.points() ? predictErrorBounds(*set.points(), camera, one, tolerance)
                                    : predictBoxBounds(set.boxes, camera, one, tolerance);
    p.bound_px = bounds.px[modeIndex(p.mode)];
    p.encoding = std::move(bounds.encodings[modeIndex(p.mode)]);
    if (!(p.bound_px <= kWrongBoundPx)) {  // a wrong picture: name the mode auto would take
      Result<ModeChoice> choice = choose();
      if (!choice) return choice.error();
      p.warning = predictionWarning(request, p, choice->mode);
    }
    return p;
  }
  Result<ModeChoice> choice = choose();
  if (!choice) return choice.error();
  p.mode = choice->mode;
  p.bound_px = choice->bound_px;
  p.encoding = choice->encoding();
  p.choice = std::move(*choice);
  p.warning = predictionWarning(request, p, std::nullopt);
  return p;
}

// --warmup as RenderOptions' two fields: a count of frames, or one frame and then by time.
void setWarmup(const WarmupRequest& warmup, uint32_t frames, RenderOptions& options) {
  using Kind = WarmupRequest::Kind;
  const double ms = warmup.kind == Kind::kTime ? warmup.ms : warmup.kind == Kind::kAuto && frames > 1 ? kAutoWarmupMs : 0.0;
  options.warmup_frames = warmup.kind == Kind::kFrames ? warmup.frames : ms > 0.0 ? 1 : 0;
  options.warmup_ms = ms;
}

// A sampled surface's points on screen: twice their spacing where the surface comes nearest
// the eye, so that they close it there too (at the fit's scale, a perspective view magnifies the
// nearest corner of a box 1.5 times: sized for the middle, the far side showed through it).
float surfacePointPx(const LoadedSet& set, const Camera& camera) {
  if (!(set.surface_spacing > 0.0) || !set.points()) return 0.0f;
  const glm::dmat4 view_projection = camera.viewProjection();
  const glm::dvec3 forward = -glm::dvec3(camera.rotation[0][2], camera.rotation[1][2], camera.rotation[2][2]);
  const glm::dvec3 right(camera.rotation[0][0], camera.rotation[1][0], camera.rotation[2][0]);
  // The sample nearest the eye along the view, in front of the near plane (any one for ortho).
  glm::dvec3 nearest = set.points()->positions.front();
  double depth = std::numeric_limits<double>::infinity();
  if (!camera.ortho)
    for (const glm::dvec3& p : set.points()->positions) {
      const double d = glm::dot(p - camera.eye, forward);
      if (d >= camera.near_plane && d < depth) depth = d, nearest = p;
    }
  const auto pixel = [&](const glm::dvec3& p) {
    const glm::dvec4 clip = view_projection * glm::dvec4(p, 1.0);
    return glm::dvec2(clip.x / clip.w * 0.5 * camera.width, clip.y / clip.w * 0.5 * camera.height);
  };
  const double spacing_px = glm::length(pixel(nearest + set.surface_spacing * right) - pixel(nearest));
  if (!std::isfinite(spacing_px)) return 0.0f;
  return static_cast<float>(std::min(64.0, 2.0 * spacing_px));
}

// pointSizeFor's size, at least a sampled surface's (surfacePointPx) unless given.
float defaultPointSize(const RenderRequest& request, const LoadedSet& set, const Camera& camera, const DeviceFacts& facts) {
  const float size = pointSizeFor(request, set.count, set.bounds, camera, facts, set.spacing);
  return request.point_size ? size : std::max(size, surfacePointPx(set, camera));
}

// Shading auto on a picture too large for the shading passes' buffers draws it plain, with a
// warning in `warnings`.
RenderOptions renderOptionsFor(const RenderRequest& request, const LoadedSet& set, PrecisionMode mode,
                               const Camera& camera, const DeviceFacts& facts, std::vector<std::string>& warnings) {
  RenderOptions options;
  options.mode = mode;
  options.backend = *request.backend;
  options.point_size = defaultPointSize(request, set, camera, facts);
  // A 2D grid drawn at its spacing closes exactly with squares; discs would leave their corners open.
  options.round_points = request.round_points.value_or(!set.bounds.planar);
  options.background_rgba8 = request.background_rgba8;
  options.frames = request.frames;
  setWarmup(request.warmup, request.frames, options);
  options.tolerance_px = request.tolerance_px;
  options.probe = request.error;
  options.native_path = request.native_path;
  options.max_chunk_points = request.chunk_points;
  // A stream's chunks are its blocks (renderStream), at most set.stream_block points.
  if (set.stream)
    options.max_chunk_points = options.max_chunk_points ? std::min(options.max_chunk_points, set.stream_block)
                                                        : set.stream_block;
  options.shading = shadingFor(request, set.bounds);
  options.edl = request.edl;
  if (!request.shading && options.shading == Shading::kEdl && !shadingFits(facts, camera.width, camera.height, options)) {
    options.shading = Shading::kNone;
    warnings.push_back("a " + std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                       " picture is more than " + facts.name + " shades (maxTexelBufferElements " +
                       std::to_string(facts.max_texel_buffer_elements) + "): drawn without shading");
  }
  return options;
}

// --views 4: each view rendered in its own mode (--mode auto decides per view), one labelled sheet.
Status renderSheet(const RenderRequest& request, const VulkanContext& context, const LoadedSet& set,
                   const std::vector<RenderView>& views, const std::vector<Camera>& cameras, RenderOutcome& outcome,
                   const std::function<void(const SheetView&)>& view_done) {
  std::vector<LabelledView> sheet;
  for (size_t i = 0; i < views.size(); ++i) {
    Result<ModePrediction> prediction = predictMode(request, context, set, cameras[i]);
    if (!prediction) return prediction.error();
    std::vector<std::string> shading_warnings;
    const RenderOptions options =
        renderOptionsFor(request, set, prediction->mode, cameras[i], context.facts, shading_warnings);
    for (const std::string& w : shading_warnings) outcome.warnings.push_back("view " + std::string(views[i].label) + ": " + w);
    Result<RenderResult> rendered = renderPoints(context, *set.points(), cameras[i], options, prediction->encoding.get());
    if (!rendered) return rendered.error();
    const std::string mode(modeName(prediction->mode));
    const std::string label = "view " + std::string(views[i].label) + ": ";
    if (!cameras[i].note.empty()) outcome.warnings.push_back(label + cameras[i].note);
    if (!prediction->warning.empty()) outcome.warnings.push_back(label + prediction->warning);
    const DrawnPixels drawn = drawnPixels(rendered->image, request.background_rgba8);
    if (std::string cover = coverWarning(drawn.share(), drawn.span()); !cover.empty())
      outcome.warnings.push_back(label + cover);
    sheet.push_back({std::string(views[i].label) + " (" + mode + ")", std::move(rendered->image)});
    outcome.views.push_back({views[i].label, std::move(*prediction), std::move(rendered->gpu_ms)});
    if (view_done) view_done(outcome.views.back());
  }
  outcome.image = composeContactSheet(sheet, 2, request.camera.width, request.camera.height);
  if (set.coloring) drawLegend(outcome.image, *set.coloring);
  return okStatus();
}

// What a view's picture tells, and the picture with its legend into the outcome.
void finishView(const RenderRequest& request, const LoadedSet& set, RenderResult rendered, RenderOutcome& outcome) {
  const DrawnPixels drawn = drawnPixels(rendered.image, request.background_rgba8);
  outcome.drawn_share = drawn.share();
  if (std::string cover = coverWarning(drawn.share(), drawn.span()); !cover.empty()) outcome.warnings.push_back(cover);
  outcome.image = std::move(rendered.image);
  if (set.coloring) drawLegend(outcome.image, *set.coloring);
  outcome.result = std::move(rendered);
}

// One view, the set in memory or streamed: the render and, with --error, the error measured.
Status renderOne(const RenderRequest& request, const VulkanContext& context, const LoadedSet& set,
                 const Camera& camera, RenderOutcome& outcome, Progress& progress) {
  Result<ModePrediction> prediction = predictMode(request, context, set, camera);
  if (!prediction) return prediction.error();
  outcome.prediction = std::move(*prediction);
  if (!camera.note.empty()) outcome.warnings.push_back(camera.note);
  if (!outcome.prediction.warning.empty()) outcome.warnings.push_back(outcome.prediction.warning);
  outcome.phases.mark("mode");
  const RenderOptions options =
      renderOptionsFor(request, set, outcome.prediction.mode, camera, context.facts, outcome.warnings);
  outcome.point_size = options.point_size;
  outcome.shading = options.shading;
  Result<RenderResult> rendered = [&]() -> Result<RenderResult> {
    if (!set.stream) return renderPoints(context, *set.points(), camera, options, outcome.prediction.encoding.get());
    PointStream stream;
    stream.count = set.count;
    stream.has_colors = set.has_colors || set.elevation;
    const int axis = set.z_up ? 2 : 1;
    stream.read = [&](size_t first, size_t n, PointSet& block) -> Status {
      if (Status status = set.stream->read(first, n, block); !status) return status;
      if (set.elevation) colorByElevation(block, axis, set.bounds.min[axis], set.bounds.max[axis], request.threads);
      if (set.coloring) {
        block.colors.resize(block.size());
        colorByAttribute(block.dimensions.all().front(), 0, block.size(), *set.coloring, block.colors.data(),
                         request.threads);
      }
      progress.advance(n);
      return okStatus();
    };
    progress.start("streaming " + set.inputs + " to the GPU (points)", set.count);
    Result<RenderResult> streamed = renderStream(context, stream, camera, options);
    progress.finish();
    return streamed;
  }();
  if (!rendered) return rendered.error();
  outcome.phases.mark("render");
  if (request.error) {
    outcome.error = measureError(*set.points(), camera, *rendered, options);
    outcome.phases.mark("error");
  }
  finishView(request, set, std::move(*rendered), outcome);
  return okStatus();
}

// A fitted view leaves 1% of the picture free each side; where the default points are larger (a
// sparse set's), the fit is made again leaving their radius, so no point touches the edge.
Result<std::vector<Camera>> refitForPoints(const RenderRequest& request, const LoadedSet& set,
                                           const std::vector<RenderView>& views, const DeviceFacts& facts,
                                           std::vector<Camera> cameras) {
  const CameraSpec& spec = request.camera;
  if (request.point_size || spec.eye || spec.view_center || spec.view_width) return cameras;
  double radius = 0.0, free = HUGE_VAL;
  for (const Camera& camera : cameras) {
    radius = std::max(radius, 0.5 * defaultPointSize(request, set, camera, facts));
    free = std::min(free, 0.5 * kFitMarginShare * std::min(camera.width, camera.height));
  }
  if (radius + 0.5 <= free) return cameras;
  RenderRequest refit = request;
  refit.camera.fit_margin_px = radius + 0.5;
  return viewCameras(refit, views, set.bounds, set.z_up);
}

// One pass over a stream (LoadedSet::one_pass): encoded and uploaded for a provisional camera and
// mode from its preview while its bounds, batch boxes and spacing samples are gathered; then the
// outline and spacing (the batches they need, read again), the camera, the mode's check and the
// options, and the frames. False where the whole set wants another mode, or is 3D without colours
// (coloured by elevation): `set` then has its bounds, outline and spacing, and the caller reads the
// stream the usual way.
Result<bool> renderOnce(const RenderRequest& request, const VulkanContext& context, LoadedSet& set,
                  const std::vector<RenderView>& views, RenderOutcome& outcome, Progress& progress) {
  Result<std::vector<Camera>> provisional = viewCameras(request, views, boundsWithOutline(set.preview), set.z_up);
  if (!provisional) return provisional.error();
  PrecisionMode mode = kFallbackMode;
  if (request.mode != "auto") {
    mode = *parseMode(request.mode);
  } else {
    Result<ModeChoice> choice = chooseModeOnDevice(context, set.preview_boxes, provisional->front(), *request.backend,
                                                   request.tolerance_px, autoTargetOf(request, set.count));
    if (!choice) return choice.error();
    mode = choice->mode;
  }
  std::vector<std::string> ignored;
  const RenderOptions options = renderOptionsFor(request, set, mode, provisional->front(), context.facts, ignored);
  set.bounds = noBounds();
  SpacingSampler sampler(needsSpacing(request) ? kSpacingSamples : 0, request.threads);
  PointStream stream;
  stream.count = set.count;
  stream.has_colors = set.has_colors;
  stream.read = [&](size_t first, size_t n, PointSet& block) -> Status {
    if (Status status = set.stream->read(first, n, block); !status) return status;
    gatherBlock(block, set.bounds, set.boxes, sampler);
    progress.advance(n);
    return okStatus();
  };
  bool again = false;
  const auto read_again = [&again] {
    again = true;
    return Status(Error{"the stream must be read again"});
  };
  const StreamSettle settle = [&](Camera& camera, RenderOptions& settled) -> Status {
    progress.finish();
    outcome.phases.mark("upload");
    if (Status s = streamOutlineAndSpacing(request, set.inputs, *set.stream, sampler.finish(), set, progress); !s) return s;
    outcome.points_read_again = set.reread_points;
    outcome.phases.mark("reread");
    if (wantsElevation(request, set.has_colors, set.bounds)) return read_again();
    Result<std::vector<Camera>> cameras = viewCameras(request, views, set.bounds, set.z_up);
    if (cameras) cameras = refitForPoints(request, set, views, context.facts, std::move(*cameras));
    if (!cameras) return viewErrorOf(set, cameras.error());
    camera = cameras->front();
    Result<ModePrediction> prediction = predictMode(request, context, set, camera);
    if (!prediction) return prediction.error();
    if (prediction->mode != mode) return read_again();
    outcome.prediction = std::move(*prediction);
    if (!camera.note.empty()) outcome.warnings.push_back(camera.note);
    if (!outcome.prediction.warning.empty()) outcome.warnings.push_back(outcome.prediction.warning);
    settled = renderOptionsFor(request, set, mode, camera, context.facts, outcome.warnings);
    outcome.point_size = settled.point_size;
    outcome.shading = settled.shading;
    outcome.phases.mark("mode");
    return okStatus();
  };
  progress.start("streaming " + set.inputs + " to the GPU (points)", set.count);
  Result<RenderResult> rendered = renderStreamOnce(context, stream, provisional->front(), options, settle);
  progress.finish();
  if (again) return false;
  if (!rendered) return rendered.error();
  outcome.phases.mark("render");
  finishView(request, set, std::move(*rendered), outcome);
  return true;
}

// A CPU device's memory is the host's (lavapipe, the default without a GPU): while a render runs,
// the device's budget is what --max-memory leaves beside the points read (a stream: its blocks),
// or --max-device-memory where that is lower. The points' device copies, the picture's images and
// the readback are the device's buffers, charged there; a stream's device copy is the whole set,
// which without this bound took host memory past --max-memory. A stream's blocks were sized to
// --max-memory before the device was known: its render pass's are sized here to half of it, the
// other half left to the device (the passes before, bounds and outline, held no device memory).
// A refusal is then exit 4 naming --max-memory (vulkan/buffers.cpp); where --max-device-memory
// is given too, the tighter of the two refuses and names the other (--max-memory given or by its
// default) as the next limit. Put back at the end: a
// Python Renderer's device outlives it.
class HostMemoryBudget {
 public:
  HostMemoryBudget(VulkanContext& context, const RenderRequest& request, LoadedSet& set)
      : context_(context), budget_(context.device_memory_budget), host_(context.host_budget), next_(context.next_budget) {
    const PointSet* points = set.points();
    if (context.facts.type != "cpu" || (!points && !set.stream)) return;
    const uint64_t limit = request.max_memory ? request.max_memory : defaultMemoryLimit();
    if (!points) set.stream_block = std::min(set.stream_block, streamBlockPoints(limit / 2, set.stream_point_bytes));
    const uint64_t held =
        points ? heldBytes(*points) : streamHeldBytes(set.count, set.stream_block, set.stream_point_bytes);
    const uint64_t left = limit > held ? limit - held : 1;  // 0 would be no budget at all
    const std::string option =
        request.max_memory ? "--max-memory " + formatBytes(limit) : "--max-memory (" + formatBytes(limit) + ", half of RAM)";
    const std::string what = points ? " of points read" : " of the stream's blocks";
    const std::string host = limit > held ? "the " + formatBytes(left) + " that " + option + " leaves beside the " +
                                                formatBytes(held) + what
                                          : option + ", which the " + formatBytes(held) + what + " already take";
    // The tighter bound refuses and names the looser (a review finding: raising the one named let
    // the render run into the other with no warning).
    if (budget_ != 0 && budget_ <= left) {
      context.next_budget = host;
      return;
    }
    if (budget_ != 0) context.next_budget = "--max-device-memory " + formatBytes(budget_);
    context.device_memory_budget = left;
    context.host_budget = host;
  }
  ~HostMemoryBudget() {
    context_.device_memory_budget = budget_;
    context_.host_budget = host_;
    context_.next_budget = next_;
  }
  HostMemoryBudget(const HostMemoryBudget&) = delete;
  HostMemoryBudget& operator=(const HostMemoryBudget&) = delete;

 private:
  VulkanContext& context_;
  uint64_t budget_;
  std::string host_, next_;
};

}  // namespace

RenderColor parseRenderColor(std::string_view name) {
  if (name == "auto") return RenderColor::kAuto;
  if (name == "rgb") return RenderColor::kRgb;
  if (name == "elevation") return RenderColor::kElevation;
  return RenderColor::kAttribute;
}

std::string predictionWarning(const RenderRequest& request, const ModePrediction& prediction,
                              std::optional<PrecisionMode> auto_mode) {
  const std::string mode(modeName(prediction.mode));
  if (const std::optional<ModeChoice>& c = prediction.choice) {
    if (c->enough) return std::string();
    char limit[32];
    std::snprintf(limit, sizeof limit, "%g", kAutoBoundPx);
    return std::string("no mode this device runs stays within ") + limit + " px for this view; " + mode +
           " is the most accurate here (bound " + formatBound(prediction.bound_px) + ")";
  }
  if (request.mode == "auto" || prediction.bound_px <= kWrongBoundPx) return std::string();
  const std::string bound = std::isfinite(prediction.bound_px) ? "up to " + formatBound(prediction.bound_px)
                                                               : std::string("unbounded");
  return "--mode " + mode + ": predicted error " + bound + " (> " + formatNumber(kWrongBoundPx) +
         " px): the picture is wrong here" +
         (auto_mode ? "; --mode auto picks " + std::string(modeName(*auto_mode)) : std::string());
}

std::string coverWarning(double drawn_share, double drawn_span) {
  if (drawn_share == 0.0)
    return "the picture shows nothing: no point was drawn in the view (frame the data with --view-center and "
           "--view-width, or --eye and --target)";
  if (!(drawn_share < kPoorCoverShare)) return std::string();
  char share[32];
  std::snprintf(share, sizeof share, "%.2g%%", 100.0 * drawn_share);
  if (drawn_span >= 0.5)
    return std::string("the data covers ") + share + " of the picture (under 1%): it spans the picture, but its "
           "points are sparse at this size; larger points (--point-size N) show more";
  return std::string("the data covers ") + share + " of the picture (under 1%): frame it closer with --view-center "
         "and --view-width, or --eye and --target";
}

const char* backendName(Backend backend) { return backend == Backend::kCompute ? "compute" : "raster"; }

uint64_t meshSurfaceSamples(SurfaceChoice choice, const PointSet& mesh, uint32_t width, uint32_t height) {
  if (choice == SurfaceChoice::kOff || !mesh.isMesh()) return 0;
  const uint64_t pixels = uint64_t{width} * height;
  if (choice == SurfaceChoice::kAuto && mesh.size() >= pixels) return 0;  // dense enough to draw as points
  const Box box = boundingBox(mesh.positions);
  // The fit's scale, about: the box's diagonal across the picture's larger side (an elongated part
  // lies along it; the smaller side made the engine's samples 2× too sparse at 1920×1080).
  const double pixel = glm::length(box.max - box.min) / std::max(1u, std::max(width, height));
  if (choice == SurfaceChoice::kAuto && !(medianTriangleEdge(mesh) > kCoarseTrianglePx * pixel)) return 0;
  const double area = surfaceArea(mesh);
  if (!(area > 0.0)) return 0;
  // Two per pixel: at one, uniform samples leave a few holes wider than the 3-pixel discs that EDL
  // then outlines (the far side showed through BoxTextured's front faces).
  const double cap = 2.0 * static_cast<double>(pixels);
  const double wanted = pixel > 0.0 ? std::min(cap, 2.0 * area / (pixel * pixel)) : cap;
  return static_cast<uint64_t>(std::max(1.0, std::ceil(wanted)));
}

Status checkPictureOutput(const std::string& path) {
  if (Status s = AtomicFile::checkTarget(path); !s) return s;  // where it goes, before any work
  if (!hasExtension(path, ".png") && path.rfind("/dev/", 0) != 0)
    return Error{"-o " + path + ": the picture is written as PNG; name it .png", ExitCode::kUsage};
  return okStatus();
}

Status checkModeName(const std::string& mode) {
  if (mode == "auto" || parseMode(mode)) return okStatus();
  return Error{"--mode " + mode + ": must be " + modeOptionChoices(), ExitCode::kUsage};
}

Status checkViewCount(uint32_t views) {
  if (views == 1 || views == 4) return okStatus();
  return Error{"--views " + std::to_string(views) + ": must be 1 or 4", ExitCode::kUsage};
}

Result<WarmupRequest> parseWarmup(const std::string& flag, const std::string& text) {
  WarmupRequest out;
  if (text == "auto") return out;
  auto refuse = [&](const std::string& why) {
    return Error{flag + ": '" + text + "' " + why + " (a frame count such as 2, a duration such as 300ms or 0.5s, or auto)",
                 ExitCode::kUsage};
  };
  const size_t digits = text.find_first_not_of("0123456789.");
  const std::string number = text.substr(0, digits), unit = digits == std::string::npos ? "" : text.substr(digits);
  if (number.empty() || number.front() == '.') return refuse("is not a warm-up");
  if (unit.empty()) {
    // A count: whole frames only, within uint32_t.
    if (number.find('.') != std::string::npos) return refuse("is no whole number of frames; a duration needs ms or s");
    uint64_t frames = 0;
    if (!parseDecimalU64(number, frames) || frames > UINT32_MAX) return refuse("is more frames than can be counted");
    out.kind = WarmupRequest::Kind::kFrames;
    out.frames = static_cast<uint32_t>(frames);
    return out;
  }
  if (unit != "ms" && unit != "s") return refuse("has no unit it knows: ms or s");
  char* end = nullptr;
  const double value = std::strtod(number.c_str(), &end);
  if (end != number.c_str() + number.size() || !std::isfinite(value)) return refuse("is not a duration");
  out.kind = WarmupRequest::Kind::kTime;
  out.ms = unit == "s" ? value * 1000.0 : value;
  if (!(out.ms > 0.0)) return refuse("is no time; --warmup 0 draws no warm-up frame");
  if (out.ms < kMinWarmupMs) return refuse("is under " + formatNumber(kMinWarmupMs) + " ms");
  if (out.ms > kMaxWarmupMs) return refuse("is more than " + formatNumber(kMaxWarmupMs / 1000.0) + " s");
  return out;
}

std::string warmupText(const WarmupRequest& warmup) {
  switch (warmup.kind) {
    case WarmupRequest::Kind::kAuto: return "auto";
    case WarmupRequest::Kind::kFrames: return std::to_string(warmup.frames);
    case WarmupRequest::Kind::kTime: {
      // The shortest fixed-point text that reads back to the same double (no exponent: parseWarmup
      // takes none); kMinWarmupMs..kMaxWarmupMs fits the buffer.
      char text[64];
      const std::to_chars_result r = std::to_chars(text, text + sizeof text, warmup.ms, std::chars_format::fixed);
      return std::string(text, r.ptr) + "ms";
    }
  }
  return "auto";
}

Status checkRenderRequest(const RenderRequest& request) {
  if (Status s = checkModeName(request.mode); !s) return s;
  if (Status s = checkViewCount(request.views); !s) return s;
  if (request.views == 4) {
    if (request.camera.eye || request.camera.ortho.value_or(false))
      return Error{"--views 4 frames each view with --fit in perspective; drop --eye/--target/--up and --ortho",
                   ExitCode::kUsage};
    if (request.error || request.report)
      return Error{std::string("--views 4 makes a contact sheet; ") + (request.error ? "--error" : "--json") +
                       " measures one view (use --views 1)",
                   ExitCode::kUsage};
    const uint32_t least = 2 + kContactSheetGap;  // two 1-px views and the line between them
    if (request.camera.width < least || request.camera.height < least)
      return Error{"--views 4 needs --width and --height of at least " + std::to_string(least) + " px, got " +
                       std::to_string(request.camera.width) + "x" + std::to_string(request.camera.height),
                   ExitCode::kUsage};
  }
  return okStatus();
}

void RenderPhases::mark(const char* name) {
  const auto now = std::chrono::steady_clock::now();
  list_.emplace_back(name, std::chrono::duration<double, std::milli>(now - last_).count());
  last_ = now;
}

double peakRssMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // kilobytes on Linux
}

std::vector<RenderView> viewsFor(uint32_t count, bool z_up) {
  const RenderView three_quarter = z_up ? RenderView{"three-quarter", {0.6, -1.0, 0.5}, {0, 0, 1}}
                                        : RenderView{"three-quarter", {0.6, 0.5, 1.0}, {0, 1, 0}};
  if (count == 1) return {three_quarter};
  if (z_up)
    return {{"front", {0, -1, 0}, {0, 0, 1}}, {"side", {1, 0, 0}, {0, 0, 1}}, {"top", {0, 0, 1}, {0, 1, 0}}, three_quarter};
  return {{"front", {0, 0, 1}, {0, 1, 0}}, {"side", {1, 0, 0}, {0, 1, 0}}, {"top", {0, 1, 0}, {0, 0, -1}}, three_quarter};
}

bool zUpFor(const RenderRequest& request, bool data_z_up) {
  if (request.up_axis != UpAxis::kAuto) return request.up_axis == UpAxis::kZ;
  return data_z_up || (!request.points && !request.inputs.empty() && std::all_of(request.inputs.begin(), request.inputs.end(), [](
                                                         const std::string& path) { return hasExtension(path, ".las") || hasExtension(path, ".laz"); }));
}

Result<std::vector<Camera>> viewCameras(const RenderRequest& request, const std::vector<RenderView>& views,
                                        const Bounds& bounds, bool z_up) {
  const CameraSpec& spec = request.camera;
  std::vector<Camera> cameras;
  for (const RenderView& view : views) {
    CameraSpec view_spec = spec;
    // One y-up view is makeCamera's own default fit.
    if (!spec.eye && (views.size() == 4 || z_up)) view_spec.fit_direction = view.direction, view_spec.fit_up = view.up;
    // Four views share the picture: each gets a quarter less the lines between them, so the sheet
    // is exactly width x height (composeContactSheet).
    if (views.size() == 4)
      view_spec.width = contactSheetCell(spec.width, 2), view_spec.height = contactSheetCell(spec.height, 2);
    Result<Camera> camera = makeCamera(view_spec, bounds);
    if (!camera) return camera.error();
    cameras.push_back(*camera);
  }
  return cameras;
}

Backend backendFor(const RenderRequest& request, size_t count, uint32_t width, uint32_t height, const DeviceFacts& facts) {
  if (request.backend) return *request.backend;
  // The limits renderPoints checks for compute (viewer/render.cpp's checkOptions).
  const bool fits = uint64_t{4} * count <= facts.max_storage_buffer_range &&
                    uint64_t{8} * width * height <= facts.max_storage_buffer_range;
  return facts.int64_atomics && fits ? Backend::kCompute : Backend::kRaster;
}

// It keys on the data, not the camera: a survey seen from above with --ortho still has the relief
// EDL brings out, and a flat set seen in perspective has no relief, only the depth ramp of a
// tilted plane. With --error the image check compares plain pixels with the reference raster.
Shading shadingFor(const RenderRequest& request, const Bounds& bounds) {
  if (request.shading) return *request.shading;
  if (request.error) return Shading::kNone;
  return bounds.planar ? Shading::kNone : Shading::kEdl;
}

// The median of the sampled spacings (ops/point_spacing.h), each projected at its point's depth
// as a distance across the picture; none when no sampled point is in view.
std::optional<double> projectedSpacing(std::span<const SpacingSample> spacing, const Camera& camera) {
  if (spacing.empty()) return std::nullopt;
  // The picture's x axis in world directions: the first row of the rotation.
  const glm::dvec3 across(camera.rotation[0][0], camera.rotation[1][0], camera.rotation[2][0]);
  PositionArray ends;
  ends.reserve(2 * spacing.size());
  for (const SpacingSample& s : spacing) {
    ends.push_back(s.position);
    ends.push_back(s.position + s.distance * across);
  }
  const std::vector<WindowPoint> windows = projectReference(ends, camera);
  std::vector<double> pixels;
  for (size_t k = 0; k + 1 < windows.size(); k += 2) {
    const WindowPoint &a = windows[k], &b = windows[k + 1];
    if (a.visible && b.visible) pixels.push_back(std::hypot(b.x - a.x, b.y - a.y));
  }
  if (pixels.empty()) return std::nullopt;
  std::nth_element(pixels.begin(), pixels.begin() + std::ptrdiff_t(pixels.size() / 2), pixels.end());
  return pixels[pixels.size() / 2];
}

// With the set's spacing samples: the projected spacing rounded up for a 2D set (a grid drawn
// larger than its resolution closes without a screen-door pattern: a 256² mandelbrot2d at 768 px,
// 3 px); kRoundShare (kSquareShare) of it for a 3D set, whose remaining gaps the hole filling before
// eye-dome lighting closes (shaders/render/fill.comp; at 1024x768 a Mandelbulb of 226K points,
// 7 px, of 1.55M, 3 px; the default Menger sponge, 8 px, its holes open). At most 8 px, or where
// the points are few, as large as kPointPixelBudget pictures of point pixels allow (at most 64).
// Without samples (a streamed set), the
// count over the outline: a 3D set's quarter of its points (a closed surface shows its front half,
// and a folded one hides about half of that behind its folds) over the ellipse inside the box's
// screen rectangle, at most 4 px, and 1 px in ortho; a 2D set's points over the rectangle, at most
// 8 px. Always 1 with --error (the reference raster draws 1-px points); the same on both backends.
float pointSizeFor(const RenderRequest& request, size_t count, const Bounds& box, const Camera& camera,
                   const DeviceFacts& facts, std::span<const SpacingSample> samples) {
  if (request.point_size) return static_cast<float>(*request.point_size);
  if (request.error) return 1.0f;
  if (request.backend.value_or(Backend::kRaster) == Backend::kRaster && !facts.large_points) return 1.0f;
  if (std::optional<double> spacing = projectedSpacing(samples, camera)) {
    const bool round = request.round_points.value_or(!box.planar);
    // A disc of 2 px is its square (every pixel centre lies within it): at least 3 px, whose
    // corners leave out overlap the neighbours' (a 1.55M Mandelbulb at 640x480: 0.58% artefacts
    // at 2 px, 0.16% at 3).
    const double size = box.planar ? *spacing : round ? std::max(3.0, kRoundShare * *spacing) : kSquareShare * *spacing;
    const double pixels = double(camera.width) * double(camera.height);
    const double most = std::min({std::max(8.0, std::floor(std::sqrt(kPointPixelBudget * pixels / double(std::max<size_t>(count, 1))))),
                                  64.0, double(facts.max_point_size)});
    return static_cast<float>(std::clamp(std::ceil(size), 1.0, most));
  }
  if (camera.ortho && !box.planar) return 1.0f;
  // The data's outline when the fit framed it (every one of its points is inside the picture), else
  // the box's corners.
  PositionArray corners = box.outline;
  if (corners.empty()) {
    for (int i = 0; i < 8; ++i)
      corners.push_back({(i & 1) ? box.max.x : box.min.x, (i & 2) ? box.max.y : box.min.y, (i & 4) ? box.max.z : box.min.z});
  }
  double x0 = camera.width, y0 = camera.height, x1 = 0.0, y1 = 0.0;
  for (const WindowPoint& w : projectReference(corners, camera)) {
    if (!w.visible) return 1.0f;  // the eye is inside or near the data: no outline to fill
    x0 = std::min(x0, std::max(w.x, 0.0)), x1 = std::max(x1, std::min(w.x, double(camera.width)));
    y0 = std::min(y0, std::max(w.y, 0.0)), y1 = std::max(y1, std::min(w.y, double(camera.height)));
  }
  const double rectangle = std::max(0.0, x1 - x0) * std::max(0.0, y1 - y0);
  const double area = box.planar ? rectangle : rectangle * 0.25 * 3.14159265358979;
  const double shown = box.planar ? static_cast<double>(count) : 0.25 * static_cast<double>(count);
  const double spacing = std::sqrt(area / std::max(1.0, shown));
  const double most = box.planar ? 8.0 : 4.0;
  return static_cast<float>(std::clamp(std::ceil(spacing), 1.0, std::min(most, double(facts.max_point_size))));
}

namespace {

// What a stream's readers met in its blocks (after its headers' notices): said with the others.
void addStreamNotices(const LoadedSet& set, RenderOutcome& outcome) {
  if (!set.stream) return;
  const std::vector<std::string>& all = set.stream->notices();
  outcome.notices.insert(outcome.notices.end(), all.begin() + static_cast<std::ptrdiff_t>(set.stream_notices), all.end());
}

}  // namespace

Result<RenderOutcome> runRenderJob(const RenderRequest& request, Progress& progress,
                                   const std::function<void(const SheetView&)>& view_done) {
  if (Status s = checkRenderRequest(request); !s) return s.error();
  // Before the input is read: a 1000000-pixel-wide picture should not wait for a large file to load first.
  const CameraSpec& spec = request.camera;
  const uint64_t pixels = uint64_t{spec.width} * spec.height;
  if (Status s = checkMemory("a " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " picture",
                             pixels * kPictureBytesPerPixel, request.max_memory);
      !s)
    return s.error();

  RenderOutcome outcome;
  // The Vulkan device is made while the input is read: creating it takes 150 ms or more on the
  // NVIDIA driver, a good part of a 16.7M-point render's second. Its errors wait until the input
  // has been read, so a bad file is still reported first.
  std::future<Result<std::unique_ptr<VulkanContext>>> device_made;
  if (request.context)
    request.context->clearValidationMessages();
  else
    device_made = std::async(std::launch::async, [&request] {
      return VulkanContext::create(ContextOptions{request.device, request.validate, request.max_device_memory});
    });
  Result<LoadedSet> set = loadInput(request, progress, outcome.phases);
  if (!set) return set.error();
  outcome.points = set->count;
  outcome.streamed = set->stream != nullptr;
  outcome.points_read_again = set->reread_points;
  outcome.copc = set->copc;
  outcome.notices = set->notices;
  if (set->owned && !set->owned->isMesh())  // drawn as its surface: what of its texture it lacks
    outcome.warnings.insert(outcome.warnings.end(), set->texture.notes.begin(), set->texture.notes.end());
  if (request.views == 4 && set->bounds.planar)
    return Error{set->inputs + ": --views 4 shows a 3D set from four sides; this set is 2D (every z is 0)",
                 ExitCode::kUsage};
  const std::vector<RenderView> views = viewsFor(request.views, set->z_up);
  Result<std::vector<Camera>> cameras = std::vector<Camera>();
  if (!set->one_pass) {
    cameras = viewCameras(request, views, set->bounds, set->z_up);
    if (!cameras) return viewErrorOf(*set, cameras.error());
    outcome.phases.mark("camera");
  }

  if (request.context)
    outcome.context = request.context;
  else if (Result<std::unique_ptr<VulkanContext>> made = device_made.get(); made)
    outcome.context = std::move(*made);
  else
    return made.error();
  outcome.phases.mark("device");  // what is left of making it once the input is in
  const HostMemoryBudget host_budget(*outcome.context, request, *set);
  const VulkanContext& context = *outcome.context;
  outcome.device = context.facts;
  outcome.backend = backendFor(request, set->count, spec.width, spec.height, context.facts);
  RenderRequest resolved = request;  // the policies below see the backend that runs
  resolved.backend = outcome.backend;
  if (set->one_pass) {
    Result<bool> drawn = renderOnce(resolved, context, *set, views, outcome, progress);
    if (!drawn) return drawn.error();
    if (*drawn) {
      outcome.validation_messages = context.validationMessages();
      addStreamNotices(*set, outcome);
      outcome.read_set = ReleaseInBackground(std::move(*set));
      return outcome;
    }
    // The points as uploaded would not do: drawn from a second read, with the bounds now known.
    set->one_pass = false;
    set->elevation = wantsElevation(request, set->has_colors, set->bounds);
    outcome.read_twice = true;
    cameras = viewCameras(request, views, set->bounds, set->z_up);
    if (!cameras) return viewErrorOf(*set, cameras.error());
  }
  cameras = refitForPoints(resolved, *set, views, context.facts, std::move(*cameras));
  if (!cameras) return cameras.error();
  Status rendered = views.size() == 4 ? renderSheet(resolved, context, *set, views, *cameras, outcome, view_done)
                                      : renderOne(resolved, context, *set, cameras->front(), outcome, progress);
  if (!rendered) return rendered.error();
  outcome.validation_messages = context.validationMessages();
  addStreamNotices(*set, outcome);
  // Giving the set's memory back (s11u.ply's 600 MB: 20-50 ms) overlaps writing the picture.
  outcome.read_set = ReleaseInBackground(std::move(*set));
  return outcome;
}

Status writeRenderPicture(const std::string& path, RenderOutcome& outcome) {
  if (Status written = writePng(path, outcome.image); !written) return written;
  outcome.phases.mark("png");
  return okStatus();
}

std::string renderReportJson(const RenderRequest& request, const RenderOutcome& outcome) {
  const DeviceFacts& f = outcome.device;
  const RenderResult& r = outcome.result;
  const PrecisionMode mode = outcome.prediction.mode;
  const double gpu_median = medianOf(r.gpu_ms), frame_median = medianOf(r.frame_ms);
  const double per_frame_ms = r.gpu_ms.empty() ? frame_median : gpu_median;
  using V = JsonValue;
  JsonObject o;
  o.add("mode", V::string(modeName(mode))).add("mode_requested", V::string(request.mode));
  o.add("predicted_bound_px", V::number(outcome.prediction.bound_px));
  // What the bound was predicted from: every point the view shows, the set's bounding box (--mode
  // auto, where the box showed the mode within the limit), or (a streamed set, read once while it
  // is drawn) the box of every 1024 points.
  const bool from_box = outcome.prediction.choice && outcome.prediction.choice->from_box;
  o.add("predicted_from", V::string(outcome.prediction.from_boxes ? "batch_boxes" : from_box ? "box" : "points"));
  if (const std::optional<CopcReadStats>& c = outcome.copc)  // a COPC input: what its view read
    o.add("copc", JsonObject()
                      .add("points_read", V::integer(c->points))
                      .add("bytes_read", V::integer(c->bytes))
                      .add("nodes_read", V::integer(c->nodes))
                      .add("file_points", V::integer(c->file_points))
                      .add("file_bytes", V::integer(c->file_bytes)));
  if (const std::optional<ModeChoice>& c = outcome.prediction.choice) {
    JsonObject choice;
    choice.add("enough", V::boolean(c->enough)).add("limit_px", V::number(kAutoBoundPx));
    choice.add("device_class", V::string(deviceClassName(deviceClassOf(f.type))));
    // What the order minimised: the predicted time to the picture (one frame), or the frames.
    choice.add("ordered_by", V::string(c->by_picture_time ? "time_to_picture" : "frame"));
    if (c->by_picture_time) choice.add("predicted_ms", V::number(c->predicted_ms));
    if (c->runner_up) {
      JsonObject runner_up;
      runner_up.add("mode", V::string(modeName(*c->runner_up))).add("predicted_bound_px", V::number(c->runner_up_bound_px));
      // "box": bounded over the set's bounding box, which showed it within the limit (no pass over the points).
      runner_up.add("predicted_from", V::string(c->runner_up_from_box ? "box" : "points"));
      if (c->by_picture_time) runner_up.add("predicted_ms", V::number(c->runner_up_predicted_ms));
      choice.add("runner_up", runner_up);
    } else
      choice.add("runner_up", V::null());
    std::vector<V> rejected;
    for (const ModeChoice::Rejected& passed : c->rejected) {
      JsonObject one;
      one.add("mode", V::string(modeName(passed.mode))).add("predicted_bound_px", V::number(passed.bound_px));
      one.add("usable", V::boolean(!std::isnan(passed.bound_px)));
      if (!passed.reason.empty()) one.add("reason", V::string(passed.reason));
      rejected.push_back(V::object(one));
    }
    choice.add("rejected", V::array(rejected));
    o.add("auto", choice);
  }
  o.add("backend", V::string(backendName(outcome.backend))).add("order", V::string(pointOrderName(request.order)));
  o.add("device", V::string(f.name)).add("device_type", V::string(f.type));
  o.add("driver", V::string(f.driver_name + " " + f.driver_info));
  o.add("driver_version", V::string(formatDriverVersion(f.vendor_id, f.driver_version)));
  o.add("api_version", V::string(formatApiVersion(f.api_version)));
  o.add("points", V::integer(outcome.points));
  if (outcome.streamed) {
    o.add("points_read_again", V::integer(outcome.points_read_again));
    o.add("read_twice", V::boolean(outcome.read_twice));
  }
  o.add("width", V::integer(request.camera.width)).add("height", V::integer(request.camera.height));
  o.add("point_size", V::number(outcome.point_size));
  o.add("shading", V::string(outcome.shading == Shading::kEdl ? "edl" : "none"));
  o.add("frames", V::integer(r.frame_ms.size()));
  if (r.gpu_ms.empty()) {
    o.add("gpu_ms", V::null());
  } else {
    o.add("gpu_ms", JsonObject()
                        .add("median", V::number(gpu_median))
                        .add("p95", V::number(percentileOf(r.gpu_ms, 95)))
                        .add("min", V::number(*std::min_element(r.gpu_ms.begin(), r.gpu_ms.end()))));
    // Every timed frame in order: a slow start (the first frames after a large upload) shows here.
    o.add("gpu_ms_each", V::numbers(r.gpu_ms));
  }
  o.add("frame_ms", JsonObject().add("median", V::number(frame_median)).add("p95", V::number(percentileOf(r.frame_ms, 95))));
  // The warm-up that ran before the timed frames: untimed frames and their wall time, and the time
  // it was to last at least (--warmup by time, or auto with several frames; null: a count).
  RenderOptions warmup;
  setWarmup(request.warmup, request.frames, warmup);
  o.add("warmup", JsonObject()
                      .add("frames", V::integer(r.warmup_frames))
                      .add("ms", V::number(r.warmup_ms))
                      .add("until_ms", warmup.warmup_ms > 0.0 ? V::number(warmup.warmup_ms) : V::null()));
  o.add("upload_ms", V::number(r.upload_ms)).add("readback_ms", V::number(r.readback_ms));
  o.add("e2e_ms", V::number(r.upload_ms + frame_median + r.readback_ms));
  JsonObject phases;
  for (const auto& [name, ms] : outcome.phases.list()) phases.add(name, V::number(ms));
  o.add("phases_ms", phases).add("peak_rss_mb", V::number(peakRssMb()));
  o.add("points_per_s", V::number(static_cast<double>(outcome.points) / (per_frame_ms * 1e-3)));
  o.add("bytes_per_point", V::integer(bytesPerPoint(mode))).add("chunks", V::integer(r.chunks));
  // The per-batch modes' plan for this view: what the frame loaded (position bytes per point of
  // the whole set; colours are read per pixel by the resolve), the batches it culled and, in
  // adaptive mode, the share of batches at each tier count and the tolerance it chose them for.
  if (const std::optional<BatchPlanStats>& plan = r.batch_plan) {
    const double batches = static_cast<double>(std::max<size_t>(plan->batches, 1));
    JsonObject p;
    p.add("batches", V::integer(plan->batches)).add("culled", V::integer(plan->culled));
    p.add("loaded_bytes_per_point", V::number(plan->bytes_per_point));
    if (modeInfo(mode).tiers) {
      std::vector<double> shares;
      for (size_t count : plan->at_tiers) shares.push_back(static_cast<double>(count) / batches);
      p.add("tier_share", V::numbers(shares)).add("tolerance_px", V::number(request.tolerance_px));
    }
    o.add("batch_plan", p);
  } else {
    o.add("batch_plan", V::null());
  }
  // Only a mode with two raster paths (vertex input or pulling from a storage buffer) says which ran.
  const bool two_paths = modeInfo(mode).shaders.vertex_pull.code != nullptr;
  o.add("native_path", !two_paths ? V::null() : V::string(r.pulled_positions ? "pull" : "attribute"));
  // The compute splat's order (RenderOptions::near_end_first): the set's, from its far end
  // (reversed), or some chunks each way; null for the raster backend.
  o.add("splat_order", outcome.backend != Backend::kCompute ? V::null()
                       : V::string(r.reversed_chunks == 0                ? "input"
                                   : r.reversed_chunks == r.chunks ? "reversed"
                                                                   : "both"));
  if (const std::optional<ErrorReport>& error = outcome.error) {
    const ErrorStats& e = error->stats;
    o.add("error_px", anyMeasured(e) ? V::object(JsonObject()
                                                     .add("max", V::number(e.max_px))
                                                     .add("p99", V::number(e.p99_px))
                                                     .add("rms", V::number(e.rms_px)))
                                     : V::null());
    o.add("share_off_half_px", V::number(e.share_off_half_px));
    o.add("points_visible", V::integer(e.points)).add("points_lost", V::integer(e.lost));
    o.add("pixels_differing", error->pixels_compared ? V::integer(error->pixels_differing) : V::null());
  }
  o.add("drawn_share", V::number(outcome.drawn_share));
  std::vector<V> warnings;
  for (const std::string& w : outcome.warnings) warnings.push_back(V::string(w));
  o.add("warnings", V::array(warnings));
  return o.block();
}

}  // namespace dpoint
