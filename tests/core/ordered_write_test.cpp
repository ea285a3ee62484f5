#include <gtest/gtest.h>

#include <atomic>
#include <string>

#include "core/ordered_write.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::TempDir;

// Chunk k: k % 7 · 1000 bytes (some empty) of the letter 'a' + k % 26, tagged with k.
Status makeChunk(size_t k, std::vector<char>& bytes) {
  bytes.assign((k % 7) * 1000, static_cast<char>('a' + k % 26));
  const std::string tag = std::to_string(k) + ";";
  bytes.insert(bytes.end(), tag.begin(), tag.end());
  return okStatus();
}

std::string expected(size_t chunks) {
  std::string all;
  std::vector<char> bytes;
  for (size_t k = 0; k < chunks; ++k) {
    EXPECT_TRUE(makeChunk(k, bytes).ok());
    all.append(bytes.data(), bytes.size());
  }
  return all;
}

TEST(OrderedWrite, chunksMadeOnManyThreadsLandInOrder) {
  TempDir dir;
  for (unsigned threads : {1u, 3u, 8u}) {
    const std::string path = dir.file("out" + std::to_string(threads));
    Result<AtomicFile> f = AtomicFile::create(path);
    ASSERT_TRUE(f.ok()) << f.error().message;
    size_t next_written = 0;
    bool in_order = true;
    Status s = writeChunksInOrder(*f, 5000, threads, makeChunk, [&](size_t k) { in_order = in_order && k == next_written++; });
    ASSERT_TRUE(s.ok()) << s.error().message;
    ASSERT_TRUE(f->commit().ok());
    EXPECT_TRUE(in_order);
    EXPECT_EQ(next_written, 5000u);
    EXPECT_TRUE(test::readFile(path) == expected(5000)) << threads << " threads";
  }
}

TEST(OrderedWrite, theFirstFailingChunkIsReportedAndNothingAppears) {
  TempDir dir;
  Result<AtomicFile> f = AtomicFile::create(dir.file("out"));
  ASSERT_TRUE(f.ok());
  std::atomic<size_t> made{0};
  Status s = writeChunksInOrder(*f, 100000, 4, [&](size_t k, std::vector<char>& bytes) -> Status {
    ++made;
    if (k == 900 || k == 901 || k == 5000) return Error{"chunk " + std::to_string(k) + " fails"};
    return makeChunk(k, bytes);
  });
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().message, "chunk 900 fails");
  EXPECT_LT(made.load(), size_t{1000});  // the work stopped within a window of the failure
}

}  // namespace
}  // namespace dpoint
