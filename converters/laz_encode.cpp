// LAZ encoding (converters/laz_encode.h says what and whence): the version-2 item encoders, the
// chunk and its table, the laszip VLR and a whole file. Each encoder mirrors its decoder in
// laz_decode_v2.cpp step for step (the same models, updated in the same order); where LASzip's
// encoder has a choice the decoder cannot see (which of two equal sequences a GPS time joins), the
// choice is LASzip's, so that dpoint's files come out the size LASzip's do.
#include "converters/laz_encode.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <memory>

#include "converters/laz_common.h"
#include "converters/laz_encoder.h"
#include "converters/laz_layered.h"
#include "core/bytes.h"
#include "core/parallel.h"

namespace dpoint {

static_assert(std::endian::native == std::endian::little, "LAZ fields are little-endian, copied as they are");

namespace {

std::string str(uint64_t v) { return std::to_string(v); }

constexpr uint16_t kCompressorChunked = 2, kCompressorLayered = 3;
constexpr uint16_t kItemVersion2 = 2, kItemVersion3 = 3;

// --- Item encoders, version 2 ----------------------------------------------------------------------

class ItemEncoder {
 public:
  virtual ~ItemEncoder() = default;
  virtual void encode(LazEncoder& encoder, const uint8_t* item) = 0;
};

// POINT10 (laz_decode_v2.cpp's Point10Decoder says what each field's coding is).
class Point10Encoder final : public ItemEncoder {
 public:
  explicit Point10Encoder(const uint8_t* first) { std::memcpy(last_, first, sizeof last_); }

  void encode(LazEncoder& e, const uint8_t* item) override {
    const uint8_t returns = item[14];
    const uint32_t r = returns & 7u, n = (returns >> 3) & 7u;
    const uint32_t m = kLazReturnMap[n][r], l = kLazReturnLevel[n][r];
    const uint16_t intensity = loadUnaligned<uint16_t>(item + 12);
    const uint16_t source_id = loadUnaligned<uint16_t>(item + 18), last_source_id = loadUnaligned<uint16_t>(last_ + 18);
    const uint32_t changed = (uint32_t{last_[14] != returns} << 5) | (uint32_t{last_intensity_[m] != intensity} << 4) |
                             (uint32_t{last_[15] != item[15]} << 3) | (uint32_t{last_[16] != item[16]} << 2) |
                             (uint32_t{last_[17] != item[17]} << 1) | uint32_t{last_source_id != source_id};
    e.encodeSymbol(changed_model_, changed);
    if (changed & 32) e.encodeSymbol(returns_models_[last_[14]], returns);
    if (changed & 16) {
      intensity_encoder_.encode(e, last_intensity_[m], intensity, m < 3 ? m : 3);
      last_intensity_[m] = intensity;
    }
    if (changed & 8) e.encodeSymbol(class_models_[last_[15]], item[15]);
    if (changed & 4) e.encodeSymbol(scan_angle_models_[(returns >> 6) & 1u], static_cast<uint8_t>(item[16] - last_[16]));
    if (changed & 2) e.encodeSymbol(user_models_[last_[17]], item[17]);
    if (changed & 1) source_id_encoder_.encode(e, last_source_id, source_id);

    const uint32_t single = n == 1 ? 1 : 0;
    const int32_t dx = difference(item, 0), dy = difference(item, 4);
    dx_encoder_.encode(e, dx_history_[m].get(), dx, single);
    dx_history_[m].add(dx);
    uint32_t k = dx_encoder_.k();
    dy_encoder_.encode(e, dy_history_[m].get(), dy, single + (k < 20 ? k & ~1u : 20));
    dy_history_[m].add(dy);
    k = (dx_encoder_.k() + dy_encoder_.k()) / 2;
    const int32_t z = loadUnaligned<int32_t>(item + 8);
    z_encoder_.encode(e, last_height_[l], z, single + (k < 18 ? k & ~1u : 18));
    last_height_[l] = z;
    std::memcpy(last_, item, sizeof last_);
  }

 private:
  // The coordinate at `at` minus the last one's, wrapping as LASzip's int32 difference does.
  int32_t difference(const uint8_t* item, size_t at) const {
    return static_cast<int32_t>(static_cast<uint32_t>(loadUnaligned<int32_t>(item + at)) -
                                static_cast<uint32_t>(loadUnaligned<int32_t>(last_ + at)));
  }

