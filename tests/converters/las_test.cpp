// LAS reading and writing (issue #13): the corpus (../shared/corpus/las, laspy's test files: LAS
// 1.1–1.4, formats 1, 3, 4, 6, 7, extra bytes, EVLRs, 64-bit counts; a 1.0 file made from one),
// files built here byte by byte from the spec's tables (independently of converters/las.cpp's),
// malformed headers, round trips, and loaders.gl (npm, tests/external/node/read_las.mjs) as the
// independent reader.
#include "converters/las.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "converters/csv.h"
#include "converters/ply.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::contains;
using test::readFile;
using test::TempDir;
using test::writeFile;

const std::string kCorpus = std::string(DPOINT_CORPUS_DIR) + "/las/";

// --- Files built byte by byte (LAS 1.4 R15 tables 3, 7–17) ---------------------------------------

struct Record {
  int32_t x = 0, y = 0, z = 0;
  uint16_t intensity = 0;
  uint8_t classification = 0;  // for formats 0–5 the caller may set the flag bits 5–7 too
  uint16_t red = 0, green = 0, blue = 0;
};

struct LasSpec {
  int minor = 2;
  int format = 0;
  uint32_t record_length = 0;  // 0: the format's base size
  double scale[3] = {0.01, 0.01, 0.01};
  double offset[3] = {0, 0, 0};
  int64_t legacy_count = -1;  // -1: the number of records (0 for formats 6–10 in a 1.4 file)
  int64_t count64 = -1;       // 1.4 only; -1: the number of records
  std::vector<Record> records;
};

template <typename T>
void put(std::string& s, size_t at, T v) {
  std::memcpy(s.data() + at, &v, sizeof v);
}

