// One `dpoint info` report as a library call. A front end (the CLI, a Python module) describes a
// set in memory (describePoints), a stream read a block at a time (describeStream) or the files of
// `dpoint info FILE...` (describeFiles) and gets back an InfoReport: the facts ops/info computes
// (counts, bounds, float32 spacing, nearest neighbours, what float32 merges), each render mode's
// predicted error for one view, and a LAS file's header. infoReportText and infoReportJson are
// `dpoint info`'s output and `dpoint info --json`'s, so every front end gives the same facts in
// the same words. Nothing here prints; progress goes to the caller's Progress.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "converters/las.h"
#include "converters/point_inputs.h"
#include "converters/point_io.h"
#include "core/point_set.h"
#include "core/progress.h"
#include "core/result.h"
#include "ops/info.h"
#include "viewer/camera.h"
#include "viewer/precision.h"

namespace dpoint {

// How the facts are computed: info's --sample, the camera options and --tolerance, --threads.
struct InfoOptions {
  CameraSpec camera;                 // the view whose error bounds are predicted (--fit by default)
  size_t sample = 10000;             // points sampled for the nearest-neighbour distance (≥ 1)
  double tolerance_px = kDefaultTolerancePx;  // adaptive mode's tier choice, which its bound follows
  unsigned threads = 0;              // 0: all cores; the report does not depend on it
  // --up-axis: the data's up for the fitted view, as `dpoint render` takes it; unset (auto): z for
  // a set that records z up (LAS, a PLY written from LAS) and, streamed, for .las/.laz input.
  std::optional<bool> z_up;
  // A stream's points a block (describeStream; the report is the same whatever it is):
  // streamBlockPoints of --max-memory; 0: viewer/render.h's kStreamBlockPoints.
  uint64_t stream_block = 0;
  // The stream's first pass reads the dimensions every file has, for their ranges; false where
  // their columns do not fit the block's memory (they are listed without ranges).
  bool stream_ranges = true;
};

// Every mode's predicted error for one view (viewer/precision.h).
struct InfoAdvice {
  Camera camera;
  ErrorBounds bounds;  // from the points, or for a streamed set from its batches' boxes (from_boxes)
};

// A LAS file's header (converters/las.h), and whether its bounds hold the points read.
struct LasFacts {
  LasHeader header;
  bool bounds_hold = true;
  std::string crs;  // lasCrsSummary of its CRS records; empty: none
};

// A dimension of the set (core/dimensions.h) and its range; min > max where the set is empty.
struct DimensionRange {
  std::string name;
  DimType type = DimType::kF64;
  double min = 0.0, max = 0.0;
};

struct InfoReport {
  std::string name;                  // the set's name in the report ("file"): the caller's
  PointSetInfo info;
  std::vector<DimensionRange> dimensions;  // a streamed set's: those every file has
  // Read a block at a time: float32's merged points, which need every point at once, are not
  // counted (info.float_merged stays 0, the JSON says null) and the bounds are from boxes.
  bool streamed = false;
  std::optional<LasFacts> las;       // one LAS file only
  std::string crs;                   // the coordinate system another format stated (PointSet::crs, E57's)
  // One COPC file, read by view (describeFiles): the points, bytes and nodes its view read; the
  // facts are of those points, the LAS header's of the whole file.
  std::optional<CopcReadStats> copc;
  std::optional<InfoAdvice> advice;  // none for an empty set, or one with no view
  // Why a set of points has no view, so no bound by mode (its extent overflows a double: ±1e308);
  // the rest of the report stands. Empty otherwise.
  std::string no_view;
  // What the readers read past (ReadOptions::notices), one line each: describeFiles's; the CLI
  // prints them on stderr.
  std::vector<std::string> notices;
};

// The report of a set in memory, named `name`. Non-finite positions are taken as they are (the
// CLI reads them only with --allow-nonfinite). Fails only as makeCamera fails on the options'
// camera (kUsage).
Result<InfoReport> describePoints(const PointSet& points, const std::string& name, const InfoOptions& options);

// The report of a set read a block at a time, twice (computeStreamedInfo; `dpoint info --stream`),
// showing "reading NAME twice (points)" as progress. The bounds are predicted from the box of every
// batch (predictBoxBounds), as render predicts a streamed set's. Errors are the stream's, an
// interruption's (SIGINT/SIGTERM) and makeCamera's.
Result<InfoReport> describeStream(PointInputStream& stream, const std::string& name, const InfoOptions& options,
                                  Progress& progress);

// What `dpoint info FILE...` reads: its inputs and its reading options.
struct InfoInputs {
  std::vector<std::string> paths;    // taken as one set (point_inputs.h); none is a usage error
  std::string stream = "auto";       // auto|on|off (openPointStream)
  bool allow_nonfinite = false;      // accept nan/inf positions instead of failing
  uint64_t max_memory = 0;           // host memory limit in bytes; 0: half of RAM
  int scene = -1;                    // glTF: the scene (-1: the default), as `convert --scene`
  bool all_scenes = false;           // glTF: every scene (`--all-scenes`)
  std::vector<std::string> columns = {};  // text input: what each column holds (`--columns`)
};

// The report of the files, named describeInputs(paths): streamed (describeStream) where
// openPointStream says so, else read whole (describePoints), with the header of a single LAS file.
// A single COPC file (not --stream on) is read by view, as render reads it (copcQueryFor with the
// options' camera): only the octree's nodes its picture needs, at its resolution.
// Errors are the readers' (naming the file), and those of describePoints and describeStream.
Result<InfoReport> describeFiles(const InfoInputs& inputs, const InfoOptions& options, Progress& progress);

// `dpoint info`'s text, every line ending in '\n'.
std::string infoReportText(const InfoReport& report);
// `dpoint info --json`'s object ("file" is the name), ending in '\n'. Unbounded modes' bounds are null.
std::string infoReportJson(const InfoReport& report);

}  // namespace dpoint
