// SIGINT, SIGTERM and SIGKILL in the middle of generate, convert, render and bench (issue #12):
// the first two stop the run (exit 130 / 143) with no output left, SIGKILL leaves no output file.
// Each run is big enough to take many seconds; it is signalled once it has worked for a while
// (CPU time), and must be gone well before a generous timeout (how fast it stops is measured by
// hand: bench/results/fuzz.md; a test only bounds it loosely).
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <thread>

#include "test_support.h"

namespace dpoint {
namespace {

using Clock = std::chrono::steady_clock;
using test::TempDir;

// CPU seconds the process has used (/proc/PID/stat utime + stime).
double cpuSeconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t close = text.rfind(')');  // the command name may hold spaces
  if (close == std::string::npos) return 0.0;
  std::istringstream fields(text.substr(close + 2));
  std::string field;
  unsigned long long utime = 0, stime = 0;
  for (int i = 3; i <= 15 && fields >> field; ++i) {
    if (i == 14) utime = std::stoull(field);
    if (i == 15) stime = std::stoull(field);
  }
  return static_cast<double>(utime + stime) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

// A dpoint run in the background; stderr goes to a file in `dir`.
class BackgroundRun {
 public:
  BackgroundRun(const TempDir& dir, const std::vector<std::string>& args) : err_path_(dir.file("stderr.txt")) {
    pid_ = ::fork();
    if (pid_ == 0) {
      const int err = ::open(err_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int null = ::open("/dev/null", O_RDWR);
      ::dup2(null, 0);
      ::dup2(null, 1);
      ::dup2(err, 2);
      std::vector<char*> argv = {const_cast<char*>(DPOINT_EXE)};
      for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      ::execv(DPOINT_EXE, argv.data());
      ::_exit(127);
    }
  }
  ~BackgroundRun() {
    if (pid_ > 0 && !reaped_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  pid_t pid() const { return pid_; }

  // Waits until `ready` holds (true) or the run ends or 60 s pass (false).
  bool waitUntil(const std::function<bool()>& ready) {
    for (auto end = Clock::now() + std::chrono::seconds(60); Clock::now() < end;) {
      if (ready()) return true;
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        reaped_ = true;
        status_ = status;
        return false;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }
  bool waitForCpu(double seconds) { return waitUntil([&] { return cpuSeconds(pid_) >= seconds; }); }

  // Sends `signal` and waits for the end, at most `limit`; the wait status, or -1 on timeout.
  int stop(int signal, std::chrono::seconds limit = std::chrono::seconds(10)) {
    ::kill(pid_, signal);
    for (auto end = Clock::now() + limit; Clock::now() < end;) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        reaped_ = true;
        return status;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return -1;
  }
  std::string err() const { return test::readFile(err_path_); }

 private:
  std::string err_path_;
  pid_t pid_ = -1;
  bool reaped_ = false;
  int status_ = 0;
};

// Files a stopped run left: everything in `dir` but its inputs (`keep`) and the test's stderr
// capture, except that a bench's finished datasets in its cache stay (whole files, made to be
// reused); a named temporary (PATH.dpoint-…) anywhere counts, and so do a timed draw's picture and
// report in the cache (timed-draw.*, which a stopped bench had left).
std::vector<std::string> leftBehind(const TempDir& dir, const std::vector<std::string>& keep) {
  std::vector<std::string> left;
  std::error_code ec;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir.path(), ec)) {
    const std::string name = e.path().filename();
    if (e.is_directory() || name == "stderr.txt" || std::find(keep.begin(), keep.end(), name) != keep.end()) continue;
    const bool cached = e.path().parent_path() == dir.file("cache");
    if (!cached || name.find(".dpoint-") != std::string::npos || name.rfind("timed-draw", 0) == 0)
      left.push_back(e.path().string());
  }
  return left;
}

// Whether any process still runs with `text` in its command line (a bench's child, orphaned).
bool processWithArgument(const std::string& text) {
  for (const auto& e : std::filesystem::directory_iterator("/proc")) {
    std::ifstream in(e.path() / "cmdline");
    std::string cmdline((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (cmdline.find(text) != std::string::npos) return true;
  }
  return false;
}

template <typename T>
void append(std::string& bytes, std::initializer_list<T> values) {
  for (T v : values) bytes.append(reinterpret_cast<const char*>(&v), sizeof v);
}

// A small GLB placing a 20,000-point mesh 5,000 times (EXT_mesh_gpu_instancing): 100M points,
// minutes of CSV output, from 300 KB of input.
void writeInstancedGlb(const std::string& path) {
  constexpr int kPoints = 20000, kInstances = 5000;
  std::string bin;
  for (int i = 0; i < kPoints; ++i) append<float>(bin, {float(i % 100), float(i / 100), 0.5f});
  for (int i = 0; i < kInstances; ++i) append<float>(bin, {0.0f, 0.0f, float(i)});
  const std::string json =
      R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"extensionsUsed":["EXT_mesh_gpu_instancing"],)"
      R"("nodes":[{"mesh":0,"extensions":{"EXT_mesh_gpu_instancing":{"attributes":{"TRANSLATION":1}}}}],)"
      R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"mode":0}]}],)"
      R"("buffers":[{"byteLength":)" + std::to_string(bin.size()) + R"(}],)"
      R"("bufferViews":[{"buffer":0,"byteLength":)" + std::to_string(kPoints * 12) +
      R"(},{"buffer":0,"byteOffset":)" + std::to_string(kPoints * 12) + R"(,"byteLength":)" +
      std::to_string(kInstances * 12) + R"(}],)"
      R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" + std::to_string(kPoints) +
      R"(,"type":"VEC3"},{"bufferView":1,"componentType":5126,"count":)" + std::to_string(kInstances) +
      R"(,"type":"VEC3"}]})";
  std::string padded = json + std::string((4 - json.size() % 4) % 4, ' ');
  std::string glb;
  append<uint32_t>(glb, {0x46546C67u, 2u, uint32_t(12 + 8 + padded.size() + 8 + bin.size())});
  append<uint32_t>(glb, {uint32_t(padded.size()), 0x4E4F534Au});
  glb += padded;
  append<uint32_t>(glb, {uint32_t(bin.size()), 0x004E4942u});
  glb += bin;
  test::writeFile(path, glb);
}

