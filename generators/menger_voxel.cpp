// The Menger sponge by the seed's method: sample its occupancy on a grid and run marching cubes.
//
// Sample i of N per axis sits at the voxel centre (i + 0.5)·size/N and takes the occupancy of lattice
// cell floor((i + 0.5)·3^n / N), computed in integers as floor((2i + 1)·3^n / 2N), so no rounding
// decides membership (a centre exactly on a lattice plane goes to the upper cell). One empty
// sample on every side closes the surface; marching cubes at 0.5 puts each vertex midway between
// an inside and an outside sample.
#include <cmath>

#include "core/memory.h"
#include "core/parallel.h"
#include "generators/marching_cubes.h"
#include "generators/menger.h"

namespace dpoint {

Result<PointSet> generateMengerVoxel(const MengerParams& params) {
  const int n = params.level;  // level and size were checked by generateMenger
  constexpr int kMaxResolution = 4096;
  if (params.resolution < 2 || params.resolution > kMaxResolution)
    return Error{"--resolution " + std::to_string(params.resolution) + ": must be 2.." + std::to_string(kMaxResolution) +
                     " for the voxel method",
                 ExitCode::kUsage};  // a range, as every generator's --resolution (--max-memory bounds the rest)
  const uint64_t res = static_cast<uint64_t>(params.resolution);
  const uint64_t padded = res + 2;
  // The field (one double a sample) dominates; the mesh is at most a few vertices per boundary voxel.
  if (Status s = checkMemory("menger voxel grid of " + std::to_string(padded) + "^3 samples",
                             padded * padded * padded * sizeof(double) + 40 * padded * padded * 6 * sizeof(double),
                             params.max_memory);
      !s)
    return s.error();

  uint64_t side = 1;
  for (int l = 0; l < n; ++l) side *= 3;
  // Lattice cell of sample i (0-based inside the sponge's range): floor((2i + 1)·side / 2res).
  std::vector<uint64_t> cell(res);
  for (uint64_t i = 0; i < res; ++i) cell[i] = ((2 * i + 1) * side) / (2 * res);

  std::vector<double> field(padded * padded * padded, 0.0);
  parallelFor(res, params.threads, [&](size_t i, unsigned) {
    for (uint64_t j = 0; j < res; ++j)
      for (uint64_t k = 0; k < res; ++k)
        if (mengerCellInSponge(cell[i], cell[j], cell[k])) field[((i + 1) * padded + j + 1) * padded + k + 1] = 1.0;
  });
  const double step = params.size / static_cast<double>(res);
  // Sample 1 (the first inside the range) sits at the centre of voxel 0: 0.5·step.
  const glm::dvec3 origin(-0.5 * step);
  const int p = static_cast<int>(padded);
  return marchingCubes(field, p, p, p, 0.5, origin, glm::dvec3(step));
}

}  // namespace dpoint
