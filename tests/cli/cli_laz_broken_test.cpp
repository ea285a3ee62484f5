// Broken LAZ files through `dpoint convert` as a user meets them (issue #35): a truncated chunk, a
// wrong chunk table, counts that lie, a bad laszip VLR. Each is one line on stderr naming the file
// (and, where a chunk is at fault, the chunk and its byte), exit 2, no crash, and no output file.
// The decoder's own tests (tests/converters/laz_decode_test.cpp) pin the messages in detail; these
// pin what the command does with them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "las_bytes.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::at;
using test::put;
using test::readFile;
using test::runDpoint;
using test::TempDir;
using test::writeFile;

const std::string kLaz = std::string(DPOINT_CORPUS_DIR) + "/laz/";

// Offset of the laszip VLR's data (after its 54-byte VLR header).
size_t laszipVlr(const std::string& file) {
  const size_t data = test::laszipVlrAt(file);
  if (data == 0) ADD_FAILURE() << "no laszip VLR";
  return data;
}

struct Broken {
  std::string name;
  std::function<void(std::string&)> change;
  std::vector<std::string> expected;  // parts of the message after "dpoint: error: PATH: "
};

// Writes each broken variant of `original` into a fresh folder and converts it to CSV.
void expectEachRefused(const std::string& original, const std::vector<Broken>& cases) {
  for (const Broken& c : cases) {
    SCOPED_TRACE(c.name);
    TempDir dir;
    std::string bytes = original;
    c.change(bytes);
    const std::string in = dir.file(c.name + ".laz");
    writeFile(in, bytes);
    const auto before = dir.entries();
    test::CommandResult r = runDpoint({"convert", in, "-o", dir.file("out.csv")});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.rfind("dpoint: error: " + in + ": ", 0), 0u) << r.err;
    for (const std::string& part : c.expected) EXPECT_TRUE(test::contains(r.err, part));
    EXPECT_FALSE(test::fileExists(dir.file("out.csv")));
    EXPECT_EQ(dir.entries(), before) << "something was written";
  }
}

// autzen_trim.laz: LAS 1.2, point format 3, 110,000 points in fixed chunks of 50,000: chunk 0 is
// 283,499 bytes at byte 2152, chunk 1 262,423 at 285,651, chunk 2 55,259 at 548,074, the chunk
// table at 603,333 of the 603,353-byte file.
TEST(CliLazBroken, truncatedChunksAndWrongChunkTablesExitTwoNamingTheChunkAndByte) {
  const std::string autzen = readFile(kLaz + "autzen_trim.laz");
  ASSERT_EQ(autzen.size(), 603353u);
  const size_t pointer = at<uint32_t>(autzen, 96), table = 603333;
  ASSERT_EQ(at<int64_t>(autzen, pointer), static_cast<int64_t>(table));
  // The chunk table re-encoded with chunk 0 1,000 bytes shorter or longer and chunk 1 the opposite
  // (LASzip's integer compressor; fuzz/seeds/laz/make_laz_seeds.py's chunk_table([(0, 282499),
  // (0, 263423), (0, 55259)]) and ([(0, 284499), (0, 261423), (0, 55259)])): every chunk still
  // lies before the table, but chunk 0's code ends early or has bytes left over.
  const std::string shorter("\x00\x00\x00\x00\x03\x00\x00\x00\x97\x91\x8b\x9a\x53\x45\x59\xf8\x74\x00\x00\x00", 20);
  const std::string longer("\x00\x00\x00\x00\x03\x00\x00\x00\x97\x99\x1e\x90\x68\x49\x1a\xdc\x53\x00\x00\x00", 20);
  ASSERT_EQ(autzen.size() - table, shorter.size());
  const auto truncate = [](size_t size) { return [size](std::string& f) { f.resize(size); }; };
  const auto tableAt = [pointer](int64_t offset) { return [=](std::string& f) { put(f, pointer, offset); }; };
  const auto count = [](uint32_t n) { return [n](std::string& f) { put(f, 107, n); }; };
  expectEachRefused(autzen, {
      // The table, which alone says where chunks end, is cut off with the file's end: what is
      // known is where the file ends and where the table should have been.
      {"truncated_in_chunk_1", truncate(285651 + 1000), {"truncated", "603333", "286651-byte file"}},
      {"truncated_before_the_chunk_table", truncate(table), {"truncated", "603333", "603333-byte file"}},
      // The last chunk cut short, the table moved up behind it.
      {"truncated_chunk_2_table_kept",
       [&](std::string& f) {
         f = f.substr(0, 548074 + 30000) + f.substr(table);
         put<int64_t>(f, pointer, 548074 + 30000);
       },
       {"chunk 2", "byte 548074"}},
      {"chunk_table_offset_past_the_end", tableAt(603353 + 100), {"chunk table", "603453", "603353-byte file"}},
      {"chunk_table_offset_before_the_chunks", tableAt(100), {"chunk table", "100", "2152"}},
      {"chunk_table_offset_into_chunk_1", tableAt(285651), {"the chunk table at byte 285651: version", "is not 0"}},
      {"chunk_0_bytes_1000_fewer", [&](std::string& f) { f.replace(table, shorter.size(), shorter); },
       {"chunk 0 of 3 (282499 bytes at byte 2152, points 0 to 49999)", "ends early"}},
      {"chunk_0_bytes_1000_more", [&](std::string& f) { f.replace(table, longer.size(), longer); },
       {"chunk 0 of 3 (284499 bytes at byte 2152, points 0 to 49999)", "left over"}},
      {"chunk_table_lists_4_chunks", [&](std::string& f) { put<uint32_t>(f, table + 4, 4); },
       {"the chunk table at byte 603333 lists 4 chunks", "need 3"}},
      // Counts that lie: one point more than chunk 2 holds, one fewer, a chunk more than the table.
      {"count_one_more", count(110001), {"chunk 2 of 3 (55259 bytes at byte 548074, points 100000 to 110000)"}},
      {"count_one_fewer", count(109999),
       {"chunk 2 of 3 (55259 bytes at byte 548074, points 100000 to 109998)", "left over"}},
      {"count_needs_a_fourth_chunk", count(150001), {"3 chunks", "150001 points", "need 4"}},
      {"count_zero", count(0), {"3 chunks", "0 points"}},
  });
}

