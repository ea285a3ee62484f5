// dpoint's LAZ decoder (converters/laz_decode.h): every .laz of the corpus (../shared/corpus/laz,
// laz-perf's test files: point formats 0–3, extra bytes, LAS 1.0–1.4, LASzip 2.2 to 3.4) against
// its uncompressed .las twin byte for byte; the result independent of the thread count; and
// broken files (truncated, a chunk table past the end, corrupt chunks, bad laszip VLRs), each an
// error that says why, never a crash.
#include "converters/laz_decode.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "converters/las.h"
#include "converters/point_io.h"
#include "las_bytes.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::at;
using test::contains;
using test::lasRecords;
using test::put;
using test::readFile;

const std::string kLaz = std::string(DPOINT_CORPUS_DIR) + "/laz/";

Result<std::string> decodeBytes(const std::string& bytes, unsigned threads = 1) {
  return decodeLaz(InputFile::fromMemory("broken.laz", bytes), threads);
}

// Where a LAZ file's pieces lie: the laszip VLR's data, the i64 before the chunks, the table.
struct Layout {
  size_t laszip_vlr = 0;  // offset of the VLR's data
  size_t point_offset = 0;
  size_t table = 0;
};
Layout layoutOf(const std::string& file) {
  Layout l;
  size_t p = at<uint16_t>(file, 94);
  for (uint32_t i = 0; i < at<uint32_t>(file, 100); ++i) {
    if (std::strncmp(file.data() + p + 2, "laszip encoded", 16) == 0) l.laszip_vlr = p + 54;
    p += 54 + at<uint16_t>(file, p + 20);
  }
  l.point_offset = at<uint32_t>(file, 96);
  l.table = static_cast<size_t>(at<int64_t>(file, l.point_offset));
  return l;
}

// --- The corpus --------------------------------------------------------------------------------------

TEST(LazDecode, corpusFilesMatchTheirLasTwinsByteForByte) {
  int compared = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kLaz)) {
    if (entry.path().extension() != ".laz") continue;
    const std::string laz = entry.path();
    if (entry.path().filename() == "point-time-1.4.las.laz") continue;  // no twin: the next test
    // "x.las.laz" and "x.laz" are both twins of "x.las".
    std::string twin = entry.path().stem();
    if (std::filesystem::path(twin).extension() != ".las") twin += ".las";
    SCOPED_TRACE(laz);
    ASSERT_TRUE(test::fileExists(kLaz + twin)) << "no twin " << twin;
    Result<std::string> records = decodeLazFile(laz);
    ASSERT_TRUE(records.ok()) << records.error().message;
    const std::string expected = lasRecords(readFile(kLaz + twin));
    EXPECT_EQ(records->size(), expected.size());
    EXPECT_TRUE(*records == expected) << "records differ";
    ++compared;
  }
  EXPECT_EQ(compared, 10);  // the README's pairs
}

TEST(LazDecode, las14FileDecodesItsHeadersCount) {
  const std::string laz = readFile(kLaz + "point-time-1.4.las.laz");
  ASSERT_EQ(laz[25], 4);
  const uint64_t count = at<uint64_t>(laz, 247);
  ASSERT_EQ(count, 1065u);
  Result<std::string> records = decodeLazFile(kLaz + "point-time-1.4.las.laz");
  ASSERT_TRUE(records.ok()) << records.error().message;
  ASSERT_EQ(records->size(), count * 28);
  // Its first point's integers x, y, z are point-time.las's (the same survey, same scales).
  const std::string twin = lasRecords(readFile(kLaz + "point-time.las"));
  EXPECT_EQ(records->substr(0, 12), twin.substr(0, 12));
}

TEST(LazDecode, fileWithoutPointsDecodesToNothing) {
  Result<std::string> records = decodeLazFile(kLaz + "no-points-1.3.laz");
  ASSERT_TRUE(records.ok()) << records.error().message;
  EXPECT_TRUE(records->empty());
}

TEST(LazDecode, resultDoesNotDependOnThreadCount) {
  // autzen_trim.laz: 110,000 points in three chunks (50,000, 50,000, 10,000).
  Result<std::string> one = decodeLazFile(kLaz + "autzen_trim.laz", 1);
  ASSERT_TRUE(one.ok()) << one.error().message;
  for (unsigned threads : {2u, 3u, 8u}) {
    Result<std::string> many = decodeLazFile(kLaz + "autzen_trim.laz", threads);
    ASSERT_TRUE(many.ok()) << many.error().message;
    EXPECT_TRUE(*many == *one) << threads << " threads";
  }
}

