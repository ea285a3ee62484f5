// Tests of the exact geometric generators (Sierpinski, Menger) and of the pnoise3 colours.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "generators/menger.h"
#include "generators/perlin.h"
#include "generators/sierpinski.h"
#include "test_support.h"

namespace dpoint {
namespace {

// Exact identity of doubles (distinguishes −0 from +0), for maps and equality of point lists.
std::array<uint64_t, 3> bitsOf(const glm::dvec3& p) {
  std::array<uint64_t, 3> bits;
  std::memcpy(&bits[0], &p.x, 8);
  std::memcpy(&bits[1], &p.y, 8);
  std::memcpy(&bits[2], &p.z, 8);
  return bits;
}

bool sameBits(const PositionArray& a, const PositionArray& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (bitsOf(a[i]) != bitsOf(b[i])) return false;
  return true;
}

uint64_t pow4(int n) { return uint64_t{1} << (2 * n); }

// ---------------------------------------------------------------------------------------------
// pnoise3

TEST(Perlin, pnoise3MatchesAll805ReferenceSamplesBitForBit) {
  std::ifstream in(DPOINT_REFERENCE_DIR "/pnoise3_samples.csv");
  ASSERT_TRUE(in) << "missing " DPOINT_REFERENCE_DIR "/pnoise3_samples.csv";
  std::string line;
  std::getline(in, line);
  ASSERT_EQ(line, "x,y,z,pnoise3");
  int rows = 0, mismatches = 0;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    double v[4];
    char comma;
    fields >> v[0] >> comma >> v[1] >> comma >> v[2] >> comma >> v[3];
    ASSERT_TRUE(fields) << "unreadable row " << line;
    // The package parsed its arguments as C floats; its result is a float widened to double.
    const float noise = pnoise3(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]));
    if (static_cast<double>(noise) != v[3]) {
      ++mismatches;
      ADD_FAILURE() << "row " << rows + 2 << ": " << line << " gives " << noise;
    }
    ++rows;
  }
  EXPECT_EQ(rows, 805);
  EXPECT_EQ(mismatches, 0);
}

TEST(Perlin, pnoise3IsZeroAtLatticePointsAndRepeatsEvery1024) {
  EXPECT_EQ(pnoise3(0.0f, 0.0f, 0.0f), 0.0f);
  EXPECT_EQ(pnoise3(3.0f, -7.0f, 12.0f), 0.0f);
  // Halves and quarters keep the fractional part exact at ±1024, so the wrap must give equal bits.
  EXPECT_EQ(pnoise3(0.5f, 0.25f, 0.75f), pnoise3(1024.5f, 0.25f, 0.75f));
  EXPECT_EQ(pnoise3(-0.5f, 0.25f, 0.75f), pnoise3(1023.5f, 0.25f, 0.75f));
  EXPECT_EQ(pnoise3(0.5f, 0.25f, 0.75f), pnoise3(0.5f, 0.25f, -1023.25f));
  // Either side of ±1024, where the cell stops being v's floor and comes from fmod.
  EXPECT_EQ(pnoise3(0.25f, 0.25f, 0.75f), pnoise3(-1023.75f, 0.25f, 0.75f));
  EXPECT_EQ(pnoise3(0.0f, 0.25f, 0.75f), pnoise3(1024.0f, 0.25f, 0.75f));
  EXPECT_EQ(pnoise3(0.0f, 0.25f, 0.75f), pnoise3(-1024.0f, 0.25f, 0.75f));
  EXPECT_EQ(pnoise3(0.25f, 0.5f, 0.75f), pnoise3(0.25f, 2048.5f, 0.75f));
  EXPECT_EQ(pnoise3(0.25f, 0.5f, 0.75f), pnoise3(0.25f, -3071.5f, 0.75f));
  EXPECT_NE(pnoise3(0.5f, 0.25f, 0.75f), 0.0f);
}

