// dpoint's LAZ encoder (converters/laz_encode.h): every LAS twin of the corpus (../shared/corpus/laz,
// point formats 0–3, LAS 1.0–1.4, extra bytes, empty) compressed and decoded back to its records
// byte for byte, within 5% of the size LASzip made of the same records (the corpus .laz), the
// arithmetic encoder against the decoder on every kind of symbol, and the chunk table. laz-perf's
// verdict on the files `dpoint convert` writes is tests/external/lazperf_reads_dpoint_laz.py.
#include "converters/laz_encode.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "converters/laz_codec.h"
#include "converters/laz_encoder.h"
#include "las_bytes.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::at;
using test::lasRecords;
using test::readFile;

const std::string kLaz = std::string(DPOINT_CORPUS_DIR) + "/laz/";

TEST(LazEncoder, decoderReadsBackBitsSymbolsRawBitsAndIntegers) {
  std::mt19937 engine(7);
  const auto rng = [&] { return static_cast<uint32_t>(engine()); };
  LazBitModel bit_e, bit_d;
  LazSymbolModel small_e(5), small_d(5), big_e(300), big_d(300);
  LazIntegerEncoder ints_e(32, 3);
  LazIntegerDecoder ints_d(32, 3);
  LazIntegerEncoder shorts_e(16, 1);
  LazIntegerDecoder shorts_d(16, 1);
  struct Op {
    int kind;
    uint32_t value, extra;
  };
  std::vector<Op> ops;
  for (int i = 0; i < 200000; ++i) {
    const int kind = static_cast<int>(rng() % 6);
    uint32_t value = rng(), extra = rng() % 32 + 1;
    if (kind == 0) value = (rng() % 10) < 8 ? 0 : 1;  // skewed bits
    if (kind == 1) value %= 5;
    if (kind == 2) value = (rng() % 4 == 0) ? value % 300 : value % 3;
    if (kind == 3 && extra < 32) value &= (1u << extra) - 1;
    if (kind == 5) value &= 0xFFFF;
    ops.push_back({kind, value, extra});
  }
  LazEncoder e;
  int32_t prediction = 0;
  for (const Op& op : ops) {
    switch (op.kind) {
      case 0: e.encodeBit(bit_e, op.value); break;
      case 1: e.encodeSymbol(small_e, op.value); break;
      case 2: e.encodeSymbol(big_e, op.value); break;
      case 3: e.writeBits(op.extra, op.value); break;
      case 4: ints_e.encode(e, prediction, static_cast<int32_t>(op.value), op.extra % 3); prediction = static_cast<int32_t>(op.value); break;
      case 5: shorts_e.encode(e, 1000, static_cast<int32_t>(op.value)); break;
    }
  }
  e.done();
  const std::vector<uint8_t>& bytes = e.bytes();
  LazDecoder d(bytes.data(), bytes.size());
  prediction = 0;
  for (size_t i = 0; i < ops.size(); ++i) {
    const Op& op = ops[i];
    uint32_t got = 0;
    switch (op.kind) {
      case 0: got = d.decodeBit(bit_d); break;
      case 1: got = d.decodeSymbol(small_d); break;
      case 2: got = d.decodeSymbol(big_d); break;
      case 3: got = d.readBits(op.extra); break;
      case 4: got = static_cast<uint32_t>(ints_d.decode(d, prediction, op.extra % 3)); prediction = static_cast<int32_t>(got); break;
      case 5: got = static_cast<uint32_t>(shorts_d.decode(d, 1000)); break;
    }
    ASSERT_EQ(got, op.value) << "operation " << i << " of kind " << op.kind;
  }
  EXPECT_TRUE(d.ok());
  // The code ends where the decoder stops reading: LAZ chunks have no other end marker.
  EXPECT_EQ(d.consumed(), bytes.size());
}

