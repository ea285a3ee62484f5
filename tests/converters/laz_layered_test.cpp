// LAZ layered chunks (converters/laz_layered.h), point formats 6–8: encode → decode gives the
// records byte for byte (the corpus's LAS 1.4 files and synthetic records that switch scanner
// channels, returns, flags, GPS time sequences and colours); chunks LASzip wrote (laspy's test
// files, tests/data/laz/) decode to what laz-perf decodes them to and re-encode to the same bytes;
// laz-perf decodes dpoint's files to the records; truncated and corrupt chunks are errors that say
// which layer and point, never a crash.
#include "converters/laz_layered.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <array>
#include <bit>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "converters/laz_decode.h"
#include "converters/laz_encode.h"
#include "las_bytes.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::at;
using test::contains;
using test::lasRecords;
using test::put;
using test::readFile;

const std::string kCorpus = std::string(DPOINT_CORPUS_DIR) + "/";
const std::string kData = std::string(DPOINT_TESTS_DIR) + "/data/laz/";

int lasFormat(const std::string& file) { return static_cast<uint8_t>(file[104]) & 0x3F; }
uint16_t lasRecordLength(const std::string& file) { return at<uint16_t>(file, 105); }
// FNV-1a, 64 bits: a fingerprint of records decoded by laz-perf when the tests were written.
uint64_t fnv1a(const std::string& bytes) {
  uint64_t h = 0xcbf29ce484222325u;
  for (unsigned char c : bytes) h = (h ^ c) * 0x100000001b3u;
  return h;
}

uint32_t baseLength(int format) { return format == 6 ? 30 : format == 7 ? 36 : 38; }

LazInfo infoFor(int format, uint32_t record_length) {
  Result<LazInfo> info = lazInfoForFormat(format, record_length);
  EXPECT_TRUE(info.ok()) << (info.ok() ? "" : info.error().message);
  return info.ok() ? *info : LazInfo{};
}

// Compresses `points` records as chunks of `chunk` points and decodes each chunk back: the
// decoded records must be the originals. Returns the chunks' total bytes (0 after a failure).
size_t roundTrip(const LazInfo& info, const std::string& records, uint64_t chunk) {
  const size_t length = info.recordLength();
  const uint64_t points = records.size() / length;
  std::string decoded(records.size(), '\0');
  size_t total = 0;
  for (uint64_t first = 0; first < points; first += chunk) {
    const uint64_t n = std::min(chunk, points - first);
    const std::vector<uint8_t> bytes = encodeLayeredChunk(info, records.data() + first * length, n);
    total += bytes.size();
    Status s = decodeLayeredChunk(info, reinterpret_cast<const char*>(bytes.data()), bytes.size(), n,
                                  decoded.data() + first * length);
    EXPECT_TRUE(s.ok()) << "chunk at point " << first << ": " << (s.ok() ? "" : s.error().message);
    if (!s.ok()) return 0;
  }
  for (size_t i = 0; i < records.size(); ++i) {
    if (decoded[i] != records[i]) {
      ADD_FAILURE() << "record " << i / length << " byte " << i % length << " decodes to "
                    << int(static_cast<uint8_t>(decoded[i])) << ", not " << int(static_cast<uint8_t>(records[i]));
      return 0;
    }
  }
  return total;
}

