// The exact picture (DESIGN §5): long double projection, probe-versus-reference error statistics,
// and the reference raster.
//
// Why long double is exact enough: p − eye of two doubles is exact in the 64-bit x87 significand
// when their exponents are within 11 of each other and otherwise off by 2^-64 relative; each
// product and sum after it rounds at 2^-64, so the window position carries an error of a few
// 2^-64 relative to the viewport, far under the float floor (2^-24) the GPU modes are judged against.
#include "viewer/reference.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "core/parallel.h"

namespace dpoint {
namespace {

using Real = long double;

struct MatrixL {
  Real m[4][4];  // m[column][row], as glm
};

MatrixL toLongDouble(const glm::dmat4& matrix) {
  MatrixL out;
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) out.m[c][r] = static_cast<Real>(matrix[c][r]);
  }
  return out;
}

void multiply(const MatrixL& a, const Real (&v)[4], Real (&out)[4]) {
  for (int r = 0; r < 4; ++r) out[r] = a.m[0][r] * v[0] + a.m[1][r] * v[1] + a.m[2][r] * v[2] + a.m[3][r] * v[3];
}

// The one visibility rule for reference (T = long double) and probe (T = double). Bounds are
// checked on the double results: a long double x just under `width` may round up to it.
template <typename T>
WindowPoint toWindow(T x, T y, T z, T w, uint32_t width, uint32_t height) {
  if (!(std::isfinite(x) && std::isfinite(y) && std::isfinite(z) && std::isfinite(w)) || !(w > 0)) return {};
  const double depth = static_cast<double>(z / w);
  const double x_win = static_cast<double>((x / w * T(0.5) + T(0.5)) * static_cast<T>(width));
  const double y_win = static_cast<double>((y / w * T(0.5) + T(0.5)) * static_cast<T>(height));
  if (!(depth >= 0.0 && depth <= 1.0)) return {};
  // (0, width] × (0, height]: a point exactly on the left or top edge lights pixel −1 (below).
  if (!(x_win > 0.0 && x_win <= double(width) && y_win > 0.0 && y_win <= double(height))) return {};
  return {x_win, y_win, depth, true};
}

}  // namespace

std::vector<WindowPoint> projectReference(const PositionArray& positions, const Camera& camera) {
  const MatrixL rotation = toLongDouble(camera.rotation);
  const MatrixL projection = toLongDouble(camera.projection);
  const Real eye[3] = {camera.eye.x, camera.eye.y, camera.eye.z};
  std::vector<WindowPoint> out(positions.size());
  constexpr size_t kChunk = 1 << 16;
  const size_t chunks = (positions.size() + kChunk - 1) / kChunk;
  parallelFor(chunks, 0, [&](size_t chunk, unsigned) {
    const size_t end = std::min(positions.size(), (chunk + 1) * kChunk);
    for (size_t i = chunk * kChunk; i < end; ++i) {
      const glm::dvec3& p = positions[i];
      const Real relative[4] = {Real(p.x) - eye[0], Real(p.y) - eye[1], Real(p.z) - eye[2], 1};
      Real eye_space[4], clip[4];
      multiply(rotation, relative, eye_space);
      multiply(projection, eye_space, clip);
      out[i] = toWindow(clip[0], clip[1], clip[2], clip[3], camera.width, camera.height);
    }
  });
  return out;
}

WindowPoint windowFromClip(const glm::vec4& clip, const Camera& camera) {
  return toWindow(double(clip.x), double(clip.y), double(clip.z), double(clip.w), camera.width, camera.height);
}

ErrorStats compareToReference(const std::vector<WindowPoint>& reference, const std::vector<WindowPoint>& probe) {
  assert(reference.size() == probe.size());
  ErrorStats stats;
  std::vector<double> errors;
  errors.reserve(reference.size());
  size_t off_half_px = 0;
  long double sum_squares = 0;
  for (size_t i = 0; i < reference.size(); ++i) {
    if (!reference[i].visible) continue;
    ++stats.points;
    const WindowPoint& q = probe[i];
    if (!q.visible || !std::isfinite(q.x) || !std::isfinite(q.y)) {
      ++stats.lost;
      continue;
    }
    const double error = std::hypot(q.x - reference[i].x, q.y - reference[i].y);
    errors.push_back(error);
    sum_squares += static_cast<long double>(error) * error;
    if (error >= 0.5) ++off_half_px;
    stats.max_px = std::max(stats.max_px, error);
  }
  if (stats.points > 0) {
    stats.share_off_half_px = double(off_half_px + stats.lost) / double(stats.points);
  }
  if (!errors.empty()) {
    const size_t n = errors.size();
    stats.rms_px = static_cast<double>(std::sqrt(sum_squares / static_cast<long double>(n)));
    // Nearest rank: the smallest error with at least 99% of the errors at or below it.
    const size_t rank = (99 * n + 99) / 100;  // ceil(0.99 n), 1-based
    std::nth_element(errors.begin(), errors.begin() + static_cast<ptrdiff_t>(rank - 1), errors.end());
    stats.p99_px = errors[rank - 1];
  }
  return stats;
}

Image rasterReference(const std::vector<WindowPoint>& window, const std::vector<uint32_t>& colors_rgba8,
                      uint32_t width, uint32_t height, uint32_t background_rgba8) {
  assert(window.size() == colors_rgba8.size());
  Image image;
  image.width = width;
  image.height = height;
  const size_t pixels = size_t(width) * height;
  image.rgba.resize(pixels * 4);
  auto store = [&image](size_t pixel, uint32_t rgba) {
    // R in the low byte, so the bytes in memory are R, G, B, A whatever the host's byte order.
    for (size_t k = 0; k < 4; ++k) image.rgba[pixel * 4 + k] = static_cast<uint8_t>(rgba >> (8 * k));
  };
  for (size_t pixel = 0; pixel < pixels; ++pixel) store(pixel, background_rgba8);
  // Strictly greater wins and points are visited in index order, so on equal depth the lower index
  // stays (VK_COMPARE_OP_GREATER). A pixel with no point yet takes any visible point, even one at
  // depth exactly 0 (see the header).
  std::vector<double> depth(pixels, 0.0);
  std::vector<bool> covered(pixels, false);
  for (size_t i = 0; i < window.size(); ++i) {
    const WindowPoint& p = window[i];
    if (!p.visible) continue;
    // Checked before the conversion: a window for another viewport size must not index out of bounds.
    if (!(p.x > 0.0 && p.x <= double(width) && p.y > 0.0 && p.y <= double(height))) continue;
    // The pixel whose centre lies in [x − 0.5, x + 0.5): a size-1 point square with the top-left
    // fill rule (a centre on the left/top edge is in, on the right/bottom edge out), which is what
    // lavapipe does when a point falls exactly on a pixel corner. Off the corners it is floor(x).
    const auto px = static_cast<uint32_t>(std::ceil(p.x) - 1.0);
    const auto py = static_cast<uint32_t>(std::ceil(p.y) - 1.0);
    const size_t pixel = size_t(py) * width + px;
    if (covered[pixel] && !(p.depth > depth[pixel])) continue;
    covered[pixel] = true;
    depth[pixel] = p.depth;
    store(pixel, colors_rgba8[i]);
  }
  return image;
}
}  // namespace dpoint
