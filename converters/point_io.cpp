#include "converters/point_io.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <optional>

#include "converters/copc.h"
#include "converters/e57.h"
#include "converters/gltf_write.h"
#include "converters/las_crs.h"
#include "core/atomic_file.h"
#include "core/text.h"
#include "ops/point_filters.h"

namespace dpoint {
namespace {

// The CSV file is created only once the checking walk has passed, so input errors come first
// and a refused input leaves no output behind, as with readGltf then writeCsv.
class CsvPointSink final : public GltfPointSink {
 public:
  CsvPointSink(const std::string& output, const ColorFilters& filters,
               const WriteOptions& options)
      : output_(output), filters_(filters), options_(options) {}

  Status begin(const GltfSummary& summary) override {
    // glTF positions have z (PointSet::z_axis) unless dpoint wrote the file from a 2D set; a scene
    // placing no points is an empty set.
    flat_ = summary.flat;
    CsvLayout layout{flat_, summary.colors && !filters_.drop, {}};
    for (const auto& [name, type] : summary.dimensions) layout.dimensions.push_back(name);
    Result<CsvRowWriter> writer = CsvRowWriter::create(
        output_, layout, CsvWriteOptions{options_.decimals, options_.threads, options_.progress, false, options_.notices},
        summary.points);  // the renames said, as writeCsv says them (a review finding)
    if (!writer) return writer.error();
    writer_.emplace(std::move(*writer));
    return okStatus();
  }

  Status points(PointSet& block) override {
    if (flat_)  // a file that says 2D but has a z would lose it in x,y columns
      for (size_t i = 0; i < block.size(); ++i)
        if (block.positions[i].z != 0.0)
          return Error{"a glTF marked 2D by dpoint has a point with z = " + formatNumber(block.positions[i].z) +
                       "; not written as x,y"};
    if (filters_.drop) block.colors.clear();
    if (filters_.srgb8) encodeColorsSrgb8(block);
    // A block with dimensions is written whole (a partial batch of rows; appendSet).
    return block.dimensions.empty() ? writer_->append(block.positions, block.colors) : writer_->appendSet(block);
  }

  Status commit() { return writer_->commit(); }