// Records of point format 6, 7 or 8 with `extra` extra bytes that exercise every path of the
// coder: scanner channels 0–3 switching (and some points of one channel in a row), return numbers
// stepping by ±1, jumping, invalid (0, > n), numbers of returns up to 15, classification flags,
// classes above 31, scan angles to the int16 extremes, GPS times advancing steadily, repeating
// (multiple returns), jumping to new sequences and back, by multiples and negative steps, NaN and
// −0; colours constant, grey and random; coordinates that wrap int32.
std::string syntheticRecords(int format, uint16_t extra, uint64_t points, uint32_t seed = 7) {
  const size_t length = baseLength(format) + extra;
  std::string out(points * length, '\0');
  std::mt19937 rng(seed);
  const auto chance = [&](double p) { return std::uniform_real_distribution<double>(0, 1)(rng) < p; };
  const auto uniform = [&](int64_t lo, int64_t hi) { return std::uniform_int_distribution<int64_t>(lo, hi)(rng); };
  int32_t x = 1000, y = -2000, z = 50;
  uint8_t channel = 0, r = 1, n = 1, flags = 0, cls = 2, user = 0;
  int16_t angle = 0;
  uint16_t source = 7, intensity = 100;
  std::array<double, 4> time = {1000.0, 2000.0, 3000.0, 4000.0};
  std::array<uint16_t, 4> colour = {100, 100, 100, 500};
  std::vector<uint8_t> bytes(extra, 0);
  for (uint64_t i = 0; i < points; ++i) {
    char* p = out.data() + i * length;
    if (chance(0.08)) channel = static_cast<uint8_t>(uniform(0, 3));
    if (chance(0.01)) {
      x = static_cast<int32_t>(uniform(INT32_MIN, INT32_MAX));  // differences wrap
      y = static_cast<int32_t>(uniform(INT32_MIN, INT32_MAX));
    } else {
      x += static_cast<int32_t>(uniform(-300, 300));
      y += static_cast<int32_t>(uniform(-300, 300));
    }
    z = chance(0.01) ? static_cast<int32_t>(uniform(INT32_MIN, INT32_MAX)) : z + static_cast<int32_t>(uniform(-50, 50));
    // Returns: mostly pulses of n returns counted up, sometimes odd jumps and invalid pairs.
    if (r >= n || chance(0.05)) {
      n = static_cast<uint8_t>(chance(0.1) ? uniform(0, 15) : uniform(1, 4));
      r = static_cast<uint8_t>(chance(0.05) ? uniform(0, 15) : 1);
    } else {
      r = static_cast<uint8_t>(chance(0.1) ? uniform(0, 15) : r + 1);
    }
    if (chance(0.03)) flags = static_cast<uint8_t>(uniform(0, 63));
    if (chance(0.05)) cls = static_cast<uint8_t>(chance(0.3) ? uniform(32, 255) : uniform(0, 9));
    if (chance(0.02)) user = static_cast<uint8_t>(uniform(0, 255));
    if (chance(0.1))
      angle = static_cast<int16_t>(chance(0.1) ? (chance(0.5) ? INT16_MIN : INT16_MAX) : uniform(-3000, 3000));
    if (chance(0.01)) source = static_cast<uint16_t>(uniform(0, 65535));
    intensity = static_cast<uint16_t>(chance(0.3) ? intensity : uniform(0, 65535));
    // GPS time: the channel's own sequence advances; the first return of a pulse takes a new time.
    double& t = time[channel];
    if (r <= 1 || chance(0.02)) {
      const double roll = std::uniform_real_distribution<double>(0, 1)(rng);
      if (roll < 0.80) t += 1e-5;                         // steady pulses
      else if (roll < 0.85) t += 1e-5 * static_cast<double>(uniform(2, 700));  // multiples, ≥ 500 too
      else if (roll < 0.88) t -= 1e-5 * static_cast<double>(uniform(1, 20));   // negative multiples
      else if (roll < 0.91) t += static_cast<double>(uniform(1000, 100000));   // a new sequence
      else if (roll < 0.94) t = time[uniform(0, 3)];                           // back to another one
      else if (roll < 0.95) t = std::numeric_limits<double>::quiet_NaN();
      else if (roll < 0.96) t = -0.0;
      else if (roll < 0.97) t = 0.0;
      else t += 3e-6;
    }
    if (format >= 7 && chance(0.05)) {
      if (chance(0.5)) {
        const uint16_t grey = static_cast<uint16_t>(uniform(0, 65535));
        colour[0] = colour[1] = colour[2] = grey;
      } else {
        for (size_t c = 0; c < 3; ++c) colour[c] = static_cast<uint16_t>(uniform(0, 65535));
      }
      if (chance(0.3)) colour[3] = static_cast<uint16_t>(uniform(0, 65535));
    }
    for (size_t b = 0; b < bytes.size(); ++b) {
      if (b == 0) continue;                                   // one byte constant
      if (b == 1 && chance(0.01)) bytes[b] = static_cast<uint8_t>(uniform(0, 255));  // rarely changing
      if (b >= 2) bytes[b] = static_cast<uint8_t>(uniform(0, 255));
    }
    put(out, i * length, x);
    put(out, i * length + 4, y);
    put(out, i * length + 8, z);
    put(out, i * length + 12, intensity);
    p[14] = static_cast<char>(r | n << 4);
    p[15] = static_cast<char>((flags & 0x0F) | channel << 4 | (flags & 0x30) << 2);
    p[16] = static_cast<char>(cls);
    p[17] = static_cast<char>(user);
    put(out, i * length + 18, angle);
    put(out, i * length + 20, source);
    put(out, i * length + 22, t);
    if (format >= 7)
      for (size_t c = 0; c < (format == 8 ? 4u : 3u); ++c) put(out, i * length + 30 + 2 * c, colour[c]);
    if (extra != 0) std::memcpy(p + baseLength(format), bytes.data(), extra);
  }
  return out;
}

