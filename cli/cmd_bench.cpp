// dpoint bench: the speed-against-error report (issue #10, DESIGN §5–7): suites of datasets drawn
// in every precision mode on each backend, timed and measured against the exact reference, written
// as report.md, results.json, speed_vs_error.svg, breakdown.svg and montage.png.
// dpoint bench io FILE: times reading (and optionally writing) a file inside one process, for
// the I/O benchmark in bench/ (which also times the whole process from outside).
// dpoint bench copy: only the device's copy bandwidth, the figure the report's bandwidth bound uses.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <unistd.h>
#include <csignal>
#include <ctime>
#include <memory>
#include <string_view>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include "bench/baseline.h"
#include "bench/report.h"
#include "bench/run.h"
#include "cli/cli_check.h"
#include "cli/cli_output.h"
#include "cli/cli_run.h"
#include "cli/commands.h"
#include "cli/version.h"
#include "converters/point_io.h"
#include "core/interrupt.h"
#include "core/memory.h"
#include "core/progress.h"
#include "viewer/render_job.h"

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
  // As convert's -o: writing over the input would replace the file being timed (a review finding).
  if (!o.write.empty())
    if (Status s = checkNotAlso("--write", o.write, {{"the input", o.input}}); !s) return reportError(s.error());
  auto t0 = std::chrono::steady_clock::now();
  Result<PointSet> points = readPoints(o.input, ReadOptions{o.common.threads, false, nullptr});
  if (!points) return reportError(points.error());
  const double read_s = secondsSince(t0);
  const double in_mb = static_cast<double>(fileSize(o.input)) / 1e6;
  // One line, printed whole at the end: an interrupted or failed write leaves none (a review
  // finding: half an object was left on stdout).
  char line[256];
  std::snprintf(line, sizeof line, "{\"points\": %zu, \"read_s\": %.4f, \"read_MBps\": %.1f", points->size(), read_s,
                in_mb / read_s);
  std::string json = line;
  if (!o.write.empty()) {
    WriteOptions w;
    w.threads = o.common.threads;
    w.decimals = o.decimals;
    auto t1 = std::chrono::steady_clock::now();
    if (Status s = writePoints(o.write, *points, w); !s) return reportError(s.error());
    const double write_s = secondsSince(t1);
    const double out_mb = static_cast<double>(fileSize(o.write)) / 1e6;
    std::snprintf(line, sizeof line, ", \"write_s\": %.4f, \"write_MBps\": %.1f", write_s, out_mb / write_s);
    json += line;
  }
  std::printf("%s}\n", json.c_str());
  return 0;
}

struct BenchReportOptions {
  std::string suite = "ci", out = "bench-out", cache = "bench-cache", device = "auto", backend = "both";
  std::vector<std::string> sizes;
  uint32_t frames = 20;
  std::string warmup = "300ms";  // passed to every timed `dpoint render` (parseWarmup)
  bool validate = false, no_error = false, no_copy_bandwidth = false;
  std::string copy_bytes = "auto";
  uint32_t copy_repeats = 10;
  std::string baseline;  // an earlier results.json to compare with; empty: none
  CommonOptions common;
};

struct BenchCopyOptions {
  std::string device = "auto";
  std::string copy_bytes = "auto";
  uint32_t copy_repeats = 10;
  bool validate = false;
  CommonOptions common;
};

extern "C" char** environ;

