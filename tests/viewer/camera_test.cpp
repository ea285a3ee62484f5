#include "viewer/camera.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <unistd.h>
#include <string>
#include <utility>
#include <vector>

#include "converters/point_io.h"
#include "core/progress.h"
#include "generators/mandelbrot2d.h"
#include "generators/mandelbulb.h"
#include "viewer/reference.h"
#include "viewer/render_job.h"

namespace dpoint {
namespace {

PositionArray cornersOf(const Bounds& b) {
  PositionArray out;
  for (int i = 0; i < 8; ++i) {
    out.push_back({(i & 1) ? b.max.x : b.min.x, (i & 2) ? b.max.y : b.min.y, (i & 4) ? b.max.z : b.min.z});
  }
  return out;
}

Camera make(const CameraSpec& spec, const Bounds& bounds) {
  Result<Camera> camera = makeCamera(spec, bounds);
  EXPECT_TRUE(camera.ok()) << camera.error().message;
  return camera.ok() ? camera.value() : Camera{};
}

WindowPoint project(const Camera& camera, const glm::dvec3& p) { return projectReference({p}, camera)[0]; }

bool allFinite(const glm::dmat4& m) {
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) {
      if (!std::isfinite(m[c][r])) return false;
    }
  }
  return true;
}

void expectUsable(const Camera& camera) {
  EXPECT_TRUE(allFinite(camera.rotation));
  EXPECT_TRUE(allFinite(camera.projection));
  EXPECT_TRUE(std::isfinite(camera.near_plane) && std::isfinite(camera.far_plane));
  EXPECT_LT(camera.near_plane, camera.far_plane);
  if (!camera.ortho) {
    EXPECT_GT(camera.near_plane, 0.0);
  }
}

// Every corner inside the viewport with depth in [0, 1], and the box not lost in a corner of it:
// its projection spans at least `min_fill` of the width or of the height.
void expectFramed(const Camera& camera, const Bounds& bounds, double min_fill) {
  expectUsable(camera);
  double lo_x = HUGE_VAL, hi_x = -HUGE_VAL, lo_y = HUGE_VAL, hi_y = -HUGE_VAL;
  for (const WindowPoint& w : projectReference(cornersOf(bounds), camera)) {
    ASSERT_TRUE(w.visible);
    EXPECT_GE(w.depth, 0.0);
    EXPECT_LE(w.depth, 1.0);
    lo_x = std::min(lo_x, w.x), hi_x = std::max(hi_x, w.x);
    lo_y = std::min(lo_y, w.y), hi_y = std::max(hi_y, w.y);
  }
  EXPECT_GE(std::max((hi_x - lo_x) / camera.width, (hi_y - lo_y) / camera.height), min_fill);
}

TEST(Camera, fitFramesTheBoundingBox) {
  const std::vector<Bounds> boxes = {
      {{-1, -1, -1}, {1, 1, 1}},
      {{-5, 20, 0.5}, {100, 22, 0.75}},
      {{0, 0, -300}, {1, 1, 300}},
      {{6.378e6, 6.378e6, 6.378e6}, {6.378e6 + 0.01, 6.378e6 + 0.01, 6.378e6 + 0.01}},
      {{6.378e6, -2.0, 1e-3}, {6.378e6 + 0.01, -1.99, 1e-3 + 0.01}},
  };
  const std::array<std::array<uint32_t, 2>, 3> viewports = {{{1024, 768}, {300, 1000}, {1, 1}}};
  for (const Bounds& bounds : boxes) {
    for (const auto& [width, height] : viewports) {
      SCOPED_TRACE(std::to_string(bounds.min.x) + " " + std::to_string(width) + "x" + std::to_string(height));
      CameraSpec spec;
      spec.width = width, spec.height = height;
      const Camera camera = make(spec, bounds);
      EXPECT_FALSE(camera.ortho);
      expectFramed(camera, bounds, 0.3);
    }
  }
}

