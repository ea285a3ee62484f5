#include "cli/cli_generate_output.h"

#include <cassert>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "cli/cli_check.h"
#include "cli/cli_output.h"
#include "cli/cli_run.h"
#include "cli/cli_text.h"
#include "converters/point_io.h"
#include "converters/tile_file.h"
#include "ops/mesh_sample.h"
#include "core/memory.h"
#include "generators/generate.h"
#include "generators/perlin.h"

namespace dpoint {
namespace {

PointColors pointColorsOf(const OutputOptions& o) {
  return o.colors == "noise" ? PointColors::kNoise : o.colors == "none" ? PointColors::kNone : PointColors::kAuto;
}

// --offset, 0 when not given.
Result<glm::dvec3> offsetOf(const OutputOptions& o) {
  return o.offset.empty() ? Result<glm::dvec3>(glm::dvec3(0.0)) : parseVec3("--offset", o.offset);
}

// Colours and offset (generators/generate.h): the steps after any generator that act point by point.
Status colorAndOffset(PointSet& points, const OutputOptions& o, bool auto_noise) {
  Result<uint64_t> limit = memoryLimit(o);
  if (!limit) return limit.error();
  const PointColoring coloring{pointColorsOf(o), auto_noise, o.common.threads, *limit};
  if (Status s = colorGenerated(points, coloring); !s) return s;
  if (o.offset.empty()) return okStatus();
  Result<glm::dvec3> offset = offsetOf(o);
  if (!offset) return offset.error();
  return offsetPoints(points, *offset);
}

// The set's vertices go to a .ply written here (not handed back), as they are (no --sample).
bool plyWrittenHere(const OutputOptions& o) {
  Result<FileFormat> format = formatOf(o.output);
  return !capturingPoints() && format && *format == FileFormat::kPly && o.sample.count == 0;
}

}  // namespace

void addOutputOptions(CLI::App& cmd, OutputOptions& o, const std::string& auto_colors) {
  CLI::Option* output = cmd.add_option("-o,--output", o.output, pointOutputHelp())->check(checkStatus(checkPointOutput));
  if (!capturingPoints()) output->required();
  cmd.add_option("--colors", o.colors, "Colours: auto (" + auto_colors + "), noise (Perlin pnoise3, as the original study's Python generator coloured its points), none")
      ->check(oneOf("--colors", {"auto", "noise", "none"}))
      ->default_val("auto");
  cmd.add_option("--offset", o.offset, "Translate every point by X,Y,Z (exact double sums, one rounding)");
  cmd.add_option("--decimals", o.decimals, "CSV: fixed digits after the point of coordinates and 0..1 colours (default: shortest round trip)")
      ->check(CLI::Range(0, 100));
  addMaxMemoryOption(cmd, o.max_memory);
  cmd.add_option("--order", o.order, kPointOrderHelp)->default_val("input");
  cmd.add_option("--tile", o.tile,
                 "I/N: compute only tile I (from 0) of N (1 to " + std::to_string(kMaxTiles) +
                     ") of the set, into a .ply part that `dpoint merge` welds with\n"
                 "the others into the file one process writes, byte for byte (--order then goes to merge; --sample\n"
                 "and --decimals to the merged file)")
      // An empty value wrote the whole set as if no --tile were given (a review finding).
      ->check(check([](const std::string& v) { return v.empty() ? std::string("--tile: empty; give I/N, e.g. 0/4") : ""; }));
  addCommonOptions(cmd, o.common);
}

Result<uint64_t> memoryLimit(const OutputOptions& o) { return memoryLimitOf(o.max_memory); }

double PhaseClock::lap() {
  const auto now = std::chrono::steady_clock::now();
  const double s = std::chrono::duration<double>(now - last_).count();
  last_ = now;
  return s;
}

// Colours, offset, order and writing (or handing the set back, capturePoints): the steps after any
// generator. Unless quiet, one line of where the time went (generation counted from `clock`'s start,
// before the parameters).
int finish(Result<PointSet> generated, const OutputOptions& o, PointOrder order, bool auto_noise, Progress& progress,
           PhaseClock& clock, bool noise_made) {
  if (!generated) return reportError(generated.error());
  const double generate_s = clock.lap();
  PointSet& points = *generated;
  // Colours made with the mesh are the noise's already, and there is no --offset (coloursAtWrite).
  const bool colours_made = noise_made && points.hasColors();
  const bool colours_at_write = coloursAtWrite(o, auto_noise) && !colours_made;
  if (colours_at_write) {
    ColorArray().swap(points.colors);
  } else if (!colours_made) {
    if (Status s = colorAndOffset(points, o, auto_noise); !s) return reportError(s.error());
  }
  if (o.sample.count != 0) {  // on the coloured, offset mesh: colours interpolate, positions are in their frame
    Result<uint64_t> limit = memoryLimit(o);
    if (!limit) return reportError(limit.error());
    const SampleOptions sample = sampleOptionsOf(o.sample, o.common.threads, *limit, &progress);
    Result<PointSet> sampled = sampleSurface(points, sample, "the generated mesh");
    if (!sampled) return reportError(sampled.error());
    points = std::move(*sampled);
  }
  const double colours_s = clock.lap();
  if (order != PointOrder::kInput) {
    Result<uint64_t> limit = memoryLimit(o);
    if (!limit) return reportError(limit.error());
    if (Status s = checkReorderMemory(points, order, *limit); !s) return reportError(s.error());
    reorderPoints(points, order, o.common.threads, &progress);
  }
  const double order_s = clock.lap();
  if (capturingPoints()) {
    if (!o.common.quiet)
      std::fprintf(stderr, "time (s): generate %.2f, colours and offset %.2f, order %.2f; %zu points, %zu triangles\n",
                   generate_s, colours_s, order_s, points.size(), points.triangles.size() / 3);
    capturePoints(std::move(points));
    return 0;
  }
  WriteOptions w;
  w.threads = o.common.threads;
  w.decimals = o.decimals;
  w.progress = &progress;
  if (colours_at_write) w.colors_of = seedColors;
  if (Status s = writePointsWithNotes(o.output, points, w); !s) return reportError(s.error());
  if (!o.common.quiet)
    std::fprintf(stderr, "time (s): generate %.2f, colours and offset %.2f, order %.2f, write %.2f; %zu points, %zu triangles%s\n",
                 generate_s, colours_s, order_s, clock.lap(), points.size(), points.triangles.size() / 3,
                 colours_at_write ? "; the colours made as the rows were written"
                 : colours_made   ? "; the colours made with the mesh on the device"
                                  : "");
  return 0;
}

// Whether the noise colours are made as the PLY writer formats the rows (PlyWriteOptions::colors_of)
// rather than before: the same file, without the colours' own pass over the set or their 12 bytes
// a point. They need a .ply written here (plyWrittenHere: no --sample interpolating them), noise
// colours, and the positions as written being those coloured (no --offset after the colours). A
// reorder is no obstacle: a colour is a function of its point's position.
bool coloursAtWrite(const OutputOptions& o, bool auto_noise) {
  return noiseColors(pointColorsOf(o), auto_noise) && plyWrittenHere(o) && o.offset.empty();
}

bool canFinishMade(const OutputOptions& o, bool auto_noise) {
  return plyWrittenHere(o) && (!noiseColors(pointColorsOf(o), auto_noise) || coloursAtWrite(o, auto_noise));
}

int finishMade(const PointFunction& made, const OutputOptions& o, PointOrder order, bool auto_noise, Progress& progress,
               PhaseClock& clock) {
  assert(canFinishMade(o, auto_noise));
  const double generate_s = clock.lap();
  Result<uint64_t> limit = memoryLimit(o);
  if (!limit) return reportError(limit.error());
  Result<glm::dvec3> parsed = offsetOf(o);
  if (!parsed) return reportError(parsed.error());
  const glm::dvec3 offset = *parsed;
  // As offsetPoints adds it: one rounding a coordinate. z stays +0 (a 2D set) only where the
  // offset's z is ±0.
  std::function<glm::dvec3(uint64_t)> at = made.at;
  if (offset != glm::dvec3(0.0)) at = [&made, offset](uint64_t i) { return made.at(i) + offset; };
  PointSet facts;
  facts.z_axis = made.z_present || offset.z != 0.0 ? ZAxis::kPresent : ZAxis::kAbsent;
  const double colours_s = clock.lap();

  WriteOptions w;
  w.threads = o.common.threads;
  w.progress = &progress;
  if (coloursAtWrite(o, auto_noise)) w.colors_of = seedColors;
  std::optional<MortonRows> rows;
  if (order == PointOrder::kMorton) {
    if (Status s = checkOrderable(made.count); !s) return reportError(s.error());
    if (Status s = checkMemory("ordering " + std::to_string(made.count) + " points", mortonRowsBytes(made.count), *limit); !s)
      return reportError(s.error());
    rows = mortonRows(made.count, at, o.common.threads, &progress);
  }
  // Row r is point r, or in Morton order the point the rows name.
  w.positions_of = {made.count, [&rows, &at](size_t begin, size_t end, glm::dvec3* out) {
                      for (size_t r = begin; r < end; ++r) out[r - begin] = at(rows ? rows->source(r) : r);
                    }};
  const double order_s = clock.lap();
  if (Status s = writePointsWithNotes(o.output, facts, w); !s) return reportError(s.error());
  if (!o.common.quiet)
    std::fprintf(stderr, "time (s): generate %.2f, colours and offset %.2f, order %.2f, write %.2f; %llu points, 0 triangles; "
                 "the points made as the rows were written\n",
                 generate_s, colours_s, order_s, clock.lap(), static_cast<unsigned long long>(made.count));
  return 0;
}

bool canStreamRows(const OutputOptions& o, PointOrder order, bool auto_noise) {
  return plyWrittenHere(o) && order == PointOrder::kInput && o.offset.empty() &&
         (coloursAtWrite(o, auto_noise) || pointColorsOf(o) == PointColors::kNone);
}

Result<std::unique_ptr<PlyRowStream>> rowStream(const OutputOptions& o, bool colors, Progress& progress) {
  return PlyRowStream::create(o.output, colors, o.common.threads, &progress);
}

namespace {

// The generator's sink into a PlyRowStream or a TileRowStream (their start and add).
template <typename Stream>
EscapeRowSink sinkInto(Stream& stream, bool colors, bool float_colors) {
  EscapeRowSink sink;
  sink.colors = colors;
  sink.float_colors = float_colors;
  sink.start = [&stream](uint64_t vertices, uint64_t triangles) { return stream.start(vertices, triangles); };
  sink.slab = [&stream](std::span<const uint8_t> vertex_rows, std::span<const uint8_t> face_rows) {
    return stream.add(vertex_rows, face_rows);
  };
  return sink;
}

}  // namespace

EscapeRowSink rowSink(PlyRowStream& stream) { return sinkInto(stream, stream.colors(), false); }

namespace {

// The time line of a set whose rows went to `stream`, once it is finished (`generate_s` before).
void reportRows(const PlyRowStream& stream, const OutputOptions& o, double generate_s, PhaseClock& clock) {
  if (!o.common.quiet)
    std::fprintf(stderr,
                 "time (s): generate %.2f, colours and offset 0.00, order 0.00, write %.2f; %llu points, %llu triangles%s; "
                 "the rows made on the device and written as they came%s\n",
                 generate_s, clock.lap(), static_cast<unsigned long long>(stream.vertices()),
                 static_cast<unsigned long long>(stream.faces()),
                 stream.colors() ? "; the colours made with the mesh on the device" : "",
                 stream.moved() ? " (the header laid out first had another length: the vertex rows were moved)" : "");
}

}  // namespace

int finishRows(Result<PointSet> generated, PlyRowStream& stream, const OutputOptions& o, PhaseClock& clock) {
  if (!generated) return reportError(generated.error());
  assert(stream.started() && generated->size() == 0);
  const double generate_s = clock.lap();
  if (Status s = stream.finish(); !s) return reportError(s.error());
  reportRows(stream, o, generate_s, clock);
  return 0;
}

Result<std::unique_ptr<TileRowStream>> tileRowStream(const OutputOptions& o, TileSpec tile, const std::string& signature,
                                                     bool colors, Progress& progress) {
  return TileRowStream::create(o.output, tile, signature, colors, o.common.threads, &progress);
}

EscapeRowSink tileRowSink(TileRowStream& stream) {
  const bool colors = stream.rows().colors();
  return sinkInto(stream, colors, colors);  // a part's colours are floats
}

int finishTileRows(Result<PointTile> generated, TileRowStream& stream, const OutputOptions& o, PhaseClock& clock) {
  if (!generated) return reportError(generated.error());
  assert(stream.rows().started() && generated->points.size() == 0);
  const double generate_s = clock.lap();
  if (Status s = stream.finish(generated->owned, generated->foreign); !s) return reportError(s.error());
  reportRows(stream.rows(), o, generate_s, clock);
  return 0;
}

// A tile: colours and offset on its points, then its part file.
int finishTile(Result<PointTile> generated, const OutputOptions& o, bool auto_noise, const std::string& signature,
               Progress& progress) {
  if (!generated) return reportError(generated.error());
  if (Status s = colorAndOffset(generated->points, o, auto_noise); !s) return reportError(s.error());
  if (Status s = writeTile(o.output, *generated, signature, &progress, o.common.threads); !s) return reportError(s.error());
  return 0;
}

Status checkHandedBack(const OutputOptions& o) {
  if (!capturingPoints()) return okStatus();
  const char* handed_back = "this run hands the points back to its caller instead of writing them";
  if (!o.output.empty()) return Error{"-o " + o.output + ": " + handed_back, ExitCode::kUsage};
  if (!o.tile.empty())
    return Error{"--tile " + o.tile + ": a tile is a part file for dpoint merge; " + handed_back, ExitCode::kUsage};
  if (o.decimals >= 0)
    return Error{"--decimals " + std::to_string(o.decimals) + " says how a CSV is written; " + handed_back,
                 ExitCode::kUsage};
  return okStatus();
}

// --tile checks before any work: a .ply part, and no --order (which needs the whole set).
Result<TileSpec> tileOptions(const OutputOptions& o) {
  Result<TileSpec> tile = parseTileSpec("--tile", o.tile);
  if (!tile) return tile.error();
  Result<FileFormat> format = formatOf(o.output);
  if (!format || *format != FileFormat::kPly)
    return Error{"--tile: -o " + o.output + ": a tile is written as .ply (dpoint merge makes any of " + std::string(kPointOutputFormats) + ")",
                 ExitCode::kUsage};
  if (o.order != "input")
    return Error{"--tile: --order " + o.order + " needs the whole set; give it to dpoint merge", ExitCode::kUsage};
  if (o.sample.count != 0)
    return Error{"--tile: --sample needs the whole mesh; sample the merged file with dpoint convert --sample", ExitCode::kUsage};
  return tile;
}

}  // namespace dpoint
