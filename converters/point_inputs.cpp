#include "converters/point_inputs.h"

#include <algorithm>

#include "core/tile.h"

namespace dpoint {
namespace {

// Every path a tile of the same count, each index once.
bool completeTileSet(const std::vector<std::string>& paths) {
  std::vector<bool> seen;
  for (const std::string& path : paths) {
    if (!isTileFile(path)) return false;
    Result<TileHeader> h = readTileHeader(path);
    if (!h) return false;  // read file by file: the PLY reader names what is wrong
    if (seen.empty()) seen.assign(h->tile.count, false);
    if (h->tile.count != seen.size() || seen[h->tile.index]) return false;
    seen[h->tile.index] = true;
  }
  return std::all_of(seen.begin(), seen.end(), [](bool s) { return s; }) && seen.size() == paths.size();
}

}  // namespace

Result<PointSet> readPointInputs(const std::vector<std::string>& paths, const ReadOptions& options) {
  if (paths.size() == 1) return readPoints(paths[0], options);
  if (completeTileSet(paths)) {
    Result<PointSet> whole = mergeTiles(paths, 0, options.progress);
    if (whole && options.points_only) whole->triangles.clear();
    return whole;
  }
  PointSet out;
  bool any_colors = false;
  for (const std::string& path : paths) {
    Result<PointSet> part = readPoints(path, options);
    if (!part) return part.error();
    if (part->size() == 0) continue;
    if (out.size() + part->size() > UINT32_MAX && !part->triangles.empty())
      return Error{path + ": the inputs hold more than 2^32 points, past what triangle indices address",
                   ExitCode::kResourceLimit};
    const uint32_t offset = static_cast<uint32_t>(out.size());
    for (uint32_t index : part->triangles) out.triangles.push_back(offset + index);
    // Colours: white for the files without, before the first coloured one and after it.
    if (part->hasColors()) {
      any_colors = true;
      out.colors.resize(out.size(), glm::vec3(1.0f));
      out.colors.insert(out.colors.end(), part->colors.begin(), part->colors.end());
    } else if (any_colors) {
      out.colors.resize(out.size() + part->size(), glm::vec3(1.0f));
    }
    out.positions.insert(out.positions.end(), part->positions.begin(), part->positions.end());
  }
  return out;
}

std::string describeInputs(const std::vector<std::string>& paths) {
  if (paths.size() == 1) return paths[0];
  return paths[0] + " and " + std::to_string(paths.size() - 1) + " more";
}

}  // namespace dpoint
