#include "converters/point_io.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "converters/gltf_read.h"
#include "converters/gltf_write.h"

namespace dpoint {

Result<FileFormat> formatOf(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".csv") return FileFormat::kCsv;
  if (ext == ".ply") return FileFormat::kPly;
  if (ext == ".glb") return FileFormat::kGlb;
  if (ext == ".gltf") return FileFormat::kGltf;
  return Error{path + ": unknown file type '" + ext + "' (expected .csv, .ply, .glb or .gltf)", ExitCode::kUsage};
}

Result<PointSet> readPoints(const std::string& path, const ReadOptions& options) {
  Result<FileFormat> format = formatOf(path);
  if (!format) return format.error();
  switch (*format) {
    case FileFormat::kCsv:
      return readCsv(path, CsvReadOptions{options.threads, options.allow_nonfinite, options.progress});
    case FileFormat::kPly:
      return readPly(path, PlyReadOptions{options.allow_nonfinite, options.progress});
    case FileFormat::kGlb:
    case FileFormat::kGltf: {
      GltfReadOptions gltf;
      gltf.allow_nonfinite = options.allow_nonfinite;
      return readGltf(path, gltf);
    }
  }
  return Error{path + ": unreachable format"};
}

Status writePoints(const std::string& path, const PointSet& points, const WriteOptions& options) {
  Result<FileFormat> format = formatOf(path);
  if (!format) return format.error();
  if (points.positions.empty()) return Error{path + ": nothing to write: the point set is empty"};
  switch (*format) {
    case FileFormat::kCsv:
      return writeCsv(path, points, CsvWriteOptions{options.decimals, options.threads, options.progress});
    case FileFormat::kPly:
      return writePly(path, points, PlyWriteOptions{options.ply_encoding, options.ply_colors, options.progress});
    case FileFormat::kGlb:
      return writeGlb(path, points);
    case FileFormat::kGltf:
      return Error{path + ": writing .gltf is not supported; write .glb", ExitCode::kUsage};
  }
  return Error{path + ": unreachable format"};
}

}  // namespace dpoint
