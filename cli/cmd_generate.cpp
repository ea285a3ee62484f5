// dpoint generate KIND -o OUT: the datasets of the study (DESIGN §8).
// Parsing and reporting only; every generator is a library function.
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <memory>
#include <optional>
#include <sstream>

#include "cli/cli_device.h"
#include "cli/cli_text.h"
#include "cli/commands.h"
#include "converters/point_io.h"
#include "core/memory.h"
#include "ops/point_order.h"
#include "converters/tile_file.h"
#include "generators/julia.h"
#include "generators/mandelbrot2d.h"
#include "generators/mandelbulb.h"
#include "generators/menger.h"
#include "generators/perlin.h"
#include "generators/random2d.h"
#include "generators/sierpinski.h"

namespace dpoint {
namespace {

// Options every generator shares: where the output goes and what is done to it after generation.
struct OutputOptions {
  std::string output;
  std::string tile;  // "I/N": write tile I of N (core/tile.h) instead of the whole set
  std::string colors = "auto";
  std::string offset;
  int decimals = -1;
  std::string max_memory;
  std::string order = "input";
  CommonOptions common;
};

void addOutputOptions(CLI::App& cmd, OutputOptions& o, const std::string& auto_colors) {
  cmd.add_option("-o,--output", o.output, "Output file (.csv, .ply, .glb); written whole or not at all")->required();
  cmd.add_option("--colors", o.colors, "Colours: auto (" + auto_colors + "), noise (the seed's pnoise3), none")
      ->check(CLI::IsMember({"auto", "noise", "none"}))
      ->default_val("auto");
  cmd.add_option("--offset", o.offset, "Translate every point by X,Y,Z (exact double sums, one rounding)");
  cmd.add_option("--decimals", o.decimals, "CSV: fixed digits after the point (default: shortest round trip)")
      ->check(CLI::Range(0, 100));
  addMaxMemoryOption(cmd, o.max_memory);
  cmd.add_option("--order", o.order, kPointOrderHelp)->default_val("input");
  cmd.add_option("--tile", o.tile,
                 "I/N: compute only tile I (from 0) of N of the set, into a .ply part that `dpoint merge` welds with\n"
                 "the others into the file one process writes, byte for byte (--order then goes to merge)");
  addCommonOptions(cmd, o.common);
}

// "a,b,c" → exactly `count` finite doubles; the error names the flag and the text.
Status parseBounds(const std::string& text, double& lo, double& hi) {
  Result<std::vector<double>> bounds = parseNumbers("--bounds", text, 2);
  if (!bounds) return bounds.error();
  lo = (*bounds)[0];
  hi = (*bounds)[1];
  return okStatus();
}

Result<uint64_t> memoryLimit(const OutputOptions& o) { return memoryLimitOf(o.max_memory); }

// Colours and offset: the steps after any generator that act point by point (a tile applies them
// to its own points and copies alike).
Status colorAndOffset(PointSet& points, const OutputOptions& o, bool auto_noise) {
  const bool noise = o.colors == "noise" || (o.colors == "auto" && auto_noise);
  if (o.colors == "none") points.colors.clear();
  if (noise) {
    Result<uint64_t> limit = memoryLimit(o);
    if (!limit) return limit.error();
    // The generators' own estimates cover positions and triangles; colours come on top.
    const uint64_t needed = points.size() * (sizeof(glm::dvec3) + sizeof(glm::vec3)) + points.triangles.size() * 4;
    if (Status s = checkMemory("colouring " + std::to_string(points.size()) + " points", needed, *limit); !s) return s;
    colorByNoise(points, o.common.threads);  // on the fractal's own coordinates, before the offset
  }
  if (!o.offset.empty()) {
    Result<std::vector<double>> offset = parseNumbers("--offset", o.offset, 3);
    if (!offset) return offset.error();
    const glm::dvec3 d((*offset)[0], (*offset)[1], (*offset)[2]);
    for (glm::dvec3& p : points.positions) p += d;
  }
  return okStatus();
}

// Seconds since `start`, and since the last call (the phases of the time line).
class PhaseClock {
 public:
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return s;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

std::string seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f", s);
  return text;
}

// Colours, offset, order and writing: the steps after any generator. Unless quiet, one line of
// where the time went (generation counted from `clock`'s start, before the parameters).
int finish(Result<PointSet> generated, const OutputOptions& o, PointOrder order, bool auto_noise, Progress& progress,
           PhaseClock& clock) {
  if (!generated) return reportError(generated.error());
  const double generate_s = clock.lap();
  PointSet& points = *generated;
  if (Status s = colorAndOffset(points, o, auto_noise); !s) return reportError(s.error());
  const double colours_s = clock.lap();
  if (order != PointOrder::kInput) {
    Result<uint64_t> limit = memoryLimit(o);
    if (!limit) return reportError(limit.error());
    const uint64_t needed = points.size() * (sizeof(glm::dvec3) + (points.hasColors() ? sizeof(glm::vec3) : 0)) +
                            points.triangles.size() * 4 + reorderExtraBytes(points.size(), order);
    if (Status s = checkMemory("ordering " + std::to_string(points.size()) + " points", needed, *limit); !s)
      return reportError(s.error());
    reorderPoints(points, order, o.common.threads, &progress);
  }
  const double order_s = clock.lap();
  WriteOptions w;
  w.threads = o.common.threads;
  w.decimals = o.decimals;
  w.progress = &progress;
  if (Status s = writePoints(o.output, points, w); !s) return reportError(s.error());
  if (!o.common.quiet)
    std::fprintf(stderr, "time (s): generate %s, colours and offset %s, order %s, write %s; %zu points, %zu triangles\n",
                 seconds(generate_s).c_str(), seconds(colours_s).c_str(), seconds(order_s).c_str(),
                 seconds(clock.lap()).c_str(), points.size(), points.triangles.size() / 3);
  return 0;
}

// A tile: colours and offset on its points, then its part file.
int finishTile(Result<PointTile> generated, const OutputOptions& o, bool auto_noise, const std::string& signature,
               Progress& progress) {
  if (!generated) return reportError(generated.error());
  if (Status s = colorAndOffset(generated->points, o, auto_noise); !s) return reportError(s.error());
  if (Status s = writeTile(o.output, *generated, signature, &progress); !s) return reportError(s.error());
  return 0;
}

// What makes two runs' tiles one dataset: the kind and every option that shapes the points, as
// CLI11 prints them (given or default), less those that only say where and how to run or write.
std::string tileSignature(const CLI::App& cmd) {
  static const std::vector<std::string> kIgnored = {"output", "tile", "threads", "quiet", "grid-out", "device",
                                                    "max-memory", "decimals", "order", "validate", "counts", "help"};
  std::istringstream lines(cmd.config_to_str(true, false));
  std::string line, signature = cmd.get_name();
  while (std::getline(lines, line)) {
    const std::string name = line.substr(0, line.find('='));
    if (line.empty() || std::find(kIgnored.begin(), kIgnored.end(), name) != kIgnored.end()) continue;
    signature += " " + line;
  }
  return signature;
}

// --tile checks before any work: a .ply part, and no --order (which needs the whole set).
Result<TileSpec> tileOptions(const OutputOptions& o) {
  Result<TileSpec> tile = parseTileSpec("--tile", o.tile);
  if (!tile) return tile.error();
  Result<FileFormat> format = formatOf(o.output);
  if (!format || *format != FileFormat::kPly)
    return Error{"--tile: -o " + o.output + ": a tile is written as .ply (dpoint merge makes the .ply, .csv or .glb)",
                 ExitCode::kUsage};
  if (o.order != "input")
    return Error{"--tile: --order " + o.order + " needs the whole set; give it to dpoint merge", ExitCode::kUsage};
  return tile;
}

// Checks the output path's extension before any work, so a typo does not cost a long run.
bool outputTypeOk(const OutputOptions& o, int& code) {
  Result<FileFormat> format = formatOf(o.output);
  if (format && *format != FileFormat::kGltf) return true;
  code = reportError(format ? Error{o.output + ": write .glb, not .gltf", ExitCode::kUsage} : format.error());
  return false;
}

template <typename Params, typename Options>
void registerKind(RunCommand& run, const std::shared_ptr<Options>& o, CLI::App* cmd, bool auto_noise,
                  Result<PointSet> (*generate)(const Params&),
                  Result<PointTile> (*generate_tile)(const Params&, TileSpec),
                  Result<Params> (*makeParams)(const Options&, Progress*)) {
  cmd->callback([o, &run, cmd, auto_noise, generate, generate_tile, makeParams, name = cmd->get_name()] {
    const std::string signature = o->out.tile.empty() ? std::string() : tileSignature(*cmd);
    run = [o, auto_noise, generate, generate_tile, makeParams, name, signature] {
      int code = 0;
      if (!outputTypeOk(o->out, code)) return code;
      Result<PointOrder> order = parsePointOrder("--order", o->out.order);
      if (!order) return reportError(order.error());
      std::optional<TileSpec> tile;
      if (!o->out.tile.empty()) {
        Result<TileSpec> spec = tileOptions(o->out);
        if (!spec) return reportError(spec.error());
        tile = *spec;
      }
      PhaseClock clock;
      Progress progress(progressSink(o->out.common.quiet), name);
      Result<Params> params = makeParams(*o, &progress);
      if (!params) return reportError(params.error());
      if (tile) return finishTile(generate_tile(*params, *tile), o->out, auto_noise, signature, progress);
      return finish(generate(*params), o->out, *order, auto_noise, progress, clock);
    };
  });
}

// Fills the shared fields of a generator's Params.
template <typename Params>
Result<Params> withCommon(Params p, const OutputOptions& out, Progress* progress) {
  Result<uint64_t> limit = memoryLimit(out);
  if (!limit) return limit.error();
  p.threads = out.common.threads;
  p.max_memory = *limit;
  p.progress = progress;
  return p;
}

// Kinds whose options are their Params plus the output options.
template <typename Params>
struct PlainOptions {
  Params params;
  OutputOptions out;
};
template <typename Params>
Result<Params> plainParams(const PlainOptions<Params>& o, Progress* progress) {
  return withCommon(o.params, o.out, progress);
}

// ---- mandelbulb ----
struct MandelbulbOptions {
  MandelbulbParams params;
  std::string bounds = "-1.5,1.5";
  std::string variant = "seed", frame = "native";
  GenerateDeviceOptions device;
  OutputOptions out;
};
constexpr const char* kSeedCpuOnly =
    "--variant seed runs on the CPU only: it calls libm's acos, atan2, sin, cos and pow, which no shader reproduces "
    "bit for bit (use --variant fast on a device)";
Result<MandelbulbParams> mandelbulbParams(const MandelbulbOptions& o, Progress* progress) {
  MandelbulbParams p = o.params;
  if (Status s = parseBounds(o.bounds, p.lo, p.hi); !s) return s.error();
  p.variant = o.variant == "fast" ? MandelbulbVariant::kFast : MandelbulbVariant::kSeed;
  p.frame = o.frame == "seed" ? GridFrame::kSeed : GridFrame::kNative;
  const bool seed = p.variant == MandelbulbVariant::kSeed;
  Result<std::shared_ptr<GenerateDevice>> device =
      GenerateDevice::open(o.device, "mandelbulb", seed ? kSeedCpuOnly : "", o.out.common.quiet);
  if (!device) return device.error();
  if (*device)
    p.planes = (*device)->planes({EscapeKernel::kMandelbulbFast, glm::dvec4(0.0), 0.0, kMandelbulbAxisRho2},
                                 GridAxis{p.resolution, p.lo, p.hi});
  p.full_counts = fullCounts(o.device, device->get());
  return withCommon(p, o.out, progress);
}

// ---- julia ----
struct JuliaOptions {
  JuliaParams params;
  std::string c = "-0.7,0.27015,0.27015,0";
  std::string bounds = "-1.5,1.5";
  std::string frame = "native";
  GenerateDeviceOptions device;
  OutputOptions out;
};
Result<JuliaParams> juliaParams(const JuliaOptions& o, Progress* progress) {
  JuliaParams p = o.params;
  Result<std::vector<double>> c = parseNumbers("--c", o.c, 4);
  if (!c) return c.error();
  p.c = glm::dvec4((*c)[0], (*c)[1], (*c)[2], (*c)[3]);
  if (Status s = parseBounds(o.bounds, p.lo, p.hi); !s) return s.error();
  p.frame = o.frame == "seed" ? GridFrame::kSeed : GridFrame::kNative;
  Result<std::shared_ptr<GenerateDevice>> device = GenerateDevice::open(o.device, "julia", "", o.out.common.quiet);
  if (!device) return device.error();
  if (*device)
    p.planes = (*device)->planes({EscapeKernel::kJulia, p.c, kJuliaEscapeSquare, 0.0}, GridAxis{p.resolution, p.lo, p.hi});
  p.full_counts = fullCounts(o.device, device->get());
  return withCommon(p, o.out, progress);
}

// ---- menger ----
struct MengerOptions {
  MengerParams params;
  std::string method = "exact";
  OutputOptions out;
};
Result<MengerParams> mengerParams(const MengerOptions& o, Progress* progress) {
  MengerParams p = o.params;
  p.method = o.method == "voxel" ? MengerMethod::kVoxel : MengerMethod::kExact;
  return withCommon(p, o.out, progress);
}

// ---- mandelbrot2d ----
struct Mandelbrot2dOptions {
  Mandelbrot2dParams params;
  std::string center = "-0.7436450,0.1318259";
  GenerateDeviceOptions device;
  OutputOptions out;
};
Result<Mandelbrot2dParams> mandelbrot2dParams(const Mandelbrot2dOptions& o, Progress* progress) {
  Mandelbrot2dParams p = o.params;
  Result<std::vector<double>> c = parseNumbers("--center", o.center, 2);
  if (!c) return c.error();
  p.center_x = (*c)[0];
  p.center_y = (*c)[1];
  Result<std::shared_ptr<GenerateDevice>> device =
      GenerateDevice::open(o.device, "mandelbrot2d", "", o.out.common.quiet);
  if (!device) return device.error();
  if (*device) p.perturbation = (*device)->perturbation();
  return withCommon(p, o.out, progress);
}

void addEscapeGridOptions(CLI::App* cmd, int& resolution, int& max_iter, double& level, std::string& bounds,
                          std::string& frame, std::string& grid_out, int default_iter) {
  cmd->add_option("--resolution", resolution, "Grid points per axis (2..65536)")->default_val(200);
  cmd->add_option("--max-iter", max_iter, "Iterations before a point counts as inside")->default_val(default_iter);
  cmd->add_option("--level", level, "Surface level on the escape-count field (default: max_iter/4)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--bounds", bounds, "Grid range LO,HI on every axis")->default_val("-1.5,1.5");
  cmd->add_option("--frame", frame, "Coordinates: native (the fractal's own) or seed (grid corner at 0, like skimage)")
      ->check(CLI::IsMember({"native", "seed"}))
      ->default_val("native");
  cmd->add_option("--grid-out", grid_out, "Also write the raw escape-count grid (uint8 if max_iter <= 255, else uint16)");
}

}  // namespace

void addGenerateCommand(CLI::App& app, RunCommand& run) {
  CLI::App* generate = app.add_subcommand("generate", "Generate a dataset of the study");
  // Optional for CLI11, so that an unknown kind is reported by name ("not expected: spiral")
  // rather than as "a subcommand is required"; no kind at all gets the list here.
  generate->require_subcommand(0, 1);
  generate->callback([generate, &run] {
    if (!generate->get_subcommands().empty()) return;
    run = [] {
      return reportError(Error{"generate: name a kind: mandelbulb, julia, menger, sierpinski, random2d, mandelbrot2d",
                               ExitCode::kUsage});
    };
  });

  auto mb = std::make_shared<MandelbulbOptions>();
  CLI::App* mandelbulb = generate->add_subcommand("mandelbulb", "Power-8 Mandelbulb surface (marching cubes on escape counts)");
  addEscapeGridOptions(mandelbulb, mb->params.resolution, mb->params.max_iter, mb->params.level, mb->bounds, mb->frame,
                       mb->params.grid_out, 100);
  mandelbulb->add_option("--power", mb->params.power, "Exponent of the Mandelbulb map")->default_val(8);
  mandelbulb->add_option("--variant", mb->variant, "seed: the study's trigonometric escape function, bit for bit; "
                                                   "fast: trig-free power-8 form")
      ->check(CLI::IsMember({"seed", "fast"}))
      ->default_val("seed");
  addGenerateDeviceOptions(*mandelbulb, mb->device,
                           "--variant seed always runs on the CPU (libm's trigonometry has no bit-exact shader form):\n"
                           "auto gives it the CPU, an explicit device is an error");
  addEscapeCountsOption(*mandelbulb, mb->device);
  addOutputOptions(*mandelbulb, mb->out, "noise");
  registerKind(run, mb, mandelbulb, true, &generateMandelbulb, &generateMandelbulbTile, &mandelbulbParams);

  auto ju = std::make_shared<JuliaOptions>();
  CLI::App* julia = generate->add_subcommand("julia", "Quaternion Julia set surface (the seed's iteration, k = 0 slice)");
  addEscapeGridOptions(julia, ju->params.resolution, ju->params.max_iter, ju->params.level, ju->bounds, ju->frame,
                       ju->params.grid_out, 200);
  julia->add_option("--c", ju->c, "Julia constant as 4 numbers")->default_val("-0.7,0.27015,0.27015,0");
  addGenerateDeviceOptions(*julia, ju->device, "");
  addEscapeCountsOption(*julia, ju->device);
  addOutputOptions(*julia, ju->out, "noise");
  registerKind(run, ju, julia, true, &generateJulia, &generateJuliaTile, &juliaParams);

  auto me = std::make_shared<MengerOptions>();
  CLI::App* menger = generate->add_subcommand("menger", "Menger sponge: exposed faces of its 20^n cubes");
  menger->add_option("--level", me->params.level, "Subdivision level (0..8)")->default_val(4);
  menger->add_option("--size", me->params.size, "Edge length of the sponge")->default_val(1.0);
  menger->add_option("--method", me->method, "exact: the exposed faces of the lattice cubes; voxel: sampled grid + "
                                             "marching cubes, as the seed did")
      ->check(CLI::IsMember({"exact", "voxel"}))
      ->default_val("exact");
  menger->add_option("--resolution", me->params.resolution, "Voxel method: samples per axis (2..4096)")->default_val(200);
  addOutputOptions(*menger, me->out, "noise");
  registerKind(run, me, menger, true, &generateMenger, &generateMengerTile, &mengerParams);

  auto si = std::make_shared<PlainOptions<SierpinskiParams>>();
  CLI::App* sierpinski = generate->add_subcommand("sierpinski", "Sierpinski tetrahedron: 4^n tetrahedra from the seed's corners");
  sierpinski->add_option("--level", si->params.level, "Subdivision level (0..12)")->default_val(9);
  sierpinski->add_flag("--unwelded", si->params.unwelded, "The seed's 4^(n+1) rows instead of the 2*4^n+2 distinct vertices");
  addOutputOptions(*sierpinski, si->out, "noise");
  registerKind(run, si, sierpinski, true, &generateSierpinski, &generateSierpinskiTile,
               &plainParams<SierpinskiParams>);

  auto r = std::make_shared<PlainOptions<Random2dParams>>();
  CLI::App* random2d = generate->add_subcommand(
      "random2d", "N points uniform in [-1,1)^2 (z = 0); identical on every machine and thread count");
  random2d->add_option("--count,-n", r->params.count, "Number of points")
      ->default_val(1000000)
      ->check(CLI::Range(uint64_t{1}, uint64_t{1} << 40));
  random2d->add_option("--seed", r->params.seed, "Seed of the generator")->default_val(1);
  addOutputOptions(*random2d, r->out, "none");
  registerKind(run, r, random2d, false, &generateRandom2d, &generateRandom2dTile, &plainParams<Random2dParams>);

  auto m2 = std::make_shared<Mandelbrot2dOptions>();
  CLI::App* mandelbrot2d = generate->add_subcommand(
      "mandelbrot2d", "2D Mandelbrot deep zoom: a resolution^2 grid coloured by escape count (perturbation when deep)");
  mandelbrot2d->add_option("--center", m2->center, "View centre X,Y")->default_val("-0.7436450,0.1318259");
  mandelbrot2d->add_option("--width", m2->params.width, "View width")->default_val(1e-6);
  mandelbrot2d->add_option("--resolution", m2->params.resolution, "Points per side (2..65536)")->default_val(1024);
  mandelbrot2d->add_option("--max-iter", m2->params.max_iter, "Iterations before a point counts as inside")->default_val(2000);
  addGenerateDeviceOptions(*mandelbrot2d, m2->device,
                           "On a device: the perturbation deltas (the reference orbit stays on the CPU)");
  mandelbrot2d->add_option("--grid-out", m2->params.grid_out,
                           "Also write the escape counts, row-major (uint8 if max_iter <= 255, else uint16)");
  addOutputOptions(*mandelbrot2d, m2->out, "escape count");
  registerKind(run, m2, mandelbrot2d, false, &generateMandelbrot2d, &generateMandelbrot2dTile, &mandelbrot2dParams);
}

}  // namespace dpoint
