// LAZ layered chunks (LASzip compressor 3, item version 3): the point formats 6–8 of LAS 1.4,
// POINT14, RGB14, RGBNIR14 and BYTE14, decoded and encoded. (Being written.)
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "converters/laz_decode.h"
#include "core/result.h"

namespace dpoint {

// Decodes one layered chunk of `points` (≥ 1) points from [data, data + bytes) into `records`
// (points × info.recordLength() bytes), as decodeLazChunk does for pointwise chunks.
Status decodeLayeredChunk(const LazInfo& info, const char* data, size_t bytes, uint64_t points, char* records);

// The bytes of one layered chunk holding `points` (≥ 1) records of info.recordLength() bytes.
std::vector<uint8_t> encodeLayeredChunk(const LazInfo& info, const char* records, uint64_t points);

}  // namespace dpoint
