// Escape-time fractals (Mandelbulb, quaternion Julia) and the marching cubes that meshes them,
// checked against the seed study's own grids and scikit-image's vertices (shared/reference).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <numbers>
#include <set>
#include <sstream>
#include <unordered_map>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "generators/escape_grid.h"
#include "generators/julia.h"
#include "generators/mandelbulb.h"
#include "generators/marching_cubes.h"
#include "test_support.h"

namespace dpoint {
namespace {

PositionArray readVertices(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // header x,y,z
  PositionArray out;
  while (std::getline(in, line)) {
    glm::dvec3 p;
    char comma;
    std::istringstream(line) >> p.x >> comma >> p.y >> comma >> p.z;
    out.push_back(p);
  }
  return out;
}

// Reference vertices with none of ours within `tolerance` (bucketed by a cell of 1e-3).
size_t unmatchedVertices(const PositionArray& reference, const PositionArray& ours,
                         double tolerance) {
  constexpr double kCell = 1e-3;
  auto key = [](int64_t x, int64_t y, int64_t z) { return (x * 73856093) ^ (y * 19349663) ^ (z * 83492791); };
  std::unordered_multimap<int64_t, glm::dvec3> buckets;
  for (const glm::dvec3& p : ours) {
    const glm::dvec3 c = glm::floor(p / kCell);
    buckets.emplace(key(static_cast<int64_t>(c.x), static_cast<int64_t>(c.y), static_cast<int64_t>(c.z)), p);
  }
  size_t unmatched = 0;
  for (const glm::dvec3& p : reference) {
    const glm::dvec3 c = glm::floor(p / kCell);
    bool found = false;
    for (int dx = -1; dx <= 1 && !found; ++dx)
      for (int dy = -1; dy <= 1 && !found; ++dy)
        for (int dz = -1; dz <= 1 && !found; ++dz) {
          auto range = buckets.equal_range(key(static_cast<int64_t>(c.x) + dx, static_cast<int64_t>(c.y) + dy,
                                               static_cast<int64_t>(c.z) + dz));
          for (auto it = range.first; it != range.second && !found; ++it)
            found = glm::length(it->second - p) <= tolerance;
        }
    unmatched += found ? 0 : 1;
  }
  return unmatched;
}

// Every directed edge (a, b) of the triangles, counted.
std::map<std::pair<uint32_t, uint32_t>, int> directedEdges(const PointSet& mesh) {
  std::map<std::pair<uint32_t, uint32_t>, int> edges;
  for (size_t t = 0; t < mesh.triangles.size(); t += 3)
    for (size_t e = 0; e < 3; ++e) ++edges[{mesh.triangles[t + e], mesh.triangles[t + (e + 1) % 3]}];
  return edges;
}

void expectSameMesh(const PointSet& a, const PointSet& b) {
  ASSERT_EQ(a.positions.size(), b.positions.size());
  EXPECT_TRUE(a.positions == b.positions);
  EXPECT_TRUE(a.triangles == b.triangles);
}

TEST(Mandelbulb, seedGridMatchesReferenceByteForByte) {
  test::TempDir dir;
  MandelbulbParams params;
  params.resolution = 64;
  params.grid_out = dir.file("grid.u8");
  Result<PointSet> mesh = generateMandelbulb(params);
  ASSERT_TRUE(mesh.ok()) << mesh.error().message;
  const std::string ours = test::readFile(params.grid_out);
  const std::string reference = test::readFile(DPOINT_REFERENCE_DIR "/mandelbulb_r64_i100_escape.u8");
  ASSERT_EQ(ours.size(), 64u * 64u * 64u);
  EXPECT_TRUE(ours == reference);
}

// The seed's loop as it is written (mandelbulb.h), without the shortcuts mandelbulbEscapeSeed takes.
int plainSeedEscape(double cx, double cy, double cz, int max_iter, double power) {
  double x = cx, y = cy, z = cz;
  for (int i = 0; i < max_iter; ++i) {
    const double r = std::sqrt(x * x + y * y + z * z);
    if (r > 2.0) return i;
    if (r == 0.0) {
      x = cx, y = cy, z = cz;
      continue;
    }
    const double theta = std::acos(z / r), phi = std::atan2(y, x);
    const double r2 = r * r, r4 = r2 * r2;
    const double rn = power == 8.0 ? r4 * r4 : std::pow(r, power);
    const double nt = power * theta, np = power * phi, sin_t = std::sin(nt);
    x = rn * sin_t * std::cos(np) + cx;
    y = rn * sin_t * std::sin(np) + cy;
    z = rn * std::cos(nt) + cz;
  }
  return max_iter;
}

// The escape shortcut and the cycle detection give the plain loop's counts: on a res-61 grid of
// the default cube (odd: the origin included), on points near the surface (a finer grid in a
// corner of the bulb), at the lazy pass's cap, at max_iter and at caps of 1 to 4 (where the
// interior lookahead starts at the first update), for powers 8 and 3. Every shortcut is taken on
// these points, so a wrong margin, bound or a false cycle would show.
TEST(Mandelbulb, seedShortcutsGiveThePlainLoopsCounts) {
  const GridAxis coarse{61, -1.5, 1.5}, fine{41, 0.55, 0.75};
  size_t points = 0, mismatches = 0;
  for (const GridAxis& axis : {coarse, fine})
    for (double power : {8.0, 3.0})
      for (int limit : {1, 2, 3, 4, 26, 100})
        for (int i = 0; i < axis.resolution; ++i)
          for (int j = 0; j < axis.resolution; ++j)
            for (int k = 0; k < axis.resolution; k += 2) {
              const double x = axis.value(i), y = axis.value(j), z = axis.value(k);
              ++points;
              if (mandelbulbEscapeSeed(x, y, z, limit, power) != plainSeedEscape(x, y, z, limit, power)) ++mismatches;
            }
  EXPECT_EQ(mismatches, 0u) << "of " << points;
}

TEST(Mandelbulb, oddResolutionHasOriginInside) {
  EXPECT_EQ(mandelbulbEscapeSeed(0.0, 0.0, 0.0, 100), 100);
  EXPECT_EQ(mandelbulbEscapeFast(0.0, 0.0, 0.0, 100), 100);
  const GridAxis axis{65, -1.5, 1.5};
  ASSERT_EQ(axis.value(32), 0.0);
  const EscapeRowFunction seed = mandelbulbRow(MandelbulbVariant::kSeed, 8.0);
  Result<std::vector<uint32_t>> plane = computeEscapeGrid(axis, 100, seed, 0, 32, 1);
  ASSERT_TRUE(plane.ok());
  EXPECT_EQ((*plane)[32 * 65 + 32], 100u);
  MandelbulbParams params;
  params.resolution = 33;  // the seed crashes on any odd resolution
  Result<PointSet> mesh = generateMandelbulb(params);
  ASSERT_TRUE(mesh.ok()) << mesh.error().message;
  EXPECT_GT(mesh->positions.size(), 0u);
  for (const glm::dvec3& p : mesh->positions)
    ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
}

// The fast variant's counts against the seed's on every 8th x-plane of the res-200 grid (25 planes,
// a million voxels); the share is reported, and must be small.
TEST(Mandelbulb, fastVariantDisagreesWithSeedOnFewVoxels) {
  const GridAxis axis{200, -1.5, 1.5};
  const EscapeRowFunction seed_row = mandelbulbRow(MandelbulbVariant::kSeed, 8.0);
  const EscapeRowFunction fast_row = mandelbulbRow(MandelbulbVariant::kFast, 8.0);
  size_t differ = 0, total = 0;
  for (int plane = 4; plane < 200; plane += 8) {
    Result<std::vector<uint32_t>> seed = computeEscapeGrid(axis, 100, seed_row, 0, plane, 1);
    Result<std::vector<uint32_t>> fast = computeEscapeGrid(axis, 100, fast_row, 0, plane, 1);
    ASSERT_TRUE(seed.ok() && fast.ok());
    for (size_t i = 0; i < seed->size(); ++i) differ += (*seed)[i] != (*fast)[i];
    total += seed->size();
  }
  const double share = static_cast<double>(differ) / static_cast<double>(total);
  std::cout << "fast vs seed at res 200: " << differ << " of " << total << " voxels differ (" << 100.0 * share
            << "%)\n";
  RecordProperty("fast_vs_seed_differing_voxels", std::to_string(differ) + "/" + std::to_string(total));
  EXPECT_LT(share, 0.01);
}

// The row function runs several points at once in SIMD lanes; it must give each point the count
// of the one-point escape function, on the polar axis too.
TEST(Mandelbulb, fastRowEqualsOnePointEscape) {
  const GridAxis axis{23, -1.5, 1.5};
  std::vector<double> zs;
  for (int k = 0; k < 23; ++k) zs.push_back(axis.value(k));
  zs.push_back(0.0);
  const EscapeRowFunction row = mandelbulbRow(MandelbulbVariant::kFast, 8.0);
  for (int limit : {1, 2, 3, 26, 100})
    for (double x : {-0.6, 0.0, 0.2, 1.3})
      for (double y : {0.0, 0.5, -0.15})
        for (size_t n : {size_t{1}, size_t{5}, zs.size()}) {
          std::vector<uint32_t> counts(n, 12345);
          row(x, y, zs.data(), n, limit, counts.data());
          for (size_t k = 0; k < n; ++k)
            ASSERT_EQ(counts[k], static_cast<uint32_t>(mandelbulbEscapeFast(x, y, zs[k], limit)))
                << x << " " << y << " " << zs[k] << " limit " << limit;
        }
}

TEST(Mandelbulb, rejectsBadResolutionAndLevel) {
  auto failure = [](MandelbulbParams p) {
    Result<PointSet> r = generateMandelbulb(p);
    EXPECT_FALSE(r.ok());
    return r.ok() ? Error{} : r.error();
  };
  MandelbulbParams p;
  p.resolution = 1;
  Error e = failure(p);
  EXPECT_EQ(e.code, ExitCode::kUsage);
  EXPECT_NE(e.message.find("--resolution"), std::string::npos) << e.message;
  EXPECT_NE(e.message.find("2..65536"), std::string::npos) << e.message;
  p.resolution = 65537;
  EXPECT_NE(failure(p).message.find("--resolution"), std::string::npos);
  p = MandelbulbParams{};
  p.max_iter = 0;
  EXPECT_NE(failure(p).message.find("--max-iter"), std::string::npos);
  for (double level : {0.0, 100.0, 150.0, -2.0}) {
    p = MandelbulbParams{};
    p.resolution = 8;
    p.level = level;
    e = failure(p);
    EXPECT_EQ(e.code, ExitCode::kUsage);
    EXPECT_NE(e.message.find("--level"), std::string::npos) << e.message;
    EXPECT_NE(e.message.find("(0, 100)"), std::string::npos) << e.message;
  }
  p = MandelbulbParams{};
  p.lo = 1.0;
  p.hi = -1.0;
  EXPECT_NE(failure(p).message.find("--bounds"), std::string::npos);
  p = MandelbulbParams{};
  p.variant = MandelbulbVariant::kFast;
  p.power = 3.0;
  EXPECT_NE(failure(p).message.find("--power 8"), std::string::npos);
}

TEST(Mandelbulb, refusesOverMemoryLimit) {
  MandelbulbParams params;
  params.resolution = 1024;
  params.max_memory = 100u << 20;  // 100 MiB against a mesh of about 650 MB
  Result<PointSet> r = generateMandelbulb(params);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ExitCode::kResourceLimit);
  EXPECT_NE(r.error().message.find("--max-memory"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("mandelbulb"), std::string::npos) << r.error().message;
}

TEST(Julia, gridMatchesReferenceAndIsMirrorSymmetric) {
  test::TempDir dir;
  JuliaParams params;
  params.resolution = 64;
  params.grid_out = dir.file("grid.u8");
  Result<PointSet> mesh = generateJulia(params);
  ASSERT_TRUE(mesh.ok()) << mesh.error().message;
  const std::string ours = test::readFile(params.grid_out);
  EXPECT_TRUE(ours == test::readFile(DPOINT_REFERENCE_DIR "/julia_r64_i200_escape.u8"));
  ASSERT_EQ(ours.size(), 64u * 64u * 64u);
  auto at = [&](size_t i, size_t j, size_t k) { return ours[(i * 64 + j) * 64 + k]; };
  for (size_t i = 0; i < 64; ++i)
    for (size_t j = 0; j < 64; ++j)
      for (size_t k = 0; k < j; ++k) ASSERT_EQ(at(i, j, k), at(i, k, j)) << i << " " << j << " " << k;
  // The same grid held in memory and written whole.
  Result<std::vector<uint32_t>> whole = computeEscapeGrid(GridAxis{64, -1.5, 1.5}, 200, juliaRow(params.c), 0, 0, 64);
  ASSERT_TRUE(whole.ok());
  ASSERT_TRUE(writeEscapeGrid(dir.file("whole.u8"), *whole, 200).ok());
  EXPECT_TRUE(test::readFile(dir.file("whole.u8")) == ours);
  // Exact by construction at any resolution, the origin included.
  const GridAxis odd{41, -1.5, 1.5};
  Result<std::vector<uint32_t>> grid = computeEscapeGrid(odd, 200, juliaRow(params.c), 0, 0, 41);
  ASSERT_TRUE(grid.ok());
  for (size_t i = 0; i < 41; ++i)
    for (size_t j = 0; j < 41; ++j)
      for (size_t k = 0; k < j; ++k) ASSERT_EQ((*grid)[(i * 41 + j) * 41 + k], (*grid)[(i * 41 + k) * 41 + j]);
}

TEST(Julia, escapeSquareThresholdEqualsTheSquareRootTest) {
  // Every double within 2^20 ulps of 4 and of the threshold, and the threshold's neighbours.
  for (double centre : {4.0, kJuliaEscapeSquare}) {
    double below = centre, above = centre;
    for (int i = 0; i < (1 << 20); ++i) {
      below = std::nextafter(below, 0.0);
      above = std::nextafter(above, 8.0);
      for (double s : {below, above}) ASSERT_EQ(std::sqrt(s) > 2.0, s > kJuliaEscapeSquare) << s;
    }
  }
  EXPECT_FALSE(std::sqrt(std::nextafter(4.0, 8.0)) > 2.0);
  EXPECT_EQ(kJuliaEscapeSquare, std::nextafter(4.0, 8.0));
}

TEST(Julia, rejectsNonFiniteConstantAndBadLevel) {
  JuliaParams params;
  params.resolution = 8;
  params.c.y = std::nan("");
  Result<PointSet> r = generateJulia(params);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ExitCode::kUsage);
  EXPECT_NE(r.error().message.find("--c"), std::string::npos) << r.error().message;
  params = JuliaParams{};
  params.level = 200.0;
  r = generateJulia(params);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("--level 200: must lie inside"), std::string::npos) << r.error().message;
}

