// dpoint render and dpoint devices as a user runs them (on lavapipe in CI, validation layer on).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "converters/ply.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::readFile;
using test::runDpoint;
using test::TempDir;
using test::writeFile;

// The number after "key": in a JSON text written by dpoint (flat enough for a search).
double jsonNumber(const std::string& json, const std::string& key) {
  size_t at = json.find("\"" + key + "\": ");
  if (at == std::string::npos) return -1.0;
  return std::strtod(json.c_str() + at + key.size() + 4, nullptr);
}

TEST(CliRender, helpNamesEveryModeAndOption) {
  test::CommandResult help = runDpoint({"render", "--help"});
  EXPECT_EQ(help.exit_code, 0);
  for (const char* word : {"auto", "fp32", "split", "rte", "df64", "native", "batch", "adaptive", "--tolerance",
                           "--view-center", "--error", "--validate", "--frames", "--device", "lavapipe", "0.1 px"})
    EXPECT_NE(help.out.find(word), std::string::npos) << word;
  // The mode list comes from the mode table, laid out on lines of at most 102 characters.
  EXPECT_NE(help.out.find("Modes: fp32 (float positions), split (the study's hi+lo, no better than fp32), rte "
                          "(relative to eye),\ndf64 (double-float arithmetic), native (fp64 shaders), batch "
                          "(per-batch double origins), adaptive\n(per-batch tiers of 10 bits, as few as --tolerance "
                          "allows); all but fp32 and split work in a frame\nscaled to the view"),
            std::string::npos)
      << help.out;
  EXPECT_EQ(runDpoint({"devices", "--help"}).exit_code, 0);
}

TEST(CliRender, writesPngAndJsonWithEveryMeasurement) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "mandelbulb", "--resolution", "33", "--quiet", "-o", dir.file("mb.csv")}).exit_code, 0);
  test::CommandResult r = runDpoint({"render", dir.file("mb.csv"), "-o", dir.file("mb.png"), "--mode", "df64", "--error",
                                     "--validate", "--frames", "3", "--width", "320", "--height", "240", "--json",
                                     dir.file("mb.json")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(readFile(dir.file("mb.png")).substr(0, 8), "\x89PNG\r\n\x1a\n");
  const std::string json = readFile(dir.file("mb.json"));
  for (const char* key : {"mode", "backend", "device", "driver_version", "points", "width", "height", "gpu_ms", "median",
                          "p95", "e2e_ms", "points_per_s", "bytes_per_point", "error_px", "max", "p99", "rms",
                          "share_off_half_px", "pixels_differing"})
    EXPECT_NE(json.find(std::string("\"") + key + "\""), std::string::npos) << key << " in " << json;
  EXPECT_NE(json.find("\"mode\": \"df64\""), std::string::npos);
  EXPECT_NE(json.find("\"mode_requested\": \"df64\""), std::string::npos);
  EXPECT_GE(jsonNumber(json, "predicted_bound_px"), jsonNumber(json, "max")) << "the bound holds";
  EXPECT_EQ(jsonNumber(json, "bytes_per_point"), 28.0);
  EXPECT_EQ(jsonNumber(json, "width"), 320.0);
  EXPECT_GT(jsonNumber(json, "points_per_s"), 0.0);
  // Every timed frame, in order: three numbers for --frames 3.
  const size_t each_at = json.find("\"gpu_ms_each\": [");
  ASSERT_NE(each_at, std::string::npos) << json;
  const std::string each = json.substr(each_at, json.find(']', each_at) - each_at);
  EXPECT_EQ(std::count(each.begin(), each.end(), ','), 2) << each;
  EXPECT_LT(jsonNumber(json, "max"), 0.01);
  EXPECT_NE(r.out.find("error: max"), std::string::npos) << r.out;
  // Where the wall time went, step by step, and the peak memory (issue #11's time to a picture).
  const size_t phases_at = json.find("\"phases_ms\": {");
  ASSERT_NE(phases_at, std::string::npos) << json;
  const std::string phases = json.substr(phases_at, json.find('}', phases_at) - phases_at);
  for (const char* step : {"read", "camera", "device", "mode", "render", "error", "png"})
    EXPECT_GE(jsonNumber(phases, step), 0.0) << step << " in " << phases;
  EXPECT_GT(jsonNumber(phases, "render"), 0.0);
  EXPECT_GT(jsonNumber(json, "peak_rss_mb"), 1.0);
  EXPECT_NE(r.out.find("time to picture (ms): read "), std::string::npos) << r.out;
}

// DESIGN §7 offset, end to end: a generated fractal moved to the Earth's radius.
// --warmup auto (the default): a single picture is drawn once (no warm-up frame, said beside its
// time); with --frames above 1 frames are drawn untimed by time first (at least one), and --warmup N
// is kept. No assertion on how long anything took: only the counts the run reports.
TEST(CliRender, quietPrintsNothingButStillWritesThePictureAndReport) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "menger", "--level", "2", "--quiet", "-o", dir.file("m.ply")}).exit_code, 0);
  for (const char* views : {"1", "4"}) {
    test::CommandResult r = runDpoint({"render", dir.file("m.ply"), "-o", dir.file("m.png"), "--width", "96", "--height",
                                       "64", "--views", views, "--quiet"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out, "") << "--views " << views;
    EXPECT_EQ(r.err, "") << "--views " << views;
    EXPECT_TRUE(test::fileExists(dir.file("m.png")));
  }
  // Without --quiet the report is there (the same command).
  test::CommandResult loud = runDpoint({"render", dir.file("m.ply"), "-o", dir.file("m.png"), "--width", "96", "--height", "64"});
  EXPECT_NE(loud.out.find("time to picture"), std::string::npos) << loud.out;
}

TEST(CliRender, warmupAutoDrawsASinglePictureOnce) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "mandelbulb", "--resolution", "24", "--quiet", "-o", dir.file("mb.ply")}).exit_code, 0);
  auto gpuLine = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = {"render", dir.file("mb.ply"), "-o", dir.file("mb.png"), "--width", "64", "--height", "48"};
    args.insert(args.end(), extra.begin(), extra.end());
    const test::CommandResult r = runDpoint(args);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    const size_t at = r.out.find("gpu: ");
    return at == std::string::npos ? std::string() : r.out.substr(at, r.out.find('\n', at) - at);
  };
  EXPECT_NE(gpuLine({}).find("median of 1 (p95"), std::string::npos);
  EXPECT_NE(gpuLine({}).find(", no warm-up,"), std::string::npos) << gpuLine({});
  EXPECT_EQ(gpuLine({"--frames", "3"}).find("no warm-up"), std::string::npos);
  EXPECT_NE(gpuLine({"--warmup", "2"}).find(" after 2 warm-up frames in "), std::string::npos) << gpuLine({"--warmup", "2"});
  EXPECT_NE(gpuLine({"--frames", "3", "--warmup", "0"}).find("median of 3 (p95"), std::string::npos);
  EXPECT_NE(gpuLine({"--frames", "3", "--warmup", "0"}).find("no warm-up"), std::string::npos);
}

