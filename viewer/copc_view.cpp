#include "viewer/copc_view.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/input_file.h"

namespace dpoint {
namespace {

// The eight corners of a node's cube.
std::array<glm::dvec3, 8> corners(const CopcBox& cube) {
  std::array<glm::dvec3, 8> c;
  for (int i = 0; i < 8; ++i)
    c[i] = {(i & 1) ? cube.max[0] : cube.min[0], (i & 2) ? cube.max[1] : cube.min[1],
            (i & 4) ? cube.max[2] : cube.min[2]};
  return c;
}

// A perspective view's selection: the root, and a node where its cube may meet the frustum (not every
// corner beyond one side plane, nor every corner behind the eye) and its level is needed at the
// cube's nearest depth: the level above it is coarser than a pixel there (a pixel at depth d spans
// 2 d tan(fov/2) / height). Both tests accept a node's ancestors wherever they accept the node (a
// child's corners lie in its parent's cube), as CopcQuery::select must.
std::function<bool(const CopcBox&, int)> frustumSelect(const Camera& camera, double fov_degrees, double spacing) {
  const glm::dmat4 clip = camera.viewProjection();
  const glm::dvec3 forward(-camera.rotation[0][2], -camera.rotation[1][2], -camera.rotation[2][2]);
  const double pixel_per_depth = 2.0 * std::tan(fov_degrees * M_PI / 360.0) / camera.height;
  const glm::dvec3 eye = camera.eye;
  return [=](const CopcBox& cube, int level) {
    if (level == 0) return true;  // the root always: a view that meets nothing draws an empty picture
    const std::array<glm::dvec3, 8> c = corners(cube);
    int outside[5] = {0, 0, 0, 0, 0};  // x < -w, x > w, y < -w, y > w, w ≤ 0
    double nearest = HUGE_VAL;
    for (const glm::dvec3& p : c) {
      const glm::dvec4 q = clip * glm::dvec4(p, 1.0);
      outside[0] += q.x < -q.w, outside[1] += q.x > q.w, outside[2] += q.y < -q.w, outside[3] += q.y > q.w;
      outside[4] += q.w <= 0.0;
      nearest = std::min(nearest, glm::dot(p - eye, forward));
    }
    for (int n : outside)
      if (n == 8) return false;
    if (nearest <= 0.0) return true;
    const double parent_spacing = spacing / std::ldexp(1.0, level - 1);
    return parent_spacing > nearest * pixel_per_depth;
  };
}

}  // namespace

Result<CopcQuery> copcQueryFor(const CameraSpec& camera, const std::string& path, unsigned threads,
                               uint64_t max_memory) {
  Result<InputFile> file = InputFile::open(path);
  if (!file) return file.error();
  Result<CopcHeader> header = readCopcHeader(*file);
  if (!header) return header.error();
  const CameraSpec& c = camera;
  CopcQuery query;
  query.threads = threads;
  query.max_memory = max_memory;
  const bool planar = header->min[2] == 0.0 && header->max[2] == 0.0;
  if (!c.ortho.value_or(planar) && (c.eye || c.view_center || c.view_width)) {
    // A perspective view the user placed: its camera does not depend on the points (the header's
    // box gives only its near and far planes), so the nodes are chosen for the very view drawn.
    Bounds bounds;
    bounds.min = {header->min[0], header->min[1], header->min[2]};
    bounds.max = {header->max[0], header->max[1], header->max[2]};
    bounds.planar = planar;
    Result<Camera> view = makeCamera(c, bounds);
    if (!view) return view.error();
    query.select = frustumSelect(*view, c.fov_degrees, header->info.spacing);
    return query;
  }
  double window = 2.0 * header->info.halfsize;
  if (c.ortho.value_or(planar) && c.view_width && !c.eye) {
    window = *c.view_width;
    if (c.view_center) {
      const double half_w = window / 2.0, half_h = window * c.height / c.width / 2.0;
      query.box.min[0] = c.view_center->x - half_w, query.box.max[0] = c.view_center->x + half_w;
      query.box.min[1] = c.view_center->y - half_h, query.box.max[1] = c.view_center->y + half_h;
    }
  }
  query.resolution = window / std::max(c.width, c.height);
  return query;
}

}  // namespace dpoint
