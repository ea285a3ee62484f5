// glTF/GLB to CSV streamed as the scene is walked (convertGltfToCsv, streamGltf) against the
// in-memory path it replaces in `dpoint convert` (readGltf, the colour filters, writePoints):
// the same bytes on points, meshes, instancing, mixed colours, planar sets and real models, for
// every formatting option and thread count; the same errors in the same order; no file left
// behind by a refused input or a write that fails half-way.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "converters/gltf_read.h"
#include "converters/gltf_write.h"
#include "ops/point_filters.h"
#include "converters/point_io.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::TempDir;

constexpr double kEarthRadius = 6.378e6;

// n points a few metres apart at Earth radius; colours when asked; z = 0 exactly when planar.
PointSet cloud(size_t n, bool colours, bool planar) {
  PointSet set;
  for (size_t i = 0; i < n; ++i) {
    const double t = double(i);
    set.positions.push_back({kEarthRadius + 0.001 * double(i % 1000), -kEarthRadius + 0.0007 * double(i % 1500),
                             planar ? 0.0 : 0.5 * kEarthRadius + 1e-4 * t});
    if (colours) set.colors.push_back({float(i % 256) / 255.0f, 0.1f * float(i % 10), 1.0f / float(1 + i)});
  }
  return set;
}

PointSet tetrahedron(bool colours) {
  PointSet set;
  const glm::dvec3 base(1e8, -2e7, 3.5e6);
  set.positions = {base, base + glm::dvec3(1, 0, 0), base + glm::dvec3(0, 1, 0), base + glm::dvec3(0, 0, 1)};
  if (colours) set.colors = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.5f, 0.5f, 0.5f}};
  set.triangles = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  return set;
}

// data.bin: positions (3 float VEC3), ubyte VEC4 colours, ushort indices, instance translations.
void writeBuffer(const TempDir& dir) {
  const float positions[9] = {1, 2, 3, 0, 0, 0, -1, 0.5f, 2};
  const uint8_t colours[12] = {255, 0, 0, 10, 0, 255, 0, 20, 51, 102, 204, 255};
  const uint16_t indices[4] = {0, 2, 1, 0};
  const float translations[6] = {0, 0, 0, 10, 20, -30};
  std::string bytes(sizeof positions + sizeof colours + sizeof indices + sizeof translations, '\0');
  char* p = bytes.data();
  for (const auto& [data, size] : {std::pair<const void*, size_t>{positions, sizeof positions},
                                   {colours, sizeof colours}, {indices, sizeof indices},
                                   {translations, sizeof translations}}) {
    std::memcpy(p, data, size);
    p += size;
  }
  test::writeFile(dir.file("data.bin"), bytes);
}

// Node 0 (far-away matrix) places a points primitive without COLOR_0 (material colour) and, as
// its child through TRS, the indexed triangle primitive with COLOR_0; node 2 places the points
// mesh twice more by EXT_mesh_gpu_instancing. Scene 1 holds node 2 alone.
std::string mixedGltf() {
  return R"({
  "asset": {"version": "2.0"},
  "extensionsUsed": ["EXT_mesh_gpu_instancing"],
  "scene": 0,
  "scenes": [{"nodes": [0, 2]}, {"nodes": [2]}],
  "nodes": [
    {"matrix": [2,0,0,0, 0,2,0,0, 0,0,2,0, 6378000,0,0,1], "mesh": 1, "children": [1]},
    {"translation": [0,5,0], "rotation": [0,0,1.4142135623730951,1.4142135623730951], "scale": [1,1,3], "mesh": 0},
    {"translation": [1e7, 1e-3, 7], "mesh": 1,
     "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 3}}}}
  ],
  "meshes": [
    {"primitives": [{"attributes": {"POSITION": 0, "COLOR_0": 1}, "indices": 2, "mode": 4}]},
    {"primitives": [{"attributes": {"POSITION": 0}, "material": 0, "mode": 0}]}
  ],
  "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.25, 0.5, 0.1, 1]}}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [-1, 0, 0], "max": [1, 2, 3]},
    {"bufferView": 1, "componentType": 5121, "normalized": true, "count": 3, "type": "VEC4"},
    {"bufferView": 2, "componentType": 5123, "count": 3, "type": "SCALAR"},
    {"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"}
  ],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 36},
    {"buffer": 0, "byteOffset": 36, "byteLength": 12},
    {"buffer": 0, "byteOffset": 48, "byteLength": 6},
    {"buffer": 0, "byteOffset": 56, "byteLength": 24}
  ],
  "buffers": [{"byteLength": 80, "uri": "data.bin"}]
})";
}