// The JSON's "warmup": the untimed frames that ran, their wall time and the time asked (null for a
// count), for a count, a duration in ms or s, and auto with several frames (by time: at least one).
TEST(CliRender, warmupByTimeOrCountIsReportedInTheJson) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "mandelbulb", "--resolution", "16", "--quiet", "-o", dir.file("mb.ply")}).exit_code, 0);
  auto warmupOf = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = {"render", dir.file("mb.ply"), "-o", dir.file("mb.png"), "--width", "32",
                                     "--height", "24", "--quiet", "--json", dir.file("mb.json")};
    args.insert(args.end(), extra.begin(), extra.end());
    const test::CommandResult r = runDpoint(args);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    const std::string json = readFile(dir.file("mb.json"));
    const size_t at = json.find("\"warmup\": {");
    return at == std::string::npos ? std::string() : json.substr(at, json.find('}', at) - at + 1);
  };
  const std::string single = warmupOf({});
  EXPECT_EQ(jsonNumber(single, "frames"), 0.0) << single;
  EXPECT_EQ(jsonNumber(single, "ms"), 0.0) << single;
  EXPECT_NE(single.find("\"until_ms\": null"), std::string::npos) << single;
  const std::string by_auto = warmupOf({"--frames", "2"});
  EXPECT_GE(jsonNumber(by_auto, "frames"), 1.0) << by_auto;
  EXPECT_GT(jsonNumber(by_auto, "ms"), 0.0) << by_auto;
  EXPECT_EQ(jsonNumber(by_auto, "until_ms"), 300.0) << by_auto;
  const std::string counted = warmupOf({"--warmup", "3"});
  EXPECT_EQ(jsonNumber(counted, "frames"), 3.0) << counted;
  EXPECT_NE(counted.find("\"until_ms\": null"), std::string::npos) << counted;
  const std::string timed = warmupOf({"--warmup", "0.02s"});
  EXPECT_GE(jsonNumber(timed, "frames"), 1.0) << timed;
  EXPECT_EQ(jsonNumber(timed, "until_ms"), 20.0) << timed;
  const std::string in_ms = warmupOf({"--warmup", "1.5ms", "--frames", "2"});
  EXPECT_GE(jsonNumber(in_ms, "frames"), 1.0) << in_ms;
  EXPECT_EQ(jsonNumber(in_ms, "until_ms"), 1.5) << in_ms;
}

// A value that is no count, no duration and not auto is a usage error naming the flag and the
// value, before anything is read or written; --help says what it takes.
TEST(CliRender, warmupRefusesWhatIsNeitherACountNorADuration) {
  TempDir dir;
  writeFile(dir.file("p.csv"), "x,y,z\n0,0,0\n1,1,1\n");
  for (const char* bad : {"1.5", "0ms", "0s", "10us", "fast", "-1", "", "3 ms", "1e3ms", "4294967296", "61s", "ms", "0.0001ms"}) {
    for (const char* command : {"render", "bench"}) {
      std::vector<std::string> args = {command, "--warmup", bad};
      if (std::string(command) == "render") args.insert(args.begin() + 1, {dir.file("p.csv"), "-o", dir.file("p.png")});
      else args.insert(args.end(), {"--out", dir.file("out"), "--cache", dir.file("cache")});
      const test::CommandResult r = runDpoint(args);
      EXPECT_EQ(r.exit_code, 1) << command << " --warmup '" << bad << "': " << r.err;
      EXPECT_NE(r.err.find(std::string("--warmup: '") + bad + "'"), std::string::npos) << r.err;
      EXPECT_FALSE(std::filesystem::exists(dir.file("p.png")) || std::filesystem::exists(dir.file("out")) ||
                   std::filesystem::exists(dir.file("cache")))
          << command << " --warmup '" << bad << "' wrote something";
    }
  }
  const test::CommandResult help = runDpoint({"render", "--help"});
  EXPECT_NE(help.out.find("a duration (300ms, 0.5s)"), std::string::npos) << help.out;
  EXPECT_NE(runDpoint({"bench", "--help"}).out.find("300ms"), std::string::npos);
}

TEST(CliRender, generatedFractalAtEarthRadiusShowsFloatFailing) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "mandelbulb", "--resolution", "33", "--offset", "6378137,0,0", "--quiet", "-o",
                       dir.file("far.ply")}).exit_code, 0);
  double max_px[2] = {0, 0};
  int i = 0;
  for (const char* mode : {"fp32", "native"}) {
    std::string json = dir.file(std::string(mode) + ".json");
    test::CommandResult r = runDpoint({"render", dir.file("far.ply"), "-o", dir.file("far.png"), "--mode", mode,
                                       "--error", "--validate", "--width", "256", "--height", "256", "--json", json});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    max_px[i++] = jsonNumber(readFile(json), "max");
  }
  EXPECT_GE(max_px[0], 1.0) << "fp32";
  EXPECT_LE(max_px[1], 0.01) << "native";
}

// A Mandelbulb moved to x = 1e18 (double's step there is 128) lies flat in that plane, 2 wide. The
// default perspective eye rounded into the plane and the picture showed nothing (exit 0, "the
// picture shows nothing"). It is drawn orthographic from the fit's direction now, in memory and
// streamed, and render and info say so.
TEST(CliRender, aSetFlatFarFromTheOriginIsDrawnAndTheReportsSayHow) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "mandelbulb", "--resolution", "20", "--offset", "1e18,0,0", "--quiet", "-o",
                       dir.file("flat.ply")}).exit_code, 0);
  for (const char* stream : {"off", "on"}) {
    SCOPED_TRACE(stream);
    const test::CommandResult r = runDpoint({"render", dir.file("flat.ply"), "-o", dir.file("flat.png"), "--stream", stream,
                                             "--width", "256", "--height", "192", "--json", dir.file("flat.json")});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(test::contains(r.err, "at coordinates up to 1e+18: too little for double to place a perspective eye"))
        << r.err;
    EXPECT_FALSE(test::contains(r.err, "shows nothing")) << r.err;
    EXPECT_GT(jsonNumber(readFile(dir.file("flat.json")), "drawn_share"), 0.05);
  }
  const test::CommandResult info = runDpoint({"info", dir.file("flat.ply")});
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_TRUE(test::contains(info.out, "orthographic, 744 points visible")) << info.out;
  EXPECT_TRUE(test::contains(info.out, "\nview note:          the data span (0, ")) << info.out;
  EXPECT_TRUE(test::contains(runDpoint({"info", dir.file("flat.ply"), "--json"}).out, "\"note\": \"the data span")) ;
}

