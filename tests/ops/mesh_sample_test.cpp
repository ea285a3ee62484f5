// The mesh sampler (ops/mesh_sample.h) on BoxTextured, the 2CylinderEngine and a generated
// Mandelbulb mesh: every point on its triangle, the share of points per triangle as its share of the
// area (chi-square), the same points on any thread count, Poisson samples spread evenly.
#include "ops/mesh_sample.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "converters/gltf_read.h"
#include "converters/ply.h"
#include "test_support.h"

namespace dpoint {
namespace {

const std::string kModels = "/usr/share/assimp/models/glTF2/";

PointSet readMesh(const std::string& path) {
  GltfReadOptions options;
  options.triangles = true;
  Result<PointSet> mesh = readGltf(path, options);
  EXPECT_TRUE(mesh.ok()) << mesh.error().message;
  return mesh.ok() ? std::move(*mesh) : PointSet{};
}

PointSet mandelbulbMesh() {
  test::TempDir dir;
  const std::string path = dir.file("bulb.ply");
  const test::CommandResult run = test::runDpoint({"generate", "mandelbulb", "--resolution", "48", "-o", path, "-q"});
  EXPECT_EQ(run.exit_code, 0) << run.err;
  Result<PointSet> mesh = readPly(path);
  EXPECT_TRUE(mesh.ok());
  return mesh.ok() ? std::move(*mesh) : PointSet{};
}

double extentOf(const PointSet& set) {
  const Box box = boundingBox(set.positions);
  return glm::length(box.max - box.min);
}

// Every point lies on the plane of its triangle and inside it, to 1e-12 of the extent.
void expectOnTriangles(const PointSet& mesh, const PointSet& sample, const std::vector<uint32_t>& faces,
                       const std::string& what) {
  const double tolerance = 1e-12 * extentOf(mesh);
  ASSERT_EQ(faces.size(), sample.size());
  double worst = 0.0;
  for (size_t i = 0; i < sample.size(); ++i) {
    const uint32_t* v = &mesh.triangles[3 * size_t{faces[i]}];
    const glm::dvec3 a = mesh.positions[v[0]], b = mesh.positions[v[1]], c = mesh.positions[v[2]];
    const glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
    const glm::dvec3 p = sample.positions[i];
    worst = std::max(worst, std::fabs(glm::dot(p - a, n)));
    // Inside: each edge's side, as a distance from the edge's line.
    const glm::dvec3 corners[3] = {a, b, c};
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 e = corners[(k + 1) % 3] - corners[k];
      const double outside = glm::dot(glm::cross(e, p - corners[k]), n) / glm::length(e);
      worst = std::max(worst, -outside);
    }
  }
  EXPECT_LE(worst, tolerance) << what << ": a point is " << worst << " off its triangle";
}

// Pearson's chi-square of the points per bin of triangles (bins of about equal area, contiguous in
// index order) against the counts the areas predict; the p-value by Wilson and Hilferty's normal
// approximation of the chi-square distribution.
double chiSquareP(const PointSet& mesh, const std::vector<uint32_t>& faces, size_t bins) {
  const size_t triangles = mesh.triangles.size() / 3;
  std::vector<double> area(triangles);
  double total = 0.0;
  for (size_t t = 0; t < triangles; ++t) {
    const glm::dvec3 a = mesh.positions[mesh.triangles[3 * t]];
    area[t] = 0.5 * glm::length(glm::cross(mesh.positions[mesh.triangles[3 * t + 1]] - a, mesh.positions[mesh.triangles[3 * t + 2]] - a));
    total += area[t];
  }
  bins = std::min(bins, triangles);
  std::vector<size_t> bin_of(triangles);
  std::vector<double> expected(bins, 0.0);
  double running = 0.0;
  for (size_t t = 0; t < triangles; ++t) {
    bin_of[t] = std::min(bins - 1, static_cast<size_t>(running / total * static_cast<double>(bins)));
    expected[bin_of[t]] += area[t] / total * static_cast<double>(faces.size());
    running += area[t];
  }
  std::vector<double> observed(bins, 0.0);
  for (uint32_t f : faces) observed[bin_of[f]] += 1.0;
  double chi2 = 0.0;
  size_t used = 0;
  for (size_t b = 0; b < bins; ++b) {
    if (expected[b] <= 0.0) continue;
    chi2 += (observed[b] - expected[b]) * (observed[b] - expected[b]) / expected[b];
    ++used;
  }
  const double k = static_cast<double>(used - 1);
  const double z = (std::cbrt(chi2 / k) - (1.0 - 2.0 / (9.0 * k))) / std::sqrt(2.0 / (9.0 * k));
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

void checkUniform(const PointSet& mesh, const std::string& what, uint64_t count) {
  ASSERT_FALSE(mesh.triangles.empty()) << what;
  std::vector<uint32_t> faces;
  SampleOptions options;
  options.count = count;
  options.seed = 37;
  options.faces = &faces;
  Result<PointSet> sample = sampleSurface(mesh, options, what);
  ASSERT_TRUE(sample.ok()) << sample.error().message;
  ASSERT_EQ(sample->size(), count);
  expectOnTriangles(mesh, *sample, faces, what);
  const double p = chiSquareP(mesh, faces, 64);
  EXPECT_GE(p, 0.01) << what << ": points per triangle do not follow the areas";
  // Normals are unit vectors; colours come with a coloured mesh.
  const Dimension* nx = sample->dimensions.find("nx");
  const Dimension* ny = sample->dimensions.find("ny");
  const Dimension* nz = sample->dimensions.find("nz");
  ASSERT_TRUE(nx && ny && nz);
  for (size_t i = 0; i < sample->size(); i += 97)
    EXPECT_NEAR(glm::length(glm::dvec3(nx->value(i), ny->value(i), nz->value(i))), 1.0, 1e-6) << what;
  EXPECT_EQ(sample->hasColors(), mesh.hasColors()) << what;
  // The same points on one thread and on three; another seed, other points.
  options.faces = nullptr;
  options.threads = 1;
  Result<PointSet> one = sampleSurface(mesh, options, what);
  options.threads = 3;
  Result<PointSet> three = sampleSurface(mesh, options, what);
  ASSERT_TRUE(one.ok() && three.ok());
  EXPECT_EQ(std::memcmp(one->positions.data(), three->positions.data(), count * sizeof(glm::dvec3)), 0) << what;
  EXPECT_EQ(std::memcmp(one->positions.data(), sample->positions.data(), count * sizeof(glm::dvec3)), 0) << what;
  options.seed = 38;
  Result<PointSet> other = sampleSurface(mesh, options, what);
  ASSERT_TRUE(other.ok());
  EXPECT_NE(std::memcmp(other->positions.data(), sample->positions.data(), count * sizeof(glm::dvec3)), 0) << what;
}

TEST(MeshSample, boxTexturedPointsLieOnItsTrianglesInProportionToTheirAreas) {
  checkUniform(readMesh(kModels + "BoxTextured-glTF-Binary/BoxTextured.glb"), "BoxTextured", 20000);
}

TEST(MeshSample, twoCylinderEnginePointsLieOnItsTrianglesInProportionToTheirAreas) {
  checkUniform(readMesh(kModels + "2CylinderEngine-glTF-Binary/2CylinderEngine.glb"), "2CylinderEngine", 400000);
}

TEST(MeshSample, mandelbulbMeshPointsLieOnItsTrianglesInProportionToTheirAreas) {
  checkUniform(mandelbulbMesh(), "Mandelbulb", 200000);
}

// Mean and smallest nearest-neighbour distance, by brute force (small sets).
std::pair<double, double> spacing(const PointSet& set) {
  double sum = 0.0, smallest = 1e300;
  for (size_t i = 0; i < set.size(); ++i) {
    double best = 1e300;
    for (size_t j = 0; j < set.size(); ++j)
      if (j != i) best = std::min(best, glm::length(set.positions[i] - set.positions[j]));
    sum += best;
    smallest = std::min(smallest, best);
  }
  return {sum / static_cast<double>(set.size()), smallest};
}

TEST(MeshSample, poissonSamplesAreEvenAndDeterministic) {
  const PointSet box = readMesh(kModels + "BoxTextured-glTF-Binary/BoxTextured.glb");
  SampleOptions options;
  options.count = 3000;
  Result<PointSet> uniform = sampleSurface(box, options, "box");
  options.method = SampleMethod::kPoisson;
  std::vector<uint32_t> faces;
  options.faces = &faces;
  Result<PointSet> poisson = sampleSurface(box, options, "box");
  ASSERT_TRUE(uniform.ok() && poisson.ok());
  ASSERT_EQ(poisson->size(), 3000u);
  expectOnTriangles(box, *poisson, faces, "box poisson");
  const auto [uniform_mean, uniform_min] = spacing(*uniform);
  const auto [poisson_mean, poisson_min] = spacing(*poisson);
  // An even sample: no two points close together, and a larger mean spacing than independent points.
  EXPECT_GT(poisson_mean, 1.3 * uniform_mean);
  EXPECT_GT(poisson_min, 10.0 * uniform_min);
  // A square grid of the same count on the box's 6 faces has spacing sqrt(6 / 3000) = 0.0447.
  EXPECT_NEAR(poisson_mean, 0.0447, 0.0447 * 0.2);
  options.faces = nullptr;
  options.threads = 1;
  Result<PointSet> again = sampleSurface(box, options, "box");
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(std::memcmp(again->positions.data(), poisson->positions.data(), 3000 * sizeof(glm::dvec3)), 0);
}

// Stratified (render's surface): each triangle gets its expected count rounded down or up, and the
// points lie on their triangles.
TEST(MeshSample, stratifiedGivesEachTriangleItsShareWithinOnePoint) {
  const PointSet engine = readMesh(kModels + "2CylinderEngine-glTF-Binary/2CylinderEngine.glb");
  ASSERT_FALSE(engine.triangles.empty());
  std::vector<uint32_t> faces;
  SampleOptions options;
  options.count = 300000;
  options.method = SampleMethod::kStratified;
  options.faces = &faces;
  Result<PointSet> sample = sampleSurface(engine, options, "engine");
  ASSERT_TRUE(sample.ok()) << sample.error().message;
  expectOnTriangles(engine, *sample, faces, "engine stratified");
  const size_t triangles = engine.triangles.size() / 3;
  std::vector<double> area(triangles);
  double total = 0.0;
  for (size_t t = 0; t < triangles; ++t) {
    const glm::dvec3 a = engine.positions[engine.triangles[3 * t]];
    area[t] = 0.5 * glm::length(glm::cross(engine.positions[engine.triangles[3 * t + 1]] - a,
                                           engine.positions[engine.triangles[3 * t + 2]] - a));
    total += area[t];
  }
  std::vector<double> count(triangles, 0.0);
  for (uint32_t f : faces) count[f] += 1.0;
  double worst = 0.0;
  for (size_t t = 0; t < triangles; ++t) worst = std::max(worst, std::fabs(count[t] - area[t] / total * 300000.0));
  EXPECT_LT(worst, 1.0 + 1e-6) << "a triangle's count is more than one point from its share";
  EXPECT_GE(chiSquareP(engine, faces, 64), 0.01);
}

TEST(MeshSample, refusesWhatCannotBeSampled) {
  PointSet points;
  points.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  SampleOptions options;
  options.count = 10;
  Result<PointSet> none = sampleSurface(points, options, "cloud.ply");
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.error().message, "cloud.ply: has no triangles to sample (it is a point set)");
  points.triangles = {0, 1, 1};
  Result<PointSet> flat = sampleSurface(points, options, "flat.ply");
  ASSERT_FALSE(flat.ok());
  EXPECT_TRUE(test::contains(flat.error().message, "its triangles have no area")) << flat.error().message;
  points.triangles = {0, 1, 2};
  options.count = 0;
  EXPECT_FALSE(sampleSurface(points, options, "t").ok());
  options.count = uint64_t{1} << 40;
  options.max_memory = uint64_t{1} << 30;
  Result<PointSet> huge = sampleSurface(points, options, "t");
  ASSERT_FALSE(huge.ok());
  EXPECT_EQ(huge.error().code, ExitCode::kResourceLimit);
  EXPECT_FALSE(parseSampleMethod("grid").ok());
}

}  // namespace
}  // namespace dpoint