// Options as `dpoint convert` passes them.
struct Case {
  GltfReadOptions read;
  ColorFilters filters;
  WriteOptions write;
};

std::vector<Case> formattingCases() {
  std::vector<Case> cases(5);
  cases[1].write.decimals = 15;
  cases[2].filters.drop = true;
  cases[3].filters.srgb8 = true;
  cases[3].write.decimals = 3;
  cases[4].read.all_scenes = true;
  return cases;
}

// The in-memory path: readGltf, the filters, writePoints; the error it stops at, if any.
Status convertInMemory(const std::string& input, const Case& c, const std::string& output) {
  GltfReadOptions read = c.read;
  read.triangles = false;  // as `dpoint convert` reads for CSV
  Result<PointSet> set = readGltf(input, read);
  if (!set) return set.error();
  if (c.filters.drop) set->colors.clear();
  if (c.filters.srgb8) encodeColorsSrgb8(*set);
  return writePoints(output, *set, c.write);
}

// Both paths on one input: the same bytes, or the same error and no file from either.
void expectSameOutput(const std::string& input, const Case& c, const std::string& label) {
  TempDir dir;
  const Status expected = convertInMemory(input, c, dir.file("memory.csv"));
  const Status streamed = convertGltfToCsv(input, c.read, c.filters, dir.file("stream.csv"), c.write);
  ASSERT_EQ(expected.ok(), streamed.ok()) << label << ": " << (expected ? streamed : expected).error().message;
  if (!expected) {
    EXPECT_EQ(streamed.error().message, expected.error().message) << label;
    EXPECT_EQ(int(streamed.error().code), int(expected.error().code)) << label;
    EXPECT_TRUE(dir.entries().empty()) << label;
    return;
  }
  const std::string bytes = test::readFile(dir.file("memory.csv"));
  EXPECT_FALSE(bytes.empty()) << label;
  EXPECT_TRUE(test::readFile(dir.file("stream.csv")) == bytes) << label << ": streamed CSV differs";
}

void expectSameOutputForAllCases(const std::string& input, const std::string& label) {
  const std::vector<Case> cases = formattingCases();
  for (size_t i = 0; i < cases.size(); ++i) expectSameOutput(input, cases[i], label + " case " + std::to_string(i));
}

TEST(GltfStream, csvEqualsInMemoryOnPointsAndMeshes) {
  TempDir dir;
  const std::vector<std::pair<std::string, PointSet>> inputs = {
      {"points_colours.glb", cloud(2000, true, false)}, {"points.glb", cloud(2000, false, false)},
      {"planar.glb", cloud(500, true, true)},           {"mesh.glb", tetrahedron(false)},
      {"mesh_colours.glb", tetrahedron(true)}};
  for (const auto& [name, set] : inputs) {
    ASSERT_TRUE(writeGlb(dir.file(name), set));
    expectSameOutputForAllCases(dir.file(name), name);
  }
}

TEST(GltfStream, csvEqualsInMemoryWithInstancingMixedColoursAndScenes) {
  TempDir dir;
  writeBuffer(dir);
  test::writeFile(dir.file("mixed.gltf"), mixedGltf());
  expectSameOutputForAllCases(dir.file("mixed.gltf"), "mixed.gltf");
  Case scene1;
  scene1.read.scene = 1;  // instanced points only: material colour, no COLOR_0 anywhere
  expectSameOutput(dir.file("mixed.gltf"), scene1, "mixed.gltf scene 1");
}

