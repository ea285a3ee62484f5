// Helpers shared by the test suites: scratch folders, whole-file I/O, running the dpoint binary.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/point_set.h"
#include "test_config.h"

namespace dpoint::test {

// A fresh folder under $TMPDIR (or /tmp), removed with its content at scope exit.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  const std::string& path() const { return path_; }
  std::string file(const std::string& name) const { return path_ + "/" + name; }
  // Names of the entries in the folder, sorted.
  std::vector<std::string> entries() const;

 private:
  std::string path_;
};

std::string readFile(const std::string& path);
// The first line of `text` with its line end (all of it when it has none).
inline std::string firstLine(const std::string& text) { return text.substr(0, text.find('\n') + 1); }
void writeFile(const std::string& path, const std::string& bytes);
bool fileExists(const std::string& path);

struct CommandResult {
  int exit_code = -1;  // -1 when killed by a signal
  bool timed_out = false;  // killed (SIGKILL) for running past runCommand's limit
  std::string out;
  std::string err;
};
// Runs argv[0] with the arguments (no shell), capturing stdout and stderr. With a non-zero
// `limit`, a run still going after it is killed and marked timed_out: a bound for "does not
// hang", generous so that it never measures speed (tests assert no timings). A run that dies by
// any other signal fails the calling test (ADD_FAILURE): no command may abort or crash.
CommandResult runCommand(const std::vector<std::string>& argv, std::chrono::seconds limit = std::chrono::seconds(0));
// Runs build/dpoint with the arguments.
CommandResult runDpoint(const std::vector<std::string>& args);
// EXPECT_TRUE(test::contains(message, "part")): a failure prints the whole text.
inline ::testing::AssertionResult contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << text << "' does not contain '" << part << "'";
}

// The arguments of `a` followed by those of `b`: one command line built from shared pieces.
inline std::vector<std::string> concat(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// Bytes process `pid` has written so far (/proc/PID/io wchar); 0 once it is gone.
uint64_t bytesWrittenBy(int pid);

// A PNG's width and height, from its IHDR chunk (big-endian, at bytes 16 and 20).
std::pair<uint32_t, uint32_t> pngSize(const std::string& png);

}  // namespace dpoint::test