// A LAS 1.4 file (375-byte header, no VLRs) holding `records`.
std::string lasFile(int format, uint16_t record_length, const std::string& records) {
  std::string h(375, '\0');
  std::memcpy(h.data(), "LASF", 4);
  h[24] = 1;
  h[25] = 4;
  put<uint16_t>(h, 94, 375);
  put<uint32_t>(h, 96, 375);
  h[104] = static_cast<char>(format);
  put<uint16_t>(h, 105, record_length);
  for (size_t axis = 0; axis < 3; ++axis) put<double>(h, 131 + 8 * axis, 0.01);
  put<uint64_t>(h, 247, records.size() / record_length);
  return h + records;
}

// The layer sizes of a chunk: after its raw first point and point count.
std::vector<uint32_t> layerSizes(const std::vector<uint8_t>& chunk, size_t record_length, size_t layers) {
  std::vector<uint32_t> sizes(layers);
  std::memcpy(sizes.data(), chunk.data() + record_length + 4, 4 * layers);
  return sizes;
}

// --- Round trips -----------------------------------------------------------------------------------

TEST(LazLayered, corpusFormat6To8RecordsRoundTripByteForByte) {
  int files = 0;
  for (const char* dir : {"las", "laz"}) {
    for (const auto& entry : std::filesystem::directory_iterator(kCorpus + dir)) {
      if (entry.path().extension() != ".las") continue;
      const std::string file = readFile(entry.path());
      const int format = lasFormat(file);
      if ((static_cast<uint8_t>(file[104]) & 0xC0) != 0 || format < 6 || format > 8) continue;
      SCOPED_TRACE(entry.path().string());
      const LazInfo info = infoFor(format, lasRecordLength(file));
      const std::string records = lasRecords(file);
      EXPECT_GT(roundTrip(info, records, 50000), 0u);
      EXPECT_GT(roundTrip(info, records, 997), 0u);  // many chunks, each starting its channels afresh
      ++files;
    }
  }
  // rand1_6.las, 1_4_w_evlr.las, test1_4.las, unregistered_extra_bytes.las (6), simple1_4.las (7).
  EXPECT_GE(files, 5);
}

TEST(LazLayered, syntheticRecordsOfFormats6To8RoundTripByteForByte) {
  for (int format : {6, 7, 8}) {
    for (uint16_t extra : {uint16_t{0}, uint16_t{5}}) {
      SCOPED_TRACE("format " + std::to_string(format) + " + " + std::to_string(extra) + " extra bytes");
      const LazInfo info = infoFor(format, baseLength(format) + extra);
      const std::string records = syntheticRecords(format, extra, 20000, 11u * static_cast<uint32_t>(format) + extra);
      EXPECT_GT(roundTrip(info, records, 20000), 0u);
      EXPECT_GT(roundTrip(info, records, 313), 0u);
      EXPECT_GT(roundTrip(info, records.substr(0, info.recordLength()), 1), 0u);  // a chunk of one point
      EXPECT_GT(roundTrip(info, records.substr(0, 2 * info.recordLength()), 2), 0u);
    }
  }
}

