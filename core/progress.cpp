#include "core/progress.h"

#include <unistd.h>

namespace dpoint {

std::FILE* progressSink(bool quiet) {
  return (!quiet && ::isatty(STDERR_FILENO)) ? stderr : nullptr;
}

void Progress::start(std::string label, uint64_t total) {
  finish();
  std::lock_guard<std::mutex> lock(mutex_);
  label_ = std::move(label);
  total_ = total;
  done_ = 0;
  active_ = sink_ != nullptr;
  start_ = last_ = std::chrono::steady_clock::now();
}

void Progress::advance(uint64_t units) {
  done_.fetch_add(units, std::memory_order_relaxed);
  if (!active_) return;
  auto now = std::chrono::steady_clock::now();
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock() || now - last_ < std::chrono::milliseconds(200)) return;
  last_ = now;
  print(false);
}

void Progress::finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!active_) return;
  print(true);
  active_ = false;
}

void Progress::print(bool final_line) {
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  uint64_t done = done_.load(std::memory_order_relaxed);
  double percent = total_ ? 100.0 * static_cast<double>(done) / static_cast<double>(total_) : 100.0;
  if (percent > 100.0) percent = 100.0;
  std::fprintf(sink_, "\r%s: %5.1f%% (%.1f s)%s", label_.c_str(), percent, seconds,
               final_line ? "\n" : "");
  std::fflush(sink_);
}

}  // namespace dpoint
