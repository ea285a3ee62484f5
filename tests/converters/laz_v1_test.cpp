// LAZ item version 1 and compressor 1: the files LASzip 1.x wrote (converters/laz_decode.h,
// laz_decode_v1.cpp). A real one: libLAS's 1.2-with-color.laz as LASzip 1.0 wrote it in 2011
// (tests/data/laz/README.md), which decodes to libLAS's uncompressed 1.2-with-color.las byte for
// byte (laz-perf cannot judge: it reads neither item version 1 nor compressor 1). Then round trips
// through a version-1 encoder written here from LASzip's laswriteitemcompressed_v1 (dpoint writes
// version 2 only), which re-encodes that file's records to LASzip 1.0's very bytes: every path of
// the four items, compressor 1 and chunked files of version-1 items;
// and hostile input: LASzip's own broken files, cuts and corruptions of the real file, each an error
// that says why, never a crash or a long loop.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "converters/las.h"
#include "converters/laz_codec.h"
#include "converters/laz_decode.h"
#include "converters/laz_encode.h"
#include "converters/laz_encoder.h"
#include "converters/point_io.h"
#include "las_bytes.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::at;
using test::contains;
using test::lasRecords;
using test::laszipVlrAt;
using test::put;
using test::readFile;

const std::string kData = std::string(DPOINT_TESTS_DIR) + "/data/laz/";
const std::string kLaszip1 = kData + "1.2-with-color.laz";  // LASzip 1.0: compressor 1, items version 1
const std::string kTwin = kData + "1.2-with-color.las";

Result<std::string> decodeBytes(const std::string& bytes, unsigned threads = 1) {
  return decodeLaz(InputFile::fromMemory("v1.laz", bytes), threads);
}

// --- A version-1 encoder, for these tests only -------------------------------------------------------
//
// Written from LASzip's laswriteitemcompressed_v1.cpp, as the decoder was from its reader: where
// the encoder has a choice (the GPS time multiplier), the choice is LASzip's.

int32_t median3(const std::array<int32_t, 3>& v) {
  return std::max(std::min(v[0], v[1]), std::min(std::max(v[0], v[1]), v[2]));
}
int32_t wrapMinus(int32_t a, int32_t b) {
  return static_cast<int32_t>(static_cast<uint32_t>(a) - static_cast<uint32_t>(b));
}

class ItemEncoderV1 {
 public:
  virtual ~ItemEncoderV1() = default;
  virtual void encode(LazEncoder& e, const uint8_t* item) = 0;
};

class Point10EncoderV1 final : public ItemEncoderV1 {
 public:
  explicit Point10EncoderV1(const uint8_t* first) { std::memcpy(last_, first, 20); }
  void encode(LazEncoder& e, const uint8_t* item) override {
    const int32_t dx = wrapMinus(at32(item, 0), at32(last_, 0)), dy = wrapMinus(at32(item, 4), at32(last_, 4));
    dx_.encode(e, median3(dx_history_), dx);
    uint32_t k = dx_.k();
    dy_.encode(e, median3(dy_history_), dy, std::min(k, 19u));
    k = (k + dy_.k()) / 2;
    z_.encode(e, at32(last_, 8), at32(item, 8), std::min(k, 19u));
    const uint16_t intensity = at16(item, 12), last_intensity = at16(last_, 12);
    const uint16_t source = at16(item, 18), last_source = at16(last_, 18);
    const uint32_t changed = (uint32_t{intensity != last_intensity} << 5) | (uint32_t{item[14] != last_[14]} << 4) |
                             (uint32_t{item[15] != last_[15]} << 3) | (uint32_t{item[16] != last_[16]} << 2) |
                             (uint32_t{item[17] != last_[17]} << 1) | uint32_t{source != last_source};
    e.encodeSymbol(changed_, changed);
    if (changed & 32) intensity_.encode(e, last_intensity, intensity);
    if (changed & 16) e.encodeSymbol(model(returns_[last_[14]]), item[14]);
    if (changed & 8) e.encodeSymbol(model(classes_[last_[15]]), item[15]);
    if (changed & 4) scan_angle_.encode(e, last_[16], item[16], k < 3 ? 1u : 0u);
    if (changed & 2) e.encodeSymbol(model(user_[last_[17]]), item[17]);
    if (changed & 1) source_.encode(e, last_source, source);
    dx_history_[next_] = dx;
    dy_history_[next_] = dy;
    next_ = (next_ + 1) % 3;
    std::memcpy(last_, item, 20);
  }

