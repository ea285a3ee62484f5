// The study's 2D datasets: N points uniform in [-1, 1)², z = 0.
//
// Own generator and own integer-to-double mapping, so the file is the same on every standard
// library and for every thread count: point i takes outputs 2i and 2i+1 of splitmix64 (Steele,
// Lea, Flood 2014; a counter-based generator, so any point can be computed on its own), and a
// 64-bit output u maps to ((u >> 11) - 2^52) · 2^-52, exact in double: a uniform grid of step
// 2^-52 on [-1, 1).
#pragma once

#include <cstdint>

#include "core/point_set.h"
#include "core/random.h"
#include "core/progress.h"
#include "core/result.h"
#include "core/tile.h"

namespace dpoint {

struct Random2dParams {
  uint64_t count = 1000000;
  uint64_t seed = 1;
  unsigned threads = 0;          // 0: all cores
  uint64_t max_memory = 0;       // bytes; 0: half of physical memory
  Progress* progress = nullptr;
};

Result<PointSet> generateRandom2d(const Random2dParams& params);
// Tile `tile` (core/tile.h): points [⌊I·count/N⌋, ⌊(I+1)·count/N⌋), at most 2^32 of them.
Result<PointTile> generateRandom2dTile(const Random2dParams& params, TileSpec tile);

}  // namespace dpoint
