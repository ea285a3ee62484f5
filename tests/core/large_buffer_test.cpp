// LargeBuffer (core/memory.h): a mapped buffer for large outputs and the heap for small ones; both
// hold what is written, move without copying, and release once. ReleaseInBackground: an object
// destroyed on a thread of its own, waited for.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

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

// The object is destroyed once, on another thread, and the holder's end waits for it (the
// destructor here takes 50 ms, so a holder that did not wait would see it unfinished).
TEST(ReleaseInBackground, destroysOnceOnAnotherThreadAndWaits) {
  struct Slow {
    std::atomic<int>* destroyed;
    std::atomic<std::thread::id>* on;
    bool live = true;
    Slow(std::atomic<int>* d, std::atomic<std::thread::id>* t) : destroyed(d), on(t) {}
    Slow(Slow&& other) noexcept : destroyed(other.destroyed), on(other.on) { other.live = false; }
    ~Slow() {
      if (!live) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      *on = std::this_thread::get_id();
      ++*destroyed;
    }
  };
  std::atomic<int> destroyed{0};
  std::atomic<std::thread::id> on;
  {
    ReleaseInBackground release(Slow(&destroyed, &on));
    ReleaseInBackground moved = std::move(release);
    ReleaseInBackground other(Slow(&destroyed, &on));
    other = std::move(moved);  // waits for other's own object first
    EXPECT_GE(destroyed.load(), 1);
  }
  EXPECT_EQ(destroyed.load(), 2);
  static_assert(!std::is_constructible_v<ReleaseInBackground, ReleaseInBackground&>);
  static_assert(!std::is_constructible_v<ReleaseInBackground, std::vector<int>&>);
  EXPECT_NE(on.load(), std::this_thread::get_id());
  ReleaseInBackground empty;
  empty.wait();  // nothing to wait for
}

}  // namespace
}  // namespace dpoint