// The four commands (generate twice), each started on work that lasts many seconds. `keep`: the inputs it was given.
struct LongRun {
  const char* name;
  std::function<std::vector<std::string>(const TempDir&)> start;  // makes the inputs, returns the args
  std::vector<std::string> keep;
};

std::vector<LongRun> longRuns() {
  return {
      {"generate", [](const TempDir& d) {
         return std::vector<std::string>{"generate", "mandelbulb", "--resolution", "1200", "--threads", "1", "-o",
                                         d.file("out.ply")};
       }, {}},
      // Marching cubes on the device (lavapipe here): stopped between slabs.
      {"generate --mesh device", [](const TempDir& d) {
         return std::vector<std::string>{"generate", "julia", "--resolution", "600", "--device", "cpu", "--mesh",
                                         "device", "-o", d.file("out.ply")};
       }, {}},
      {"convert", [](const TempDir& d) {
         writeInstancedGlb(d.file("in.glb"));
         return std::vector<std::string>{"convert", d.file("in.glb"), "-o", d.file("out.csv"), "--threads", "1"};
       }, {"in.glb"}},
      {"render", [](const TempDir& d) {
         test::CommandResult made = test::runDpoint({"generate", "random2d", "--count", "200000", "-o", d.file("in.ply")});
         EXPECT_EQ(made.exit_code, 0) << made.err;
         return std::vector<std::string>{"render", d.file("in.ply"), "-o", d.file("out.png"), "--frames", "1000000",
                                         "--json", d.file("out.json")};
       }, {"in.ply"}},
      {"bench", [](const TempDir& d) {
         return std::vector<std::string>{"bench", "--suite", "ci", "--out", d.file("report"), "--cache",
                                         d.file("cache"), "--no-copy-bandwidth"};
       }, {}},
  };
}

TEST(CliInterrupt, sigintAndSigtermStopEveryLongCommandAndLeaveNoOutput) {
  for (const LongRun& run : longRuns()) {
    for (int signal : {SIGINT, SIGTERM}) {
      SCOPED_TRACE(std::string(run.name) + (signal == SIGINT ? " SIGINT" : " SIGTERM"));
      TempDir dir;
      const std::vector<std::string> args = run.start(dir);
      BackgroundRun process(dir, args);
      ASSERT_TRUE(process.waitForCpu(0.3)) << "it ended before it was signalled: " << process.err();
      const int status = process.stop(signal);
      ASSERT_NE(status, -1) << "still running 10 s after the signal";
      ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
      EXPECT_EQ(WEXITSTATUS(status), signal == SIGINT ? 130 : 143) << process.err();
      EXPECT_NE(process.err().find(signal == SIGINT ? "interrupted by SIGINT" : "interrupted by SIGTERM"),
                std::string::npos)
          << process.err();
      // A bench's dpoint runs stop with it.
      for (int i = 0; i < 500 && processWithArgument(dir.path()); ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      EXPECT_FALSE(processWithArgument(dir.path())) << "a child run is still going";
      EXPECT_EQ(leftBehind(dir, run.keep), std::vector<std::string>{});
    }
  }
}

// SIGKILL cannot be caught: what is left must still be nothing at the output paths (generate has
// its own test, Cli.sigkillWhileWritingLeavesNoFile, killed while writing).
TEST(CliInterrupt, sigkillLeavesNoOutputFile) {
  for (const LongRun& run : longRuns()) {
    if (std::string(run.name) == "generate") continue;
    SCOPED_TRACE(run.name);
    TempDir dir;
    const std::vector<std::string> args = run.start(dir);
    BackgroundRun process(dir, args);
    // convert: once it writes its output; the others once they have worked a while.
    const bool going = std::string(run.name) == "convert"
                           ? process.waitUntil([&] { return test::bytesWrittenBy(process.pid()) > (4u << 20); })
                           : process.waitForCpu(0.3);
    ASSERT_TRUE(going) << process.err();
    const int status = process.stop(SIGKILL);
    ASSERT_TRUE(status != -1 && WIFSIGNALED(status));
    // A killed bench's runs get SIGTERM from the kernel (PR_SET_PDEATHSIG) and stop.
    for (int i = 0; i < 500 && processWithArgument(dir.path()); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    EXPECT_FALSE(processWithArgument(dir.path())) << "a child run is still going";
    EXPECT_EQ(leftBehind(dir, run.keep), std::vector<std::string>{});
  }
}

}  // namespace
}  // namespace dpoint
