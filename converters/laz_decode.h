// LAZ (LASzip-compressed LAS) decoding: the point records of a .laz file back as the uncompressed
// LAS records, byte for byte. dpoint's own decoder, written from LASzip's sources
// (lasreadpoint, lasreaditemcompressed_v1 and _v2, laszip_common_v2, laszip.cpp's VLR; Apache 2.0)
// and laz-perf's (readers.cpp, detail/field_*.cpp), on the entropy coder of laz_codec.h. The
// layered chunks of point formats 6–8 are laz_layered.h's; the item decoders of versions 1 and 2
// are laz_decode_v1.cpp's and laz_decode_v2.cpp's.
//
// The format, as relied on here:
// - The LAS header's point data format byte has bit 7 (old writers: bit 6) set; the format is the
//   byte & 0x3F. Record length and point counts are the uncompressed records'.
// - A VLR "laszip encoded" / 22204 describes the coding: compressor u16, coder u16, version major
//   u8, minor u8, revision u16, options u32, chunk size u32 (0xFFFFFFFF: variable), number and
//   offset of special EVLRs (i64 each), item count u16, then per item type, size, version (u16).
// - Compressor 1 (pointwise, LASzip 1.x's): at the offset to point data the first point raw, then
//   one arithmetic code of all the other points, up to the file's end (LAS 1.4: its first EVLR);
//   no chunk table. It decodes as one chunk of every point.
// - Compressors 2 and 3: at the offset to point data, an i64: the chunk table's offset (−1: written
//   at the file's last 8 bytes). The chunks follow that i64, back to back. The table: version u32
//   (0), chunk count u32, then per chunk its point count (variable chunks only) and byte count,
//   each coded with an integer decompressor (32 bits, 2 contexts) predicted from the previous
//   chunk's.
// - A chunk (compressor 2, pointwise): its first point raw (the items' bytes in order), then an
//   arithmetic code of the other points, item by item, every model reset at the chunk's start.
//   A layered chunk (compressor 3): the first point raw, the point count, then one code per field
//   group (layer) and its byte count (laz_layered.h). A fixed chunk size gives every chunk that
//   many points but the last.
// - Item decoders, versions 1 (LASzip 1.x) and 2: POINT10 (type 6, 20 bytes: the fields shared by
//   formats 0–5), GPSTIME11 (7, 8 bytes), RGB12 (8, 6 bytes), BYTE (0, the extra bytes, n bytes).
//   Version 3: POINT14 (10, 30 bytes: all of formats 6–10's first 30), RGB14 (11, 6), RGBNIR14
//   (12, 8), BYTE14 (14, n).
//
// Supported, with the arithmetic coder, fixed and variable chunks and LAS 1.0–1.4 headers:
// compressors 1 (pointwise) and 2 (pointwise chunked) with item versions 1 and 2, point formats
// 0–3; compressor 3 (layered chunked) with item version 3, point formats 6–8; either with or
// without extra bytes. Refused by name: other coders, item version 4 (LASzip 3.4's context-switch
// fix), layered items with compressors 1 and 2 and the older items with 3, the waveform items of
// formats 4, 5, 9 and 10 (WAVEPACKET13, WAVEPACKET14), items that disagree with the header's
// format, and a file whose chunk table is missing (its writer was interrupted; LASzip rebuilds
// such a table, dpoint does not).
//
// Hostile input: every length and offset is checked against the file before it is used, a
// chunk's decoder reads only the chunk's bytes, and a chunk must decode its points with exactly its
// bytes (LASzip's encoder pads its last bytes so that a decoder ends where the chunk ends; so does
// compressor 1's, at the point data's end), so a truncated or corrupt chunk is an Error naming the
// chunk and the point, never a crash. No item decoder loops on its data (version 2's GPS time
// follows at most one sequence switch per point). A corrupt chunk can still decode to wrong points
// that pass these checks: LAZ has no checksum.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/input_file.h"
#include "core/memory.h"
#include "core/result.h"

namespace dpoint {

// LASzip's item types (laszip.hpp's LASitem::Type), the one list for every LAZ file: formats 0–5
// use POINT10 [GPSTIME11] [RGB12] [WAVEPACKET13] [BYTE], formats 6–10 POINT14 [RGB14 or
// RGBNIR14] [WAVEPACKET14] [BYTE14]. Types 1–5 (SHORT to DOUBLE) were never written.
enum LazItemType : uint16_t {
  kLazByte = 0,
  kLazPoint10 = 6,
  kLazGpsTime11 = 7,
  kLazRgb12 = 8,
  kLazWavePacket13 = 9,
  kLazPoint14 = 10,
  kLazRgb14 = 11,
  kLazRgbNir14 = 12,
  kLazWavePacket14 = 13,
  kLazByte14 = 14,
};

struct LazItem {
  uint16_t type = 0, size = 0, version = 0;
};

// The laszip VLR.
struct LazInfo {
  uint16_t compressor = 0, coder = 0;
  uint8_t major = 0, minor = 0;
  uint16_t revision = 0;
  uint32_t options = 0;
  uint32_t chunk_size = 0;  // kLazVariableChunks: each chunk's count is in the chunk table
  std::vector<LazItem> items;

