#include "core/point_set.h"

#include <cstring>

namespace dpoint {

bool PointSet::isPlanar() const {
  for (const glm::dvec3& p : positions) {
    uint64_t bits;
    std::memcpy(&bits, &p.z, sizeof bits);
    if (bits != 0) return false;
  }
  return true;
}

}  // namespace dpoint
