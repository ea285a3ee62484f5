// LAZ encoding: LAS point records compressed as LASzip compresses them, so that LASzip, laz-perf
// and every reader built on them (PDAL, QGIS, CloudCompare, the COPC viewers) read dpoint's .laz
// files. The inverse of laz_decode.h, which says what the format is; written from LASzip's
// writers (laswritepoint, laswriteitemcompressed_v2, laszip.cpp's VLR; Apache 2.0) on the entropy
// coder of laz_encoder.h.
//
// What dpoint writes:
// - Point formats 0–3: compressor 2 (pointwise chunked), items POINT10, GPSTIME11, RGB12 and BYTE
//   (extra bytes), version 2, as LASzip 2.x and 3.x write them.
// - Point formats 6–8: compressor 3 (layered chunked), items POINT14, RGB14, RGBNIR14 and BYTE14,
//   version 3 (laz_layered.h), as LASzip 3.x writes LAS 1.4 points.
// - Chunks of kLazChunkPoints points (LASzip's default), each compressed on its own (in parallel),
//   then the chunk table; the i64 before the chunks holds the table's offset.
// - The laszip VLR last among the VLRs, version 3.4 r3, no special EVLRs (−1, −1).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "converters/laz_decode.h"
#include "core/result.h"

namespace dpoint {

constexpr uint32_t kLazChunkPoints = 50000;

// The laszip VLR's contents for records of `point_format` (0–3, 6–8) of `record_length` bytes (the
// format's base size plus extra bytes). Fails for other formats (4, 5, 9, 10 carry waveforms).
Result<LazInfo> lazInfoForFormat(int point_format, uint32_t record_length, uint32_t chunk_size = kLazChunkPoints);

// The laszip VLR's data, without its 54-byte VLR header (what parseLaszipVlr reads).
std::string laszipVlrData(const LazInfo& info);

// One chunk: `points` (≥ 1) records of info.recordLength() bytes compressed, as they lie in the
// file (the first record raw, then the code).
std::vector<uint8_t> encodeLazChunk(const LazInfo& info, const char* records, uint64_t points);

// The chunk table (version 0, the count, the coded sizes) for chunks of these byte sizes (and,
// for variable chunks, point counts).
std::string encodeLazChunkTable(const LazInfo& info, const std::vector<LazChunk>& chunks);

// A whole uncompressed LAS file (1.0–1.4, point formats 0–3 and 6–8, VLRs and EVLRs kept) as a
// LAZ file: the header's format byte marked (bit 7), the laszip VLR added, the records chunked and
// compressed on `threads` threads (0: all cores), EVLRs after the chunk table. Fails naming what
// is wrong with the input (not LAS, a waveform format, records past the end).
Result<std::string> compressLasBytes(std::string_view las, unsigned threads = 0,
                                     uint32_t chunk_size = kLazChunkPoints);

}  // namespace dpoint
