// What `dpoint bench` runs (issue #10; docs/performance.md): the suites as lists of cases. A case is one
// dataset, made by `dpoint generate` with the arguments given here (or written out literally for the
// degenerate sets no generator makes), seen from one view at one resolution. Every case is run in
// every precision mode on every backend asked for; each run is timed and measured against the
// exact reference.
//
//   ci     small sets of every family and small versions of the hard cases (their sweeps every other
//          decade): minutes on lavapipe
//   paper  the study's datasets at its sizes, 1920×1080, with its RTX 3090 figures beside ours
//   hard   docs/precision.md, the hard cases: the offset sweep 1e0 … 1e8 (and the Earth's radius), the deep-zoom sweep
//          1e-1 … 1e-15, tiny (1e-40, 1e-300), the Mandelbulb through its origin, degenerate sets
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/result.h"
#include "viewer/camera.h"

namespace dpoint {

enum class BenchSuite { kCi, kPaper, kHard };
std::string_view suiteName(BenchSuite suite);

// How a case's camera is set from its data's bounds.
struct BenchView {
  enum class Kind {
    kFit,     // the whole box, as `dpoint render --fit` frames it
    kNear,    // perspective from the box centre + distance·(0.1, 0.2, 1), looking at the centre, y up
    kWindow,  // orthographic window `window_width` wide around `window_center`
  };
  Kind kind = Kind::kFit;
  double distance = 0.0;
  glm::dvec3 window_center{0.0};
  double window_width = 0.0;
};

// One row of the study's tables for one precision path, both columns as the paper prints them
// (text, not numbers: one cell reads "31.12.16"); empty where it prints nothing.
struct StudyCells {
  std::string rendering_time_ms;  // "Rendering Time": the paper does not say what it covers
  std::string fps;                // "Frame Rate": the column to compare our per-frame time with
  bool empty() const { return rendering_time_ms.empty() && fps.empty(); }
};

// The study's RTX 3090 figures for a dataset: Table 2 (emulated double, its float hi/lo split) and
// Table 3 (native double), or, for the 10M 2D set, the native frame rate a figure caption gives.
struct StudyFigures {
  StudyCells emulated;  // Table 2
  StudyCells native;    // Table 3
  std::string source;   // "Tables 2 and 3", "figure caption"
};

// The sweeps breakdown.svg draws: x is the view width (deep zoom) or the offset.
enum class Sweep { kNone, kDeepZoom, kOffset };

struct BenchCase {
  BenchSuite suite = BenchSuite::kCi;
  std::string family;   // the panel of speed_vs_error.svg: "2D random", "Mandelbulb", …, "offset", "deep zoom"
  std::string name;     // unique within the suite: "Sierpinski 16.7M", "offset 1e+06", "deep zoom 1e-12"
  std::string size_label;  // the study's size label ("16.7M"), matched by --sizes; empty for hard cases
  std::vector<std::string> generate;  // `dpoint generate` arguments, kind first; empty: `literal_csv`
  std::string literal_csv;            // the dataset as CSV text, for sets no generator makes
  BenchView view;
  uint32_t width = 1920, height = 1080;
  Sweep sweep = Sweep::kNone;
  double sweep_x = 0.0;
  std::optional<StudyFigures> study;
  bool hard = false;     // one of the hard cases (docs/precision.md) (reported by error), not a speed dataset
  bool montage = false;  // the view montage.png shows in every mode
};

// The cases of a suite, in the order they run.
std::vector<BenchCase> suiteCases(BenchSuite suite);

// Whether `label` (from --sizes) names the case's size: case-insensitive, "16.7m" is "16.7M".
bool hasSizeLabel(const BenchCase& bench_case, std::string_view label);

// The file the case's dataset is cached in, inside the cache folder: a name made of the generate
// arguments (so a change of arguments never reuses a stale file), ".ply" (binary: fast to read).
std::string cacheFileName(const BenchCase& bench_case);

// The camera of a case for data with these bounds.
CameraSpec cameraSpecFor(const BenchCase& bench_case, const Bounds& bounds);

}  // namespace dpoint
