// PCD, the Point Cloud Library's format (robotics, ROS): read and written (issue #37).
//
// Reading: the v0.7 header (0.5 and 0.6 too: COUNT, WIDTH/HEIGHT and TYPE may be missing), `#`
// comment lines anywhere in it, then DATA ascii, binary (rows of the fields) or binary_compressed
// (LZF, liblzf: the fields one after another). Fields x, y (and z; without z the set is 2D) of any
// numeric type; rgb or rgba packed in 4 bytes (0x00RRGGBB, rgba's alpha in the top byte, kept as
// the dimension `alpha`) as 8-bit colours; normal_x/y/z as the dimensions nx/ny/nz; `_` fields
// (PCL's padding) skipped; every other field a dimension of its own type (a field of COUNT n as
// NAME_0 … NAME_n-1). An organized cloud (WIDTH × HEIGHT) reads as its points in row order; a point
// whose x, y or z is NaN (no return) is dropped and the count told through `notices`. An infinite
// coordinate is an error unless allow_nonfinite. In ASCII a packed colour of TYPE F is the float
// whose bits are the colour, as PCL reads it (PCL 1.13 writes ASCII rgb as TYPE U, the integer).
// Errors name the file and the header line, or the data line and column (ASCII) or byte (binary).
//
// Binary and compressed rows are decoded in blocks on all cores into preassigned places, so the
// result does not depend on the thread count. The header's counts are checked against the bytes
// that follow and against max_memory before anything is allocated.
//
// Writing: x y z as float (F 4) when every coordinate is exactly a float, else as double (F 8,
// told through `notices`: PCL's typed loaders such as pcl::PointXYZ want float); rgb as PCL's
// packed float (alpha 0), or rgba with a uint8 `alpha` dimension; nx/ny/nz as normal_x/y/z; every
// other dimension in its own type (names with spaces get `_`). A 2D set gets z = 0 and a
// `# dpoint: 2D` comment that the reader honours, as the up axis z is kept. Triangles are not
// written (PCD holds points). WIDTH is the count, HEIGHT 1.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "core/input_file.h"
#include "core/point_set.h"
#include "core/progress.h"
#include "core/result.h"

namespace dpoint {

enum class PcdEncoding { kAscii, kBinary, kBinaryCompressed };

// "ascii", "binary", "binary_compressed"; an error lists them.
Result<PcdEncoding> parsePcdEncoding(std::string_view text);
const char* pcdEncodingName(PcdEncoding encoding);

struct PcdReadOptions {
  bool allow_nonfinite = false;
  Progress* progress = nullptr;
  unsigned threads = 0;      // 0: all cores
  uint64_t max_memory = 0;   // bytes for the point set and the decompressed data; 0: defaultMemoryLimit()
  std::vector<std::string>* notices = nullptr;  // dropped NaN points, a VIEWPOINT not applied
};

struct PcdWriteOptions {
  PcdEncoding encoding = PcdEncoding::kBinary;
  Progress* progress = nullptr;
  std::vector<std::string>* notices = nullptr;  // coordinates written as double
  unsigned threads = 0;  // ASCII rows formatted on this many cores (0: all); the bytes do not depend on it
  // When not null, the coordinate-system text the header states (`# dpoint: crs` lines) in place of
  // the set's own (PointSet::crs): --crs's WKT, a LAS source's made WKT, or none (writePoints).
  const std::string* crs = nullptr;
};

Result<PointSet> readPcd(const std::string& path, const PcdReadOptions& options = {});
Result<PointSet> readPcd(const InputFile& file, const PcdReadOptions& options = {});
Status writePcd(const std::string& path, const PointSet& points, const PcdWriteOptions& options = {});

}  // namespace dpoint
