// The CLI embedded in another program (cli/cli_run.h), as the Python module uses it: runEmbedded
// parses, checks and words errors as the executable does, hands back the set `dpoint generate`
// would write, prints no error, and can run again and again in one process; the bench's children
// are $DPOINT_EXECUTABLE when it is set.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "cli/cli_run.h"
#include "converters/point_io.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::concat;
using test::contains;
using test::fileExists;
using test::readFile;
using test::TempDir;

// What this process writes on stderr (file descriptor 2) while the object lives.
class StderrCapture {
 public:
  StderrCapture() : path_(dir_.file("stderr")) {
    std::fflush(stderr);
    saved_ = ::dup(STDERR_FILENO);
    const int file = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(file, STDERR_FILENO);
    ::close(file);
  }
  ~StderrCapture() { restore(); }
  // Stops capturing and returns what was written.
  std::string text() {
    restore();
    return readFile(path_);
  }

 private:
  void restore() {
    if (saved_ < 0) return;
    std::fflush(stderr);
    ::dup2(saved_, STDERR_FILENO);
    ::close(saved_);
    saved_ = -1;
  }
  TempDir dir_;
  std::string path_;
  int saved_ = -1;
};

// An environment variable set for one scope, and unset after it.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) { ::setenv(name, value.c_str(), 1); }
  ~ScopedEnv() { ::unsetenv(name_); }

 private:
  const char* name_;
};

// `generate ARGS` embedded with capture and written with writePoints, against the executable's
// `generate ARGS -o FILE`: the same bytes.
void expectHandedBackSetIsWhatTheExecutableWrites(const std::vector<std::string>& args) {
  TempDir dir;
  EmbeddedRun embedded = runEmbedded(concat({"generate"}, args), true);
  ASSERT_EQ(embedded.code, 0) << (embedded.error ? embedded.error->message : "");
  ASSERT_FALSE(embedded.error);
  ASSERT_TRUE(embedded.points);
  ASSERT_GT(embedded.points->size(), 0u);
  ASSERT_TRUE(writePoints(dir.file("embedded.ply"), *embedded.points));
  test::CommandResult cli = test::runDpoint(concat(concat({"generate"}, args), {"-o", dir.file("cli.ply")}));
  ASSERT_EQ(cli.exit_code, 0) << cli.err;
  EXPECT_TRUE(readFile(dir.file("embedded.ply")) == readFile(dir.file("cli.ply")));
}

TEST(CliEmbedded, generateHandsBackTheSetTheExecutableWrites) {
  expectHandedBackSetIsWhatTheExecutableWrites({"sierpinski", "--level", "5", "--quiet"});
}

TEST(CliEmbedded, handedBackSetIsColouredOffsetAndOrderedAsWritten) {
  expectHandedBackSetIsWhatTheExecutableWrites({"menger", "--level", "2", "--colors", "noise", "--offset",
                                                "6378137,-0.5,1e-3", "--order", "morton", "--quiet"});
}

// A bad value, wherever it is caught (CLI11, dpoint's validators, the command), is the
// executable's message and exit code, and nothing is printed.
TEST(CliEmbedded, badValueIsTheExecutablesUsageErrorAndPrintsNothing) {
  const std::vector<std::vector<std::string>> cases = {
      {"generate", "sierpinski", "--colors", "blue"},          // CLI11's IsMember
      {"generate", "sierpinski", "--level", "three"},          // CLI11's conversion
      {"generate", "mandelbrot2d", "--max-iter", "0"},         // dpoint's validator (cli_check.h)
      {"generate", "random2d", "--count", "10", "--offset", "1,2"},  // the command, before any work
  };
  for (const std::vector<std::string>& args : cases) {
    SCOPED_TRACE(args[2] + " " + args[3]);
    TempDir dir;
    StderrCapture err;
    EmbeddedRun embedded = runEmbedded(args, true);
    const std::string printed = err.text();
    EXPECT_EQ(printed, "");
    EXPECT_EQ(embedded.code, static_cast<int>(ExitCode::kUsage));
    ASSERT_TRUE(embedded.error);
    EXPECT_EQ(embedded.error->code, ExitCode::kUsage);
    EXPECT_FALSE(embedded.points);
    test::CommandResult cli = test::runDpoint(concat(args, {"-o", dir.file("x.ply")}));
    EXPECT_EQ(cli.exit_code, embedded.code);
    EXPECT_FALSE(embedded.error->message.empty());
    EXPECT_TRUE(contains(cli.err, embedded.error->message));
  }
}

TEST(CliEmbedded, unknownOptionIsNamedWithTheNearestOne) {
  TempDir dir;
  StderrCapture err;
  EmbeddedRun embedded = runEmbedded({"generate", "sierpinski", "--levle", "3"}, true);
  EXPECT_EQ(err.text(), "");
  ASSERT_TRUE(embedded.error);
  EXPECT_EQ(embedded.error->code, ExitCode::kUsage);
  EXPECT_TRUE(contains(embedded.error->message, "unknown option '--levle'; did you mean '--level'?"));
  test::CommandResult cli = test::runDpoint({"generate", "sierpinski", "--levle", "3", "-o", dir.file("x.ply")});
  EXPECT_EQ(cli.err, "dpoint: error: " + embedded.error->message + "\n");

  EmbeddedRun kind = runEmbedded({"generate", "sierpinsky"}, true);
  ASSERT_TRUE(kind.error);
  EXPECT_TRUE(contains(kind.error->message, "did you mean 'sierpinski'?"));
  EmbeddedRun none = runEmbedded({}, true);
  ASSERT_TRUE(none.error);
  EXPECT_EQ(none.code, static_cast<int>(ExitCode::kUsage));
  EXPECT_TRUE(contains(none.error->message, "name a command (commands: generate, merge"));
}

