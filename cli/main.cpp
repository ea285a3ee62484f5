// dpoint: one executable, one subcommand per job. Parsing and printing only; the work is in
// the libraries. One top-level catch turns failures into exit codes.
#include <cstdio>
#include <new>

#include "cli/cli_check.h"
#include "cli/cli_suggest.h"
#include "cli/commands.h"
#include "cli/version.h"
#include "core/interrupt.h"
#include "core/memory.h"

namespace dpoint {

int reportError(const Error& error) {
  std::fprintf(stderr, "dpoint: error: %s\n", error.message.c_str());
  noteErrorReported();
  return static_cast<int>(error.code);
}

void addCommonOptions(CLI::App& command, CommonOptions& options) {
  command.add_option("--threads", options.threads, "Worker threads (0: all cores)")->default_val(0);
  command.add_flag("--quiet,-q", options.quiet, "No progress output");
}

void addMaxMemoryOption(CLI::App& command, std::string& text) {
  command.add_option("--max-memory", text,
                     "Refuse (exit 4) work whose memory, estimated before allocating, is above this, e.g. 512M, 8G "
                     "(default: half of RAM)");
}

Result<uint64_t> memoryLimitOf(const std::string& text) {
  if (text.empty()) return uint64_t{0};
  return parseMemorySize("--max-memory", text);
}

}  // namespace dpoint

int main(int argc, char** argv) {
  using namespace dpoint;
  watchInterrupts();  // before any thread starts (core/interrupt.h)
  CLI::App app{"dpoint: double-precision point datasets. Generate fractal and test sets, convert between\n"
               "CSV, PLY, GLB and LAS, render them offscreen with Vulkan in six precision modes, and inspect the\n"
               "precision a dataset needs.\n"
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
    // An unknown option is what went wrong whatever CLI11 calls it ("not expected", "a subcommand
    // is required"): it is named with the nearest known one.
    if (e.get_exit_code() != 0)
      if (std::optional<std::string> unknown = unknownOptionMessage(app, argc, argv))
        return reportError(Error{*unknown, ExitCode::kUsage});
    int code = app.exit(e);  // prints help, version or the usage error
    return code == 0 ? 0 : static_cast<int>(ExitCode::kUsage);
  }
  try {
    const int code = run ? run() : static_cast<int>(ExitCode::kUsage);
    // A run cut short by SIGINT/SIGTERM exits 128 + signal whatever error the cut caused.
    return code != 0 && interrupted() ? 128 + interruptSignal() : code;
  } catch (const std::bad_alloc&) {
    return reportError(Error{"out of memory", ExitCode::kResourceLimit});
  } catch (const std::exception& e) {
    return reportError(Error{std::string("internal error: ") + e.what(), ExitCode::kBadInput});
  }
}
