// dpoint convert IN -o OUT: text, PLY, PCD, GLB and LAS in any direction, and glTF/GLB input with scene
// selection (converters/gltf_read.h says what a glTF file turns into, converters/las.h a LAS file).
#include <cstdio>
#include <memory>
#include <optional>

#include "cli/cli_check.h"
#include "cli/cli_output.h"
#include "cli/commands.h"
#include "converters/csv.h"
#include "converters/gltf_read.h"
#include "converters/las_crs.h"
#include "converters/point_io.h"
#include "core/memory.h"
#include "core/text.h"
#include "ops/mesh_sample.h"
#include "ops/point_order.h"

namespace dpoint {
namespace {

struct ConvertOptions {
  std::string input, output;
  int decimals = -1;
  bool ply_ascii = false;
  std::string ply_colors = "auto";
  std::string pcd_encoding = "binary";
  // The options themselves: whether each was given (their values have defaults).
  const CLI::Option* ply_colors_option = nullptr;
  const CLI::Option* pcd_encoding_option = nullptr;
  bool allow_nonfinite = false;
  std::string columns;  // --columns x,y,z,-,intensity
  SampleCliOptions sample;  // --sample N: points on the mesh's surface instead of its vertices
  bool no_colors = false;
  int scene = -1;
  bool all_scenes = false;
  bool unique = false;
  std::string color_format = "linear";
  uint64_t max_points = 0;
  std::string order = "input";
  double las_scale = 0.0;  // 0: the input LAS file's, else chosen from the data
  std::optional<std::string> crs;  // --crs: EPSG:CODE, WKT or a file holding it; none: the input's CRS records
  DimensionChoice dimensions;  // --keep, --drop
  std::string max_memory;
  uint64_t memory_limit = 0;  // max_memory parsed
  CommonOptions common;
};

GltfReadOptions gltfOptions(const ConvertOptions& o) {
  GltfReadOptions g;
  g.max_memory = o.memory_limit;
  g.scene = o.scene;
  g.all_scenes = o.all_scenes;
  g.allow_nonfinite = o.allow_nonfinite;
  g.max_points = o.max_points;
  g.threads = o.common.threads;
  return g;
}

// `texture`: when not null, gets a glTF mesh's base-colour textures (for --sample).
Result<PointSet> readConvertInput(const ConvertOptions& o, Progress& progress, MeshTexture* texture) {
  GltfReadOptions g = gltfOptions(o);
  // Only PLY and GLB hold triangles: for the others (CSV, PTS, PCD, LAS, LAZ, COPC) a mesh's index
  // list is not built from a glTF file, and a PLY file's triangle rows are not read where its size
  // shows them whole (PlyReadOptions::faces_unkept), unless --sample needs them: a PLY mesh to PCD
  // read its faces only to drop them.
  Result<FileFormat> out_format = formatOf(o.output);
  const bool triangles = !out_format || holdsTriangles(*out_format) || o.sample.count != 0;
  g.triangles = triangles;
  ReadOptions r{o.common.threads, o.allow_nonfinite, &progress};
  r.faces_unkept = !triangles;
  if (o.no_colors) r.las_color = LasColorSource::kNone;  // not read, nor spoken of (the filter drops a glTF's)
  r.max_memory = o.memory_limit;
  r.columns = columnsOf(o.columns);
  r.texture = texture;
  std::vector<std::string> notices;
  r.notices = &notices;
  Result<PointSet> points = readInput(o.input, r, g);
  // Notes about a file that was read; a refused file gets its one error line only.
  if (points)
    for (const std::string& notice : notices) std::fprintf(stderr, "dpoint: note: %s\n", notice.c_str());
  return points;
}

int runConvert(ConvertOptions& o) {
  Result<PointOrder> order = parsePointOrder("--order", o.order);
  if (!order) return reportError(order.error());
  // The input is not replaced by what is made of it (README, exit codes): a failed or unwanted
  // conversion would leave nothing to go back to.
  if (Status s = checkNotAlso("-o", o.output, {{"the input", o.input}}); !s) return reportError(s.error());
  Result<uint64_t> limit = memoryLimitOf(o.max_memory);
  if (!limit) return reportError(limit.error());
  o.memory_limit = *limit;
  Progress progress(progressSink(o.common.quiet), "convert");
  WriteOptions w;
  w.threads = o.common.threads;
  w.decimals = o.decimals;
  w.ply_encoding = o.ply_ascii ? PlyEncoding::kAscii : PlyEncoding::kBinary;
  w.ply_colors = parsePlyColorType(o.ply_colors).value_or(PlyColorType::kAuto);  // checked by the option
  w.pcd_encoding = *parsePcdEncoding(o.pcd_encoding);  // checked by the option's validator
  w.progress = &progress;
  w.las_scale = o.las_scale;
  // Options that would do nothing are refused, as --crs for a PLY output is (a review finding:
  // each passed silently).
  if (o.dimensions.keep && !o.dimensions.drop.empty())
    return reportError(Error{"--keep and --drop: give one of them (--keep names the dimensions that stay, --drop those "
                             "that go)",
                             ExitCode::kUsage});
  if (Status used = checkFormatOptionsUsed(o.output, {o.decimals >= 0, o.ply_ascii, o.ply_colors_option->count() > 0,
                                                      o.pcd_encoding_option->count() > 0, o.las_scale != 0.0,
                                                      o.crs.has_value()});
      !used)
    return reportError(used.error());
  if (o.crs) {
    Result<std::string> wkt = crsAsWkt(*o.crs);
    if (!wkt) return reportError(wkt.error());
    w.las_crs = std::move(*wkt);
  }
  const Result<FileFormat> out_format = formatOf(o.output);
  const bool to_csv = out_format && *out_format == FileFormat::kCsv;
  const ColorFilters filters{o.no_colors, o.color_format == "srgb8"};
  // glTF to CSV is written as the scene is walked, the same bytes as below without holding the
  // point set; --unique and --order morton need the whole set, so they take the path below.
  const Result<FileFormat> in_format = formatOf(o.input);
  const bool choose_dimensions = o.dimensions.keep || !o.dimensions.drop.empty();
  // (PTS and PTX, whose rows are not CSV's, take the path below: a review found a .ptx of CSV rows.)
  if (in_format && isGltf(*in_format) && to_csv && !isPtsPath(o.output) && !isPtxPath(o.output) && !o.unique &&
      *order == PointOrder::kInput &&
      !choose_dimensions && o.columns.empty() && o.sample.count == 0) {
    if (Status s = convertGltfToCsv(o.input, gltfOptions(o), filters, o.output, w); !s) return reportError(s.error());
    return 0;
  }
  // LAS (or LAZ) → CSV: values at the file's step (849087.70 at 0.01 is "849087.7"), unless --decimals.
  if (o.decimals < 0 && to_csv && in_format && (*in_format == FileFormat::kLas || *in_format == FileFormat::kLaz)) {
    Result<LasHeader> header = readLasHeader(o.input);
    if (!header) return reportError(header.error());
    w.decimals = lasStepDecimals(*header);
    w.decimals_at_scale = w.decimals >= 0;
  }
  MeshTexture texture;
  Result<PointSet> points = readConvertInput(o, progress, o.sample.count != 0 ? &texture : nullptr);
  if (!points) return reportError(points.error());
  if (o.sample.count != 0) {
    for (const std::string& note : texture.notes) std::fprintf(stderr, "dpoint: note: %s\n", note.c_str());
    SampleOptions sample = sampleOptionsOf(o.sample, o.common.threads, o.memory_limit, &progress);
    sample.texture = &texture;
    Result<PointSet> sampled = sampleSurface(*points, sample, o.input);
    if (!sampled) return reportError(sampled.error());
    points = std::move(sampled);
  }
  if (Status s = selectDimensions(*points, o.dimensions, o.input); !s) return reportError(s.error());
  if (Status s = filterPoints(*points, filters, o.unique, *order, o.memory_limit, o.common.threads, &progress); !s)
    return reportError(s.error());
  if (Status s = writePointsWithNotes(o.output, *points, w); !s) return reportError(s.error());
  return 0;
}

}  // namespace

void addConvertCommand(CLI::App& app, RunCommand& run) {
  auto o = std::make_shared<ConvertOptions>();
  CLI::App* cmd = app.add_subcommand("convert", "Convert a point set or mesh between .csv (and text: .xyz, .txt, .asc, .pts, .ptx), .ply, .pcd, .glb, .las, .laz and .e57");
  cmd->add_option("input", o->input, "Input file (.csv, .xyz, .txt, .asc, .pts, .ptx, .e57, .ply, .pcd, .glb, .gltf, .las, .laz)")->required();
  cmd->add_option("-o,--output", o->output, "Output file (.csv, .xyz, .txt, .asc, .pts, .ptx, .ply, .pcd, .glb, .las, .laz, .e57); written whole or not at all")
      ->required()
      ->check(checkStatus(checkPointOutput));
  cmd->add_option("--decimals", o->decimals,
                  "CSV: fixed digits after the point of coordinates and 0..1 colours (15 gives the %.15f of the original study's Python generator); default: shortest round trip, "
                  "or for LAS input the file's step (scale 0.01: at most 2 digits, trailing zeros dropped)")
      ->check(CLI::Range(0, 100));
  cmd->add_flag("--ply-ascii", o->ply_ascii, "PLY: write ASCII instead of binary little-endian");
  o->ply_colors_option = cmd->add_option("--ply-colors", o->ply_colors,
                  "PLY: colour property type. auto: ushort for 16-bit colours (LAS), every bit kept, else uchar;\n"
                  "uchar: 8-bit (what Open3D and PCL read); ushort; float: exact")
      ->check(oneOf("--ply-colors", {"auto", "uchar", "ushort", "float"}))
      ->default_val("auto");
  o->pcd_encoding_option = cmd->add_option("--pcd-encoding", o->pcd_encoding,
                  "PCD: DATA ascii, binary (rows of the fields) or binary_compressed (LZF, the smallest)")
      ->check(oneOf("--pcd-encoding", {"ascii", "binary", "binary_compressed"}))
      ->default_val("binary");
  cmd->add_option("--crs", o->crs,
                  "LAS/LAZ/COPC, E57, PLY and PCD: the coordinate reference system, as EPSG:CODE (EPSG:32633; with heights EPSG:6580+5703),\n"
                  "WKT, or a file holding WKT (a .prj), in place of the input's CRS records: an EPSG CRS as GeoTIFF keys\n"
                  "in a LAS 1.2 file where nothing else needs LAS 1.4 (what every LAS reader takes), any other as WKT\n"
                  "in a LAS 1.4 file; E57: its coordinateMetadata, as WKT; PLY and PCD: header comments, as WKT.\n"
                  "Default: the input's (an E57 file's coordinateMetadata goes to a LAS file where PROJ makes it WKT,\n"
                  "and a LAS file's CRS to E57 and PCD as WKT)")
      ->type_name("CRS");
  cmd->add_option("--las-scale", o->las_scale,
                  "LAS output: the coordinate step for x, y and z (the offset is the bounding box's minimum rounded "
                  "down to a whole number); a point beyond the 32-bit integers at this step is an error (exit 2). "
                  "Default: a LAS input's own scale and offset (the same point records), else per axis the "
                  "data's own decimal step (0.01 for centimetres), else the finest the extent fits")
      ->default_str("auto")
      ->check(positiveNumber("--las-scale"));
  cmd->add_flag("--allow-nonfinite", o->allow_nonfinite, "Accept nan/inf coordinates instead of rejecting them");
  addColumnsOption(*cmd, o->columns);
  addSampleOptions(*cmd, o->sample);
  cmd->add_flag("--no-colors", o->no_colors, "Drop colours");
  cmd->add_option("--keep", o->dimensions.keep,
                  "Keep only these dimensions (comma-separated names, as `dpoint info` lists them; none: no dimension)");
  cmd->add_option("--drop", o->dimensions.drop, "Drop these dimensions (comma-separated names; all: every one)");
  auto* scene = cmd->add_option("--scene", o->scene,
                                "glTF: walk scene N instead of the default scene (else scene 0)")
                    ->check(nonNegativeNumber("--scene"));
  cmd->add_flag("--all-scenes", o->all_scenes, "glTF: walk every scene, one after the other")->excludes(scene);
  cmd->add_flag("--unique", o->unique,
                "Drop points whose x,y,z exactly equal an earlier point's (first kept; triangles renumbered, "
                "collapsed ones dropped)");
  cmd->add_option("--color-format", o->color_format,
                  "linear: colours as read (linear 0..1; glTF primitives without COLOR_0 take their material's "
                  "baseColorFactor); srgb8: each channel sRGB-encoded and rounded to 8 bits, written as k/255")
      ->check(oneOf("--color-format", {"linear", "srgb8"}))
      ->default_val("linear");
  cmd->add_option("--max-points", o->max_points,
                  "Refuse (exit 4) input of more than N points, before --unique; glTF and LAS are refused before "
                  "allocating")
      ->check(positiveNumber("--max-points"));
  cmd->add_option("--order", o->order, std::string(kPointOrderHelp) + "; applied last, after --unique")
      ->default_val("input");
  addMaxMemoryOption(*cmd, o->max_memory);
  addCommonOptions(*cmd, o->common);
  cmd->callback([o, &run] { run = [o] { return runConvert(*o); }; });
}

}  // namespace dpoint
