// The options the subcommands share (commands.h). reportError is in cli_run.cpp, beside the
// embedded run it answers to.
#include "cli/commands.h"

#include "core/memory.h"
#include "core/text.h"

namespace dpoint {

void addCommonOptions(CLI::App& command, CommonOptions& options) {
  command.add_option("--threads", options.threads, "Worker threads (0: all cores)")->default_val(0);
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

Result<uint64_t> memoryLimitOf(const std::string& text) {
  if (text.empty()) return uint64_t{0};
  return parseMemorySize("--max-memory", text);
}

}  // namespace dpoint
