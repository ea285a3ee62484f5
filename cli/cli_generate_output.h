// The output half of `dpoint generate`, shared by every kind: the options that say where the
// points go and what is done to them after the generator (colours, offset, order), the checks made
// before any work, and the steps after it (writing the set, or a tile's part file).
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "cli/commands.h"
#include "converters/ply.h"
#include "converters/tile_file.h"
#include "core/point_set.h"
#include "core/progress.h"
#include "core/result.h"
#include "core/tile.h"
#include "generators/escape_grid.h"
#include "ops/point_order.h"

namespace dpoint {

// Options every generator shares: where the output goes and what is done to it after generation.
struct OutputOptions {
  std::string output;
  std::string tile;  // "I/N": write tile I of N (core/tile.h) instead of the whole set
  std::string colors = "auto";
  std::string offset;
  int decimals = -1;
  std::string max_memory;
  std::string order = "input";
  SampleCliOptions sample;  // --sample N (mesh kinds): N points on the surface instead of the mesh
  CommonOptions common;
};

// `auto_colors`: what --colors auto gives for the kind, for the help text. -o is checked as it is
// parsed (cli_output.h: a written format, a folder it can be written into), before any work; it is
// required unless the set is handed back to an embedding program (capturingPoints(), cli_run.h).
void addOutputOptions(CLI::App& cmd, OutputOptions& o, const std::string& auto_colors);
// --max-memory as bytes (0: half of RAM).
Result<uint64_t> memoryLimit(const OutputOptions& o);

// Seconds since the last call (the phases of the time line).
class PhaseClock {
 public:
  double lap();

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

// When the set is handed back (capturingPoints()): -o, --tile and --decimals, which say how or
// where it is written, are usage errors that say so. Before any work; ok when not capturing.
Status checkHandedBack(const OutputOptions& o);
// --tile checks before any work: a .ply part, and no --order (which needs the whole set).
Result<TileSpec> tileOptions(const OutputOptions& o);
// Whether the noise colours are made as the PLY writer formats the rows (see the .cpp).
bool coloursAtWrite(const OutputOptions& o, bool auto_noise);
// Colours, offset, order and writing (or handing the set back, capturePoints): the steps after any generator. Unless quiet, one line of
// where the time went (generation counted from `clock`'s start, before the parameters).
// noise_made: the generator was asked for the seed noise colours with the mesh (a mesher on the
// device, only where coloursAtWrite holds); where the set has colours they are those, written as
// they are.
int finish(Result<PointSet> generated, const OutputOptions& o, PointOrder order, bool auto_noise, Progress& progress,
           PhaseClock& clock, bool noise_made = false);
// Whether a surface meshed on the device can go to the file as the device's PLY rows, as it is
// made (converters/ply.h PlyRowStream): a .ply written here, in input order, no --offset, and the
// noise colours made with the mesh (coloursAtWrite) or none.
bool canStreamRows(const OutputOptions& o, PointOrder order, bool auto_noise);
// The stream and the generator's sink that feeds it (generators/escape_grid.h); the stream is null
// where the output takes no positional writes (a pipe).
Result<std::unique_ptr<PlyRowStream>> rowStream(const OutputOptions& o, bool colors, Progress& progress);
EscapeRowSink rowSink(PlyRowStream& stream);
// finish for a set whose rows went to `stream` (started): its faces and header, the time line.
int finishRows(Result<PointSet> generated, PlyRowStream& stream, const OutputOptions& o, PhaseClock& clock);
// A set whose points are a function of their index (random2d): `count` of them, point i at at(i),
// called from several threads at once; z_present when some z is not 0.
struct PointFunction {
  uint64_t count = 0;
  std::function<glm::dvec3(uint64_t)> at;
  bool z_present = false;
};
// Whether finishMade writes this output: a .ply written here (not handed back), no --sample, and
// not noise colours with an --offset (they are made from the points before the offset, which the
// writer's rows no longer hold).
bool canFinishMade(const OutputOptions& o, bool auto_noise);
// finish for a PointFunction: the same file, with no array of points held. The offset is added as
// each point is made, the Morton order is taken as rows (ops/point_order.h's mortonRows), and the
// PLY writer makes each chunk's positions, and noise colours, as it formats the rows.
int finishMade(const PointFunction& points, const OutputOptions& o, PointOrder order, bool auto_noise,
               Progress& progress, PhaseClock& clock);
// A tile: colours and offset on its points, then its part file.
int finishTile(Result<PointTile> generated, const OutputOptions& o, bool auto_noise, const std::string& signature,
               Progress& progress);
// A tile's part file as the device's rows, as it is made (converters/tile_file.h TileRowStream),
// where canStreamRows holds: the stream (null where the output takes no positional writes), its
// sink (colours as floats), and finishRows for it.
Result<std::unique_ptr<TileRowStream>> tileRowStream(const OutputOptions& o, TileSpec tile, const std::string& signature,
                                                     bool colors, Progress& progress);
EscapeRowSink tileRowSink(TileRowStream& stream);
int finishTileRows(Result<PointTile> generated, TileRowStream& stream, const OutputOptions& o, PhaseClock& clock);

}  // namespace dpoint
