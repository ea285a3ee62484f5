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

// Point n of the set `seed` gives: z = 0, x and y from outputs 2n and 2n + 1 of splitmix64, each
// u as ((u >> 11) - 2^52) · 2^-52. Cheap enough to make again where a caller needs it (a writer's
// rows, made as they are written: core/point_set.h's MadePositions).
inline glm::dvec3 random2dPoint(uint64_t seed, uint64_t n) {
  // (u >> 11) is an integer m < 2^53; (m - 2^52) · 2^-52 lies in [-1, 1) and both steps are exact
  // (an integer below 2^53 in magnitude, then a power-of-two scaling).
  auto unitSigned = [](uint64_t u) {
    return static_cast<double>(static_cast<int64_t>(u >> 11) - (int64_t{1} << 52)) * 0x1p-52;
  };
  return glm::dvec3(unitSigned(splitmix64At(seed, 2 * n)), unitSigned(splitmix64At(seed, 2 * n + 1)), 0.0);
}

Result<PointSet> generateRandom2d(const Random2dParams& params);
// Tile `tile` (core/tile.h): points [⌊I·count/N⌋, ⌊(I+1)·count/N⌋), at most 2^32 of them.
Result<PointTile> generateRandom2dTile(const Random2dParams& params, TileSpec tile);

}  // namespace dpoint