TEST(LazDecode, parsesTheLaszipVlr) {
  const std::string file = readFile(kLaz + "extrabytes.laz");
  const Layout l = layoutOf(file);
  Result<LazInfo> info = parseLaszipVlr(std::string_view(file).substr(l.laszip_vlr, 34 + 4 * 6));
  ASSERT_TRUE(info.ok()) << info.error().message;
  EXPECT_EQ(info->compressor, 2);
  EXPECT_EQ(info->coder, 0);
  EXPECT_EQ(info->major, 2);
  EXPECT_EQ(info->minor, 2);
  EXPECT_EQ(info->chunk_size, 50000u);
  ASSERT_EQ(info->items.size(), 4u);
  EXPECT_EQ(info->items[3].type, kLazByte);
  EXPECT_EQ(info->items[3].size, 27);
  EXPECT_EQ(info->recordLength(), 61u);
  EXPECT_TRUE(checkLazItems(*info, 3, 61).ok());
  Status wrong = checkLazItems(*info, 1, 61);
  ASSERT_FALSE(wrong.ok());
  EXPECT_TRUE(contains(wrong.error().message, "(POINT10, GPSTIME11, RGB12, BYTE(27)) do not match point format 1"));
}

TEST(LazDecode, readsTheChunkTable) {
  Result<InputFile> file = InputFile::open(kLaz + "autzen_trim.laz");
  ASSERT_TRUE(file.ok());
  const std::string bytes = readFile(kLaz + "autzen_trim.laz");
  const Layout l = layoutOf(bytes);
  Result<LazInfo> info = parseLaszipVlr(std::string_view(bytes).substr(l.laszip_vlr, 34 + 3 * 6));
  ASSERT_TRUE(info.ok());
  Result<std::vector<LazChunk>> chunks = readLazChunkTable(*file, l.point_offset, *info, 110000);
  ASSERT_TRUE(chunks.ok()) << chunks.error().message;
  ASSERT_EQ(chunks->size(), 3u);
  EXPECT_EQ((*chunks)[0].offset, l.point_offset + 8);
  EXPECT_EQ((*chunks)[0].points, 50000u);
  EXPECT_EQ((*chunks)[2].points, 10000u);
  EXPECT_EQ((*chunks)[2].offset + (*chunks)[2].bytes, l.table);  // back to back up to the table
}

TEST(LazDecode, findsChunkTableOffsetAtTheFileEnd) {
  // A writer that cannot seek back stores −1 before the chunks and the table's offset in the last
  // 8 bytes.
  std::string file = readFile(kLaz + "point-time.las.laz");
  const Layout l = layoutOf(file);
  put<int64_t>(file, l.point_offset, -1);
  file.append(8, '\0');
  put<int64_t>(file, file.size() - 8, static_cast<int64_t>(l.table));
  Result<std::string> records = decodeBytes(file, 2);
  ASSERT_TRUE(records.ok()) << records.error().message;
  EXPECT_TRUE(*records == lasRecords(readFile(kLaz + "point-time.las")));
}

// --- Broken files ------------------------------------------------------------------------------------

TEST(LazDecode, rejectsTruncatedFile) {
  const std::string file = readFile(kLaz + "point-color-time.las.laz");
  Result<std::string> half = decodeBytes(file.substr(0, file.size() / 2));
  ASSERT_FALSE(half.ok());
  EXPECT_TRUE(contains(half.error().message, "broken.laz: truncated: the chunk table's offset 18512 is past the end"));
  // Every cut gives an error (the last bytes after the table are not needed), never a crash.
  const size_t table = layoutOf(file).table;
  for (size_t size = 0; size < table; size += 37) {
    const std::string cut = file.substr(0, size);
    EXPECT_FALSE(decodeBytes(cut).ok()) << size << " bytes";
  }
}

