// dpoint convert IN -o OUT: CSV, PLY and GLB in any direction (glTF input is read as a first
// version; full glTF coverage is issue #4).
#include <memory>

#include "cli/commands.h"
#include "converters/point_io.h"

namespace dpoint {
namespace {

struct ConvertOptions {
  std::string input, output;
  int decimals = -1;
  bool ply_ascii = false;
  std::string ply_colors = "uchar";
  bool allow_nonfinite = false;
  bool no_colors = false;
  CommonOptions common;
};

int runConvert(const ConvertOptions& o) {
  Progress progress(progressSink(o.common.quiet), "convert");
  Result<PointSet> points = readPoints(o.input, ReadOptions{o.common.threads, o.allow_nonfinite, &progress});
  if (!points) return reportError(points.error());
  if (o.no_colors) points->colors.clear();
  WriteOptions w;
  w.threads = o.common.threads;
  w.decimals = o.decimals;
  w.ply_encoding = o.ply_ascii ? PlyEncoding::kAscii : PlyEncoding::kBinary;
  w.ply_colors = o.ply_colors == "float" ? PlyColorType::kFloat : PlyColorType::kUchar;
  w.progress = &progress;
  if (Status s = writePoints(o.output, *points, w); !s) return reportError(s.error());
  return 0;
}

}  // namespace

void addConvertCommand(CLI::App& app, RunCommand& run) {
  auto o = std::make_shared<ConvertOptions>();
  CLI::App* cmd = app.add_subcommand("convert", "Convert a point set or mesh between .csv, .ply and .glb");
  cmd->add_option("input", o->input, "Input file (.csv, .ply, .glb, .gltf)")->required();
  cmd->add_option("-o,--output", o->output, "Output file (.csv, .ply, .glb); written whole or not at all")->required();
  cmd->add_option("--decimals", o->decimals,
                  "CSV: fixed digits after the point (15 gives the seed's %.15f); default: shortest round trip")
      ->check(CLI::Range(0, 100));
  cmd->add_flag("--ply-ascii", o->ply_ascii, "PLY: write ASCII instead of binary little-endian");
  cmd->add_option("--ply-colors", o->ply_colors, "PLY: colour property type")
      ->check(CLI::IsMember({"uchar", "float"}))
      ->default_val("uchar");
  cmd->add_flag("--allow-nonfinite", o->allow_nonfinite, "Accept nan/inf coordinates instead of rejecting them");
  cmd->add_flag("--no-colors", o->no_colors, "Drop colours");
  addCommonOptions(*cmd, o->common);
  cmd->callback([o, &run] { run = [o] { return runConvert(*o); }; });
}

}  // namespace dpoint