 private:
  static int32_t at32(const uint8_t* p, size_t o) {
    int32_t v;
    std::memcpy(&v, p + o, 4);
    return v;
  }
  static uint16_t at16(const uint8_t* p, size_t o) {
    uint16_t v;
    std::memcpy(&v, p + o, 2);
    return v;
  }
  static LazSymbolModel& model(std::unique_ptr<LazSymbolModel>& slot) {
    if (!slot) slot = std::make_unique<LazSymbolModel>(256);
    return *slot;
  }
  uint8_t last_[20];
  std::array<int32_t, 3> dx_history_{}, dy_history_{};
  uint32_t next_ = 0;
  LazSymbolModel changed_{64};
  std::array<std::unique_ptr<LazSymbolModel>, 256> returns_, classes_, user_;
  LazIntegerEncoder dx_{32, 1}, dy_{32, 20}, z_{32, 20}, intensity_{16, 1}, scan_angle_{8, 2}, source_{16, 1};
};

class GpsTimeEncoderV1 final : public ItemEncoderV1 {
 public:
  explicit GpsTimeEncoderV1(const uint8_t* first) { std::memcpy(&last_, first, 8); }
  void encode(LazEncoder& e, const uint8_t* item) override {
    int64_t time;
    std::memcpy(&time, item, 8);
    const int64_t d64 = static_cast<int64_t>(static_cast<uint64_t>(time) - static_cast<uint64_t>(last_));
    const int32_t d = static_cast<int32_t>(d64);
    const bool fits = d64 == d;
    if (diff_ == 0) {
      if (time == last_) {
        e.encodeSymbol(zero_diff_, 0);
        return;
      }
      if (fits) {
        e.encodeSymbol(zero_diff_, 1);
        ic_.encode(e, 0, d, 0);
        diff_ = d;
      } else {
        e.encodeSymbol(zero_diff_, 2);
        writeTime(e, time);
      }
      last_ = time;
      return;
    }
    if (time == last_) {
      e.encodeSymbol(multi_, 511);
      return;
    }
    if (!fits) {
      e.encodeSymbol(multi_, 510);
      writeTime(e, time);
      last_ = time;
      return;
    }
    // LASzip's (I32)(float quotient + 0.5f), clamped to 0..509; the float clamped first so that
    // its conversion stays defined (the clamp to 509 and 0 follows anyway).
    const float quotient = std::clamp(static_cast<float>(d) / static_cast<float>(diff_), -1e6f, 1e6f);
    const int32_t multi = std::clamp(static_cast<int32_t>(quotient + 0.5f), 0, 509);
    e.encodeSymbol(multi_, static_cast<uint32_t>(multi));
    if (multi == 1) {
      ic_.encode(e, diff_, d, 1);
      diff_ = d;
      extreme_ = 0;
    } else if (multi == 0) {
      ic_.encode(e, diff_ / 4, d, 2);
      countExtreme(d);
    } else {
      const int32_t predicted = static_cast<int32_t>(static_cast<uint32_t>(multi) * static_cast<uint32_t>(diff_));
      ic_.encode(e, predicted, d, multi < 10 ? 3 : multi < 50 ? 4 : 5);
      if (multi == 509) countExtreme(d);
    }
    last_ = time;
  }

 private:
  static void writeTime(LazEncoder& e, int64_t time) {
    e.writeInt(static_cast<uint32_t>(static_cast<uint64_t>(time)));
    e.writeInt(static_cast<uint32_t>(static_cast<uint64_t>(time) >> 32));
  }
  void countExtreme(int32_t d) {
    if (++extreme_ > 3) {
      diff_ = d;
      extreme_ = 0;
    }
  }
  int64_t last_ = 0;
  int32_t diff_ = 0, extreme_ = 0;
  LazSymbolModel multi_{512}, zero_diff_{3};
  LazIntegerEncoder ic_{32, 6};
};

class RgbEncoderV1 final : public ItemEncoderV1 {
 public:
  explicit RgbEncoderV1(const uint8_t* first) { std::memcpy(last_, first, 6); }
  void encode(LazEncoder& e, const uint8_t* item) override {
    uint32_t used = 0;
    for (uint32_t b = 0; b < 6; ++b) used |= uint32_t{item[b] != last_[b]} << b;
    e.encodeSymbol(used_, used);
    for (uint32_t b = 0; b < 6; ++b)
      if (used & (1u << b)) ic_.encode(e, last_[b], item[b], b);
    std::memcpy(last_, item, 6);
  }

