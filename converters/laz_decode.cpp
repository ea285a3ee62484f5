// LAZ decoding (converters/laz_decode.h says what and whence): the laszip VLR, the chunk table, one
// chunk and the file-level decode; the item decoders are laz_decode_v1.cpp's and
// laz_decode_v2.cpp's. Only little-endian hosts: fields are copied out of the bytes with memcpy, as
// in las.cpp.
#include "converters/laz_decode.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstring>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <span>

#include "converters/laz_codec.h"
#include "converters/laz_item_decoder.h"
#include "converters/laz_layered.h"
#include "core/bytes.h"
#include "core/memory.h"
#include "core/parallel.h"

namespace dpoint {

static_assert(std::endian::native == std::endian::little, "LAZ fields are little-endian, copied as they are");

namespace {

std::string str(uint64_t v) { return std::to_string(v); }

// LASzip's item type names (laszip.hpp), for messages.
std::string itemName(uint16_t type) {
  // Types 0..14 as LASzip enumerates them (of the first six only BYTE is ever written).
  static const char* const kNames[] = {"BYTE", "SHORT", "INT", "LONG", "FLOAT", "DOUBLE", "POINT10", "GPSTIME11",
                                       "RGB12", "WAVEPACKET13", "POINT14", "RGB14", "RGBNIR14", "WAVEPACKET14",
                                       "BYTE14"};
  return type < std::size(kNames) ? kNames[type] : "unknown";
}

std::string itemList(const std::vector<LazItem>& items) {
  std::string out;
  for (const LazItem& item : items) {
    if (!out.empty()) out += ", ";
    out += itemName(item.type);
    // Appended: GCC 12 warns falsely on "(" + string (bug 105651).
    if (item.type == kLazByte || item.type == kLazByte14) {
      out += '(';
      out += str(item.size);
      out += ')';
    }
  }
  return out.empty() ? "none" : out;
}

// --- The laszip VLR --------------------------------------------------------------------------------

constexpr size_t kVlrFixedBytes = 34;  // up to and with the item count
constexpr size_t kVlrItemBytes = 6;
constexpr uint16_t kCompressorPointwise = 1, kCompressorChunked = 2, kCompressorLayered = 3;

// The decoded item types and their sizes (0: any): versions 1 and 2 with compressors 1 and 2
// (point formats 0–3; version 1 is LASzip 1.x's), version 3 with compressor 3 (formats 6–8;
// laz_layered.h). LASzip codes LAS 1.4's points only in layers, and the older items never so.
struct ItemSupport {
  uint16_t type;
  uint16_t size;
};
constexpr ItemSupport kDecodedPointwise[] = {{kLazPoint10, 20}, {kLazGpsTime11, 8}, {kLazRgb12, 6}, {kLazByte, 0}};
constexpr ItemSupport kDecodedLayered[] = {{kLazPoint14, 30}, {kLazRgb14, 6}, {kLazRgbNir14, 8}, {kLazByte14, 0}};
constexpr uint16_t kLayeredVersion = 3;
bool pointwiseVersion(uint16_t version) { return version == 1 || version == 2; }
constexpr const char* kSupportedItems =
    "only versions 1 and 2 of POINT10, GPSTIME11, RGB12 and BYTE: point formats 0 to 3, and version 3 of POINT14, "
    "RGB14, RGBNIR14 and BYTE14: formats 6 to 8";

const ItemSupport* findSupport(const ItemSupport (&table)[4], uint16_t type) {
  for (const ItemSupport& s : table)
    if (s.type == type) return &s;
  return nullptr;
}


// The decoder of a pointwise item of either version.
std::unique_ptr<LazItemDecoder> makeItemDecoder(const LazItem& item, const uint8_t* first) {
  return item.version == 1 ? makeLazItemDecoderV1(item, first) : makeLazItemDecoderV2(item, first);
}

}  // namespace

// --- The laszip VLR --------------------------------------------------------------------------------

uint32_t LazInfo::recordLength() const {
  uint32_t length = 0;
  for (const LazItem& item : items) length += item.size;
  return length;
}

bool LazInfo::variableChunks() const { return chunk_size == kLazVariableChunks; }

Result<LazInfo> parseLaszipVlr(std::string_view data) {
  const std::string what = "laszip VLR: ";
  if (data.size() < kVlrFixedBytes)
    return Error{what + str(data.size()) + " bytes, fewer than the " + str(kVlrFixedBytes) + " of its fixed fields"};
  const char* p = data.data();
  LazInfo info;
  info.compressor = loadUnaligned<uint16_t>(p);
  info.coder = loadUnaligned<uint16_t>(p + 2);
  info.major = static_cast<uint8_t>(p[4]);
  info.minor = static_cast<uint8_t>(p[5]);
  info.revision = loadUnaligned<uint16_t>(p + 6);
  info.options = loadUnaligned<uint32_t>(p + 8);
  info.chunk_size = loadUnaligned<uint32_t>(p + 12);
  // p + 16, p + 24: the number and offset of special EVLRs (unused by LASzip itself).
  const uint16_t count = loadUnaligned<uint16_t>(p + 32);
  const size_t needed = kVlrFixedBytes + kVlrItemBytes * count;
  if (data.size() < needed)
    return Error{what + str(data.size()) + " bytes, fewer than the " + str(needed) + " that its " + str(count) +
                 " items need"};
  if (info.compressor != kCompressorPointwise && info.compressor != kCompressorChunked &&
      info.compressor != kCompressorLayered)
    return Error{what + "compressor " + str(info.compressor) + " is not one of LASzip's (1 to 3)"};
  if (info.coder != 0)
    return Error{"LAZ coder " + str(info.coder) + " is not supported (only 0, the arithmetic coder)"};
  // Compressor 1 has no chunks: LASzip 1.x wrote 0 or 1 here, later versions their default.
  if (info.chunk_size == 0 && info.compressor != kCompressorPointwise) return Error{what + "chunk size 0"};
  if (count == 0) return Error{what + "no items"};
  for (uint16_t i = 0; i < count; ++i) {
    const char* q = p + kVlrFixedBytes + kVlrItemBytes * i;
    LazItem item{loadUnaligned<uint16_t>(q), loadUnaligned<uint16_t>(q + 2), loadUnaligned<uint16_t>(q + 4)};
    const std::string name = "LAZ item type " + str(item.type) + " (" + itemName(item.type) + ")";
    // Each compressor has its own items (the table's comment).
    const bool layered = info.compressor == kCompressorLayered;
    const auto decodedBy = [&](bool by_layers) {
      const ItemSupport* s = findSupport(by_layers ? kDecodedLayered : kDecodedPointwise, item.type);
      const bool version = by_layers ? item.version == kLayeredVersion : pointwiseVersion(item.version);
      return version ? s : nullptr;
    };
    const ItemSupport* support = decodedBy(layered);
    if (!support && decodedBy(!layered))
      return Error{what + name + " version " + str(item.version) + " does not go with compressor " +
                   str(info.compressor) +
                   (layered ? " (layered chunked: version 3 of POINT14, RGB14, RGBNIR14 and BYTE14)"
                            : " (pointwise: versions 1 and 2 of POINT10, GPSTIME11, RGB12 and BYTE)")};
    if (!support)
      return Error{name + " version " + str(item.version) + " is not supported (" + kSupportedItems + ")"};
    if (support->size != 0 && item.size != support->size)
      return Error{what + name + " has size " + str(item.size) + ", not " + str(support->size)};
    if (item.size == 0) return Error{what + name + " has size 0"};
    info.items.push_back(item);
  }
  return info;
}

Status checkLazItems(const LazInfo& info, int point_format, uint32_t record_length) {
  const bool pointwise = point_format >= 0 && point_format <= 3, layered = point_format >= 6 && point_format <= 8;
  if (!pointwise && !layered)
    return Error{"LAZ point format " + str(static_cast<uint64_t>(point_format)) +
                 " is not supported (only formats 0 to 3 and 6 to 8: 4, 5, 9 and 10 carry waveforms)"};
  static constexpr uint32_t kBase[9] = {20, 28, 26, 34, 0, 0, 30, 36, 38};
  const uint32_t base = kBase[point_format];
  if (record_length < base)
    return Error{"point record length " + str(record_length) + " is shorter than point format " +
                 str(static_cast<uint64_t>(point_format)) + "'s " + str(base) + " bytes"};
  const uint16_t extra = static_cast<uint16_t>(record_length - base);
  std::vector<LazItem> expected;
  if (pointwise) {
    // The versions are not compared (parseLaszipVlr checked them).
    expected.push_back({kLazPoint10, 20, 0});
    if (point_format == 1 || point_format == 3) expected.push_back({kLazGpsTime11, 8, 0});
    if (point_format >= 2) expected.push_back({kLazRgb12, 6, 0});
    if (extra != 0) expected.push_back({kLazByte, extra, 0});
  } else {
    expected.push_back({kLazPoint14, 30, 0});
    if (point_format == 7) expected.push_back({kLazRgb14, 6, 0});
    if (point_format == 8) expected.push_back({kLazRgbNir14, 8, 0});
    if (extra != 0) expected.push_back({kLazByte14, extra, 0});
  }
  bool same = expected.size() == info.items.size();
  for (size_t i = 0; same && i < expected.size(); ++i)
    same = expected[i].type == info.items[i].type && expected[i].size == info.items[i].size;
  if (!same)
    return Error{"the laszip VLR's items (" + itemList(info.items) + ") do not match point format " +
                 str(static_cast<uint64_t>(point_format)) + " with " + str(record_length) + "-byte records (" +
                 itemList(expected) + ")"};
  return okStatus();
}

// --- One chunk -------------------------------------------------------------------------------------

Status decodeLazChunk(const LazInfo& info, const char* data, size_t bytes, uint64_t points, char* records) {
  if (info.compressor == kCompressorLayered) return decodeLayeredChunk(info, data, bytes, points, records);
  const size_t length = info.recordLength();
  assert(length > 0);
  if (points == 0) return Error{"a chunk of 0 points"};
  if (bytes < length)
    return Error{"the chunk's " + str(bytes) + " bytes are fewer than its first point's " + str(length) +
                 " raw bytes"};
  // The first point raw; the item decoders start from it.
  std::memcpy(records, data, length);
  std::vector<std::unique_ptr<LazItemDecoder>> decoders;
  std::vector<size_t> offsets;
  size_t offset = 0;
  for (const LazItem& item : info.items) {
    decoders.push_back(makeItemDecoder(item, reinterpret_cast<const uint8_t*>(records) + offset));
    offsets.push_back(offset);
    offset += item.size;
  }
  // The code starts after the raw point, even for a chunk of one point (its encoder flushed 4 bytes).
  // Compressor 1's whole point data is such a chunk.
  LazDecoder decoder(reinterpret_cast<const uint8_t*>(data) + length, bytes - length);
  const auto failure = [&](uint64_t point) {
    std::string where = "point " + str(point) + " of " + str(points) + ": ";
    if (decoder.invalid()) return Error{where + "invalid arithmetic code (corrupt data)"};
    return Error{where + "the compressed data ends early (the decoder needs " + str(decoder.overrun()) +
                 " bytes past the chunk's " + str(bytes) + "; truncated or corrupt)"};
  };
  if (!decoder.ok()) return failure(0);
  for (uint64_t p = 1; p < points; ++p) {
    uint8_t* record = reinterpret_cast<uint8_t*>(records) + p * length;
    for (size_t i = 0; i < decoders.size(); ++i) {
      decoders[i]->decode(decoder, record + offsets[i]);
      if (decoders[i]->corrupt())
        return Error{"point " + str(p) + " of " + str(points) + ": the GPS time switches time sequence twice (corrupt data)"};
    }
    if (!decoder.ok()) return failure(p);
  }
  const size_t left = bytes - length - decoder.consumed();
  if (left != 0)
    return Error{str(left) + " of the chunk's " + str(bytes) + " bytes are left over after its " + str(points) +
                 " points (corrupt chunk or chunk table)"};
  return okStatus();
}

// --- The chunk table -------------------------------------------------------------------------------

Result<std::vector<LazChunk>> readLazChunkTable(const InputFile& file, uint64_t point_data_offset, const LazInfo& info,
                                                uint64_t point_count) {
  const std::string& path = file.path();
  // (Compressor 1's chunk size may be 0: it must not reach the division below.)
  if (info.compressor == kCompressorPointwise)
    return Error{path + ": compressor 1 has no chunk table (its point data is one code)"};
  const uint64_t size = file.size();
  const auto readExactly = [&](uint64_t at, void* out, size_t n, const std::string& what) -> Status {
    if (at > size || size - at < n)
      return Error{path + ": truncated: " + what + " (" + str(n) + " bytes at byte " + str(at) +
                   ") is past the end of the " + str(size) + "-byte file"};
    Result<size_t> got = file.readAt(at, out, n);
    if (!got) return got.error();
    if (*got != n) return Error{path + ": truncated: " + what + " ends at the file's end"};
    return okStatus();
  };
  int64_t table_at = 0;
  if (Status s = readExactly(point_data_offset, &table_at, 8, "the chunk table's offset"); !s) return s.error();
  const uint64_t chunks_at = point_data_offset + 8;
  if (table_at == -1) {  // written by a writer that could not seek back: at the file's end
    if (size < chunks_at + 8)
      return Error{path + ": truncated: no chunk table offset at the end of the " + str(size) + "-byte file"};
    if (Status s = readExactly(size - 8, &table_at, 8, "the chunk table's offset at the file's end"); !s)
      return s.error();
  }
  if (table_at >= 0 && static_cast<uint64_t>(table_at) == point_data_offset)
    return Error{path + ": the chunk table is missing (its offset points at itself: the compressor was interrupted)"};
  if (table_at < 0 || static_cast<uint64_t>(table_at) < chunks_at)
    return Error{path + ": the chunk table's offset " + std::to_string(table_at) + " lies before the chunks' start " +
                 str(chunks_at)};
  const uint64_t table = static_cast<uint64_t>(table_at);
  if (table > size || size - table < 8)
    return Error{path + ": truncated: the chunk table's offset " + str(table) + " is past the end of the " + str(size) +
                 "-byte file"};
  uint32_t head[2] = {0, 0};
  if (Status s = readExactly(table, head, 8, "the chunk table"); !s) return s.error();
  const std::string where = "the chunk table at byte " + str(table);
  if (head[0] != 0)
    return Error{path + ": " + where + ": version " + str(head[0]) + " is not 0 (a wrong offset to the table?)"};
  const uint32_t count = head[1];

  // Bound the count before allocating: every chunk holds at least its raw first point and 4 bytes
  // more (a pointwise chunk's code ends with the 4 bytes an encoder flushes, a layered chunk has
  // its point count and layer sizes), between the chunks' start and the table.
  const uint64_t chunk_bytes = table - chunks_at;
  const uint64_t length = info.recordLength();
  if (count > chunk_bytes / (length + 4))
    return Error{path + ": " + where + " lists " + str(count) + " chunks, more than the " + str(chunk_bytes) +
                 " bytes before it can hold"};
  if (!info.variableChunks()) {
    const uint64_t needed = point_count / info.chunk_size + (point_count % info.chunk_size != 0 ? 1 : 0);
    if (count != needed)
      return Error{path + ": " + where + " lists " + str(count) + " chunks, but " + str(point_count) +
                   " points in chunks of " + str(info.chunk_size) + " need " + str(needed)};
  } else if (count > point_count) {
    return Error{path + ": " + where + " lists " + str(count) + " chunks for " + str(point_count) + " points"};
  }
  std::vector<LazChunk> chunks(count);
  if (count == 0 && point_count != 0)
    return Error{path + ": " + where + " lists no chunks for " + str(point_count) + " points"};
  if (count == 0) return chunks;

  // The coded entries: at most 7 bytes per value (a class symbol, a corrector symbol and 24 raw
  // bits, each symbol at most ~16 bits with LASzip's count limits) plus the decoder's 4.
  const uint64_t values = info.variableChunks() ? 2 * uint64_t{count} : count;
  const uint64_t coded_at = table + 8;
  std::vector<uint8_t> coded(static_cast<size_t>(std::min<uint64_t>(size - coded_at, 8 * values + 8)));
  if (Status s = readExactly(coded_at, coded.data(), coded.size(), "the chunk table's entries"); !s) return s.error();
  LazDecoder decoder(coded.data(), coded.size());
  LazIntegerDecoder entries(32, 2);
  uint32_t last_points = 0, last_bytes = 0;
  uint64_t offset = chunks_at, points_seen = 0;
  for (uint32_t i = 0; i < count; ++i) {
    LazChunk& c = chunks[i];
    if (info.variableChunks()) {
      last_points = static_cast<uint32_t>(entries.decode(decoder, static_cast<int32_t>(last_points), 0));
      c.points = last_points;
    } else {
      c.points = i + 1 < count ? info.chunk_size : point_count - uint64_t{info.chunk_size} * (count - 1);
    }
    last_bytes = static_cast<uint32_t>(entries.decode(decoder, static_cast<int32_t>(last_bytes), 1));
    c.bytes = last_bytes;
    c.offset = offset;
    if (!decoder.ok())
      return Error{path + ": the chunk table is " + (decoder.invalid() ? "corrupt" : "truncated") + " (at chunk " +
                   str(i) + " of " + str(count) + ")"};
    if (c.points == 0) return Error{path + ": the chunk table gives chunk " + str(i) + " 0 points"};
    if (c.bytes == 0 || c.bytes > table - offset)
      return Error{path + ": the chunk table gives chunk " + str(i) + " " + str(c.bytes) + " bytes from byte " +
                   str(offset) + ", past the chunk table at byte " + str(table)};
    offset += c.bytes;
    points_seen += c.points;
  }
  if (points_seen != point_count)
    return Error{path + ": the chunk table's chunks hold " + str(points_seen) + " points, the header " +
                 str(point_count)};
  return chunks;
}

// --- The file --------------------------------------------------------------------------------------

namespace {

// Public header block: byte offsets of the fields used here (LAS 1.4 R15, table 3; 1.0–1.3 are
// prefixes of it).
constexpr size_t kVersionMajorAt = 24, kVersionMinorAt = 25, kHeaderSizeAt = 94, kPointOffsetAt = 96;
constexpr size_t kVlrCountAt = 100, kFormatAt = 104, kRecordLengthAt = 105, kLegacyCountAt = 107;
constexpr size_t kEvlrStartAt = 235, kEvlrCountAt = 243;  // LAS 1.4
constexpr size_t kCountAt = 247;  // LAS 1.4: the 64-bit count
constexpr uint32_t kHeaderSize12 = 227, kHeaderSize13 = 235, kHeaderSize14 = 375;
constexpr size_t kVlrHeaderBytes = 54;
constexpr uint16_t kLaszipRecordId = 22204;

struct LazHeader {
  int point_format = 0;
  uint32_t record_length = 0;
  uint64_t point_offset = 0;
  uint64_t point_end = 0;  // where the point data ends: the first EVLR or the file's end
  uint64_t point_count = 0;
  LazInfo info;
};

Result<LazHeader> readHeader(const InputFile& file) {
  const std::string& path = file.path();
  char h[kHeaderSize14] = {};
  Result<size_t> got = file.readAt(0, h, sizeof h);
  if (!got) return got.error();
  if (*got < 4 || std::memcmp(h, "LASF", 4) != 0)
    return Error{path + ": not a LAS/LAZ file (it does not start with 'LASF')"};
  const int major = static_cast<uint8_t>(h[kVersionMajorAt]), minor = static_cast<uint8_t>(h[kVersionMinorAt]);
  const std::string version = std::to_string(major) + "." + std::to_string(minor);
  if (major != 1 || minor > 4)
    return Error{path + ": header: version " + version + " is not supported (LAS 1.0 to 1.4)"};
  const uint32_t needed = minor >= 4 ? kHeaderSize14 : minor == 3 ? kHeaderSize13 : kHeaderSize12;
  if (*got < needed)
    return Error{path + ": truncated header: the file has " + str(file.size()) + " bytes, a LAS " + version +
                 " header " + str(needed)};
  const uint16_t header_size = loadUnaligned<uint16_t>(h + kHeaderSizeAt);
  if (header_size < needed)
    return Error{path + ": header: header size " + str(header_size) + " is smaller than LAS " + version + "'s " +
                 str(needed) + " bytes"};
  LazHeader hd;
  const uint8_t raw_format = static_cast<uint8_t>(h[kFormatAt]);
  if ((raw_format & 0xC0) == 0)
    return Error{path + ": not compressed: point data format " + str(raw_format) +
                 " has neither bit 7 nor bit 6 set (read it as LAS)"};
  hd.point_format = raw_format & 0x3F;
  hd.record_length = loadUnaligned<uint16_t>(h + kRecordLengthAt);
  hd.point_offset = loadUnaligned<uint32_t>(h + kPointOffsetAt);
  if (hd.point_offset < header_size)
    return Error{path + ": header: offset to point data " + str(hd.point_offset) + " lies inside the " +
                 str(header_size) + "-byte header"};
  const uint32_t legacy = loadUnaligned<uint32_t>(h + kLegacyCountAt);
  hd.point_count = legacy;
  if (minor >= 4) {
    const uint64_t count = loadUnaligned<uint64_t>(h + kCountAt);
    if (count != 0 && legacy != 0 && count != legacy)
      return Error{path + ": header: legacy point count " + str(legacy) + " disagrees with the 64-bit count " +
                   str(count)};
    if (count != 0) hd.point_count = count;
  }

  // The VLRs lie between the header and the point data; the laszip one is among them.
  const uint32_t vlr_count = loadUnaligned<uint32_t>(h + kVlrCountAt);
  uint64_t at = header_size;
  std::optional<LazInfo> info;
  for (uint32_t i = 0; i < vlr_count && !info; ++i) {
    char v[kVlrHeaderBytes];
    if (at + kVlrHeaderBytes > hd.point_offset)
      return Error{path + ": VLR " + str(i) + " at byte " + str(at) + " runs past the offset to point data " +
                   str(hd.point_offset)};
    Result<size_t> read = file.readAt(at, v, sizeof v);
    if (!read) return read.error();
    if (*read != sizeof v) return Error{path + ": truncated: the file ends in VLR " + str(i)};
    const uint16_t record_id = loadUnaligned<uint16_t>(v + 18), bytes = loadUnaligned<uint16_t>(v + 20);
    const uint64_t data_at = at + kVlrHeaderBytes;
    if (data_at + bytes > hd.point_offset)
      return Error{path + ": VLR " + str(i) + " (" + str(bytes) + " bytes at byte " + str(data_at) +
                   ") runs past the offset to point data " + str(hd.point_offset)};
    // The user ID is 16 bytes, NUL-padded.
    if (record_id == kLaszipRecordId && std::string_view(v + 2, strnlen(v + 2, 16)) == "laszip encoded") {
      std::string data(bytes, '\0');
      Result<size_t> data_read = file.readAt(data_at, data.data(), bytes);
      if (!data_read) return data_read.error();
      if (*data_read != bytes) return Error{path + ": truncated: the file ends in the laszip VLR"};
      Result<LazInfo> parsed = parseLaszipVlr(data);
      if (!parsed) return Error{path + ": " + parsed.error().message};
      info = std::move(*parsed);
    }
    at = data_at + bytes;
  }
  if (!info)
    return Error{path + ": no laszip VLR (user ID 'laszip encoded', record 22204) among its " + str(vlr_count) +
                 " VLRs"};
  hd.info = std::move(*info);
  if (Status s = checkLazItems(hd.info, hd.point_format, hd.record_length); !s)
    return Error{path + ": " + s.error().message};
  // Compressor 1's code has no table to say where it ends: at the EVLRs of LAS 1.4, else the file's end.
  if (hd.info.compressor == kCompressorPointwise) {
    const uint64_t size = file.size();
    if (hd.point_offset > size)
      return Error{path + ": truncated: the point data starts at byte " + str(hd.point_offset) +
                   ", past the end of the " + str(size) + "-byte file"};
    hd.point_end = size;
    if (minor >= 4 && loadUnaligned<uint32_t>(h + kEvlrCountAt) != 0) {
      const uint64_t evlrs = loadUnaligned<uint64_t>(h + kEvlrStartAt);
      if (evlrs < hd.point_offset || evlrs > size)
        return Error{path + ": header: the first EVLR's offset " + str(evlrs) + " is not between the offset to point " +
                     "data " + str(hd.point_offset) + " and the file's end " + str(size)};
      hd.point_end = evlrs;
    }
  }
  return hd;
}

}  // namespace

Result<LazChunks> openLazChunks(const InputFile& file) {
  Result<LazHeader> header = readHeader(file);
  if (!header) return header.error();
  LazChunks out;
  if (header->info.compressor == kCompressorPointwise) {
    // No chunk table: the point data is one code, read as one chunk of every point.
    if (header->point_count != 0)
      out.chunks.push_back({header->point_offset, header->point_end - header->point_offset, header->point_count});
  } else {
    Result<std::vector<LazChunk>> table =
        readLazChunkTable(file, header->point_offset, header->info, header->point_count);
    if (!table) return table.error();
    out.chunks = std::move(*table);
  }
  out.info = std::move(header->info);
  out.record_length = header->record_length;
  out.point_count = header->point_count;
  out.first_point.assign(out.chunks.size(), 0);
  for (size_t i = 1; i < out.chunks.size(); ++i) out.first_point[i] = out.first_point[i - 1] + out.chunks[i - 1].points;
  return out;
}

Status decodeLazChunkList(const InputFile& file, const LazInfo& info, std::span<const LazChunk> chunks,
                          uint32_t record_length, char* records, unsigned threads,
                          const std::function<std::string(size_t)>& where) {
  if (chunks.empty()) return okStatus();
  threads = parallelWorkers(chunks.size(), threads);
  std::vector<uint64_t> at(chunks.size(), 0);  // each chunk's first record in `records`
  for (size_t i = 1; i < chunks.size(); ++i) at[i] = at[i - 1] + chunks[i - 1].points;
  // The error reported is the first failing chunk's: chunks are handed out in order, and once one
  // fails no later one starts, so every earlier one is decoded and its error, if any, wins.
  std::atomic<size_t> failed{chunks.size()};
  std::mutex mutex;
  std::optional<Error> error;
  std::vector<std::vector<char>> buffers(threads);
  parallelFor(chunks.size(), threads, [&](size_t i, unsigned worker) {
    if (i > failed.load()) return;
    const LazChunk& c = chunks[i];
    std::vector<char>& buffer = buffers[worker];
    buffer.resize(static_cast<size_t>(c.bytes));
    std::optional<Error> problem;
    Result<size_t> got = file.readAt(c.offset, buffer.data(), buffer.size());
    if (!got) {
      problem = got.error();
    } else if (*got != buffer.size()) {
      problem = Error{where(i) + "truncated: the file ends inside the chunk"};
    } else if (Status s = decodeLazChunk(info, buffer.data(), buffer.size(), c.points, records + at[i] * record_length);
               !s) {
      problem = Error{where(i) + s.error().message};
    }
    if (!problem) return;
    std::lock_guard<std::mutex> lock(mutex);
    if (i < failed.load()) {
      failed.store(i);
      error = std::move(*problem);
    }
  });
  if (error) return *error;
  return okStatus();
}

Status decodeLazChunks(const InputFile& file, const LazChunks& laz, size_t first, size_t last, char* records,
                       unsigned threads) {
  assert(first <= last && last <= laz.chunks.size());
  const std::span<const LazChunk> chunks(laz.chunks.data() + first, last - first);
  return decodeLazChunkList(file, laz.info, chunks, laz.record_length, records, threads, [&](size_t j) {
    const size_t i = first + j;
    const LazChunk& c = laz.chunks[i];
    const std::string range = "points " + str(laz.first_point[i]) + " to " + str(laz.first_point[i] + c.points - 1);
    if (laz.info.compressor == kCompressorPointwise)
      return file.path() + ": the point data (compressor 1: one code of " + str(c.bytes) + " bytes at byte " +
             str(c.offset) + ", " + range + "): ";
    return file.path() + ": chunk " + str(i) + " of " + str(laz.chunks.size()) + " (" + str(c.bytes) +
           " bytes at byte " + str(c.offset) + ", " + range + "): ";
  });
}

Result<LazRecords> decodeLazRecords(const InputFile& file, unsigned threads, uint64_t max_memory, size_t lead) {
  const std::string& path = file.path();
  Result<LazChunks> opened = openLazChunks(file);
  if (!opened) return opened.error();
  const LazChunks& laz = *opened;
  // The records and one chunk's bytes per thread.
  const uint64_t length = laz.record_length;
  const unsigned workers = parallelWorkers(laz.chunks.size(), threads);
  uint64_t largest = 0;
  for (const LazChunk& c : laz.chunks) largest = std::max(largest, c.bytes);
  if (laz.point_count > (UINT64_MAX - lead - largest * workers) / length)
    return Error{path + ": " + str(laz.point_count) + " points of " + str(length) + " bytes overflow 64 bits",
                 ExitCode::kResourceLimit};
  if (Status s = checkMemory(path + ": decoding " + str(laz.point_count) + " points",
                             lead + laz.point_count * length + largest * workers, max_memory);
      !s)
    return s.error();
  LazRecords out{LargeBuffer(lead + static_cast<size_t>(laz.point_count * length))};
  if (Status s = decodeLazChunks(file, laz, 0, laz.chunks.size(), out.bytes.data() + lead, workers); !s)
    return s.error();
  return out;
}

Result<std::string> decodeLaz(const InputFile& file, unsigned threads, uint64_t max_memory) {
  Result<LazRecords> records = decodeLazRecords(file, threads, max_memory);
  if (!records) return records.error();
  return std::string(records->view());
}

Result<std::string> decodeLazFile(const std::string& path, unsigned threads, uint64_t max_memory) {
  Result<InputFile> file = InputFile::open(path);
  if (!file) return file.error();
  return decodeLaz(*file, threads, max_memory);
}

}  // namespace dpoint