TEST(LazDecode, rejectsChunkTableOffsetPastTheEnd) {
  std::string file = readFile(kLaz + "point-time.las.laz");
  const Layout l = layoutOf(file);
  put<int64_t>(file, l.point_offset, static_cast<int64_t>(file.size()) + 100);
  Result<std::string> records = decodeBytes(file);
  ASSERT_FALSE(records.ok());
  EXPECT_TRUE(
      contains(records.error().message, "the chunk table's offset 15733 is past the end of the 15633-byte file"));
  put<int64_t>(file, l.point_offset, 10);
  records = decodeBytes(file);
  ASSERT_FALSE(records.ok());
  EXPECT_TRUE(contains(records.error().message, "the chunk table's offset 10 lies before the chunks' start"));
  put<int64_t>(file, l.point_offset, static_cast<int64_t>(l.point_offset));
  records = decodeBytes(file);
  ASSERT_FALSE(records.ok());
  EXPECT_TRUE(contains(records.error().message, "the chunk table is missing"));
}

TEST(LazDecode, rejectsChunkTableThatDisagreesWithTheHeader) {
  std::string file = readFile(kLaz + "autzen_trim.laz");
  const Layout l = layoutOf(file);
  put<uint32_t>(file, l.table + 4, 2);  // three chunks of 50,000 hold 110,000 points
  Result<std::string> records = decodeBytes(file);
  ASSERT_FALSE(records.ok());
  EXPECT_TRUE(contains(records.error().message,
                       "lists 2 chunks, but 110000 points in chunks of 50000 need 3"));
  put<uint32_t>(file, l.table + 4, 3);
  put<uint32_t>(file, l.table, 1);
  records = decodeBytes(file);
  ASSERT_FALSE(records.ok());
  EXPECT_TRUE(contains(records.error().message, ": version 1 is not 0"));
  put<uint32_t>(file, l.table, 0);
  file[l.table + 9] ^= 0x40;  // a byte of the coded entries (here it changes chunk 2's byte count)
  records = decodeBytes(file);
  ASSERT_FALSE(records.ok());
  EXPECT_TRUE(contains(records.error().message, "broken.laz: the chunk table gives chunk 2 4077841170 bytes from byte "
                                                "602998, past the chunk table at byte 603333"));
}

TEST(LazDecode, rejectsCorruptChunk) {
  std::string file = readFile(kLaz + "point-color-time.las.laz");
  const Layout l = layoutOf(file);
  file[l.point_offset + 8 + 40] ^= 0x5A;  // a byte of the arithmetic code, past the raw first point
  Result<std::string> records = decodeBytes(file);
  ASSERT_FALSE(records.ok());
  EXPECT_TRUE(contains(records.error().message,
                       "broken.laz: chunk 0 of 1 (17191 bytes at byte 1321, points 0 to 1064): point "));
  // This flip makes the GPS time switch sequence twice in point 3, which no encoder writes.
  EXPECT_TRUE(contains(records.error().message, "point 3 of 1065: the GPS time switches time sequence twice"));
}

TEST(LazDecode, gpsTimeSwitchingOnAndOnIsCorruptNotALongLoop) {
  // Every byte of a chunk's code after its raw first point set to each value in turn: whatever it
  // decodes to, the decode ends (an error or points), and never hangs on sequence switches.
  const std::string base = readFile(kLaz + "point-time.las.laz");
  const Layout l = layoutOf(base);
  size_t corrupt = 0;
  for (size_t at = 0; at < 64; ++at)
    for (int value : {0x00, 0xFF, 0x80, 0x7F}) {
      std::string file = base;
      file[l.point_offset + 8 + 28 + at] = static_cast<char>(value);
      Result<std::string> records = decodeBytes(file);
      if (!records.ok()) ++corrupt;
    }
  EXPECT_GT(corrupt, 0u);
}

TEST(LazDecode, reportsTheFirstCorruptChunkWhateverTheThreads) {
  std::string file = readFile(kLaz + "autzen_trim.laz");
  Result<InputFile> open = InputFile::open(kLaz + "autzen_trim.laz");
  ASSERT_TRUE(open.ok());
  const Layout l = layoutOf(file);
  Result<LazInfo> info = parseLaszipVlr(std::string_view(file).substr(l.laszip_vlr, 34 + 3 * 6));
  ASSERT_TRUE(info.ok());
  Result<std::vector<LazChunk>> chunks = readLazChunkTable(*open, l.point_offset, *info, 110000);
  ASSERT_TRUE(chunks.ok());
  for (size_t c : {1u, 2u}) file[(*chunks)[c].offset + 100] ^= 0x33;  // chunks 1 and 2
  for (unsigned threads : {1u, 2u, 3u}) {
    Result<std::string> records = decodeBytes(file, threads);
    ASSERT_FALSE(records.ok());
    EXPECT_TRUE(contains(records.error().message, "chunk 1 of 3")) << threads << " threads";
  }
}