 private:
  uint8_t last_[6];
  LazSymbolModel used_{64};
  LazIntegerEncoder ic_{8, 6};
};

class ByteEncoderV1 final : public ItemEncoderV1 {
 public:
  ByteEncoderV1(const uint8_t* first, size_t n) : last_(first, first + n), ic_(8, static_cast<uint32_t>(n)) {}
  void encode(LazEncoder& e, const uint8_t* item) override {
    for (uint32_t i = 0; i < last_.size(); ++i) ic_.encode(e, last_[i], item[i], i);
    std::memcpy(last_.data(), item, last_.size());
  }

 private:
  std::vector<uint8_t> last_;
  LazIntegerEncoder ic_;
};

// One pointwise code of `points` records with version-1 items: the first record raw, then the code.
std::string encodeV1(const LazInfo& info, const char* records, uint64_t points) {
  const size_t length = info.recordLength();
  const uint8_t* in = reinterpret_cast<const uint8_t*>(records);
  std::vector<std::unique_ptr<ItemEncoderV1>> items;
  std::vector<size_t> offsets;
  size_t offset = 0;
  for (const LazItem& item : info.items) {
    EXPECT_EQ(item.version, 1);
    if (item.type == kLazPoint10) items.push_back(std::make_unique<Point10EncoderV1>(in + offset));
    else if (item.type == kLazGpsTime11) items.push_back(std::make_unique<GpsTimeEncoderV1>(in + offset));
    else if (item.type == kLazRgb12) items.push_back(std::make_unique<RgbEncoderV1>(in + offset));
    else items.push_back(std::make_unique<ByteEncoderV1>(in + offset, item.size));
    offsets.push_back(offset);
    offset += item.size;
  }
  LazEncoder e;
  for (uint64_t p = 1; p < points; ++p)
    for (size_t i = 0; i < items.size(); ++i) items[i]->encode(e, in + p * length + offsets[i]);
  e.done();
  std::string out(records, length);
  out.append(reinterpret_cast<const char*>(e.bytes().data()), e.bytes().size());
  return out;
}

// The laszip VLR of LASzip 1.x for point format 0–3 records of `length` bytes: items version 1.
LazInfo infoV1(int format, uint32_t length, uint16_t compressor, uint32_t chunk_size = 0) {
  LazInfo info;
  info.compressor = compressor;
  info.major = 1;
  info.minor = 2;
  info.chunk_size = chunk_size;
  static constexpr uint32_t kBase[4] = {20, 28, 26, 34};
  info.items.push_back({kLazPoint10, 20, 1});
  if (format == 1 || format == 3) info.items.push_back({kLazGpsTime11, 8, 1});
  if (format >= 2) info.items.push_back({kLazRgb12, 6, 1});
  if (length > kBase[format]) info.items.push_back({kLazByte, static_cast<uint16_t>(length - kBase[format]), 1});
  return info;
}

// A LAZ file of an uncompressed LAS file's records: its header and VLRs, the laszip VLR of `info`
// and either one code of all points (compressor 1) or chunks of info.chunk_size points and their
// table (compressor 2), each code from `encode`.
template <class Encode>
std::string lazFileOf(const std::string& las, const LazInfo& info, Encode encode) {
  const uint16_t header_size = at<uint16_t>(las, 94);
  size_t vlr_end = header_size;
  for (uint32_t i = 0; i < at<uint32_t>(las, 100); ++i) vlr_end += 54 + at<uint16_t>(las, vlr_end + 20);
  std::string out = las.substr(0, vlr_end);
  const std::string data = laszipVlrData(info);
  std::string vlr(54, '\0');
  std::memcpy(vlr.data() + 2, "laszip encoded", 14);
  put<uint16_t>(vlr, 18, 22204);
  put<uint16_t>(vlr, 20, static_cast<uint16_t>(data.size()));
  out += vlr + data;
  put<uint32_t>(out, 100, at<uint32_t>(las, 100) + 1);
  out[104] = static_cast<char>(out[104] | 0x80);
  put<uint32_t>(out, 96, static_cast<uint32_t>(out.size()));
  const std::string records = lasRecords(las);
  const size_t length = info.recordLength();
  const uint64_t points = records.size() / length;
  if (info.compressor == 1) {
    if (points > 0) out += encode(info, records.data(), points);
    return out;
  }
  const size_t table_at = out.size();
  out.append(8, '\0');
  std::vector<LazChunk> chunks;
  for (uint64_t first = 0; first < points; first += info.chunk_size) {
    const uint64_t n = std::min<uint64_t>(info.chunk_size, points - first);
    const std::string chunk = encode(info, records.data() + first * length, n);
    chunks.push_back({out.size(), chunk.size(), n});
    out += chunk;
  }
  put<int64_t>(out, table_at, static_cast<int64_t>(out.size()));
  return out + encodeLazChunkTable(info, chunks);
}