std::string makeLas(const LasSpec& spec) {
  const uint32_t base[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
  const uint32_t rgb_at[11] = {0, 0, 20, 28, 0, 28, 0, 30, 30, 0, 30};
  const uint32_t header_size = spec.minor >= 4 ? 375 : spec.minor == 3 ? 235 : 227;
  const uint32_t length = spec.record_length ? spec.record_length : base[spec.format];
  const uint64_t n = spec.records.size();
  std::string s(header_size, '\0');
  std::memcpy(s.data(), "LASF", 4);
  s[24] = 1;
  s[25] = static_cast<char>(spec.minor);
  put<uint16_t>(s, 94, static_cast<uint16_t>(header_size));
  put<uint32_t>(s, 96, header_size);
  s[104] = static_cast<char>(spec.format);
  put<uint16_t>(s, 105, static_cast<uint16_t>(length));
  const int64_t records = static_cast<int64_t>(n);
  const int64_t legacy =
      spec.legacy_count >= 0 ? spec.legacy_count : (spec.minor >= 4 && spec.format >= 6 ? 0 : records);
  put<uint32_t>(s, 107, static_cast<uint32_t>(legacy));
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  for (size_t i = 0; i < n; ++i) {
    const int32_t v[3] = {spec.records[i].x, spec.records[i].y, spec.records[i].z};
    for (int k = 0; k < 3; ++k) {
      const double c = v[k] * spec.scale[k] + spec.offset[k];
      lo[k] = i == 0 ? c : std::min(lo[k], c);
      hi[k] = i == 0 ? c : std::max(hi[k], c);
    }
  }
  for (int k = 0; k < 3; ++k) {
    put<double>(s, 131 + 8 * k, spec.scale[k]);
    put<double>(s, 155 + 8 * k, spec.offset[k]);
    put<double>(s, 179 + 16 * k, hi[k]);
    put<double>(s, 187 + 16 * k, lo[k]);
  }
  if (spec.minor >= 4) put<uint64_t>(s, 247, static_cast<uint64_t>(spec.count64 >= 0 ? spec.count64 : records));
  for (const Record& r : spec.records) {
    std::string rec(length, '\0');
    put<int32_t>(rec, 0, r.x);
    put<int32_t>(rec, 4, r.y);
    put<int32_t>(rec, 8, r.z);
    put<uint16_t>(rec, 12, r.intensity);
    rec[spec.format >= 6 ? 16 : 15] = static_cast<char>(r.classification);
    if (rgb_at[spec.format]) {
      put<uint16_t>(rec, rgb_at[spec.format], r.red);
      put<uint16_t>(rec, rgb_at[spec.format] + 2, r.green);
      put<uint16_t>(rec, rgb_at[spec.format] + 4, r.blue);
    }
    for (size_t b = base[spec.format]; b < length; ++b) rec[b] = static_cast<char>(0xA5);  // extra bytes
    s += rec;
  }
  return s;
}

LasSpec threePoints(int minor, int format) {
  LasSpec spec;
  spec.minor = minor;
  spec.format = format;
  spec.scale[0] = 0.001;
  spec.offset[0] = 637000;
  spec.offset[1] = 5800000;
  // x, y, z, intensity, classification, red, green, blue
  spec.records = {{12345, -2, 40000, 100, 2, 1, 2, 3},
                  {0, 0, 0, 7, 5, 255, 0, 9},
                  {-7, 2147483647, -2147483647, 0, 9, 0, 200, 0}};
  return spec;
}

Result<PointSet> readBytes(const std::string& bytes, const LasReadOptions& options = {}) {
  TempDir dir;
  writeFile(dir.file("t.las"), bytes);
  return readLas(dir.file("t.las"), options);
}

std::string readError(const std::string& bytes) {
  Result<PointSet> r = readBytes(bytes);
  EXPECT_FALSE(r.ok());
  return r.ok() ? std::string() : r.error().message;
}

// --- The corpus ----------------------------------------------------------------------------------

struct CorpusFile {
  const char* name;
  int minor, format;
  uint32_t record_length;
  uint64_t count;
  bool rgb;
};
const CorpusFile kCorpusFiles[] = {
    {"autzen.las", 2, 1, 28, 106, false},
    {"simple.las", 2, 3, 34, 1065, true},
    {"simple1_1.las", 1, 1, 28, 1065, false},
    {"simple1_3.las", 3, 4, 57, 999, false},            // waveform packets after the points
    {"simple1_4.las", 4, 7, 36, 22600, true},           // an EVLR after the points
    {"extrabytes.las", 4, 3, 61, 1065, true},           // 27 extra bytes per record
    {"1_4_w_evlr.las", 4, 6, 30, 1000, false},          // legacy count 0, an EVLR
    {"test1_4.las", 4, 6, 30, 1000, false},             // legacy count 0
    {"unregistered_extra_bytes.las", 4, 6, 34, 4, false},  // extra bytes without their VLR
};

// The merged-point count of an asked scale, over many chunks and buckets and any thread count,
// against two whole sorts: 300K points on a 0.001 grid with copies, offsets below the scale (which
// merge) and -0 beside 0 (which is the same position).
TEST(Las, mergedPointsAreCountedAsTwoWholeSortsCountThem) {
  TempDir dir;
  PointSet set;
  std::mt19937_64 rng(20261129);
  std::uniform_int_distribution<int> cell(0, 40);
  std::uniform_int_distribution<int> kind(0, 9);
  for (size_t i = 0; i < 300000; ++i) {
    glm::dvec3 p(cell(rng) * 0.001, cell(rng) * 0.001 + 100.0, cell(rng) * 0.001 - 5.0);
    const int k = kind(rng);
    if (k == 0) p.x += 0.0001 * (1 + kind(rng));  // another position on the same integers
    if (k == 1 && p.x == 0.0) p.x = -0.0;
    set.positions.push_back(p);
  }
  std::vector<std::array<double, 3>> exact;
  std::vector<std::array<int64_t, 3>> stored;
  for (const glm::dvec3& p : set.positions) {
    exact.push_back({p.x, p.y, p.z});
    stored.push_back({static_cast<int64_t>(std::round(p.x / 0.001)), static_cast<int64_t>(std::round((p.y - 100.0) / 0.001)),
                      static_cast<int64_t>(std::round((p.z + 5.0) / 0.001))});
  }
  std::sort(exact.begin(), exact.end());
  std::sort(stored.begin(), stored.end());
  const auto distinct_exact = std::unique(exact.begin(), exact.end()) - exact.begin();
  const auto distinct_stored = std::unique(stored.begin(), stored.end()) - stored.begin();
  const uint64_t expected = static_cast<uint64_t>(distinct_exact - distinct_stored);
  ASSERT_GT(expected, 1000u);
  for (unsigned threads : {1u, 2u, 4u}) {
    LasWriteReport report;
    LasWriteOptions options;
    options.scale = 0.001;
    options.threads = threads;
    options.report = &report;
    ASSERT_TRUE(writeLas(dir.file("m.las"), set, options).ok());
    EXPECT_EQ(report.merged_points, expected) << threads << " threads";
  }
}

// An int64 column (a CSV's integers past 2^53) into LAS's uint64 wave_byte_offset went through a
// double: 9007199254740993 was written as ...992 (a review finding). It is copied as an integer,
// and a negative one does not fit.
TEST(Las, aWholeNumberPast2To53KeepsItsDigitsInA64BitField) {
  TempDir dir;
  PointSet set;
  set.positions = {{0, 0, 0}, {1, 1, 1}};
  Dimension& offset = set.dimensions.add("wave_byte_offset", DimType::kI64, 2);
  offset.set<int64_t>(0, 9007199254740993ll);
  offset.set<int64_t>(1, std::numeric_limits<int64_t>::max());
  ASSERT_TRUE(writeLas(dir.file("w.las"), set).ok());
  Result<PointSet> back = readLas(dir.file("w.las"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  const Dimension* read = back->dimensions.find("wave_byte_offset");
  ASSERT_NE(read, nullptr);
  ASSERT_EQ(read->type, DimType::kU64);
  EXPECT_EQ(read->get<uint64_t>(0), 9007199254740993ull);
  EXPECT_EQ(read->get<uint64_t>(1), static_cast<uint64_t>(std::numeric_limits<int64_t>::max()));
  offset.set<int64_t>(1, -5);
  Status negative = writeLas(dir.file("n.las"), set);
  ASSERT_FALSE(negative.ok());
  EXPECT_TRUE(contains(negative.error().message, "wave_byte_offset = -5 does not fit")) << negative.error().message;
}

TEST(Las, readsEveryCorpusFileWithItsCountAndFormat) {
  for (const CorpusFile& f : kCorpusFiles) {
    SCOPED_TRACE(f.name);
    Result<LasHeader> header = readLasHeader(kCorpus + f.name);
    ASSERT_TRUE(header.ok()) << header.error().message;
    EXPECT_EQ(header->version_minor, f.minor);
    EXPECT_EQ(header->point_format, f.format);
    EXPECT_EQ(header->record_length, f.record_length);
    EXPECT_EQ(header->point_count, f.count);
    Result<PointSet> points = readLas(kCorpus + f.name);
    ASSERT_TRUE(points.ok()) << points.error().message;
    EXPECT_EQ(points->size(), f.count);
    EXPECT_EQ(points->hasColors(), f.rgb);
  }
}

// LAS 1.0 as its writers laid it out (LAS 1.0 spec; libLAS, las-rs): the 1.2 header's fields, bytes
// 4-7 reserved (1.1 put the file source ID there), and the two-byte point data start signature
// 0xCCDD after the VLRs, inside the offset to point data. Made from simple1_1.las (format 1, which
// 1.0 has), it must read as the same points.
TEST(Las, readsLas10FileWithItsPointDataStartSignature) {
  const std::string original = readFile(kCorpus + "simple1_1.las");
  Result<LasHeader> original_header = readLasHeader(kCorpus + "simple1_1.las");
  ASSERT_TRUE(original_header.ok()) << original_header.error().message;
  const uint32_t points_at = original_header->point_offset;
  std::string bytes = original.substr(0, points_at) + "\xDD\xCC" + original.substr(points_at);
  bytes[25] = 0;                       // version 1.0
  put<uint32_t>(bytes, 4, 0);          // reserved
  put<uint32_t>(bytes, 96, points_at + 2);
  TempDir dir;
  writeFile(dir.file("v10.las"), bytes);
  Result<LasHeader> header = readLasHeader(dir.file("v10.las"));
  ASSERT_TRUE(header.ok()) << header.error().message;
  EXPECT_EQ(header->version_minor, 0);
  EXPECT_EQ(header->point_format, 1);
  EXPECT_EQ(header->point_count, 1065u);
  Result<PointSet> points = readLas(dir.file("v10.las"));
  ASSERT_TRUE(points.ok()) << points.error().message;
  Result<PointSet> expected = readLas(kCorpus + "simple1_1.las");
  ASSERT_TRUE(expected.ok()) << expected.error().message;
  EXPECT_EQ(points->positions, expected->positions);
  EXPECT_FALSE(points->hasColors());
}

TEST(Las, computesCoordinatesAsIntegerTimesScalePlusOffset) {
  const LasSpec spec = threePoints(2, 1);
  Result<PointSet> points = readBytes(makeLas(spec));
  ASSERT_TRUE(points.ok()) << points.error().message;
  ASSERT_EQ(points->size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    const Record& r = spec.records[i];
    // Two roundings, as PDAL and laspy do, never fused (the build has -ffp-contract=off).
    const double x = r.x * spec.scale[0], y = r.y * spec.scale[1], z = r.z * spec.scale[2];
    EXPECT_EQ(points->positions[i], glm::dvec3(x + spec.offset[0], y + spec.offset[1], z + spec.offset[2])) << i;
  }
  EXPECT_FALSE(points->hasColors());  // format 1 has no RGB
}

TEST(Las, readsEveryPointFormatWithExtraBytesSkipped) {
  for (int format = 0; format <= 10; ++format) {
    for (uint32_t extra : {0u, 7u}) {
      SCOPED_TRACE("format " + std::to_string(format) + ", extra " + std::to_string(extra));
      LasSpec spec = threePoints(4, format);
      const uint32_t base[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
      spec.record_length = base[format] + extra;
      Result<PointSet> points = readBytes(makeLas(spec));
      ASSERT_TRUE(points.ok()) << points.error().message;
      ASSERT_EQ(points->size(), 3u);
      EXPECT_EQ(points->positions[1], glm::dvec3(637000, 5800000, 0));
      const bool rgb = format == 2 || format == 3 || format == 5 || format == 7 || format == 8 || format == 10;
      ASSERT_EQ(points->hasColors(), rgb);
      // Every channel <= 255: 8-bit values in the 16-bit fields.
      if (rgb) {
        EXPECT_EQ(points->colors[2], glm::vec3(0.0f, 200.0f / 255.0f, 0.0f));
      }
    }
  }
}

TEST(Las, uses64BitCountOfA14Header) {
  LasSpec spec = threePoints(4, 6);
  spec.legacy_count = 0;
  Result<PointSet> points = readBytes(makeLas(spec));
  ASSERT_TRUE(points.ok()) << points.error().message;
  EXPECT_EQ(points->size(), 3u);
  // A 1.4 file of a legacy format whose writer filled only the legacy field.
  spec = threePoints(4, 1);
  spec.count64 = 0;
  points = readBytes(makeLas(spec));
  ASSERT_TRUE(points.ok()) << points.error().message;
  EXPECT_EQ(points->size(), 3u);
}

TEST(Las, emptyFileOfZeroPointsReadsAsEmptySet) {
  LasSpec spec = threePoints(2, 3);
  spec.records.clear();
  Result<PointSet> points = readBytes(makeLas(spec));
  ASSERT_TRUE(points.ok()) << points.error().message;
  EXPECT_EQ(points->size(), 0u);
}

// --- Malformed input -----------------------------------------------------------------------------

TEST(Las, rejectsEmptyFileAndBadSignature) {
  EXPECT_TRUE(contains(readError(""), "empty file, not a LAS file"));
  std::string bytes = makeLas(threePoints(2, 0));
  bytes[3] = 'X';
  EXPECT_TRUE(contains(readError(bytes), "t.las: not a LAS file (it does not start with 'LASF')"));
}

TEST(Las, rejectsTruncatedHeader) {
  const std::string bytes = makeLas(threePoints(2, 0));
  EXPECT_TRUE(contains(readError(bytes.substr(0, 200)),
                       "truncated header: the file has 200 bytes, a LAS header at least 227"));
  const std::string v14 = makeLas(threePoints(4, 6));
  EXPECT_TRUE(contains(readError(v14.substr(0, 300)),
                       "truncated header: the file has 300 bytes, a LAS 1.4 header 375"));
}

TEST(Las, rejectsCountPastFileEndBeforeAllocating) {
  LasSpec spec = threePoints(2, 0);
  spec.legacy_count = 1000;
  EXPECT_TRUE(contains(readError(makeLas(spec)),
                       "truncated: the header declares 1000 points of 20 bytes from byte 227, but only 60 bytes follow "
                       "(room for 3 points)"));
  spec = threePoints(4, 6);
  spec.count64 = int64_t{1} << 62;  // would need 2^62 · 24 bytes of positions
  EXPECT_TRUE(contains(readError(makeLas(spec)), "declares 4611686018427387904 points"));
  std::string cut = makeLas(threePoints(2, 0));
  cut.pop_back();
  EXPECT_TRUE(contains(readError(cut), "room for 2 points"));
}

TEST(Las, rejectsRecordLengthShorterThanTheFormat) {
  LasSpec spec = threePoints(2, 1);
  spec.record_length = 20;
  EXPECT_TRUE(contains(readError(makeLas(spec)),
                       "header: point record length 20 is shorter than point format 1's 28 bytes"));
}

TEST(Las, rejectsZeroOrNonFiniteScaleAndOffset) {
  LasSpec spec = threePoints(2, 0);
  spec.scale[1] = 0;
  EXPECT_TRUE(contains(readError(makeLas(spec)), "header: y scale 0 is not a finite, non-zero number"));
  spec = threePoints(2, 0);
  spec.offset[2] = std::nan("");
  EXPECT_TRUE(contains(readError(makeLas(spec)), "header: z offset nan is not a finite number"));
  spec = threePoints(2, 0);
  spec.scale[0] = 1e300;
  EXPECT_TRUE(contains(readError(makeLas(spec)), "header: x scale 1e+300 and offset 637000 give coordinates beyond"));
}

TEST(Las, rejectsUnknownVersionFormatAndOffset) {
  std::string bytes = makeLas(threePoints(2, 0));
  bytes[25] = 5;
  EXPECT_TRUE(contains(readError(bytes), "header: version 1.5 is not supported (LAS 1.0 to 1.4)"));
  bytes = makeLas(threePoints(2, 0));
  bytes[104] = 11;
  EXPECT_TRUE(contains(readError(bytes), "header: point data format 11 is not one of LAS's formats 0 to 10"));
  bytes = makeLas(threePoints(2, 0));
  put<uint32_t>(bytes, 96, 100);
  EXPECT_TRUE(contains(readError(bytes), "header: offset to point data 100 lies inside the 227-byte header"));
  bytes = makeLas(threePoints(2, 0));
  put<uint16_t>(bytes, 94, 200);
  EXPECT_TRUE(contains(readError(bytes), "header: header size 200 is smaller than LAS 1.2's 227 bytes"));
}

TEST(Las, rejectsLegacyCountThatDisagreesWith64BitCount) {
  LasSpec spec = threePoints(4, 1);
  spec.legacy_count = 2;
  EXPECT_TRUE(contains(readError(makeLas(spec)), "header: legacy point count 2 disagrees with the 64-bit count 3"));
}

TEST(Las, readsLazByItsHeaderBitsEvenNamedLas) {
  Result<PointSet> laz = readBytes(readFile(kCorpus + "simple.laz"));
  ASSERT_TRUE(laz.ok()) << laz.error().message;
  Result<PointSet> las = readLas(kCorpus + "simple.las");
  ASSERT_TRUE(las.ok());
  EXPECT_EQ(laz->positions, las->positions);
  EXPECT_EQ(laz->colors, las->colors);
}

TEST(Las, corruptedHeadersAreRefusedOrReadNeverCrash) {
  // Random bytes over the header and the first record of a valid 1.4 file (seeded, so every run
  // tries the same 3000 files); under DPOINT_SANITIZE any read out of bounds would show.
  const std::string valid = makeLas(threePoints(4, 7));
  std::mt19937_64 random(1);
  size_t refused = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::string bytes = valid;
    for (int flips = 1 + static_cast<int>(random() % 4); flips > 0; --flips)
      bytes[random() % (375 + 36)] = static_cast<char>(random());
    Result<PointSet> r = readBytes(bytes);
    if (!r.ok()) {
      ++refused;
      EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
    } else {
      EXPECT_LE(r->size(), (bytes.size() - 375) / 20);  // never more records than the bytes hold
    }
  }
  EXPECT_GT(refused, 0u);
}

// --- Colours -------------------------------------------------------------------------------------

TEST(Las, colourValuesUpTo255AreEightBitElseSixteen) {
  // simple.las stores 8-bit values in its 16-bit fields (the first point: 68, 77, 88).
  Result<PointSet> simple = readLas(kCorpus + "simple.las");
  ASSERT_TRUE(simple.ok()) << simple.error().message;
  EXPECT_EQ(simple->colors[0], glm::vec3(68.0f / 255.0f, 77.0f / 255.0f, 88.0f / 255.0f));
  // One channel of one point above 255 makes the whole file 16-bit.
  LasSpec spec = threePoints(2, 2);
  spec.records[1].blue = 256;
  Result<PointSet> wide = readBytes(makeLas(spec));
  ASSERT_TRUE(wide.ok()) << wide.error().message;
  EXPECT_EQ(wide->colors[0], glm::vec3(1.0f / 65535.0f, 2.0f / 65535.0f, 3.0f / 65535.0f));
  EXPECT_EQ(wide->colors[1].z, 256.0f / 65535.0f);
}

TEST(Las, intensityIsGreyOverTheFileMaximum) {
  LasReadOptions options;
  options.color = LasColorSource::kIntensity;
  Result<PointSet> points = readBytes(makeLas(threePoints(2, 0)), options);  // intensities 100, 7, 0
  ASSERT_TRUE(points.ok()) << points.error().message;
  EXPECT_EQ(points->colors, (ColorArray{glm::vec3(1.0f), glm::vec3(7.0f / 100.0f), glm::vec3(0.0f)}));
}

TEST(Las, classificationFollowsThePaletteAndIgnoresFlagBits) {
  LasReadOptions options;
  options.color = LasColorSource::kClassification;
  LasSpec spec = threePoints(2, 1);
  spec.records[0].classification = 2 | 0xE0;  // ground, with the synthetic/key-point/withheld flags
  Result<PointSet> legacy = readBytes(makeLas(spec), options);
  ASSERT_TRUE(legacy.ok()) << legacy.error().message;
  EXPECT_EQ(legacy->colors[0], lasClassColor(2));
  EXPECT_EQ(legacy->colors[1], lasClassColor(5));
  EXPECT_EQ(legacy->colors[2], lasClassColor(9));
  spec = threePoints(4, 6);
  spec.records[0].classification = 200;  // formats 6–10: a whole byte, user-definable above 63
  Result<PointSet> wide = readBytes(makeLas(spec), options);
  ASSERT_TRUE(wide.ok()) << wide.error().message;
  EXPECT_EQ(wide->colors[0], lasClassColor(200));
  // Ground, vegetation, building and water are told apart.
  EXPECT_NE(lasClassColor(2), lasClassColor(5));
  EXPECT_NE(lasClassColor(6), lasClassColor(9));
  EXPECT_GT(lasClassColor(9).z, lasClassColor(9).x);  // water is blue
}

TEST(Las, askingForRgbOfAFormatWithoutIsAnErrorNamingTheFile) {
  LasReadOptions options;
  options.color = LasColorSource::kRgb;
  Result<PointSet> las = readLas(kCorpus + "autzen.las", options);
  ASSERT_FALSE(las.ok());
  EXPECT_EQ(las.error().message,
            kCorpus + "autzen.las: point format 1 has no RGB colours (formats 2, 3, 5, 7, 8 and 10 have)");
  options.color = LasColorSource::kNone;
  Result<PointSet> simple = readLas(kCorpus + "simple.las", options);
  ASSERT_TRUE(simple.ok()) << simple.error().message;
  EXPECT_FALSE(simple->hasColors());
}

// --- Header bounds, threads ----------------------------------------------------------------------

TEST(Las, headerBoundsThatMissThePointsAreReportedNotRefused) {
  for (const char* name : {"simple.las", "simple1_3.las"}) {
    Result<LasHeader> header = readLasHeader(kCorpus + name);
    Result<PointSet> points = readLas(kCorpus + name);
    ASSERT_TRUE(header.ok() && points.ok());
    // simple1_3.las stores its raw integers (x · 1000) as bounds.
    EXPECT_EQ(lasBoundsContain(*header, boundingBox(points->positions)), std::string(name) == "simple.las") << name;
  }
}

TEST(Las, resultDoesNotDependOnThreadCount) {
  LasReadOptions one, three;
  one.threads = 1;
  three.threads = 3;
  Result<PointSet> a = readLas(kCorpus + "simple1_4.las", one), b = readLas(kCorpus + "simple1_4.las", three);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->positions, b->positions);
  EXPECT_EQ(a->colors, b->colors);
}

// --- Writing -------------------------------------------------------------------------------------

TEST(Las, writerStoresFormat0Or2WithWholeNumberOffsetAndExactBounds) {
  TempDir dir;
  PointSet set;
  set.positions = {{637012.241, 5800843.145, 265.125}, {637013.5, 5800842.0, -1.25}};
  ASSERT_TRUE(writeLas(dir.file("a.las"), set).ok());
  Result<LasHeader> plain = readLasHeader(dir.file("a.las"));
  ASSERT_TRUE(plain.ok()) << plain.error().message;
  EXPECT_EQ(plain->version_minor, 2);
  EXPECT_EQ(plain->point_format, 0);
  EXPECT_EQ(plain->record_length, 20u);
  EXPECT_EQ(plain->scale, glm::dvec3(0.001));
  EXPECT_EQ(plain->offset, glm::dvec3(637012, 5800842, -2));
  Result<PointSet> back = readLas(dir.file("a.las"));
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->positions, set.positions);
  const Box box = boundingBox(back->positions);
  EXPECT_EQ(plain->min, box.min);  // the header's bounds are the values a reader computes
  EXPECT_EQ(plain->max, box.max);
  set.colors = {{1, 0.5f, 0}, {0.25f, 0.75f, 1}};
  ASSERT_TRUE(writeLas(dir.file("c.las"), set).ok());
  Result<LasHeader> colored = readLasHeader(dir.file("c.las"));
  ASSERT_TRUE(colored.ok());
  EXPECT_EQ(colored->point_format, 2);
  EXPECT_EQ(colored->record_length, 26u);
  EXPECT_EQ(readFile(dir.file("c.las")).size(), 227u + 2 * 26u);
}

TEST(Las, csvToLasToCsvIsExactForDecimalEastingsAndNorthings) {
  // Millimetre eastings and northings over a kilometre tile, as decimals with 3 digits (z = 0).
  TempDir dir;
  std::mt19937_64 random(13);
  std::string csv = "x,y\n";
  const auto mm = [](uint64_t millimetres) {
    char text[40];
    std::snprintf(text, sizeof text, "%llu.%03llu", static_cast<unsigned long long>(millimetres / 1000),
                  static_cast<unsigned long long>(millimetres % 1000));
    return std::string(text);
  };
  for (int i = 0; i < 20000; ++i) {
    const uint64_t x = 637000000 + random() % 1000000, y = 5800000000 + random() % 1000000;
    csv += mm(x) + "," + mm(y) + "\n";
  }
  writeFile(dir.file("in.csv"), csv);
  Result<PointSet> in = readCsv(dir.file("in.csv"));
  ASSERT_TRUE(in.ok()) << in.error().message;
  ASSERT_TRUE(writeLas(dir.file("mid.las"), *in).ok());
  Result<PointSet> mid = readLas(dir.file("mid.las"));
  ASSERT_TRUE(mid.ok()) << mid.error().message;
  EXPECT_EQ(mid->positions, in->positions);
  // A LAS file carries every field of its format (here all 0): only the coordinates are compared.
  mid->dimensions = Dimensions();
  ASSERT_TRUE(writeCsv(dir.file("out.csv"), *mid).ok());
  // LAS has z (issue #24): the CSV written from it keeps its z column, here all 0.
  PointSet in3d = *in;
  in3d.z_axis = ZAxis::kPresent;
  ASSERT_TRUE(writeCsv(dir.file("in_shortest.csv"), in3d).ok());
  EXPECT_TRUE(readFile(dir.file("out.csv")) == readFile(dir.file("in_shortest.csv")));
}

TEST(Las, lasToCsvToLasAtTheSameScaleReadsEveryCoordinateBack) {
  // simple.las has offset 0: its coordinates are X · 0.01 in double, which a whole-number offset
  // would not give back for about one in ten; the writer finds the offset that does.
  Result<PointSet> original = readLas(kCorpus + "simple.las");
  ASSERT_TRUE(original.ok()) << original.error().message;
  TempDir dir;
  LasWriteOptions options;
  options.scale = 0.01;
  ASSERT_TRUE(writeLas(dir.file("copy.las"), *original, options).ok());
  Result<PointSet> copy = readLas(dir.file("copy.las"));
  ASSERT_TRUE(copy.ok()) << copy.error().message;
  EXPECT_EQ(copy->positions, original->positions);
  EXPECT_EQ(copy->colors, original->colors);  // 8-bit values in, c · 257 out, the same floats back
  Result<LasHeader> header = readLasHeader(dir.file("copy.las"));
  ASSERT_TRUE(header.ok());
  EXPECT_EQ(header->offset, glm::dvec3(0.0));
}

TEST(Las, lasToLasKeepsEveryPointAndSixteenBitColour) {
  // simple1_4.las: 16-bit colours, scales 1e-6, 1e-7, 1e-3 and offsets 1, 1, 0 (every y is 1);
  // written back at 1e-6, x keeps its integers and z moves by rounding only.
  TempDir dir;
  Result<PointSet> original = readLas(kCorpus + "simple1_4.las");
  ASSERT_TRUE(original.ok()) << original.error().message;
  LasWriteOptions options;
  options.scale = 1e-6;
  ASSERT_TRUE(writeLas(dir.file("copy.las"), *original, options).ok());
  Result<PointSet> copy = readLas(dir.file("copy.las"));
  ASSERT_TRUE(copy.ok()) << copy.error().message;
  ASSERT_EQ(copy->size(), original->size());
  EXPECT_EQ(copy->colors, original->colors);
  for (size_t i = 0; i < copy->size(); ++i)
    for (int k = 0; k < 3; ++k)
      ASSERT_NEAR(copy->positions[i][k], original->positions[i][k], 1e-9) << "point " << i << " axis " << k;
}

TEST(Las, writerRefusesPointBeyondInt32NamingTheFirst) {
  TempDir dir;
  PointSet set;
  set.positions = {{0, 0, 0}, {1000, 0, 0}, {3000, 0, 0}, {5000, 0, 0}};
  LasWriteOptions options;
  options.scale = 1e-6;  // 2147.48 m at most from the offset: no offset holds 5 km
  Status s = writeLas(dir.file("far.las"), set, options);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code, ExitCode::kBadInput);
  EXPECT_TRUE(contains(s.error().message,
                       "far.las: point 2: x = 3000 is 3e+09 steps of the scale 1e-06 from the offset 0"));
  EXPECT_TRUE(dir.entries().empty());  // nothing half-written
}

