#include "core/point_set.h"

#include <cassert>
#include <cstring>

#include <glm/common.hpp>

namespace dpoint {

bool PointSet::isPlanar() const {
  for (const glm::dvec3& p : positions) {
    uint64_t bits;
    std::memcpy(&bits, &p.z, sizeof bits);
    if (bits != 0) return false;
  }
  return true;
}

Box boundingBox(const std::vector<glm::dvec3>& positions, size_t first, size_t last) {
  assert(first < last && last <= positions.size());
  Box box{positions[first], positions[first]};
  for (size_t i = first + 1; i < last; ++i) {
    box.min = glm::min(box.min, positions[i]);
    box.max = glm::max(box.max, positions[i]);
  }
  return box;
}

}  // namespace dpoint
