// The data model (DESIGN §2): only what a scene needs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

namespace dpoint {

struct PointSet {
  std::vector<glm::dvec3> positions;  // always double
  std::vector<glm::vec3> colors;      // empty, or one linear 0..1 colour per point
  std::vector<uint32_t> triangles;    // empty for point sets; 3 vertex indices per triangle

  size_t size() const { return positions.size(); }
  bool hasColors() const { return !colors.empty(); }
  bool isMesh() const { return !triangles.empty(); }
  // True when every z is +0.0 (bit pattern zero): the set is 2D and CSV writes `x,y`.
  bool isPlanar() const;
};

// Smallest and largest coordinates of positions [first, last); asserts first < last.
struct Box {
  glm::dvec3 min{0.0}, max{0.0};
};
Box boundingBox(const std::vector<glm::dvec3>& positions, size_t first, size_t last);
inline Box boundingBox(const std::vector<glm::dvec3>& positions) { return boundingBox(positions, 0, positions.size()); }

}  // namespace dpoint
