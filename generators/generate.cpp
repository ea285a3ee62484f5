#include "generators/generate.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <vector>

#include "core/memory.h"
#include "core/text.h"
#include "generators/perlin.h"

namespace dpoint {

bool noiseColors(PointColors colors, bool auto_noise) {
  return colors == PointColors::kNoise || (colors == PointColors::kAuto && auto_noise);
}

Status colorGenerated(PointSet& points, const PointColoring& coloring) {
  const bool noise = noiseColors(coloring.colors, coloring.auto_noise);
  if (coloring.colors == PointColors::kNone) points.colors.clear();
  if (!noise) return okStatus();
  // The generators' own estimates cover positions and triangles; colours come on top.
  const uint64_t needed = points.size() * (sizeof(glm::dvec3) + sizeof(glm::vec3)) + points.triangles.size() * 4;
  if (Status s = checkMemory("colouring " + std::to_string(points.size()) + " points", needed, coloring.max_memory); !s)
    return s;
  colorByNoise(points, coloring.threads);
  return okStatus();
}

Status offsetPoints(PointSet& points, const glm::dvec3& offset) {
  size_t beyond = SIZE_MAX;
  for (size_t i = 0; i < points.size(); ++i) {
    glm::dvec3& p = points.positions[i];
    p += offset;
    if (beyond == SIZE_MAX && !(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))) beyond = i;
  }
  if (beyond == SIZE_MAX) return okStatus();
  return Error{"--offset " + formatNumber(offset.x) + "," + formatNumber(offset.y) + "," + formatNumber(offset.z) +
                   ": point " + std::to_string(beyond) + " moved by it leaves double's range (" +
                   formatNumber(points.positions[beyond].x) + ", " + formatNumber(points.positions[beyond].y) + ", " +
                   formatNumber(points.positions[beyond].z) + ")",
               ExitCode::kUsage};
}

std::string tileSignature(const std::string& kind, const std::string& option_lines) {
  static const std::vector<std::string> kIgnored = {"output", "tile", "threads", "quiet", "grid-out", "device",
                                                    "max-memory", "decimals", "order", "validate", "counts", "mesh", "help"};
  std::istringstream lines(option_lines);
  std::string line, signature = kind;
  while (std::getline(lines, line)) {
    const std::string name = line.substr(0, line.find('='));
    if (line.empty() || std::find(kIgnored.begin(), kIgnored.end(), name) != kIgnored.end()) continue;
    signature += " " + line;
  }
  return signature;
}

}  // namespace dpoint
