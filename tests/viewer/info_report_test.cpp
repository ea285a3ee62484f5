// viewer/info_report.h gives a set in memory the report `dpoint info` prints for the same points
// in a file: the same JSON and text, byte for byte, with the file's path as the report's name (a
// front end such as the Python module gets the CLI's facts, not a second implementation's).
#include "viewer/info_report.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "converters/point_io.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::runDpoint;
using test::TempDir;

// 200 points of a 3D grid at the Earth's radius (1 m apart in x, where float32 steps 0.5 m), a copy of one,
// two points float32 merges, colours and two triangles: every line of the report has something to say.
PointSet earthGrid() {
  PointSet points;
  for (int i = 0; i < 200; ++i)
    points.positions.emplace_back(6378137.0 + 1.0 * (i % 10), 0.5 * ((i / 10) % 5), 0.125 * (i / 50));
  points.positions.push_back(points.positions[17]);
  points.positions.emplace_back(6378137.0 + 0.001, 7.0, 7.0);
  points.positions.emplace_back(6378137.0 + 0.002, 7.0, 7.0);
  for (size_t i = 0; i < points.size(); ++i) points.colors.emplace_back(float(i % 3) / 2, 0.5f, 1.0f);
  points.triangles = {0, 1, 10, 1, 11, 10};
  return points;
}

// A 2D grid (every z 0): the fit is orthographic.
PointSet plane() {
  PointSet points;
  for (int i = 0; i < 64; ++i)
    points.positions.emplace_back(-0.743645 + 1e-12 * (i % 8), 0.1318259 + 1e-12 * (i / 8), 0.0);
  return points;
}

// describePoints' report of `points` (named `path`), checked against what `dpoint info --json` and
// `dpoint info` print, each with `flags`, for the same points written to `path` (binary PLY keeps
// every double): the same JSON and text, byte for byte.
InfoReport expectDpointInfosReport(const PointSet& points, const std::string& path, const InfoOptions& options,
                                   const std::vector<std::string>& flags = {}) {
  EXPECT_TRUE(writePoints(path, points).ok()) << path;
  Result<InfoReport> report = describePoints(points, path, options);
  EXPECT_TRUE(report.ok()) << (report.ok() ? "" : report.error().message);
  if (!report.ok()) return InfoReport{};
  test::CommandResult json = runDpoint(test::concat({"info", "--json", path}, flags));
  EXPECT_EQ(json.exit_code, 0) << json.err;
  EXPECT_EQ(infoReportJson(*report), json.out) << path;
  test::CommandResult text = runDpoint(test::concat({"info", path}, flags));
  EXPECT_EQ(text.exit_code, 0) << text.err;
  EXPECT_EQ(infoReportText(*report), text.out) << path;
  return *report;
}

TEST(InfoReport, describePointsGivesTheJsonAndTextOfDpointInfo) {
  TempDir dir;
  const InfoReport grid = expectDpointInfosReport(earthGrid(), dir.file("grid.ply"), InfoOptions{});
  ASSERT_TRUE(grid.advice.has_value());
  EXPECT_FALSE(grid.advice->camera.ortho) << "a 3D set's fit is a perspective";
  EXPECT_FALSE(grid.streamed);
  EXPECT_FALSE(grid.las.has_value());
  EXPECT_EQ(grid.info.triangles, 2u);
  EXPECT_EQ(grid.info.float_merged, 1u) << "the two points 1 mm apart at 6378137 m";
  EXPECT_TRUE(test::contains(infoReportJson(grid), "\"float32_represents\": false"));

  // The camera options, the sample and the tolerance reach the report as the flags do.
  InfoOptions zoom;
  zoom.camera.view_center = glm::dvec3(-0.743645, 0.1318259, 0.0);
  zoom.camera.view_width = 4e-12;
  zoom.camera.width = 512, zoom.camera.height = 256;
  zoom.sample = 7, zoom.tolerance_px = 0.5, zoom.threads = 1;
  const InfoReport deep =
      expectDpointInfosReport(plane(), dir.file("plane.ply"), zoom,
                              {"--view-center", "-0.743645,0.1318259", "--view-width", "4e-12", "--width", "512",
                               "--height", "256", "--sample", "7", "--tolerance", "0.5", "--threads", "1"});
  ASSERT_TRUE(deep.advice.has_value());
  EXPECT_TRUE(deep.advice->camera.ortho) << "a 2D set's view is orthographic";
  EXPECT_EQ(deep.info.neighbor_sample, 7u);
  EXPECT_TRUE(test::contains(infoReportJson(deep), "\"view\": {\"width\": 512, \"height\": 256, \"ortho\": true"));
}