TEST(Perlin, seedColorAddsOffsetsInDoubleAndRoundsOnce) {
  const glm::dvec3 p(0.1, -1.3, 2.7);
  const glm::vec3 color = seedColor(p);
  for (int c = 0; c < 3; ++c) {
    const double offset = 100.0 * c;
    const double n = pnoise3(static_cast<float>(p.x + offset), static_cast<float>(p.y + offset),
                             static_cast<float>(p.z + offset));
    EXPECT_EQ(color[c], static_cast<float>(0.5 + 0.5 * n)) << "channel " << c;
    EXPECT_GE(color[c], 0.0f);
    EXPECT_LE(color[c], 1.0f);
  }
  // The seed added 100 to a Python float (double) and the package rounded the sum to float. For
  // x = 2^-18 + 2^-45 that sum rounds up to 100 + 2^-17, while float(x) + 100 in float is a tie
  // that rounds to 100: the green channel must be the first.
  const glm::dvec3 q(0x1p-18 + 0x1p-45, 0.3, 0.6);
  const float seed_way = static_cast<float>(
      0.5 + 0.5 * double(pnoise3(static_cast<float>(q.x + 100.0), static_cast<float>(q.y + 100.0),
                                 static_cast<float>(q.z + 100.0))));
  const float float_way = static_cast<float>(
      0.5 + 0.5 * double(pnoise3(static_cast<float>(q.x) + 100.0f, static_cast<float>(q.y) + 100.0f,
                                 static_cast<float>(q.z) + 100.0f)));
  ASSERT_NE(seed_way, float_way);
  EXPECT_EQ(seedColor(q).g, seed_way);
}

TEST(Perlin, colorByNoiseColoursEveryPoint) {
  PointSet points;
  for (int i = 0; i < 50000; ++i) points.positions.emplace_back(i * 0.013, -i * 0.007, 1.0 + i * 0.001);
  colorByNoise(points, 2);
  ASSERT_EQ(points.colors.size(), points.positions.size());
  for (size_t i : {size_t{0}, size_t{1234}, size_t{49999}}) EXPECT_EQ(points.colors[i], seedColor(points.positions[i]));
  PointSet empty;
  colorByNoise(empty, 0);
  EXPECT_TRUE(empty.colors.empty());
}

// ---------------------------------------------------------------------------------------------
// Sierpinski

Result<PointSet> sierpinski(int level, bool unwelded, unsigned threads = 0) {
  SierpinskiParams params;
  params.level = level;
  params.unwelded = unwelded;
  params.threads = threads;
  return generateSierpinski(params);
}

// The seed's algorithm, written independently: recursive midpoints in double, children 0..3 in
// order, 4 rows per tetrahedron.
void seedTetrahedra(const std::array<glm::dvec3, 4>& v, int level, PositionArray& rows) {
  if (level == 0) {
    rows.insert(rows.end(), v.begin(), v.end());
    return;
  }
  for (int k = 0; k < 4; ++k) {
    std::array<glm::dvec3, 4> child;
    for (int j = 0; j < 4; ++j) child[j] = (v[k] + v[j]) / 2.0;
    seedTetrahedra(child, level - 1, rows);
  }
}

