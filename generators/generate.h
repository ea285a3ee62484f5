// What `dpoint generate` does around any generator, for every front end: the colours and the
// offset applied point by point after it (a tile applies them to its own points alike), and the
// signature that makes the tiles of separate runs one dataset (converters/tile_file.h).
#pragma once

#include <cstdint>
#include <string>

#include <glm/vec3.hpp>

#include "core/point_set.h"
#include "core/result.h"

namespace dpoint {

// --colors: auto (the kind's own choice), noise (the seed's pnoise3), none.
enum class PointColors { kAuto, kNoise, kNone };

// Whether `colors` means noise for a kind whose auto is noise (auto_noise) or not.
bool noiseColors(PointColors colors, bool auto_noise);

struct PointColoring {
  PointColors colors = PointColors::kAuto;
  bool auto_noise = false;  // what auto means for the kind: noise for the 3D fractals
  unsigned threads = 0;
  uint64_t max_memory = 0;  // bytes; 0: half of physical memory
};

// Drops the colours (none), or colours by noise on the generator's own coordinates (before any
// offset) when the colours fit the memory limit (kResourceLimit otherwise).
Status colorGenerated(PointSet& points, const PointColoring& coloring);

// Every point moved by `offset`: exact double sums, one rounding each. Fails (exit 1, naming the
// first such point) where a sum leaves double's range: no file of infinite coordinates is written.
Status offsetPoints(PointSet& points, const glm::dvec3& offset);

// The kind and every option that shapes the points, from "name=value" lines (CLI11's
// config_to_str, given or default), less those that only say where and how to run or write.
std::string tileSignature(const std::string& kind, const std::string& option_lines);

}  // namespace dpoint
