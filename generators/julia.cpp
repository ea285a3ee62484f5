#include "generators/julia.h"

#include <cmath>

namespace dpoint {

int juliaEscape(double x, double y, double z, const glm::dvec4& c, int max_iter) {
  double w = 0.0;
  for (int i = 0; i < max_iter; ++i) {
    const double x2 = x * x, rest = y * y + z * z + w * w;
    if (std::sqrt(x2 + rest) > 2.0) return i;
    const double nx = x2 - rest + c.x;
    const double ny = 2.0 * x * y + c.y;
    const double nz = 2.0 * x * z + c.z;
    w = 2.0 * x * w + c.w;
    x = nx;
    y = ny;
    z = nz;
  }
  return max_iter;
}

EscapeRowFunction juliaRow(const glm::dvec4& c) {
  return [c](double x, double y, const double* zs, size_t n, int limit, uint32_t* counts) {
    for (size_t k = 0; k < n; ++k) counts[k] = static_cast<uint32_t>(juliaEscape(x, y, zs[k], c, limit));
  };
}

namespace {
Status validateJulia(const JuliaParams& params) {
  if (Status s = validateEscapeParams(params.resolution, params.max_iter, params.lo, params.hi, params.level); !s)
    return s;
  for (int d = 0; d < 4; ++d)
    if (!std::isfinite(params.c[d])) return Error{"--c: every component must be finite", ExitCode::kUsage};
  return okStatus();
}
}  // namespace

Result<PointSet> generateJulia(const JuliaParams& params) {
  if (Status s = validateJulia(params); !s) return s.error();
  return generateEscapeSurface(escapeSurfaceParams("julia", params), juliaRow(params.c));
}

Result<PointTile> generateJuliaTile(const JuliaParams& params, TileSpec tile) {
  if (Status s = validateJulia(params); !s) return s.error();
  return generateEscapeSurfaceTile(escapeSurfaceParams("julia", params), juliaRow(params.c), tile);
}

}  // namespace dpoint
