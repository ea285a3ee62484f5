// A `dpoint` run: the app with every subcommand, parsed and run, with one top-level catch that
// turns failures into exit codes; and the same run embedded, its errors and points captured.
#include "cli/cli_run.h"

#include <cassert>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <regex>
#include <utility>

#include "cli/cli_check.h"
#include "cli/cli_suggest.h"
#include "cli/commands.h"
#include "cli/version.h"
#include "core/interrupt.h"
#include "core/text.h"

namespace dpoint {
namespace {

// The runEmbedded in progress on this thread, if any. Thread-local, so the commands (which run on
// the caller's thread) find it without every add*Command and finish() taking a parameter for it.
struct Capture {
  bool points_wanted = false;
  std::optional<Error> error;
  std::optional<PointSet> points;
};
thread_local Capture* t_capture = nullptr;

// Set by runDpoint: the process is the executable's, and ends with this run.
bool g_executable = false;

// A word that is a whole number in exponent form ("1e6", "2.5e3") as its digits ("1000000"), so
// that a count takes what a size does; any other word (1e-9, a path, 1e3,0,0) is left as it is.
// Below 2^53 the digits are the same number for an option of any type.
std::string wholeNumberWord(const std::string& word) {
  static const std::regex kExponent(R"(^\+?[0-9]+(\.[0-9]+)?[eE]\+?[0-9]+$)");
  if (!std::regex_match(word, kExponent)) return word;
  const double v = std::strtod(word.c_str(), nullptr);
  if (!(v < 9007199254740992.0) || v != std::floor(v)) return word;
  return std::to_string(static_cast<uint64_t>(v));
}

int runAppUnguarded(int argc, const char* const* argv_in) {
  std::vector<std::string> words(argv_in, argv_in + argc);
  for (size_t i = 1; i < words.size(); ++i) words[i] = wholeNumberWord(words[i]);
  std::vector<const char*> argv_words;
  for (const std::string& w : words) argv_words.push_back(w.c_str());
  const char* const* argv = argv_words.data();
  CLI::App app{"dpoint: double-precision point datasets. Generate fractal and test sets, convert between\n"
               "CSV and text exports (PTS, PTX), PLY, PCD, GLB, LAS, LAZ, COPC and E57, render them offscreen\n"
               "with Vulkan in seven precision modes, and inspect the precision a dataset needs.\n"
               "Exit codes: 0 ok, 1 usage, 2 bad input, 3 no usable Vulkan device, 4 resource limit,\n"
               "130/143 stopped by SIGINT/SIGTERM (the output is not written).",
               "dpoint"};
  app.set_version_flag("--version", "dpoint " DPOINT_VERSION);
  app.require_subcommand(1);
  RunCommand run;
  addGenerateCommand(app, run);
  addMergeCommand(app, run);
  addConvertCommand(app, run);
  addRenderCommand(app, run);
  addInfoCommand(app, run);
  addDevicesCommand(app, run);
  addBenchCommand(app, run);
  // `dpoint` alone: the command list, as a usage error (exit 1), like `git` alone.
  if (argc < 2) {
    if (t_capture) return reportError(Error{missingCommandMessage(app), ExitCode::kUsage});
    std::printf("%s", app.help().c_str());
    return static_cast<int>(ExitCode::kUsage);
  }
  // A mistyped command or kind is named with the nearest one, before CLI11 calls it a missing
  // subcommand or an unexpected argument.
  if (std::optional<std::string> unknown = unknownCommandMessage(app, argc, argv))
    return reportError(Error{*unknown, ExitCode::kUsage});
  try {
    app.parse(argc, argv);
  } catch (const UsageError& e) {  // a value one of dpoint's own validators refused (cli_check.h)
    return reportError(Error{e.what(), ExitCode::kUsage});
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() != 0) {
      // An unknown option is what went wrong whatever CLI11 calls it ("not expected", "a subcommand
      // is required"): it is named with the nearest known one.
      if (std::optional<std::string> unknown = unknownOptionMessage(app, argc, argv))
        return reportError(Error{*unknown, ExitCode::kUsage});
      return reportError(Error{usageMessage(e, app, argc, argv), ExitCode::kUsage});
    }
    int code = app.exit(e);  // prints help, version or the usage error
    return code == 0 ? 0 : static_cast<int>(ExitCode::kUsage);
  }
  const int code = run ? run() : static_cast<int>(ExitCode::kUsage);
  // A run cut short by SIGINT/SIGTERM exits 128 + signal whatever error the cut caused.
  return code != 0 && interrupted() ? 128 + interruptSignal() : code;
}

// The one top-level catch: nothing thrown while the app is built, parsed or run reaches main (or
// the Python module) as an exception; each becomes the house error with its exit code.
int runApp(int argc, const char* const* argv) {
  try {
    return runAppUnguarded(argc, argv);
  } catch (const std::bad_alloc&) {
    return reportError(Error{"out of memory", ExitCode::kResourceLimit});
  } catch (const UsageError& e) {
    return reportError(Error{e.what(), ExitCode::kUsage});
  } catch (const std::exception& e) {
    return reportError(Error{std::string("internal error: ") + e.what(), ExitCode::kBadInput});
  } catch (...) {
    return reportError(Error{"internal error: an unknown exception", ExitCode::kBadInput});
  }
}

}  // namespace

