// LAZ layered chunks: LASzip's compressor 3 with item version 3, the coding of LAS 1.4's point
// formats 6–8 (items POINT14, RGB14, RGBNIR14 and BYTE14), decoded and encoded. dpoint's own code,
// written from LASzip's sources (lasreadpoint, laswritepoint, lasreaditemcompressed_v3,
// laswriteitemcompressed_v3, laszip_common_v3; Apache 2.0) and laz-perf's (detail/field_point14,
// field_rgb14, field_nir14, field_byte14), on the entropy coder of laz_codec.h / laz_encoder.h.
//
// The chunk, as it lies between two chunk-table boundaries:
// - the first point raw (all items' bytes, info.recordLength()), u32 the chunk's point count;
// - u32 byte counts of every layer, item by item: POINT14's nine (channel, returns and x/y; z;
//   classification; flags; intensity; scan angle; user data; point source ID; GPS time), RGB14's
//   one, RGBNIR14's two (RGB, NIR), BYTE14's one per extra byte;
// - the layers in that order, each its own arithmetic code of the points after the first.
// A layer other than the first two is written only when some value in it changes within the
// chunk (LASzip's "changed" flags): a 0-byte layer means every point keeps the value before it,
// and a decoder then reads nothing for it.
//
// The point's scanner channel (record byte 15, bits 4–5) selects one of four contexts: each has
// its own models, its own last point and predictors, created when a point of that channel first
// appears in the chunk, starting from the last point of the channel before. Item version 3 has two
// quirks that its bytes depend on, kept here: the colour and extra-byte items are told the channel
// only on a point where it changes (else channel 0), and on a switch to a context that exists
// already they still predict that point from the previous context's last values.
//
// Not covered: item version 4 (LASzip 3.4's fix of those quirks; refused by parseLaszipVlr), the
// waveform items (formats 9, 10) and LASzip's selective decompression.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "converters/laz_decode.h"
#include "core/result.h"

namespace dpoint {

// Decodes one layered chunk of `points` (≥ 1) points from [data, data + bytes) into `records`
// (points × info.recordLength() bytes), as decodeLazChunk does for pointwise chunks: reads nothing
// outside the data and no layer past its own bytes. Fails when the items are not POINT14 [RGB14 or
// RGBNIR14] [BYTE14] (version 3), when the chunk's own point count is not `points`, when the layer
// sizes do not add up to the chunk's bytes, and when a layer ends early, holds an invalid code or
// has bytes left over; the message names the point and the layer ("point 812 of 50000: the
// intensity layer (...)"), not the file or the chunk (the caller's).
Status decodeLayeredChunk(const LazInfo& info, const char* data, size_t bytes, uint64_t points, char* records);

// The bytes of one layered chunk holding `points` (1 ≤ points < 2^32) records of
// info.recordLength() bytes, as LASzip 3.x writes them. `info`'s items must be POINT14 [RGB14 or
// RGBNIR14] [BYTE14] (an assert: lazInfoForFormat gives them). GPS times are compared as bit
// patterns, so every record, NaN or −0 included, decodes to the same bytes.
std::vector<uint8_t> encodeLayeredChunk(const LazInfo& info, const char* records, uint64_t points);

}  // namespace dpoint
