// libFuzzer target `ply`: the PLY reader `dpoint convert IN.ply` runs (converters/ply.h: ASCII and
// binary, vertices and faces), given the input's bytes as a file (InputFile::fromMemory), then
// again as `dpoint render` reads it (points only, so it stops after the vertices).
#include <cstring>

#include "converters/ply.h"
#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace dpoint;
  const InputFile input = InputFile::fromMemory("fuzz.ply", fuzz::bytesOf(data, size));
  PlyReadOptions options;
  options.threads = 1;
  options.max_memory = fuzz::kMaxMemory;
  Result<PointSet> whole = readPly(input, options);
  fuzz::checkOutcome(whole, input.path());
  options.points_only = true;
  Result<PointSet> points = readPly(input, options);
  fuzz::checkOutcome(points, input.path());
  // Reading less can only fail where reading everything failed, and gives the same points.
  if (whole && !points) fuzz::broken("points-only reads what the whole read read", points.error().message);
  const auto same = [](const auto& a, const auto& b) {  // bitwise: NaN may be allowed some day
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0);
  };
  if (whole && points && !(same(whole->positions, points->positions) && same(whole->colors, points->colors)))
    fuzz::broken("points-only gives the same points", std::to_string(points->size()));
  return 0;
}