TEST(Camera, fitOfOnePointLooksAtIt) {
  for (const glm::dvec3 p : {glm::dvec3(0.0), glm::dvec3(6.378e6, 1.0, -3.0), glm::dvec3(-0.7, 0.13, 0.0)}) {
    for (bool planar : {false, true}) {
      const Bounds bounds{p, p, planar && p.z == 0.0};
      const Camera camera = make(CameraSpec{}, bounds);
      expectUsable(camera);
      EXPECT_NE(camera.eye, p);
      const WindowPoint w = project(camera, p);
      ASSERT_TRUE(w.visible);
      EXPECT_NEAR(w.x, 512.0, 1e-6);
      EXPECT_NEAR(w.y, 384.0, 1e-6);
    }
  }
}

TEST(Camera, fit2DIsOrthographicStraightDownWithASmallMargin) {
  const Bounds bounds{{-2, -1, 0}, {2, 1, 0}, true};
  const Camera camera = make(CameraSpec{}, bounds);
  EXPECT_TRUE(camera.ortho);
  EXPECT_EQ(camera.rotation, glm::dmat4(1.0));
  expectFramed(camera, bounds, 0.9);
  // x spans the width less the 2% margin; +y is up on screen (smaller window y).
  EXPECT_NEAR(project(camera, {2, 0, 0}).x - project(camera, {-2, 0, 0}).x, 1024.0 / 1.02, 1e-9);
  EXPECT_LT(project(camera, {0, 1, 0}).y, project(camera, {0, -1, 0}).y);
  EXPECT_NEAR(project(camera, {0, 0, 0}).x, 512.0, 1e-9);
}

TEST(Camera, fitPerspectiveOn2DDataLooksStraightDown) {
  const Bounds bounds{{10, 20, 0}, {14, 21, 0}, true};
  CameraSpec spec;
  spec.ortho = false;
  const Camera camera = make(spec, bounds);
  EXPECT_FALSE(camera.ortho);
  expectFramed(camera, bounds, 0.9);
  EXPECT_DOUBLE_EQ(camera.eye.x, 12.0);
  EXPECT_DOUBLE_EQ(camera.eye.y, 20.5);
  EXPECT_GT(camera.eye.z, 0.0);
}

TEST(Camera, lookAtPutsTheTargetAtTheViewportCentre) {
  CameraSpec spec;
  spec.eye = glm::dvec3(10, 5, 3), spec.target = glm::dvec3(1, 2, -4), spec.up = glm::dvec3(0, 0, 1);
  const Bounds bounds{{-5, -5, -5}, {5, 5, 5}};
  const Camera camera = make(spec, bounds);
  expectUsable(camera);
  const WindowPoint centre = project(camera, *spec.target);
  ASSERT_TRUE(centre.visible);
  EXPECT_NEAR(centre.x, 512.0, 1e-9);
  EXPECT_NEAR(centre.y, 384.0, 1e-9);
  // Up in the world is up on screen (y down), and right = forward × up is right on screen.
  const glm::dvec3 forward = glm::normalize(*spec.target - *spec.eye);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, *spec.up));
  EXPECT_LT(project(camera, *spec.target + 0.5 * *spec.up).y, 384.0);
  EXPECT_GT(project(camera, *spec.target + 0.5 * right).x, 512.0);
  // Look-at does not frame the box, but near and far still enclose it.
  for (const glm::dvec3& corner : cornersOf(bounds)) {
    const glm::dvec4 clip = camera.viewProjection() * glm::dvec4(corner, 1.0);
    EXPECT_GT(clip.w, 0.0);
    EXPECT_GE(clip.z / clip.w, 0.0);
    EXPECT_LE(clip.z / clip.w, 1.0);
  }
}

TEST(Camera, pointsBehindOrAtTheEyeAreInvisibleAndFinite) {
  CameraSpec spec;
  spec.eye = glm::dvec3(0.5, 0.5, 0.5), spec.target = glm::dvec3(0.5, 0.5, -1), spec.up = glm::dvec3(0, 1, 0);
  const Bounds bounds{{0, 0, 0}, {1, 1, 1}};  // the eye is inside the box
  const Camera camera = make(spec, bounds);
  expectUsable(camera);
  const PositionArray points = {*spec.eye, *spec.eye + glm::dvec3(0, 0, 0.25),
                                          *spec.eye + glm::dvec3(0.1, 0.2, 1e-3),
                                          *spec.eye + glm::dvec3(0, 0, -1e-9)};  // in front, nearer than near
  for (const WindowPoint& w : projectReference(points, camera)) {
    EXPECT_FALSE(w.visible);
    EXPECT_EQ(w.x, 0.0);
    EXPECT_EQ(w.y, 0.0);
    EXPECT_EQ(w.depth, 0.0);
  }
  // The box in front of the eye is still seen.
  EXPECT_TRUE(project(camera, {0.5, 0.5, 0.0}).visible);
}

