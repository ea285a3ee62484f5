// COPC through the CLI (issue #35): every writer's .copc.laz reads back as the same points, and a
// render of a COPC file reads only the nodes its view needs: the whole file at the picture's
// resolution by default, a few nodes for a small orthographic window; --json says how much. info
// reads the same nodes for the same view.
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

PositionArray sorted(PositionArray p) {
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

// info reads a COPC file's nodes and keeps its CRS: simple1_4.las's WKT is an EVLR, which the read
// of the nodes (the hierarchy left behind) dropped: "none" where convert had copied it.
TEST(CliCopc, infoNamesTheCrsOfAnEvlr) {
  TempDir dir;
  const std::string las = std::string(DPOINT_CORPUS_DIR) + "/las/simple1_4.las";
  ASSERT_EQ(runDpoint({"convert", las, "-o", dir.file("s.copc.laz"), "-q"}).exit_code, 0);
  test::CommandResult info = runDpoint({"info", dir.file("s.copc.laz"), "-q"});
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_NE(info.out.find("LAS CRS:            Geographic Coordinate System, WKT\n"), std::string::npos) << info.out;
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

  // info reads as render does: the same nodes for the same view, and says so; --stream on reads
  // the file as plain LAZ, every point.
  const auto info = [&](const std::vector<std::string>& extra) {
    std::vector<std::string> args = {"info", dir.file("r.copc.laz"), "--width", "200", "--height", "200", "--json",
                                     "--sample", "100"};
    args.insert(args.end(), extra.begin(), extra.end());
    test::CommandResult r = runDpoint(args);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return r.out;
  };
  const std::string described = info({});
  EXPECT_EQ(number(described, "points_read"), number(whole, "points_read")) << described;
  EXPECT_EQ(number(described, "points"), number(whole, "points_read")) << described;
  EXPECT_EQ(number(described, "file_points"), 600000.0);
  const std::string described_deep =
      info({"--ortho", "--view-center", centre_text, "--view-width", std::to_string(extent.x / 100)});
  EXPECT_EQ(number(described_deep, "bytes_read"), number(deep, "bytes_read")) << described_deep;
  const std::string all = info({"--stream", "on"});
  EXPECT_EQ(all.find("\"copc\""), std::string::npos) << all;
  EXPECT_EQ(number(all, "points"), 600000.0);
  test::CommandResult text = runDpoint({"info", dir.file("r.copc.laz"), "--width", "200", "--height", "200"});
  EXPECT_TRUE(test::contains(text.out, "(read by view, of 600000 in the file: COPC)")) << text.out;
  EXPECT_TRUE(test::contains(text.out, "copc:               the view read ")) << text.out;
}

// A perspective view of 3D data: the nodes in its frustum, each as deep as a pixel at its nearest
// depth needs. From far away, a coarse preview; from within the set, looking along it, the near
// nodes deep and the far ones coarse, less than the whole file at the picture's resolution.
TEST(CliCopc, aPerspectiveViewReadsItsFrustumDeepWhereNear) {
  TempDir dir;
  const std::string copc = dir.file("s.copc.laz");
  ASSERT_EQ(runDpoint({"generate", "sierpinski", "--level", "9", "-q", "-o", copc}).exit_code, 0);
  const auto render = [&](const std::vector<std::string>& view) {
    std::vector<std::string> args = {"render", copc, "-o", dir.file("v.png"), "--width", "320", "--height", "240",
                                     "--json", dir.file("v.json"), "-q"};
    args.insert(args.end(), view.begin(), view.end());
    test::CommandResult r = runDpoint(args);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return readFile(dir.file("v.json"));
  };
  const std::string whole = render({});
  const std::string far = render({"--eye", "0.2,0,40", "--target", "0.2,0,0", "--up", "0,1,0"});
  const std::string near = render({"--eye", "0.9,0,-0.3", "--target", "0.5,0,-0.33", "--up", "0,0,1"});
  const std::string away = render({"--eye", "0.2,0,3", "--target", "0.2,0,6", "--up", "0,1,0"});
  EXPECT_LT(number(far, "points_read"), number(whole, "points_read")) << far;
  EXPECT_GT(number(far, "points_read"), 0.0);
  EXPECT_LT(number(near, "bytes_read"), number(whole, "bytes_read")) << near;
  EXPECT_GT(number(near, "nodes_read"), number(far, "nodes_read")) << near;
  EXPECT_EQ(number(away, "nodes_read"), 1.0) << away;  // looking away from the set: the root only
}

// info and render go by the content: a plain LAZ named .copc.laz is read whole (it had been
// refused, "not COPC: LAS 1.2", where convert read it), a COPC named .laz by view.
TEST(CliCopc, infoAndRenderTellCopcByItsContentNotItsName) {
  TempDir dir;
  std::filesystem::copy_file(std::string(DPOINT_CORPUS_DIR) + "/las/simple.laz", dir.file("plain.copc.laz"));
  for (const char* command : {"info", "render"}) {
    std::vector<std::string> args = {command, dir.file("plain.copc.laz")};
    if (std::string(command) == "render") args.insert(args.end(), {"-o", dir.file("p.png"), "--width", "64", "--height", "48"});
    test::CommandResult plain = runDpoint(args);
    EXPECT_EQ(plain.exit_code, 0) << command << ": " << plain.err;
    EXPECT_FALSE(test::contains(plain.out, "read by view")) << plain.out;
  }
  ASSERT_EQ(runDpoint({"convert", std::string(DPOINT_CORPUS_DIR) + "/las/simple.las", "-o", dir.file("c.copc.laz")}).exit_code, 0);
  std::filesystem::copy_file(dir.file("c.copc.laz"), dir.file("renamed.laz"));
  test::CommandResult renamed = runDpoint({"info", dir.file("renamed.laz")});
  EXPECT_EQ(renamed.exit_code, 0) << renamed.err;
  EXPECT_TRUE(test::contains(renamed.out, "(read by view, of 1065 in the file: COPC)")) << renamed.out;
}

}  // namespace
}  // namespace dpoint