TEST(LazLayered, everyChannelPairAndReturnStepRoundTrips) {
  // Each point switches channel in turn through all 16 (from, to) pairs, its return number
  // stepping every way: +1, −1, by more with and without a time change.
  const LazInfo info = infoFor(8, 38 + 2);
  std::string records = syntheticRecords(8, 2, 4096, 3);
  for (size_t i = 0; i < 4096; ++i) {
    const uint8_t channel = static_cast<uint8_t>((i / 4 + i) & 3);
    char& b = records[i * 40 + 15];
    b = static_cast<char>((b & 0xCF) | channel << 4);
    records[i * 40 + 14] = static_cast<char>((i * 7) % 16 | ((i / 16) % 16) << 4);
  }
  EXPECT_GT(roundTrip(info, records, 4096), 0u);
}

TEST(LazLayered, aChunkWhereNothingChangesWritesOnlyItsXyAndZLayers) {
  for (int format : {6, 7, 8}) {
    SCOPED_TRACE("format " + std::to_string(format));
    const uint16_t extra = 3;
    const LazInfo info = infoFor(format, baseLength(format) + extra);
    const std::string one = syntheticRecords(format, extra, 1, 5);
    std::string records;
    for (int i = 0; i < 1000; ++i) records += one;
    const std::vector<uint8_t> chunk = encodeLayeredChunk(info, records.data(), 1000);
    const size_t layers = 9 + (format == 7 ? 1 : format == 8 ? 2 : 0) + extra;
    const std::vector<uint32_t> sizes = layerSizes(chunk, info.recordLength(), layers);
    EXPECT_GT(sizes[0], 0u);  // LASzip writes the channel/returns/XY and Z layers whatever they hold
    EXPECT_GT(sizes[1], 0u);
    for (size_t i = 2; i < layers; ++i) EXPECT_EQ(sizes[i], 0u) << "layer " << i;
    EXPECT_GT(roundTrip(info, records, 1000), 0u);
  }
}

TEST(LazLayered, onlyTheLayersWhoseValuesChangeAreWritten) {
  // Format 8: a grey colour held constant leaves RGB out; NIR and the intensity change.
  const LazInfo info = infoFor(8, 38);
  std::string records = syntheticRecords(8, 0, 500, 9);
  const std::string first = records.substr(0, 38);
  for (size_t i = 0; i < 500; ++i) {
    std::string r = first;
    put<uint16_t>(r, 12, static_cast<uint16_t>(i * 3));  // intensity
    put<uint16_t>(r, 30, 700);
    put<uint16_t>(r, 32, 700);
    put<uint16_t>(r, 34, 700);
    put<uint16_t>(r, 36, static_cast<uint16_t>(i));  // NIR
    records.replace(i * 38, 38, r);
  }
  const std::vector<uint32_t> sizes = layerSizes(encodeLayeredChunk(info, records.data(), 500), 38, 11);
  EXPECT_GT(sizes[4], 0u);   // intensity
  EXPECT_EQ(sizes[8], 0u);   // GPS time
  EXPECT_EQ(sizes[9], 0u);   // RGB
  EXPECT_GT(sizes[10], 0u);  // NIR
  EXPECT_GT(roundTrip(info, records, 500), 0u);
}