TEST(Camera, reversedZGivesTheNearerPointTheGreaterDepth) {
  for (bool ortho : {false, true}) {
    CameraSpec spec;
    spec.eye = glm::dvec3(0, 0, 10), spec.target = glm::dvec3(0, 0, 0), spec.up = glm::dvec3(0, 1, 0);
    spec.ortho = ortho;
    const Camera camera = make(spec, {{-1, -1, -1}, {1, 1, 1}});
    const WindowPoint nearer = project(camera, {0.1, 0.1, 0.5});
    const WindowPoint farther = project(camera, {0.1, 0.1, -0.5});
    ASSERT_TRUE(nearer.visible && farther.visible);
    EXPECT_GT(nearer.depth, farther.depth) << "ortho " << ortho;
    // The planes themselves map to 1 (near) and 0 (far).
    EXPECT_NEAR(project(camera, {0, 0, 10 - camera.near_plane}).depth, 1.0, 1e-12);
    EXPECT_NEAR(project(camera, {0, 0, 10 - camera.far_plane}).depth, 0.0, 1e-12);
  }
}

// The deep-zoom hard case: a 1e-9 wide window at the Mandelbrot seahorse valley, 1024 px wide, so
// a pixel is ~1e-12 against coordinates ~0.74 (float resolves 6e-8 there). The exact window x of
// a double input p is 512 + (p − cx)·1024/w (p − cx is exact); the projection must hit it within
// 1e-6 px, and points placed at pixel centres (up to the ~6e-5 px rounding of p) land on their pixel.
TEST(Camera, orthoDeepZoomPutsPixelCentresAtHalfPixels) {
  const double cx = -0.7436450, cy = 0.1318259, view_width = 1e-9;
  CameraSpec spec;
  spec.ortho = true, spec.view_center = glm::dvec3(cx, cy, 0), spec.view_width = view_width;
  const Bounds bounds{{cx - 1e-9, cy - 1e-9, 0}, {cx + 1e-9, cy + 1e-9, 0}, true};
  const Camera camera = make(spec, bounds);
  ASSERT_TRUE(camera.ortho);
  const double pixel = view_width / 1024;
  PositionArray points;
  std::vector<int> columns, rows;
  for (int k = -512; k < 512; ++k) {
    const int j = (k * 7 + 100000) % 768 - 384;  // rows spread over the whole height
    points.push_back({cx + (k + 0.5) * pixel, cy - (j + 0.5) * pixel, 0.0});
    columns.push_back(512 + k), rows.push_back(384 + j);
  }
  const std::vector<WindowPoint> window = projectReference(points, camera);
  for (size_t i = 0; i < points.size(); ++i) {
    ASSERT_TRUE(window[i].visible) << i;
    const long double exact_x = 512.0L + (long double)(points[i].x - cx) * 1024.0L / (long double)view_width;
    const long double exact_y = 384.0L - (long double)(points[i].y - cy) * 1024.0L / (long double)view_width;
    EXPECT_NEAR(window[i].x, double(exact_x), 1e-6) << i;
    EXPECT_NEAR(window[i].y, double(exact_y), 1e-6) << i;
    EXPECT_NEAR(window[i].x, columns[i] + 0.5, 1e-3) << i;
    EXPECT_NEAR(window[i].y, rows[i] + 0.5, 1e-3) << i;
    EXPECT_EQ(int(std::floor(window[i].x)), columns[i]);
    EXPECT_EQ(int(std::floor(window[i].y)), rows[i]);
  }
}

TEST(Camera, viewWidthOverridesThePerspectiveFitWindow) {
  CameraSpec spec;
  spec.view_center = glm::dvec3(3, 4, 5), spec.view_width = 2.0;
  const Camera camera = make(spec, {{0, 0, 0}, {10, 10, 10}});
  EXPECT_FALSE(camera.ortho);
  const glm::dvec3 right(camera.rotation[0][0], camera.rotation[1][0], camera.rotation[2][0]);
  EXPECT_NEAR(project(camera, *spec.view_center).x, 512.0, 1e-9);
  // The window is 2 wide at the target: half of it to the right is the right edge.
  EXPECT_NEAR(project(camera, *spec.view_center + 0.5 * right).x, 768.0, 1e-9);
}