TEST(Sierpinski, cornersAreTheSeedsCorners) {
  const glm::dvec3 expected[4] = {{0.0, 0.0, 1.0},
                                  {std::sqrt(8.0 / 9.0), 0.0, -1.0 / 3.0},
                                  {-std::sqrt(2.0 / 9.0), std::sqrt(2.0 / 3.0), -1.0 / 3.0},
                                  {-std::sqrt(2.0 / 9.0), -std::sqrt(2.0 / 3.0), -1.0 / 3.0}};
  Result<PointSet> level0 = sierpinski(0, true);
  ASSERT_TRUE(level0.ok());
  ASSERT_EQ(level0->positions.size(), 4u);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(bitsOf(sierpinskiCorner(k)), bitsOf(expected[k])) << "corner " << k;
    EXPECT_EQ(bitsOf(level0->positions[k]), bitsOf(expected[k])) << "row " << k;
  }
  // The outer corners of a deep level are still exactly the seed's.
  Result<PointSet> level5 = sierpinski(5, true);
  ASSERT_TRUE(level5.ok());
  const uint64_t all_k = (pow4(5) - 1) / 3;  // tetrahedron 11111 (base 4), times k
  for (int k = 0; k < 4; ++k)
    EXPECT_EQ(bitsOf(level5->positions[4 * all_k * k + k]), bitsOf(expected[k])) << "corner " << k;
}

TEST(Sierpinski, unweldedFollowsSeedOrder) {
  for (int level : {1, 3, 5}) {
    PositionArray seed;
    seedTetrahedra({sierpinskiCorner(0), sierpinskiCorner(1), sierpinskiCorner(2), sierpinskiCorner(3)}, level, seed);
    Result<PointSet> ours = sierpinski(level, true);
    ASSERT_TRUE(ours.ok());
    ASSERT_EQ(ours->positions.size(), seed.size());
    // Repeated midpoints round differently from our one-rounding lattice formula, but only in the
    // last bits; distinct corners are at least 2^-5 apart, so the order is pinned.
    for (size_t i = 0; i < seed.size(); ++i)
      ASSERT_LT(glm::length(ours->positions[i] - seed[i]), 1e-15) << "level " << level << " row " << i;
    ASSERT_EQ(ours->triangles.size(), 12 * pow4(level));
    for (size_t i = 0; i < ours->triangles.size(); ++i) ASSERT_EQ(ours->triangles[i] / 4, i / 12);
  }
}

TEST(Sierpinski, weldedCountIs2Times4PowNPlus2) {
  for (int level = 0; level <= 7; ++level) {
    Result<PointSet> welded = sierpinski(level, false);
    ASSERT_TRUE(welded.ok());
    EXPECT_EQ(welded->positions.size(), 2 * pow4(level) + 2) << "level " << level;
    EXPECT_EQ(welded->triangles.size(), 12 * pow4(level));
  }
  // The seed's measured level 9: 1,048,576 rows, 524,290 distinct.
  Result<PointSet> unwelded = sierpinski(9, true);
  Result<PointSet> welded = sierpinski(9, false);
  ASSERT_TRUE(unwelded.ok() && welded.ok());
  EXPECT_EQ(unwelded->positions.size(), 1048576u);
  EXPECT_EQ(welded->positions.size(), 524290u);
}

TEST(Sierpinski, weldedIsUnweldedWithRepeatsDroppedBitForBit) {
  for (int level : {0, 1, 2, 6}) {
    Result<PointSet> unwelded = sierpinski(level, true);
    Result<PointSet> welded = sierpinski(level, false);
    ASSERT_TRUE(unwelded.ok() && welded.ok());
    // First appearances by exact bits: shared corners must come out bit-identical, or there
    // would be more than 2·4^n + 2 of them.
    std::map<std::array<uint64_t, 3>, uint32_t> seen;
    PositionArray distinct;
    for (const glm::dvec3& p : unwelded->positions)
      if (seen.emplace(bitsOf(p), static_cast<uint32_t>(distinct.size())).second) distinct.push_back(p);
    EXPECT_TRUE(sameBits(distinct, welded->positions)) << "level " << level;
    ASSERT_EQ(welded->triangles.size(), unwelded->triangles.size());
    for (size_t i = 0; i < welded->triangles.size(); ++i)
      ASSERT_EQ(welded->triangles[i], seen.at(bitsOf(unwelded->positions[unwelded->triangles[i]])))
          << "level " << level << " entry " << i;
  }
}