  // Bytes of one uncompressed record: the sum of the items' sizes.
  uint32_t recordLength() const;
  bool variableChunks() const;
};
constexpr uint32_t kLazVariableChunks = 0xFFFFFFFFu;

// Parses the laszip VLR's data (without its 54-byte VLR header). Fails, naming what is wrong, on
// a short or inconsistent record and on anything this decoder does not support (top comment):
// "LAZ item type 9 (WAVEPACKET13) version 1 is not supported (...)".
Result<LazInfo> parseLaszipVlr(std::string_view data);

// The items a LAS point format 0–3 or 6–8 with `record_length`-byte records needs (POINT10,
// GPSTIME11 for 1 and 3, RGB12 for 2 and 3, BYTE for extra bytes; POINT14, RGB14 for 7, RGBNIR14
// for 8, BYTE14 for extra bytes), compared with `info`'s: an Error saying both lists when they
// differ, or naming the format when it is not supported.
Status checkLazItems(const LazInfo& info, int point_format, uint32_t record_length);

struct LazChunk {
  uint64_t offset = 0;  // in the file
  uint64_t bytes = 0;
  uint64_t points = 0;
};

// Reads the i64 at `point_data_offset` and the chunk table it points to (compressors 2 and 3:
// compressor 1 has no table, an Error). Checks that the chunks lie between the i64 and the table,
// that their points add up to `point_count`, and that the table is neither missing, past the
// file's end nor corrupt. Messages start with the file's path.
Result<std::vector<LazChunk>> readLazChunkTable(const InputFile& file, uint64_t point_data_offset,
                                                const LazInfo& info, uint64_t point_count);

// Decodes one chunk of `points` (≥ 1) points from [data, data + bytes) into `records`, which holds
// points × info.recordLength() bytes: the LAS point records (a layered chunk through
// decodeLayeredChunk; compressor 1's point data is one chunk). Reads nothing outside the data.
// Fails when the data ends before the points do, holds an invalid code, or has bytes left over;
// the message names the point ("point 812 of 50000: ...") but not the file or chunk (the caller's).
// `info` must have passed parseLaszipVlr.
Status decodeLazChunk(const LazInfo& info, const char* data, size_t bytes, uint64_t points, char* records);

// A LAZ file's chunks, to decode a few at a time (LasPointStream): the laszip VLR, the chunk
// table, each chunk's first point, and the header's record length and count. Compressor 1's point
// data is one chunk of every point (none when there are no points).
struct LazChunks {
  LazInfo info;
  std::vector<LazChunk> chunks;
  std::vector<uint64_t> first_point;  // per chunk
  uint32_t record_length = 0;
  uint64_t point_count = 0;
};
// Parses the header fields, the laszip VLR and the chunk table (readLazChunkTable's checks); for
// compressor 1, where the point data ends.
Result<LazChunks> openLazChunks(const InputFile& file);
// Decodes chunks [first, last) into `records` (their points × record length bytes, from chunk
// `first`'s first point) on `threads` threads (0: all cores); the error is the first failing
// chunk's, naming the file, the chunk, its bytes and points.
Status decodeLazChunks(const InputFile& file, const LazChunks& laz, size_t first, size_t last, char* records,
                       unsigned threads = 0);
// The mechanism under it, for chunks that need not follow each other in the file (COPC's nodes):
// each chunk read and decoded on one of `threads` threads (0: all cores) into `records`, one after
// another in the list's order. Errors start with where(i), the caller's name for chunk i (file
// and position); the one reported is the first failing chunk's, whatever the thread count.
Status decodeLazChunkList(const InputFile& file, const LazInfo& info, std::span<const LazChunk> chunks,
                          uint32_t record_length, char* records, unsigned threads,
                          const std::function<std::string(size_t)>& where);

// All point records of a .laz file (LAS 1.0–1.4, point formats 0–3 and 6–8), count × record length bytes,
// exactly as the uncompressed .las holds them. Parses the LAS header fields it needs (version,
// header size, offset to point data, VLR count, point format, record length, legacy and 64-bit
// counts), finds the laszip VLR among the VLRs, reads the chunk table and decodes the chunks on
// `threads` threads (0: all cores), each into its own place: the result does not depend on the
// thread count, nor does the error (the first failing chunk's). The records are allocated only
// after every check, and only within `max_memory` (0: defaultMemoryLimit(); past it an Error with
// ExitCode::kResourceLimit): LAZ's compression ratio has no bound, so a small file may claim many
// points.
Result<std::string> decodeLazFile(const std::string& path, unsigned threads = 0, uint64_t max_memory = 0);
// The same from an open file (bytes in memory: InputFile::fromMemory).
Result<std::string> decodeLaz(const InputFile& file, unsigned threads = 0, uint64_t max_memory = 0);

// decodeLaz's records in memory that nothing zeroes first (a LargeBuffer, 2 MiB pages where the
// kernel gives them): each chunk's pages are first touched by the worker that decodes it, so a
// large file pays no serial fill before the parallel decode (a zero fill and a copy after it kept
// two cores at 1.55–1.72× one core's speed; bench/results/2026-11-28/cpu/laz_scaling.md). `lead` bytes
// are left, unwritten, in front of the records for the caller (readLas puts the file's header and
// VLRs there and reads the whole as a LAS file, with no copy).
struct LazRecords {
  LargeBuffer bytes;  // lead + count × record length
  std::string_view view() const { return {bytes.data(), bytes.size()}; }
};
Result<LazRecords> decodeLazRecords(const InputFile& file, unsigned threads = 0, uint64_t max_memory = 0,
                                    size_t lead = 0);

}  // namespace dpoint