TEST(Camera, viewIsRotationAfterTranslationAndViewProjectionMatchesTheReference) {
  const Camera camera = make(CameraSpec{}, {{1, 2, 3}, {4, 5, 7}});
  const glm::dvec4 at_eye = camera.view() * glm::dvec4(camera.eye, 1.0);
  EXPECT_NEAR(glm::length(glm::dvec3(at_eye)), 0.0, 1e-12);
  const glm::dvec3 p(2, 3, 4);
  const glm::dvec4 clip = camera.viewProjection() * glm::dvec4(p, 1.0);
  const WindowPoint w = project(camera, p);
  EXPECT_NEAR((clip.x / clip.w * 0.5 + 0.5) * camera.width, w.x, 1e-9);
  EXPECT_NEAR((clip.y / clip.w * 0.5 + 0.5) * camera.height, w.y, 1e-9);
  EXPECT_NEAR(clip.z / clip.w, w.depth, 1e-12);
}

void expectUsageError(const CameraSpec& spec, const std::string& needle) {
  Result<Camera> camera = makeCamera(spec, {{0, 0, 0}, {1, 1, 1}});
  ASSERT_FALSE(camera.ok()) << needle;
  EXPECT_EQ(camera.error().code, ExitCode::kUsage);
  EXPECT_NE(camera.error().message.find(needle), std::string::npos) << camera.error().message;
}

TEST(Camera, rejectsBadOptionsNamingThem) {
  CameraSpec spec;
  spec.height = 0;
  expectUsageError(spec, "--height 0: must be at least 1");
  for (double fov : {0.0, 180.0, -10.0, double(NAN)}) {
    spec = {};
    spec.fov_degrees = fov;
    expectUsageError(spec, ": must be in (0, 180)");
  }
  for (double width : {0.0, -1.0, double(INFINITY), double(NAN)}) {
    spec = {};
    spec.view_width = width;
    expectUsageError(spec, ": must be a finite number above 0");
  }
  spec = {};
  spec.eye = glm::dvec3(1, 2, 3), spec.target = glm::dvec3(1, 2, 3), spec.up = glm::dvec3(0, 1, 0);
  expectUsageError(spec, "--eye and --target are the same point (1, 2, 3)");
  spec.target = glm::dvec3(1, 5, 3);
  expectUsageError(spec, "--up (0, 1, 0) is parallel to the view direction");
  spec.up = glm::dvec3(0, 0, 0);
  expectUsageError(spec, ": must be a finite non-zero vector");
  spec.up.reset();
  expectUsageError(spec, "missing --up");
  spec = {};
  spec.eye = glm::dvec3(NAN, 0, 0), spec.target = glm::dvec3(0, 0, 0), spec.up = glm::dvec3(0, 1, 0);
  expectUsageError(spec, ": must be finite");
}