// --- The real file -----------------------------------------------------------------------------------

TEST(LazV1, laszip1FileDecodesToItsUncompressedTwinByteForByte) {
  const std::string laz = readFile(kLaszip1);
  Result<LazInfo> info = parseLaszipVlr(std::string_view(laz).substr(laszipVlrAt(laz), 34 + 3 * 6));
  ASSERT_TRUE(info.ok()) << info.error().message;
  EXPECT_EQ(info->compressor, 1);
  EXPECT_EQ(info->major, 1);
  EXPECT_EQ(info->minor, 0);
  ASSERT_EQ(info->items.size(), 3u);
  for (const LazItem& item : info->items) EXPECT_EQ(item.version, 1);
  Result<std::string> records = decodeLazFile(kLaszip1);
  ASSERT_TRUE(records.ok()) << records.error().message;
  const std::string expected = lasRecords(readFile(kTwin));
  ASSERT_EQ(records->size(), 1065u * 34);
  EXPECT_TRUE(*records == expected) << "records differ";
  // The tests' version-1 encoder writes LASzip 1.0's bytes for them: the round trips below are
  // through LASzip's own coding (the extra bytes' item aside, which no real file here holds).
  EXPECT_TRUE(encodeV1(*info, expected.data(), 1065) == laz.substr(at<uint32_t>(laz, 96))) << "re-encoded code differs";
}

TEST(LazV1, laszip12HeaderOfTheSameCodeDecodesTheSame) {
  // LASzip's own copy of this file (its pnacl example, 2014) differs only in its VLR: version 1.2
  // and chunk size 0, which compressor 1 does not use.
  std::string laz = readFile(kLaszip1);
  const size_t vlr = laszipVlrAt(laz);
  laz[vlr + 5] = 2;
  put<uint32_t>(laz, vlr + 12, 0);
  Result<std::string> records = decodeBytes(laz);
  ASSERT_TRUE(records.ok()) << records.error().message;
  EXPECT_TRUE(*records == lasRecords(readFile(kTwin)));
}

TEST(LazV1, laszip1FileReadsAsItsTwinWholeAndStreamed) {
  Result<PointSet> laz = readPoints(kLaszip1), las = readPoints(kTwin);
  ASSERT_TRUE(laz.ok()) << laz.error().message;
  ASSERT_TRUE(las.ok()) << las.error().message;
  EXPECT_EQ(laz->positions, las->positions);
  EXPECT_EQ(laz->colors, las->colors);
  // Streamed: the one code is decoded for the first block and kept for the rest.
  Result<std::unique_ptr<LasPointStream>> stream = LasPointStream::open(kLaszip1, 2);
  ASSERT_TRUE(stream.ok()) << stream.error().message;
  ASSERT_EQ((*stream)->count(), 1065u);
  for (uint64_t first = 0; first < 1065; first += 400) {
    PointSet block;
    const uint64_t n = std::min<uint64_t>(400, 1065 - first);
    ASSERT_TRUE((*stream)->read(first, n, block).ok());
    ASSERT_EQ(block.positions.size(), n);
    for (uint64_t i = 0; i < n; ++i) EXPECT_EQ(block.positions[i], las->positions[first + i]) << first + i;
  }
}

// --- Round trips through the version-1 encoder ---------------------------------------------------------