TEST(LazLayered, filesOf50000And50001PointsRoundTripThroughTheLazReader) {
  for (uint64_t points : {uint64_t{50000}, uint64_t{50001}}) {
    SCOPED_TRACE(std::to_string(points) + " points");
    const std::string records = syntheticRecords(7, 4, points, 21);
    Result<std::string> laz = compressLasBytes(lasFile(7, 40, records), 2);
    ASSERT_TRUE(laz.ok()) << laz.error().message;
    for (unsigned threads : {1u, 3u}) {
      Result<std::string> decoded = decodeLaz(InputFile::fromMemory("synthetic.laz", *laz), threads);
      ASSERT_TRUE(decoded.ok()) << decoded.error().message;
      EXPECT_TRUE(*decoded == records);
    }
  }
}

// --- Files other writers made ----------------------------------------------------------------------

struct OtherWriter {
  const char* file;
  int format;
  uint64_t points;
  uint64_t lazperf_fnv;  // laz-perf 0.0.7's records, FNV-1a
};
// laspy's test files (tests/data/laz/README.md): written by lazrs, laz-perf/LASzip (COPC) and TerraScan.
constexpr OtherWriter kOtherWriters[] = {
    {"1_4_w_evlr.laz", 6, 1000, 0x7434f969bddef559u},
    {"simple.copc.laz", 7, 1065, 0x2b9c1be162ecbe35u},
    {"append-bug.laz", 8, 37805, 0x3f7150bfb85f3a9bu},
};

TEST(LazLayered, filesOfOtherWritersDecodeAsLazperfDecodesThem) {
  for (const OtherWriter& w : kOtherWriters) {
    SCOPED_TRACE(w.file);
    const std::string file = readFile(kData + w.file);
    EXPECT_EQ(lasFormat(file), w.format);
    Result<std::string> records = decodeLaz(InputFile::fromMemory(w.file, file), 2);
    ASSERT_TRUE(records.ok()) << records.error().message;
    EXPECT_EQ(records->size() / lasRecordLength(file), w.points);
    EXPECT_EQ(fnv1a(*records), w.lazperf_fnv);
  }
  // 1_4_w_evlr.laz's uncompressed twin is in the corpus.
  Result<std::string> records = decodeLazFile(kData + std::string("1_4_w_evlr.laz"), 1);
  ASSERT_TRUE(records.ok()) << records.error().message;
  EXPECT_TRUE(*records == lasRecords(readFile(kCorpus + "las/1_4_w_evlr.las")));
}

TEST(LazLayered, chunksOfOtherWritersReencodeToTheSameBytes) {
  // dpoint's encoder makes LASzip's choices, so the same points give the same chunk.
  for (const OtherWriter& w : kOtherWriters) {
    SCOPED_TRACE(w.file);
    const std::string bytes = readFile(kData + w.file);
    const InputFile file = InputFile::fromMemory(w.file, bytes);
    Result<std::string> records = decodeLaz(file, 1);
    ASSERT_TRUE(records.ok()) << records.error().message;
    // The laszip VLR and the chunk table, found as the reader finds them.
    size_t vlr = at<uint16_t>(bytes, 94);
    while (std::strncmp(bytes.data() + vlr + 2, "laszip encoded", 16) != 0) vlr += 54 + at<uint16_t>(bytes, vlr + 20);
    const uint16_t vlr_bytes = at<uint16_t>(bytes, vlr + 20);
    Result<LazInfo> info = parseLaszipVlr(std::string_view(bytes).substr(vlr + 54, vlr_bytes));
    ASSERT_TRUE(info.ok()) << info.error().message;
    Result<std::vector<LazChunk>> chunks = readLazChunkTable(file, at<uint32_t>(bytes, 96), *info, w.points);
    ASSERT_TRUE(chunks.ok()) << chunks.error().message;
    const size_t length = info->recordLength();
    uint64_t first = 0;
    for (const LazChunk& c : *chunks) {
      const std::vector<uint8_t> again = encodeLayeredChunk(*info, records->data() + first * length, c.points);
      EXPECT_TRUE(std::string(again.begin(), again.end()) == bytes.substr(c.offset, c.bytes))
          << "chunk at point " << first << ": " << again.size() << " bytes, the file's " << c.bytes;
      first += c.points;
    }
  }
}