TEST(Las, writerRefusesNonFinitePointsAndBadScale) {
  TempDir dir;
  PointSet set;
  set.positions = {{0, 0, 0}, {1, std::nan(""), 0}};
  Status s = writeLas(dir.file("nan.las"), set);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.error().message, "nan.las: point 1 (1, nan, 0) is not finite"));
  set.positions.pop_back();
  LasWriteOptions options;
  options.scale = -1;  // 0 is "automatic" (the source's, else 0.001)
  s = writeLas(dir.file("negative.las"), set, options);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code, ExitCode::kUsage);
  EXPECT_TRUE(contains(s.error().message, "LAS scale -1 is not a finite number > 0"));
  EXPECT_TRUE(dir.entries().empty());
}

// The header's global encoding: point formats 6-10 always say their coordinate system is WKT
// (R15; the build before wrote 0 for a set from CSV, and PDAL reports that as an error), and a
// LAS file's GPS time kind (bit 0: adjusted standard time) survives LAS -> PLY -> LAS (the build
// before lost it, so 1815.las's times read back as seconds of a week). libLAS's WKT record
// (liblas 2112, autzen.las) is kept with the other coordinate system records.
TEST(Las, globalEncodingAndCoordinateSystemRecordsSurvive) {
  TempDir dir;
  PointSet set;
  set.positions = {{1, 2, 3}};
  set.dimensions.add("classification", DimType::kU8, 1).set<uint8_t>(0, 40);  // > 31: format 6
  ASSERT_TRUE(writeLas(dir.file("six.las"), set));
  std::string six = readFile(dir.file("six.las"));
  ASSERT_EQ(static_cast<int>(six[104]), 6);
  EXPECT_EQ(six[6] & 0x10, 0x10);

  const std::string corpus = std::string(DPOINT_CORPUS_DIR);
  Result<PointSet> gps = readLas(corpus + "/laz/1815.las");
  ASSERT_TRUE(gps);
  ASSERT_TRUE(writePly(dir.file("1815.ply"), *gps));
  Result<PointSet> ply = readPly(dir.file("1815.ply"));
  ASSERT_TRUE(ply && ply->las);
  EXPECT_EQ(ply->las->global_encoding, 1);
  ASSERT_TRUE(writeLas(dir.file("back.las"), *ply));
  EXPECT_EQ(readFile(dir.file("back.las"))[6], 1);

  Result<PointSet> autzen = readLas(corpus + "/las/autzen.las");
  ASSERT_TRUE(autzen);
  ASSERT_TRUE(writeLas(dir.file("autzen.las"), *autzen));
  Result<PointSet> again = readLas(dir.file("autzen.las"));
  ASSERT_TRUE(again && again->las);
  bool liblas = false;
  for (const LasVlr& vlr : again->las->vlrs) liblas = liblas || (vlr.user_id == "liblas" && vlr.record_id == 2112);
  EXPECT_TRUE(liblas);
}