  uint8_t last_[20];
  std::array<uint16_t, 16> last_intensity_{};  // 0 at a chunk's start, as the decoder's
  std::array<int32_t, 8> last_height_{};
  std::array<LazMedian5, 16> dx_history_, dy_history_;

  LazSymbolModel changed_model_{64};
  // The return byte, classification and user data each have a model per previous value.
  LazKeyedModels<256> returns_models_{256}, class_models_{256}, user_models_{256};
  std::array<LazSymbolModel, 2> scan_angle_models_{LazSymbolModel(256), LazSymbolModel(256)};
  LazIntegerEncoder intensity_encoder_{16, 4};
  LazIntegerEncoder source_id_encoder_{16, 1};
  LazIntegerEncoder dx_encoder_{32, 2};
  LazIntegerEncoder dy_encoder_{32, 22};
  LazIntegerEncoder z_encoder_{32, 20};
};

// GPSTIME11: LASzip's choices, in its order: unchanged, a 32-bit step (as a multiple of the last
// step where one is), another of the four sequences within 32 bits, else a new sequence.
class GpsTimeEncoder final : public ItemEncoder {
 public:
  explicit GpsTimeEncoder(const uint8_t* first) { time_[0] = loadUnaligned<uint64_t>(first); }

  void encode(LazEncoder& e, const uint8_t* item) override {
    const uint64_t t = loadUnaligned<uint64_t>(item);
    for (;;) {  // a switch to another sequence codes the point again in that one (at most once)
      const bool zero = diff_[last_] == 0;
      if (t == time_[last_]) {
        if (zero) e.encodeSymbol(zero_diff_model_, 0);
        else e.encodeSymbol(multi_model_, kLazGpsUnchanged);
        return;
      }
      const int64_t step = static_cast<int64_t>(t - time_[last_]);
      if (fits32(step)) {
        const int32_t d = static_cast<int32_t>(step);
        if (zero) {
          e.encodeSymbol(zero_diff_model_, 1);
          time_encoder_.encode(e, 0, d, 0);
          diff_[last_] = d;
          extreme_[last_] = 0;
        } else {
          encodeMultiple(e, d);
        }
        time_[last_] = t;
        return;
      }
      uint32_t other = 1;
      while (other < 4 && !fits32(static_cast<int64_t>(t - time_[(last_ + other) & 3u]))) ++other;
      if (other < 4) {
        if (zero) e.encodeSymbol(zero_diff_model_, other + 2);
        else e.encodeSymbol(multi_model_, kLazGpsFull + other);
        last_ = (last_ + other) & 3u;
        continue;
      }
      // A new sequence: the high 32 bits predicted by this sequence's, the low 32 raw.
      if (zero) e.encodeSymbol(zero_diff_model_, 2);
      else e.encodeSymbol(multi_model_, kLazGpsFull);
      time_encoder_.encode(e, static_cast<int32_t>(time_[last_] >> 32), static_cast<int32_t>(t >> 32), 8);
      e.writeInt(static_cast<uint32_t>(t));
      next_ = (next_ + 1) & 3u;
      last_ = next_;
      diff_[last_] = 0;
      extreme_[last_] = 0;
      time_[last_] = t;
      return;
    }
  }

 private:
  static bool fits32(int64_t v) { return v == static_cast<int64_t>(static_cast<int32_t>(v)); }
  int32_t times(int32_t multiple) const {
    return static_cast<int32_t>(static_cast<uint32_t>(multiple) * static_cast<uint32_t>(diff_[last_]));
  }
  void countExtreme(int32_t d) {
    if (++extreme_[last_] > 3) {
      diff_[last_] = d;
      extreme_[last_] = 0;
    }
  }