int reportError(const Error& error) {
  if (t_capture) {
    if (!t_capture->error) t_capture->error = error;
    return static_cast<int>(error.code);
  }
  // One line whatever the message quotes (a file name with a newline in it): control bytes as \xNN,
  // but for the indented lines of a message made so (bench's quote of a failed child's errors).
  std::string line;
  for (size_t i = 0; i < error.message.size(); ++i) {
    const char c = error.message[i];
    const unsigned char u = static_cast<unsigned char>(c);
    if (c == '\n' && error.message.compare(i + 1, 2, "  ") == 0) {
      line += c;
    } else if (u < 0x20 || u == 0x7f) {
      appendHexByte(line, u);
    } else {
      line += c;
    }
  }
  std::fprintf(stderr, "dpoint: error: %s\n", line.c_str());
  noteErrorReported();
  return static_cast<int>(error.code);
}

int runDpoint(int argc, char** argv) {
  g_executable = true;
  return runApp(argc, argv);
}

bool runningAsExecutable() { return g_executable && !t_capture; }

void exitProcessNow(int code) {
  std::fflush(nullptr);
  std::_Exit(code);
}

EmbeddedRun runEmbedded(const std::vector<std::string>& args, bool capture_points) {
  std::vector<const char*> argv = {"dpoint"};
  for (const std::string& a : args) argv.push_back(a.c_str());
  Capture capture;
  capture.points_wanted = capture_points;
  // Set for this call only, also when the run throws.
  struct Scope {
    Capture* outer;
    ~Scope() { t_capture = outer; }
  } scope{std::exchange(t_capture, &capture)};
  EmbeddedRun result;
  result.code = runApp(static_cast<int>(argv.size()), argv.data());
  result.error = std::move(capture.error);
  // Every failure path reports; should one not, the caller still gets an error with the code.
  if (result.code != 0 && !result.error)
    result.error = Error{"dpoint failed (exit " + std::to_string(result.code) + ")", static_cast<ExitCode>(result.code)};
  if (result.code == 0) result.points = std::move(capture.points);
  return result;
}

bool capturingPoints() { return t_capture && t_capture->points_wanted; }

void capturePoints(PointSet points) {
  assert(capturingPoints());
  t_capture->points = std::move(points);
}

std::string dpointExecutable() {
  const char* set = std::getenv("DPOINT_EXECUTABLE");
  return set && *set ? set : "/proc/self/exe";
}

}  // namespace dpoint
