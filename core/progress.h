// Progress of long work. A library reports into a Progress; only the CLI chooses where it goes
// (stderr when it is a terminal and --quiet is not given; nowhere otherwise).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <string>

namespace dpoint {

class Progress {
 public:
  Progress() = default;  // silent
  Progress(std::FILE* sink, std::string label) : sink_(sink), label_(std::move(label)) {}
  Progress(const Progress&) = delete;
  ~Progress() { finish(); }

  // Starts a phase of `total` units (bytes, points) under a label.
  void start(std::string label, uint64_t total);
  // Thread-safe; prints at most every 200 ms.
  void advance(uint64_t units);
  // Ends the current line.
  void finish();
  bool silent() const { return sink_ == nullptr; }

 private:
  void print(bool final_line);

  std::FILE* sink_ = nullptr;
  std::string label_;
  std::atomic<uint64_t> done_{0};
  uint64_t total_ = 0;
  bool active_ = false;
  std::mutex mutex_;
  std::chrono::steady_clock::time_point start_{}, last_{};
};

// A Progress that prints to stderr when it is a terminal and `quiet` is false.
std::FILE* progressSink(bool quiet);

}  // namespace dpoint