// Records of point format 0–3 with `extra` extra bytes that take every path of the version-1
// items: coordinates that wrap int32, every field changing alone and together, GPS times
// repeating, stepping by 1, 2–9, 10–49, 50–508 and ≥ 509 times the last difference, by a zero or
// negative multiple, and jumping past 32 bits; colours and extra bytes steady, stepping and random.
std::string syntheticRecords(int format, uint32_t extra, uint64_t points, uint32_t seed) {
  static constexpr uint32_t kBase[4] = {20, 28, 26, 34};
  const size_t length = kBase[format] + extra;
  std::string out(points * length, '\0');
  std::mt19937 rng(seed);
  const auto chance = [&](double p) { return std::uniform_real_distribution<double>(0, 1)(rng) < p; };
  const auto uniform = [&](int64_t lo, int64_t hi) { return std::uniform_int_distribution<int64_t>(lo, hi)(rng); };
  int32_t x = 1000, y = -2000, z = 50;
  uint16_t intensity = 100, source = 7;
  uint8_t returns = 9, cls = 2, angle = 0, user = 0;
  int64_t time = 0x41D2345678000000;  // a double's pattern; stepped as an integer
  int64_t step = 1000;
  std::array<uint16_t, 3> rgb = {100, 200, 300};
  std::vector<uint8_t> bytes(extra, 5);
  for (uint64_t i = 0; i < points; ++i) {
    char* p = out.data() + i * length;
    if (chance(0.01)) x = static_cast<int32_t>(uniform(INT32_MIN, INT32_MAX));
    else x += static_cast<int32_t>(uniform(-300, 300));
    y += static_cast<int32_t>(chance(0.01) ? uniform(-2000000000, 2000000000) : uniform(-300, 300));
    z = chance(0.01) ? static_cast<int32_t>(uniform(INT32_MIN, INT32_MAX)) : z + static_cast<int32_t>(uniform(-50, 50));
    if (chance(0.3)) intensity = static_cast<uint16_t>(uniform(0, 65535));
    if (chance(0.1)) returns = static_cast<uint8_t>(uniform(0, 255));
    if (chance(0.05)) cls = static_cast<uint8_t>(uniform(0, 255));
    if (chance(0.1)) angle = static_cast<uint8_t>(uniform(0, 255));  // wraps as a byte
    if (chance(0.02)) user = static_cast<uint8_t>(uniform(0, 255));
    if (chance(0.01)) source = static_cast<uint16_t>(uniform(0, 65535));
    std::memcpy(p, &x, 4);
    std::memcpy(p + 4, &y, 4);
    std::memcpy(p + 8, &z, 4);
    std::memcpy(p + 12, &intensity, 2);
    p[14] = static_cast<char>(returns);
    p[15] = static_cast<char>(cls);
    p[16] = static_cast<char>(angle);
    p[17] = static_cast<char>(user);
    std::memcpy(p + 18, &source, 2);
    size_t at_byte = 20;
    if (format == 1 || format == 3) {
      const double roll = std::uniform_real_distribution<double>(0, 1)(rng);
      if (roll < 0.50) time += step;                                // the same step
      else if (roll < 0.60) {}                                      // unchanged
      else if (roll < 0.70) time += step * uniform(2, 9);
      else if (roll < 0.75) time += step * uniform(10, 49);
      else if (roll < 0.80) time += step * uniform(50, 800);        // 509 and beyond
      else if (roll < 0.85) time -= step * uniform(1, 5);           // a negative multiple: 0
      else if (roll < 0.88) time += uniform(1, step / 8);           // a small one: 0
      else if (roll < 0.92) step = uniform(1, 100000), time += step;  // a new difference
      else if (roll < 0.95) time += uniform(int64_t{1} << 33, int64_t{1} << 40);  // past 32 bits
      else if (roll < 0.97) time -= uniform(int64_t{1} << 33, int64_t{1} << 40);
      else time += uniform(-(int64_t{1} << 31), (int64_t{1} << 31) - 1);
      std::memcpy(p + at_byte, &time, 8);
      at_byte += 8;
    }
    if (format >= 2) {
      if (chance(0.2)) rgb = {static_cast<uint16_t>(uniform(0, 65535)), static_cast<uint16_t>(uniform(0, 65535)),
                              static_cast<uint16_t>(uniform(0, 65535))};
      else if (chance(0.3)) rgb[static_cast<size_t>(uniform(0, 2))] += static_cast<uint16_t>(uniform(1, 300));
      std::memcpy(p + at_byte, rgb.data(), 6);
      at_byte += 6;
    }
    for (uint32_t b = 0; b < extra; ++b) {
      if (chance(0.2)) bytes[b] = static_cast<uint8_t>(uniform(0, 255));
      else if (chance(0.3)) ++bytes[b];
      p[at_byte + b] = static_cast<char>(bytes[b]);
    }
  }
  return out;
}

