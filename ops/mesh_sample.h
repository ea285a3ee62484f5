// Points on a mesh's surface (issue #37 item 3): what Open3D's sample_points_uniformly and
// sample_points_poisson_disk, PCL's pcl_mesh_sampling and CloudCompare's "Sample points on a mesh"
// do, for `convert --sample N`, `generate … --sample N`, the Python module and `render` of a mesh.
//
// Uniform: sample i picks a triangle with probability area / total area (Walker's alias table, two
// draws) and a point uniform in it (barycentric sqrt(r1) mapping,
// Osada et al. 2002), each from its own outputs of splitmix64 (core/random.h): the set depends on
// the seed only, not on the thread count. A sample is p0 + b·(p1 − p0) + c·(p2 − p0) in double, so
// it lies on its triangle to the rounding of those few operations.
//
// Poisson: weighted sample elimination (Yuksel 2015), as Open3D does it: `factor`·N uniform samples,
// each weighted by its neighbours within r_max = 2·sqrt(A / N / (2·sqrt 3)) as (1 − d/r_max)^8 (d
// at least r_min = r_max · 0.5 · (1 − (N/M)^1.5)); the heaviest is removed and its neighbours'
// weights lowered until N remain. Ties go to the lower index, so it is deterministic. The
// neighbours come from a grid of cells 2·r_max wide (eight cells a query) in Morton order; the
// heaviest from a 4-ary heap updated lazily. 2M points from 10M candidates: 248 s -> 54 s on the
// 2-core VM (bench/results/2026-12-01/cpu/poisson.md).
//
// Stratified: sample i lies at (i + shift) / N of the running sum of the areas (systematic
// sampling: each triangle gets its expected count rounded up or down, the seed draws the shift), at
// point i of the R2 sequence (Roberts 2018) in the unit square folded onto its triangle (a point
// past the diagonal reflected), so the samples of a large triangle spread evenly. As fast as uniform and with no clumps or holes: `render` draws a mesh's surface so.
//
// Each sample gets the triangle's colours and normals interpolated: vertex colours when the mesh
// has them, times the texel of a textured triangle (SampleOptions::texture), vertex normals
// (dimensions nx, ny, nz) when it has them, else the face normal. Other
// dimensions are not carried (a vertex attribute need not mean anything between vertices).
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "core/point_set.h"
#include "core/progress.h"
#include "core/result.h"
#include "ops/mesh_texture.h"

namespace dpoint {

enum class SampleMethod { kUniform, kPoisson, kStratified };

// "uniform", "poisson" or "stratified" (a usage error lists them).
Result<SampleMethod> parseSampleMethod(std::string_view text);

struct SampleOptions {
  uint64_t count = 0;  // points to make, at least 1
  SampleMethod method = SampleMethod::kUniform;
  uint64_t seed = 0;
  unsigned threads = 0;     // 0: all cores (the result does not depend on it)
  uint64_t max_memory = 0;  // 0: defaultMemoryLimit()
  Progress* progress = nullptr;
  double poisson_factor = 5.0;  // Poisson: uniform samples drawn per point kept (Open3D's init_factor)
  std::vector<uint32_t>* faces = nullptr;  // when not null: gets the triangle of each point
  // When not null: the mesh's base-colour textures (mesh_texture.h), multiplied into the colours.
  const MeshTexture* texture = nullptr;
};

// The sample of `mesh`'s triangles. Errors: no triangles, no area, a non-finite vertex of a
// triangle, a count of 0 or beyond memory (kResourceLimit). `what` names the mesh in messages.
Result<PointSet> sampleSurface(const PointSet& mesh, const SampleOptions& options, const std::string& what);

// The total area of the mesh's triangles (0 for a point set).
double surfaceArea(const PointSet& mesh);
// How coarse a mesh is where most of its surface lies: with its triangles ordered by their longest
// edge, the longest edge of the one at half of the area (0 for a point set). A marching-cubes mesh's
// is about its grid step; a CAD part's, whose flat faces are a few long triangles, far more.
double medianTriangleEdge(const PointSet& mesh);

}  // namespace dpoint