// An unlinked file for a child's stderr (closed on exec, so the child holds it only as its fd 2);
// -1 where the temporary folder takes no O_TMPFILE, and the child then writes to ours.
int openChildErrors() {
  const char* folder = std::getenv("TMPDIR");
  return ::open(folder && *folder ? folder : "/tmp", O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
}

// The last `limit` bytes a child wrote to its stderr, each line indented by two spaces.
std::string childErrors(int fd, size_t limit = 4096) {
  struct stat info{};
  if (fd < 0 || ::fstat(fd, &info) != 0 || info.st_size <= 0) return {};
  const off_t from = info.st_size > static_cast<off_t>(limit) ? info.st_size - static_cast<off_t>(limit) : 0;
  std::string text(static_cast<size_t>(info.st_size - from), '\0');
  const ssize_t got = ::pread(fd, text.data(), text.size(), from);
  text.resize(got > 0 ? static_cast<size_t>(got) : 0);
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  std::string indented;
  for (size_t start = 0; start < text.size();) {
    const size_t end = std::min(text.find('\n', start), text.size());
    indented += "\n  " + text.substr(start, end - start);
    start = end + 1;
  }
  return indented;
}

// `dpoint ARGS` run as a child process of dpointExecutable() (cli_run.h: this very executable, or
// $DPOINT_EXECUTABLE where dpoint is embedded): the bench's datasets and timed draws are exactly
// what a user's `dpoint generate` and `dpoint render` give.
Status runDpointChild(const std::vector<std::string>& args, unsigned threads) {
  std::vector<std::string> argv = {"dpoint"};
  argv.insert(argv.end(), args.begin(), args.end());
  if (threads) argv.insert(argv.end(), {"--threads", std::to_string(threads)});
  std::vector<char*> c_argv;
  for (std::string& a : argv) c_argv.push_back(a.data());
  c_argv.push_back(nullptr);
  std::string command;
  for (size_t i = 0; i + 1 < c_argv.size(); ++i) command += (i ? " " : "") + argv[i];
  // The child's report goes nowhere (the bench reads its --json). Its stderr is kept aside: the
  // warnings of a run that succeeds are the bench's own cases (fp32 unbounded on a hard case, a
  // set that covers little of the picture) and would bury the bench's progress; a run that fails
  // has them in the bench's error.
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  struct ErrorsFile {
    int fd = openChildErrors();
    ~ErrorsFile() {
      if (fd >= 0) ::close(fd);
    }
  } errors;
  if (errors.fd >= 0) posix_spawn_file_actions_adddup2(&actions, errors.fd, STDERR_FILENO);
  // The child starts with no signal blocked (ours are, for the interrupt watcher), and dies with
  // us: it gets SIGTERM if the bench is killed (core/interrupt.h, kParentPidVariable).
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t none;
  sigemptyset(&none);
  posix_spawnattr_setsigmask(&attributes, &none);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK);
  std::vector<std::string> environment = {std::string(kParentPidVariable) + "=" + std::to_string(getpid())};
  for (char** e = environ; *e; ++e)
    if (std::string_view(*e).rfind(std::string(kParentPidVariable) + "=", 0) != 0) environment.emplace_back(*e);
  std::vector<char*> c_environment;
  for (std::string& e : environment) c_environment.push_back(e.data());
  c_environment.push_back(nullptr);
  if (interrupted()) return interruptedError();
  pid_t pid = 0;
  const std::string executable = dpointExecutable();
  const int spawned = posix_spawn(&pid, executable.c_str(), &actions, &attributes, c_argv.data(), c_environment.data());
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  if (spawned != 0)
    return Error{"cannot run " + command + " (" + executable + "): " + std::strerror(spawned), ExitCode::kBadInput};
  // An interrupt is forwarded to the child, which stops and exits 130/143 like any dpoint run.
  registerChildProcess(pid);
  if (interrupted()) ::kill(pid, interruptSignal());  // came before the registration
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      unregisterChildProcess(pid);
      return Error{"waiting for " + command + ": " + std::strerror(errno), ExitCode::kBadInput};
    }
  }
  unregisterChildProcess(pid);
  if (interrupted()) return interruptedError();
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return okStatus();
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return Error{command + " failed (exit " + std::to_string(code) + ")" + childErrors(errors.fd),
               code == static_cast<int>(ExitCode::kResourceLimit) ? ExitCode::kResourceLimit : ExitCode::kBadInput};
}

// --copy-bytes: auto (0: the device's default) or a size such as 64M or 1GiB.
Result<uint64_t> parseCopyBytes(const std::string& text) {
  return text == "auto" ? Result<uint64_t>(uint64_t{0}) : parseMemorySize("--copy-bytes", text);
}

