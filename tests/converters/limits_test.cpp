// Resource limits of the readers (issue #12): every array sized from a file is checked against
// the data that backs it and against --max-memory before it is allocated; over the limit is
// ExitCode::kResourceLimit with one line naming the file, the count and --max-memory.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "converters/point_io.h"
#include "gltf_test_support.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::TempDir;

void expectLimit(const Result<PointSet>& result, const std::string& path, const std::vector<std::string>& parts) {
  ASSERT_FALSE(result.ok());
  const Error& e = result.error();
  EXPECT_EQ(e.code, ExitCode::kResourceLimit) << e.message;
  EXPECT_EQ(e.message.rfind(path + ": ", 0), 0u) << e.message;
  EXPECT_EQ(e.message.find('\n'), std::string::npos) << e.message;
  EXPECT_NE(e.message.find("--max-memory"), std::string::npos) << e.message;
  for (const std::string& part : parts) EXPECT_NE(e.message.find(part), std::string::npos) << e.message;
}

template <typename T>
void append(std::string& bytes, std::initializer_list<T> values) {
  for (T v : values) bytes.append(reinterpret_cast<const char*>(&v), sizeof v);
}

TEST(Limits, csvLinesBeyondMaxMemoryAreRefusedBeforeAllocating) {
  TempDir dir;
  std::string csv = "x,y\n";
  for (int i = 0; i < 1000; ++i) csv += "1,2\n";
  test::writeFile(dir.file("a.csv"), csv);
  ReadOptions options;
  options.max_memory = 10000;  // 1000 rows need 24,000 bytes
  expectLimit(readPoints(dir.file("a.csv"), options), dir.file("a.csv"), {"1000 lines"});
  options.max_memory = 24000;
  EXPECT_TRUE(readPoints(dir.file("a.csv"), options).ok());
}

// Three bytes of file (uchar x, y, z) make 24 bytes of point set.
TEST(Limits, plyVerticesBeyondMaxMemoryAreRefusedBeforeAllocating) {
  TempDir dir;
  std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex 1000\nproperty uchar x\nproperty uchar y\n"
                    "property uchar z\nend_header\n";
  ply += std::string(3000, '\1');
  test::writeFile(dir.file("a.ply"), ply);
  ReadOptions options;
  options.max_memory = 20000;
  expectLimit(readPoints(dir.file("a.ply"), options), dir.file("a.ply"), {"1000 vertices"});
  options.max_memory = 24000;
  EXPECT_TRUE(readPoints(dir.file("a.ply"), options).ok());
}

// A face of 255 one-byte indices is fan-triangulated into 253 triangles (3036 bytes).
TEST(Limits, plyFaceTrianglesBeyondMaxMemoryAreRefusedAsTheyGrow) {
  TempDir dir;
  std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
                    "property double z\nelement face 1\nproperty list uchar uchar vertex_indices\nend_header\n";
  append<double>(ply, {0, 0, 0, 1, 0, 0, 0, 1, 0});
  ply += char(255);
  for (int i = 0; i < 255; ++i) ply += char(i % 3);
  test::writeFile(dir.file("a.ply"), ply);
  ReadOptions options;
  options.max_memory = 72 + 3000;
  expectLimit(readPoints(dir.file("a.ply"), options), dir.file("a.ply"), {"face 0"});
  options.max_memory = 72 + 3036;
  Result<PointSet> read = readPoints(dir.file("a.ply"), options);
  ASSERT_TRUE(read.ok()) << read.error().message;
  EXPECT_EQ(read->triangles.size(), 3u * 253);
}

// `nodes` nodes each placing a 3-point mesh, or one node placing it `instances` times.
std::string placedMesh(int nodes, int instances) {
  std::string bin;
  append<float>(bin, {0, 0, 0, 1, 0, 0, 0, 1, 0});
  for (int i = 0; i < instances; ++i) append<float>(bin, {float(i), 0, 0});
  std::string node_list, children;
  for (int i = 0; i < nodes; ++i) {
    node_list += std::string(i ? "," : "") + R"({"mesh":0)" +
                 (instances ? R"(,"extensions":{"EXT_mesh_gpu_instancing":{"attributes":{"TRANSLATION":1}}})" : "") + "}";
    children += std::string(i ? "," : "") + std::to_string(i);
  }
  std::vector<unsigned char> bytes(bin.begin(), bin.end());
  return R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[)" + children + R"(]}],"nodes":[)" + node_list +
         R"(],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"mode":0}]}],)"
         R"("buffers":[{"byteLength":)" + std::to_string(bin.size()) +
         R"(,"uri":"data:application/octet-stream;base64,)" + test::base64(bytes) + R"("}],)"
         R"("bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":)" +
         std::to_string(12 * instances) + R"(}],)"
         R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},)"
         R"({"bufferView":1,"componentType":5126,"count":)" + std::to_string(instances) + R"(,"type":"VEC3"}]})";
}

