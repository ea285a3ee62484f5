#include "core/memory.h"

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "core/interrupt.h"
#include "core/parallel.h"

// Valgrind's client requests (macros that do nothing outside valgrind), where its headers are.
#if __has_include(<valgrind/memcheck.h>)
#include <valgrind/memcheck.h>
#define DPOINT_HAS_MEMCHECK 1
#else
#define DPOINT_HAS_MEMCHECK 0
#endif

namespace dpoint {

uint64_t defaultMemoryLimit() {
  long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  if (pages <= 0 || page <= 0) return uint64_t{4} << 30;
  return static_cast<uint64_t>(pages) * static_cast<uint64_t>(page) / 2;
}

Result<uint64_t> parseMemorySize(const std::string& flag, const std::string& text) {
  size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (...) {
    used = 0;
  }
  std::string unit = text.substr(used);
  double scale = 0.0;
  if (unit.empty() || unit == "B") scale = 1.0;
  else if (unit == "K" || unit == "KiB" || unit == "KB") scale = 1024.0;
  else if (unit == "M" || unit == "MiB" || unit == "MB") scale = 1024.0 * 1024.0;
  else if (unit == "G" || unit == "GiB" || unit == "GB") scale = 1024.0 * 1024.0 * 1024.0;
  if (used == 0 || scale == 0.0 || !(value > 0.0) || !std::isfinite(value) || value * scale > 1e19)
    return Error{flag + " " + text + ": not a size (examples: 512M, 8G, 1000000)", ExitCode::kUsage};
  // A count of bytes is whole (1.5 was cut to 1 byte in silence, and 0.5 to 0, the default limit);
  // a fraction of a unit is cut to the byte below (0.1G).
  const double bytes = value * scale;
  if (scale == 1.0 ? bytes != std::floor(bytes) : bytes < 1.0)
    return Error{flag + " " + text + ": not a whole number of bytes (examples: 512M, 1.5G, 1000000)", ExitCode::kUsage};
  return static_cast<uint64_t>(bytes);
}

std::string formatBytes(uint64_t bytes) {
  char text[64];
  const double b = static_cast<double>(bytes);
  if (b >= 1024.0 * 1024.0 * 1024.0) std::snprintf(text, sizeof text, "%.2f GiB", b / (1024.0 * 1024.0 * 1024.0));
  else if (b >= 1024.0 * 1024.0) std::snprintf(text, sizeof text, "%.1f MiB", b / (1024.0 * 1024.0));
  else std::snprintf(text, sizeof text, "%llu bytes", static_cast<unsigned long long>(bytes));
  return text;
}

Status checkMemory(const std::string& what, uint64_t needed, uint64_t limit) {
  if (limit == 0) limit = defaultMemoryLimit();
  if (needed <= limit) return okStatus();
  std::string need = formatBytes(needed), most = formatBytes(limit);
  if (need == most) {  // close to the limit: the bytes say which is larger ("1.3 MiB, more than 1.3 MiB" did not)
    need += " (" + std::to_string(needed) + " bytes)";
    most += " (" + std::to_string(limit) + " bytes)";
  }
  return Error{what + " needs about " + need + ", more than the limit of " + most + " (--max-memory)",
               ExitCode::kResourceLimit};
}

void prefaultForWrite(void* data, size_t bytes, unsigned threads) {
#ifdef MADV_POPULATE_WRITE
  constexpr uintptr_t kChunk = uintptr_t{8} << 20;  // a multiple of every page size
  const uintptr_t page = static_cast<uintptr_t>(sysconf(_SC_PAGESIZE));
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(data) + page - 1) & ~(page - 1);
  const uintptr_t end = reinterpret_cast<uintptr_t>(data) + bytes;
  if (end > begin)
    parallelFor((end - begin + kChunk - 1) / kChunk, threads, [&](size_t chunk, unsigned) {
      if (interrupted()) return;  // the first writes fault in what is left
      const uintptr_t first = begin + chunk * kChunk;
      (void)madvise(reinterpret_cast<void*>(first), std::min(kChunk, end - first), MADV_POPULATE_WRITE);
    });
#else
  (void)data, (void)bytes, (void)threads;
#endif
}

void adviseHugePages(void* data, size_t bytes) {
#ifdef MADV_HUGEPAGE
  constexpr uintptr_t kHuge = uintptr_t{2} << 20;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes) & ~(kHuge - 1);
  if (end > begin) (void)madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)data, (void)bytes;
#endif
}

void* mapHugePages(size_t bytes) {
  constexpr uintptr_t kHuge = uintptr_t{2} << 20;
  void* raw = mmap(nullptr, bytes + kHuge, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED) return nullptr;
  const uintptr_t start = reinterpret_cast<uintptr_t>(raw), aligned = (start + kHuge - 1) & ~(kHuge - 1);
  const uintptr_t page = static_cast<uintptr_t>(sysconf(_SC_PAGESIZE));
  const uintptr_t used_end = (aligned + bytes + page - 1) & ~(page - 1);
  if (aligned > start) munmap(raw, aligned - start);
  if (start + bytes + kHuge > used_end) munmap(reinterpret_cast<void*>(used_end), start + bytes + kHuge - used_end);
  void* data = reinterpret_cast<void*>(aligned);
#ifdef MADV_HUGEPAGE
  (void)madvise(data, used_end - aligned, MADV_HUGEPAGE);  // a hint: without it the pages are 4 KiB
#endif
#if DPOINT_HAS_MEMCHECK
  VALGRIND_MAKE_MEM_UNDEFINED(data, bytes);  // as fresh heap memory is: memcheck tracks what is written
#endif
  return data;
}

void unmapPages(void* data, size_t bytes) noexcept {
  if (data) munmap(data, bytes);
}

LargeBuffer::LargeBuffer(size_t bytes) : size_(bytes) {
  if (bytes >= kHugeBlockBytes)
    if (void* p = mapHugePages(bytes)) {
      data_ = static_cast<char*>(p);
      mapped_ = bytes;
      return;
    }
  data_ = new char[std::max<size_t>(bytes, 1)];
}

LargeBuffer::LargeBuffer(LargeBuffer&& other) noexcept
    : data_(std::exchange(other.data_, nullptr)),
      size_(std::exchange(other.size_, 0)),
      mapped_(std::exchange(other.mapped_, 0)) {}

LargeBuffer& LargeBuffer::operator=(LargeBuffer&& other) noexcept {
  if (this != &other) {
    release();
    data_ = std::exchange(other.data_, nullptr);
    size_ = std::exchange(other.size_, 0);
    mapped_ = std::exchange(other.mapped_, 0);
  }
  return *this;
}

LargeBuffer::~LargeBuffer() { release(); }

void LargeBuffer::release() {
  if (!data_) return;
  if (mapped_) unmapPages(data_, mapped_);
  else delete[] data_;
  data_ = nullptr;
}

}  // namespace dpoint