// `dpoint info` predicts each mode's error for the view `dpoint render` draws with the same camera
// options: the outline-framed fit, from the z-up three-quarter direction for a survey (--up-axis
// auto: LAS) and from the y-up one otherwise or with --up-axis y. (Render fits again, a little
// farther, where a sparse set's default points would touch the edge; --point-size keeps its fit.)
TEST(CliRender, infoPredictsTheBoundRenderPrintsForTheSameView) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "mandelbulb", "--resolution", "33", "--offset", "6378137,0,0", "--quiet", "-o",
                       dir.file("far.ply")}).exit_code, 0);
  const std::string survey = std::string(DPOINT_CORPUS_DIR) + "/las/simple.las";
  struct Case {
    std::string input;
    std::vector<std::string> view;
  };
  for (const Case& c : {Case{dir.file("far.ply"), {}}, Case{survey, {}}, Case{survey, {"--up-axis", "y"}}}) {
    std::vector<std::string> info = {"info", c.input, "--width", "320", "--height", "240", "--json"};
    info.insert(info.end(), c.view.begin(), c.view.end());
    const test::CommandResult described = runDpoint(info);
    ASSERT_EQ(described.exit_code, 0) << described.err;
    const size_t bounds = described.out.find("\"error_bound_px\"");
    ASSERT_NE(bounds, std::string::npos) << described.out;
    for (const char* mode : {"rte", "batch"}) {  // fp32's is null (unbounded) at the Earth's radius
      SCOPED_TRACE(c.input + (c.view.empty() ? "" : " " + c.view[1]) + " " + mode);
      const double predicted = jsonNumber(described.out.substr(bounds), mode);
      std::vector<std::string> render = {"render", c.input, "-o", dir.file("r.png"), "--mode", mode, "--width", "320",
                                         "--height", "240", "--point-size", "3", "--json", dir.file("r.json")};
      render.insert(render.end(), c.view.begin(), c.view.end());
      const test::CommandResult drawn = runDpoint(render);
      ASSERT_EQ(drawn.exit_code, 0) << drawn.err;
      EXPECT_GT(predicted, 0.0);
      EXPECT_EQ(predicted, jsonNumber(readFile(dir.file("r.json")), "predicted_bound_px"));
    }
  }
}

// A review finding: `--json` naming the input replaced it by the report (exit 0), and naming -o
// replaced the picture. Both are usage errors now, before any work, and nothing is written.
TEST(CliRender, theReportIsNeitherTheInputNorThePicture) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "menger", "--level", "1", "--quiet", "-o", dir.file("m.ply")}).exit_code, 0);
  const std::string input = readFile(dir.file("m.ply"));
  test::CommandResult over_input = runDpoint({"render", dir.file("m.ply"), "-o", dir.file("m.png"), "--json", dir.file("m.ply")});
  EXPECT_EQ(over_input.exit_code, 1);
  EXPECT_NE(over_input.err.find("--json " + dir.file("m.ply") + ": is also an input"), std::string::npos) << over_input.err;
  EXPECT_TRUE(readFile(dir.file("m.ply")) == input);
  test::CommandResult over_picture =
      runDpoint({"render", dir.file("m.ply"), "-o", dir.file("m.png"), "--json", dir.file("./m.png")});
  EXPECT_EQ(over_picture.exit_code, 1);
  EXPECT_NE(over_picture.err.find("is also -o"), std::string::npos) << over_picture.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("m.png")));
}

// A review finding: --max-memory did not bound a streamed set (50M let a 5M-point stream peak at
// 590 MB). Streaming holds two blocks of points; a limit below them is refused before any work.
TEST(CliRender, aStreamRespectsMaxMemory) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "random2d", "--count", "20000", "--quiet", "-o", dir.file("r.ply")}).exit_code, 0);
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"render", dir.file("r.ply"), "-o", dir.file("r.png"), "--width", "64", "--height", "48"},
        std::vector<std::string>{"info", dir.file("r.ply")}}) {
    SCOPED_TRACE(args[0]);
    std::vector<std::string> tight = args;
    tight.insert(tight.end(), {"--stream", "on", "--max-memory", "1M"});
    const test::CommandResult refused = runDpoint(tight);
    EXPECT_EQ(refused.exit_code, 4);
    EXPECT_NE(refused.err.find(dir.file("r.ply") + ": streaming 20000 points a block at a time needs about 1.4 MiB"),
              std::string::npos)
        << refused.err;
    std::vector<std::string> enough = args;
    enough.insert(enough.end(), {"--stream", "on", "--max-memory", "64M", "-q"});
    EXPECT_EQ(runDpoint(enough).exit_code, 0);
  }
  EXPECT_TRUE(std::filesystem::exists(dir.file("r.png")));
}

// A CPU device's buffers (lavapipe's) are host memory: they count against --max-memory beside the
// set read. 1M points hold 24 MB; fp32's positions and colours on the device take 16 MB more, so
// 30M is refused (exit 4, naming --max-memory, no picture) where it passed before; 48M draws.
TEST(CliRender, aCpuDevicesBuffersCountAgainstMaxMemory) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "random2d", "--count", "1000000", "--quiet", "-o", dir.file("r.ply")}).exit_code, 0);
  const std::vector<std::string> render = {"render", dir.file("r.ply"), "--device", "cpu", "--stream", "off", "--mode",
                                           "fp32", "--width", "64", "--height", "48", "-q", "--max-memory"};
  std::vector<std::string> tight = render;
  tight.insert(tight.end(), {"30M", "-o", dir.file("tight.png")});
  const test::CommandResult refused = runDpoint(tight);
  EXPECT_EQ(refused.exit_code, 4) << refused.err;
  EXPECT_NE(refused.err.find("on the CPU device (whose memory is the host's)"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("that --max-memory 30.0 MiB leaves beside the 22.9 MiB of points read"), std::string::npos)
      << refused.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("tight.png")));
  // With --max-device-memory as well, the tighter refuses and names the other, the next limit met
  // by raising the one named alone.
  std::vector<std::string> both = tight;
  both.insert(both.end(), {"--max-device-memory", "1G"});
  test::CommandResult next = runDpoint(both);
  EXPECT_EQ(next.exit_code, 4) << next.err;
  EXPECT_NE(next.err.find("22.9 MiB of points read (past it, --max-device-memory 1.00 GiB is the next limit)"),
            std::string::npos)
      << next.err;
  both = render;
  both.insert(both.end(), {"48M", "--max-device-memory", "10M", "-o", dir.file("tight.png")});
  next = runDpoint(both);
  EXPECT_EQ(next.exit_code, 3) << next.err;
  EXPECT_NE(next.err.find("(--max-device-memory; past it, the 25.1 MiB that --max-memory 48.0 MiB leaves beside the "
                          "22.9 MiB of points read is the next limit)"),
            std::string::npos)
      << next.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("tight.png")));
  std::vector<std::string> enough = render;
  enough.insert(enough.end(), {"48M", "-o", dir.file("enough.png")});
  const test::CommandResult drawn = runDpoint(enough);
  EXPECT_EQ(drawn.exit_code, 0) << drawn.err;
  EXPECT_TRUE(std::filesystem::exists(dir.file("enough.png")));

  // A stream's device copy is the whole set: beside its two blocks of 1M points (72 MB, 68.7 MiB) it does
  // not fit 80M, which the build before let it pass unseen; 120M holds both.
  std::vector<std::string> stream = render;
  stream[5] = "on";
  std::vector<std::string> stream_tight = stream;
  stream_tight.insert(stream_tight.end(), {"80M", "-o", dir.file("stream-tight.png")});
  const test::CommandResult stream_refused = runDpoint(stream_tight);
  EXPECT_EQ(stream_refused.exit_code, 4) << stream_refused.err;
  EXPECT_NE(stream_refused.err.find("that --max-memory 80.0 MiB leaves beside the 68.7 MiB of the stream's blocks"),
            std::string::npos)
      << stream_refused.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("stream-tight.png")));
  std::vector<std::string> stream_enough = stream;
  stream_enough.insert(stream_enough.end(), {"120M", "-o", dir.file("stream-enough.png")});
  const test::CommandResult stream_drawn = runDpoint(stream_enough);
  EXPECT_EQ(stream_drawn.exit_code, 0) << stream_drawn.err;
  EXPECT_TRUE(std::filesystem::exists(dir.file("stream-enough.png")));
}

