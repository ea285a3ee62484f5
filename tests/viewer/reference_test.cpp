#include "viewer/reference.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "test_support.h"

namespace dpoint {
namespace {

WindowPoint at(double x, double y, double depth = 0.5) { return {x, y, depth, true}; }

// Eye at the origin looking down −z, 90° vertical fov, 200×100: focal length 1, aspect 2.
Camera simplePerspective() {
  CameraSpec spec;
  spec.width = 200, spec.height = 100, spec.fov_degrees = 90.0;
  spec.eye = glm::dvec3(0, 0, 0), spec.target = glm::dvec3(0, 0, -1), spec.up = glm::dvec3(0, 1, 0);
  Result<Camera> camera = makeCamera(spec, {{-4, -4, -8}, {4, 4, -1}});
  EXPECT_TRUE(camera.ok());
  return camera.ok() ? camera.value() : Camera{};
}

TEST(Reference, projectionFollowsTheClipAndWindowFormulas) {
  const Camera camera = simplePerspective();
  const double n = camera.near_plane, f = camera.far_plane;
  // (1, 1, −2): x_c = 1/2, y_c = −1, w_c = 2 → ndc (0.25, −0.5) → window (125, 25).
  const WindowPoint w = projectReference({{1, 1, -2}}, camera)[0];
  ASSERT_TRUE(w.visible);
  EXPECT_NEAR(w.x, 125.0, 1e-12);
  EXPECT_NEAR(w.y, 25.0, 1e-12);
  EXPECT_NEAR(w.depth, (n / (f - n) * -2.0 + n * f / (f - n)) / 2.0, 1e-15);
  // Outside the viewport or beyond far: invisible.
  EXPECT_FALSE(projectReference({{5, 0, -2}}, camera)[0].visible);
  EXPECT_FALSE(projectReference({{0, 0, -2 * f}}, camera)[0].visible);
}

TEST(Reference, windowFromClipDividesInDoubleAndRejectsWhatIsNotInView) {
  const Camera camera = simplePerspective();
  const WindowPoint w = windowFromClip({0.5f, -1.0f, 0.25f, 2.0f}, camera);
  ASSERT_TRUE(w.visible);
  EXPECT_EQ(w.x, 125.0);
  EXPECT_EQ(w.y, 25.0);
  EXPECT_EQ(w.depth, 0.125);
  // Float's own division of 1/3 would round; the double division keeps more digits.
  EXPECT_EQ(windowFromClip({1.0f, 0.0f, 0.5f, 3.0f}, camera).x, (1.0 / 3.0 * 0.5 + 0.5) * 200.0);
  const std::vector<glm::vec4> rejected = {
      {0, 0, 0.5f, 0},         {0, 0, -0.5f, -1},      {NAN, 0, 0.5f, 1}, {0, INFINITY, 0.5f, 1},
      {0, 0, 1.5f, 1},         {0, 0, -0.1f, 1},       {-1, 0, 0.5f, 1},  {0, -1, 0.5f, 1},
      {0, 0, 0.5f, INFINITY},
  };
  for (const glm::vec4& clip : rejected) {
    const WindowPoint r = windowFromClip(clip, camera);
    EXPECT_FALSE(r.visible) << clip.x << " " << clip.y << " " << clip.z << " " << clip.w;
    EXPECT_EQ(r.x, 0.0);
    EXPECT_EQ(r.y, 0.0);
    EXPECT_EQ(r.depth, 0.0);
  }
  // The right and bottom edges are in, the left and top ones out: a point exactly on a pixel
  // corner lights the pixel up and left of it (top-left fill rule), and at x = 0 that is none.
  EXPECT_TRUE(windowFromClip({1, 1, 0.5f, 1}, camera).visible);
}

TEST(Reference, compareReportsMaxRmsP99ShareAndLost) {
  const std::vector<WindowPoint> reference = {at(10, 10), at(20, 20), at(30, 30), at(40, 40),
                                              at(50, 50), WindowPoint{}};
  const std::vector<WindowPoint> probe = {at(10, 10),      at(20.25, 20), at(30.5, 30),   at(40, 42),
                                          WindowPoint{},   at(60, 60)};  // lost; visible only in the probe
  const ErrorStats stats = compareToReference(reference, probe);
  EXPECT_EQ(stats.points, 5u);
  EXPECT_EQ(stats.lost, 1u);
  EXPECT_DOUBLE_EQ(stats.max_px, 2.0);
  EXPECT_DOUBLE_EQ(stats.p99_px, 2.0);  // nearest rank of 4 errors: the 4th
  EXPECT_NEAR(stats.rms_px, std::sqrt((0.0625 + 0.25 + 4.0) / 4.0), 1e-12);
  // Off by ≥ 0.5 px: the 0.5 px one, the 2 px one, and the lost one.
  EXPECT_DOUBLE_EQ(stats.share_off_half_px, 3.0 / 5.0);
}

TEST(Reference, compareP99IsTheNearestRank) {
  std::vector<WindowPoint> reference, probe;
  for (int i = 200; i >= 1; --i) {  // errors 0.01 … 2.00, out of order
    reference.push_back(at(100, 100));
    probe.push_back(at(100 + i * 0.01, 100));
  }
  const ErrorStats stats = compareToReference(reference, probe);
  EXPECT_NEAR(stats.p99_px, 1.98, 1e-12);  // rank ceil(0.99 · 200) = 198
  EXPECT_NEAR(stats.max_px, 2.0, 1e-12);
  EXPECT_EQ(stats.lost, 0u);
  EXPECT_DOUBLE_EQ(stats.share_off_half_px, 151.0 / 200.0);  // 0.50 … 2.00
}

TEST(Reference, compareWithNothingVisibleIsAllZero) {
  const ErrorStats none = compareToReference({WindowPoint{}}, {at(1, 1)});
  EXPECT_EQ(none.points, 0u);
  EXPECT_EQ(none.max_px, 0.0);
  EXPECT_EQ(none.share_off_half_px, 0.0);
  const ErrorStats all_lost = compareToReference({at(1, 1), at(2, 2)}, {WindowPoint{}, WindowPoint{}});
  EXPECT_EQ(all_lost.lost, 2u);
  EXPECT_EQ(all_lost.share_off_half_px, 1.0);
  EXPECT_EQ(all_lost.rms_px, 0.0);
}

std::vector<uint8_t> pixelAt(const Image& image, uint32_t x, uint32_t y) {
  const size_t offset = (size_t(y) * image.width + x) * 4;
  return {image.rgba.begin() + ptrdiff_t(offset), image.rgba.begin() + ptrdiff_t(offset + 4)};
}

TEST(Reference, rasterCoversTheFloorPixelRowMajorTopFirstWithRInTheLowByte) {
  // (1, 1) is a pixel corner: the top-left rule gives it to pixel (0, 0).
  const std::vector<WindowPoint> window = {at(2.999, 0.001), at(0.5, 1.999), at(1.0, 1.0), WindowPoint{}};
  const std::vector<uint32_t> colors = {0x44332211u, 0xff0000ffu, 0x80ff00ffu, 0xffffffffu};
  const Image image = rasterReference(window, colors, 4, 3, 0xff302010u);
  ASSERT_EQ(image.rgba.size(), 4u * 3u * 4u);
  EXPECT_EQ(pixelAt(image, 2, 0), (std::vector<uint8_t>{0x11, 0x22, 0x33, 0x44}));
  EXPECT_EQ(pixelAt(image, 0, 1), (std::vector<uint8_t>{0xff, 0x00, 0x00, 0xff}));
  EXPECT_EQ(pixelAt(image, 0, 0), (std::vector<uint8_t>{0xff, 0x00, 0xff, 0x80}));
  EXPECT_EQ(std::vector<uint8_t>(image.rgba.begin() + 8, image.rgba.begin() + 12), pixelAt(image, 2, 0));
  const std::vector<uint8_t> background = {0x10, 0x20, 0x30, 0xff};
  size_t background_pixels = 0;
  for (uint32_t y = 0; y < 3; ++y) {
    for (uint32_t x = 0; x < 4; ++x) background_pixels += pixelAt(image, x, y) == background;
  }
  EXPECT_EQ(background_pixels, 12u - 3u);  // the invisible point draws nothing
}

TEST(Reference, rasterKeepsTheGreaterDepth) {
  const std::vector<WindowPoint> window = {at(1.5, 1.5, 0.2), at(1.2, 1.7, 0.6), at(1.9, 1.1, 0.4)};
  const Image image = rasterReference(window, {0xff0000ffu, 0xff00ff00u, 0xffff0000u}, 3, 3, 0);
  EXPECT_EQ(pixelAt(image, 1, 1), (std::vector<uint8_t>{0x00, 0xff, 0x00, 0xff}));
}

TEST(Reference, rasterTieKeepsTheLowerIndex) {
  const std::vector<WindowPoint> window = {at(0.1, 0.1, 0.0), at(0.9, 0.9, 0.0), at(1.5, 0.5, 0.7),
                                           at(1.5, 0.5, 0.7)};
  const Image image = rasterReference(window, {0x000000aau, 0x000000bbu, 0x000000ccu, 0x000000ddu}, 2, 1, 0);
  // A first point at depth exactly 0 is drawn, and an equal depth does not replace it.
  EXPECT_EQ(pixelAt(image, 0, 0)[0], 0xaa);
  EXPECT_EQ(pixelAt(image, 1, 0)[0], 0xcc);
}

}  // namespace
}  // namespace dpoint