TEST(Julia, gridOutIsUint16AboveMaxIter255) {
  test::TempDir dir;
  JuliaParams params;
  params.resolution = 6;
  params.max_iter = 300;
  params.grid_out = dir.file("grid.u16");
  ASSERT_TRUE(generateJulia(params).ok());
  const std::string bytes = test::readFile(params.grid_out);
  ASSERT_EQ(bytes.size(), 2u * 6 * 6 * 6);
  const GridAxis axis{6, -1.5, 1.5};
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      for (int k = 0; k < 6; ++k) {
        const size_t at = 2 * static_cast<size_t>((i * 6 + j) * 6 + k);
        const int stored = static_cast<uint8_t>(bytes[at]) | static_cast<uint8_t>(bytes[at + 1]) << 8;
        ASSERT_EQ(stored, juliaEscape(axis.value(i), axis.value(j), axis.value(k), params.c, 300));
      }
}

TEST(MarchingCubes, matchesSkimageVerticesMandelbulb) {
  MandelbulbParams params;
  params.resolution = 64;
  params.frame = GridFrame::kSeed;
  Result<PointSet> mesh = generateMandelbulb(params);
  ASSERT_TRUE(mesh.ok());
  const PositionArray reference = readVertices(DPOINT_REFERENCE_DIR "/mandelbulb_r64_i100_skimage_verts.csv");
  ASSERT_EQ(reference.size(), 13120u);
  const size_t unmatched = unmatchedVertices(reference, mesh->positions, 1e-6);
  std::cout << "mandelbulb r64: " << mesh->positions.size() << " vertices (skimage " << reference.size() << "), "
            << unmatched << " of skimage's without one of ours within 1e-6\n";
  EXPECT_LE(static_cast<double>(unmatched), 0.005 * static_cast<double>(reference.size()));
  EXPECT_NEAR(static_cast<double>(mesh->positions.size()), 13120.0, 131.2);
}