// A report that cannot be written fails the run, and the picture written before it goes too: a
// failed run leaves nothing (a review finding: --json onto a full disk left the PNG).
TEST(CliRender, aReportThatCannotBeWrittenTakesThePictureWithIt) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "random2d", "--count", "100", "-q", "-o", dir.file("r.ply")}).exit_code, 0);
  std::filesystem::create_symlink("/dev/full", dir.file("full.json"));
  const test::CommandResult r = runDpoint({"render", dir.file("r.ply"), "--width", "32", "--height", "32", "-q", "-o",
                                           dir.file("r.png"), "--json", dir.file("full.json")});
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("r.png")));
}

// Each draw has buffers of its own: --chunk-points that would cut a set into more than kMaxChunks
// draws is refused before any is made (a review finding: --chunk-points 1 over 100,000 points took
// 990 MB past --max-memory 200M).
TEST(CliRender, chunkPointsMakingThousandsOfDrawsIsRefused) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "random2d", "--count", "2000", "-q", "-o", dir.file("r.ply")}).exit_code, 0);
  const test::CommandResult refused = runDpoint({"render", dir.file("r.ply"), "--chunk-points", "1", "--width", "32",
                                                 "--height", "32", "-q", "-o", dir.file("r.png")});
  EXPECT_EQ(refused.exit_code, 1) << refused.err;
  EXPECT_NE(refused.err.find("--chunk-points 1: 2000 points would take more than 1024 draws; give at least 2"),
            std::string::npos)
      << refused.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("r.png")));
  const test::CommandResult drawn = runDpoint({"render", dir.file("r.ply"), "--chunk-points", "2", "--width", "32",
                                               "--height", "32", "-q", "-o", dir.file("r.png")});
  EXPECT_EQ(drawn.exit_code, 0) << drawn.err;
  // The help says so too.
  EXPECT_TRUE(test::contains(runDpoint({"render", "--help"}).out, "at most 1024 draws")) << "render --help";
}

// A stream whose two blocks of 16.7M points would pass --max-memory is read in smaller blocks
// instead of being refused (2M points took 144 MB, over a limit of 100M): the same picture and the
// same report as in one block, for a 2D set (one pass) and a 3D one (bounds, outline, spacing and
// elevation passes first).
TEST(CliRender, aStreamIsReadInBlocksThatFitMaxMemory) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "random2d", "--count", "2000000", "-q", "-o", dir.file("flat.ply")}).exit_code, 0);
  ASSERT_EQ(runDpoint({"generate", "random2d", "--count", "2000000", "--offset", "0,0,1", "-q", "-o",
                       dir.file("raised.ply")}).exit_code, 0);
  for (const char* name : {"flat", "raised"}) {
    SCOPED_TRACE(name);
    std::string pictures[2], reports[2];
    for (int k = 0; k < 2; ++k) {
      std::vector<std::string> render = {"render", dir.file(std::string(name) + ".ply"), "--stream", "on", "--width",
                                         "256", "--height", "192", "-q", "-o", dir.file(std::to_string(k) + ".png")};
      std::vector<std::string> info = {"info", dir.file(std::string(name) + ".ply"), "--stream", "on"};
      if (k == 1) {  // the render's blocks on a CPU device take half of --max-memory, beside its copy of the set
        render.insert(render.end(), {"--max-memory", "150M"});
        info.insert(info.end(), {"--max-memory", "100M"});
      }
      const test::CommandResult drawn = runDpoint(render);
      ASSERT_EQ(drawn.exit_code, 0) << drawn.err;
      pictures[k] = test::readFile(dir.file(std::to_string(k) + ".png"));
      const test::CommandResult told = runDpoint(info);
      ASSERT_EQ(told.exit_code, 0) << told.err;
      reports[k] = told.out;
    }
    EXPECT_TRUE(pictures[0] == pictures[1]) << "blocks of 1048576 points draw what one block draws";
    EXPECT_EQ(reports[0], reports[1]);
  }
}