// point-time.las.laz: LAS 1.2, point format 1 (POINT10, GPSTIME11), 1,065 points in one chunk of
// 14,272 bytes at byte 1315.
TEST(CliLazBroken, badLaszipVlrAndLyingCountsExitTwoSayingWhy) {
  const std::string small = readFile(kLaz + "point-time.las.laz");
  const size_t vlr = laszipVlr(small);
  ASSERT_EQ(at<uint16_t>(small, vlr + 32), 2u);
  const auto field16 = [vlr](size_t offset, uint16_t v) { return [=](std::string& f) { put(f, vlr + offset, v); }; };
  const auto count = [](uint32_t n) { return [n](std::string& f) { put(f, 107, n); }; };
  expectEachRefused(small, {
      {"items_1_of_2", field16(32, 1), {"laszip VLR's items (POINT10)", "point format 1"}},
      {"items_3_of_2", field16(32, 3), {"laszip VLR", "3 items"}},
      {"compressor_7", field16(0, 7), {"compressor 7"}},
      // Compressor 1 is read (LASzip 1.x), so a chunked file relabelled so is one code that goes wrong.
      {"compressor_1", field16(0, 1), {"compressor 1", "point data"}},
      {"coder_1", field16(2, 1), {"coder 1", "not supported"}},
      {"waveform_item", field16(34 + 6, 9), {"item type 9 (WAVEPACKET13)", "not supported"}},
      {"chunk_size_0", [vlr](std::string& f) { put<uint32_t>(f, vlr + 12, 0); }, {"chunk size 0"}},
      {"no_laszip_vlr", [vlr](std::string& f) { f[vlr - 54 + 2] = 'X'; }, {"no laszip VLR"}},
      {"truncated_in_the_chunk", [](std::string& f) { f.resize(1315 + 7000); }, {"truncated", "8315-byte file"}},
      {"count_one_more", count(1066), {"chunk 0 of 1 (14272 bytes at byte 1315, points 0 to 1065)", "point 1065"}},
      {"count_one_fewer", count(1064), {"chunk 0 of 1 (14272 bytes at byte 1315, points 0 to 1063)", "left over"}},
  });
}

}  // namespace
}  // namespace dpoint
