// Never a crash (issue #36, item 1): every command, run by a user who cannot write the current
// folder, or in a folder holding someone else's bench-out/, exits with its documented code, never
// by a signal. Root writes everywhere, so the runs drop to the unprivileged user nobody (setpriv);
// a developer who is not root runs them as themselves, whom a 0555 folder stops as well.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "test_support.h"

namespace dpoint {
namespace {

using test::contains;
using test::runCommand;
using test::TempDir;
using test::writeFile;

constexpr uid_t kNobody = 65534;

// The folders the runs use, readable by nobody: the executable's copy (the build tree may sit
// under a folder nobody cannot enter), an input set, a folder it may write into, a read-only one,
// and one whose bench-out/ belongs to root.
class UnprivilegedRuns : public ::testing::Test {
 protected:
  void SetUp() override {
    namespace fs = std::filesystem;
    fs::permissions(dir_.path(), fs::perms(0755));
    for (const char* folder : {"in", "readonly", "foreign"}) fs::create_directory(dir_.file(folder));
    fs::create_directory(dir_.file("out"));
    fs::create_directory(dir_.file("foreign/bench-out"));
    fs::copy_file(DPOINT_EXE, dir_.file("in/dpoint"));
    writeFile(dir_.file("in/set.csv"), "x,y,z,r,g,b\n0,0,0,1,0,0\n1,0,0,0,1,0\n0,1,0,0,0,1\n0,0,1,1,1,1\n");
    fs::permissions(dir_.file("in"), fs::perms(0755));
    fs::permissions(dir_.file("out"), fs::perms(root() ? 0777 : 0755));
    fs::permissions(dir_.file("readonly"), fs::perms(0555));
    // Writable by the user, but its bench-out/ is not: someone else's report.
    fs::permissions(dir_.file("foreign"), fs::perms(root() ? 0777 : 0755));
    fs::permissions(dir_.file("foreign/bench-out"), fs::perms(0555));
  }

  static bool root() { return ::geteuid() == 0; }

  // Runs dpoint with `args` in `folder` as the unprivileged user.
  test::CommandResult run(const std::string& folder, const std::vector<std::string>& args) {
    std::vector<std::string> argv;
    if (root()) argv = {"/usr/bin/setpriv", "--reuid=65534", "--regid=65534", "--clear-groups"};
    argv.insert(argv.end(), {"/usr/bin/env", "-C", dir_.file(folder), "HOME=" + dir_.file("out"),
                             dir_.file("in/dpoint")});
    argv.insert(argv.end(), args.begin(), args.end());
    return runCommand(argv, std::chrono::seconds(120));
  }

  TempDir dir_;
};

struct Case {
  std::vector<std::string> args;
  int code;  // the documented exit code
};

std::vector<Case> everyCommand(const std::string& in, const std::string& out) {
  const std::string set = in + "/set.csv";
  return {
      {{"--version"}, 0},
      {{"--help"}, 0},
      {{"generate", "--help"}, 0},
      {{"convert", "--help"}, 0},
      {{"render", "--help"}, 0},
      {{"info", "--help"}, 0},
      {{"devices", "--help"}, 0},
      {{"bench", "--help"}, 0},
      {{"merge", "--help"}, 0},
      {{"info", set}, 0},
      {{"info", set, "--json"}, 0},
      {{"convert", set, "-o", out + "/set.ply"}, 0},
      {{"generate", "random2d", "--count", "100", "-o", out + "/r.csv"}, 0},
      {{"render", set, "-o", out + "/set.png", "--width", "64", "--height", "48"}, 0},
      {{"devices"}, 0},
      // Writing where the user may not: a usage error naming the place, before any work.
      {{"generate", "random2d", "--count", "100", "-o", "r.csv"}, 1},
      {{"convert", set, "-o", "set.ply"}, 1},
      {{"render", set, "-o", "set.png"}, 1},
      {{"bench", "--suite", "ci"}, 1},  // the default --out, bench-out, here
  };
}

TEST_F(UnprivilegedRuns, everyCommandInAReadOnlyFolderExitsAsDocumented) {
  for (const Case& c : everyCommand(dir_.file("in"), dir_.file("out"))) {
    test::CommandResult r = run("readonly", c.args);
    std::string line = "dpoint";
    for (const std::string& a : c.args) line += " " + a;
    EXPECT_EQ(r.exit_code, c.code) << line << "\n" << r.err;
    EXPECT_FALSE(contains(r.err, "terminate called")) << line;
    if (c.code == 1) {
      EXPECT_TRUE(contains(r.err, "dpoint: error: ")) << line;
    }
  }
}

TEST_F(UnprivilegedRuns, aForeignBenchOutStopsOnlyBench) {
  const std::vector<Case> cases = {
      {{"--version"}, 0},
      {{"info", dir_.file("in/set.csv")}, 0},
      {{"convert", dir_.file("in/set.csv"), "-o", "set.ply"}, 0},
      {{"render", dir_.file("in/set.csv"), "-o", "set.png", "--width", "64", "--height", "48"}, 0},
      {{"devices"}, 0},
  };
  for (const Case& c : cases) {
    test::CommandResult r = run("foreign", c.args);
    EXPECT_EQ(r.exit_code, c.code) << c.args[0] << "\n" << r.err;
  }
  test::CommandResult bench = run("foreign", {"bench", "--suite", "ci"});
  EXPECT_EQ(bench.exit_code, 1) << bench.err;
  EXPECT_TRUE(contains(bench.err, "dpoint: error: --out bench-out: cannot write into folder"));
}

}  // namespace
}  // namespace dpoint