TEST(Sierpinski, trianglesFaceOutwardOfTheirTetrahedron) {
  Result<PointSet> mesh = sierpinski(3, true);
  ASSERT_TRUE(mesh.ok());
  const PositionArray& p = mesh->positions;
  for (size_t t = 0; t < pow4(3); ++t) {
    const glm::dvec3 centre = (p[4 * t] + p[4 * t + 1] + p[4 * t + 2] + p[4 * t + 3]) / 4.0;
    for (size_t f = 0; f < 4; ++f) {
      const uint32_t* tri = &mesh->triangles[12 * t + 3 * f];
      const glm::dvec3 normal = glm::cross(p[tri[1]] - p[tri[0]], p[tri[2]] - p[tri[0]]);
      EXPECT_GT(glm::dot(normal, (p[tri[0]] + p[tri[1]] + p[tri[2]]) / 3.0 - centre), 0.0)
          << "tetrahedron " << t << " face " << f;
      // Face f is the one opposite corner f.
      EXPECT_TRUE(tri[0] != 4 * t + f && tri[1] != 4 * t + f && tri[2] != 4 * t + f);
    }
  }
}

TEST(Sierpinski, rejectsLevelOutOfRange) {
  for (int level : {-1, 13}) {
    Result<PointSet> result = sierpinski(level, false);
    ASSERT_FALSE(result.ok());
    EXPECT_EQ(result.error().code, ExitCode::kUsage);
    EXPECT_NE(result.error().message.find("--level " + std::to_string(level)), std::string::npos);
    EXPECT_NE(result.error().message.find("0..12"), std::string::npos) << result.error().message;
  }
}

TEST(Sierpinski, refusesOverMemoryLimit) {
  SierpinskiParams params;
  params.level = 6;
  params.unwelded = true;
  params.max_memory = 100000;  // level 6 unwelded needs 16384·24 + 4096·48 bytes
  Result<PointSet> result = generateSierpinski(params);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error().code, ExitCode::kResourceLimit);
  EXPECT_NE(result.error().message.find("--max-memory"), std::string::npos) << result.error().message;
  params.max_memory = 16384 * 24 + 4096 * 48;
  EXPECT_TRUE(generateSierpinski(params).ok());
}

// ---------------------------------------------------------------------------------------------
// Menger

Result<PointSet> menger(int level, double size = 1.0, unsigned threads = 0) {
  MengerParams params;
  params.level = level;
  params.size = size;
  params.threads = threads;
  return generateMenger(params);
}

// The sponge's membership, written digit by digit.
bool inSponge(int x, int y, int z, int side) {
  if (x < 0 || y < 0 || z < 0 || x >= side || y >= side || z >= side) return false;
  for (; side > 1; side /= 3, x /= 3, y /= 3, z /= 3)
    if ((x % 3 == 1) + (y % 3 == 1) + (z % 3 == 1) >= 2) return false;
  return true;
}

// Lattice coordinates of a vertex: each coordinate must be exactly (k·size)/3^n for some k.
std::array<int, 3> latticeOf(const glm::dvec3& p, int side, double size) {
  std::array<int, 3> k;
  for (int a = 0; a < 3; ++a) {
    k[a] = static_cast<int>(std::lround(p[a] * side / size));
    EXPECT_EQ(p[a], (k[a] * size) / side) << "coordinate " << p[a] << " is off the lattice";
  }
  return k;
}

TEST(Menger, exactFaceCountMatchesFormula) {
  const uint64_t expected[5] = {6, 72, 1056, 18048, 336384};
  for (int level = 0; level <= 4; ++level) {
    EXPECT_EQ(mengerFaceCount(level), expected[level]);
    Result<PointSet> mesh = menger(level);
    ASSERT_TRUE(mesh.ok());
    EXPECT_EQ(mesh->triangles.size(), 6 * expected[level]) << "level " << level;
  }
}