// The default is --mode auto: it names the mode it took, its bound and the runner-up, and the
// measured error stays within the bound. fp32 at the Earth's radius would not.
TEST(CliRender, autoIsTheDefaultAndTakesAModeWithinTheLimit) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "mandelbulb", "--resolution", "33", "--offset", "6378137,0,0", "--quiet", "-o",
                       dir.file("far.ply")}).exit_code, 0);
  for (const char* backend : {"raster", "compute"}) {
    test::CommandResult r = runDpoint({"render", dir.file("far.ply"), "-o", dir.file("far.png"), "--backend", backend,
                                       "--error", "--validate", "--width", "256", "--height", "256", "--json",
                                       dir.file("far.json")});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("mode auto: "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("runner-up "), std::string::npos) << r.out;
    const std::string json = readFile(dir.file("far.json"));
    EXPECT_NE(json.find("\"mode_requested\": \"auto\""), std::string::npos) << json;
    // Not fp32 (which auto.rejected lists, passed over): the report's first member is the mode drawn.
    EXPECT_NE(json.rfind("{\n  \"mode\": \"", 0), std::string::npos) << json;
    EXPECT_EQ(json.rfind("{\n  \"mode\": \"fp32\"", 0), std::string::npos) << json;
    EXPECT_NE(json.find("\"enough\": true"), std::string::npos) << json;
    EXPECT_LE(jsonNumber(json, "predicted_bound_px"), 0.1);
    EXPECT_LE(jsonNumber(json, "max"), jsonNumber(json, "predicted_bound_px"));
    EXPECT_EQ(jsonNumber(json, "share_off_half_px"), 0.0);
    // One picture: the modes ordered by predicted time to it, the choice's and the runner-up's stated.
    EXPECT_TRUE(test::contains(json, "\"ordered_by\": \"time_to_picture\"")) << json;
    EXPECT_GT(jsonNumber(json, "predicted_ms"), 0.0) << json;
    EXPECT_NE(r.out.find("predicted encoding, upload and 1-px frame: "), std::string::npos) << r.out;
    // --error compares every bound with the error: the runner-up's is its points' too.
    EXPECT_TRUE(test::contains(json, "\"predicted_from\": \"points\", \"predicted_ms\"")) << json;
  }
  // Without --error, a choice and a runner-up that the set's box shows within the limit are bounded
  // over the box, with no pass over the points of their own, and said to be; fp32, passed over,
  // keeps its points' bound. Two threads: the order by predicted time then puts rte (bounded over a
  // box) after native on lavapipe as on a GPU, where on 4 or more cores lavapipe's would put batch
  // (per batch, never bounded over one box) there.
  {
    test::CommandResult r = runDpoint({"render", dir.file("far.ply"), "-o", dir.file("far.png"), "--width", "256",
                                       "--height", "256", "--threads", "2", "--json", dir.file("box.json")});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(test::contains(r.out, "predicted error bound at most ")) << r.out;
    EXPECT_TRUE(test::contains(r.out, " (from the box); runner-up ")) << r.out;
    EXPECT_TRUE(test::contains(r.out, ", from the box)")) << r.out;
    const std::string json = readFile(dir.file("box.json"));
    EXPECT_TRUE(test::contains(json, "\"predicted_from\": \"box\", \"predicted_ms\"")) << json;
    EXPECT_TRUE(test::contains(json, "\"predicted_from\": \"box\",\n")) << "the choice's bound: " << json;
    EXPECT_LE(jsonNumber(json, "predicted_bound_px"), 0.1);
    EXPECT_TRUE(test::contains(json, "\"rejected\": [{\"mode\": \"fp32\"")) << json;
  }
  // Several frames: what they wait for is the frames, in the measured speed order.
  test::CommandResult r = runDpoint({"render", dir.file("far.ply"), "-o", dir.file("far.png"), "--frames", "2",
                                     "--width", "128", "--height", "128", "--json", dir.file("frames.json")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string frames = readFile(dir.file("frames.json"));
  EXPECT_TRUE(test::contains(frames, "\"ordered_by\": \"frame\"")) << frames;
  EXPECT_FALSE(test::contains(frames, "predicted_ms")) << frames;
  EXPECT_EQ(r.out.find("predicted encoding"), std::string::npos) << r.out;
}

// fp32 at a 1e-40 view loses every point: there is no error to report, and the report says so
// (null in JSON, never a perfect 0), next to an unbounded prediction.
TEST(CliRender, everyPointLostReportsNoErrorRatherThanZero) {
  TempDir dir;
  writeFile(dir.file("tiny.csv"), "x,y\n1e-30,2e-30\n1.00000000003e-30,2e-30\n1e-30,2.00000000004e-30\n");
  test::CommandResult r = runDpoint({"render", dir.file("tiny.csv"), "-o", dir.file("tiny.png"), "--mode", "fp32",
                                     "--error", "--validate", "--view-center", "1e-30,2e-30", "--view-width", "1e-40",
                                     "--width", "64", "--height", "64", "--json", dir.file("tiny.json")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("no point measured"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("bound unbounded"), std::string::npos) << r.out;
  const std::string json = readFile(dir.file("tiny.json"));
  EXPECT_NE(json.find("\"error_px\": null"), std::string::npos) << json;
  EXPECT_NE(json.find("\"predicted_bound_px\": null"), std::string::npos) << json;
  EXPECT_EQ(jsonNumber(json, "points_lost"), 3.0) << json;
  // The same view in native: every point measured, on its pixel.
  r = runDpoint({"render", dir.file("tiny.csv"), "-o", dir.file("tiny.png"), "--mode", "native", "--error",
                 "--view-center", "1e-30,2e-30", "--view-width", "1e-40", "--width", "64", "--height", "64", "--json",
                 dir.file("tiny.json")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_LT(jsonNumber(readFile(dir.file("tiny.json")), "max"), 1e-4);
}

TEST(CliRender, badInputAndOptionsFailWithoutWritingAnything) {
  TempDir dir;
  writeFile(dir.file("empty.csv"), "x,y,z\n");
  writeFile(dir.file("one.csv"), "x,y,z\n1,2,3\n");
  writeFile(dir.file("flat.csv"), "x,y\n1,2\n3,4\n");
  struct Case {
    std::vector<std::string> args;
    int code;
    const char* message;
  };
  const std::vector<Case> cases = {
      {{dir.file("empty.csv")}, 2, "empty.csv"},
      {{dir.file("missing.csv")}, 2, "missing.csv"},
      {{dir.file("one.csv"), "--mode", "emulated"}, 1, "--mode"},
      {{dir.file("one.csv"), "--eye", "0,0,5"}, 1, "--target"},
      {{dir.file("one.csv"), "--eye", "0,0,5", "--target", "0,0,5"}, 1, "--eye"},
      {{dir.file("one.csv"), "--view-width", "-1"}, 1, "--view-width"},
      {{dir.file("one.csv"), "--point-size", "0"}, 1, "--point-size"},
      {{dir.file("one.csv"), "--background", "300,0,0"}, 1, "--background"},
      {{dir.file("one.csv"), "--device", "7"}, 3, "--device 7"},
      {{dir.file("one.csv"), "--backend", "mesh"}, 1, "--backend"},
      {{dir.file("one.csv"), "--order", "hilbert"}, 1, "--order"},
      {{dir.file("one.csv"), "--shade", "soft"}, 1, "--shade"},
      {{dir.file("one.csv"), "--edl-radius", "0.5"}, 1, "--edl-radius"},
      {{dir.file("one.csv"), "--edl-strength", "0"}, 1, "--edl-strength"},
      {{dir.file("one.csv"), "--color", "heat"}, 1, "--color"},
      {{dir.file("one.csv"), "--color", "rgb"}, 2, "no colours"},
      {{dir.file("one.csv"), "--views", "2"}, 1, "--views"},
      {{dir.file("one.csv"), "--views", "4", "--error"}, 1, "--views 4"},
      {{dir.file("one.csv"), "--views", "4", "--ortho"}, 1, "--views 4"},
      {{dir.file("flat.csv"), "--views", "4"}, 1, "2D"},
      {{dir.file("one.csv"), "--up-axis", "x"}, 1, "--up-axis"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = {"render"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    args.insert(args.end(), {"-o", dir.file("out.png")});
    test::CommandResult r = runDpoint(args);
    EXPECT_EQ(r.exit_code, c.code) << c.message << ": " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_FALSE(test::fileExists(dir.file("out.png"))) << c.message;
  }
  test::CommandResult jpg = runDpoint({"render", dir.file("one.csv"), "-o", dir.file("out.jpg")});
  EXPECT_EQ(jpg.exit_code, 1);
  EXPECT_NE(jpg.err.find(".png"), std::string::npos);
}

// Readable previews (issue #13): eye-dome lighting by default for 3D, a colour map for sets
// without colours, and a four-view contact sheet.
TEST(CliRender, previewsShadeColourAndShowFourViews) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "mandelbulb", "--resolution", "33", "--quiet", "-o", dir.file("mb.ply")}).exit_code, 0);
  auto render = [&](const std::string& name, std::vector<std::string> extra) {
    std::vector<std::string> args = {"render", dir.file("mb.ply"), "-o", dir.file(name), "--validate", "--width", "320",
                                     "--height", "240", "--quiet"};
    args.insert(args.end(), extra.begin(), extra.end());
    test::CommandResult r = runDpoint(args);
    EXPECT_EQ(r.exit_code, 0) << name << ": " << r.err;
    return readFile(dir.file(name));
  };
  // Binary PNGs compared with ==, so a failure does not print them.
  const std::string plain = render("none.png", {"--shade", "none", "--point-size", "1"});
  EXPECT_TRUE(render("auto.png", {"--point-size", "1"}) == render("edl.png", {"--shade", "edl", "--point-size", "1"}))
      << "a 3D view is shaded by default";
  EXPECT_FALSE(plain == readFile(dir.file("edl.png")));
  EXPECT_TRUE(render("error.png", {"--error"}) == plain) << "--error keeps plain 1-px points";
  EXPECT_FALSE(render("elevation.png", {"--shade", "none", "--point-size", "1", "--color", "elevation"}) == plain);
  EXPECT_TRUE(render("rgb.png", {"--shade", "none", "--point-size", "1", "--color", "rgb"}) == plain)
      << "rgb: the set's own colours";
  // A few thousand points over a 320 x 240 view leave gaps at 1 px: auto takes larger points.
  test::CommandResult sized = runDpoint({"render", dir.file("mb.ply"), "-o", dir.file("sized.png"), "--width", "320",
                                         "--height", "240", "--shade", "none"});
  ASSERT_EQ(sized.exit_code, 0) << sized.err;
  EXPECT_EQ(sized.out.find(", 1 px points"), std::string::npos) << sized.out;
  EXPECT_FALSE(readFile(dir.file("sized.png")) == plain);
  const std::string sheet = render("views.png", {"--views", "4"});
  EXPECT_EQ(test::pngSize(sheet), std::make_pair(320u, 240u)) << "four 159 x 119 views and 2-px lines: the size asked for";
  test::CommandResult r = runDpoint({"render", dir.file("mb.ply"), "-o", dir.file("views.png"), "--views", "4",
                                     "--width", "320", "--height", "240", "--backend", "compute"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* view : {"view front", "view side", "view top", "view three-quarter", "4 views"})
    EXPECT_NE(r.out.find(view), std::string::npos) << view << " in " << r.out;
}

// A binary PLY drawn a block at a time (a file larger than memory) gives the picture the set in
// memory gives; what needs the whole set is refused, and so is a file that cannot be streamed.
TEST(CliRender, streamedPlyDrawsTheSamePicture) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "mandelbulb", "--resolution", "40", "--quiet", "-o", dir.file("mb.ply")}).exit_code, 0);
  for (const char* backend : {"raster", "compute"}) {
    SCOPED_TRACE(backend);
    for (const char* stream : {"off", "on"}) {
      test::CommandResult r = runDpoint({"render", dir.file("mb.ply"), "-o", dir.file(stream + std::string(".png")),
                                         "--backend", backend, "--mode", "batch", "--stream", stream, "--validate",
                                         "--width", "256", "--height", "256", "--json", dir.file(stream + std::string(".json"))});
      ASSERT_EQ(r.exit_code, 0) << r.err;
      EXPECT_EQ(r.out.find("(streamed)") != std::string::npos, stream == std::string("on")) << r.out;
    }
    EXPECT_TRUE(readFile(dir.file("off.png")) == readFile(dir.file("on.png")));
    // Streamed, the bound is predicted from the box of each batch: no less than the points' own.
    const std::string streamed = readFile(dir.file("on.json"));
    EXPECT_TRUE(test::contains(streamed, "\"predicted_from\": \"batch_boxes\"")) << streamed;
    // Coloured, it is drawn in one pass: encoded while its bounds are gathered.
    EXPECT_TRUE(test::contains(streamed, "\"read_twice\": false")) << streamed;
    EXPECT_TRUE(test::contains(streamed, "\"preview\": ")) << streamed;
    EXPECT_GE(jsonNumber(streamed, "predicted_bound_px"), jsonNumber(readFile(dir.file("off.json")), "predicted_bound_px"));
  }
  // In Morton order the second pass (outline and spacing) reads again only the batches whose box
  // leaves a share open (on a set this small, nearly all: a batch spans several outline rows; on
  // 1e8 random2d points 3.8%): the same picture.
  ASSERT_EQ(runDpoint({"generate", "mandelbulb", "--resolution", "120", "--quiet", "--order", "morton", "-o",
                       dir.file("mbz.ply")}).exit_code, 0);
  for (const char* stream : {"off", "on"}) {
    test::CommandResult r = runDpoint({"render", dir.file("mbz.ply"), "-o", dir.file(stream + std::string("z.png")),
                                       "--backend", "compute", "--mode", "fp32", "--stream", stream, "--validate",
                                       "--json", dir.file(stream + std::string("z.json"))});
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  EXPECT_TRUE(readFile(dir.file("offz.png")) == readFile(dir.file("onz.png")));
  const std::string onz = readFile(dir.file("onz.json"));
  EXPECT_GT(jsonNumber(onz, "points_read_again"), 0.0) << onz;
  EXPECT_LE(jsonNumber(onz, "points_read_again"), jsonNumber(onz, "points")) << onz;
  ASSERT_EQ(runDpoint({"convert", dir.file("mb.ply"), "-o", dir.file("ascii.ply"), "--ply-ascii"}).exit_code, 0);
  test::CommandResult ascii = runDpoint({"render", dir.file("ascii.ply"), "-o", dir.file("a.png"), "--stream", "on"});
  EXPECT_EQ(ascii.exit_code, 2);
  EXPECT_NE(ascii.err.find("an ASCII PLY file cannot be streamed"), std::string::npos) << ascii.err;
  test::CommandResult error = runDpoint({"render", dir.file("mb.ply"), "-o", dir.file("e.png"), "--stream", "on", "--error"});
  EXPECT_EQ(error.exit_code, 1);
  EXPECT_NE(error.err.find("is read once"), std::string::npos) << error.err;
  EXPECT_FALSE(test::fileExists(dir.file("a.png")) || test::fileExists(dir.file("e.png")));
}

// An E57 file drawn a block at a time gives the picture the set in memory gives: libE57Format's
// two posed scans with invalid points (joined, coloured by intensity and by scan number, which the
// stream reads as the join makes them) and its spherical scan; info says the same of it.
TEST(CliRender, streamedE57DrawsTheSamePicture) {
  TempDir dir;
  const std::string data = std::string(DPOINT_TESTS_DIR) + "/data/e57/";
  for (const auto& [file, color] : std::vector<std::pair<std::string, std::string>>{
           {"two_scans.e57", ""}, {"two_scans.e57", "intensity"}, {"two_scans.e57", "point_source_id"}, {"spherical.e57", ""}}) {
    SCOPED_TRACE(file + " " + color);
    for (const char* stream : {"off", "on"}) {
      std::vector<std::string> args{"render", data + file, "-o", dir.file(stream + std::string(".png")), "--stream", stream,
                                    "--validate", "--width", "160", "--height", "120", "--mode", "batch"};
      if (!color.empty()) args.insert(args.end(), {"--color", color});
      test::CommandResult r = runDpoint(args);
      ASSERT_EQ(r.exit_code, 0) << r.err;
      EXPECT_EQ(r.out.find("(streamed)") != std::string::npos, stream == std::string("on")) << r.out;
    }
    EXPECT_TRUE(readFile(dir.file("off.png")) == readFile(dir.file("on.png")));
  }
  const test::CommandResult whole = runDpoint({"info", "--json", "--stream", "off", data + "two_scans.e57"});
  const test::CommandResult streamed = runDpoint({"info", "--json", "--stream", "on", data + "two_scans.e57"});
  ASSERT_EQ(whole.exit_code, 0) << whole.err;
  ASSERT_EQ(streamed.exit_code, 0) << streamed.err;
  EXPECT_EQ(whole.err, streamed.err);  // the same notes: points left out, what the join fills in
  const auto line = [](const std::string& json, const std::string& key) {  // the key's line of the report
    const size_t at = json.find("\n  \"" + key + "\": ");
    return at == std::string::npos ? std::string() : json.substr(at, json.find('\n', at + 1) - at);
  };
  for (const char* key : {"points", "min", "max", "min_neighbor_distance"}) {
    EXPECT_FALSE(line(whole.out, key).empty()) << key;
    EXPECT_EQ(line(whole.out, key), line(streamed.out, key)) << key;
  }
  EXPECT_TRUE(test::contains(streamed.out, "\"streamed\": true"));
  // The dimensions by name and type, and their ranges from the first pass, as the whole read has them.
  EXPECT_FALSE(line(whole.out, "dimensions").empty());
  EXPECT_EQ(line(whole.out, "dimensions"), line(streamed.out, "dimensions"));
  for (const char* name : {"intensity\", \"type\": \"float32", "rowIndex\", \"type\": \"uint8",
                           "point_source_id\", \"type\": \"uint16", "timeStamp\", \"type\": \"float64"})
    EXPECT_TRUE(test::contains(streamed.out, "{\"name\": \"" + std::string(name) + "\", \"min\": ")) << name;
  EXPECT_FALSE(test::contains(line(streamed.out, "dimensions"), "null")) << streamed.out;
}

// A stream drawn in one pass is encoded for the camera and mode its preview (whole batches spread
// over the file) suggests; where the whole set wants otherwise, it is read again, and the picture
// is still the one the set in memory gives. 300,000 2D points near the origin; the preview passes
// over points 28,672..32,767 (its runs are batches 0..6, 8, ...).
TEST(CliRender, aStreamThePreviewMisjudgesIsReadAgain) {
  TempDir dir;
  const auto write = [&](const std::string& name, const std::function<void(size_t, glm::dvec3&)>& odd) {
    PointSet set;
    uint64_t state = 12345;
    const auto next = [&] { return double((state = state * 6364136223846793005ull + 1442695040888963407ull) >> 11) * 0x1p-53; };
    for (size_t i = 0; i < 300000; ++i) {
      glm::dvec3 p(next(), next(), 0.0);
      if (i >= 28672 && i < 32768) odd(i, p);
      set.positions.push_back(p);
    }
    ASSERT_TRUE(writePly(dir.file(name), set).ok());
  };
  // One point off the plane: the preview sees a 2D set (white), the whole one is 3D, coloured by
  // elevation once its extent is known.
  write("lift.ply", [](size_t i, glm::dvec3& p) { p.z = i == 30000 ? 0.5 : 0.0; });
  // A cluster 1e4 away, which the view shows: off screen in the preview, every mode's bound 0 and
  // fp32 the fastest; float32 cannot hold the cluster at this zoom.
  write("far.ply", [](size_t, glm::dvec3& p) { p.x += 1e4; });
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
      {"lift.ply", {"--mode", "fp32"}},
      {"far.ply", {"--view-center", "10000.5,0.5", "--view-width", "1"}}};
  for (const auto& [name, extra] : cases) {
    SCOPED_TRACE(name);
    for (const char* stream : {"off", "on"}) {
      std::vector<std::string> args = {"render", dir.file(name), "-o", dir.file(stream + name + ".png"), "--stream",
                                       stream, "--width", "256", "--height", "256", "--validate", "--json",
                                       dir.file(stream + name + ".json")};
      args.insert(args.end(), extra.begin(), extra.end());
      test::CommandResult r = runDpoint(args);
      ASSERT_EQ(r.exit_code, 0) << r.err;
    }
    const std::string on = readFile(dir.file("on" + name + ".json"));
    EXPECT_TRUE(test::contains(on, "\"read_twice\": true")) << on;
    EXPECT_TRUE(readFile(dir.file("off" + name + ".png")) == readFile(dir.file("on" + name + ".png")));
    if (name == "far.ply") {
      EXPECT_FALSE(test::contains(on, "{\n  \"mode\": \"fp32\"")) << on;  // the report's first key
    }
  }
}

