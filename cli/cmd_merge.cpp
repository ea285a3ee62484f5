// dpoint merge TILE... -o OUT: the parts of `dpoint generate KIND --tile I/N` welded into the file
// one `dpoint generate KIND` writes with the same output options, byte for byte (converters/tile_file.h).
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "cli/cli_check.h"
#include "cli/cli_output.h"
#include "cli/commands.h"
#include "converters/point_io.h"
#include "core/memory.h"
#include "ops/point_order.h"
#include "converters/tile_file.h"

namespace dpoint {
namespace {

struct MergeOptions {
  std::vector<std::string> inputs;
  std::string output;
  int decimals = -1;
  std::string max_memory;
  std::string order = "input";
  CommonOptions common;
};

int runMerge(const MergeOptions& o) {
  Result<PointOrder> order = parsePointOrder("--order", o.order);
  if (!order) return reportError(order.error());
  // No tile is replaced by the merge (README, exit codes): the set would no longer be whole.
  std::vector<std::pair<std::string, std::string>> tiles;
  for (const std::string& tile : o.inputs) tiles.push_back({"a tile", tile});
  if (Status s = checkNotAlso("-o", o.output, tiles); !s) return reportError(s.error());
  uint64_t limit = 0;
  if (!o.max_memory.empty()) {
    Result<uint64_t> parsed = parseMemorySize("--max-memory", o.max_memory);
    if (!parsed) return reportError(parsed.error());
    limit = *parsed;
  }
  Progress progress(progressSink(o.common.quiet), "merge");
  // A binary PLY in the tiles' order is streamed from the parts (the same bytes, without the set
  // in memory); other formats and orders take the whole set first.
  PlyWriteOptions ply;
  ply.progress = &progress;
  ply.threads = o.common.threads;
  Result<FileFormat> format = formatOf(o.output);
  if (format && *format == FileFormat::kPly && *order == PointOrder::kInput && canMergeToPly(ply)) {
    if (Status s = mergeTilesToPly(o.inputs, o.output, ply, limit); !s) return reportError(s.error());
    return 0;
  }
  // For a format without triangles the tiles' face rows are not read.
  Result<PointSet> merged = mergeTiles(o.inputs, limit, &progress, o.common.threads, !format || holdsTriangles(*format));
  if (!merged) return reportError(merged.error());
  PointSet& points = *merged;
  // From here on as `dpoint generate` finishes a whole set (cli_generate_output.cpp: finish).
  if (Status s = checkReorderMemory(points, *order, limit); !s) return reportError(s.error());
  reorderPoints(points, *order, o.common.threads, &progress);
  WriteOptions w;
  w.threads = o.common.threads;
  w.decimals = o.decimals;
  w.progress = &progress;
  if (Status s = writePointsWithNotes(o.output, points, w); !s) return reportError(s.error());
  return 0;
}

}  // namespace

void addMergeCommand(CLI::App& app, RunCommand& run) {
  auto o = std::make_shared<MergeOptions>();
  CLI::App* cmd = app.add_subcommand(
      "merge",
      "Weld the tiles of `dpoint generate KIND --tile I/N` (all N, in any order) into one file: the same bytes\n"
      "as the single `dpoint generate KIND` with these output options, vertex order included");
  cmd->add_option("tiles", o->inputs, "The tile parts (.ply)")->required();
  cmd->add_option("-o,--output", o->output, pointOutputHelp())->required()->check(checkStatus(checkPointOutput));
  cmd->add_option("--decimals", o->decimals, "CSV: fixed digits after the point of coordinates and 0..1 colours (default: shortest round trip)")
      ->check(CLI::Range(0, 100));
  cmd->add_option("--max-memory", o->max_memory, "Refuse (exit 4) when the estimate is above this (default: half of RAM)");
  cmd->add_option("--order", o->order, kPointOrderHelp)->default_val("input");
  addCommonOptions(*cmd, o->common);
  cmd->callback([o, &run] { run = [o] { return runMerge(*o); }; });
}

}  // namespace dpoint