// The four views of `dpoint render --views 4`: the fit's direction and up steer the eye; the box
// stays framed, the eye sits along the direction from the centre, and up points up on screen.
// A review finding: data near the largest double (two points at 1e308) gave a fitted eye past it,
// and the error blamed --view-center/--view-width, which were not given. Now it is bad input
// (exit 2) saying why, and --ortho, which needs no eye that far, frames it. Points at ±1e308 whose
// fit sees none of them: auto must not take fp32, whose encoding cannot hold them (it had, and
// renderPoints then refused the set), so every mode past its range is unbounded.
TEST(Camera, coordinatesNearTheLargestDoubleAreBadInputNamingWhy) {
  // One point at 1e308 is framed both ways: its centre is no longer (min + max) / 2, which
  // overflowed (perspective refused it, and ortho drew nothing in a view infinitely wide).
  PointSet same;
  same.positions = {{1e308, 1e308, 1e308}, {1e308, 1e308, 1e308}};
  for (bool ortho : {false, true}) {
    CameraSpec spec;
    spec.ortho = ortho;
    const Camera camera = make(spec, boundsOf(same));
    expectUsable(camera);
    const WindowPoint w = project(camera, same.positions[0]);
    EXPECT_TRUE(w.visible) << ortho;
    EXPECT_NEAR(w.x, camera.width / 2.0, 1.0) << ortho;
    EXPECT_NEAR(w.y, camera.height / 2.0, 1.0) << ortho;
  }
  // A perspective eye past the largest double: refused, naming why.
  const double most = std::numeric_limits<double>::max();
  same.positions = {{most, most, most}, {most, most, most}};
  Result<Camera> perspective = makeCamera(CameraSpec{}, boundsOf(same));
  ASSERT_FALSE(perspective.ok());
  EXPECT_EQ(perspective.error().code, ExitCode::kBadInput);
  EXPECT_NE(perspective.error().message.find("too large to view in perspective"), std::string::npos) << perspective.error().message;
  EXPECT_EQ(perspective.error().message.find("--view-center"), std::string::npos) << perspective.error().message;
  // A field of view so narrow that the distance overflows for a unit box: the option's fault, not
  // the coordinates' (a review finding: "the data's coordinates (up to 0.99) are too large").
  CameraSpec narrow;
  narrow.fov_degrees = 1e-300;
  Result<Camera> needle = makeCamera(narrow, boundsOf(PointSet{PositionArray{{-1, -1, -1}, {1, 1, 1}}}));
  ASSERT_FALSE(needle.ok());
  EXPECT_EQ(needle.error().code, ExitCode::kUsage);
  EXPECT_EQ(needle.error().message.rfind("--fov 1e-300: so narrow a view", 0), 0u) << needle.error().message;
  EXPECT_FALSE(makeCamera(CameraSpec{}, boundsOf(PointSet{PositionArray{{1e308, 1e308, 1e308}, {-1e308, -1e308, -1e308}}})).ok());
  PointSet apart;  // past float32's range, and behind the eye
  apart.positions = {{1e39, 0.0, 0.0}, {1e39, 1.0, 1.0}};
  CameraSpec away;
  away.eye = glm::dvec3(1e39 + 1e25, 0.0, 0.0);
  away.target = glm::dvec3(1e39 + 2e25, 0.0, 0.0);
  away.up = glm::dvec3(0.0, 1.0, 0.0);
  Result<Camera> camera = makeCamera(away, boundsOf(apart));
  ASSERT_TRUE(camera.ok()) << camera.error().message;
  const ErrorBounds bounds = predictErrorBounds(apart, *camera);
  EXPECT_EQ(bounds.visible, 0u);
  EXPECT_TRUE(std::isinf(bounds.px[modeIndex(PrecisionMode::kFp32)]));
  EXPECT_TRUE(std::isfinite(bounds.px[modeIndex(PrecisionMode::kNative)]));
}

TEST(Camera, fitDirectionAndUpSteerTheFramedView) {
  const Bounds bounds{{6.378e6, -2.0, 10.0}, {6.378e6 + 3.0, 1.0, 11.0}};
  const glm::dvec3 centre = 0.5 * (bounds.min + bounds.max);
  for (const auto& [direction, up] : std::vector<std::pair<glm::dvec3, glm::dvec3>>{
           {{0, 0, 1}, {0, 1, 0}}, {{1, 0, 0}, {0, 1, 0}}, {{0, 1, 0}, {0, 0, -1}}, {{0.6, -1, 0.5}, {0, 0, 1}}}) {
    CameraSpec spec;
    spec.fit_direction = direction, spec.fit_up = up;
    const Camera camera = make(spec, bounds);
    expectFramed(camera, bounds, 0.3);
    // The eye looks back along the direction (the fit centres the box's lopsided perspective
    // projection, so the eye need not sit exactly on the line through the box's centre).
    const glm::dvec3 backward(camera.rotation[0][2], camera.rotation[1][2], camera.rotation[2][2]);
    EXPECT_NEAR(glm::dot(backward, direction / glm::length(direction)), 1.0, 1e-12);
    const glm::dvec3 from_centre = camera.eye - centre;
    EXPECT_GT(glm::dot(from_centre / glm::length(from_centre), direction / glm::length(direction)), 0.95);
    // A point above the centre (along up) lands above it on screen: smaller window y.
    EXPECT_LT(project(camera, centre + 0.1 * up).y, project(camera, centre).y);
  }
  CameraSpec parallel;
  parallel.fit_direction = glm::dvec3(0, 2, 0), parallel.fit_up = glm::dvec3(0, 1, 0);
  expectUsageError(parallel, "the fit's up (0, 1, 0) is parallel to its direction (0, 2, 0)");
  CameraSpec zero;
  zero.fit_direction = glm::dvec3(0.0);
  expectUsageError(zero, "the fit direction must be a finite non-zero vector");
  CameraSpec with_eye;
  with_eye.eye = glm::dvec3(0, 0, 5), with_eye.target = glm::dvec3(0.0), with_eye.up = glm::dvec3(0, 1, 0);
  with_eye.fit_direction = glm::dvec3(1, 0, 0);
  expectUsageError(with_eye, "cannot be combined with --eye");
}


