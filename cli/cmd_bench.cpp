// dpoint bench io FILE: times reading (and optionally writing) a file inside one process, for
// the I/O benchmark in bench/ (which also times the whole process from outside).
#include <chrono>
#include <cstdio>
#include <memory>
#include <sys/stat.h>

#include "cli/commands.h"
#include "converters/point_io.h"

namespace dpoint {
namespace {

struct BenchIoOptions {
  std::string input, write;
  int decimals = -1;
  CommonOptions common;
};

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

uint64_t fileSize(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 ? static_cast<uint64_t>(st.st_size) : 0;
}

int runBenchIo(const BenchIoOptions& o) {
  auto t0 = std::chrono::steady_clock::now();
  Result<PointSet> points = readPoints(o.input, ReadOptions{o.common.threads, false, nullptr});
  if (!points) return reportError(points.error());
  const double read_s = secondsSince(t0);
  const double in_mb = static_cast<double>(fileSize(o.input)) / 1e6;
  std::printf("{\"points\": %zu, \"read_s\": %.4f, \"read_MBps\": %.1f", points->size(), read_s, in_mb / read_s);
  if (!o.write.empty()) {
    WriteOptions w;
    w.threads = o.common.threads;
    w.decimals = o.decimals;
    auto t1 = std::chrono::steady_clock::now();
    if (Status s = writePoints(o.write, *points, w); !s) return reportError(s.error());
    const double write_s = secondsSince(t1);
    const double out_mb = static_cast<double>(fileSize(o.write)) / 1e6;
    std::printf(", \"write_s\": %.4f, \"write_MBps\": %.1f", write_s, out_mb / write_s);
  }
  std::printf("}\n");
  return 0;
}

}  // namespace

void addBenchCommand(CLI::App& app, RunCommand& run) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks (the renderer's speed-vs-error matrix comes with the renderer)");
  bench->require_subcommand(1);
  auto o = std::make_shared<BenchIoOptions>();
  CLI::App* io = bench->add_subcommand("io", "Time reading a point file (and writing it with --write)");
  io->add_option("input", o->input, "Input file")->required();
  io->add_option("--write", o->write, "Also write the set to this file and time it");
  io->add_option("--decimals", o->decimals, "CSV output: fixed digits after the point")->check(CLI::Range(0, 100));
  addCommonOptions(*io, o->common);
  io->callback([o, &run] { run = [o] { return runBenchIo(*o); }; });
}

}  // namespace dpoint