  // A step d as a multiple of the last step: LASzip rounds d / last in float (its I32_QUANTIZE);
  // the quotient is clamped first, where LASzip's cast would overflow (any symbol decodes right).
  void encodeMultiple(LazEncoder& e, int32_t d) {
    const float ratio = static_cast<float>(d) / static_cast<float>(diff_[last_]);
    const float rounded = ratio >= 0 ? ratio + 0.5f : ratio - 0.5f;
    const int32_t multi = static_cast<int32_t>(std::clamp(rounded, -2.0e9f, 2.0e9f));
    if (multi == 1) {
      e.encodeSymbol(multi_model_, 1);
      time_encoder_.encode(e, diff_[last_], d, 1);
      extreme_[last_] = 0;
    } else if (multi > 0) {
      if (multi < static_cast<int32_t>(kLazGpsMulti)) {
        e.encodeSymbol(multi_model_, static_cast<uint32_t>(multi));
        time_encoder_.encode(e, times(multi), d, multi < 10 ? 2 : 3);
      } else {
        e.encodeSymbol(multi_model_, kLazGpsMulti);
        time_encoder_.encode(e, times(static_cast<int32_t>(kLazGpsMulti)), d, 4);
        countExtreme(d);
      }
    } else if (multi < 0) {
      if (multi > kLazGpsMultiMinus) {
        e.encodeSymbol(multi_model_, static_cast<uint32_t>(static_cast<int32_t>(kLazGpsMulti) - multi));
        time_encoder_.encode(e, times(multi), d, 5);
      } else {
        e.encodeSymbol(multi_model_, static_cast<uint32_t>(static_cast<int32_t>(kLazGpsMulti) - kLazGpsMultiMinus));
        time_encoder_.encode(e, times(kLazGpsMultiMinus), d, 6);
        countExtreme(d);
      }
    } else {
      e.encodeSymbol(multi_model_, 0);
      time_encoder_.encode(e, 0, d, 7);
      countExtreme(d);
    }
  }

  std::array<uint64_t, 4> time_{};
  std::array<int32_t, 4> diff_{};
  std::array<int32_t, 4> extreme_{};
  uint32_t last_ = 0, next_ = 0;
  LazSymbolModel multi_model_{kLazGpsMultiSymbols};
  LazSymbolModel zero_diff_model_{6};
  LazIntegerEncoder time_encoder_{32, 9};
};

// RGB12: which bytes changed, then each changed byte against its prediction (laz_decode_v2.cpp's
// RgbDecoder).
class RgbEncoder final : public ItemEncoder {
 public:
  explicit RgbEncoder(const uint8_t* first) {
    for (size_t c = 0; c < 3; ++c) last_[c] = loadUnaligned<uint16_t>(first + 2 * c);
  }

  void encode(LazEncoder& e, const uint8_t* item) override {
    std::array<uint16_t, 3> v;
    for (size_t c = 0; c < 3; ++c) v[c] = loadUnaligned<uint16_t>(item + 2 * c);
    uint32_t used = 0;
    for (size_t c = 0; c < 3; ++c) {
      used |= uint32_t{lo(last_[c]) != lo(v[c])} << (2 * c);
      used |= uint32_t{hi(last_[c]) != hi(v[c])} << (2 * c + 1);
    }
    const bool grey = lo(v[0]) == lo(v[1]) && lo(v[0]) == lo(v[2]) && hi(v[0]) == hi(v[1]) && hi(v[0]) == hi(v[2]);
    used |= uint32_t{!grey} << 6;
    e.encodeSymbol(used_model_, used);
    if (used & 1) e.encodeSymbol(byte_models_[0], byteDiff(lo(v[0]), lo(last_[0])));
    if (used & 2) e.encodeSymbol(byte_models_[1], byteDiff(hi(v[0]), hi(last_[0])));
    if (used & 64) {
      int change = lo(v[0]) - lo(last_[0]);
      if (used & 4) e.encodeSymbol(byte_models_[2], byteDiff(lo(v[1]), clampByte(change + lo(last_[1]))));
      if (used & 16) {
        change = (change + lo(v[1]) - lo(last_[1])) / 2;
        e.encodeSymbol(byte_models_[4], byteDiff(lo(v[2]), clampByte(change + lo(last_[2]))));
      }
      change = hi(v[0]) - hi(last_[0]);
      if (used & 8) e.encodeSymbol(byte_models_[3], byteDiff(hi(v[1]), clampByte(change + hi(last_[1]))));
      if (used & 32) {
        change = (change + hi(v[1]) - hi(last_[1])) / 2;
        e.encodeSymbol(byte_models_[5], byteDiff(hi(v[2]), clampByte(change + hi(last_[2]))));
      }
    }
    last_ = v;
  }

 private:
  static int lo(uint16_t v) { return v & 0xFF; }
  static int hi(uint16_t v) { return v >> 8; }
  static int clampByte(int v) { return std::clamp(v, 0, 255); }
  static uint32_t byteDiff(int value, int base) { return static_cast<uint32_t>(value - base) & 0xFFu; }