// -o is required of the executable (and of a run that does not capture), refused with capture, as
// are the other options that say how or where the set is written.
TEST(CliEmbedded, writingOptionsAreRequiredWithoutCaptureAndRefusedWithIt) {
  TempDir dir;
  EmbeddedRun uncaptured = runEmbedded({"generate", "sierpinski", "--level", "2"}, false);
  ASSERT_TRUE(uncaptured.error);
  EXPECT_EQ(uncaptured.code, static_cast<int>(ExitCode::kUsage));
  EXPECT_TRUE(contains(uncaptured.error->message, "--output is required"));
  struct Case {
    std::vector<std::string> extra;
    const char* message;
  };
  const std::vector<Case> cases = {
      {{"-o", dir.file("x.ply")}, "hands the points back to its caller instead of writing them"},
      {{"--tile", "0/2"}, "--tile 0/2: a tile is a part file for dpoint merge"},
      {{"--decimals", "3"}, "--decimals 3 says how a CSV is written"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.extra[0]);
    EmbeddedRun run = runEmbedded(concat({"generate", "sierpinski", "--level", "2", "--quiet"}, c.extra), true);
    ASSERT_TRUE(run.error);
    EXPECT_EQ(run.code, static_cast<int>(ExitCode::kUsage));
    EXPECT_TRUE(contains(run.error->message, c.message));
    EXPECT_FALSE(run.points);
  }
  EXPECT_FALSE(fileExists(dir.file("x.ply")));
  // Without capture the same run writes its file, as the executable does.
  EmbeddedRun written = runEmbedded({"generate", "sierpinski", "--level", "2", "--quiet", "-o", dir.file("y.ply")}, false);
  EXPECT_EQ(written.code, 0);
  EXPECT_FALSE(written.points);
  EXPECT_TRUE(fileExists(dir.file("y.ply")));
}

TEST(CliEmbedded, runsAgainAndAgainInOneProcess) {
  const std::vector<std::string> args = {"generate", "random2d", "--count", "1000", "--seed", "7", "--quiet"};
  EmbeddedRun first = runEmbedded(args, true);
  EmbeddedRun failed = runEmbedded({"generate", "random2d", "--count", "0"}, true);
  EmbeddedRun second = runEmbedded(args, true);
  ASSERT_TRUE(first.points);
  ASSERT_TRUE(second.points);
  EXPECT_TRUE(first.points->positions == second.points->positions);
  EXPECT_TRUE(failed.error);
  EXPECT_FALSE(second.error) << "an earlier run's error stays with it";
  EXPECT_FALSE(capturingPoints()) << "the capture ends with the run";
  EmbeddedRun help = runEmbedded({"generate", "sierpinski", "--help"}, true);
  EXPECT_EQ(help.code, 0);
  EXPECT_FALSE(help.error);
}

TEST(CliEmbedded, benchChildrenAreDpointExecutableWhenSet) {
  ::unsetenv("DPOINT_EXECUTABLE");
  EXPECT_EQ(dpointExecutable(), "/proc/self/exe");
  {
    ScopedEnv empty("DPOINT_EXECUTABLE", "");
    EXPECT_EQ(dpointExecutable(), "/proc/self/exe");
  }
  {
    ScopedEnv set("DPOINT_EXECUTABLE", DPOINT_EXE);
    EXPECT_EQ(dpointExecutable(), DPOINT_EXE);
  }
}

// The bench embedded, as dpoint.bench() runs it: its first child is the program named by
// $DPOINT_EXECUTABLE (here a script that records its arguments and fails), not this test binary.
TEST(CliEmbedded, embeddedBenchRunsItsChildrenFromDpointExecutable) {
  TempDir dir;
  const std::string fake = dir.file("fake-dpoint");
  test::writeFile(fake, "#!/bin/sh\nprintf '%s\\n' \"$*\" > '" + dir.file("arguments") + "'\nexit 7\n");
  ASSERT_EQ(::chmod(fake.c_str(), 0755), 0);
  ScopedEnv set("DPOINT_EXECUTABLE", fake);
  EmbeddedRun run = runEmbedded({"bench", "--suite", "ci", "--device", "cpu", "--no-copy-bandwidth", "--quiet",
                                 "--out", dir.file("out"), "--cache", dir.file("cache")},
                                false);
  ASSERT_TRUE(run.error);
  EXPECT_TRUE(contains(run.error->message, "failed (exit 7)"));
  EXPECT_TRUE(contains(readFile(dir.file("arguments")), "--quiet"));
}

}  // namespace
}  // namespace dpoint