TEST(LazV1, everyItemRoundTripsThroughAVersion1Chunk) {
  for (int format = 0; format <= 3; ++format) {
    for (uint32_t extra : {0u, 1u, 7u}) {
      SCOPED_TRACE("format " + std::to_string(format) + ", " + std::to_string(extra) + " extra bytes");
      for (uint16_t compressor : {uint16_t{1}, uint16_t{2}}) {
        const LazInfo info = infoV1(format, (format == 0 ? 20 : format == 1 ? 28 : format == 2 ? 26 : 34) + extra,
                                    compressor, compressor == 1 ? 0 : 50000);
        const uint64_t points = 5000;
        const std::string records = syntheticRecords(format, extra, points, 11u + static_cast<uint32_t>(format));
        const std::string code = encodeV1(info, records.data(), points);
        std::string decoded(records.size(), '\0');
        Status s = decodeLazChunk(info, code.data(), code.size(), points, decoded.data());
        ASSERT_TRUE(s.ok()) << s.error().message;
        size_t first_difference = 0;
        while (first_difference < records.size() && decoded[first_difference] == records[first_difference])
          ++first_difference;
        EXPECT_EQ(first_difference, records.size()) << "record " << first_difference / info.recordLength();
        // A chunk of one point is its raw record and the encoder's flush.
        std::string one(info.recordLength(), '\0');
        const std::string single = encodeV1(info, records.data(), 1);
        ASSERT_TRUE(decodeLazChunk(info, single.data(), single.size(), 1, one.data()).ok());
        EXPECT_EQ(one, records.substr(0, info.recordLength()));
      }
    }
  }
}

TEST(LazV1, chunkedFileOfVersion1ItemsDecodesToTheRecords) {
  // LASzip 2.x could write version-1 items in chunks (compressor 2) on request: the chunk table and
  // fixed chunks as ever, each chunk a version-1 code.
  const std::string las = readFile(kTwin);
  const LazInfo info = infoV1(3, 34, 2, 300);  // 1,065 points: four chunks, the last of 165
  const std::string laz = lazFileOf(las, info, encodeV1);
  for (unsigned threads : {1u, 3u}) {
    Result<std::string> records = decodeBytes(laz, threads);
    ASSERT_TRUE(records.ok()) << records.error().message;
    EXPECT_TRUE(*records == lasRecords(las)) << threads << " threads";
  }
}

TEST(LazV1, compressor1WithVersion2ItemsDecodes) {
  // LASzip 2 and later write compressor 1 (no chunks) with version-2 items when asked to.
  const std::string las = readFile(kTwin);
  Result<LazInfo> info = lazInfoForFormat(3, 34);
  ASSERT_TRUE(info.ok());
  info->compressor = 1;
  const std::string laz = lazFileOf(las, *info, [](const LazInfo& i, const char* records, uint64_t points) {
    const std::vector<uint8_t> bytes = encodeLazChunk(i, records, points);
    return std::string(bytes.begin(), bytes.end());
  });
  Result<std::string> records = decodeBytes(laz);
  ASSERT_TRUE(records.ok()) << records.error().message;
  EXPECT_TRUE(*records == lasRecords(las));
}

TEST(LazV1, compressor1FileWithoutPointsDecodesToNothing) {
  std::string las = readFile(kTwin);
  put<uint32_t>(las, 107, 0);
  las.resize(at<uint32_t>(las, 96));
  const std::string laz = lazFileOf(las, infoV1(3, 34, 1), encodeV1);
  Result<std::string> records = decodeBytes(laz);
  ASSERT_TRUE(records.ok()) << records.error().message;
  EXPECT_TRUE(records->empty());
}

TEST(LazV1, compressor1CodeEndsAtTheFirstEvlrOfLas14) {
  // A LAS 1.4 file written with compressor 1: the code runs up to the EVLRs, not the file's end.
  const std::string las12 = readFile(kTwin);
  std::string las = las12.substr(0, 227) + std::string(375 - 227, '\0') + lasRecords(las12);
  las[25] = 4;
  put<uint16_t>(las, 94, 375);
  put<uint32_t>(las, 96, 375);
  put<uint64_t>(las, 247, 1065);
  std::string laz = lazFileOf(las, infoV1(3, 34, 1), encodeV1);
  const uint64_t evlr_at = laz.size();
  std::string evlr(60, '\0');
  std::memcpy(evlr.data() + 2, "dpoint test", 11);
  put<uint64_t>(evlr, 20, 16);
  laz += evlr + std::string(16, 'x');
  put<uint64_t>(laz, 235, evlr_at);
  put<uint32_t>(laz, 243, 1);
  Result<std::string> records = decodeBytes(laz);
  ASSERT_TRUE(records.ok()) << records.error().message;
  EXPECT_TRUE(*records == lasRecords(las12));
  put<uint64_t>(laz, 235, evlr_at - 10);  // inside the code
  records = decodeBytes(laz);
  ASSERT_FALSE(records.ok());
  EXPECT_TRUE(contains(records.error().message, "the compressed data ends early"));
  put<uint64_t>(laz, 235, 10);
  records = decodeBytes(laz);
  ASSERT_FALSE(records.ok());
  EXPECT_TRUE(contains(records.error().message, "header: the first EVLR's offset 10 is not between the offset to "
                                                "point data 481 and the file's end"));
}

