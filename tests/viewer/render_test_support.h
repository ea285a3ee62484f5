// Shared by the renderer's test suites (render_test.cpp, precision_test.cpp): the Vulkan fixture
// and the DESIGN §7 point clouds.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "generators/mandelbrot2d.h"
#include "viewer/camera.h"
#include "vulkan/context.h"
#include "viewer/probe.h"
#include "viewer/render.h"

namespace dpoint {

// A suite on real Vulkan, run on both backends (the parameter): one context for the whole suite,
// as an application holds one (the NVIDIA driver stops creating instances after some dozens of
// load/unload cycles in a process), the validation layer on, and any message fails the test.
class VulkanRenderTest : public ::testing::TestWithParam<Backend> {
 protected:
  static void SetUpTestSuite() {
    Result<std::unique_ptr<VulkanContext>> created = VulkanContext::create(ContextOptions{"auto", true});
    if (created.ok()) shared_ = std::move(*created);
    else setup_error_ = created.error().message;
  }
  static void TearDownTestSuite() { shared_.reset(); }
  void SetUp() override {
    ASSERT_TRUE(shared_) << setup_error_;
    context_ = shared_.get();
    context_->clearValidationMessages();
  }
  void TearDown() override {
    if (!context_) return;
    for (const std::string& m : context_->validationMessages()) ADD_FAILURE() << m;
  }

  struct Measured {
    RenderResult render;
    ErrorReport error;
  };
  Measured measure(const PointSet& points, const Camera& camera, PrecisionMode mode, RenderOptions options = {}) {
    options.mode = mode;
    options.backend = GetParam();
    options.probe = true;
    Result<RenderResult> r = renderPoints(*context_, points, camera, options);
    EXPECT_TRUE(r.ok()) << modeName(mode) << ": " << r.error().message;
    if (!r.ok()) return {};
    ErrorReport e = measureError(points, camera, *r, options);
    return {std::move(*r), std::move(e)};
  }

  VulkanContext* context_ = nullptr;
  static inline std::unique_ptr<VulkanContext> shared_;
  static inline std::string setup_error_;
};

// 10 × 10 × 10 points `spacing` apart, centred on `centre`, coloured by position.
inline PointSet cloud(const glm::dvec3& centre, double spacing) {
  PointSet s;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j)
      for (int k = 0; k < 10; ++k) {
        s.positions.push_back(centre + spacing * glm::dvec3(i - 4.5, j - 4.5, k - 4.5));
        s.colors.emplace_back(0.1f * static_cast<float>(i), 0.1f * static_cast<float>(j), 0.1f * static_cast<float>(k));
      }
  return s;
}

// Looks at the cloud's centre from `distance` away along +z (and a little off axis, so no
// coordinate of the eye-relative vector is zero), 1024 × 1024.
inline Camera lookAtCloud(const PointSet& s, const glm::dvec3& centre, double distance) {
  CameraSpec spec;
  spec.width = spec.height = 1024;
  spec.eye = centre + distance * glm::dvec3(0.1, 0.2, 1.0);
  spec.target = centre;
  spec.up = glm::dvec3(0, 1, 0);
  Result<Camera> camera = makeCamera(spec, boundsOf(s));
  EXPECT_TRUE(camera.ok()) << camera.error().message;
  return *camera;
}

// DESIGN §7 deepzoom: the Mandelbrot grid around the study's centre at view `width`, one point per
// pixel centre of a `side`² orthographic view of the same window.
struct DeepZoom {
  PointSet grid;
  Camera camera;
};
inline DeepZoom deepZoom(double width, int side, int max_iter) {
  Mandelbrot2dParams params;
  params.width = width;
  params.resolution = side;
  params.max_iter = max_iter;
  Result<PointSet> grid = generateMandelbrot2d(params);
  EXPECT_TRUE(grid.ok()) << grid.error().message;
  if (!grid.ok()) return {};
  CameraSpec spec;
  spec.width = spec.height = static_cast<uint32_t>(side);
  spec.view_center = glm::dvec3(params.center_x, params.center_y, 0.0);
  spec.view_width = width;
  Result<Camera> camera = makeCamera(spec, boundsOf(*grid));
  EXPECT_TRUE(camera.ok()) << camera.error().message;
  EXPECT_TRUE(camera.ok() && camera->ortho) << "2D data defaults to orthographic";
  if (!camera.ok()) return {};
  return {std::move(*grid), *camera};
}

inline std::string backendName(const ::testing::TestParamInfo<Backend>& param) {
  return param.param == Backend::kRaster ? "raster" : "compute";
}

}  // namespace dpoint