TEST(MarchingCubes, matchesSkimageVerticesJulia) {
  JuliaParams params;
  params.resolution = 64;
  params.frame = GridFrame::kSeed;
  Result<PointSet> mesh = generateJulia(params);
  ASSERT_TRUE(mesh.ok());
  const PositionArray reference = readVertices(DPOINT_REFERENCE_DIR "/julia_r64_i200_skimage_verts.csv");
  ASSERT_EQ(reference.size(), 3850u);
  const size_t unmatched = unmatchedVertices(reference, mesh->positions, 1e-6);
  std::cout << "julia r64: " << mesh->positions.size() << " vertices (skimage " << reference.size() << "), "
            << unmatched << " unmatched\n";
  EXPECT_LE(static_cast<double>(unmatched), 0.005 * static_cast<double>(reference.size()));
  EXPECT_NEAR(static_cast<double>(mesh->positions.size()), 3850.0, 38.5);
}

TEST(MarchingCubes, lazyClassificationEqualsFullComputation) {
  EscapeSurfaceParams params;
  params.axis = {57, -1.5, 1.5};
  params.max_iter = 100;
  params.level = 25.0;
  for (double level : {25.0, 7.5, 90.0}) {
    params.level = level;
    params.lazy = true;
    Result<PointSet> lazy = generateEscapeSurface(params, mandelbulbRow(MandelbulbVariant::kSeed, 8.0));
    params.lazy = false;
    Result<PointSet> full = generateEscapeSurface(params, mandelbulbRow(MandelbulbVariant::kSeed, 8.0));
    ASSERT_TRUE(lazy.ok() && full.ok());
    EXPECT_GT(lazy->positions.size(), 100u);
    expectSameMesh(*lazy, *full);
  }
  params.level = 25.0;
  params.lazy = true;
  Result<PointSet> lazy_fast = generateEscapeSurface(params, mandelbulbRow(MandelbulbVariant::kFast, 8.0));
  params.lazy = false;
  Result<PointSet> full_fast = generateEscapeSurface(params, mandelbulbRow(MandelbulbVariant::kFast, 8.0));
  ASSERT_TRUE(lazy_fast.ok() && full_fast.ok());
  expectSameMesh(*lazy_fast, *full_fast);
  // The mesh from the marching cubes of the whole grid held in memory.
  const GridAxis axis{57, -1.5, 1.5};
  Result<std::vector<uint32_t>> grid =
      computeEscapeGrid(axis, 100, mandelbulbRow(MandelbulbVariant::kSeed, 8.0), 0, 0, 57);
  ASSERT_TRUE(grid.ok());
  const std::vector<double> values(grid->begin(), grid->end());
  const double step = axis.step();
  PointSet whole = marchingCubes(values, 57, 57, 57, 25.0, glm::dvec3(0.0), glm::dvec3(step));
  params.level = 25.0;
  params.lazy = true;
  params.frame = GridFrame::kSeed;
  Result<PointSet> streamed = generateEscapeSurface(params, mandelbulbRow(MandelbulbVariant::kSeed, 8.0));
  ASSERT_TRUE(streamed.ok());
  ASSERT_EQ(whole.positions.size(), streamed->positions.size());
  EXPECT_TRUE(whole.triangles == streamed->triangles);
  for (size_t v = 0; v < whole.positions.size(); ++v)
    ASSERT_LE(glm::length(whole.positions[v] - streamed->positions[v]), 1e-15) << v;
}

