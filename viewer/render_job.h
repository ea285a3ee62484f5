// One `dpoint render` run as a library call. A front end (the CLI, a Python module) fills a
// RenderRequest with what the user asked, calls runRenderJob and gets back a RenderOutcome: the
// picture and the facts to print or report (renderReportJson: the JSON of render's --json). The
// policies live here so that every front end gives the same answer: the point size, the views of
// a contact sheet and their cameras, the shading, the up axis, the colouring, the streaming of a
// large PLY (its bounds in one pass) and the mode (--mode auto's choice, or the bound of the mode
// asked for). Nothing here prints; progress goes to the caller's Progress.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "converters/point_io.h"
#include "core/memory.h"
#include "core/progress.h"
#include "core/result.h"
#include "image/image.h"
#include "ops/point_order.h"
#include "ops/point_spacing.h"
#include "viewer/camera.h"
#include "viewer/precision.h"
#include "viewer/probe.h"
#include "viewer/render.h"
#include "vulkan/context.h"

namespace dpoint {

// --color: where the points' colours come from: the set's own, a map of the elevation, or a map of
// one of its dimensions (RenderRequest::color_attribute; ops/attribute_colors.h) with a legend.
enum class RenderColor { kAuto, kRgb, kElevation, kAttribute };
// auto, rgb, elevation, or any other name: a dimension (kAttribute).
RenderColor parseRenderColor(std::string_view name);

// --up-axis: the data's up for the fitted views. auto: z for LAS input (surveys), y otherwise.
enum class UpAxis { kAuto, kY, kZ };

const char* backendName(Backend backend);  // "raster", "compute"

// --warmup: the untimed frames before the timed ones (RenderOptions' warm-up). auto: none for a
// single frame (the picture comes sooner), else kAutoWarmupMs by time; a count of frames ("2"); or
// a duration ("300ms", "0.5s"): frames until that much wall time has passed, at least one.
struct WarmupRequest {
  enum class Kind { kAuto, kFrames, kTime };
  Kind kind = Kind::kAuto;
  uint32_t frames = 0;  // kFrames
  double ms = 0.0;      // kTime: kMinWarmupMs to kMaxWarmupMs
};
// auto's warm-up with more than one timed frame: on the H100 the first frames after a multi-second
// upload ran 2–4× slower in flat steps for up to ~300 ms (docs/performance.md).
inline constexpr double kAutoWarmupMs = 300.0;
inline constexpr double kMaxWarmupMs = 60000.0;  // a longer one is taken for a typo (300s for 300ms)
inline constexpr double kMinWarmupMs = 0.001;    // a shorter one is no duration a frame can measure
// "auto", a whole number, or a number with "ms" or "s". Fails (kUsage) naming `flag` and the text.
Result<WarmupRequest> parseWarmup(const std::string& flag, const std::string& text);
// The text parseWarmup reads back to the same request ("auto", "2", "300ms").
std::string warmupText(const WarmupRequest& warmup);

enum class SurfaceChoice { kAuto, kOn, kOff };

// How many points to sample on `mesh` drawn into a `width` × `height` picture: two per pixel of its
// surface seen face-on at the fit's scale (the box's diagonal across the larger side), at most 2
// per pixel of the picture. 0 for kOff, a point set, and for kAuto unless the mesh is coarse on
// screen: fewer vertices than pixels and the area-weighted median triangle (medianTriangleEdge)
// longer than kCoarseTrianglePx, a CAD part's flat faces, which its vertices alone leave empty.
// A generated Mandelbulb, Julia set, Sierpinski tetrahedron or Menger sponge at its default
// resolution (3-19 px at 640×480 to 1920×1080; a res-64 Mandelbulb 16 px at 1024×768) keeps its
// vertices, which the hole filling closes; the 2CylinderEngine's are 31-94 px, BoxTextured's 500+.
inline constexpr double kCoarseTrianglePx = 24.0;
uint64_t meshSurfaceSamples(SurfaceChoice choice, const PointSet& mesh, uint32_t width, uint32_t height);

// What the user asked for, as plain values (the CLI's options, parsed).
struct RenderRequest {
  std::vector<std::string> inputs;   // drawn as one (point_inputs.h)
  // A set in memory, drawn instead of reading `inputs` (a front end's own arrays: the Python
  // module). It is never changed: a colouring by elevation or an --order works on a copy. `inputs`
  // then only names it in messages (empty: "points").
  std::shared_ptr<const PointSet> points;
  // A device made before, used instead of making one (a front end that draws many times keeps one
  // device: the Python module's Renderer). Its validation messages are cleared first.
  std::shared_ptr<VulkanContext> context;
  std::string mode = "auto";         // a mode name (modeName) or "auto"
  std::optional<Backend> backend;    // none: auto (backendFor)
  std::string device = "auto";       // ContextOptions::device
  bool validate = false;             // the Khronos validation layer; messages come back in the outcome
  uint64_t max_device_memory = 0;    // 0: what the device has
  CameraSpec camera;                 // the picture's size and the user's camera
  std::optional<double> point_size;  // pixels; none: pointSizeFor's choice
  std::optional<bool> round_points;  // RenderOptions::round_points; none: round for a 3D set
  // A mesh input (triangles): draw points sampled on its surface (ops/mesh_sample.h). kAuto: when its
  // vertices are sparser on screen than the picture's pixels (meshSurfaceSamples).
  SurfaceChoice surface = SurfaceChoice::kAuto;
  uint32_t background_rgba8 = 0xff000000u;
  std::optional<Shading> shading;    // none: shadingFor's choice
  EdlOptions edl;
  RenderColor color = RenderColor::kAuto;
  std::string color_attribute;       // kAttribute: the dimension's name
  UpAxis up_axis = UpAxis::kAuto;
  PointOrder order = PointOrder::kInput;
  uint32_t views = 1;                // 1, or 4: a contact sheet of four labelled views
  bool error = false;                // measure the error against the exact CPU reference
  bool report = false;               // a report (renderReportJson) is wanted: one view only
  uint32_t frames = 1;
  WarmupRequest warmup;              // --warmup (auto by default)
  double tolerance_px = kDefaultTolerancePx;  // adaptive mode's tier choice (--tolerance)
  uint64_t chunk_points = 0;         // most points per draw; 0: as the device allows
  NativePath native_path = NativePath::kAuto;
  std::string stream = "auto";       // auto|on|off (openPointStream)
  std::vector<std::string> columns = {};  // text input: what each column holds (`--columns`)
  uint64_t max_memory = 0;           // host memory limit in bytes; 0: half of RAM
  unsigned threads = 0;
};

// -o: a place the picture can be written (AtomicFile::checkTarget's errors), as PNG (a .png name,
// or a device such as /dev/null; kUsage).
Status checkPictureOutput(const std::string& path);
// --mode: auto or a mode name (kUsage, listing them).
Status checkModeName(const std::string& mode);
// --views: 1 or 4 (kUsage).
Status checkViewCount(uint32_t views);
// The request's combinations: --views 1 or 4, and 4 only with the fitted perspective camera and
// without --error or a report; a known mode name. kUsage, naming the flags.
Status checkRenderRequest(const RenderRequest& request);

// Host and device bytes per pixel at most: colour and depth (or the compute backend's 64-bit key
// and packed picture), the readback buffer, the host image and, with --error, the reference raster.
inline constexpr uint64_t kPictureBytesPerPixel = 32;

// Where a run's wall time goes, step by step (the time to a picture).
class RenderPhases {
 public:
  void mark(const char* name);
  const std::vector<std::pair<const char*, double>>& list() const { return list_; }  // milliseconds

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
  std::vector<std::pair<const char*, double>> list_;
};
// The process's peak resident memory so far, in MB.
double peakRssMb();

// What the run predicted for its mode: the bound, and with --mode auto the choice made.
struct ModePrediction {
  PrecisionMode mode = kFallbackMode;
  double bound_px = 0.0;             // +inf: unbounded
  // A streamed set's bound is from the boxes of its batches (predictBoxBounds), the points being read
  // once while they are drawn: an upper bound of the one its points would give.
  bool from_boxes = false;
  std::optional<ModeChoice> choice;  // --mode auto
  std::string warning;               // the picture is likely wrong in this mode (predictionWarning); or empty
  // The mode's encoding, made for the bound (same camera and tolerance), which renderPoints takes
  // rather than making it again; null: none was made (a streamed set, or the mode refuses the set).
  std::shared_ptr<const ModeEncoding> encoding;
};

// Over this predicted bound a forced --mode draws a wrong picture (points half a pixel or more off),
// and the run says so; --mode auto itself holds to kAutoBoundPx.
inline constexpr double kWrongBoundPx = 0.5;
// Under this share of its pixels drawn, a picture shows the data as a speck, and the run says so.
inline constexpr double kPoorCoverShare = 0.01;

// The warning of a prediction: a forced mode whose bound is over kWrongBoundPx (naming the mode
// --mode auto picks, `auto_mode`), or --mode auto with no mode within kAutoBoundPx; else empty.
std::string predictionWarning(const RenderRequest& request, const ModePrediction& prediction,
                              std::optional<PrecisionMode> auto_mode);
// The warning of a picture that shows nothing (share 0) or under kPoorCoverShare of it; else empty.
// drawn_share and drawn_span are DrawnPixels' share() and span() (image/image.h).
// A speck (drawn_span under a half) asks for a closer frame; data that spans the picture but whose
// points are sparse at this size asks for larger points instead.
std::string coverWarning(double drawn_share, double drawn_span = 0.0);

// A view of a contact sheet: its label and the fit's direction (target to eye) and up.
struct RenderView {
  const char* label;
  glm::dvec3 direction, up;
};
// One view: the three-quarter one; four: front, side, top, three-quarter. Directions are in the
// up axis's frame: with z up, "front" looks along +y and the oblique view sits in front, above.
std::vector<RenderView> viewsFor(uint32_t count, bool z_up);
// The up axis the request's views use (UpAxis::kAuto: z when every input is .las, or when the data
// records z up: PointSet::z_up, a PLY written from LAS).
bool zUpFor(const RenderRequest& request, bool data_z_up = false);
// The camera of each view: the request's own for one y-up view, else fitted along the view's
// direction; four views get a quarter of the picture each.
Result<std::vector<Camera>> viewCameras(const RenderRequest& request, const std::vector<RenderView>& views,
                                        const Bounds& bounds, bool z_up);

// Backend auto: compute wherever the device runs it for this set and picture (64-bit atomics, the
// colours and the per-pixel keys each in one storage buffer), else raster. Compute draws the same
// picture (points of every size: shaders/render/points_splat.comp) and is the faster on lavapipe and
// on GPUs with a small graphics front end.
Backend backendFor(const RenderRequest& request, size_t count, uint32_t width, uint32_t height, const DeviceFacts& facts);

// Shading auto: eye-dome lighting for a 3D set, none for a 2D one and with --error.
Shading shadingFor(const RenderRequest& request, const Bounds& bounds);
// Point size auto: from the spacing of the points on screen (`spacing`: the set's samples,
// sampleSpacing), or for a streamed set (no samples) from the count over the outline; 1 with --error.
float pointSizeFor(const RenderRequest& request, size_t count, const Bounds& box, const Camera& camera,
                   const DeviceFacts& facts, std::span<const SpacingSample> spacing = {});

// Points the probe measured: visible in the reference and not lost. With none, there is no error
// to report (null, never a perfect 0).
inline bool anyMeasured(const ErrorStats& e) { return e.points > e.lost; }

// One rendered view of a contact sheet (--views 4).
struct SheetView {
  std::string label;
  ModePrediction prediction;
  std::vector<double> gpu_ms;
};

struct RenderOutcome {
  Image image;                 // the picture (the contact sheet with four views)
  // The device it ran on, kept open for the caller: destroyed with the outcome, after the
  // picture is written (its teardown is no part of the run's phases).
  std::shared_ptr<VulkanContext> context;  // the request's own, when it gave one
  size_t points = 0;
  bool streamed = false;       // drawn a block at a time (its bound from batch boxes, no --error)
  uint64_t points_read_again = 0;  // streamed: the points its outline and spacing read a second time
  // Streamed in one pass, then read again whole: the whole set wanted another mode than its preview
  // did, or (3D, no colours) its elevation colours.
  bool read_twice = false;
  DeviceFacts device;
  Backend backend = Backend::kRaster;  // the one that ran (backendFor with --backend auto)
  std::vector<std::string> validation_messages;  // with `validate`: any fails the run
  // What makes the picture wrong or poor, one line each (no "warning:" prefix): a forced mode
  // whose bound is over kWrongBoundPx, --mode auto with no mode within its limit, a picture drawn
  // on under 1% of its pixels or on none ("view LABEL: " first for a view of a sheet).
  std::vector<std::string> warnings;
  // What the readers read past (ReadOptions::notices: a PCD's points without a return, a LAS
  // file's extra bytes record it cannot follow), one line each.
  std::vector<std::string> notices;
  double drawn_share = std::nan("");  // one view: the share of pixels drawn (DrawnPixels::share)
  // One view:
  ModePrediction prediction;
  float point_size = 1.0f;
  Shading shading = Shading::kNone;
  RenderResult result;         // timings and counts (its image moved to `image`)
  std::optional<ErrorReport> error;
  RenderPhases phases;
  // Four views:
  std::vector<SheetView> views;
  // A COPC input: the points, bytes and nodes its view read (readCopcPoints).
  std::optional<CopcReadStats> copc;
  // The set as read, destroyed on a thread of its own while the picture is written; the outcome
  // waits for it when it is destroyed.
  ReleaseInBackground read_set;
};

// Runs the request: checks it, reads (or streams) the input, makes the device, picks the mode and
// the views, renders, measures the error. `view_done` (may be empty) hears of each view of a
// contact sheet as it is drawn. The picture is not written: writeRenderPicture does it.
Result<RenderOutcome> runRenderJob(const RenderRequest& request, Progress& progress,
                                   const std::function<void(const SheetView&)>& view_done = {});

// Writes the outcome's picture as PNG and counts the time as the phase "png".
Status writeRenderPicture(const std::string& path, RenderOutcome& outcome);

// The JSON report of one view (render's --json), with the peak memory at the time of the call.
std::string renderReportJson(const RenderRequest& request, const RenderOutcome& outcome);

}  // namespace dpoint
