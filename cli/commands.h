// Subcommands of the dpoint executable. Each add*Command registers its options on the app and,
// when the subcommand is chosen, stores in `run` the action that does the work and returns the
// exit code (DESIGN §1: 0 ok, 1 usage, 2 bad input, 3 no Vulkan device, 4 resource limit).
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

#include "core/result.h"
#include "ops/mesh_sample.h"

namespace dpoint {

using RunCommand = std::function<int()>;

void addInfoCommand(CLI::App& app, RunCommand& run);
void addConvertCommand(CLI::App& app, RunCommand& run);
void addGenerateCommand(CLI::App& app, RunCommand& run);
void addBenchCommand(CLI::App& app, RunCommand& run);
void addRenderCommand(CLI::App& app, RunCommand& run);
void addDevicesCommand(CLI::App& app, RunCommand& run);
void addMergeCommand(CLI::App& app, RunCommand& run);

// Prints "dpoint: error: <message>" on stderr and returns the error's exit code; inside
// runEmbedded (cli_run.h) it prints nothing and hands the first error to the caller instead.
int reportError(const Error& error);

// Options every long-running command shares.
struct CommonOptions {
  unsigned threads = 0;
  bool quiet = false;
};
void addCommonOptions(CLI::App& command, CommonOptions& options);

// --max-memory SIZE for commands that size memory from their input or options; `text` stays
// empty when it is not given. memoryLimitOf: 0 (the default, half of RAM) or the bytes.
void addMaxMemoryOption(CLI::App& command, std::string& text);
Result<uint64_t> memoryLimitOf(const std::string& text);

// --columns x,y,z,-,intensity for commands that read text point files (CsvReadOptions::columns);
// columnsOf: its names, none when it is not given.
void addColumnsOption(CLI::App& command, std::string& text);
std::vector<std::string> columnsOf(const std::string& text);

// --sample N, --sample-method, --sample-seed: points on a mesh's surface (`convert` of a mesh,
// `generate` of a mesh kind). count 0: not asked for.
struct SampleCliOptions {
  uint64_t count = 0;
  std::string method = "uniform";
  uint64_t seed = 0;
};
void addSampleOptions(CLI::App& command, SampleCliOptions& options);
// The sampler's options (the method was checked by addSampleOptions' validator).
SampleOptions sampleOptionsOf(const SampleCliOptions& options, unsigned threads, uint64_t max_memory, Progress* progress);

}  // namespace dpoint