// The fit frames a box however small it is against its coordinates: a deep zoom 1e-15 wide at
// 0.74 is a few ulps of double, and it still fills the picture (it was a 2-px square under the old
// 1e-10 relative floor), ortho and perspective, planar and 3D.
TEST(Camera, fitFillsThePictureAtEveryScale) {
  const glm::dvec3 c(-0.7436450, 0.1318259, 0.0);
  for (double width : {1e-6, 1e-12, 1e-15}) {
    for (bool planar : {true, false}) {
      for (bool ortho : {true, false}) {
        SCOPED_TRACE(std::to_string(width) + (planar ? " planar" : " 3D") + (ortho ? " ortho" : " perspective"));
        const glm::dvec3 half(width / 2, width / 2, planar ? 0.0 : width / 2);
        const Bounds bounds{c - half, c + half, planar};
        CameraSpec spec;
        spec.ortho = ortho;
        const Camera camera = make(spec, bounds);
        expectFramed(camera, bounds, 0.85);
      }
    }
  }
}

// An orthographic fit of data 1.2e306 wide: the view's height from the aspect, not width · height
// (which overflowed at 1024 × 768 and gave a blank picture and a bound of 0 px). Data spanning
// more than the largest double have no finite view: refused, naming why.
TEST(Camera, orthoFitOfDataNearTheLargestDoubleFillsThePicture) {
  const Bounds bounds{glm::dvec3(0.0), glm::dvec3(1.2e306, 1.2e306, 0.0), true};
  CameraSpec spec;
  spec.ortho = true;
  const Camera camera = make(spec, bounds);
  expectFramed(camera, bounds, 0.85);
  const Bounds widest{glm::dvec3(-1.6e308, -1.6e308, 0.0), glm::dvec3(1.6e308, 1.6e308, 0.0), true};
  spec.width = 100, spec.height = 400;
  Result<Camera> portrait = makeCamera(spec, widest);
  ASSERT_FALSE(portrait);
  EXPECT_EQ(portrait.error().code, ExitCode::kBadInput);
  EXPECT_NE(portrait.error().message.find("beyond the largest double"), std::string::npos) << portrait.error().message;
}

// A --fov so narrow that double cannot place the points within half a pixel of the fitted eye, and
// data below double's normal range, are refused naming why (each drew a blank picture with a bound
// of 0 px, exit 0); --fov 1e-9 still frames the data.
TEST(Camera, viewsBeyondDoubleAreRefused) {
  const Bounds box{glm::dvec3(0.0), glm::dvec3(1.0), false};
  CameraSpec narrow;
  narrow.fov_degrees = 1e-15;
  Result<Camera> blank = makeCamera(narrow, box);
  ASSERT_FALSE(blank);
  EXPECT_EQ(blank.error().code, ExitCode::kUsage);
  EXPECT_NE(blank.error().message.find("--fov 1e-15: too narrow for double"), std::string::npos) << blank.error().message;
  narrow.fov_degrees = 1e-9;
  expectFramed(make(narrow, box), box, 0.85);
  for (bool planar : {true, false}) {
    const Bounds tiny{glm::dvec3(0.0), glm::dvec3(1e-309, 1e-309, planar ? 0.0 : 1e-309), planar};
    Result<Camera> camera = makeCamera(CameraSpec{}, tiny);
    ASSERT_FALSE(camera) << planar;
    EXPECT_EQ(camera.error().code, ExitCode::kBadInput);
    EXPECT_NE(camera.error().message.find("no finite projection"), std::string::npos) << camera.error().message;
  }
}