TEST(LazDecode, randomCorruptionIsAnErrorOrWrongPointsNeverACrash) {
  // LAZ has no checksum, so a flipped byte may decode to other points; it must never read out of
  // bounds, hang or crash (run under DPOINT_SANITIZE for the full check).
  const std::string file = readFile(kLaz + "extrabytes.laz");
  std::mt19937 random(7);
  int errors = 0;
  for (int i = 0; i < 200; ++i) {
    std::string broken = file;
    broken[random() % broken.size()] ^= static_cast<char>(1 + random() % 255);
    if (!decodeBytes(broken).ok()) ++errors;
  }
  EXPECT_GT(errors, 0);
}

TEST(LazDecode, decodeChunkRejectsShortAndOverlongData) {
  const std::string file = readFile(kLaz + "point10.las.laz");
  const Layout l = layoutOf(file);
  Result<LazInfo> info = parseLaszipVlr(std::string_view(file).substr(l.laszip_vlr, 34 + 6));
  ASSERT_TRUE(info.ok());
  const std::string chunk = file.substr(l.point_offset + 8, l.table - l.point_offset - 8);
  std::string records(1065 * 20, '\0');
  EXPECT_TRUE(decodeLazChunk(*info, chunk.data(), chunk.size(), 1065, records.data()).ok());
  Status short_data = decodeLazChunk(*info, chunk.data(), chunk.size() - 100, 1065, records.data());
  ASSERT_FALSE(short_data.ok());
  EXPECT_TRUE(contains(short_data.error().message, "the compressed data ends early"));
  Status too_few = decodeLazChunk(*info, chunk.data(), 12, 1065, records.data());
  ASSERT_FALSE(too_few.ok());
  EXPECT_TRUE(contains(too_few.error().message, "the chunk's 12 bytes are fewer than its first point's 20 raw bytes"));
  // Fewer points than the chunk holds leave its last bytes unread.
  Status left_over = decodeLazChunk(*info, chunk.data(), chunk.size(), 1000, records.data());
  ASSERT_FALSE(left_over.ok());
  EXPECT_TRUE(contains(left_over.error().message, "bytes are left over after its 1000 points"));
}

TEST(LazDecode, rejectsBadLaszipVlr) {
  const std::string original = readFile(kLaz + "point-time.las.laz");
  const Layout l = layoutOf(original);
  const auto decodeWith = [&](auto change) {
    std::string file = original;
    change(file);
    Result<std::string> records = decodeBytes(file);
    return records.ok() ? std::string("decoded") : records.error().message;
  };
  EXPECT_TRUE(contains(decodeWith([&](std::string& f) { put<uint16_t>(f, l.laszip_vlr, 3); }),
                       "broken.laz: laszip VLR: LAZ item type 6 (POINT10) version 2 does not go with compressor 3"));
  EXPECT_TRUE(contains(decodeWith([&](std::string& f) { put<uint16_t>(f, l.laszip_vlr, 4); }),
                       "broken.laz: laszip VLR: compressor 4 is not one of LASzip's (1 to 3)"));
  EXPECT_TRUE(contains(decodeWith([&](std::string& f) { put<uint16_t>(f, l.laszip_vlr + 2, 1); }),
                       "LAZ coder 1 is not supported"));
  // The first item: type 6 (POINT10), size 20, version 2.
  EXPECT_TRUE(contains(decodeWith([&](std::string& f) { put<uint16_t>(f, l.laszip_vlr + 34 + 4, 4); }),
                       "LAZ item type 6 (POINT10) version 4 is not supported (only versions 1 and 2 of POINT10, "
                       "GPSTIME11, RGB12 and BYTE: point formats 0 to 3, and version 3 of POINT14"));
  EXPECT_TRUE(contains(decodeWith([&](std::string& f) {
                         put<uint16_t>(f, l.laszip_vlr + 34, 9);
                         put<uint16_t>(f, l.laszip_vlr + 34 + 4, 3);
                       }),
                       "LAZ item type 9 (WAVEPACKET13) version 3 is not supported"));
  EXPECT_TRUE(contains(decodeWith([&](std::string& f) { put<uint16_t>(f, l.laszip_vlr + 34 + 2, 21); }),
                       "laszip VLR: LAZ item type 6 (POINT10) has size 21, not 20"));
  EXPECT_TRUE(contains(decodeWith([&](std::string& f) { put<uint16_t>(f, l.laszip_vlr + 32, 500); }),
                       "laszip VLR: 46 bytes, fewer than the 3034 that its 500 items need"));
  EXPECT_TRUE(contains(decodeWith([&](std::string& f) { f[l.laszip_vlr - 54 + 2] = 'X'; }),
                       "broken.laz: no laszip VLR (user ID 'laszip encoded', record 22204) among its 5 VLRs"));
  EXPECT_TRUE(contains(decodeWith([&](std::string& f) { f[104] = static_cast<char>(0x80 | 0); }),
                       "the laszip VLR's items (POINT10, GPSTIME11) do not match point format 0 with 28-byte records "
                       "(POINT10, BYTE(8))"));
  EXPECT_TRUE(contains(decodeWith([&](std::string& f) { f[104] = static_cast<char>(0x80 | 9); }),
                       "LAZ point format 9 is not supported (only formats 0 to 3 and 6 to 8"));
  EXPECT_FALSE(parseLaszipVlr(std::string_view(original).substr(l.laszip_vlr, 20)).ok());
}