TEST(MarchingCubes, identicalForAnyThreadCount) {
  for (MandelbulbVariant variant : {MandelbulbVariant::kSeed, MandelbulbVariant::kFast}) {
    MandelbulbParams params;
    params.resolution = 81;
    params.variant = variant;
    params.threads = 1;
    Result<PointSet> one = generateMandelbulb(params);
    params.threads = 2;
    Result<PointSet> two = generateMandelbulb(params);
    params.threads = 5;  // other slab boundaries
    Result<PointSet> five = generateMandelbulb(params);
    ASSERT_TRUE(one.ok() && two.ok() && five.ok());
    expectSameMesh(*one, *two);
    expectSameMesh(*one, *five);
  }
  // A zoom whose mesh outgrows the reservation (63,516 vertices against 36,905): the arrays move
  // while slabs placed earlier are still being copied in by other workers (escape_grid.cpp).
  MandelbulbParams zoom;
  zoom.resolution = 81;
  zoom.variant = MandelbulbVariant::kFast;
  zoom.lo = -1.0;
  zoom.hi = 1.0;
  zoom.threads = 1;
  Result<PointSet> one = generateMandelbulb(zoom);
  ASSERT_TRUE(one.ok());
  EXPECT_GT(one->size(), 1.25 * 0.5 * std::pow(81.0, 2.5));
  for (unsigned threads : {7u, 16u}) {
    zoom.threads = threads;
    Result<PointSet> many = generateMandelbulb(zoom);
    ASSERT_TRUE(many.ok());
    expectSameMesh(*one, *many);
  }
}