std::string utcNow() {
  std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

// The command as a user would type it to get this run again, every setting spelled out.
std::string commandLine(const BenchReportOptions& o) {
  std::string s = "dpoint bench --suite " + o.suite + " --backend " + o.backend + " --device " + o.device +
                  " --frames " + std::to_string(o.frames) + " --warmup " + o.warmup;
  if (!o.sizes.empty()) {
    s += " --sizes ";
    for (size_t i = 0; i < o.sizes.size(); ++i) s += (i ? "," : "") + o.sizes[i];
  }
  if (o.no_error) s += " --no-error";
  if (o.no_copy_bandwidth) s += " --no-copy-bandwidth";
  else {
    if (o.copy_bytes != "auto") s += " --copy-bytes " + o.copy_bytes;
    if (o.copy_repeats != 10) s += " --copy-repeats " + std::to_string(o.copy_repeats);
  }
  return s + " --out " + o.out + " --cache " + o.cache;
}

// Validation messages fail the run, after everything else was reported.
int failOnValidationMessages(const VulkanContext& context) {
  const std::vector<std::string>& messages = context.validationMessages();
  if (messages.empty()) return 0;
  for (const std::string& m : messages) std::fprintf(stderr, "dpoint: %s\n", m.c_str());
  return reportError(Error{std::to_string(messages.size()) + " Vulkan validation message(s)", ExitCode::kNoDevice});
}

int runBenchReport(const BenchReportOptions& o) {
  // The default --out is checked here, when bench runs, not while the command line is built: a
  // folder no other command writes must not stop them (CLI11 validates a default_val at once).
  if (Status s = checkOutputFolder("--out", o.out); !s) return reportError(Error{s.error().message, ExitCode::kUsage});
  // The cache as --out: a file given as it, or a place it cannot be made, is a usage error before any work.
  if (Status s = checkOutputFolder("--cache", o.cache); !s) return reportError(Error{s.error().message, ExitCode::kUsage});
  std::optional<Baseline> baseline;  // read before the run: a bad file fails at once, not after it
  if (!o.baseline.empty()) {
    Result<Baseline> read = readBaseline(o.baseline);
    if (!read) return reportError(read.error());
    baseline = std::move(*read);
  }
  BenchOptions options;
  if (o.suite == "ci") options.suites = {BenchSuite::kCi};
  else if (o.suite == "paper") options.suites = {BenchSuite::kPaper};
  else if (o.suite == "hard") options.suites = {BenchSuite::kHard};
  else if (o.suite == "all") options.suites = {BenchSuite::kPaper, BenchSuite::kHard};
  else return reportError(Error{"--suite " + o.suite + ": must be ci, paper, hard or all", ExitCode::kUsage});
  if (o.backend == "raster") options.backends = {Backend::kRaster};
  else if (o.backend == "compute") options.backends = {Backend::kCompute};
  else if (o.backend == "both") options.backends = {Backend::kRaster, Backend::kCompute};
  else return reportError(Error{"--backend must be raster, compute or both, got '" + o.backend + "'", ExitCode::kUsage});
  if (o.frames == 0) return reportError(Error{"--frames 0: must be at least 1", ExitCode::kUsage});
  if (!o.sizes.empty()) {
    if (o.suite != "paper" && o.suite != "all")
      return reportError(Error{"--sizes picks datasets of the paper suite; --suite is " + o.suite, ExitCode::kUsage});
    const std::vector<BenchCase> paper = suiteCases(BenchSuite::kPaper);
    std::string known;
    for (const BenchCase& c : paper)
      if (known.find(" " + c.size_label + ",") == std::string::npos) known += " " + c.size_label + ",";
    for (const std::string& size : o.sizes) {
      if (std::none_of(paper.begin(), paper.end(), [&](const BenchCase& c) { return hasSizeLabel(c, size); }))
        return reportError(Error{"--sizes: the paper suite has no dataset of size '" + size + "' (it has" +
                                     known.substr(0, known.size() - 1) + ")", ExitCode::kUsage});
    }
  }
  options.sizes = o.sizes;
  options.frames = o.frames;
  options.warmup = *parseWarmup("--warmup", o.warmup);
  options.measure_error = !o.no_error;
  options.cache_dir = o.cache;
  const unsigned threads = o.common.threads;
  options.device = o.device;
  options.validate = o.validate;
  options.measure_copy_bandwidth = !o.no_copy_bandwidth;
  Result<uint64_t> copy_bytes = parseCopyBytes(o.copy_bytes);
  if (!copy_bytes) return reportError(copy_bytes.error());
  options.copy.bytes = *copy_bytes;
  options.copy.copies = o.copy_repeats;
  options.run_dpoint = [threads](const std::vector<std::string>& args) { return runDpointChild(args, threads); };
  std::FILE* sink = progressSink(o.common.quiet);
  if (sink) options.log = [sink](const std::string& line) { std::fprintf(sink, "bench: %s\n", line.c_str()); };

  Result<std::unique_ptr<VulkanContext>> context = VulkanContext::create(ContextOptions{o.device, o.validate});
  if (!context) return reportError(context.error());
  Result<BenchRun> run = runBench(**context, options);
  if (!run) return reportError(run.error());
  const std::vector<CheckFailure> failures = checkRun(*run);
  ReportContext report{commandLine(o), utcNow(), DPOINT_VERSION, std::nullopt};
  if (baseline) report.baseline = compareToBaseline(*run, *baseline);
  Result<std::vector<std::string>> written = writeReport(*run, report, failures, o.out);
  if (!written) return reportError(written.error());

  size_t skipped = 0;
  for (const BenchRow& row : run->rows) skipped += !row.skipped.empty();
  std::printf("bench: %zu runs (%zu cases, %zu did not run) on %s in %.0f s\n", run->rows.size(), run->cases.size(), skipped,
              run->device.name.c_str(), run->seconds);
  for (const std::string& path : *written) std::printf("wrote %s\n", path.c_str());
  if (!failures.empty()) std::fprintf(stderr, "dpoint: warning: %zu check(s) failed; see report.md\n", failures.size());
  if (report.baseline) {
    const BaselineReport& b = *report.baseline;
    std::printf("bench: against %s: %zu of %zu rows more than 5%% slower\n", b.path.c_str(), b.slower(), b.rows.size());
    // A baseline of other cases compares nothing: said, so that a check of it cannot pass unseen.
    if (b.rows.empty())
      std::fprintf(stderr,
                   "dpoint: warning: %s: no timed row of this run (its case, backend and mode) is in the baseline "
                   "(%zu timed rows there): nothing was compared; record a baseline of this --suite and --sizes\n",
                   b.path.c_str(), baseline->rows.size());
    for (const BaselineComparison& c : b.rows)
      if (c.slower)
        std::fprintf(stderr, "dpoint: warning: %s %s %s: %.4g ms against the baseline's %.4g ms (%.2fx)\n",
                     c.case_name.c_str(), c.backend.c_str(), c.mode.c_str(), c.now_ms, c.baseline_ms, c.ratio());
    if (!b.same_device)
      std::fprintf(stderr, "dpoint: warning: the baseline ran on %s, this run on %s\n",
                   b.device.empty() ? "a device it does not name" : b.device.c_str(), run->device.name.c_str());
  }
  return failOnValidationMessages(**context);
}

int runBenchCopy(const BenchCopyOptions& o) {
  Result<uint64_t> bytes = parseCopyBytes(o.copy_bytes);
  if (!bytes) return reportError(bytes.error());
  Result<std::unique_ptr<VulkanContext>> context = VulkanContext::create(ContextOptions{o.device, o.validate});
  if (!context) return reportError(context.error());
  Result<CopyBandwidth> copy = measureCopyBandwidth(**context, CopyBandwidthOptions{*bytes, o.copy_repeats, 1});
  if (!copy) return reportError(copy.error());
  std::printf("%s: copy bandwidth %s\n", (*context)->facts.name.c_str(), copyBandwidthText(*copy).c_str());
  return failOnValidationMessages(**context);
}

}  // namespace