TEST(GltfStream, zColumnKeptEvenWhenEveryZIsZero) {
  // glTF positions have z: a 3D set at z = 0 keeps its z column (issue #24: the values do not
  // decide). (A set dpoint writes as 2D says so in the asset and comes back x,y: issue #34.)
  TempDir dir;
  PointSet planar = cloud(300, true, true);
  planar.z_axis = ZAxis::kPresent;
  ASSERT_TRUE(writeGlb(dir.file("planar.glb"), planar));
  ASSERT_TRUE(convertGltfToCsv(dir.file("planar.glb"), {}, {}, dir.file("planar.csv")));
  EXPECT_EQ(test::readFile(dir.file("planar.csv")).substr(0, 12), "x,y,z,r,g,b\n");
  expectSameOutputForAllCases(dir.file("planar.glb"), "planar.glb");
  // Planar but for the last point: the first walk must look at every z. (The GLB stores z − 0.5
  // as float; the node adds 0.5 back, exactly, so the other points stay at +0.0.)
  PointSet almost = cloud(300, false, true);
  almost.positions.back().z = 1.0;
  ASSERT_TRUE(writeGlb(dir.file("almost.glb"), almost));
  ASSERT_TRUE(convertGltfToCsv(dir.file("almost.glb"), {}, {}, dir.file("almost.csv")));
  const std::string text = test::readFile(dir.file("almost.csv"));
  EXPECT_EQ(text.substr(0, 6), "x,y,z\n");
  EXPECT_NE(text.find(",0\n"), std::string::npos);
  expectSameOutputForAllCases(dir.file("almost.glb"), "almost.glb");
}

TEST(GltfStream, outputDoesNotDependOnBlocksBatchesOrThreads) {
  // More points than one block (2^16) and than one writer batch at 1 thread (2^17), not a multiple of either.
  TempDir dir;
  ASSERT_TRUE(writeGlb(dir.file("big.glb"), cloud(3 * kGltfStreamBlockPoints + 12345, true, false)));
  Case c;
  c.write.threads = 1;
  expectSameOutput(dir.file("big.glb"), c, "big.glb, 1 thread");
  ASSERT_TRUE(convertGltfToCsv(dir.file("big.glb"), {}, {}, dir.file("t1.csv"), c.write));
  c.write.threads = 3;
  c.write.decimals = 15;
  expectSameOutput(dir.file("big.glb"), c, "big.glb, 3 threads, --decimals 15");
  c.write.decimals = -1;
  ASSERT_TRUE(convertGltfToCsv(dir.file("big.glb"), {}, {}, dir.file("t3.csv"), c.write));
  EXPECT_TRUE(test::readFile(dir.file("t1.csv")) == test::readFile(dir.file("t3.csv")));
}

TEST(GltfStream, csvEqualsInMemoryOnAssimpModels) {
  const std::string root = "/usr/share/assimp/models/glTF2";
  ASSERT_TRUE(std::filesystem::is_directory(root)) << root << " is absent (scripts/setup installs assimp-testmodels)";
  size_t files = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
    const std::string ext = entry.path().extension().string();
    if (!entry.is_regular_file() || (ext != ".gltf" && ext != ".glb")) continue;
    ++files;
    expectSameOutput(entry.path().string(), Case{}, entry.path().string());
    Case fixed;
    fixed.write.decimals = 15;
    expectSameOutput(entry.path().string(), fixed, entry.path().string() + " --decimals 15");
  }
  EXPECT_GT(files, 20u);
}

// Records what the walk hands out.
class RecordingSink final : public GltfPointSink {
 public:
  Status begin(const GltfSummary& s) override {
    ++begins;
    summary = s;
    return okStatus();
  }
  Status points(PointSet& block) override {
    EXPECT_LE(block.size(), kGltfStreamBlockPoints);
    EXPECT_EQ(block.colors.size(), summary.colors ? block.size() : 0u);
    EXPECT_TRUE(block.triangles.empty());
    all.positions.insert(all.positions.end(), block.positions.begin(), block.positions.end());
    all.colors.insert(all.colors.end(), block.colors.begin(), block.colors.end());
    ++blocks;
    return blocks == fail_at ? Status(Error{"sink refused block " + std::to_string(blocks)}) : okStatus();
  }
  int begins = 0;
  size_t blocks = 0, fail_at = 0;
  GltfSummary summary;
  PointSet all;
};

