// Reading and writing a PointSet by file extension: text (.csv, .xyz, .txt, .asc, .pts), .ply, .pcd,
// .glb (and .gltf input), .las, .laz and .copc.laz, and glTF/GLB to CSV streamed without a PointSet.
#pragma once

#include <optional>
#include <string>

#include "converters/gltf_read.h"
#include "converters/copc.h"
#include "converters/csv.h"
#include "converters/las.h"
#include "converters/pcd.h"
#include "converters/ply.h"
#include "core/point_set.h"
#include "core/result.h"
#include "ops/point_order.h"

namespace dpoint {

enum class FileFormat { kCsv, kPly, kPcd, kGlb, kGltf, kLas, kLaz, kE57 };

// From the extension, case-insensitive. Error names the path and the extensions accepted.
Result<FileFormat> formatOf(const std::string& path);
inline bool isGltf(FileFormat format) { return format == FileFormat::kGlb || format == FileFormat::kGltf; }
// The formats that hold a mesh's triangles; the others (CSV, PTS, PCD, LAS, LAZ, COPC) keep points only.
inline bool holdsTriangles(FileFormat format) { return format == FileFormat::kPly || isGltf(format); }
// True for a path ending in .copc.laz (any case): written as COPC (converters/copc.h), an octree
// of LAZ 1.4 chunks that reads as plain LAZ too.
bool isCopcPath(const std::string& path);
// Whether `info` and `render` read the file by view as COPC: a .laz file whose content is COPC
// (its first VLR the COPC info), whatever its name says (a plain LAZ named .copc.laz had been
// refused, a COPC named .laz read whole). A file that does not open goes by its name.
bool readsAsCopc(const std::string& path);
// The points of the COPC nodes `query` selects (readCopcRecords), read as readLas reads a file:
// the header and VLRs of the file with those records after them. `stats` gets the points, bytes
// and nodes read, and `file_bytes` the file's size.
struct CopcReadStats {
  uint64_t points = 0, bytes = 0, nodes = 0, file_bytes = 0, file_points = 0;
};
Result<PointSet> readCopcPoints(const std::string& path, const CopcQuery& query, const LasReadOptions& options,
                                CopcReadStats* stats = nullptr);
// The error for a format that is read but not written (.gltf), with what to write instead;
// ok for the others. writePoints and the CLI's output check both give it.
Status checkWrittenFormat(const std::string& path, FileFormat format);

struct ReadOptions {
  unsigned threads = 0;
  bool allow_nonfinite = false;
  Progress* progress = nullptr;
  bool points_only = false;  // PLY: stop after the vertex element (faces are not read)
  uint64_t max_memory = 0;   // --max-memory for what is read; 0: defaultMemoryLimit() (core/memory.h)
  // Where colours come from. LAS: converters/las.h. Other formats: kAuto and kRgb take the file's
  // colours (kRgb fails when it has none), kNone drops them; kIntensity and kClassification are
  // errors (only LAS has those fields).
  LasColorSource las_color = LasColorSource::kAuto;
  // When not null, gets one line per thing the reader read past (PCD: points without a return, a
  // viewpoint not applied; LAS: an extra bytes record it cannot follow).
  std::vector<std::string>* notices = nullptr;
  // Text files: what each column holds (CsvReadOptions::columns); an error for other formats.
  std::vector<std::string> columns = {};
  // glTF input: when not null, receives its base-colour textures (GltfReadOptions::texture), for
  // sampling its surface; other formats leave it empty.
  MeshTexture* texture = nullptr;
  bool faces_unkept = false;  // PLY: PlyReadOptions::faces_unkept (no faces kept; a whole file still checked)
};

struct WriteOptions {
  unsigned threads = 0;
  int decimals = -1;  // CSV only
  bool decimals_at_scale = false;  // CSV: decimals is the input's step (CsvWriteOptions::at_scale)
  PlyEncoding ply_encoding = PlyEncoding::kBinary;
  PlyColorType ply_colors = PlyColorType::kAuto;
  PcdEncoding pcd_encoding = PcdEncoding::kBinary;
  Progress* progress = nullptr;
  double las_scale = 0.0;  // LAS: the coordinate step for x, y and z; 0: the source's, else 0.001 (converters/las.h)
  // LAS/LAZ/COPC and E57: the CRS as one line of WKT 1 (crsAsWkt, --crs), in place of the source's.
  // Without it a set read from a file other than LAS keeps its own (PointSet::crs): E57 writes it
  // as it is, LAS where PROJ makes it WKT (else a note says it is left out).
  std::string las_crs;
  // When not null, gets one line per thing the file cannot hold as given (GLB: points that will
  // not read back bit-exactly).
  std::vector<std::string>* notices = nullptr;
  // PLY only (another format is refused): colours, or positions, made as the rows are
  // (PlyWriteOptions); with positions_of, `points` holds only the set's facts.
  ColorSource colors_of;
  MadePositions positions_of;
};

Result<PointSet> readPoints(const std::string& path, const ReadOptions& options = {});

// How a caller names readInput's options in its messages: the CLI's flags, the module's keywords.
struct InputOptionNames {
  std::string scenes = "--scene and --all-scenes";
  std::string max_points = "--max-points";
};
// An input as `dpoint convert` and the module's read take it: .glb/.gltf through readGltf(gltf)
// (with read's max_memory and allow_nonfinite), every other format through readPoints(read), where
// a scene choice is a usage error; more points than gltf.max_points (0: no limit) is
// kResourceLimit, a LAS file's count taken from its header before anything is allocated.
Result<PointSet> readInput(const std::string& path, const ReadOptions& read, GltfReadOptions gltf,
                           const InputOptionNames& names = {});
// Which of a write's format options were given: each means something to one format only.
struct FormatOptionsGiven {
  bool decimals = false, ply_ascii = false, ply_colors = false, pcd_encoding = false, las_scale = false, crs = false;
};
// The usage error for the first option given that `path`'s format does not use (a review finding:
// each was passed over in silence), named as the CLI's flag (the module names its keyword). An
// unknown format passes: the write says what it is.
Status checkFormatOptionsUsed(const std::string& path, const FormatOptionsGiven& given);

// An empty set is written as an empty file of the format (a CSV header, a PLY or LAS of 0 points);
// GLB cannot hold one (glTF accessors have at least one element), and says so.
Status writePoints(const std::string& path, const PointSet& points, const WriteOptions& options = {});

// What `dpoint convert` does to colours between reading and writing.
struct ColorFilters {
  bool drop = false;   // --no-colors
  bool srgb8 = false;  // --color-format srgb8: encodeColorsSrgb8 (point_filters.h)
};

// Convert's --keep and --drop: comma-separated dimension names (core/dimensions.h). `keep` given:
// only those stay (`none`: no dimension); then those in `drop` go (`all`: every one). A name the
// set does not have is a usage error that lists the names it has (`what` names the input).
struct DimensionChoice {
  std::optional<std::string> keep;
  std::string drop;
};
Status selectDimensions(PointSet& points, const DimensionChoice& choice, const std::string& what);

// What `dpoint convert` does to a set between reading and writing, in its order: `colors.drop`,
// --unique (drop duplicate positions), `colors.srgb8`, then `order` (its memory checked against
// `memory_limit` first: kResourceLimit). The Python module's write does the same on a copy.
Status filterPoints(PointSet& points, const ColorFilters& colors, bool unique, PointOrder order, uint64_t memory_limit,
                    unsigned threads, Progress* progress);

// glTF/GLB input to a CSV file written block by block as the scene is walked (streamGltf):
// memory is the loaded model plus a few blocks of rows, however many points the scene places.
// The file is byte-identical to readGltf(input, read), then the filters, then writePoints(output);
// the errors are the same and come in the same order: the input's, then the output's; a scene
// that places no points gives a CSV with a header only. On any error, nothing is left at `output`. options.ply_* are unused.
Status convertGltfToCsv(const std::string& input, const GltfReadOptions& read, const ColorFilters& filters,
                        const std::string& output, const WriteOptions& options = {});

}  // namespace dpoint
