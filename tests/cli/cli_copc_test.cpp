// COPC through the CLI (issue #35): every writer's .copc.laz reads back as the same points, and a
// render of a COPC file reads only the nodes its view needs: the whole file at the picture's
// resolution by default, a few nodes for a small orthographic window; --json says how much.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "converters/copc.h"
#include "converters/point_io.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::readFile;
using test::runDpoint;
using test::TempDir;

// The number after "KEY": in a JSON text (the report's keys are unique).
double number(const std::string& json, const std::string& key) {
  const size_t at = json.find("\"" + key + "\": ");
  if (at == std::string::npos) return -1.0;
  return std::stod(json.substr(at + key.size() + 4));
}

std::vector<glm::dvec3> sorted(std::vector<glm::dvec3> p) {
  std::sort(p.begin(), p.end(), [](const glm::dvec3& a, const glm::dvec3& b) {
    return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
  });
  return p;
}

TEST(CliCopc, convertWritesCopcThatReadsAsTheSamePoints) {
  TempDir dir;
  const std::string las = std::string(DPOINT_CORPUS_DIR) + "/las/simple1_4.las";
  test::CommandResult r = runDpoint({"convert", las, "-o", dir.file("s.copc.laz"), "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  Result<InputFile> file = InputFile::open(dir.file("s.copc.laz"));
  ASSERT_TRUE(file);
  EXPECT_TRUE(isCopc(*file));
  Result<PointSet> copc = readPoints(dir.file("s.copc.laz")), source = readPoints(las);
  ASSERT_TRUE(copc) << copc.error().message;
  ASSERT_TRUE(source);
  EXPECT_EQ(sorted(copc->positions), sorted(source->positions));  // the octree reorders, keeps every point
}

TEST(CliCopc, aSmallWindowReadsAFewNodesAndTheReportSaysSo) {
  TempDir dir;
  // 600,000 points on a 2D square 1000 wide: several levels of nodes.
  ASSERT_EQ(runDpoint({"generate", "random2d", "--count", "600000", "--seed", "5", "-q", "-o", dir.file("r.ply")}).exit_code, 0);
  ASSERT_EQ(runDpoint({"convert", dir.file("r.ply"), "-o", dir.file("r.copc.laz"), "-q"}).exit_code, 0);
  Result<PointSet> set = readPoints(dir.file("r.ply"));
  ASSERT_TRUE(set);
  const Box box = boundingBox(set->positions, 0, set->size());
  const glm::dvec3 centre = (box.min + box.max) * 0.5, extent = box.max - box.min;
  const auto render = [&](const std::vector<std::string>& view) {
    std::vector<std::string> args = {"render", dir.file("r.copc.laz"), "-o", dir.file("v.png"), "--width", "200",
                                     "--height", "200", "--json", dir.file("v.json")};
    args.insert(args.end(), view.begin(), view.end());
    test::CommandResult r = runDpoint(args);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("copc: the view read "), std::string::npos) << r.out;
    return readFile(dir.file("v.json"));
  };
  const std::string whole = render({});
  const double file_bytes = number(whole, "file_bytes");
  EXPECT_EQ(number(whole, "file_points"), 600000.0);
  // The whole file at 200 px: a thinned preview, not every point.
  EXPECT_GT(number(whole, "points_read"), 0.0);
  EXPECT_LT(number(whole, "points_read"), 600000.0);
  // A window 1% of the extent wide: a few nodes, a small part of the bytes.
  const std::string centre_text = std::to_string(centre.x) + "," + std::to_string(centre.y);
  const std::string deep = render({"--ortho", "--view-center", centre_text, "--view-width", std::to_string(extent.x / 100)});
  EXPECT_LE(number(deep, "bytes_read"), file_bytes / 2) << deep;  // 16.7M points: under 10% (bench/results)
  EXPECT_LT(number(deep, "nodes_read"), number(whole, "nodes_read") + 8) << deep;
  EXPECT_GT(number(deep, "points_read"), 0.0);
}

}  // namespace
}  // namespace dpoint