TEST(GltfStream, sinkGetsReadGltfPointsInBlocksAfterTheSummary) {
  TempDir dir;
  ASSERT_TRUE(writeGlb(dir.file("big.glb"), cloud(2 * kGltfStreamBlockPoints + 7, true, false)));
  GltfReadOptions read;
  read.triangles = false;
  Result<PointSet> expected = readGltf(dir.file("big.glb"), read);
  ASSERT_TRUE(expected) << expected.error().message;
  RecordingSink sink;
  ASSERT_TRUE(streamGltf(dir.file("big.glb"), {}, sink));
  EXPECT_EQ(sink.begins, 1);
  EXPECT_EQ(sink.blocks, 3u);
  EXPECT_EQ(sink.summary.points, expected->size());
  EXPECT_TRUE(sink.summary.colors);
  EXPECT_TRUE(std::memcmp(sink.all.positions.data(), expected->positions.data(),
                          expected->size() * sizeof(glm::dvec3)) == 0);
  EXPECT_EQ(sink.all.colors, expected->colors);

  RecordingSink failing;
  failing.fail_at = 2;
  Status s = streamGltf(dir.file("big.glb"), {}, failing);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().message, "sink refused block 2");
  EXPECT_EQ(failing.blocks, 2u);
}

TEST(GltfStream, refusedInputLeavesNoFileAndComesBeforeOutputErrors) {
  TempDir dir;
  ASSERT_TRUE(writeGlb(dir.file("points.glb"), cloud(1000, true, false)));
  // --max-points: readGltf's error, the sink never started, nothing written.
  Case limited;
  limited.read.max_points = 999;
  expectSameOutput(dir.file("points.glb"), limited, "--max-points 999");
  RecordingSink sink;
  Status s = streamGltf(dir.file("points.glb"), limited.read, sink);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().code, ExitCode::kResourceLimit);
  EXPECT_NE(s.error().message.find("more than --max-points 999 points"), std::string::npos) << s.error().message;
  EXPECT_EQ(sink.begins, 0);
  // A scene without meshes: an empty set, a CSV with its header only (issue #24).
  writeBuffer(dir);
  std::string json = mixedGltf();
  json.replace(json.find(R"({"nodes": [2]})"), 14, R"({"nodes": []})");
  test::writeFile(dir.file("empty.gltf"), json);
  Case scene1;
  scene1.read.scene = 1;
  s = convertGltfToCsv(dir.file("empty.gltf"), scene1.read, {}, dir.file("out.csv"));
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_EQ(test::readFile(dir.file("out.csv")), "x,y,z\n");
  std::filesystem::remove(dir.file("out.csv"));
  // Bad input and a missing output folder: the input's error, as when the set was read first.
  s = convertGltfToCsv(dir.file("points.glb"), limited.read, {}, dir.file("no/where/out.csv"));
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("--max-points"), std::string::npos) << s.error().message;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"data.bin", "empty.gltf", "points.glb"}));
}

TEST(GltfStream, cliWriteFailingHalfWayLeavesNoFile) {
  TempDir dir;
  ASSERT_TRUE(writeGlb(dir.file("big.glb"), cloud(200000, true, false)));  // ~14 MB of CSV
  // A 1 MB file size limit with SIGXFSZ ignored: write() fails with EFBIG after the first
  // flushes, so the error path (not a signal) is what must leave nothing.
  const std::string script = "trap '' XFSZ; ulimit -f 2048; exec \"$0\" \"$@\"";
  const test::CommandResult r = test::runCommand(
      {"/bin/sh", "-c", script, DPOINT_EXE, "convert", dir.file("big.glb"), "-o", dir.file("out.csv"), "-q"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(dir.file("out.csv")), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"big.glb"});
  // The CLI's --max-points on the streamed path: exit 4, nothing written.
  const test::CommandResult limited =
      test::runDpoint({"convert", dir.file("big.glb"), "-o", dir.file("out.csv"), "--max-points", "199999"});
  EXPECT_EQ(limited.exit_code, 4) << limited.err;
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"big.glb"});
}

}  // namespace
}  // namespace dpoint