  std::array<uint16_t, 3> last_{};
  LazSymbolModel used_model_{128};
  std::array<LazSymbolModel, 6> byte_models_{LazSymbolModel(256), LazSymbolModel(256), LazSymbolModel(256),
                                             LazSymbolModel(256), LazSymbolModel(256), LazSymbolModel(256)};
};

// BYTE: each byte's difference from the last, mod 256, in its own model.
class ByteEncoder final : public ItemEncoder {
 public:
  ByteEncoder(const uint8_t* first, size_t size) : last_(first, first + size) {
    models_.reserve(size);
    for (size_t i = 0; i < size; ++i) models_.emplace_back(256);
  }

  void encode(LazEncoder& e, const uint8_t* item) override {
    for (size_t i = 0; i < last_.size(); ++i) {
      e.encodeSymbol(models_[i], static_cast<uint8_t>(item[i] - last_[i]));
      last_[i] = item[i];
    }
  }

 private:
  std::vector<uint8_t> last_;
  std::vector<LazSymbolModel> models_;
};

std::unique_ptr<ItemEncoder> makeItemEncoder(const LazItem& item, const uint8_t* first) {
  switch (item.type) {
    case kLazPoint10: return std::make_unique<Point10Encoder>(first);
    case kLazGpsTime11: return std::make_unique<GpsTimeEncoder>(first);
    case kLazRgb12: return std::make_unique<RgbEncoder>(first);
    case kLazByte: return std::make_unique<ByteEncoder>(first, item.size);
    default: break;
  }
  assert(false && "lazInfoForFormat gives version-2 items only these types");
  return nullptr;
}

}  // namespace

// --- The items and the VLR -------------------------------------------------------------------------

Result<LazInfo> lazInfoForFormat(int point_format, uint32_t record_length, uint32_t chunk_size) {
  static constexpr uint32_t kBase[9] = {20, 28, 26, 34, 0, 0, 30, 36, 38};
  const bool pointwise = point_format >= 0 && point_format <= 3;
  const bool layered = point_format >= 6 && point_format <= 8;
  if (!pointwise && !layered)
    return Error{"point format " + std::to_string(point_format) +
                 " cannot be written as LAZ (formats 0 to 3 and 6 to 8; 4, 5, 9 and 10 carry waveforms)"};
  const uint32_t base = kBase[point_format];
  if (record_length < base || record_length - base > 0xFFFF)
    return Error{"point record length " + str(record_length) + " does not fit point format " +
                 std::to_string(point_format) + "'s " + str(base) + " bytes"};
  LazInfo info;
  info.compressor = pointwise ? kCompressorChunked : kCompressorLayered;
  info.coder = 0;
  info.major = 3;
  info.minor = 4;
  info.revision = 3;
  info.options = 0;
  info.chunk_size = chunk_size;
  const auto extra = static_cast<uint16_t>(record_length - base);
  if (pointwise) {
    info.items.push_back({kLazPoint10, 20, kItemVersion2});
    if (point_format == 1 || point_format == 3) info.items.push_back({kLazGpsTime11, 8, kItemVersion2});
    if (point_format >= 2) info.items.push_back({kLazRgb12, 6, kItemVersion2});
    if (extra != 0) info.items.push_back({kLazByte, extra, kItemVersion2});
  } else {
    info.items.push_back({kLazPoint14, 30, kItemVersion3});
    if (point_format == 7) info.items.push_back({kLazRgb14, 6, kItemVersion3});
    if (point_format == 8) info.items.push_back({kLazRgbNir14, 8, kItemVersion3});
    if (extra != 0) info.items.push_back({kLazByte14, extra, kItemVersion3});
  }
  return info;
}

std::string laszipVlrData(const LazInfo& info) {
  std::string out(34 + 6 * info.items.size(), '\0');
  char* p = out.data();
  storeUnaligned<uint16_t>(p, info.compressor);
  storeUnaligned<uint16_t>(p + 2, info.coder);
  p[4] = static_cast<char>(info.major);
  p[5] = static_cast<char>(info.minor);
  storeUnaligned<uint16_t>(p + 6, info.revision);
  storeUnaligned<uint32_t>(p + 8, info.options);
  storeUnaligned<uint32_t>(p + 12, info.chunk_size);
  storeUnaligned<int64_t>(p + 16, -1);  // no special EVLRs
  storeUnaligned<int64_t>(p + 24, -1);
  storeUnaligned<uint16_t>(p + 32, static_cast<uint16_t>(info.items.size()));
  for (size_t i = 0; i < info.items.size(); ++i) {
    char* q = p + 34 + 6 * i;
    storeUnaligned<uint16_t>(q, info.items[i].type);
    storeUnaligned<uint16_t>(q + 2, info.items[i].size);
    storeUnaligned<uint16_t>(q + 4, info.items[i].version);
  }
  return out;
}

// --- A chunk and the table -------------------------------------------------------------------------

std::vector<uint8_t> encodeLazChunk(const LazInfo& info, const char* records, uint64_t points) {
  assert(points >= 1);
  if (info.compressor == kCompressorLayered) return encodeLayeredChunk(info, records, points);
  const size_t length = info.recordLength();
  const auto* first = reinterpret_cast<const uint8_t*>(records);
  std::vector<std::unique_ptr<ItemEncoder>> encoders;
  std::vector<size_t> offsets;
  size_t offset = 0;
  for (const LazItem& item : info.items) {
    encoders.push_back(makeItemEncoder(item, first + offset));
    offsets.push_back(offset);
    offset += item.size;
  }
  LazEncoder encoder;
  for (uint64_t p = 1; p < points; ++p) {
    const uint8_t* record = first + p * length;
    for (size_t i = 0; i < encoders.size(); ++i) encoders[i]->encode(encoder, record + offsets[i]);
  }
  encoder.done();
  // The first record raw, then the code.
  std::vector<uint8_t>& code = encoder.bytes();
  code.insert(code.begin(), first, first + length);
  return std::move(code);
}

std::string encodeLazChunkTable(const LazInfo& info, const std::vector<LazChunk>& chunks) {
  std::string out(8, '\0');
  storeUnaligned<uint32_t>(out.data(), 0);  // version
  storeUnaligned<uint32_t>(out.data() + 4, static_cast<uint32_t>(chunks.size()));
  if (chunks.empty()) return out;
  LazEncoder encoder;
  LazIntegerEncoder entries(32, 2);
  uint32_t last_points = 0, last_bytes = 0;
  for (const LazChunk& c : chunks) {
    if (info.variableChunks()) {
      entries.encode(encoder, static_cast<int32_t>(last_points), static_cast<int32_t>(c.points), 0);
      last_points = static_cast<uint32_t>(c.points);
    }
    entries.encode(encoder, static_cast<int32_t>(last_bytes), static_cast<int32_t>(c.bytes), 1);
    last_bytes = static_cast<uint32_t>(c.bytes);
  }
  encoder.done();
  out.append(reinterpret_cast<const char*>(encoder.bytes().data()), encoder.bytes().size());
  return out;
}

// --- A whole file ----------------------------------------------------------------------------------

namespace {

// LAS 1.4 R15 header offsets (1.0–1.3 are prefixes).
constexpr size_t kVersionMinorAt = 25, kHeaderSizeAt = 94, kPointOffsetAt = 96, kVlrCountAt = 100;
constexpr size_t kFormatAt = 104, kRecordLengthAt = 105, kLegacyCountAt = 107;
constexpr size_t kEvlrStartAt = 235, kEvlrCountAt = 243, kCountAt = 247;
constexpr size_t kVlrHeaderBytes = 54, kHeader14 = 375;

}  // namespace

Result<std::string> compressLasBytes(std::string_view las, unsigned threads, uint32_t chunk_size) {
  if (las.size() < 227 || las.substr(0, 4) != "LASF") return Error{"not a LAS file (no 'LASF' header)"};
  const char* h = las.data();
  const int minor = static_cast<uint8_t>(h[kVersionMinorAt]);
  const uint16_t header_size = loadUnaligned<uint16_t>(h + kHeaderSizeAt);
  const uint32_t point_offset = loadUnaligned<uint32_t>(h + kPointOffsetAt);
  const uint32_t vlr_count = loadUnaligned<uint32_t>(h + kVlrCountAt);
  const uint8_t raw_format = static_cast<uint8_t>(h[kFormatAt]);
  const uint16_t record_length = loadUnaligned<uint16_t>(h + kRecordLengthAt);
  if (raw_format & 0xC0) return Error{"the records are compressed already (point format byte " + str(raw_format) + ")"};
  const bool v14 = minor >= 4 && header_size >= kHeader14;
  uint64_t count = loadUnaligned<uint32_t>(h + kLegacyCountAt);
  if (v14 && loadUnaligned<uint64_t>(h + kCountAt) != 0) count = loadUnaligned<uint64_t>(h + kCountAt);
  if (header_size > las.size() || point_offset < header_size || point_offset > las.size())
    return Error{"header: the offset to point data " + str(point_offset) + " is outside the " + str(las.size()) +
                 "-byte file"};
  if (record_length == 0 || count > (las.size() - point_offset) / record_length)
    return Error{str(count) + " records of " + str(record_length) + " bytes run past the file's end"};
  Result<LazInfo> info = lazInfoForFormat(raw_format, record_length, chunk_size);
  if (!info) return info.error();

  // The VLRs as they are, then the laszip VLR; bytes after the last VLR (before the points) stay.
  size_t at = header_size;
  for (uint32_t i = 0; i < vlr_count; ++i) {
    if (at + kVlrHeaderBytes > point_offset) return Error{"VLR " + str(i) + " runs past the offset to point data"};
    at += kVlrHeaderBytes + loadUnaligned<uint16_t>(h + at + 20);
    if (at > point_offset) return Error{"VLR " + str(i) + " runs past the offset to point data"};
  }
  const std::string vlr_data = laszipVlrData(*info);
  std::string laszip_vlr(kVlrHeaderBytes, '\0');
  std::memcpy(laszip_vlr.data() + 2, "laszip encoded", 14);
  storeUnaligned<uint16_t>(laszip_vlr.data() + 18, 22204);
  storeUnaligned<uint16_t>(laszip_vlr.data() + 20, static_cast<uint16_t>(vlr_data.size()));
  std::memcpy(laszip_vlr.data() + 22, "dpoint LAZ (LASzip 3.4 format)", 30);
  laszip_vlr += vlr_data;

  // The chunks, compressed in parallel.
  const uint64_t chunk_count = (count + chunk_size - 1) / chunk_size;
  std::vector<std::vector<uint8_t>> coded(static_cast<size_t>(chunk_count));
  const char* records = h + point_offset;
  parallelFor(coded.size(), resolveThreads(threads), [&](size_t c, unsigned) {
    const uint64_t first = uint64_t{c} * chunk_size, points = std::min<uint64_t>(chunk_size, count - first);
    coded[c] = encodeLazChunk(*info, records + first * record_length, points);
  });
  std::vector<LazChunk> chunks(coded.size());
  const uint64_t new_point_offset = point_offset + laszip_vlr.size();
  uint64_t offset = new_point_offset + 8;
  for (size_t c = 0; c < coded.size(); ++c) {
    if (coded[c].empty()) return Error{"the chunk encoder for point format " + str(raw_format) + " is missing"};
    chunks[c] = {offset, coded[c].size(), std::min<uint64_t>(chunk_size, count - uint64_t{c} * chunk_size)};
    offset += coded[c].size();
  }
  const uint64_t table_at = offset;
  const std::string table = encodeLazChunkTable(*info, chunks);
  if (new_point_offset > UINT32_MAX) return Error{"the VLRs outgrow the 32-bit offset to point data"};

  // EVLRs (LAS 1.4) follow the chunk table.
  std::string_view evlrs;
  std::string out(h, header_size);
  if (v14) {
    const uint64_t evlr_start = loadUnaligned<uint64_t>(h + kEvlrStartAt);
    const uint32_t evlr_count = loadUnaligned<uint32_t>(h + kEvlrCountAt);
    if (evlr_count != 0) {
      if (evlr_start < point_offset + count * record_length || evlr_start > las.size())
        return Error{"header: the EVLRs' start " + str(evlr_start) + " is outside the file"};
      evlrs = las.substr(static_cast<size_t>(evlr_start));
      storeUnaligned<uint64_t>(out.data() + kEvlrStartAt, table_at + table.size());
    }
  }
  out[kFormatAt] = static_cast<char>(raw_format | 0x80);
  storeUnaligned<uint32_t>(out.data() + kPointOffsetAt, static_cast<uint32_t>(new_point_offset));
  storeUnaligned<uint32_t>(out.data() + kVlrCountAt, vlr_count + 1);
  out.reserve(static_cast<size_t>(table_at + table.size() + evlrs.size()));
  out.append(h + header_size, at - header_size);  // the VLRs
  out += laszip_vlr;
  out.append(h + at, point_offset - at);          // whatever lay between the VLRs and the points
  char table_offset[8];
  storeUnaligned<int64_t>(table_offset, static_cast<int64_t>(table_at));
  out.append(table_offset, 8);
  for (const std::vector<uint8_t>& c : coded) out.append(reinterpret_cast<const char*>(c.data()), c.size());
  out += table;
  out += evlrs;
  return out;
}

}  // namespace dpoint
