#include "generators/random2d.h"

#include "core/memory.h"
#include "core/parallel.h"

namespace dpoint {
namespace {

constexpr size_t kPointsPerChunk = 1u << 16;

// Points [first, last) of the whole set.
Result<PointSet> generateRange(const Random2dParams& params, uint64_t first, uint64_t last) {
  if (params.count == 0) return Error{"--count 0: must be at least 1", ExitCode::kUsage};
  const uint64_t count = last - first;
  if (Status s = checkMemory("random2d with " + std::to_string(count) + " points", count * sizeof(glm::dvec3),
                             params.max_memory);
      !s)
    return s.error();
  PointSet points;
  resizePrefaulted(points.positions, count, params.threads);
  const size_t chunks = (count + kPointsPerChunk - 1) / kPointsPerChunk;
  if (params.progress) params.progress->start("random2d", count);
  parallelFor(chunks, params.threads, [&](size_t chunk, unsigned) {
    const size_t end = std::min<size_t>(count, (chunk + 1) * kPointsPerChunk);
    for (size_t i = chunk * kPointsPerChunk; i < end; ++i) points.positions[i] = random2dPoint(params.seed, first + i);
    if (params.progress) params.progress->advance(end - chunk * kPointsPerChunk);
  });
  if (params.progress) params.progress->finish();
  return points;
}

}  // namespace

Result<PointSet> generateRandom2d(const Random2dParams& params) { return generateRange(params, 0, params.count); }

Result<PointTile> generateRandom2dTile(const Random2dParams& params, TileSpec tile) {
  const TileRange range = tileRange(params.count, tile);
  Result<PointSet> points = generateRange(params, range.begin, range.end);
  if (!points) return points.error();
  if (points->size() > UINT32_MAX)
    return Error{"random2d: tile " + std::to_string(tile.index) + " has more than 2^32 points; use more tiles",
                 ExitCode::kResourceLimit};
  PointTile out;
  out.tile = tile;
  out.owned = static_cast<uint32_t>(points->size());
  out.points = std::move(*points);
  return out;
}

}  // namespace dpoint