void addBenchCommand(CLI::App& app, RunCommand& run) {
  CLI::App* bench = app.add_subcommand(
      "bench",
      "The speed-against-error report: every precision mode on both backends over a suite of datasets, timed\n"
      "(GPU timestamps) and measured against the exact reference. Writes report.md, results.json and\n"
      "speed_vs_error.svg into --out, with breakdown.svg (the sweeps) and montage.png (its error maps) where\n"
      "the run measured them; an earlier run's files there are replaced. Datasets are made once with\n"
      "`dpoint generate` into --cache and reused. Suites: ci (small, minutes on lavapipe), paper (the\n"
      "float-vs-double Vulkan study's datasets at 1920x1080, its RTX 3090 figures beside ours), hard (offset\n"
      "and deep-zoom sweeps, tiny, origin, degenerate), all (paper and hard).\n"
      "Each dataset and timed draw is a child process of this executable, or of $DPOINT_EXECUTABLE when set\n"
      "(a program that embeds dpoint, such as the Python module, points it at a built dpoint).\n"
      "`dpoint bench io FILE` times reading a file instead; `dpoint bench copy` measures only the copy bandwidth.");
  bench->require_subcommand(0, 1);
  auto r = std::make_shared<BenchReportOptions>();
  bench->add_option("--suite", r->suite, "ci, paper, hard or all")->default_val("ci");
  bench->add_option("--out", r->out, "Folder for the report (created; files in it replaced)")
      ->check(checkStatus([](const std::string& v) { return checkOutputFolder("--out", v); }))
      ->default_str("bench-out");  // shown, not validated here: the default is checked when bench runs
  bench->add_option("--cache", r->cache, "Folder the datasets are made in and reused from (created)")
      ->check(checkStatus([](const std::string& v) { return checkOutputFolder("--cache", v); }))
      ->default_str("bench-cache");  // as --out's: the default is checked when bench runs
  bench->add_option("--device", r->device, "auto (a discrete GPU if any, else lavapipe), cpu, or an index from `dpoint devices`")
      ->default_val("auto");
  bench->add_option("--backend", r->backend, "raster, compute or both")->default_val("both");
  bench->add_option("--frames", r->frames, "Timed frames per run (the median is reported)")->default_val(20);
  bench->add_option("--warmup", r->warmup,
                    "Untimed frames before each timed draw's: a duration (300ms, 0.5s: frames until that much time has\n"
                    "passed, at least one), a count (2), or auto (as `dpoint render`)")
      ->check(checkStatus([](const std::string& v) { return statusOf(parseWarmup("--warmup", v)); }))
      ->default_val("300ms");
  bench->add_option("--sizes", r->sizes, "paper suite: only these of the float-vs-double Vulkan study's sizes, e.g. 10K,1M,16.7M")->delimiter(',');
  bench->add_option("--baseline", r->baseline,
                    "An earlier run's results.json (bench/results/baselines/ has one per device class): rows more\n"
                    "than 5% slower than the same case, backend and mode there are marked in report.md and warned of");
  bench->add_flag("--no-error", r->no_error, "Time only: skip the probe draws and the exact reference (no error columns)");
  bench->add_flag("--validate", r->validate, "Enable the Khronos validation layer; any message fails the run");
  bench->add_flag("--no-copy-bandwidth", r->no_copy_bandwidth,
                  "Skip measuring the copy bandwidth (no bandwidth bound or % of bound in the report)");
  const char* copy_bytes_help =
      "Bytes per timed vkCmdCopyBuffer, e.g. 64M or 1G; auto: 1 GiB on a GPU, 256 MiB on a CPU device (capped by "
      "the device's allocation limit and a quarter of its memory)";
  const char* copy_repeats_help = "Timed copies (the median is reported), after one untimed";
  bench->add_option("--copy-bytes", r->copy_bytes, copy_bytes_help)->default_val("auto");
  bench->add_option("--copy-repeats", r->copy_repeats, copy_repeats_help)->check(CLI::Range(1u, 1000u))->default_val(10);
  addCommonOptions(*bench, r->common);
  auto o = std::make_shared<BenchIoOptions>();
  CLI::App* io = bench->add_subcommand("io", "Time reading a point file (and writing it with --write)");
  io->add_option("input", o->input, "Input file")->required();
  io->add_option("--write", o->write, "Also write the set to this file and time it")->check(checkStatus(checkPointOutput));
  io->add_option("--decimals", o->decimals, "CSV output: fixed digits after the point")->check(CLI::Range(0, 100));
  addCommonOptions(*io, o->common);
  io->callback([o, &run] { run = [o] { return runBenchIo(*o); }; });
  auto c = std::make_shared<BenchCopyOptions>();
  CLI::App* copy = bench->add_subcommand(
      "copy", "Measure only the device's copy bandwidth (device-local to device-local vkCmdCopyBuffer, GPU timestamps)");
  copy->add_option("--device", c->device, "auto, cpu, or an index from `dpoint devices`")->default_val("auto");
  copy->add_option("--copy-bytes", c->copy_bytes, copy_bytes_help)->default_val("auto");
  copy->add_option("--copy-repeats", c->copy_repeats, copy_repeats_help)->check(CLI::Range(1u, 1000u))->default_val(10);
  copy->add_flag("--validate", c->validate, "Enable the Khronos validation layer; any message fails the run");
  addCommonOptions(*copy, c->common);
  copy->callback([c, &run] { run = [c] { return runBenchCopy(*c); }; });
  bench->callback([bench, io, copy, r, &run] {
    if (!io->parsed() && !copy->parsed()) run = [r] { return runBenchReport(*r); };
  });
}

}  // namespace dpoint
