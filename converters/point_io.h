// Reading and writing a PointSet by file extension: .csv, .ply, .glb (and .gltf input).
#pragma once

#include <string>

#include "core/csv.h"
#include "core/ply.h"
#include "core/point_set.h"
#include "core/result.h"

namespace dpoint {

enum class FileFormat { kCsv, kPly, kGlb, kGltf };

// From the extension, case-insensitive. Error names the path and the extensions accepted.
Result<FileFormat> formatOf(const std::string& path);

struct ReadOptions {
  unsigned threads = 0;
  bool allow_nonfinite = false;
  Progress* progress = nullptr;
};

struct WriteOptions {
  unsigned threads = 0;
  int decimals = -1;  // CSV only
  PlyEncoding ply_encoding = PlyEncoding::kBinary;
  PlyColorType ply_colors = PlyColorType::kUchar;
  Progress* progress = nullptr;
};

Result<PointSet> readPoints(const std::string& path, const ReadOptions& options = {});
Status writePoints(const std::string& path, const PointSet& points, const WriteOptions& options = {});

}  // namespace dpoint