class CountingSink final : public GltfPointSink {
 public:
  Status begin(const GltfSummary& summary) override {
    total = summary.points;
    return okStatus();
  }
  Status points(PointSet&) override { return okStatus(); }
  uint64_t total = 0;
};

// 2,000 nodes placing 3 points make a 216,000-byte set from a 100 KB file: refused when the set
// is built, while streaming (what glTF to CSV does) holds no set and goes through.
TEST(Limits, gltfPointSetBeyondMaxMemoryIsRefusedButStreams) {
  TempDir dir;
  test::writeFile(dir.file("a.gltf"), placedMesh(2000, 0));
  GltfReadOptions options;
  options.max_memory = 150000;
  expectLimit(readGltf(dir.file("a.gltf"), options), dir.file("a.gltf"), {"points"});
  CountingSink sink;
  Status streamed = streamGltf(dir.file("a.gltf"), options, sink);
  ASSERT_TRUE(streamed.ok()) << streamed.error().message;
  EXPECT_EQ(sink.total, 6000u);
}

// 1,000 instances take 128 KB of matrices from 12 KB of TRANSLATION.
TEST(Limits, gltfInstancesBeyondMaxMemoryAreRefused) {
  TempDir dir;
  test::writeFile(dir.file("a.gltf"), placedMesh(1, 1000));
  GltfReadOptions options;
  options.max_memory = 100000;
  expectLimit(readGltf(dir.file("a.gltf"), options), dir.file("a.gltf"), {"1000 instances"});
  options.max_memory = 1000000;
  Result<PointSet> read = readGltf(dir.file("a.gltf"), options);
  ASSERT_TRUE(read.ok()) << read.error().message;
  EXPECT_EQ(read->size(), 3000u);
}

// An accessor without a bufferView is count zeros: nothing in the file bounds it.
TEST(Limits, gltfUnbackedAccessorBeyondMaxMemoryIsRefused) {
  TempDir dir;
  test::writeFile(dir.file("a.gltf"),
                  R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
                  R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"mode":0}]}],)"
                  R"("accessors":[{"componentType":5126,"count":100000,"type":"VEC3"}]})");
  GltfReadOptions options;
  options.max_memory = 1000000;  // 300,000 doubles are 2.4 MB
  Result<PointSet> read = readGltf(dir.file("a.gltf"), options);
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.error().code, ExitCode::kResourceLimit);
  EXPECT_NE(read.error().message.find("count 100000 without backing data"), std::string::npos) << read.error().message;
}

TEST(Limits, gltfFileBeyondMaxMemoryIsRefusedBeforeLoading) {
  TempDir dir;
  test::writeFile(dir.file("a.gltf"), placedMesh(1, 1000));
  GltfReadOptions options;
  options.max_memory = 1000;
  expectLimit(readGltf(dir.file("a.gltf"), options), dir.file("a.gltf"), {"loading"});
}

// tests/corpus/ (its README): hostile inputs, fuzz findings among them, each refused with one
// printable line naming the file (bytes from the file quoted as \xNN), exit 2 or 4.
TEST(Limits, corpusInputsFailWithOneLineNamingTheFile) {
  size_t files = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(DPOINT_TESTS_DIR "/corpus")) {
    if (!entry.is_regular_file() || entry.path().filename() == "README.md") continue;
    const std::string path = entry.path().string();
    SCOPED_TRACE(path);
    ++files;
    Result<PointSet> read = readPoints(path);
    ASSERT_FALSE(read.ok()) << "read " << read->size() << " points";
    const Error& e = read.error();
    EXPECT_TRUE(e.code == ExitCode::kBadInput || e.code == ExitCode::kResourceLimit) << int(e.code) << " " << e.message;
    EXPECT_EQ(e.message.rfind(path + ":", 0), 0u) << e.message;  // "PATH: " or "PATH:LINE: "
    EXPECT_TRUE(std::none_of(e.message.begin(), e.message.end(),
                             [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; }))
        << e.message;
  }
  EXPECT_GE(files, 11u);
}

}  // namespace
}  // namespace dpoint