// The fit of a set with an outline frames the points, not the box's empty corners: a Mandelbulb
// (its box corners project ~1.4x wider than it) spans ≥ 85% of the smaller side, every point
// inside the picture. With the box alone it spans ~72%.
// A set 2 wide in the plane x = 1e18, where double's step is 128: the fitted perspective eye, a few
// units off the plane, rounds into it and saw the data edge-on, and the planes' floor of 1e-10 of
// the coordinates put the near plane at 100, behind every point (a blank picture, exit 0). The
// default view draws it orthographic from the fit's direction, filling the picture, and says so; a
// view given with --eye keeps its perspective and its points.
TEST(Camera, aSetSmallAgainstItsCoordinatesIsDrawnOrthographicAndSaysSo) {
  const Bounds flat{{1e18, -1.0, -1.0}, {1e18, 1.0, 1.0}};
  const Camera fitted = make(CameraSpec{}, flat);
  EXPECT_TRUE(fitted.ortho);
  EXPECT_NE(fitted.note.find("drawn orthographic from the same direction"), std::string::npos) << fitted.note;
  EXPECT_NE(fitted.note.find("up to 1e+18"), std::string::npos) << fitted.note;
  expectFramed(fitted, flat, 0.85);
  // From the fit's direction: the rotation's third row (the eye's +z) is it.
  const glm::dvec3 direction = glm::normalize(glm::dvec3(0.6, 0.5, 1.0));
  EXPECT_NEAR(fitted.rotation[0][2], direction.x, 1e-12);
  EXPECT_NEAR(fitted.rotation[2][2], direction.z, 1e-12);
  // A set that double can view in perspective keeps it, with no note: the same plane at x = 1e15
  // (step 0.125), and a box 9 ulps wide (the rounded eye moves by ~5% of its distance).
  const Camera near = make(CameraSpec{}, Bounds{{1e15, -1.0, -1.0}, {1e15, 1.0, 1.0}});
  EXPECT_FALSE(near.ortho);
  EXPECT_EQ(near.note, "");
  const glm::dvec3 c(-0.7436450, 0.1318259, 0.3);
  const Camera tiny = make(CameraSpec{}, Bounds{c - glm::dvec3(5e-16), c + glm::dvec3(5e-16)});
  EXPECT_FALSE(tiny.ortho);
  EXPECT_EQ(tiny.note, "");
  // --ortho as asked, and an eye given in the plane: perspective, the points in front of it kept.
  CameraSpec ortho;
  ortho.ortho = true;
  EXPECT_EQ(make(ortho, flat).note, "");
  CameraSpec edge_on;
  edge_on.eye = glm::dvec3(1e18, 0.0, 5.0);
  edge_on.target = glm::dvec3(1e18, 0.0, 0.0);
  edge_on.up = glm::dvec3(0.0, 1.0, 0.0);
  const Camera given = make(edge_on, flat);
  EXPECT_FALSE(given.ortho);
  EXPECT_LT(given.near_plane, 4.0);
  for (const WindowPoint& w : projectReference(cornersOf(flat), given)) EXPECT_TRUE(w.visible);
}

