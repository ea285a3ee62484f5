// Memory limits for large outputs: estimate before allocating, refuse with a clear message.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <string>
#include <system_error>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/result.h"

namespace dpoint {

// Half of physical memory: the default for --max-memory.
uint64_t defaultMemoryLimit();

// Parses sizes such as 512M, 8G, 1.5GiB, 1000000 (bytes). Error names the flag and the text.
Result<uint64_t> parseMemorySize(const std::string& flag, const std::string& text);

// kResourceLimit error when `needed` exceeds `limit` (0: the default limit).
Status checkMemory(const std::string& what, uint64_t needed, uint64_t limit);

std::string formatBytes(uint64_t bytes);

// Faults in the pages of [data, data + bytes) for writing on `threads` cores (0: all), changing no
// byte. Faulting in fresh pages is most of the cost of a big resize (on the 2-core test VM, 0.27 s
// of the 0.48 s a 16.7M-point PLY read took with a plain resize), and a resize takes it on one
// thread. MADV_POPULATE_WRITE is only a hint: where the kernel lacks it (before Linux 5.14)
// nothing happens and the first write faults the pages as before.
void prefaultForWrite(void* data, size_t bytes, unsigned threads);

// Asks the kernel to back the 2 MiB-aligned interior of [data, data + bytes) with 2 MiB pages
// (transparent huge pages in "madvise" mode, Debian's default): the first writes then take 512
// times fewer page faults. Only a hint; nothing changes where the kernel declines.
void adviseHugePages(void* data, size_t bytes);

// An anonymous mapping of `bytes` that starts on a 2 MiB boundary, with transparent huge pages
// advised (mapping its own 2 MiB more, then giving back the slack before and after): every 2 MiB
// of it can then be one page. Null where mmap fails. unmapPages gives it back.
void* mapHugePages(size_t bytes);
void unmapPages(void* data, size_t bytes) noexcept;

// Bytes that nothing zeroes first, for a large output that many threads write (decoded LAZ
// records): mapped on their own and, where the kernel allows (transparent huge pages in "madvise"
// mode, Debian's default), backed by 2 MiB pages, so the threads that first write them take 512
// times fewer page faults. Falls back to the heap when the mapping fails. Move-only.
class LargeBuffer {
 public:
  LargeBuffer() = default;
  explicit LargeBuffer(size_t bytes);
  LargeBuffer(LargeBuffer&& other) noexcept;
  LargeBuffer& operator=(LargeBuffer&& other) noexcept;
  LargeBuffer(const LargeBuffer&) = delete;
  LargeBuffer& operator=(const LargeBuffer&) = delete;
  ~LargeBuffer();
  char* data() const { return data_; }
  size_t size() const { return size_; }

 private:
  void release();
  char* data_ = nullptr;
  size_t size_ = 0, mapped_ = 0;  // mapped_: the bytes mapHugePages mapped (size_), 0 for the heap
};

// Blocks of DefaultInitAllocator this large or larger are mapped by mapHugePages.
constexpr size_t kHugeBlockBytes = size_t{2} << 20;

// std::allocator, except that an element made without arguments (`resize(n)`, `vector(n)`) is
// default-initialised rather than value-initialised: a trivial type (glm's vectors) is left as the
// memory was, not zeroed. Zeroing hundreds of MB on one thread before many threads write every
// element took 110-120 ms of a 16.8M-point render on the H200 (a quarter of it) and 45 ms on the
// 2-core VM. A `resize(n)` of such a vector must therefore be followed by a write of every new
// element; `resize(n, value)` and `assign` fill as always.
//
// A block of kHugeBlockBytes or more is a mapping of its own in 2 MiB pages (mapHugePages), so the
// threads that first write it take a fault per 2 MiB rather than per 4 KiB: on the 2-core test VM
// (a PVM guest) a 4 KiB fault costs about 12 us, and the 1.55M-point Mandelbulb's positions and
// colours alone took 13,500 of them. Under valgrind the mapping is marked undefined, as heap
// memory is, so memcheck still finds an element nothing wrote.
template <typename T>
struct DefaultInitAllocator : std::allocator<T> {
  using value_type = T;
  template <typename U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() noexcept = default;
  template <typename U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}  // NOLINT: converting, as std::allocator's
  T* allocate(size_t n) {
    if (n > SIZE_MAX / sizeof(T)) throw std::bad_array_new_length();
    if (n * sizeof(T) < kHugeBlockBytes) return std::allocator<T>::allocate(n);
    void* p = mapHugePages(n * sizeof(T));
    if (!p) throw std::bad_alloc();
    return static_cast<T*>(p);
  }
  void deallocate(T* p, size_t n) noexcept {
    if (n * sizeof(T) < kHugeBlockBytes) return std::allocator<T>::deallocate(p, n);
    unmapPages(p, n * sizeof(T));
  }
  template <typename U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
template <typename T, typename U>
bool operator==(const DefaultInitAllocator<T>&, const DefaultInitAllocator<U>&) noexcept {
  return true;
}

// Destroys an object on a thread of its own, so that giving its memory back (the kernel unmapping
// the hundreds of MB of a large point set: 20-50 ms on the 2-core VM, more under load) overlaps what
// the caller does next, such as writing the picture. The destructor (or wait()) waits for it. Where
// no thread can be started, the object is destroyed at once.
class ReleaseInBackground {
 public:
  ReleaseInBackground() = default;
  // Takes `value` by move only (an lvalue would be copied; a holder is moved as a holder).
  template <typename T, typename = std::enable_if_t<!std::is_lvalue_reference_v<T> &&
                                                    !std::is_same_v<std::decay_t<T>, ReleaseInBackground>>>
  explicit ReleaseInBackground(T&& value) {
    auto held = std::make_unique<std::decay_t<T>>(std::forward<T>(value));
    try {
      thread_ = std::thread([owned = std::move(held)]() mutable { owned.reset(); });
    } catch (const std::system_error&) {  // the object dies here, with the lambda that held it
    }
  }
  ReleaseInBackground(ReleaseInBackground&& other) noexcept = default;
  ReleaseInBackground& operator=(ReleaseInBackground&& other) noexcept {
    wait();
    thread_ = std::move(other.thread_);
    return *this;
  }
  ~ReleaseInBackground() { wait(); }
  void wait() {
    if (thread_.joinable()) thread_.join();
  }

 private:
  std::thread thread_;
};

// Resizes `v` to n elements for many threads to fill. A std::allocator vector's new elements are
// zeroed, on one thread, so when it is empty its pages are faulted in on all cores first (a vector
// that holds elements keeps them, and is resized as it is). A DefaultInitAllocator vector's are
// left as they are: nothing touches its pages, and the threads that write the elements fault
// them in, each its own. Faulting them in here as well (MADV_POPULATE_WRITE holds the process's
// mmap lock for each 8 MiB) made the NVIDIA driver, loaded on another thread meanwhile, wait for
// that lock: creating its Vulkan instance took 180-240 ms during a 16.8M-point read instead of
// 80-100 ms (H200).
template <typename T, typename Allocator>
void resizePrefaulted(std::vector<T, Allocator>& v, size_t n, unsigned threads) {
  if constexpr (!std::is_same_v<Allocator, DefaultInitAllocator<T>>) {
    if (v.empty()) {
      v.reserve(n);
      prefaultForWrite(v.data(), n * sizeof(T), threads);
    }
  }
  v.resize(n);
}

}  // namespace dpoint
