// Work splitting over all cores. Items are handed out dynamically, so callers whose items write
// to disjoint, preassigned places get output that does not depend on the thread count.
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <system_error>
#include <thread>
#include <vector>

namespace dpoint {

// The most threads a job runs (--threads checks it; a caller of the library asking more gets this).
inline constexpr unsigned kMostThreads = 4096;

// 0 means "all cores": asked of the system once (glibc reads /sys/devices/system/cpu/online each
// time, and a LAS file of 65,508 undescribed extra bytes, each a dimension, asked 65,510 times: half a
// second of a fuzz input's read).
inline unsigned resolveThreads(unsigned requested) {
  if (requested != 0) return requested < kMostThreads ? requested : kMostThreads;
  static const unsigned cores = [] {
    const unsigned n = std::thread::hardware_concurrency();
    return n == 0 ? 1u : n;
  }();
  return cores;
}

// The workers parallelFor(count, threads, …) runs: no more than its items (at least one). Per-worker
// arrays are sized by it, so a small job on a many-core host does not make one for every core.
inline unsigned parallelWorkers(size_t count, unsigned threads) {
  threads = resolveThreads(threads);
  return threads > count ? static_cast<unsigned>(count == 0 ? 1 : count) : threads;
}

// Lowers `value` to `candidate` where that is smaller (from several threads at once): the first
// failing item of a parallel scan, whichever worker finds it.
template <typename T>
void lowerAtomic(std::atomic<T>& value, T candidate) {
  T seen = value.load();
  while (candidate < seen && !value.compare_exchange_weak(seen, candidate)) {
  }
}

// Calls fn(item, worker) for every item in [0, count) on parallelWorkers(count, threads) threads
// (worker < that).
inline void parallelFor(size_t count, unsigned threads,
                        const std::function<void(size_t item, unsigned worker)>& fn) {
  threads = parallelWorkers(count, threads);
  std::atomic<size_t> next{0};
  auto run = [&](unsigned worker) {
    for (size_t i = next.fetch_add(1); i < count; i = next.fetch_add(1)) fn(i, worker);
  };
  if (threads <= 1) {
    run(0);
    return;
  }
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  // A thread the system will not make (a process or address-space limit, --threads 30000): the
  // items go to the workers made, the caller among them, as they are handed out anyway.
  try {
    for (unsigned t = 1; t < threads; ++t) pool.emplace_back(run, t);
  } catch (const std::system_error&) {
  }
  run(0);
  for (std::thread& t : pool) t.join();
}

}  // namespace dpoint