// --- Hostile input -------------------------------------------------------------------------------------

TEST(LazV1, laszipsBrokenFilesAreRefusedSayingWhy) {
  // LASzip's own test files (data/broken_*.laz): a LAS 1.0 file of 213,093 points (POINT10 and
  // GPSTIME11, version 1, compressor 1) cut at 1,000 bytes, each with one field of its VLR spoilt.
  const auto message = [](const std::string& name) {
    Result<std::string> records = decodeLazFile(kData + name);
    return records.ok() ? std::string("decoded") : records.error().message;
  };
  EXPECT_TRUE(contains(message("broken_coder.laz"), "LAZ coder 15 is not supported"));
  EXPECT_TRUE(contains(message("broken_compressor.laz"), "laszip VLR: compressor 16 is not one of LASzip's (1 to 3)"));
  EXPECT_TRUE(contains(message("broken_type.laz"), "LAZ item type 22 (unknown) version 1 is not supported"));
  EXPECT_TRUE(contains(message("broken_version.laz"), "LAZ item type 6 (POINT10) version 6 is not supported (only "
                                                      "versions 1 and 2 of POINT10, GPSTIME11, RGB12 and BYTE"));
  // With its coder mended, the cut file decodes until its code runs out, then says where.
  std::string mended = readFile(kData + "broken_coder.laz");
  put<uint16_t>(mended, laszipVlrAt(mended) + 2, 0);
  Result<std::string> records = decodeBytes(mended);
  ASSERT_FALSE(records.ok());
  EXPECT_TRUE(contains(records.error().message, "v1.laz: the point data (compressor 1: one code of 671 bytes at byte "
                                                "329, points 0 to 213092): point "));
  EXPECT_TRUE(contains(records.error().message, "of 213093: the compressed data ends early"));
}

TEST(LazV1, laszipsOwnCutFileDecodesToPointsInsideItsBounds) {
  // The second real version-1 code here: broken_coder.laz's 671 bytes hold its first 92 points
  // (the decoder's last read ends 2 bytes before the cut). No twin exists; they must lie inside
  // the header's bounds, their GPS times (version 1's single sequence) must never go back, and the
  // return byte (format 1, LAS 1.0) must say return r of n with 1 ≤ r ≤ n.
  const std::string file = readFile(kData + "broken_coder.laz");
  std::string vlr = file.substr(laszipVlrAt(file), 34 + 2 * 6);
  put<uint16_t>(vlr, 2, 0);  // the arithmetic coder
  Result<LazInfo> info = parseLaszipVlr(vlr);
  ASSERT_TRUE(info.ok()) << info.error().message;
  const size_t points_at = at<uint32_t>(file, 96);
  ASSERT_EQ(file.size() - points_at, 671u);
  std::string records(92 * 28, '\0');
  Status s = decodeLazChunk(*info, file.data() + points_at, 669, 92, records.data());
  ASSERT_TRUE(s.ok()) << s.error().message;
  const auto header = [&](size_t field) { return at<double>(file, 131 + 8 * field); };  // scales, offsets, bounds
  double last_time = 0;
  for (size_t i = 0; i < 92; ++i) {
    const size_t r = i * 28;
    for (size_t axis = 0; axis < 3; ++axis) {
      const double v = at<int32_t>(records, r + 4 * axis) * header(axis) + header(3 + axis);
      EXPECT_GE(v, header(7 + 2 * axis)) << "point " << i << " axis " << axis;  // min
      EXPECT_LE(v, header(6 + 2 * axis)) << "point " << i << " axis " << axis;  // max
    }
    const int returns = static_cast<uint8_t>(records[r + 14]), number = returns & 7, of = (returns >> 3) & 7;
    EXPECT_TRUE(number >= 1 && number <= of) << "point " << i << ": return " << number << " of " << of;
    const double time = at<double>(records, r + 20);
    EXPECT_GE(time, last_time) << "point " << i;
    last_time = time;
  }
  EXPECT_GT(last_time, 413162.0);  // the first point's time, 413162.5604, and on
}

