// Eye-dome lighting (RenderOptions::shading) on real Vulkan with the validation layer on: it
// darkens exactly the pixels that have a nearer neighbour, leaves every other pixel as the plain
// render drew it, and gives the same picture after either backend.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>

#include "viewer/camera.h"
#include "viewer/pipelines.h"
#include "viewer/render.h"
#include "render_test_support.h"

namespace dpoint {
namespace {

class Shade : public VulkanRenderTest {};

constexpr uint32_t kSize = 256;

// Two grey squares facing the eye, dense enough (about two points a pixel each way) that neither
// has a hole: a near one (z = 0, side 4) in front of a far one (z = −2, side 6), seen along −z.
struct Scene {
  PointSet points;
  Camera camera;
};

Scene twoSquares(bool ortho) {
  Scene scene;
  auto square = [&](double z, double side, float grey) {
    const int n = static_cast<int>(side / 0.01);
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n; ++j) {
        scene.points.positions.emplace_back(-0.5 * side + 0.01 * i, -0.5 * side + 0.01 * j, z);
        scene.points.colors.emplace_back(grey);
      }
  };
  square(0.0, 4.0, 0.8f);
  square(-2.0, 6.0, 0.6f);
  CameraSpec spec;
  spec.width = spec.height = kSize;
  spec.eye = glm::dvec3(0.0, 0.0, 10.0);
  spec.target = glm::dvec3(0.0);
  spec.up = glm::dvec3(0.0, 1.0, 0.0);
  spec.ortho = ortho;
  scene.camera = *makeCamera(spec, boundsOf(scene.points));
  return scene;
}

uint32_t pixel(const Image& image, uint32_t x, uint32_t y) {
  uint32_t value = 0;
  std::memcpy(&value, &image.rgba[(size_t{y} * image.width + x) * 4], 4);
  return value;
}

uint32_t red(uint32_t rgba8) { return rgba8 & 0xffu; }

// The first column, going right along the middle row, where the near square ends.
uint32_t nearSquareRightEdge(const Image& plain) {
  const uint32_t y = kSize / 2, near_grey = pixel(plain, kSize / 2, y);
  uint32_t x = kSize / 2;
  while (x + 1 < kSize && pixel(plain, x + 1, y) == near_grey) ++x;
  return x;
}

Image render(VulkanContext& context, const Scene& scene, Backend backend, Shading shading) {
  RenderOptions options;
  options.backend = backend;
  options.shading = shading;
  Result<RenderResult> r = renderPoints(context, scene.points, scene.camera, options);
  EXPECT_TRUE(r.ok()) << r.error().message;
  return r.ok() ? r->image : Image{};
}

TEST_P(Shade, edlDarkensOnlyPixelsWithANearerNeighbour) {
  for (bool ortho : {false, true}) {
    SCOPED_TRACE(ortho ? "ortho" : "perspective");
    const Scene scene = twoSquares(ortho);
    const Image plain = render(*context_, scene, GetParam(), Shading::kNone);
    const Image shaded = render(*context_, scene, GetParam(), Shading::kEdl);
    ASSERT_EQ(plain.rgba.size(), shaded.rgba.size());
    const uint32_t y = kSize / 2, edge = nearSquareRightEdge(plain);
    ASSERT_GT(edge, kSize / 2 + 10);
    ASSERT_LT(edge, kSize - 20) << "the far square shows beside the near one";
    ASSERT_NE(pixel(plain, edge + 1, y), pixel(plain, edge, y));
    // The near square is flat and facing the eye: its depth is even, nothing is in front of it.
    EXPECT_EQ(pixel(shaded, kSize / 2, y), pixel(plain, kSize / 2, y));
    EXPECT_EQ(pixel(shaded, edge, y), pixel(plain, edge, y));
    // The far square's first pixel beside the near edge has a nearer neighbour: darker.
    EXPECT_LT(red(pixel(shaded, edge + 1, y)), red(pixel(plain, edge + 1, y)));
    // Five pixels on, no neighbour within the radius is nearer: unchanged; so is the background.
    EXPECT_EQ(pixel(shaded, edge + 5, y), pixel(plain, edge + 5, y));
    EXPECT_EQ(pixel(shaded, 0, 0), pixel(plain, 0, 0));
    // A larger radius reaches the edge from further away.
    RenderOptions wide;
    wide.backend = GetParam();
    wide.shading = Shading::kEdl;
    wide.edl.radius = 6.0f;
    Result<RenderResult> r = renderPoints(*context_, scene.points, scene.camera, wide);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_LT(red(pixel(r->image, edge + 5, y)), red(pixel(plain, edge + 5, y)));
  }
}

// The raster backend shades from its depth attachment, the compute backend from its visibility
// keys: the same depth values, so the same picture.
TEST_P(Shade, edlIsTheSameAfterEitherBackend) {
  const Scene scene = twoSquares(false);
  const Backend other = GetParam() == Backend::kRaster ? Backend::kCompute : Backend::kRaster;
  const Image raster = render(*context_, scene, GetParam(), Shading::kEdl);
  const Image compute = render(*context_, scene, other, Shading::kEdl);
  ASSERT_EQ(raster.rgba.size(), compute.rgba.size());
  size_t differing = 0;
  for (size_t i = 0; i < raster.rgba.size(); i += 4)
    differing += std::memcmp(&raster.rgba[i], &compute.rgba[i], 4) != 0;
  EXPECT_EQ(differing, 0u);
}

// A rippled sheet seen at a slant, drawn with gaps between its points: something for every pass
// to do (holes to fill, a staircase to smooth, slopes and steps to shade), in a picture whose
// sides are no multiple of the fused pass's 4-pixel blocks.
Scene rippledSheet() {
  Scene scene;
  for (int i = 0; i <= 120; ++i)
    for (int j = 0; j <= 120; ++j) {
      const double x = -1.0 + i / 60.0, y = -1.0 + j / 60.0;
      scene.points.positions.emplace_back(x, y, 0.3 * std::sin(3.0 * x) * std::cos(2.0 * y));
      scene.points.colors.emplace_back(0.3f + 0.3f * static_cast<float>(i % 3), 0.5f, 0.7f);
    }
  CameraSpec spec;
  spec.width = 250;
  spec.height = 131;
  spec.eye = glm::dvec3(0.4, -2.2, 1.6);
  spec.target = glm::dvec3(0.0);
  spec.up = glm::dvec3(0.0, 0.0, 1.0);
  scene.camera = *makeCamera(spec, boundsOf(scene.points));
  return scene;
}

// The fused pass (smooth_edl.comp) does the separate passes' arithmetic in the same order: the
// same picture, at every point size it takes and at eye-dome radii reaching 1 and 2 pixels.
TEST_P(Shade, fusedSmoothingAndEdlGiveTheSeparatePassesPicture) {
  const Scene scene = rippledSheet();
  for (float point_size : {1.0f, 3.0f, 8.0f})
    for (float radius : {1.4f, 2.2f}) {
      SCOPED_TRACE("point size " + std::to_string(point_size) + ", radius " + std::to_string(radius));
      RenderOptions options;
      options.backend = GetParam();
      options.shading = Shading::kEdl;
      options.point_size = point_size;
      options.edl.radius = radius;
      Result<RenderResult> fused = renderPoints(*context_, scene.points, scene.camera, options);
      options.edl.fuse = false;
      Result<RenderResult> separate = renderPoints(*context_, scene.points, scene.camera, options);
      ASSERT_TRUE(fused.ok() && separate.ok());
      ASSERT_EQ(fused->image.rgba.size(), separate->image.rgba.size());
      size_t differing = 0, shaded = 0;
      for (size_t i = 0; i < fused->image.rgba.size(); i += 4) {
        differing += std::memcmp(&fused->image.rgba[i], &separate->image.rgba[i], 4) != 0;
        shaded += fused->image.rgba[i + 1] > 0 && fused->image.rgba[i + 1] < 120;  // the sheet's 0.5 green, darkened
      }
      EXPECT_EQ(differing, 0u);
      EXPECT_GT(shaded, 100u) << "the sheet's slopes are shaded";
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, Shade, ::testing::Values(Backend::kRaster, Backend::kCompute), backendName);

}  // namespace
}  // namespace dpoint

namespace dpoint {
namespace {

// The shading's texel buffers hold the picture and a margin: a picture that would pass the
// device's maxTexelBufferElements does not fit (render_job then draws it plain, with a warning).
TEST(ShadeLimits, shadingFitsCountsThePictureAndItsMargin) {
  DeviceFacts facts;
  facts.max_texel_buffer_elements = 10000;
  RenderOptions options;
  options.shading = Shading::kEdl;
  options.point_size = 1.0f;
  const uint32_t margin = uint32_t(shadeRadii(options.point_size, options.edl.radius, options.edl.fuse).margin());
  ASSERT_GT(margin, 0u);
  const uint32_t side = 100 - 2 * margin;  // with its margins, 100 x 100 = the limit
  EXPECT_TRUE(shadingFits(facts, side, side, options));
  EXPECT_FALSE(shadingFits(facts, side + 1, side, options));
  EXPECT_FALSE(shadingFits(facts, 100, 100, options)) << "the picture alone at the limit, its margins over";
}

}  // namespace
}  // namespace dpoint
