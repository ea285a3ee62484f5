// LargeBuffer (core/memory.h): a mapped buffer for large outputs and the heap for small ones; both
// hold what is written, move without copying, and release once.
#include <gtest/gtest.h>

#include <utility>

#include "core/memory.h"
#include "core/parallel.h"

namespace dpoint {
namespace {

TEST(LargeBuffer, holdsWhatManyThreadsWriteAndMovesWithoutCopying) {
  for (size_t bytes : {size_t{0}, size_t{100}, (size_t{5} << 20) + 3}) {
    SCOPED_TRACE(bytes);
    LargeBuffer buffer(bytes);
    ASSERT_EQ(buffer.size(), bytes);
    ASSERT_NE(buffer.data(), nullptr);
    parallelFor(bytes, 2, [&](size_t i, unsigned) { buffer.data()[i] = static_cast<char>(i * 7); });
    char* const at = buffer.data();
    LargeBuffer moved = std::move(buffer);
    EXPECT_EQ(moved.data(), at);
    EXPECT_EQ(buffer.data(), nullptr);  // NOLINT(bugprone-use-after-move): moved-from is empty
    EXPECT_EQ(buffer.size(), 0u);
    size_t wrong = 0;
    for (size_t i = 0; i < bytes; ++i) wrong += moved.data()[i] != static_cast<char>(i * 7);
    EXPECT_EQ(wrong, 0u);
    LargeBuffer assigned(64);
    assigned = std::move(moved);
    EXPECT_EQ(assigned.data(), at);
  }
}

}  // namespace
}  // namespace dpoint
