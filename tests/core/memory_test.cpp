// --max-memory's check (core/memory.h): its message says which of two sizes is larger.
#include "core/memory.h"

#include <gtest/gtest.h>

#include <string>

namespace dpoint {
namespace {

// Sizes that print alike in MiB get their bytes too ("needs about 1.3 MiB, more than the limit of
// 1.3 MiB" said nothing, a review finding); sizes that differ in print keep the short form.
TEST(Memory, checkMemorySaysTheBytesWhereTheSizesPrintAlike) {
  EXPECT_TRUE(checkMemory("reading a", 1386407, 1386407).ok());
  Status close = checkMemory("reading a", 1386408, 1386407);
  ASSERT_FALSE(close.ok());
  EXPECT_EQ(close.error().code, ExitCode::kResourceLimit);
  EXPECT_EQ(close.error().message,
            "reading a needs about 1.3 MiB (1386408 bytes), more than the limit of 1.3 MiB (1386407 bytes) (--max-memory)");
  Status far = checkMemory("reading b", 3u << 20, 1u << 20);
  ASSERT_FALSE(far.ok());
  EXPECT_EQ(far.error().message, "reading b needs about 3.0 MiB, more than the limit of 1.0 MiB (--max-memory)");
  Status small = checkMemory("reading c", 1025, 1024);
  ASSERT_FALSE(small.ok());
  EXPECT_EQ(small.error().message, "reading c needs about 1025 bytes, more than the limit of 1024 bytes (--max-memory)");
}

}  // namespace
}  // namespace dpoint