TEST(Menger, exactVertexCountMatchesFormula) {
  const uint64_t expected[6] = {8, 64, 896, 15232, 283520, 5501824};
  for (int level = 0; level <= 5; ++level) {
    EXPECT_EQ(mengerVertexCount(level), expected[level]);
    Result<PointSet> mesh = menger(level);
    ASSERT_TRUE(mesh.ok());
    EXPECT_EQ(mesh->positions.size(), expected[level]) << "level " << level;
  }
}

TEST(Menger, exactFacesAreTheExposedCellFaces) {
  // Brute force at level 2: every (cell, direction) whose neighbour is out of the sponge, against
  // the quads of the mesh identified by their centre and outward normal.
  const int side = 9;
  const int step[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
  std::vector<std::array<int, 4>> expected;  // 2·face centre (integers) and direction
  for (int x = 0; x < side; ++x)
    for (int y = 0; y < side; ++y)
      for (int z = 0; z < side; ++z)
        for (int d = 0; d < 6; ++d)
          if (inSponge(x, y, z, side) && !inSponge(x + step[d][0], y + step[d][1], z + step[d][2], side))
            expected.push_back({2 * x + 1 + step[d][0], 2 * y + 1 + step[d][1], 2 * z + 1 + step[d][2], d});
  ASSERT_EQ(expected.size(), mengerFaceCount(2));
  Result<PointSet> mesh = menger(2, 3.0);
  ASSERT_TRUE(mesh.ok());
  std::vector<std::array<int, 4>> found;
  const std::vector<uint32_t>& tri = mesh->triangles;
  for (size_t q = 0; q < tri.size(); q += 6) {
    // Triangles (c0,c1,c2), (c0,c2,c3) of one unit quad.
    ASSERT_EQ(tri[q], tri[q + 3]);
    ASSERT_EQ(tri[q + 2], tri[q + 4]);
    std::array<int, 3> c[4] = {latticeOf(mesh->positions[tri[q]], side, 3.0),
                               latticeOf(mesh->positions[tri[q + 1]], side, 3.0),
                               latticeOf(mesh->positions[tri[q + 2]], side, 3.0),
                               latticeOf(mesh->positions[tri[q + 5]], side, 3.0)};
    std::array<int, 3> e1, e2, normal;
    for (int a = 0; a < 3; ++a) e1[a] = c[1][a] - c[0][a], e2[a] = c[3][a] - c[0][a];
    normal = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    int d = -1;
    for (int k = 0; k < 6; ++k)
      if (normal[0] == step[k][0] && normal[1] == step[k][1] && normal[2] == step[k][2]) d = k;
    ASSERT_NE(d, -1) << "quad " << q / 6 << " is not a unit square";
    found.push_back({c[0][0] + c[2][0], c[0][1] + c[2][1], c[0][2] + c[2][2], d});
  }
  std::sort(expected.begin(), expected.end());
  std::sort(found.begin(), found.end());
  EXPECT_EQ(found, expected);
}

TEST(Menger, exactIsWatertightAndOriented) {
  // A closed, consistently oriented 2-manifold: every directed edge once, and its reverse once.
  // (An edge where the surface touched itself would carry 4 faces and show up twice.)
  for (int level = 0; level <= 4; ++level) {
    Result<PointSet> mesh = menger(level);
    ASSERT_TRUE(mesh.ok());
    std::vector<uint64_t> edges;
    const std::vector<uint32_t>& tri = mesh->triangles;
    for (size_t t = 0; t < tri.size(); t += 3)
      for (size_t c = 0; c < 3; ++c) edges.push_back(uint64_t{tri[t + c]} << 32 | tri[t + (c + 1) % 3]);
    std::sort(edges.begin(), edges.end());
    EXPECT_EQ(std::adjacent_find(edges.begin(), edges.end()), edges.end()) << "level " << level << ": repeated edge";
    for (uint64_t e : edges)
      ASSERT_TRUE(std::binary_search(edges.begin(), edges.end(), (e << 32) | (e >> 32)))
          << "level " << level << ": edge " << (e >> 32) << "->" << (e & 0xffffffffu) << " has no reverse";
  }
}

TEST(Menger, exactEnclosesTheSpongeVolumeFacingOut) {
  // Signed volume Σ det(a, b, c)/6 is +size³·(20/27)^n only if every face points outward.
  const double size = 2.5;
  for (int level = 0; level <= 3; ++level) {
    Result<PointSet> mesh = menger(level, size);
    ASSERT_TRUE(mesh.ok());
    double volume = 0.0;
    const std::vector<uint32_t>& tri = mesh->triangles;
    for (size_t t = 0; t < tri.size(); t += 3) {
      const glm::dvec3 &a = mesh->positions[tri[t]], &b = mesh->positions[tri[t + 1]], &c = mesh->positions[tri[t + 2]];
      volume += glm::dot(a, glm::cross(b, c)) / 6.0;
    }
    EXPECT_NEAR(volume, size * size * size * std::pow(20.0 / 27.0, level), 1e-12) << "level " << level;
  }
}

TEST(Menger, exactVerticesAreDistinctLatticePointsInOrder) {
  const double size = 0.7;  // not a power of two: coordinates round
  Result<PointSet> mesh = menger(3, size);
  ASSERT_TRUE(mesh.ok());
  std::vector<std::array<int, 3>> lattice;
  for (const glm::dvec3& p : mesh->positions) lattice.push_back(latticeOf(p, 27, size));
  EXPECT_TRUE(std::is_sorted(lattice.begin(), lattice.end()));
  EXPECT_EQ(std::adjacent_find(lattice.begin(), lattice.end()), lattice.end());
  EXPECT_EQ(mesh->positions.front(), glm::dvec3(0.0));
  EXPECT_EQ(mesh->positions.back(), glm::dvec3((27 * size) / 27));
}

TEST(Menger, rejectsLevelOrSizeOutOfRange) {
  for (int level : {-1, 9}) {
    Result<PointSet> result = menger(level);
    ASSERT_FALSE(result.ok());
    EXPECT_EQ(result.error().code, ExitCode::kUsage);
    EXPECT_NE(result.error().message.find("--level " + std::to_string(level)), std::string::npos);
    EXPECT_NE(result.error().message.find("0..8"), std::string::npos) << result.error().message;
  }
  for (double size : {0.0, -1.0, std::nan(""), HUGE_VAL}) {
    Result<PointSet> result = menger(1, size);
    ASSERT_FALSE(result.ok());
    EXPECT_EQ(result.error().code, ExitCode::kUsage);
    EXPECT_NE(result.error().message.find("--size"), std::string::npos) << result.error().message;
  }
}

TEST(Menger, refusesOverMemoryLimit) {
  // Level 8 (2.56e10 cubes) needs over a terabyte: refused before anything is allocated.
  Result<PointSet> huge = menger(8);
  ASSERT_FALSE(huge.ok());
  EXPECT_EQ(huge.error().code, ExitCode::kResourceLimit);
  EXPECT_NE(huge.error().message.find("--max-memory"), std::string::npos) << huge.error().message;
  MengerParams params;
  params.level = 3;
  params.max_memory = 15232 * 24 + 18048 * 24 - 1;  // one byte short of the vertices and triangles
  Result<PointSet> small = generateMenger(params);
  ASSERT_FALSE(small.ok());
  EXPECT_EQ(small.error().code, ExitCode::kResourceLimit);
  params.max_memory += 1;
  EXPECT_TRUE(generateMenger(params).ok());
}

// ---------------------------------------------------------------------------------------------

TEST(Geometry, generatorsIdenticalForAnyThreadCount) {
  Result<PointSet> sierpinski_welded = sierpinski(6, false, 1);
  Result<PointSet> sierpinski_unwelded = sierpinski(6, true, 1);
  Result<PointSet> sponge = menger(3, 1.0, 1);
  ASSERT_TRUE(sierpinski_welded.ok() && sierpinski_unwelded.ok() && sponge.ok());
  PointSet coloured = *sponge;
  colorByNoise(coloured, 1);
  for (unsigned threads : {2u, 3u, 7u}) {
    Progress silent;
    SierpinskiParams sp;
    sp.level = 6;
    sp.threads = threads;
    sp.progress = &silent;
    Result<PointSet> welded = generateSierpinski(sp);
    sp.unwelded = true;
    Result<PointSet> unwelded = generateSierpinski(sp);
    MengerParams mp;
    mp.level = 3;
    mp.threads = threads;
    mp.progress = &silent;
    Result<PointSet> other_sponge = generateMenger(mp);
    ASSERT_TRUE(welded.ok() && unwelded.ok() && other_sponge.ok());
    EXPECT_TRUE(sameBits(welded->positions, sierpinski_welded->positions)) << threads << " threads";
    EXPECT_EQ(welded->triangles, sierpinski_welded->triangles) << threads << " threads";
    EXPECT_TRUE(sameBits(unwelded->positions, sierpinski_unwelded->positions)) << threads << " threads";
    EXPECT_EQ(unwelded->triangles, sierpinski_unwelded->triangles) << threads << " threads";
    EXPECT_TRUE(sameBits(other_sponge->positions, sponge->positions)) << threads << " threads";
    EXPECT_EQ(other_sponge->triangles, sponge->triangles) << threads << " threads";
    colorByNoise(*other_sponge, threads);
    EXPECT_EQ(other_sponge->colors, coloured.colors) << threads << " threads";
  }
}

}  // namespace
}  // namespace dpoint