TEST(MarchingCubes, meshIsConsistentlyOriented) {
  MandelbulbParams params;
  params.resolution = 64;
  Result<PointSet> mesh = generateMandelbulb(params);
  ASSERT_TRUE(mesh.ok());
  for (const auto& [edge, count] : directedEdges(*mesh)) ASSERT_EQ(count, 1) << edge.first << "->" << edge.second;

  // A closed surface: a ball of radius 0.8 in a cube, as a field that decreases outward. Every
  // directed edge is matched by its reverse and the enclosed volume is positive (outward normals).
  const int n = 24;
  std::vector<double> values;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const glm::dvec3 p = glm::dvec3(i, j, k) / static_cast<double>(n - 1) * 2.0 - 1.0;
        values.push_back(1.0 - glm::dot(p, p));
      }
  const PointSet ball = marchingCubes(values, n, n, n, 1.0 - 0.64, glm::dvec3(-1.0), glm::dvec3(2.0 / (n - 1)));
  std::map<std::pair<uint32_t, uint32_t>, int> edges = directedEdges(ball);
  for (const auto& [edge, count] : edges) {
    ASSERT_EQ(count, 1);
    ASSERT_EQ(edges.count({edge.second, edge.first}), 1u);
  }
  double volume = 0.0;
  for (size_t t = 0; t < ball.triangles.size(); t += 3) {
    const glm::dvec3 a = ball.positions[ball.triangles[t]], b = ball.positions[ball.triangles[t + 1]],
                     c = ball.positions[ball.triangles[t + 2]];
    volume += glm::dot(a, glm::cross(b, c)) / 6.0;
  }
  EXPECT_NEAR(volume, 4.0 / 3.0 * std::numbers::pi * 0.512, 0.05);
}

