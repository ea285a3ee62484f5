#include "viewer/probe.h"

#include "viewer/encode.h"

namespace dpoint {

std::vector<WindowPoint> probeWindows(const RenderResult& render, const Camera& camera) {
  std::vector<WindowPoint> probe(render.probe_clip.size());
  for (size_t i = 0; i < probe.size(); ++i) probe[i] = windowFromClip(render.probe_clip[i], camera);
  return probe;
}

ErrorReport measureError(const PointSet& points, const Camera& camera, const RenderResult& render,
                         const RenderOptions& options) {
  assert(render.probe_clip.size() == points.size());
  std::vector<WindowPoint> reference = projectReference(points.positions, camera);
  std::vector<WindowPoint> probe = probeWindows(render, camera);
  ErrorReport report;
  report.stats = compareToReference(reference, probe);
  // The reference raster draws plain 1-px points: a shaded picture is not compared.
  if (options.point_size == 1.0f && options.shading == Shading::kNone) {
    report.reference =
        rasterReference(reference, encodeColors(points), camera.width, camera.height, options.background_rgba8);
    report.pixels_compared = true;
    report.pixels_differing = countDifferingPixels(render.image, report.reference);
  }
  return report;
}

}  // namespace dpoint