// Vulkan faults (issue #12): no driver, a device without a feature the run needs (hidden by the
// test switch), a lost device (injected at every queue submission, or at the first fence wait
// after a submission that went through), and a device-memory budget too small: each ends the run
// with one line on stderr and the exit code, well before a generous bound (no hang), and leaves
// neither the picture nor the --json report.
TEST(CliRender, vulkanFaultsEndWithOneLineAndNoPicture) {
  TempDir dir;
  writeFile(dir.file("one.csv"), "x,y,z\n1,2,3\n4,5,6\n");
  struct Case {
    std::string env;
    std::vector<std::string> args;
    int code;
    const char* message;
  };
  const std::vector<Case> cases = {
      {"VK_DRIVER_FILES=/nonexistent/icd.json", {}, 3, "no Vulkan driver found"},
      {"DPOINT_TEST_VULKAN_FAULT=no-float64", {"--mode", "native"}, 3, "needs shaderFloat64"},
      {"DPOINT_TEST_VULKAN_FAULT=no-int64-atomics", {"--backend", "compute"}, 3, "shaderBufferInt64Atomics"},
      {"DPOINT_TEST_VULKAN_FAULT=device-lost", {}, 3, "VK_ERROR_DEVICE_LOST"},
      {"DPOINT_TEST_VULKAN_FAULT=device-lost-wait", {}, 3, "VK_ERROR_DEVICE_LOST"},
      {"DPOINT_TEST_VULKAN_FAULT=", {"--max-device-memory", "1M"}, 3, "--max-device-memory"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.env);
    std::vector<std::string> argv = {"/usr/bin/env", c.env, DPOINT_EXE, "render", dir.file("one.csv"), "-o",
                                     dir.file("out.png"), "--json", dir.file("out.json")};
    argv.insert(argv.end(), c.args.begin(), c.args.end());
    test::CommandResult r = test::runCommand(argv, std::chrono::seconds(60));
    ASSERT_FALSE(r.timed_out);
    EXPECT_EQ(r.exit_code, c.code) << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(dir.entries(), std::vector<std::string>{"one.csv"});  // no picture, report or temporary
    if (std::string(c.message) == "VK_ERROR_DEVICE_LOST") {  // lavapipe: already the CPU, so no "or --device cpu"
      EXPECT_TRUE(test::contains(r.err, "try again)") && !test::contains(r.err, "--device cpu")) << r.err;
    }
  }
  // With the feature hidden, --mode auto goes on in a mode the device still runs.
  test::CommandResult r = test::runCommand({"/usr/bin/env", "DPOINT_TEST_VULKAN_FAULT=no-float64", DPOINT_EXE, "render",
                                            dir.file("one.csv"), "-o", dir.file("auto.png"), "--validate"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.find("mode native"), std::string::npos) << r.out;
}

// --order morton changes only which of two points at the same depth on one pixel wins; a
// marching-cubes surface has no such pairs, so the picture is the same, on both backends.
// 1-px points: two overlapping 4-px points at one float depth tie, and the raster depth test keeps
// whichever came first (one pixel of this picture under the projected-extent fit of issue #24).
TEST(CliRender, mortonOrderDrawsTheSamePicture) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "mandelbulb", "--resolution", "48", "--quiet", "-o", dir.file("mb.ply")}).exit_code, 0);
  for (const char* backend : {"raster", "compute"}) {
    SCOPED_TRACE(backend);
    for (const char* order : {"input", "morton"}) {
      test::CommandResult r = runDpoint({"render", dir.file("mb.ply"), "-o", dir.file(order + std::string(".png")),
                                         "--backend", backend, "--mode", "native", "--order", order, "--validate",
                                         "--width", "256", "--height", "256", "--point-size", "1", "--json", dir.file("r.json")});
      ASSERT_EQ(r.exit_code, 0) << r.err;
      EXPECT_NE(readFile(dir.file("r.json")).find("\"order\": \"" + std::string(order) + "\""), std::string::npos);
    }
    EXPECT_TRUE(readFile(dir.file("input.png")) == readFile(dir.file("morton.png")));
  }
}