TEST(MarchingCubes, everyCaseUsesExactlyItsCrossedEdges) {
  for (unsigned mask = 0; mask < 256; ++mask) {
    std::set<int> crossed, used;
    for (int e = 0; e < 12; ++e) {
      const int a = mcEdgeStart(e), b = a | (1 << mcEdgeAxis(e));
      if (((mask >> a) & 1) != ((mask >> b) & 1)) crossed.insert(e);
    }
    const McCase& c = marchingCubesCase(mask);
    for (int t = 0; t < 3 * c.triangle_count; ++t) used.insert(c.edges[static_cast<size_t>(t)]);
    EXPECT_EQ(crossed, used) << "mask " << mask;
  }
}

TEST(MarchingCubes, nativeFrameVerticesLieOnGridLines) {
  JuliaParams params;
  params.resolution = 33;
  params.lo = -1.2;
  params.hi = 1.3;
  Result<PointSet> mesh = generateJulia(params);
  ASSERT_TRUE(mesh.ok());
  ASSERT_GT(mesh->positions.size(), 0u);
  const GridAxis axis{33, -1.2, 1.3};
  std::set<double> grid_values;
  for (int i = 0; i < 33; ++i) grid_values.insert(axis.value(i));
  for (const glm::dvec3& p : mesh->positions) {
    int on_grid = 0;
    for (int d = 0; d < 3; ++d) {
      on_grid += grid_values.count(p[d]) ? 1 : 0;
      ASSERT_GE(p[d], -1.2);
      ASSERT_LE(p[d], 1.3);
    }
    ASSERT_GE(on_grid, 2);
  }
}

}  // namespace
}  // namespace dpoint
