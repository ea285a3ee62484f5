#include <gtest/gtest.h>
#include <malloc.h>
#include <sys/resource.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/ordered_write.h"
#include "core/parallel.h"
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

// The address space this process maps now, in bytes (/proc/self/statm's first field, in pages).
size_t mappedBytes() {
  unsigned long pages = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%lu", &pages) != 1) pages = 0;
    std::fclose(f);
  }
  return size_t{pages} * 4096;
}

// A review finding: `--threads 200` under `ulimit -v` (or --threads 33000 past the kernel's map
// count) aborted ("terminate called"): a thread the system would not make was an exception nothing
// caught. Under an address-space limit with room for a few 8 MB thread stacks, or none, both pools
// finish their work on the threads they get, with the same results.
TEST(OrderedWrite, andParallelForFinishOnTheThreadsTheSystemGives) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "a sanitizer's runtime maps memory of its own";
#else
  TempDir dir;
  // The chunks' allocations come from a heap grown beforehand, so that the limit below refuses
  // thread stacks only: one malloc arena (a thread's own reserves 64 MB of address space), small
  // blocks from the heap, and 32 MB of it kept once freed.
  mallopt(M_ARENA_MAX, 1);
  mallopt(M_MMAP_THRESHOLD, 64 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
  std::free(std::malloc(32 << 20));
  rlimit old{};
  ASSERT_EQ(getrlimit(RLIMIT_AS, &old), 0);
  for (size_t room : {size_t{40} << 20, size_t{2} << 20}) {
    const std::string path = dir.file("out" + std::to_string(room));
    Result<AtomicFile> f = AtomicFile::create(path);
    ASSERT_TRUE(f.ok()) << f.error().message;
    std::vector<std::atomic<int>> seen(20000);
    rlimit tight = old;
    tight.rlim_cur = mappedBytes() + room;
    ASSERT_EQ(setrlimit(RLIMIT_AS, &tight), 0);
    parallelFor(seen.size(), 200, [&](size_t i, unsigned worker) { seen[i] += worker < 200 ? 1 : 100; });
    Status s = writeChunksInOrder(*f, 500, 200, makeChunk);
    ASSERT_EQ(setrlimit(RLIMIT_AS, &old), 0);
    ASSERT_TRUE(s.ok()) << s.error().message;
    ASSERT_TRUE(f->commit().ok());
    size_t once = 0;
    for (const std::atomic<int>& n : seen) once += n == 1;
    EXPECT_EQ(once, seen.size()) << (room >> 20) << " MB of room";
    EXPECT_TRUE(test::readFile(path) == expected(500)) << (room >> 20) << " MB of room";
  }
#endif
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
