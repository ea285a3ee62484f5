// CSV point files: `x,y,z,r,g,b`, `x,y,z`, `x,y,r,g,b` or `x,y` (z = 0), with or without a header.
//
// Reading: LF or CRLF line ends, an optional UTF-8 BOM, spaces or tabs around fields, blank lines
// skipped. Numbers are parsed correctly rounded (fast_float): positions to double, colours to
// float. The file is read in blocks on all cores; every row goes to its preassigned index, so the
// result is the same for any thread count. Memory: the PointSet plus one block per thread.
// Errors name the file, line, column and the bad text; the first error by line wins.
//
// Writing: doubles in shortest round-trip form (std::to_chars), or with `decimals` fixed digits
// after the point, rounded exactly like glibc printf("%.*f"). Colours as shortest floats.
#pragma once

#include <string>

#include "core/point_set.h"
#include "core/progress.h"
#include "core/result.h"

namespace dpoint {

struct CsvReadOptions {
  unsigned threads = 0;          // 0: all cores
  bool allow_nonfinite = false;  // accept nan/inf values instead of rejecting them
  Progress* progress = nullptr;
};

struct CsvWriteOptions {
  int decimals = -1;  // < 0: shortest round trip; else fixed digits after the point (0..40)
  unsigned threads = 0;
  Progress* progress = nullptr;
};

Result<PointSet> readCsv(const std::string& path, const CsvReadOptions& options = {});

// Writes atomically (AtomicFile). Header `x,y` when the set is planar (every z is +0.0),
// else `x,y,z`; `,r,g,b` when it has colours. Triangles are not stored in CSV.
Status writeCsv(const std::string& path, const PointSet& points, const CsvWriteOptions& options = {});

}  // namespace dpoint