// --- The independent judge: laz-perf -----------------------------------------------------------------

std::string findOnPath(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    const std::string candidate = dir + "/" + name;
    if (!dir.empty() && ::access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return "";
}

TEST(LazLayered, lazperfDecodesDpointFilesToTheRecords) {
  const std::string node = findOnPath("node");
  if (node.empty()) GTEST_SKIP() << "node is not on PATH";
  const std::string script = std::string(DPOINT_TESTS_DIR) + "/external/node/lazperf_records.mjs";
  struct Case {
    std::string name;
    int format;
    uint16_t length;
    std::string records;
  };
  std::vector<Case> cases;
  const std::string rand16 = readFile(kCorpus + "laz/rand1_6.las");
  cases.push_back({"rand1_6", 6, 30, lasRecords(rand16)});
  const std::string simple14 = readFile(kCorpus + "las/simple1_4.las");
  cases.push_back({"simple1_4", 7, 36, lasRecords(simple14)});
  const std::string extra = readFile(kCorpus + "las/unregistered_extra_bytes.las");
  cases.push_back({"unregistered_extra_bytes", 6, 34, lasRecords(extra)});
  cases.push_back({"synthetic6", 6, 33, syntheticRecords(6, 3, 50001, 31)});
  cases.push_back({"synthetic7", 7, 36, syntheticRecords(7, 0, 30000, 32)});
  cases.push_back({"synthetic8", 8, 45, syntheticRecords(8, 7, 50001, 33)});
  test::TempDir dir;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    Result<std::string> laz = compressLasBytes(lasFile(c.format, c.length, c.records), 2);
    ASSERT_TRUE(laz.ok()) << laz.error().message;
    const std::string in = dir.file(c.name + ".laz"), out = dir.file(c.name + ".bin");
    test::writeFile(in, *laz);
    const test::CommandResult run = test::runCommand({node, script, in, out}, std::chrono::seconds(120));
    ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
    EXPECT_TRUE(contains(run.out, "format=" + std::to_string(c.format) + " length=" + std::to_string(c.length) +
                                      " count=" + std::to_string(c.records.size() / c.length)));
    EXPECT_TRUE(readFile(out) == c.records) << "laz-perf decodes " << c.name << " to other records";
  }
}

// --- Hostile chunks --------------------------------------------------------------------------------

struct BrokenChunk {
  LazInfo info;
  std::string records;
  std::vector<uint8_t> chunk;
  size_t header = 0;  // raw point + count + sizes
  uint64_t points = 0;
};
BrokenChunk sampleChunk(uint64_t points = 300) {
  BrokenChunk b;
  b.info = infoFor(8, 38 + 2);
  b.records = syntheticRecords(8, 2, points, 41);
  b.chunk = encodeLayeredChunk(b.info, b.records.data(), points);
  b.header = 40 + 4 + 4 * (9 + 2 + 2);
  b.points = points;
  return b;
}
std::string decodeMessage(const BrokenChunk& b, const std::vector<uint8_t>& chunk, uint64_t points = 0) {
  std::string out(b.records.size() + 64 * 40, '\0');
  Status s = decodeLayeredChunk(b.info, reinterpret_cast<const char*>(chunk.data()), chunk.size(),
                                points ? points : b.points, out.data());
  return s.ok() ? "decoded" : s.error().message;
}
void setSize(std::vector<uint8_t>& chunk, size_t layer, uint32_t size) {
  std::memcpy(chunk.data() + 40 + 4 + 4 * layer, &size, 4);
}

