// The default picture of issue #24's cases on the device (lavapipe in CI, the validation layer on):
// a Mandelbulb's vertices read as a closed surface, the Menger sponge's too with its holes open,
// and a 2D grid shows no gaps. A gap is a background pixel that a 7×7 closing of the drawn pixels
// covers (picture_metrics.h); the issue asks for at most 2% of the closed area (5% for the sponge)
// and a span of at least 85% of the picture's smaller side. The hole filling itself
// (shaders/render/fill.comp) is pinned on planes: it closes the gaps between points and hides a
// back surface seen through them, and leaves a hole wider than the points' spacing open.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "converters/gltf_read.h"
#include "converters/point_io.h"
#include "generators/mandelbrot2d.h"
#include "generators/mandelbulb.h"
#include "generators/menger.h"
#include "generators/sierpinski.h"
#include "picture_metrics.h"
#include "test_config.h"
#include "test_support.h"
#include "viewer/render_job.h"

namespace dpoint {
namespace {

struct Rendered {
  test::ClosingGap gap;
  std::string backend;
  float point_size = 0.0f;
  Image image;
  // The picture's RGB at (x, y), R in the low byte.
  uint32_t rgb(uint32_t x, uint32_t y) const {
    const uint8_t* p = &image.rgba[4 * (size_t(y) * image.width + x)];
    return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16;
  }
};

// `dpoint render FILE -o out.png` with every default.
Rendered renderFile(const std::string& path, const std::string& name, RenderRequest request = {}) {
  request.inputs = {path};
  request.validate = true;
  Progress progress;
  Result<RenderOutcome> outcome = runRenderJob(request, progress);
  EXPECT_TRUE(outcome.ok()) << (outcome.ok() ? "" : outcome.error().message);
  if (!outcome.ok()) return {};
  for (const std::string& m : outcome->validation_messages) ADD_FAILURE() << m;
  Rendered r{test::closingGap(outcome->image, request.background_rgba8), backendName(outcome->backend),
             outcome->point_size, outcome->image};
  std::printf("%s: %g px points, %s backend, gaps %.2f%% of the closed area (%zu of %zu px), span %ux%u of %ux%u\n",
              name.c_str(), double(r.point_size), r.backend.c_str(), 100.0 * r.gap.share, r.gap.gaps, r.gap.closed,
              r.gap.span_x, r.gap.span_y, outcome->image.width, outcome->image.height);
  return r;
}

// The same on the set written as PLY.
Rendered renderDefault(const PointSet& points, const std::string& name, RenderRequest request = {}) {
  test::TempDir dir;
  const std::string path = dir.file(name + ".ply");
  EXPECT_TRUE(writePoints(path, points).ok());
  return renderFile(path, name, std::move(request));
}

double span(const Rendered& r) {
  return double(std::max(r.gap.span_x, r.gap.span_y)) / double(std::min(r.image.width, r.image.height));
}

PointSet mandelbrot2d(double width) {
  Mandelbrot2dParams params;
  params.width = width;
  params.resolution = 256;
  Result<PointSet> points = generateMandelbrot2d(params);
  EXPECT_TRUE(points.ok());
  return points.ok() ? std::move(*points) : PointSet{};
}

// The picture sizes every default 3D picture is pinned at: 640×480, the default 1024×768, 1920×1080.
constexpr uint32_t kSizes[3][2] = {{640, 480}, {1024, 768}, {1920, 1080}};

// The default render of `points` at each size: a span of at least 85% of the picture's smaller
// side, gaps at most `most_gaps` of the closed area and artefacts (hollow squares' outlines, glyph
// strokes, dark specks, isolated background pixels: picture_metrics.h) at most `most_artefacts`.
void expectCleanAtEverySize(const PointSet& points, const std::string& name, double most_gaps, double most_artefacts) {
  for (const auto& size : kSizes) {
    RenderRequest request;
    request.camera.width = size[0];
    request.camera.height = size[1];
    const Rendered r = renderDefault(points, name + "-" + std::to_string(size[0]), request);
    std::printf("  artefacts %.2f%% (%zu px)\n", 100.0 * r.gap.artefact_share, r.gap.artefacts);
    EXPECT_LE(r.gap.share, most_gaps) << name << " at " << size[0] << "x" << size[1];
    EXPECT_LE(r.gap.artefact_share, most_artefacts) << name << " at " << size[0] << "x" << size[1];
    EXPECT_GE(span(r), 0.85) << name << " at " << size[0] << "x" << size[1];
    EXPECT_EQ(r.backend, "compute");
  }
}

// 226K points (res 200) and 1.55M (res 420). Before the hole filling their gaps were 35% and 21%
// (640×480); with square points at 0.65 of the spacing the res-200 set at 1024×768 showed its inner
// shells through the gaps as hollow squares: 1.9% artefacts.
TEST(RenderFill, defaultMandelbulbReadsAsAClosedSurface) {
  for (int resolution : {200, 420}) {
    MandelbulbParams params;
    params.resolution = resolution;
    Result<PointSet> points = generateMandelbulb(params);
    ASSERT_TRUE(points.ok());
    expectCleanAtEverySize(*points, "mandelbulb" + std::to_string(resolution), 0.02, 0.005);
  }
}

// Level 4, exact (the default): its faces closed (the points are the small cubes' corners), its
// holes open: a hole is wider than the filling reaches (see the plane's below).
TEST(RenderFill, defaultMengerSpongeReadsAsAClosedSurface) {
  Result<PointSet> points = generateMenger(MengerParams{});
  ASSERT_TRUE(points.ok());
  expectCleanAtEverySize(*points, "menger", 0.05, 0.005);
}

// The Sierpinski tetrahedron's vertices. Level 7 (32K points) holds the bounds. Level 9
// (524K, the default) has holes of its own 2-5 px wide at these sizes, which the closing counts as
// gaps (2.9-3.2%), and small marks where a back face shows through them (0.6-0.74%): pinned there.
TEST(RenderFill, defaultSierpinskiReadsAsItsFaces) {
  for (int level : {7, 9}) {
    SierpinskiParams params;
    params.level = level;
    Result<PointSet> points = generateSierpinski(params);
    ASSERT_TRUE(points.ok());
    if (level == 7) expectCleanAtEverySize(*points, "sierpinski7", 0.02, 0.005);
    else expectCleanAtEverySize(*points, "sierpinski9", 0.035, 0.008);
  }
}

// A sparse survey (simple.las: 1,065 points over 3.4 × 4.6 km) reads as a surface: its points
// drawn up to their spacing. With 8-px squares it was scattered squares on black (10% gaps).
TEST(RenderFill, defaultSparseSurveyReadsAsASurface) {
  Result<PointSet> points = readPoints(std::string(DPOINT_CORPUS_DIR) + "/las/simple.las");
  ASSERT_TRUE(points.ok()) << points.error().message;
  expectCleanAtEverySize(*points, "simple-las", 0.02, 0.005);
}

// A plane of red points (100 × 100, 1/100 apart; tilted by 0.001 in z so the set is 3D and gets
// the shading) with a square hole of 20 × 20 spacings at its centre, seen from straight above.
PointSet planeWithHole(double z, glm::vec3 color, bool hole) {
  PointSet plane;
  for (int i = 0; i < 100; ++i)
    for (int j = 0; j < 100; ++j) {
      const double x = (i + 0.5) / 100.0, y = (j + 0.5) / 100.0;
      if (hole && std::abs(x - 0.5) < 0.1 && std::abs(y - 0.5) < 0.1) continue;
      plane.positions.push_back({x, y, z + 0.001 * x});
      plane.colors.push_back(color);
    }
  return plane;
}

RenderRequest fromAbove(double height) {
  RenderRequest request;
  request.camera.width = request.camera.height = 400;
  request.camera.eye = glm::dvec3(0.5, 0.5, height);
  request.camera.target = glm::dvec3(0.5, 0.5, 0.0);
  request.camera.up = glm::dvec3(0.0, 1.0, 0.0);
  return request;
}

TEST(RenderFill, fillingClosesGapsAndLeavesHolesOpen) {
  const Rendered r = renderDefault(planeWithHole(0.0, {1, 0, 0}, true), "holed", fromAbove(1.5));
  // The hole's centre (the picture's) shows the background; the plane around it has no gaps.
  EXPECT_EQ(r.rgb(200, 200), 0u);
  size_t red = 0, plane_pixels = 0;
  for (uint32_t y = 0; y < 400; ++y)
    for (uint32_t x = 0; x < 400; ++x) {
      // Pixels well inside the plane and well outside the hole (the plane spans ~x 75..325 here).
      const bool in_plane = x > 100 && x < 300 && y > 100 && y < 300;
      const bool near_hole = x > 160 && x < 240 && y > 160 && y < 240;
      if (!in_plane || near_hole) continue;
      ++plane_pixels;
      red += (r.rgb(x, y) & 0xffu) > 0 && (r.rgb(x, y) >> 8) == 0;
    }
  EXPECT_EQ(red, plane_pixels) << "every pixel of the plane is drawn (red, shaded or not)";
  EXPECT_GT(r.point_size, 1.0f);
}

// Two such planes without the hole, red 0.1 above blue: the blue one, seen through the gaps
// between the red one's points, is hidden where the red one lies.
TEST(RenderFill, fillingHidesTheBackSurfaceSeenThroughTheGaps) {
  PointSet both = planeWithHole(0.1, {1, 0, 0}, false);
  const PointSet back = planeWithHole(0.0, {0, 0, 1}, false);
  both.positions.insert(both.positions.end(), back.positions.begin(), back.positions.end());
  both.colors.insert(both.colors.end(), back.colors.begin(), back.colors.end());
  const Rendered r = renderDefault(both, "two-planes", fromAbove(1.5));
  size_t blue = 0;
  for (uint32_t y = 120; y < 280; ++y)
    for (uint32_t x = 120; x < 280; ++x) blue += (r.rgb(x, y) >> 16) > 0;
  EXPECT_EQ(blue, 0u) << "of 160 x 160 pixels inside the front plane";
}

// The same two planes with 30% of the front one's points missing (chosen by a hash of their
// place): the holes meet in clusters, each open along several directions for more than the
// filling's reach, and the first filling left the middle of a cluster showing the blue plane (76
// px here); the smoothing spread each such spot over its square, and eye-dome lighting outlined
// the square (936 px under 216 of 255 red, on a plane of 232-248). The second filling closes them
// (fill.comp).
TEST(RenderFill, fillingClosesClustersOfHoles) {
  PointSet both = planeWithHole(0.1, {1, 0, 0}, false);
  size_t kept = 0;
  for (size_t k = 0; k < both.size(); ++k) {
    const size_t i = k / 100, j = k % 100;
    if ((i * 7919 + j * 104729 + i * j * 31) % 100 < 30) continue;
    both.positions[kept] = both.positions[k];
    both.colors[kept++] = both.colors[k];
  }
  both.positions.resize(kept);
  both.colors.resize(kept);
  const PointSet back = planeWithHole(0.0, {0, 0, 1}, false);
  both.positions.insert(both.positions.end(), back.positions.begin(), back.positions.end());
  both.colors.insert(both.colors.end(), back.colors.begin(), back.colors.end());
  const Rendered r = renderDefault(both, "holed-planes", fromAbove(1.5));
  size_t blue = 0, dark = 0;
  for (uint32_t y = 120; y < 280; ++y)
    for (uint32_t x = 120; x < 280; ++x) {
      blue += (r.rgb(x, y) >> 16) > 0;
      dark += (r.rgb(x, y) & 0xffu) < 216;  // the plane's red is 248 here, shaded by its slight tilt
    }
  EXPECT_EQ(blue, 0u) << "of 160 x 160 pixels inside the front plane, at " << r.point_size << " px";
  EXPECT_EQ(dark, 0u) << "squares outlined around the spots of blue";
}

// A glTF mesh whose vertices lie far apart on screen (a CAD part: BoxTextured's 24 vertices, the
// 2CylinderEngine's flat faces of long triangles) is drawn as points sampled on its surface: closed,
// within the picture with a margin (no drawn pixel in the outer 2-pixel frame). As vertices, the box
// was 8 dots, two of them touching the top edge, and the engine a cloud of dots.
TEST(RenderFill, defaultGltfMeshesReadAsClosedSurfacesWithAMargin) {
  const std::string models = "/usr/share/assimp/models/glTF2/";
  const std::pair<const char*, const char*> meshes[] = {
      {"BoxTextured", "BoxTextured-glTF-Binary/BoxTextured.glb"},
      {"2CylinderEngine", "2CylinderEngine-glTF-Binary/2CylinderEngine.glb"}};
  for (const auto& [name, file] : meshes)
    for (const auto& size : kSizes) {
      RenderRequest request;
      request.camera.width = size[0];
      request.camera.height = size[1];
      const std::string what = std::string(name) + " at " + std::to_string(size[0]) + "x" + std::to_string(size[1]);
      const Rendered r = renderFile(models + file, what, request);
      std::printf("  artefacts %.2f%% (%zu px)\n", 100.0 * r.gap.artefact_share, r.gap.artefacts);
      EXPECT_LE(r.gap.share, 0.02) << what;
      EXPECT_LE(r.gap.artefact_share, 0.005) << what;
      EXPECT_GE(span(r), 0.85) << what;
      size_t edge = 0;
      for (uint32_t y = 0; y < r.image.height; ++y)
        for (uint32_t x = 0; x < r.image.width; ++x)
          if ((x < 2 || y < 2 || x + 2 >= r.image.width || y + 2 >= r.image.height) && r.rgb(x, y) != 0) ++edge;
      EXPECT_EQ(edge, 0u) << what << ": drawn pixels at the picture's edge";
    }
}

// BoxTextured with its three far faces red (facing away from the fit's eye, which looks along
// −(0.6, 0.5, 1)) and its near faces white, drawn as its surface with every default: no red pixel.
// The samples' rows near a triangle's first vertex once let the far side show through the nearest
// corner, a 20 x 40 px patch that the artefact share above did not count. (At the outline a far
// face's discs reach past the near faces' edge, as points do: red is allowed within a point's
// radius of the background.)
TEST(RenderFill, aSampledBoxShowsNoneOfItsFarSide) {
  GltfReadOptions read;
  Result<PointSet> box = readGltf("/usr/share/assimp/models/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb", read);
  ASSERT_TRUE(box.ok());
  box->colors.assign(box->size(), glm::vec3(1.0f));
  const glm::dvec3 toward_eye(0.6, 0.5, 1.0);
  for (size_t t = 0; t < box->triangles.size(); t += 3) {
    const uint32_t* v = &box->triangles[t];
    const glm::dvec3 normal =
        glm::cross(box->positions[v[1]] - box->positions[v[0]], box->positions[v[2]] - box->positions[v[0]]);
    if (glm::dot(normal, toward_eye) < 0.0)
      for (int k = 0; k < 3; ++k) box->colors[v[k]] = glm::vec3(1.0f, 0.0f, 0.0f);
  }
  for (const auto& size : kSizes) {
    RenderRequest request;
    request.camera.width = size[0];
    request.camera.height = size[1];
    const std::string what = "two-faced box at " + std::to_string(size[0]) + "x" + std::to_string(size[1]);
    const Rendered r = renderDefault(*box, "two-faced-box", request);
    const int reach = int(std::ceil(r.point_size / 2.0f)) + 1;
    const auto nearBackground = [&](uint32_t x, uint32_t y) {
      for (int dy = -reach; dy <= reach; ++dy)
        for (int dx = -reach; dx <= reach; ++dx) {
          const int64_t u = int64_t(x) + dx, v = int64_t(y) + dy;
          if (u < 0 || v < 0 || u >= int64_t(r.image.width) || v >= int64_t(r.image.height) ||
              r.rgb(uint32_t(u), uint32_t(v)) == 0)
            return true;
        }
      return false;
    };
    size_t red = 0, white = 0;
    for (uint32_t y = 0; y < r.image.height; ++y)
      for (uint32_t x = 0; x < r.image.width; ++x) {
        const uint32_t c = r.rgb(x, y);
        red += (c & 0xffu) > 0 && (c >> 8) == 0 && !nearBackground(x, y);
        white += (c & 0xffu) > 0 && (c & 0xffu) == ((c >> 8) & 0xffu);
      }
    EXPECT_EQ(red, 0u) << what << ": red pixels inside the box's outline";
    EXPECT_GT(white, size_t{size[0]} * size[1] / 3) << what;
  }
}

TEST(RenderFill, defaultMandelbrot2dGridHasNoGaps) {
  for (double width : {1e-6, 1e-12, 1e-15}) {
    const Rendered r = renderDefault(mandelbrot2d(width), "mandelbrot2d-256-" + std::to_string(width));
    EXPECT_LE(r.gap.share, 0.02) << "width " << width;
    EXPECT_GE(span(r), 0.85) << "width " << width;
    EXPECT_EQ(r.point_size, 3.0f) << "256 points over 756 px";
    EXPECT_EQ(r.backend, "compute");
  }
}

}  // namespace
}  // namespace dpoint
