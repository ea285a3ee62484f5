// dpoint generate KIND -o OUT: datasets of the study. random2d now; the fractals are issue #3.
#include <memory>

#include "cli/commands.h"
#include "converters/point_io.h"
#include "core/memory.h"
#include "generators/random2d.h"

namespace dpoint {
namespace {

struct OutputOptions {
  std::string output;
  int decimals = -1;
  std::string max_memory;
  CommonOptions common;
};

void addOutputOptions(CLI::App& cmd, OutputOptions& o) {
  cmd.add_option("-o,--output", o.output, "Output file (.csv, .ply, .glb); written whole or not at all")->required();
  cmd.add_option("--decimals", o.decimals, "CSV: fixed digits after the point (default: shortest round trip)")
      ->check(CLI::Range(0, 100));
  cmd.add_option("--max-memory", o.max_memory, "Refuse (exit 4) when the estimate is above this (default: half of RAM)");
  addCommonOptions(cmd, o.common);
}

struct Random2dOptions {
  uint64_t count = 1000000;
  uint64_t seed = 1;
  OutputOptions out;
};

int runRandom2d(const Random2dOptions& o) {
  Progress progress(progressSink(o.out.common.quiet), "random2d");
  Random2dParams params;
  params.count = o.count;
  params.seed = o.seed;
  params.threads = o.out.common.threads;
  params.progress = &progress;
  if (!o.out.max_memory.empty()) {
    Result<uint64_t> limit = parseMemorySize("--max-memory", o.out.max_memory);
    if (!limit) return reportError(limit.error());
    params.max_memory = *limit;
  }
  Result<PointSet> points = generateRandom2d(params);
  if (!points) return reportError(points.error());
  WriteOptions w;
  w.threads = o.out.common.threads;
  w.decimals = o.out.decimals;
  w.progress = &progress;
  if (Status s = writePoints(o.out.output, *points, w); !s) return reportError(s.error());
  return 0;
}

}  // namespace

void addGenerateCommand(CLI::App& app, RunCommand& run) {
  CLI::App* generate = app.add_subcommand("generate", "Generate a dataset of the study");
  generate->require_subcommand(1);

  auto r = std::make_shared<Random2dOptions>();
  CLI::App* random2d = generate->add_subcommand(
      "random2d", "N points uniform in [-1,1)^2 (z = 0); identical on every machine and thread count");
  random2d->add_option("--count,-n", r->count, "Number of points")->default_val(1000000)->check(CLI::Range(uint64_t{1}, uint64_t{1} << 40));
  random2d->add_option("--seed", r->seed, "Seed of the generator")->default_val(1);
  addOutputOptions(*random2d, r->out);
  random2d->callback([r, &run] { run = [r] { return runRandom2d(*r); }; });
}

}  // namespace dpoint