TEST(LazLayered, rejectsTruncatedChunksAtEveryLength) {
  const BrokenChunk b = sampleChunk();
  ASSERT_EQ(decodeMessage(b, b.chunk), "decoded");
  for (size_t cut = 0; cut < b.chunk.size(); ++cut) {
    const std::vector<uint8_t> truncated(b.chunk.begin(), b.chunk.begin() + static_cast<std::ptrdiff_t>(cut));
    EXPECT_NE(decodeMessage(b, truncated), "decoded") << cut << " bytes";
  }
  EXPECT_TRUE(contains(decodeMessage(b, std::vector<uint8_t>(b.chunk.begin(), b.chunk.begin() + 50)),
                       "the chunk's 50 bytes are fewer than the 96 of its first point (40 raw bytes), point count "
                       "and 13 layer sizes"));
  EXPECT_TRUE(contains(decodeMessage(b, std::vector<uint8_t>(b.chunk.begin(), b.chunk.end() - 1)),
                       "follow them (truncated or corrupt chunk)"));
}

TEST(LazLayered, rejectsLayerSizesThatLie) {
  const BrokenChunk b = sampleChunk();
  const std::vector<uint32_t> sizes = layerSizes(b.chunk, 40, 13);
  ASSERT_GT(sizes[4], 2u);  // intensity
  {
    // A short layer, its bytes handed to the next one: the short one runs out.
    std::vector<uint8_t> c = b.chunk;
    setSize(c, 4, sizes[4] - 2);
    setSize(c, 5, sizes[5] + 2);
    const std::string message = decodeMessage(b, c);
    EXPECT_TRUE(contains(message, "the intensity layer (" + std::to_string(sizes[4] - 2) + " bytes) ends early") ||
                contains(message, "invalid arithmetic code in the intensity layer"))
        << message;
    EXPECT_TRUE(contains(message, "point ")) << message;
  }
  {
    std::vector<uint8_t> c = b.chunk;
    setSize(c, 4, sizes[4] + 1);
    EXPECT_TRUE(contains(decodeMessage(b, c), "the chunk's layer sizes add up to"));
    setSize(c, 4, 0xFFFFFFFFu);
    EXPECT_TRUE(contains(decodeMessage(b, c), "the chunk's layer sizes add up to"));
  }
  {
    std::vector<uint8_t> c = b.chunk;
    c.push_back(0);
    EXPECT_TRUE(contains(decodeMessage(b, c), "1 of the chunk's " + std::to_string(c.size()) +
                                                  " bytes are left over after its layers"));
  }
  {
    // A layer with a byte too many, its neighbour one short: the long one has a byte left over
    // (or the short one runs out first).
    std::vector<uint8_t> c = b.chunk;
    setSize(c, 1, sizes[1] + 1);
    setSize(c, 2, sizes[2] - 1);
    const std::string message = decodeMessage(b, c);
    EXPECT_NE(message, "decoded");
  }
  {
    std::vector<uint8_t> c = b.chunk;
    setSize(c, 0, 0);
    setSize(c, 1, sizes[0] + sizes[1]);
    EXPECT_TRUE(
        contains(decodeMessage(b, c), "the chunk's channel/returns/XY layer is empty, but it holds 300 points"));
  }
}

TEST(LazLayered, rejectsAPointCountOtherThanTheTables) {
  const BrokenChunk b = sampleChunk();
  EXPECT_TRUE(contains(decodeMessage(b, b.chunk, 299),
                       "the chunk holds 300 points by its own count, 299 by the chunk table"));
  EXPECT_TRUE(contains(decodeMessage(b, b.chunk, 301), "the chunk holds 300 points by its own count"));
}

TEST(LazLayered, rejectsItemsThatAreNotALayeredSet) {
  const BrokenChunk b = sampleChunk();
  LazInfo swapped = b.info;
  std::swap(swapped.items[1], swapped.items[2]);
  std::string out(b.records.size(), '\0');
  Status s = decodeLayeredChunk(swapped, reinterpret_cast<const char*>(b.chunk.data()), b.chunk.size(), b.points,
                                out.data());
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.error().message, "a layered LAZ chunk's items must be POINT14"));
}