TEST(LazV1, everyCutOfTheRealFileIsAnErrorNeverACrash) {
  const std::string file = readFile(kLaszip1);
  const size_t points_at = at<uint32_t>(file, 96);
  size_t ends_early = 0;
  for (size_t size = 0; size < file.size(); size += 41) {
    Result<std::string> records = decodeBytes(file.substr(0, size));
    ASSERT_FALSE(records.ok()) << size << " bytes";
    if (size > points_at + 34 && contains(records.error().message, "the compressed data ends early")) ++ends_early;
  }
  EXPECT_GT(ends_early, 400u);  // nearly every cut inside the code names the point where it ran out
  // One byte short, too.
  Result<std::string> short_one = decodeBytes(file.substr(0, file.size() - 1));
  ASSERT_FALSE(short_one.ok());
  EXPECT_TRUE(contains(short_one.error().message, "ends early"));
}

TEST(LazV1, bytesAfterTheCodeAndCountsThatLieAreErrors) {
  std::string file = readFile(kLaszip1);
  Result<std::string> longer = decodeBytes(file + std::string(10, '\0'));
  ASSERT_FALSE(longer.ok());
  EXPECT_TRUE(contains(longer.error().message, "10 of the chunk's 21826 bytes are left over after its 1065 points"));
  put<uint32_t>(file, 107, 1066);
  Result<std::string> more = decodeBytes(file);
  ASSERT_FALSE(more.ok());
  EXPECT_TRUE(contains(more.error().message, "point 1065 of 1066: the compressed data ends early"));
  put<uint32_t>(file, 107, 1064);
  Result<std::string> fewer = decodeBytes(file);
  ASSERT_FALSE(fewer.ok());
  EXPECT_TRUE(contains(fewer.error().message, "left over after its 1064 points"));
}

TEST(LazV1, corruptCodeIsAnErrorOrWrongPointsNeverACrash) {
  // LAZ has no checksum: a changed byte may decode to other points. Every byte of the code's start
  // set to extreme values, then random flips anywhere: each decode ends (run under DPOINT_SANITIZE
  // for the full check).
  const std::string base = readFile(kLaszip1);
  const size_t code_at = at<uint32_t>(base, 96) + 34;
  size_t errors = 0;
  for (size_t i = 0; i < 64; ++i)
    for (int value : {0x00, 0xFF, 0x80, 0x7F}) {
      std::string file = base;
      file[code_at + i] = static_cast<char>(value);
      errors += decodeBytes(file).ok() ? 0 : 1;
    }
  std::mt19937 random(5);
  for (int i = 0; i < 200; ++i) {
    std::string file = base;
    file[random() % file.size()] ^= static_cast<char>(1 + random() % 255);
    errors += decodeBytes(file).ok() ? 0 : 1;
  }
  EXPECT_GT(errors, 100u);
}

TEST(LazV1, itemsAndCompressorsThatDoNotGoTogetherAreRefused) {
  const std::string original = readFile(kLaszip1);
  const size_t vlr = laszipVlrAt(original);
  const auto decodeWith = [&](auto change) {
    std::string file = original;
    change(file);
    Result<std::string> records = decodeBytes(file);
    return records.ok() ? std::string("decoded") : records.error().message;
  };
  EXPECT_TRUE(contains(decodeWith([&](std::string& f) { put<uint16_t>(f, vlr, 3); }),
                       "laszip VLR: LAZ item type 6 (POINT10) version 1 does not go with compressor 3"));
  EXPECT_TRUE(contains(decodeWith([&](std::string& f) {
                         put<uint16_t>(f, vlr + 34, kLazPoint14);
                         put<uint16_t>(f, vlr + 34 + 2, 30);
                         put<uint16_t>(f, vlr + 34 + 4, 3);
                       }),
                       "laszip VLR: LAZ item type 10 (POINT14) version 3 does not go with compressor 1"));
  EXPECT_TRUE(contains(decodeWith([&](std::string& f) { put<uint16_t>(f, vlr + 34 + 4, 4); }),
                       "LAZ item type 6 (POINT10) version 4 is not supported"));
  // The chunk size is compressor 2's and 3's: 0 is wrong only there.
  EXPECT_TRUE(contains(decodeWith([&](std::string& f) {
                         put<uint16_t>(f, vlr, 2);
                         put<uint32_t>(f, vlr + 12, 0);
                       }),
                       "laszip VLR: chunk size 0"));
}

}  // namespace
}  // namespace dpoint
