// dpoint generate KIND -o OUT: the datasets of the study (DESIGN §8).
// Parsing and reporting only; every generator is a library function, and what is done to its
// points after it is cli/cli_generate_output.h over generators/generate.h.
#include <sys/stat.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

#include "cli/cli_check.h"
#include "cli/cli_device.h"
#include "cli/cli_generate_output.h"
#include "cli/cli_output.h"
#include "cli/cli_text.h"
#include "cli/commands.h"
#include "core/atomic_file.h"
#include "generators/generate.h"
#include "generators/julia.h"
#include "generators/mandelbrot2d.h"
#include "generators/mandelbulb.h"
#include "generators/menger.h"
#include "generators/random2d.h"
#include "generators/sierpinski.h"

namespace dpoint {
namespace {

// "a,b,c" → exactly `count` finite doubles; the error names the flag and the text.
Status parseBounds(const std::string& text, double& lo, double& hi) {
  Result<std::vector<double>> bounds = parseNumbers("--bounds", text, 2);
  if (!bounds) return bounds.error();
  lo = (*bounds)[0];
  hi = (*bounds)[1];
  // Each a finite double, their span not (a review finding: -1e308,1e308 wrote NaN and infinite
  // positions that no reader takes back).
  if (!std::isfinite(hi - lo))
    return Error{"--bounds " + text + ": HI - LO is beyond the largest double; give a range whose width is finite",
                 ExitCode::kUsage};
  return okStatus();
}

// Which file is at a path (device, inode, whether a regular file), to tell a file a run made
// (renamed into place: a new inode) from one that was there before it; none where nothing is.
struct FileIdentity {
  dev_t device;
  ino_t inode;
  bool regular;
  bool operator==(const FileIdentity&) const = default;
};
std::optional<FileIdentity> fileIdentity(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) return std::nullopt;
  return FileIdentity{st.st_dev, st.st_ino, S_ISREG(st.st_mode)};
}

template <typename Params, typename Options>
void registerKind(RunCommand& run, const std::shared_ptr<Options>& o, CLI::App* cmd, bool auto_noise,
                  Result<PointSet> (*generate)(const Params&),
                  Result<PointTile> (*generate_tile)(const Params&, TileSpec),
                  Result<Params> (*makeParams)(const Options&, Progress*),
                  PointFunction (*made)(const Params&) = nullptr) {
  cmd->callback([o, &run, cmd, auto_noise, generate, generate_tile, makeParams, made, name = cmd->get_name()] {
    const std::string signature = o->out.tile.empty() ? std::string() : tileSignature(name, cmd->config_to_str(true, false));
    auto inner = [o, auto_noise, generate, generate_tile, makeParams, made, name, signature] {
      if (Status s = checkHandedBack(o->out); !s) return reportError(s.error());
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
      if (tile) {
        if constexpr (requires { params->noise_colors; }) {
          // Meshed on the device, the tile's part file too is written as it is made, from its rows.
          if (params->mesher.mesh && canStreamRows(o->out, PointOrder::kInput, auto_noise)) {
            const bool noise_made = coloursAtWrite(o->out, auto_noise);
            Result<std::unique_ptr<TileRowStream>> stream = tileRowStream(o->out, *tile, signature, noise_made, progress);
            if (!stream) return reportError(stream.error());
            if (*stream) {
              params->noise_colors = noise_made;
              params->rows = tileRowSink(**stream);
              Result<PointTile> generated = generate_tile(*params, *tile);
              if ((*stream)->rows().started()) return finishTileRows(std::move(generated), **stream, o->out, clock);
              stream->reset();  // not taken (an empty share, a mesh made on the host): its file goes
              return finishTile(std::move(generated), o->out, auto_noise, signature, progress);
            }
          }
        }
        return finishTile(generate_tile(*params, *tile), o->out, auto_noise, signature, progress);
      }
      if (made && canFinishMade(o->out, auto_noise)) return finishMade(made(*params), o->out, *order, auto_noise, progress, clock);
      bool noise_made = false;
      if constexpr (requires { params->noise_colors; }) {
        // Marching cubes on the device makes the colours written too, where they are the noise's.
        noise_made = params->noise_colors = params->mesher.mesh && coloursAtWrite(o->out, auto_noise);
        // Meshed on the device, the surface can go to the file as it is made, as the device's rows.
        if (params->mesher.mesh && canStreamRows(o->out, *order, auto_noise)) {
          Result<std::unique_ptr<PlyRowStream>> stream = rowStream(o->out, noise_made, progress);
          if (!stream) return reportError(stream.error());
          if (*stream) {
            params->rows = rowSink(**stream);
            Result<PointSet> generated = generate(*params);
            if ((*stream)->started()) return finishRows(std::move(generated), **stream, o->out, clock);
            return finish(std::move(generated), o->out, *order, auto_noise, progress, clock, noise_made);
          }
        }
      }
      return finish(generate(*params), o->out, *order, auto_noise, progress, clock, noise_made);
    };
    // --grid-out: never the output itself; and a grid this run wrote goes again when the run fails
    // after it (the output could not be written, a stop), so a failed run leaves nothing.
    run = [o, inner] {
      std::string grid;
      if constexpr (requires { o->params.grid_out; }) grid = o->params.grid_out;
      if (grid.empty()) return inner();
      if (Status s = checkNotAlso("--grid-out", grid, {{"-o", o->out.output}}); !s) return reportError(s.error());
      const std::optional<FileIdentity> before = fileIdentity(grid);
      const int code = inner();
      // Only a regular file the run put there (never a pipe, a device or the link to one, which a
      // grid is written through, as a review found /dev/stdout removed so).
      if (code != 0)
        if (const std::optional<FileIdentity> now = fileIdentity(grid); now && now->regular && now != before)
          std::remove(grid.c_str());
      return code;
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
  if (Status s = checkMeshDevice(o.device, device->get()); !s) return s.error();
  if (*device) {
    const EscapeKernelParams kernel{EscapeKernel::kMandelbulbFast, glm::dvec4(0.0), 0.0, kMandelbulbAxisRho2,
                                    kMandelbulbTrapC2};
    p.planes = (*device)->planes(kernel, GridAxis{p.resolution, p.lo, p.hi});
    p.arena = (*device)->arena();
    if (meshOnDevice(o.device, device->get())) p.mesher = (*device)->mesher(kernel);
  }
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
  if (Status s = checkMeshDevice(o.device, device->get()); !s) return s.error();
  if (*device) {
    const EscapeKernelParams kernel{EscapeKernel::kJulia, p.c, kJuliaEscapeSquare, 0.0};
    p.planes = (*device)->planes(kernel, GridAxis{p.resolution, p.lo, p.hi});
    p.arena = (*device)->arena();
    if (meshOnDevice(o.device, device->get())) p.mesher = (*device)->mesher(kernel);
  }
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
  std::string max_iter = "auto";
  GenerateDeviceOptions device;
  OutputOptions out;
};

// --max-iter of mandelbrot2d: a whole number ≥ 1, or auto (empty).
Result<std::optional<int>> parseMaxIter(const std::string& text) {
  if (text == "auto") return std::optional<int>();
  int value = 0;
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, value);
  if (error != std::errc() || stop != end || value < 1)
    return Error{"--max-iter " + text + ": must be a whole number from 1 to 2147483647, or auto", ExitCode::kUsage};
  return std::optional<int>(value);
}

constexpr const char* kMaxIterAutoHelp =
    "Iterations before a point counts as inside: a whole number, or auto (the default): max(2000, 50*d^2) with\n"
    "d = log10(4 / width), the zoom depth (2000 down to width 1.9e-6, 2179 at 1e-6, 7941 at 1e-12,\n"
    "12171 at 1e-15); generate says which it chose";

Result<Mandelbrot2dParams> mandelbrot2dParams(const Mandelbrot2dOptions& o, Progress* progress) {
  Mandelbrot2dParams p = o.params;
  Result<std::vector<double>> c = parseNumbers("--center", o.center, 2);
  if (!c) return c.error();
  p.center_x = (*c)[0];
  p.center_y = (*c)[1];
  Result<std::optional<int>> max_iter = parseMaxIter(o.max_iter);
  if (!max_iter) return max_iter.error();
  p.max_iter = *max_iter;
  if (!p.max_iter) {
    Result<int> chosen = mandelbrot2dMaxIter(p);  // also checks the other parameters
    if (!chosen) return chosen.error();
    if (!o.out.common.quiet)
      std::fprintf(stderr, "dpoint: mandelbrot2d --max-iter auto: %d at --width %s\n", *chosen,
                   formatNumber(p.width).c_str());
  }
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
      ->check(positiveNumber("--level"));
  cmd->add_option("--bounds", bounds, "Grid range LO,HI on every axis")->default_val("-1.5,1.5");
  cmd->add_option("--frame", frame, "Coordinates: native (the fractal's own) or seed (grid corner at 0, as the original study's Python generator had it from skimage)")
      ->check(oneOf("--frame", {"native", "seed"}))
      ->default_val("native");
  cmd->add_option("--grid-out", grid_out, "Also write the raw escape-count grid (uint8 if max_iter <= 255, else uint16)")
      ->check(checkStatus(AtomicFile::checkTarget));
}

}  // namespace

void addGenerateCommand(CLI::App& app, RunCommand& run) {
  CLI::App* generate = app.add_subcommand("generate", "Generate a dataset: the fractal and random sets of the float-vs-double Vulkan study (README)");
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
  mandelbulb->add_option("--variant", mb->variant, "seed: the original study's Python generator's trigonometric escape function, bit for bit; "
                                                   "fast: trig-free power-8 form")
      ->check(oneOf("--variant", {"seed", "fast"}))
      ->default_val("seed");
  addGenerateDeviceOptions(*mandelbulb, mb->device,
                           "--variant seed always runs on the CPU (libm's trigonometry has no bit-exact shader form):\n"
                           "auto gives it the CPU, an explicit device is an error");
  addEscapeCountsOption(*mandelbulb, mb->device);
  addOutputOptions(*mandelbulb, mb->out, "noise");
  addSampleOptions(*mandelbulb, mb->out.sample);
  registerKind(run, mb, mandelbulb, true, &generateMandelbulb, &generateMandelbulbTile, &mandelbulbParams);

  auto ju = std::make_shared<JuliaOptions>();
  CLI::App* julia = generate->add_subcommand("julia", "Quaternion Julia set surface (the original study's Python iteration, k = 0 slice)");
  addEscapeGridOptions(julia, ju->params.resolution, ju->params.max_iter, ju->params.level, ju->bounds, ju->frame,
                       ju->params.grid_out, 200);
  julia->add_option("--c", ju->c, "Julia constant as 4 numbers")->default_val("-0.7,0.27015,0.27015,0");
  addGenerateDeviceOptions(*julia, ju->device, "");
  addEscapeCountsOption(*julia, ju->device);
  addOutputOptions(*julia, ju->out, "noise");
  addSampleOptions(*julia, ju->out.sample);
  registerKind(run, ju, julia, true, &generateJulia, &generateJuliaTile, &juliaParams);

  auto me = std::make_shared<MengerOptions>();
  CLI::App* menger = generate->add_subcommand("menger", "Menger sponge: exposed faces of its 20^n cubes");
  menger->add_option("--level", me->params.level, "Subdivision level (0..8)")->default_val(4);
  menger->add_option("--size", me->params.size, "Edge length of the sponge")->default_val(1.0);
  menger->add_option("--method", me->method, "exact: the exposed faces of the lattice cubes; voxel: sampled grid + "
                                             "marching cubes, as the original study's Python generator did")
      ->check(oneOf("--method", {"exact", "voxel"}))
      ->default_val("exact");
  menger->add_option("--resolution", me->params.resolution, "Voxel method: samples per axis (2..4096)")->default_val(200);
  addOutputOptions(*menger, me->out, "noise");
  addSampleOptions(*menger, me->out.sample);
  registerKind(run, me, menger, true, &generateMenger, &generateMengerTile, &mengerParams);

  auto si = std::make_shared<PlainOptions<SierpinskiParams>>();
  CLI::App* sierpinski = generate->add_subcommand("sierpinski", "Sierpinski tetrahedron: 4^n tetrahedra from the original study's Python generator's corners");
  sierpinski->add_option("--level", si->params.level, "Subdivision level (0..12)")->default_val(9);
  sierpinski->add_flag("--unwelded", si->params.unwelded, "The original study's Python generator's 4^(n+1) rows instead of the 2*4^n+2 distinct vertices");
  addOutputOptions(*sierpinski, si->out, "noise");
  addSampleOptions(*sierpinski, si->out.sample);
  registerKind(run, si, sierpinski, true, &generateSierpinski, &generateSierpinskiTile,
               &plainParams<SierpinskiParams>);

  auto r = std::make_shared<PlainOptions<Random2dParams>>();
  CLI::App* random2d = generate->add_subcommand(
      "random2d", "N points uniform in [-1,1)^2 (z = 0); identical on every machine and thread count. Into a .ply\n"
                  "the points are made as the rows are written: no memory held for them (--order morton: 24 bytes a point)");
  random2d->add_option("--count,-n", r->params.count, "Number of points")
      ->default_val(1000000)
      ->check(CLI::Range(uint64_t{1}, uint64_t{1} << 40));
  random2d->add_option("--seed", r->params.seed, "Seed of the generator")->default_val(1)->check(wholeNumber64("--seed"));
  addOutputOptions(*random2d, r->out, "none");
  // Written to a .ply, its points are made as the rows are written (finishMade): no array of them.
  registerKind(run, r, random2d, false, &generateRandom2d, &generateRandom2dTile, &plainParams<Random2dParams>,
               +[](const Random2dParams& p) {
                 return PointFunction{p.count, [seed = p.seed](uint64_t i) { return random2dPoint(seed, i); }};
               });

  auto m2 = std::make_shared<Mandelbrot2dOptions>();
  CLI::App* mandelbrot2d = generate->add_subcommand(
      "mandelbrot2d", "2D Mandelbrot deep zoom: a resolution^2 grid coloured by smooth escape count (perturbation)");
  mandelbrot2d->add_option("--center", m2->center, "View centre X,Y")->default_val("-0.7436450,0.1318259");
  mandelbrot2d->add_option("--width", m2->params.width, "View width")->default_val(1e-6);
  mandelbrot2d->add_option("--resolution", m2->params.resolution, "Points per side (2..65536)")->default_val(1024);
  mandelbrot2d->add_option("--max-iter", m2->max_iter, kMaxIterAutoHelp)
      ->check(checkStatus([](const std::string& text) { return statusOf(parseMaxIter(text)); }))
      ->default_val("auto");
  addGenerateDeviceOptions(*mandelbrot2d, m2->device,
                           "On a device: the perturbation deltas (the reference orbit stays on the CPU)");
  mandelbrot2d->add_option("--grid-out", m2->params.grid_out,
                           "Also write the escape counts, row-major (uint8 if max_iter <= 255, else uint16)")
      ->check(checkStatus(AtomicFile::checkTarget));
  addOutputOptions(*mandelbrot2d, m2->out, "smooth escape count, histogram-equalised over the view");
  registerKind(run, m2, mandelbrot2d, false, &generateMandelbrot2d, &generateMandelbrot2dTile, &mandelbrot2dParams);
}

}  // namespace dpoint