TEST(LazEncoder, anEmptyCodeIsFourBytesTheDecoderUsesUp) {
  LazEncoder e;
  e.done();
  EXPECT_EQ(e.bytes().size(), 4u);
  LazDecoder d(e.bytes().data(), e.bytes().size());
  EXPECT_TRUE(d.ok());
  EXPECT_EQ(d.consumed(), 4u);
}

TEST(LazEncode, corpusTwinsRoundTripAndMatchLaszipsSize) {
  const char* pairs[][2] = {
      {"1815.las", "1815.laz"},
      {"autzen_trim.las", "autzen_trim.laz"},
      {"extrabytes.las", "extrabytes.laz"},
      {"no-points-1.3.las", "no-points-1.3.laz"},
      {"point-color-time.las", "point-color-time.las.laz"},
      {"point-color.las", "point-color.las.laz"},
      {"point-time.las", "point-time.las.laz"},
      {"point10-1.0.las", "point10-1.0.laz"},
      {"point10-1.1.las", "point10-1.1.laz"},
      {"point10.las", "point10.las.laz"},
  };
  for (const auto& pair : pairs) {
    SCOPED_TRACE(pair[0]);
    const std::string las = readFile(kLaz + pair[0]);
    Result<std::string> laz = compressLasBytes(las, 2);
    ASSERT_TRUE(laz) << laz.error().message;
    Result<std::string> records = decodeLaz(InputFile::fromMemory(pair[1], *laz), 2);
    ASSERT_TRUE(records) << records.error().message;
    EXPECT_TRUE(*records == lasRecords(las));
    // The compressed records' size against LASzip's (the files' headers and VLRs differ a little:
    // compare what follows the offset to point data).
    const std::string theirs = readFile(kLaz + pair[1]);
    const double ours = static_cast<double>(laz->size() - at<uint32_t>(*laz, 96));
    const double laszip = static_cast<double>(theirs.size() - at<uint32_t>(theirs, 96));
    EXPECT_LE(ours, laszip * 1.05 + 16) << "dpoint " << ours << " bytes, LASzip " << laszip;
    std::printf("%-22s dpoint %9.0f bytes, LASzip %9.0f (%+.2f%%)\n", pair[0], ours, laszip,
                laszip > 0 ? 100.0 * (ours - laszip) / laszip : 0.0);
  }
}

// The first `count` points of an uncompressed LAS file (1.0–1.3 headers).
std::string firstPoints(std::string las, uint32_t count) {
  std::memcpy(las.data() + 107, &count, 4);
  return las.substr(0, at<uint32_t>(las, 96) + size_t{count} * at<uint16_t>(las, 105));
}

TEST(LazEncode, manyChunksAndOnePoint) {
  // autzen_trim's 110000 points in chunks of 1000, 50000 and more than all; 5 points in chunks of
  // one; one point.
  const std::string las = readFile(kLaz + "autzen_trim.las");
  for (const auto& [input, chunk] : {std::pair{las, 1000u}, {las, 50000u}, {las, 200000u},
                                     {firstPoints(las, 5), 1u}, {firstPoints(las, 1), 50000u}}) {
    Result<std::string> laz = compressLasBytes(input, 2, chunk);
    ASSERT_TRUE(laz) << laz.error().message;
    Result<std::string> records = decodeLaz(InputFile::fromMemory("chunks.laz", *laz), 2);
    ASSERT_TRUE(records) << records.error().message;
    EXPECT_TRUE(*records == lasRecords(input)) << chunk;
  }
}

TEST(LazEncode, refusesWaveformFormatsAndCompressedInput) {
  EXPECT_FALSE(lazInfoForFormat(4, 57));
  EXPECT_FALSE(lazInfoForFormat(10, 67));
  EXPECT_FALSE(lazInfoForFormat(3, 20));  // shorter than the format
  const std::string laz = readFile(kLaz + "point10.las.laz");
  Result<std::string> again = compressLasBytes(laz);
  ASSERT_FALSE(again);
  EXPECT_NE(again.error().message.find("compressed already"), std::string::npos);
}

}  // namespace
}  // namespace dpoint
