// LAZ layered chunks (converters/laz_layered.h). Not written yet: both directions refuse.
#include "converters/laz_layered.h"

namespace dpoint {

Status decodeLayeredChunk(const LazInfo&, const char*, size_t, uint64_t, char*) {
  return Error{"layered LAZ chunks (point formats 6 to 8) are not decoded yet"};
}

std::vector<uint8_t> encodeLayeredChunk(const LazInfo&, const char*, uint64_t) { return {}; }

}  // namespace dpoint