// Large sets: 16.7M points are more than lavapipe's 128 MiB storage-buffer range holds, so
// native mode (vertex pulling there) draws them in several chunks, on both backends.
TEST(CliRender, sixteenMillionPointsRenderInChunks) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "sierpinski", "--level", "11", "--unwelded", "--quiet", "-o", dir.file("s.ply")}).exit_code, 0);
  test::CommandResult r = runDpoint({"render", dir.file("s.ply"), "-o", dir.file("s.png"), "--mode", "native",
                                     "--validate", "--width", "128", "--height", "128", "--warmup", "0", "--quiet",
                                     "--json", dir.file("s.json")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string json = readFile(dir.file("s.json"));
  EXPECT_EQ(jsonNumber(json, "points"), 16777216.0);
  EXPECT_GE(jsonNumber(json, "chunks"), 2.0) << json;
  EXPECT_GT(readFile(dir.file("s.png")).size(), 1000u);
  // The compute backend on the same set (its positions are a storage buffer too).
  test::CommandResult c = runDpoint({"render", dir.file("s.ply"), "-o", dir.file("c.png"), "--mode", "native",
                                     "--backend", "compute", "--validate", "--width", "128", "--height", "128",
                                     "--warmup", "0", "--quiet", "--json", dir.file("c.json")});
  ASSERT_EQ(c.exit_code, 0) << c.err;
  EXPECT_GE(jsonNumber(readFile(dir.file("c.json")), "chunks"), 2.0);
}

TEST(CliDevices, listsADeviceWithTheSelfTestAndUsableModes) {
  test::CommandResult text = runDpoint({"devices"});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("self-test: pass"), std::string::npos) << text.out;
  test::CommandResult json = runDpoint({"devices", "--json"});
  ASSERT_EQ(json.exit_code, 0) << json.err;
  for (const char* key : {"\"name\"", "\"shader_float64\"", "\"r64g64b64_vertex\"", "\"max_storage_buffer_range\"",
                          "\"self_test\": \"pass\"", "\"native\""})
    EXPECT_NE(json.out.find(key), std::string::npos) << key << " in " << json.out;
}