TEST(Camera, fitWithAnOutlineFramesTheDataNotItsBox) {
  MandelbulbParams params;
  params.resolution = 64;
  Result<PointSet> bulb = generateMandelbulb(params);
  ASSERT_TRUE(bulb.ok()) << bulb.error().message;
  const Bounds outlined = boundsWithOutline(*bulb);
  ASSERT_FALSE(outlined.outline.empty());
  for (const auto& [width, height] : std::vector<std::pair<uint32_t, uint32_t>>{{1024, 768}, {480, 640}}) {
    CameraSpec spec;
    spec.width = width, spec.height = height;
    const auto span = [&](const Bounds& bounds) {
      const Camera camera = make(spec, bounds);
      double lo_x = HUGE_VAL, hi_x = -HUGE_VAL, lo_y = HUGE_VAL, hi_y = -HUGE_VAL;
      for (const WindowPoint& w : projectReference(bulb->positions, camera)) {
        EXPECT_TRUE(w.visible);
        lo_x = std::min(lo_x, w.x), hi_x = std::max(hi_x, w.x), lo_y = std::min(lo_y, w.y), hi_y = std::max(hi_y, w.y);
      }
      return std::max(hi_x - lo_x, hi_y - lo_y) / std::min(width, height);
    };
    EXPECT_GE(span(outlined), 0.85);
    EXPECT_LT(span(boundsOf(*bulb)), 0.8) << "the box alone frames its corners";
  }
  // Blocks in any order give the same outline.
  OutlineBuilder builder(outlined);
  const size_t half = bulb->size() / 2;
  builder.add(PositionArray(bulb->positions.begin() + long(half), bulb->positions.end()));
  builder.add(PositionArray(bulb->positions.begin(), bulb->positions.begin() + long(half)));
  EXPECT_EQ(builder.finish(), outlined.outline);
  // Boxes of 1024 consecutive points: one in a row is taken by its corners, the rest by their
  // points; the outline is the same.
  OutlineBuilder by_boxes(outlined);
  size_t read = 0;
  for (size_t first = 0; first < bulb->size(); first += 1024) {
    const auto from = bulb->positions.begin() + long(first), to = from + long(std::min<size_t>(1024, bulb->size() - first));
    const PositionArray batch(from, to);
    if (by_boxes.addBox(boundingBox(batch))) continue;
    by_boxes.add(batch);
    read += batch.size();
  }
  EXPECT_EQ(by_boxes.finish(), outlined.outline);
  EXPECT_GT(read, 0u);
}

// Real deep zooms drawn by the default render job on the device: each fills the picture (the
// 1e-12 one was a 7-px square, the 1e-15 one 2 px).
TEST(Camera, defaultRenderOfDeepZoomsFillsThePicture) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("dpoint-camera-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (double width : {1e-6, 1e-12, 1e-15}) {
    SCOPED_TRACE(width);
    Mandelbrot2dParams params;
    params.resolution = 256, params.width = width;
    Result<PointSet> set = generateMandelbrot2d(params);
    ASSERT_TRUE(set.ok()) << set.error().message;
    const std::string path = (dir / "deep.ply").string();
    ASSERT_TRUE(writePoints(path, *set).ok());
    RenderRequest request;
    request.inputs = {path};
    request.background_rgba8 = 0xffff00ffu;
    Progress progress;
    Result<RenderOutcome> outcome = runRenderJob(request, progress);
    ASSERT_TRUE(outcome.ok()) << outcome.error().message;
    EXPECT_GE(drawnPixels(outcome->image, request.background_rgba8).span(), 0.85);
    EXPECT_LE(drawnPixels(outcome->image, request.background_rgba8).span(), 1.0);
  }
  std::filesystem::remove_all(dir);
}

// The default render of a 3D set frames the data's outline, not its box: a Mandelbulb fills the
// picture's height (its box's corners alone give ~72%) without touching its edges, in memory and
// streamed alike (the same point size from the same spacing samples).
TEST(Camera, defaultRenderOfAMandelbulbFillsThePictureInMemoryAndStreamed) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("dpoint-bulb-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  MandelbulbParams params;
  params.resolution = 64;
  Result<PointSet> bulb = generateMandelbulb(params);
  ASSERT_TRUE(bulb.ok()) << bulb.error().message;
  const std::string path = (dir / "bulb.ply").string();
  ASSERT_TRUE(writePoints(path, *bulb).ok());
  std::vector<Image> pictures;
  for (const char* stream : {"off", "on"}) {
    SCOPED_TRACE(stream);
    RenderRequest request;
    request.inputs = {path};
    request.stream = stream;
    request.mode = "batch";  // a streamed set gets no prediction: auto would pick another mode
    request.background_rgba8 = 0xffff00ffu;
    Progress progress;
    Result<RenderOutcome> outcome = runRenderJob(request, progress);
    ASSERT_TRUE(outcome.ok()) << outcome.error().message;
    EXPECT_EQ(outcome->streamed, stream == std::string("on"));
    const DrawnPixels drawn = drawnPixels(outcome->image, request.background_rgba8);
    EXPECT_GE(drawn.span(), 0.85);
    EXPECT_GT(drawn.x0, 0u);
    EXPECT_GT(drawn.y0, 0u);
    EXPECT_LT(drawn.x1, outcome->image.width - 1);
    EXPECT_LT(drawn.y1, outcome->image.height - 1);
    pictures.push_back(outcome->image);
  }
  EXPECT_EQ(pictures[0].rgba, pictures[1].rgba);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace dpoint
