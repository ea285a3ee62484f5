// LargeBuffer (core/memory.h): a mapped buffer for large outputs and the heap for small ones; both
// hold what is written, move without copying, and release once. ReleaseInBackground: an object
// destroyed on a thread of its own, waited for. DefaultInitAllocator: blocks of 2 MiB or more
// mapped on their own in 2 MiB pages, given back when freed.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>

#include <atomic>
#include <chrono>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/memory.h"
#include "core/parallel.h"
#include "core/point_set.h"

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

// The VmFlags of the mapping that holds `p` in /proc/self/smaps, "" where no mapping holds it.
std::string vmFlagsAt(const void* p) {
  std::ifstream smaps("/proc/self/smaps");
  const uintptr_t at = reinterpret_cast<uintptr_t>(p);
  bool inside = false;
  for (std::string line; std::getline(smaps, line);) {
    uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream range(line);
    if (line.find("VmFlags:") == 0) {
      if (inside) return line;
    } else if (range >> std::hex >> lo >> dash >> hi) {
      inside = dash == '-' && lo <= at && at < hi;
    }
  }
  return "";
}

TEST(DefaultInitAllocator, largeBlocksAreTheirOwnMappingInHugePagesAndAreGivenBack) {
  const void* first = nullptr;
  {
    PositionArray positions(size_t{1} << 20);  // 24 MiB
    first = positions.data();
    EXPECT_EQ(reinterpret_cast<uintptr_t>(positions.data()) % (uintptr_t{2} << 20), 0u) << "2 MiB-aligned";
    parallelFor(positions.size(), 2, [&](size_t i, unsigned) { positions[i] = glm::dvec3(static_cast<double>(i)); });
    EXPECT_EQ(positions.back().z, static_cast<double>(positions.size() - 1));
    // Transparent huge pages advised ("hg"), unless the kernel has none to give.
    const std::string flags = vmFlagsAt(positions.data());
    ASSERT_NE(flags, "");
    if (std::ifstream("/sys/kernel/mm/transparent_hugepage/enabled")) {
      EXPECT_NE(flags.find(" hg"), std::string::npos) << flags;
    }
    positions.resize(positions.size() * 2);  // grows into a new mapping, the old one given back
    EXPECT_EQ(positions[12345].x, 12345.0);
    EXPECT_EQ(vmFlagsAt(first), "");
    first = positions.data();
  }
  EXPECT_EQ(vmFlagsAt(first), "") << "freed";
  // A small block comes from the heap as before.
  ColorArray colors(1000);
  EXPECT_EQ(vmFlagsAt(colors.data()).find(" hg"), std::string::npos);
}

}  // namespace
}  // namespace dpoint
