// The options the subcommands share (commands.h). reportError is in cli_run.cpp, beside the
// embedded run it answers to.
#include "cli/commands.h"

#include "cli/cli_check.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "core/text.h"

namespace dpoint {

void addCommonOptions(CLI::App& command, CommonOptions& options) {
  command.add_option("--threads", options.threads, "Worker threads (0: all cores; at most 4096)")
      ->default_val(0)
      ->check(numberIn("--threads", 0, kMostThreads, false, ""));
  command.add_flag("--quiet,-q", options.quiet, "No progress or report lines (warnings and errors still print)");
}

void addMaxMemoryOption(CLI::App& command, std::string& text) {
  command.add_option("--max-memory", text,
                     "Refuse (exit 4) work whose memory, estimated before allocating, is above this, e.g. 512M, 8G "
                     "(default: half of RAM)");
}

void addColumnsOption(CLI::App& command, std::string& text) {
  command.add_option("--columns", text,
                     "Text input: what each column holds, e.g. x,y,z,-,intensity: x, y, z, r, g, b (red, green, blue),\n"
                     "- to skip a column, any other name a dimension; a header line is then passed over");
}

std::vector<std::string> columnsOf(const std::string& text) {
  if (text.empty()) return {};
  return splitAt(text, ',');
}

void addSampleOptions(CLI::App& command, SampleCliOptions& options) {
  command.add_option("--sample", options.count,
                     "Mesh: write N points on its surface (uniform by area; colours, normals and a glTF base-colour "
                     "texture interpolated) instead of its vertices");
  addChoiceOption(command, "--sample-method", options.method,
                  "uniform: independent points, uniform by area; poisson: an even sample (weighted sample "
                  "elimination from 5N uniform points, as Open3D's sample_points_poisson_disk); stratified: "
                  "each triangle its share of the points, spread evenly in it (as fast as uniform)",
                  {"uniform", "poisson", "stratified"});
  command.add_option("--sample-seed", options.seed, "Seed of --sample: the same seed gives the same points on any thread count")
      ->default_val(0)
      ->check(wholeNumber64("--sample-seed"));
}

SampleOptions sampleOptionsOf(const SampleCliOptions& options, unsigned threads, uint64_t max_memory, Progress* progress) {
  SampleOptions sample;
  sample.count = options.count;
  sample.method = *parseSampleMethod(options.method);  // checked by addSampleOptions' validator
  sample.seed = options.seed;
  sample.threads = threads;
  sample.max_memory = max_memory;
  sample.progress = progress;
  return sample;
}

Result<uint64_t> memoryLimitOf(const std::string& text) {
  if (text.empty()) return uint64_t{0};
  return parseMemorySize("--max-memory", text);
}

}  // namespace dpoint