namespace dpoint {
namespace {

double enclosedVolume(const PointSet& mesh) {
  double volume = 0.0;
  for (size_t t = 0; t < mesh.triangles.size(); t += 3) {
    const glm::dvec3& a = mesh.positions[mesh.triangles[t]];
    const glm::dvec3& b = mesh.positions[mesh.triangles[t + 1]];
    const glm::dvec3& c = mesh.positions[mesh.triangles[t + 2]];
    volume += glm::dot(a, glm::cross(b, c)) / 6.0;
  }
  return volume;
}

TEST(Menger, voxelMethodEnclosesAboutTheSpongeVolume) {
  MengerParams params;
  params.level = 2;
  params.method = MengerMethod::kVoxel;
  params.resolution = 81;  // 9 samples per lattice cell
  Result<PointSet> mesh = generateMenger(params);
  ASSERT_TRUE(mesh.ok()) << mesh.error().message;
  for (const glm::dvec3& p : mesh->positions) {
    ASSERT_GE(std::min({p.x, p.y, p.z}), 0.0);
    ASSERT_LE(std::max({p.x, p.y, p.z}), 1.0);
  }
  // Marching cubes cuts the voxel corners, so the volume is a little below (20/27)^2 = 0.5487;
  // the sign says the triangles face outward.
  const double volume = enclosedVolume(*mesh);
  EXPECT_GT(volume, 0.5487 * 0.95);
  EXPECT_LT(volume, 0.5487 * 1.001);
  params.threads = 1;
  Result<PointSet> one = generateMenger(params);
  ASSERT_TRUE(one.ok());
  EXPECT_TRUE(one->positions == mesh->positions && one->triangles == mesh->triangles);
}

TEST(Menger, voxelMethodRejectsResolutionOutOfRange) {
  MengerParams params;
  params.method = MengerMethod::kVoxel;
  params.resolution = 1;
  Result<PointSet> r = generateMenger(params);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ExitCode::kUsage);
  EXPECT_NE(r.error().message.find("--resolution"), std::string::npos) << r.error().message;
}

}  // namespace
}  // namespace dpoint