// The CLI reads nan and inf only with --allow-nonfinite; the report of such a set in memory is the
// one it then prints (the nulls of JSON where a number is not finite).
TEST(InfoReport, nonFinitePositionsGiveWhatDpointInfoGivesWithAllowNonfinite) {
  TempDir dir;
  PointSet points;
  points.positions = {{1.0, 2.0, 3.0},
                      {std::nan(""), 0.0, 0.0},
                      {std::numeric_limits<double>::infinity(), 1.0, 2.0},
                      {4.0, 5.0, 6.5}};
  const std::string path = dir.file("nonfinite.ply");
  ASSERT_TRUE(writePoints(path, points).ok());
  EXPECT_EQ(runDpoint({"info", path}).exit_code, 2) << "refused without --allow-nonfinite";
  const InfoReport report = expectDpointInfosReport(points, path, InfoOptions{}, {"--allow-nonfinite"});
  EXPECT_EQ(report.info.count, 4u);
  EXPECT_EQ(report.info.nonfinite, 2u);
  EXPECT_TRUE(test::contains(infoReportJson(report), "\"max\": [null, 5, 6.5]"));
  EXPECT_TRUE(test::contains(infoReportJson(report), "\"nonfinite_points\": 2"));
  EXPECT_TRUE(test::contains(infoReportText(report), "non-finite:         2 points with a coordinate nan or inf"));
  // No mode places the points: every bound unbounded (batch and adaptive said 0 px with an inf).
  // The view frames the two finite points (it framed an inf extent: 0 points visible).
  ASSERT_TRUE(report.advice.has_value());
  EXPECT_EQ(report.advice->bounds.visible, 2u);
  EXPECT_TRUE(report.advice->camera.note.empty()) << report.advice->camera.note;
  for (size_t m = 0; m < kModeCount; ++m) {
    if (report.advice->bounds.computed[m]) {
      EXPECT_EQ(report.advice->bounds.px[m], HUGE_VAL) << m;
    }
  }
  // Streamed, the same counts and bounds, and no mode bounded where a point has no place (the
  // stream refused the file, --allow-nonfinite or not, before).
  EXPECT_EQ(runDpoint({"info", "--stream", "on", path}).exit_code, 2) << "refused without --allow-nonfinite";
  test::CommandResult streamed = runDpoint({"info", "--json", "--stream", "on", "--allow-nonfinite", path});
  ASSERT_EQ(streamed.exit_code, 0) << streamed.err;
  // The view frames the finite points, as read whole (it framed an inf extent: orthographic, a note).
  for (const char* line : {"\"points\": 4", "\"max\": [null, 5, 6.5]", "\"nonfinite_points\": 2", "\"streamed\": true",
                           "\"view\": {\"width\": 1024, \"height\": 768, \"ortho\": false, \"points_visible\": 4}"})
    EXPECT_TRUE(test::contains(streamed.out, line)) << line << "\n" << streamed.out;
  EXPECT_TRUE(test::contains(streamed.out, "\"error_bound_px\": {\"fp32\": null, \"split\": null, \"rte\": null, "
                                            "\"df64\": null, \"native\": null, \"batch\": null, \"adaptive\": null}"))
      << streamed.out;
}

// An empty set: counts of 0 and no view, so no error bounds.
TEST(InfoReport, emptySetHasNoAdviceAsInDpointInfo) {
  TempDir dir;
  const InfoReport report = expectDpointInfosReport(PointSet{}, dir.file("empty.ply"), InfoOptions{});
  EXPECT_FALSE(report.advice.has_value());
  EXPECT_EQ(infoReportJson(report).find("\"view\""), std::string::npos);
  EXPECT_EQ(infoReportText(report).find("error bound by mode"), std::string::npos);
  // No bounds to state: not "min: 0 0 0", and float32 has nothing to hold (issue #36).
  EXPECT_TRUE(test::contains(infoReportText(report), "bounds:             none (no points)\n"));
  EXPECT_TRUE(test::contains(infoReportText(report), "float32 enough:     nothing to hold (no points)\n"));
  EXPECT_EQ(infoReportText(report).find("min:"), std::string::npos);
  EXPECT_TRUE(test::contains(infoReportJson(report), "\"min\": null"));
}

// One point that float32 merges with another is one point, not "1 distinct points".
TEST(InfoReport, oneMergedPointIsSingular) {
  PointSet points;
  points.positions = {{1.0, 0.0, 0.0}, {1.0 + 1e-12, 0.0, 0.0}, {2.0, 0.0, 0.0}};
  Result<InfoReport> report = describePoints(points, "two.ply", InfoOptions{});
  ASSERT_TRUE(report.ok());
  EXPECT_EQ(report->info.float_merged, 1u);
  EXPECT_TRUE(test::contains(infoReportText(*report), "no (1 distinct point merges with another)"));
}

// A set read a block at a time: what `dpoint info --stream on` prints (no merge count, bounds
// from the batches' boxes).
TEST(InfoReport, describeStreamGivesWhatDpointInfoStreamPrints) {
  TempDir dir;
  const std::string path = dir.file("grid.ply");
  ASSERT_TRUE(writePoints(path, earthGrid()).ok());
  Result<std::unique_ptr<PointInputStream>> stream = PointInputStream::open({path}, 0);
  ASSERT_TRUE(stream.ok()) << stream.error().message;
  Progress progress;  // silent
  Result<InfoReport> report = describeStream(**stream, path, InfoOptions{}, progress);
  ASSERT_TRUE(report.ok()) << report.error().message;
  EXPECT_TRUE(report->streamed);
  ASSERT_TRUE(report->advice.has_value());
  EXPECT_TRUE(report->advice->bounds.from_boxes);
  test::CommandResult json = runDpoint({"info", "--json", "--stream", "on", path});
  ASSERT_EQ(json.exit_code, 0) << json.err;
  EXPECT_EQ(infoReportJson(*report), json.out);
  EXPECT_TRUE(test::contains(json.out, "\"float32_merged_points\": null"));
}

TEST(InfoReport, describeFilesRefusesNoInput) {
  Progress progress;  // silent
  Result<InfoReport> report = describeFiles(InfoInputs{}, InfoOptions{}, progress);
  ASSERT_FALSE(report.ok());
  EXPECT_EQ(report.error().code, ExitCode::kUsage);
  EXPECT_TRUE(test::contains(report.error().message, "no input files"));
}

}  // namespace
}  // namespace dpoint