 private:
  const std::string& output_;
  const ColorFilters& filters_;
  const WriteOptions& options_;
  std::optional<CsvRowWriter> writer_;
  bool flat_ = false;  // x,y columns: the file said 2D
};

}  // namespace

Result<FileFormat> formatOf(const std::string& path) {
  const std::string ext = lowerExtension(path);
  if (ext == ".csv" || ext == ".xyz" || ext == ".txt" || ext == ".asc" || ext == ".pts" || ext == ".ptx")
    return FileFormat::kCsv;
  if (ext == ".ply") return FileFormat::kPly;
  if (ext == ".glb") return FileFormat::kGlb;
  if (ext == ".gltf") return FileFormat::kGltf;
  if (ext == ".pcd") return FileFormat::kPcd;
  if (ext == ".las") return FileFormat::kLas;
  if (ext == ".laz") return FileFormat::kLaz;
  if (ext == ".e57") return FileFormat::kE57;
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    return Error{path + ": is a folder, not a point file (.csv, .xyz, .txt, .asc, .pts, .ptx, .ply, .pcd, .glb, .gltf, .las, .laz or .e57)",
                 ExitCode::kUsage};
  return Error{path + ": unknown file type '" + ext + "' (expected .csv, .xyz, .txt, .asc, .pts, .ptx, .ply, .pcd, .glb, .gltf, .las, .laz or .e57)",
               ExitCode::kUsage};
}

bool isCopcPath(const std::string& path) {
  const std::string lower = lowerAscii(path);
  return lower.size() >= 9 && lower.compare(lower.size() - 9, 9, ".copc.laz") == 0;
}

bool readsAsCopc(const std::string& path) {
  if (lowerExtension(path) != ".laz") return false;
  Result<InputFile> file = InputFile::open(path);
  return file ? isCopc(*file) : isCopcPath(path);
}

Result<PointSet> readCopcPoints(const std::string& path, const CopcQuery& query, const LasReadOptions& options,
                                CopcReadStats* stats) {
  Result<InputFile> file = InputFile::open(path);
  if (!file) return file.error();
  Result<CopcHeader> header = readCopcHeader(*file);
  if (!header) return header.error();
  CopcNodeRead read;
  Result<std::string> records = readCopcRecords(*file, query, &read);
  if (!records) return records.error();
  // The file's header and VLRs, uncompressed and counting these records, then the records.
  const uint64_t count = records->size() / header->record_length;
  std::string bytes(static_cast<size_t>(header->point_data_offset), '\0');
  if (Result<size_t> got = file->readAt(0, bytes.data(), bytes.size()); !got) return got.error();
  bytes[104] = static_cast<char>(static_cast<uint8_t>(bytes[104]) & 0x3F);  // not compressed
  const uint32_t legacy = 0;
  const uint64_t none = 0;
  std::memcpy(bytes.data() + 107, &legacy, 4);  // formats 6-8: the legacy count is 0
  std::memcpy(bytes.data() + 235, &none, 8);    // no EVLRs (the hierarchy stays behind)
  std::memcpy(bytes.data() + 243, &legacy, 4);
  std::memcpy(bytes.data() + 247, &count, 8);
  bytes += *records;
  std::string().swap(*records);
  Result<PointSet> points = readLas(InputFile::fromMemory(path, bytes), options);
  // The coordinate system's records as the file has them, EVLRs too (a WKT record may be one).
  if (points && points->las) {
    Result<std::vector<LasVlr>> crs = readLasCrsRecords(*file);
    if (!crs) return crs.error();
    points->las->vlrs = std::move(*crs);
  }
  if (stats) *stats = {read.points, read.bytes, read.nodes, file->size(), header->point_count};
  return points;
}

Status checkWrittenFormat(const std::string& path, FileFormat format) {
  if (format == FileFormat::kGltf)
    return Error{path + ": .gltf is read, not written; write .glb (or .csv, .ply, .pcd, .las)", ExitCode::kUsage};
  return okStatus();
}

namespace {

Result<PointSet> readByFormat(const std::string& path, FileFormat format, const ReadOptions& options) {
  if (!options.columns.empty() && format != FileFormat::kCsv)
    return Error{"--columns: " + path + " is not a text file (.csv, .xyz, .txt, .asc, .pts); its fields have their names",
                 ExitCode::kUsage};
  switch (format) {
    case FileFormat::kCsv:
      return readCsv(path, CsvReadOptions{options.threads, options.allow_nonfinite, options.progress, options.max_memory,
                                          options.columns, options.notices});
    case FileFormat::kPly:
      return readPly(path, PlyReadOptions{options.allow_nonfinite, options.progress, options.threads, options.points_only,
                                          options.max_memory, options.faces_unkept, options.notices});
    case FileFormat::kPcd:
      return readPcd(path, PcdReadOptions{options.allow_nonfinite, options.progress, options.threads, options.max_memory,
                                          options.notices});
    case FileFormat::kGlb:
    case FileFormat::kGltf: {
      GltfReadOptions gltf;
      gltf.allow_nonfinite = options.allow_nonfinite;
      gltf.max_memory = options.max_memory;
      gltf.texture = options.texture;
      gltf.threads = options.threads;
      gltf.notices = options.notices;
      return readGltf(path, gltf);
    }
    case FileFormat::kLas:
    case FileFormat::kLaz:  // the LAS reader decodes LAZ (converters/laz_decode.h)
      return readLas(path, LasReadOptions{options.threads, options.progress, options.las_color, options.max_memory,
                                          options.notices});
    case FileFormat::kE57:
      return readE57(path, E57ReadOptions{options.threads, options.progress, options.max_memory, options.allow_nonfinite,
                                          options.notices});
  }
  return Error{path + ": unreachable format"};
}

}  // namespace

Result<PointSet> readPoints(const std::string& path, const ReadOptions& options) {
  if (options.texture) *options.texture = MeshTexture{};
  Result<FileFormat> format = formatOf(path);
  if (!format) return format.error();
  const bool las = *format == FileFormat::kLas || *format == FileFormat::kLaz;
  if (!las && (options.las_color == LasColorSource::kIntensity || options.las_color == LasColorSource::kClassification))
    return Error{path + ": colour by " +
                 (options.las_color == LasColorSource::kIntensity ? "intensity" : "classification") +
                 " needs a LAS file; this file has no such field"};
  Result<PointSet> points = readByFormat(path, *format, options);
  if (!points || las) return points;  // LAS colours are integers, or made here from intensity or class
  // The PLY reader tells a tile's colours (generate's own) from a file's itself.
  if (*format != FileFormat::kPly) points->colors_read_as_fractions = points->hasColors() && points->color_full_scale == 0;
  // Float colours of whole numbers above 1 are 0..255 (or 0..65535) values, as some tools write
  // a PLY's: read as CSV reads its integer colours, instead of clamped to white.
  // (Not for colours about to be dropped: --no-colors says nothing of them.)
  if (*format == FileFormat::kPly && points->colors_read_as_fractions && options.las_color != LasColorSource::kNone) {
    const WholeColorScale whole = wholeColorScale(points->colors, options.threads);
    if (whole.full != 0) {
      takeColorsAsIntegers(*points, whole.full, options.threads);
      if (options.notices)
        options.notices->push_back(path + ": its float colours are whole numbers above 1 (PLY's are 0..1): read as 0.." +
                                   std::to_string(whole.full) + " values");
    } else if (whole.odd != UINT64_MAX && options.notices) {
      options.notices->push_back(path + ": " + oddColorNote(points->colors[whole.odd], whole.odd));
    }
  }
  if (options.las_color == LasColorSource::kRgb && !points->hasColors())
    return Error{path + ": colour by RGB asked for, but the file has no colours"};
  if (options.las_color == LasColorSource::kNone) points->colors.clear();
  return points;
}

Result<PointSet> readInput(const std::string& path, const ReadOptions& read, GltfReadOptions gltf,
                           const InputOptionNames& names) {
  Result<FileFormat> format = formatOf(path);
  if (!format) return format.error();
  if (isGltf(*format)) {
    gltf.max_memory = read.max_memory;
    gltf.allow_nonfinite = read.allow_nonfinite;
    gltf.threads = read.threads;
    gltf.max_points_name = names.max_points;
    if (!gltf.texture) gltf.texture = read.texture;
    Result<PointSet> points = readGltf(path, gltf);
    if (points) points->colors_read_as_fractions = points->hasColors();
    return points;
  }
  if (gltf.scene >= 0 || gltf.all_scenes)
    return Error{path + ": " + names.scenes + " apply to .glb/.gltf input only", ExitCode::kUsage};
  auto tooMany = [&](uint64_t count) {
    return Error{path + ": " + std::to_string(count) + " points exceed " + names.max_points + " " +
                     std::to_string(gltf.max_points),
                 ExitCode::kResourceLimit};
  };
  if ((*format == FileFormat::kLas || *format == FileFormat::kLaz) && gltf.max_points != 0) {  // the header's count first
    Result<LasHeader> header = readLasHeader(path);
    if (!header) return header.error();
    if (header->point_count > gltf.max_points) return tooMany(header->point_count);
  }
  Result<PointSet> points = readPoints(path, read);
  if (points && gltf.max_points != 0 && points->size() > gltf.max_points) return tooMany(points->size());
  return points;
}

Status checkFormatOptionsUsed(const std::string& path, const FormatOptionsGiven& given) {
  const Result<FileFormat> format = formatOf(path);
  if (!format) return okStatus();
  const bool las = *format == FileFormat::kLas || *format == FileFormat::kLaz;
  const auto refuse = [&](const std::string& option, const std::string& what) {
    return Status(Error{option + ": only " + what + ", not " + quotedExcerpt(path), ExitCode::kUsage});
  };
  if (given.decimals && *format != FileFormat::kCsv)
    return refuse("--decimals", "a CSV output (.csv, .xyz, .txt, .asc, .pts, .ptx) has decimals");
  if ((given.ply_ascii || given.ply_colors) && *format != FileFormat::kPly)
    return refuse(given.ply_ascii ? "--ply-ascii" : "--ply-colors", "a PLY output (.ply) has it");
  if (given.pcd_encoding && *format != FileFormat::kPcd) return refuse("--pcd-encoding", "a PCD output (.pcd) has an encoding");
  if (given.las_scale && !las)
    return refuse("--las-scale", "a LAS, LAZ or COPC output (.las, .laz, .copc.laz) has a coordinate step");
  if (given.crs && !las && *format != FileFormat::kE57 && *format != FileFormat::kPly && *format != FileFormat::kPcd)
    return refuse("--crs", "a LAS, LAZ, COPC, E57, PLY or PCD output (.las, .laz, .copc.laz, .e57, .ply, .pcd) holds a "
                           "coordinate reference system");
  return okStatus();
}

namespace {

// The integer full scale `format` writes a set's colours at (255, 65535), 0 where it keeps floats.
double writtenColorScale(const std::string& path, FileFormat format, const PointSet& points, const WriteOptions& options) {
  switch (format) {
    case FileFormat::kPly:
      if (options.ply_colors == PlyColorType::kFloat) return 0.0;
      return options.ply_colors == PlyColorType::kUshort ||
                     (options.ply_colors == PlyColorType::kAuto && points.color_full_scale == 65535)
                 ? 65535.0
                 : 255.0;
    case FileFormat::kPcd: return 255.0;
    case FileFormat::kCsv: return isPtsPath(path) || isPtxPath(path) ? 255.0 : 0.0;
    case FileFormat::kE57: return points.color_full_scale == 65535 ? 65535.0 : 255.0;
    case FileFormat::kLas:
    case FileFormat::kLaz: return points.color_full_scale == 255 && points.las ? 255.0 : 65535.0;
    default: return 0.0;
  }
}

// The coordinate-system text a PLY or PCD header states: --crs's WKT, else the set's own, else (for
// PCD, `las_wkt`, which has no place for LAS records) a LAS source's made WKT. Text a header cannot
// carry (headerCrsProblem) is left out with a note.
std::string headerCrs(const std::string& path, const PointSet& points, const WriteOptions& options, bool las_wkt) {
  std::string crs = !options.las_crs.empty() ? options.las_crs : points.crs, why_not;
  if (crs.empty() && las_wkt && points.las) crs = lasSourceWkt(*points.las, why_not);
  if (why_not.empty()) why_not = headerCrsProblem(crs);
  if (why_not.empty()) return crs;
  if (options.notices) options.notices->push_back(path + ": coordinate system not written: " + why_not);
  return "";
}

Status writeFormat(const std::string& path, FileFormat format, const PointSet& points, const WriteOptions& options) {
  if ((options.colors_of || options.positions_of) && format != FileFormat::kPly)
    return Error{path + ": points made as the rows are written go to a .ply only"};
  // CSV and glTF have no place for it: said, not lost unseen.
  if ((format == FileFormat::kCsv || format == FileFormat::kGlb) && options.notices && statedCrs(points).any())
    options.notices->push_back(path + ": coordinate system not written: " +
                               (format == FileFormat::kCsv ? "a text file (CSV, XYZ, PTS, PTX)" : "GLB") +
                               " holds none (.las, .laz, .e57, .ply and .pcd keep it)");
  switch (format) {
    case FileFormat::kCsv:
      return writeCsv(path, points,
                      CsvWriteOptions{options.decimals, options.threads, options.progress, options.decimals_at_scale,
                                      options.notices});
    case FileFormat::kPly: {
      const std::string crs = headerCrs(path, points, options, false);
      return writePly(path, points,
                      PlyWriteOptions{options.ply_encoding, options.ply_colors, options.progress, options.threads,
                                      options.colors_of, options.positions_of, options.notices, &crs});
    }
    case FileFormat::kPcd: {
      // A LAS source's records as WKT, as E57 takes them (PCD's header holds text, not records).
      const std::string crs = headerCrs(path, points, options, true);
      return writePcd(path, points,
                      PcdWriteOptions{options.pcd_encoding, options.progress, options.notices, options.threads, &crs});
    }
    case FileFormat::kGlb:
    {
      GlbWriteReport report;
      if (Status s = writeGlb(path, points, &report); !s) {
        // The set's own faults ("cannot write GLB: point 565 has a non-finite coordinate") are named
        // here, where the path is known.
        if (s.error().message.rfind("cannot write GLB: ", 0) == 0) return Error{path + ": " + s.error().message, s.error().code};
        return s;
      }
      if (report.inexact_points != 0 && options.notices)
        options.notices->push_back(
            path + ": " + std::to_string(report.inexact_points) + " of " + std::to_string(points.size()) +
            " points will not read back bit-exactly (their offsets on one axis span more than float32's exponent "
            "range, or a coordinate is -0.0); they are within float precision of the extent. Write .ply or .csv "
            "to keep every double");
      return okStatus();
    }
    case FileFormat::kGltf:
      return checkWrittenFormat(path, format);
    case FileFormat::kE57:
      return writeE57(path, points, E57WriteOptions{options.threads, options.progress, options.notices, options.las_crs});
    case FileFormat::kLas:
    case FileFormat::kLaz: {
      LasWriteReport report;
      LasWriteOptions las;
      las.scale = options.las_scale;
      las.threads = options.threads;
      las.progress = options.progress;
      las.report = &report;
      las.crs_wkt = options.las_crs;
      // A coordinate system another format stated (an E57 file's, or the module's `crs`), where no
      // --crs gives one: made WKT by PROJ in place of a LAS source's records (the text wins, as
      // every writer takes it), or left out with a note (and the records with it).
      std::string crs_note;
      if (las.crs_wkt.empty() && !points.crs.empty()) {
        Result<std::string> wkt = crsAsWkt(points.crs, "the input's coordinate system");
        if (wkt) las.crs_wkt = std::move(*wkt);
        else crs_note = path + ": coordinate system not written: " + wkt.error().message;
        las.source_crs_dropped = true;  // the text is the set's CRS, written or not (a review finding)
      }
      if (isCopcPath(path)) {
        // COPC: the LAS 1.4 file in memory (formats 6-8), then its octree of LAZ chunks.
        std::string bytes;
        las.las14 = true;
        las.memory = &bytes;
        if (Status s = writeLas(path, points, las); !s) return s;
        CopcWriteOptions copc;
        copc.threads = options.threads;
        Result<std::string> file = copcFromLasBytes(bytes, copc);
        if (!file) return Error{path + ": " + file.error().message};
        std::string().swap(bytes);
        Result<AtomicFile> out = AtomicFile::create(path);
        if (!out) return out.error();
        if (Status s = out->write(file->data(), file->size()); !s) return s;
        if (Status s = out->commit(); !s) return s;
      } else {
        las.compress = format == FileFormat::kLaz;
        if (Status s = writeLas(path, points, las); !s) return s;
      }
      if (options.notices) {
        if (!crs_note.empty()) options.notices->push_back(crs_note);
        if (!report.crs.empty()) options.notices->push_back(path + ": " + report.crs);
        if (report.intensity_scaled)
          options.notices->push_back(path + ": intensity of 0..1 values (as PTX and E57 scans hold it) written as 0..65535, "
                                            "LAS's 16-bit intensity normalised to that range");
        for (const std::string& line : report.renamed)
          options.notices->push_back(path + ": " + line + " (a LAS extra bytes name is up to 32 letters, digits or '_')");
        for (int k = 0; k < 3; ++k)
          if (report.rounded[k]) {
            std::string note = path;
            note += ": ";
            note += "xyz"[k];
            note += report.source_scale ? " rounded to the source LAS file's scale " : " rounded to the LAS scale ";
            note += formatNumber(report.scale[k]);
            note += ", up to ";
            note += formatNumber(report.scale[k] / 2);
            note += report.source_scale ? " off: coordinates changed since it was read left its grid (las_scale, "
                                          "--las-scale, sets a finer one)"
                                        : " off: no step that keeps its digits lets its extent fit LAS's 32-bit integers";
            options.notices->push_back(std::move(note));
          }
      }
      if (report.merged_points != 0 && options.notices) {
        const glm::dvec3& sc = report.scale;
        std::string scale = formatNumber(sc.x);
        if (sc.x != sc.y || sc.y != sc.z) {
          scale = '(' + scale;
          for (double v : {sc.y, sc.z}) {
            scale += ", ";
            scale += formatNumber(v);
          }
          scale += ')';
        }
        std::string note = path;
        note += ": ";
        note += std::to_string(report.merged_points);
        note += " of ";
        note += std::to_string(points.size());
        note += " points share their integers with another at the LAS scale " + scale;
        note += options.las_scale > 0.0 ? " and read back merged (a finer --las-scale keeps them apart where the extent fits)"
                                        : " and read back merged (no finer decimal scale fits the extent in LAS's 32-bit integers)";
        options.notices->push_back(std::move(note));
      }
      return okStatus();
    }
  }
  return Error{path + ": unreachable format"};
}

}  // namespace

Status writePoints(const std::string& path, const PointSet& points, const WriteOptions& options) {
  Result<FileFormat> format = formatOf(path);
  if (!format) return format.error();
  if (Status s = checkWrittenFormat(path, *format); !s) return s;  // .gltf (the CLI checks -o first)
  // Colours read as fractions that an integer format rounds: said once the file is there (a review
  // of issue #38's wave: a float-colour PLY went to 8-bit PLY, PCD or PTS without a word).
  const double full = writtenColorScale(path, *format, points, options);
  const ColorsOffGrid off = options.notices && points.colors_read_as_fractions && points.hasColors() && full > 0.0
                                ? colorsOffGrid(points.colors, full, options.threads)
                                : ColorsOffGrid{};
  if (Status s = writeFormat(path, *format, points, options); !s) return s;
  // --crs in place of the set's own CRS: said for every format that keeps one (it was said for LAS
  // alone; the last note's list).
  if (options.notices && !options.las_crs.empty() && *format != FileFormat::kCsv && *format != FileFormat::kGlb) {
    const StatedCrs stated = statedCrs(points);
    if (stated.any() && !crsEquivalent(stated, options.las_crs))  // naming the input's own is no change
      options.notices->push_back(path + ": the input's CRS (" + crsLabel(stated) + ") replaced by " +
                                 crsLabel(StatedCrs{options.las_crs, {}, false}));
  }
  if (off.rounded != 0 || off.clamped != 0) {
    const std::string scale = full == 255.0 ? "255" : "65535";
    const std::string keeps = *format == FileFormat::kPly ? "ply_colors or --ply-colors float keeps them"
                              : *format == FileFormat::kPcd ? "PCD's rgb holds 0..255 a channel; .ply with float colours, .csv or .glb keeps them"
                              : *format == FileFormat::kCsv ? (isPtxPath(path) ? "PTX holds 0..255; .csv keeps them" : "PTS holds 0..255; .csv keeps them")
                              : *format == FileFormat::kE57 ? "E57's colours are integers; .ply with float colours, .csv or .glb keeps them"
                                                            : "LAS holds 0..65535; .ply with float colours, .csv or .glb keeps them";
    const std::string of = " of " + std::to_string(points.size()) + " points have colours read as fractions ";
    if (off.rounded != 0)
      options.notices->push_back(path + ": " + std::to_string(off.rounded) + of + "that are not " +
                                 (full == 255.0 ? "8" : "16") + "-bit values: written rounded to 0.." + scale + " (" +
                                 keeps + ")");
    if (off.clamped != 0)
      options.notices->push_back(path + ": " + std::to_string(off.clamped) + of +
                                 "with a channel outside 0..1 or not a number: written clamped to 0.." + scale +
                                 " (colours as fractions are 0..1)");
  }
  return okStatus();
}

Status selectDimensions(PointSet& points, const DimensionChoice& choice, const std::string& what) {
  const auto names = [](const std::string& list) {  // empty names (a doubled comma) are passed over
    std::vector<std::string> out = splitAt(list, ',');
    std::erase(out, std::string());
    return out;
  };
  const auto check = [&](const std::string& option, const std::vector<std::string>& asked) -> Status {
    for (const std::string& name : asked) {
      if (points.dimensions.find(name)) continue;
      std::string has;
      for (const Dimension& d : points.dimensions.all()) {
        has += has.empty() ? "" : ", ";
        has += d.name;
      }
      const bool diffuse = points.hasColors() && std::find(std::begin(kDiffuseNames), std::end(kDiffuseNames), name) !=
                                                     std::end(kDiffuseNames);
      return Error{option + " " + name + ": " + what + " has no dimension '" + name + "' (" +
                       (has.empty() ? std::string("it has none") : "it has " + has) + ")" +
                       (diffuse ? "; a PLY's diffuse_red, diffuse_green and diffuse_blue are read as its colours" : ""),
                   ExitCode::kUsage};
    }
    return okStatus();
  };
  if (choice.keep && *choice.keep != "none") {
    const std::vector<std::string> keep = names(*choice.keep);
    if (Status s = check("--keep", keep); !s) return s;
    Dimensions kept;
    for (const std::string& name : keep)
      if (!kept.find(name)) kept.all().push_back(std::move(*points.dimensions.find(name)));
    points.dimensions = std::move(kept);
  } else if (choice.keep) {
    points.dimensions = Dimensions();
  }
  if (choice.drop == "all") {
    points.dimensions = Dimensions();
  } else {
    const std::vector<std::string> drop = names(choice.drop);
    if (Status s = check("--drop", drop); !s) return s;
    for (const std::string& name : drop) points.dimensions.remove(name);
  }
  return okStatus();
}

Status filterPoints(PointSet& points, const ColorFilters& colors, bool unique, PointOrder order, uint64_t memory_limit,
                    unsigned threads, Progress* progress) {
  if (colors.drop) points.colors.clear();
  if (unique) dropDuplicatePositions(points);
  if (colors.srgb8) encodeColorsSrgb8(points);
  if (Status s = checkReorderMemory(points, order, memory_limit); !s) return s;
  reorderPoints(points, order, threads, progress);
  return okStatus();
}

Status convertGltfToCsv(const std::string& input, const GltfReadOptions& read, const ColorFilters& filters,
                        const std::string& output, const WriteOptions& options) {
  CsvPointSink sink(output, filters, options);
  GltfReadOptions noted = read;
  if (!noted.notices) noted.notices = options.notices;
  if (Status s = streamGltf(input, noted, sink); !s) return s;
  return sink.commit();
}

}  // namespace dpoint