TEST(LazLayered, corruptLayersAreErrorsOrWrongPointsNeverACrash) {
  // Random bytes flipped in the layers: every decode ends (run it under ASan to see no read
  // strays outside the chunk).
  const BrokenChunk b = sampleChunk(2000);
  std::mt19937 rng(5);
  int errors = 0;
  for (int trial = 0; trial < 400; ++trial) {
    std::vector<uint8_t> c = b.chunk;
    const size_t flips = 1 + rng() % 4;
    for (size_t f = 0; f < flips; ++f) {
      const size_t i = b.header + rng() % (c.size() - b.header);
      c[i] = static_cast<uint8_t>(c[i] ^ (1u + rng() % 255));
    }
    if (decodeMessage(b, c) != "decoded") ++errors;
  }
  EXPECT_GT(errors, 300);  // most corruptions show (LAZ has no checksum: not all can)
}

// --- The laszip VLR and the items of formats 6–8 ---------------------------------------------------

TEST(LazLayered, laszipVlrOfFormats6To8ParsesAndOtherVersionsAreRefusedByName) {
  Result<LazInfo> info8 = lazInfoForFormat(8, 41);
  ASSERT_TRUE(info8.ok());
  const std::string vlr = laszipVlrData(*info8);
  Result<LazInfo> parsed = parseLaszipVlr(vlr);
  ASSERT_TRUE(parsed.ok()) << parsed.error().message;
  EXPECT_EQ(parsed->compressor, 3);
  ASSERT_EQ(parsed->items.size(), 3u);
  EXPECT_TRUE(checkLazItems(*parsed, 8, 41).ok());
  const auto refusal = [&](auto change) {
    std::string v = vlr;
    change(v);
    Result<LazInfo> r = parseLaszipVlr(v);
    return r.ok() ? std::string("parsed") : r.error().message;
  };
  EXPECT_TRUE(contains(refusal([](std::string& v) { put<uint16_t>(v, 34 + 4, 4); }),
                       "LAZ item type 10 (POINT14) version 4 is not supported"));
  EXPECT_TRUE(contains(refusal([](std::string& v) { put<uint16_t>(v, 34 + 6, 13); }),
                       "LAZ item type 13 (WAVEPACKET14) version 3 is not supported"));
  EXPECT_TRUE(contains(refusal([](std::string& v) { put<uint16_t>(v, 0, 2); }),
                       "LAZ item type 10 (POINT14) version 3 does not go with compressor 2"));
  EXPECT_TRUE(contains(refusal([](std::string& v) { put<uint16_t>(v, 34 + 2, 31); }),
                       "LAZ item type 10 (POINT14) has size 31, not 30"));
  Result<LazInfo> info1 = lazInfoForFormat(1, 28);
  ASSERT_TRUE(info1.ok());
  std::string pointwise = laszipVlrData(*info1);
  put<uint16_t>(pointwise, 0, 3);
  Result<LazInfo> mixed = parseLaszipVlr(pointwise);
  ASSERT_FALSE(mixed.ok());
  EXPECT_TRUE(contains(mixed.error().message, "LAZ item type 6 (POINT10) version 2 does not go with compressor 3"));
}

TEST(LazLayered, itemsMustMatchFormats6To8) {
  Result<LazInfo> info7 = lazInfoForFormat(7, 36);
  ASSERT_TRUE(info7.ok());
  EXPECT_TRUE(checkLazItems(*info7, 7, 36).ok());
  Status as8 = checkLazItems(*info7, 8, 38);
  ASSERT_FALSE(as8.ok());
  EXPECT_TRUE(contains(as8.error().message, "the laszip VLR's items (POINT14, RGB14) do not match point format 8 "
                                            "with 38-byte records (POINT14, RGBNIR14)"));
  Status extra = checkLazItems(*info7, 7, 40);
  ASSERT_FALSE(extra.ok());
  EXPECT_TRUE(contains(extra.error().message, "(POINT14, RGB14, BYTE14(4))"));
  Status waveform = checkLazItems(*info7, 9, 59);
  ASSERT_FALSE(waveform.ok());
  EXPECT_TRUE(
      contains(waveform.error().message, "LAZ point format 9 is not supported (only formats 0 to 3 and 6 to 8"));
}

}  // namespace
}  // namespace dpoint