TEST(LazDecode, rejectsUncompressedLas) {
  Result<std::string> records = decodeLazFile(kLaz + "point10.las");
  ASSERT_FALSE(records.ok());
  EXPECT_TRUE(contains(records.error().message,
                       "point10.las: not compressed: point data format 0 has neither bit 7 nor bit 6"));
}

TEST(LazDecode, refusesRecordsBeyondTheMemoryLimit) {
  Result<std::string> records = decodeLazFile(kLaz + "autzen_trim.laz", 1, 1000000);
  ASSERT_FALSE(records.ok());
  EXPECT_EQ(records.error().code, ExitCode::kResourceLimit);
  EXPECT_TRUE(contains(records.error().message, "decoding 110000 points needs about"));
}

}  // namespace
}  // namespace dpoint

namespace dpoint {
namespace {

// LAZ through the LAS reader (readLas, readPoints, convert): each corpus .laz reads as the same
// point set as its twin, and written as LAS gives the twin's point records byte for byte.
TEST(LazRead, everyCorpusLazReadsAsItsTwinAndWritesItsRecords) {
  const std::string dir = std::string(DPOINT_CORPUS_DIR) + "/laz/";
  test::TempDir out;
  size_t pairs = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".laz" || entry.path().filename() == "point-time-1.4.las.laz") continue;
    std::string twin = entry.path().stem();
    if (std::filesystem::path(twin).extension() != ".las") twin += ".las";
    SCOPED_TRACE(entry.path().filename().string());
    Result<PointSet> laz = readPoints(entry.path().string()), las = readPoints(dir + twin);
    ASSERT_TRUE(laz) << laz.error().message;
    ASSERT_TRUE(las) << las.error().message;
    EXPECT_EQ(laz->positions, las->positions);
    EXPECT_EQ(laz->colors, las->colors);
    ASSERT_EQ(laz->dimensions.count(), las->dimensions.count());
    for (size_t k = 0; k < las->dimensions.count(); ++k)
      EXPECT_TRUE(laz->dimensions.all()[k].bytes == las->dimensions.all()[k].bytes) << las->dimensions.all()[k].name;
    ASSERT_TRUE(writeLas(out.file("back.las"), *laz));
    EXPECT_TRUE(lasRecords(test::readFile(out.file("back.las"))) == lasRecords(test::readFile(dir + twin)));
    ++pairs;
  }
  EXPECT_EQ(pairs, 10u);
}

TEST(LazRead, aBrokenLazIsOneErrorNamingTheFile) {
  test::TempDir dir;
  const std::string bytes = test::readFile(std::string(DPOINT_CORPUS_DIR) + "/laz/autzen_trim.laz");
  test::writeFile(dir.file("cut.laz"), bytes.substr(0, bytes.size() / 2));
  Result<PointSet> cut = readPoints(dir.file("cut.laz"));
  ASSERT_FALSE(cut);
  EXPECT_EQ(cut.error().code, ExitCode::kBadInput);
  EXPECT_TRUE(test::contains(cut.error().message, dir.file("cut.laz"))) << cut.error().message;
}

}  // namespace
}  // namespace dpoint