// Wrong or poor pictures say so (issue #24): a forced mode whose bound is over 0.5 px gets one
// warning line naming its bound and auto's pick, and the report's warnings list it; auto says why
// each faster mode was passed over; a picture with no point in view, or the data on under 1% of
// it, says that too. A good picture has no warning.
TEST(CliRender, wrongOrPoorPicturesSaySo) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "mandelbulb", "--resolution", "24", "-q", "--offset", "6378000,0,0", "-o",
                       dir.file("far.ply")}).exit_code, 0);
  auto render = [&](const std::vector<std::string>& extra) {
    std::vector<std::string> args = {"render", dir.file("far.ply"), "-o", dir.file("p.png"), "--width", "200",
                                     "--height", "150", "--json", dir.file("p.json")};
    args.insert(args.end(), extra.begin(), extra.end());
    test::CommandResult r = runDpoint(args);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return r;
  };
  auto warnings = [](const std::string& err) {
    size_t n = 0;
    for (size_t at = err.find("dpoint: warning: "); at != std::string::npos; at = err.find("dpoint: warning: ", at + 1)) ++n;
    return n;
  };
  test::CommandResult fp32 = render({"--mode", "fp32", "-q"});
  EXPECT_TRUE(test::contains(fp32.err, "dpoint: warning: --mode fp32: predicted error unbounded (> 0.5 px): the picture "
                                       "is wrong here; --mode auto picks "))
      << fp32.err;
  EXPECT_EQ(warnings(fp32.err), 1u) << fp32.err;
  std::string json = readFile(dir.file("p.json"));
  EXPECT_TRUE(test::contains(json, "\"warnings\": [\"--mode fp32: predicted error unbounded (> 0.5 px)")) << json;
  EXPECT_TRUE(test::contains(json, "\"mode_requested\": \"fp32\"")) << "the existing keys stay";

  test::CommandResult good = render({});
  EXPECT_EQ(warnings(good.err), 0u) << good.err;
  EXPECT_TRUE(test::contains(good.out, "mode auto: faster modes passed over: fp32 (unbounded error)")) << good.out;
  json = readFile(dir.file("p.json"));
  EXPECT_TRUE(test::contains(json, "\"warnings\": []")) << json;
  EXPECT_TRUE(test::contains(json, "\"rejected\": [{\"mode\": \"fp32\", \"predicted_bound_px\": null, \"usable\": true}")) << json;

  test::CommandResult nothing = render({"--ortho", "--view-center", "0,0", "--view-width", "1", "-q"});
  EXPECT_TRUE(test::contains(nothing.err, "dpoint: warning: the picture shows nothing: no point was drawn in the view"))
      << nothing.err;
  EXPECT_TRUE(test::contains(readFile(dir.file("p.json")), "\"drawn_share\": 0,\n  \"warnings\": [\"the picture shows nothing"));

  test::CommandResult speck = render({"--eye", "6378000,0,400", "--target", "6378000,0,0", "--point-size", "1", "-q"});
  EXPECT_TRUE(test::contains(speck.err, "of the picture (under 1%)")) << speck.err;
  EXPECT_EQ(warnings(speck.err), 1u) << speck.err;
}

}  // namespace
}  // namespace dpoint
