// A whole `dpoint` run as a function: what main() does, and the same run embedded in another
// program (the Python module), which gets the errors, and generate's points, back instead of
// printed and written. One parser, one set of checks and messages for both.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/point_set.h"
#include "core/result.h"

namespace dpoint {

// `dpoint ARGV[1..]` as the executable runs it: parses, runs the command, prints, returns the exit
// code. main() calls watchInterrupts() first; this does not.
int runDpoint(int argc, char** argv);

// What runEmbedded gives back.
struct EmbeddedRun {
  int code = 0;                    // the exit code the executable would give
  std::optional<Error> error;      // the first error reported; set whenever code != 0
  std::optional<PointSet> points;  // generate's finished set, with capture_points and code 0
};

// Runs `dpoint ARGS` (ARGS without the program name) in this process, on the calling thread, as
// the executable would: the same parser, checks and messages. Differences:
// - Nothing that reportError would print is printed: the first error comes back in `error`, with
//   its ExitCode as `code` (a later one, e.g. a failed clean-up after it, is dropped). CLI11's own
//   parse errors come back as Error{CLI11's message, kUsage}, a mistyped option or kind as the
//   executable's "did you mean" line; no command at all is kUsage "name a command (commands: …)".
// - --help and --version print their text on stdout and give code 0, no error.
// - With capture_points, `generate KIND` hands its finished set (after --colors, --offset, --order)
//   back in `points` instead of writing it, and -o is not required. What says how or where the set
//   is written is refused then, as a usage error that says so: -o, --tile, --decimals (a refusal
//   rather than a silent no-op, so a caller never believes a file was written or a CSV rounded).
//   --grid-out still writes its escape-count grid: it is a second output, not the set.
//   Other commands run as without capture_points.
// - Progress, notes and generate's time line go to stderr as usual (--quiet silences them).
// Never calls watchInterrupts() (SIGINT stays the embedding program's); may be called any number
// of times in one process: each call builds its own CLI11 app, and its capture (thread-local) ends
// with it.
EmbeddedRun runEmbedded(const std::vector<std::string>& args, bool capture_points);

// For the commands (cli/), not front ends: whether a runEmbedded with capture_points is running on
// this thread, and how generate hands its finished set to it.
bool capturingPoints();
void capturePoints(PointSet points);

// For the commands: whether this run is the executable's own (runDpoint, from main), so that the
// process ends with the command. False in an embedded run, which is one call among others.
bool runningAsExecutable();

// Ends the executable's process now with `code`, stdout and stderr flushed, leaving the rest of
// the teardown (the Vulkan device, the set's memory) to the kernel, as at any process's end. For a
// command that has written and printed everything, and only when runningAsExecutable().
[[noreturn]] void exitProcessNow(int code);

// The executable `dpoint bench` runs for its datasets and timed draws: $DPOINT_EXECUTABLE when
// set and not empty (a process that embeds dpoint is not itself dpoint: the Python module sets it
// to a built `dpoint`), else /proc/self/exe, this very executable.
std::string dpointExecutable();

}  // namespace dpoint