TEST(Las, writeReadOfEmptySetGivesEmptySet) {
  TempDir dir;
  ASSERT_TRUE(writeLas(dir.file("empty.las"), PointSet{}).ok());
  Result<PointSet> back = readLas(dir.file("empty.las"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->size(), 0u);
}

// --- loaders.gl, the independent reader ----------------------------------------------------------

struct Reference {
  std::string header;  // "#version=1.4 format=7 count=22600"
  PositionArray positions;
  std::vector<std::array<uint32_t, 3>> colors;  // raw 16-bit values
};

Reference readWithLoadersGl(const std::string& path) {
  const std::string node = "/usr/bin/node";
  const std::string script = std::string(DPOINT_TESTS_DIR) + "/external/node/read_las.mjs";
  EXPECT_TRUE(test::fileExists(node)) << "node is missing (scripts/setup installs it)";
  TempDir dir;
  test::CommandResult r = test::runCommand({node, script, path, "-o", dir.file("ref.csv")});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  Reference ref;
  std::istringstream in(readFile(dir.file("ref.csv")));
  std::string line;
  std::getline(in, ref.header);
  std::getline(in, line);  // column names
  while (std::getline(in, line)) {
    double v[6] = {};
    const char* p = line.data();
    const char* end = line.data() + line.size();
    int k = 0;
    for (; k < 6 && p < end; ++k) {
      auto [next, ec] = std::from_chars(p, end, v[k]);
      EXPECT_EQ(ec, std::errc()) << line;
      p = next + (next < end ? 1 : 0);
    }
    ref.positions.emplace_back(v[0], v[1], v[2]);
    if (k == 6)
      ref.colors.push_back({static_cast<uint32_t>(v[3]), static_cast<uint32_t>(v[4]), static_cast<uint32_t>(v[5])});
  }
  return ref;
}

// Positions within 1e-9 relative (they are in fact expected bit for bit: both compute X·scale +
// offset in double); colours equal to the raw 16-bit values, read as 8-bit when none exceeds 255.
void expectMatches(const PointSet& ours, const Reference& ref, const std::string& name) {
  ASSERT_EQ(ours.size(), ref.positions.size());
  size_t identical = 0;
  double worst = 0;
  for (size_t i = 0; i < ours.size(); ++i) {
    bool same = true;
    for (int k = 0; k < 3; ++k) {
      const double d = std::fabs(ours.positions[i][k] - ref.positions[i][k]);
      worst = std::max(worst, d / std::max(1.0, std::fabs(ref.positions[i][k])));
      ASSERT_LE(d, 1e-9 * std::max(1.0, std::fabs(ref.positions[i][k]))) << name << " point " << i << " axis " << k;
      same = same && ours.positions[i][k] == ref.positions[i][k];
    }
    identical += same;
  }
  ASSERT_EQ(ours.colors.size(), ref.colors.size()) << name;
  uint32_t largest = 0;
  for (const auto& c : ref.colors) largest = std::max({largest, c[0], c[1], c[2]});
  const double divisor = largest > 255 ? 65535.0 : 255.0;
  for (size_t i = 0; i < ours.colors.size(); ++i)
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(std::lround(ours.colors[i][k] * divisor), static_cast<long>(ref.colors[i][k]))
          << name << " point " << i;
  std::printf("%s: %zu points, %s, %zu positions bit-identical, largest relative difference %g\n", name.c_str(),
              ours.size(), ours.colors.empty() ? "no colours" : largest > 255 ? "16-bit colours" : "8-bit colours",
              identical, worst);
}

// Every .las file in the corpus folder (any case), sorted: a file added later is compared too.
std::vector<std::string> corpusLasNames() {
  std::vector<std::string> names;
  for (const std::filesystem::directory_entry& entry : std::filesystem::directory_iterator(kCorpus)) {
    std::string extension = entry.path().extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (entry.is_regular_file() && extension == ".las") names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

TEST(Las, matchesLoadersGlOnEveryCorpusFile) {
  const std::vector<std::string> names = corpusLasNames();
  // A file whose expectations are written down above is still there to be compared.
  for (const CorpusFile& f : kCorpusFiles)
    EXPECT_NE(std::find(names.begin(), names.end(), f.name), names.end()) << f.name << " left the corpus";
  for (const std::string& name : names) {
    SCOPED_TRACE(name);
    const Reference ref = readWithLoadersGl(kCorpus + name);
    Result<LasHeader> header = readLasHeader(kCorpus + name);
    ASSERT_TRUE(header.ok()) << header.error().message;
    // loaders.gl reads the format and count we read, and, where they are written down, the expected ones.
    EXPECT_TRUE(contains(ref.header, "format=" + std::to_string(header->point_format) +
                                         " count=" + std::to_string(header->point_count)));
    for (const CorpusFile& f : kCorpusFiles) {
      if (name != f.name) continue;
      EXPECT_EQ(header->point_format, f.format);
      EXPECT_EQ(header->point_count, f.count);
    }
    Result<PointSet> ours = readLas(kCorpus + name);
    ASSERT_TRUE(ours.ok()) << ours.error().message;
    expectMatches(*ours, ref, name);
  }
}

TEST(Las, lazDecodedByLoadersGlEqualsTheLasItWasMadeFrom) {
  const Reference laz = readWithLoadersGl(kCorpus + "simple.laz");
  EXPECT_TRUE(contains(laz.header, "format=3 count=1065"));
  Result<PointSet> las = readLas(kCorpus + "simple.las");
  ASSERT_TRUE(las.ok()) << las.error().message;
  expectMatches(*las, laz, "simple.laz");
}

}  // namespace
}  // namespace dpoint
