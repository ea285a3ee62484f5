// COPC (converters/copc.h): LAS 1.4 files of the corpus and synthetic sets written as COPC read back
// as plain LAZ to the same records (in another order), every node's points inside its cube, counts
// that add up, the info VLR at byte 375, levels that preview the whole, selective reads that read
// few nodes, and corrupt hierarchies refused by name. copc.js's verdict on the same files is
// tests/external/copc_reads_dpoint_copc.py.
#include "converters/copc.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "converters/laz_decode.h"
#include "las_bytes.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::at;
using test::lasRecords;
using test::put;
using test::readFile;

std::vector<std::string> sorted(const std::string& records, size_t length) {
  std::vector<std::string> out;
  for (size_t i = 0; i + length <= records.size(); i += length) out.push_back(records.substr(i, length));
  std::sort(out.begin(), out.end());
  return out;
}

// A LAS 1.4 file of format-6 records (scale 0.001, offset `origin`), with these VLRs and EVLRs.
std::string las14(const std::string& records, const double origin[3], const std::vector<std::string>& vlrs = {},
                  const std::vector<std::string>& evlrs = {}) {
  std::string h(375, '\0');
  std::memcpy(h.data(), "LASF", 4);
  h[24] = 1;
  h[25] = 4;
  put<uint16_t>(h, 94, 375);
  size_t vlr_bytes = 0;
  for (const std::string& v : vlrs) vlr_bytes += v.size();
  put<uint32_t>(h, 96, static_cast<uint32_t>(375 + vlr_bytes));
  put<uint32_t>(h, 100, static_cast<uint32_t>(vlrs.size()));
  h[104] = 6;
  put<uint16_t>(h, 105, 30);
  for (size_t a = 0; a < 3; ++a) {
    put<double>(h, 131 + 8 * a, 0.001);
    put<double>(h, 155 + 8 * a, origin[a]);
  }
  put<uint64_t>(h, 235, evlrs.empty() ? 0 : 375 + vlr_bytes + records.size());
  put<uint32_t>(h, 243, static_cast<uint32_t>(evlrs.size()));
  put<uint64_t>(h, 247, records.size() / 30);
  std::string out = h;
  for (const std::string& v : vlrs) out += v;
  out += records;
  for (const std::string& e : evlrs) out += e;
  return out;
}

std::string vlr(const char* user, uint16_t record, const std::string& data, size_t header = 54) {
  std::string v(header, '\0');
  std::memcpy(v.data() + 2, user, std::strlen(user));
  put<uint16_t>(v, 18, record);
  if (header == 54) put<uint16_t>(v, 20, static_cast<uint16_t>(data.size()));
  else put<uint64_t>(v, 20, data.size());
  return v + data;
}

// Format-6 records of a terrain-like surface over `extent` × `extent` metres (z a few metres of
// hills), coordinates in millimetres, with returns, classes, intensities and GPS times.
std::string surfaceRecords(uint32_t count, uint32_t seed, double extent) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::string out(size_t{count} * 30, '\0');
  for (uint32_t i = 0; i < count; ++i) {
    char* r = out.data() + size_t{i} * 30;
    const double x = u(rng) * extent, y = u(rng) * extent;
    const double z = 5 * std::sin(x / 40) * std::cos(y / 55) + u(rng) * 0.2;
    const int32_t xyz[3] = {static_cast<int32_t>(std::lround(x * 1000)), static_cast<int32_t>(std::lround(y * 1000)),
                            static_cast<int32_t>(std::lround(z * 1000))};
    std::memcpy(r, xyz, 12);
    const uint16_t intensity = static_cast<uint16_t>(rng() % 4096);
    std::memcpy(r + 12, &intensity, 2);
    const uint8_t returns = static_cast<uint8_t>(1 + rng() % 3);
    r[14] = static_cast<char>(std::min<uint8_t>(returns, static_cast<uint8_t>(1 + rng() % 3)) | (returns << 4));
    r[16] = static_cast<char>(rng() % 4 == 0 ? 6 : 2);
    const double t = 300000.0 + i * 1e-5;
    std::memcpy(r + 22, &t, 8);
  }
  return out;
}

const double kOrigin[3] = {500000, 4000000, 0};

std::vector<CopcNode> allNodes(const InputFile& file) {
  Result<CopcHeader> header = readCopcHeader(file);
  EXPECT_TRUE(header.ok()) << header.error().message;
  if (!header) return {};
  Result<std::vector<CopcNode>> nodes = readCopcNodes(file, *header, CopcQuery{});
  EXPECT_TRUE(nodes.ok()) << nodes.error().message;
  return nodes ? *nodes : std::vector<CopcNode>{};
}

// One node's records, decoded from the file's bytes here (not through readCopcRecords).
std::string nodeRecords(const std::string& copc, const CopcHeader& header, const CopcNode& node) {
  std::string records(static_cast<size_t>(node.points) * header.record_length, '\0');
  Status s = decodeLazChunk(header.laz, copc.data() + node.offset, static_cast<size_t>(node.bytes),
                            static_cast<uint64_t>(node.points), records.data());
  EXPECT_TRUE(s.ok()) << copcKeyName(node.key) << ": " << s.error().message;
  return records;
}

// Checks the structure the external walk checks too: every point inside its node's cube (within
// half a scale step), every node's parent present, the counts adding up. Returns the nodes.
std::vector<CopcNode> checkStructure(const std::string& copc) {
  const InputFile file = InputFile::fromMemory("check.copc.laz", copc);
  Result<CopcHeader> header = readCopcHeader(file);
  EXPECT_TRUE(header.ok()) << header.error().message;
  if (!header) return {};
  const std::vector<CopcNode> nodes = allNodes(file);
  std::map<CopcKey, int32_t> points;
  for (const CopcNode& n : nodes) points[n.key] = n.points;
  uint64_t total = 0;
  for (const CopcNode& n : nodes) {
    total += static_cast<uint64_t>(n.points);
    if (n.key.level > 0) {
      EXPECT_TRUE(points.count({n.key.level - 1, n.key.x / 2, n.key.y / 2, n.key.z / 2}))
          << copcKeyName(n.key) << " has no parent";
    }
    if (n.points == 0) continue;
    const std::string records = nodeRecords(copc, *header, n);
    const CopcBox cube = copcNodeCube(header->info, n.key);
    for (int32_t i = 0; i < n.points; ++i) {
      for (size_t a = 0; a < 3; ++a) {
        const double v = at<int32_t>(records, size_t(i) * header->record_length + 4 * a) * header->scale[a] +
                         header->offset[a];
        const double slack = std::abs(header->scale[a]) / 2;
        if (v < cube.min[a] - slack || v > cube.max[a] + slack) {
          ADD_FAILURE() << "node " << copcKeyName(n.key) << " point " << i << " axis " << a << ": " << v
                        << " outside [" << cube.min[a] << ", " << cube.max[a] << "]";
          return nodes;
        }
      }
    }
  }
  EXPECT_EQ(total, header->point_count);
  return nodes;
}

// Writes COPC files for the external walk (tests/external/copc_reads_dpoint_copc.py) when
// DPOINT_COPC_OUT names a folder.
void keepForExternalWalk(const std::string& name, const std::string& copc) {
  if (const char* dir = std::getenv("DPOINT_COPC_OUT")) test::writeFile(std::string(dir) + "/" + name, copc);
}

// --- Writing ---------------------------------------------------------------------------------------

TEST(CopcWrite, corpusFilesReadBackAsPlainLazToTheSameRecords) {
  struct Source {
    const char* path;
    int format;
  };
  const Source sources[] = {{"las/simple1_4.las", 7}, {"laz/rand1_6.las", 6}, {"las/1_4_w_evlr.las", 6},
                            {"las/test1_4.las", 6}};
  for (const Source& s : sources) {
    SCOPED_TRACE(s.path);
    const std::string las = readFile(std::string(DPOINT_CORPUS_DIR) + "/" + s.path);
    ASSERT_EQ(las[25], 4);  // LAS 1.4
    ASSERT_EQ(las[104], s.format);
    CopcWriteOptions options;
    options.max_points_per_node = 5000;  // several levels even for these small files
    Result<std::string> copc = copcFromLasBytes(las, options);
    ASSERT_TRUE(copc.ok()) << copc.error().message;
    const InputFile file = InputFile::fromMemory(s.path, *copc);
    EXPECT_TRUE(isCopc(file));
    // The info VLR first, at byte 375; the header says LAZ of the same format.
    EXPECT_EQ(copc->substr(377, 5), std::string("copc\0", 5));
    EXPECT_EQ(at<uint16_t>(*copc, 393), 1);
    EXPECT_EQ(at<uint16_t>(*copc, 395), 160);
    EXPECT_EQ(static_cast<uint8_t>((*copc)[104]), 0x80 | s.format);
    EXPECT_EQ(at<uint64_t>(*copc, 247), at<uint64_t>(las, 247));
    Result<std::string> records = decodeLaz(file, 2);
    ASSERT_TRUE(records.ok()) << records.error().message;
    const std::string meant = lasRecords(las);
    EXPECT_EQ(records->size(), meant.size());
    EXPECT_TRUE(sorted(*records, at<uint16_t>(las, 105)) == sorted(meant, at<uint16_t>(las, 105)));
    const std::vector<CopcNode> nodes = checkStructure(*copc);
    if (at<uint64_t>(las, 247) > 5000) {
      EXPECT_GT(nodes.size(), 1u) << "the cap of 5000 points splits the octree";
    }
    keepForExternalWalk(std::string(std::strrchr(s.path, '/') + 1, std::strchr(std::strrchr(s.path, '/'), '.')) +
                            ".copc.laz",
                        *copc);
  }
}

TEST(CopcWrite, keepsVlrsAndEvlrsWithTheInfoVlrFirstAndTheHierarchyFirstAmongEvlrs) {
  const std::string wkt = "GEOGCS[\"WGS 84\"]";
  const std::string records = surfaceRecords(1000, 3, 50);
  const std::string las = las14(records, kOrigin, {vlr("LASF_Projection", 2112, wkt + '\0'), vlr("dpoint", 7, "abc")},
                                {vlr("dpoint", 8, std::string(100, 'e'), 60)});
  Result<std::string> copc = copcFromLasBytes(las);
  ASSERT_TRUE(copc.ok()) << copc.error().message;
  EXPECT_EQ(at<uint32_t>(*copc, 100), 4u);  // info, WKT, dpoint/7, laszip
  EXPECT_EQ(copc->substr(375 + 54 + 160 + 2, 15), "LASF_Projection");
  EXPECT_NE(copc->find(wkt), std::string::npos);
  EXPECT_EQ(at<uint16_t>(*copc, 6) & 0x10, 0x10);  // WKT bit
  EXPECT_EQ(at<uint32_t>(*copc, 243), 2u);
  const uint64_t evlr = at<uint64_t>(*copc, 235);
  EXPECT_EQ(copc->substr(evlr + 2, 4), "copc");
  EXPECT_EQ(at<uint16_t>(*copc, evlr + 18), 1000);
  const uint64_t second = evlr + 60 + at<uint64_t>(*copc, evlr + 20);
  EXPECT_EQ(copc->substr(second + 2, 6), "dpoint");
  EXPECT_EQ(copc->substr(second + 60), std::string(100, 'e'));
  // The root page starts right after the hierarchy EVLR's header.
  EXPECT_EQ(at<uint64_t>(*copc, 375 + 54 + 40), evlr + 60);
}

TEST(CopcWrite, headerCarriesBoundsCountsByReturnAndGpsRange) {
  const std::string records = surfaceRecords(20000, 5, 200);
  Result<std::string> copc = copcFromLasBytes(las14(records, kOrigin));
  ASSERT_TRUE(copc.ok()) << copc.error().message;
  int32_t lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, hi[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
  uint64_t by_return[15] = {};
  for (size_t i = 0; i < records.size(); i += 30) {
    for (size_t a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], at<int32_t>(records, i + 4 * a));
      hi[a] = std::max(hi[a], at<int32_t>(records, i + 4 * a));
    }
    ++by_return[(records[i + 14] & 0x0F) - 1];
  }
  for (size_t a = 0; a < 3; ++a) {
    EXPECT_DOUBLE_EQ(at<double>(*copc, 179 + 16 * a), hi[a] * 0.001 + kOrigin[a]);
    EXPECT_DOUBLE_EQ(at<double>(*copc, 187 + 16 * a), lo[a] * 0.001 + kOrigin[a]);
  }
  for (size_t r = 0; r < 15; ++r) EXPECT_EQ(at<uint64_t>(*copc, 255 + 8 * r), by_return[r]) << "return " << r + 1;
  EXPECT_EQ(at<uint32_t>(*copc, 107), 0u);  // legacy count: 0 for formats 6-10
  const size_t info = 375 + 54;
  EXPECT_DOUBLE_EQ(at<double>(*copc, info + 56), 300000.0);
  EXPECT_DOUBLE_EQ(at<double>(*copc, info + 64), 300000.0 + 19999 * 1e-5);
  // The cube: the largest extent (x here), from the bounds' minimum corner; the root spacing 1/128
  // of its edge.
  const double halfsize = at<double>(*copc, info + 24);
  EXPECT_NEAR(halfsize, (hi[0] - lo[0]) * 0.001 / 2, 1e-9);
  for (size_t a = 0; a < 3; ++a) EXPECT_NEAR(at<double>(*copc, info + 8 * a) - halfsize, lo[a] * 0.001 + kOrigin[a], 1e-9);
  EXPECT_DOUBLE_EQ(at<double>(*copc, info + 32), 2 * halfsize / 128);
  for (size_t r = 0; r < 11; ++r) EXPECT_EQ(at<uint64_t>(*copc, info + 72 + 8 * r), 0u);
}

TEST(CopcWrite, everyPointLiesInItsNodesCubeAndNodesKeepTheCap) {
  const std::string records = surfaceRecords(300000, 7, 1000);
  CopcWriteOptions options;
  options.max_points_per_node = 4000;
  Result<std::string> copc = copcFromLasBytes(las14(records, kOrigin), options);
  ASSERT_TRUE(copc.ok()) << copc.error().message;
  const std::vector<CopcNode> nodes = checkStructure(*copc);
  int deepest = 0;
  for (const CopcNode& n : nodes) {
    EXPECT_LE(n.points, 4000) << copcKeyName(n.key);
    EXPECT_GT(n.points, 0) << copcKeyName(n.key);
    deepest = std::max(deepest, n.key.level);
  }
  EXPECT_GE(deepest, 3);
  const InputFile file = InputFile::fromMemory("surface.copc.laz", *copc);
  Result<std::string> back = decodeLaz(file, 2);
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_TRUE(sorted(*back, 30) == sorted(records, 30));
  keepForExternalWalk("surface-300000.copc.laz", *copc);
}

TEST(CopcWrite, eachLevelIsAFairPreviewOnePointPerGridCell) {
  const std::string records = surfaceRecords(200000, 9, 1000);
  CopcWriteOptions options;
  options.max_points_per_node = 3000;
  Result<std::string> copc = copcFromLasBytes(las14(records, kOrigin), options);
  ASSERT_TRUE(copc.ok()) << copc.error().message;
  const InputFile file = InputFile::fromMemory("fair.copc.laz", *copc);
  Result<CopcHeader> header = readCopcHeader(file);
  ASSERT_TRUE(header.ok()) << header.error().message;
  const CopcInfo& info = header->info;
  for (const CopcNode& n : allNodes(file)) {
    if (n.key.level > 1) continue;
    SCOPED_TRACE(copcKeyName(n.key));
    const std::string pts = nodeRecords(*copc, *header, n);
    // At most one point per cell of the node's 128-cell grid.
    const double cell = info.spacing / std::ldexp(1.0, n.key.level);
    const CopcBox cube = copcNodeCube(info, n.key);
    std::map<std::array<int64_t, 3>, int> cells;
    // And spread evenly: over 4 × 4 columns of the node, none far from the mean.
    std::array<int, 16> columns{};
    for (int32_t i = 0; i < n.points; ++i) {
      std::array<int64_t, 3> c;
      double v[3];
      for (size_t a = 0; a < 3; ++a) {
        v[a] = at<int32_t>(pts, size_t(i) * 30 + 4 * a) * 0.001 + kOrigin[a];
        c[a] = static_cast<int64_t>(std::floor((v[a] - cube.min[a]) / cell));
      }
      ++cells[c];
      const double edge = cube.max[0] - cube.min[0];
      const int cx = std::min(3, static_cast<int>((v[0] - cube.min[0]) / edge * 4));
      const int cy = std::min(3, static_cast<int>((v[1] - cube.min[1]) / edge * 4));
      ++columns[size_t(cx + 4 * cy)];
    }
    for (const auto& [c, k] : cells) EXPECT_LE(k, 1) << "cell " << c[0] << "," << c[1] << "," << c[2];
    if (n.key.level == 0) {
      EXPECT_EQ(n.points, 3000);  // 200,000 points fill more than 3,000 of the root's cells
      for (int k : columns) {
        EXPECT_GT(k, 3000 / 16 * 0.7);
        EXPECT_LT(k, 3000 / 16 * 1.3);
      }
    }
  }
}

TEST(CopcWrite, outputDoesNotDependOnThreadCount) {
  const std::string las = las14(surfaceRecords(120000, 11, 300), kOrigin);
  CopcWriteOptions options;
  options.max_points_per_node = 2000;
  options.threads = 1;
  Result<std::string> one = copcFromLasBytes(las, options);
  options.threads = 3;
  Result<std::string> three = copcFromLasBytes(las, options);
  ASSERT_TRUE(one.ok() && three.ok());
  EXPECT_TRUE(*one == *three);
  options.seed = 2;  // another pick per cell: another file
  Result<std::string> other = copcFromLasBytes(las, options);
  ASSERT_TRUE(other.ok());
  EXPECT_FALSE(*other == *one);
}

TEST(CopcWrite, deepHierarchiesGetChildPagesReadLazily) {
  const std::string las = las14(surfaceRecords(100000, 13, 500), kOrigin);
  CopcWriteOptions options;
  options.max_points_per_node = 500;
  options.page_levels = 0;
  Result<std::string> single = copcFromLasBytes(las, options);
  options.page_levels = 2;
  options.page_min_nodes = 4;
  Result<std::string> paged = copcFromLasBytes(las, options);
  ASSERT_TRUE(single.ok() && paged.ok());
  // The same nodes, in more than one page: the root page lists references (count -1).
  const InputFile single_file = InputFile::fromMemory("single.copc.laz", *single);
  const InputFile paged_file = InputFile::fromMemory("paged.copc.laz", *paged);
  const std::vector<CopcNode> a = allNodes(single_file), b = allNodes(paged_file);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].key, b[i].key);
    EXPECT_EQ(a[i].points, b[i].points);
  }
  const uint64_t root = at<uint64_t>(*paged, 375 + 54 + 40), root_size = at<uint64_t>(*paged, 375 + 54 + 48);
  int references = 0;
  for (uint64_t e = root; e < root + root_size; e += 32) references += at<int32_t>(*paged, e + 28) == -1;
  EXPECT_GT(references, 0);
  EXPECT_LT(root_size, at<uint64_t>(*single, 375 + 54 + 48));
  checkStructure(*paged);
  keepForExternalWalk("paged.copc.laz", *paged);
  // A query of the root level reads the root page only.
  Result<CopcHeader> header = readCopcHeader(paged_file);
  ASSERT_TRUE(header.ok());
  CopcQuery shallow;
  shallow.resolution = header->info.spacing;
  uint64_t page_bytes = 0;
  Result<std::vector<CopcNode>> root_only = readCopcNodes(paged_file, *header, shallow, &page_bytes);
  ASSERT_TRUE(root_only.ok()) << root_only.error().message;
  EXPECT_EQ(root_only->size(), 1u);
  EXPECT_EQ(page_bytes, root_size);
}

TEST(CopcWrite, emptyOnePointAndDuplicatePointSets) {
  for (uint32_t count : {0u, 1u}) {
    SCOPED_TRACE(std::to_string(count) + " points");
    Result<std::string> copc = copcFromLasBytes(las14(surfaceRecords(count, 1, 10), kOrigin));
    ASSERT_TRUE(copc.ok()) << copc.error().message;
    const InputFile file = InputFile::fromMemory("small.copc.laz", *copc);
    const std::vector<CopcNode> nodes = checkStructure(*copc);
    ASSERT_EQ(nodes.size(), 1u);
    EXPECT_EQ(nodes[0].points, static_cast<int32_t>(count));
    CopcNodeRead stats;
    Result<std::string> records = readCopcRecords(file, CopcQuery{}, &stats);
    ASSERT_TRUE(records.ok()) << records.error().message;
    EXPECT_EQ(records->size(), count * 30u);
    EXPECT_EQ(stats.points, count);
    Result<std::string> plain = decodeLaz(file);
    ASSERT_TRUE(plain.ok()) << plain.error().message;
    EXPECT_EQ(plain->size(), count * 30u);
    keepForExternalWalk("points-" + std::to_string(count) + ".copc.laz", *copc);
  }
  // 5,000 copies of one point and 5,000 of another, 100 to a node: they part once, then stay.
  std::string one = surfaceRecords(1, 1, 10), two = surfaceRecords(1, 2, 10), records;
  for (int i = 0; i < 5000; ++i) records += one + two;
  CopcWriteOptions options;
  options.max_points_per_node = 100;
  Result<std::string> copc = copcFromLasBytes(las14(records, kOrigin), options);
  ASSERT_TRUE(copc.ok()) << copc.error().message;
  const std::vector<CopcNode> nodes = checkStructure(*copc);
  EXPECT_LE(nodes.size(), 40u);
}

TEST(CopcWrite, refusesOtherFormatsVersionsAndCompressedInput) {
  const std::string las12 = readFile(std::string(DPOINT_CORPUS_DIR) + "/laz/point-color-time.las");
  Result<std::string> old = copcFromLasBytes(las12);
  ASSERT_FALSE(old.ok());
  EXPECT_TRUE(test::contains(old.error().message, "LAS 1.4"));
  std::string f3 = las14(surfaceRecords(10, 1, 10), kOrigin);
  f3[104] = 3;
  Result<std::string> format3 = copcFromLasBytes(f3);
  ASSERT_FALSE(format3.ok());
  EXPECT_TRUE(test::contains(format3.error().message, "point formats 6 to 8 only, not 3"));
  std::string compressed = las14(surfaceRecords(10, 1, 10), kOrigin);
  compressed[104] = static_cast<char>(0x86);
  EXPECT_TRUE(test::contains(copcFromLasBytes(compressed).error().message, "compressed already"));
  std::string short_records = las14(surfaceRecords(10, 1, 10), kOrigin);
  short_records.resize(short_records.size() - 1);
  EXPECT_TRUE(test::contains(copcFromLasBytes(short_records).error().message, "run past the file's end"));
  std::string short_length = las14(surfaceRecords(10, 1, 10), kOrigin);
  put<uint16_t>(short_length, 105, 22);
  EXPECT_TRUE(test::contains(copcFromLasBytes(short_length).error().message,
                             "point record length 22 is shorter than point format 6's 30 bytes"));
  std::string zero_scale = las14(surfaceRecords(10, 1, 10), kOrigin);
  put<double>(zero_scale, 139, 0.0);
  EXPECT_TRUE(test::contains(copcFromLasBytes(zero_scale).error().message, "axis Y is 0 or not finite"));
  CopcWriteOptions no_cap;
  no_cap.max_points_per_node = 0;
  EXPECT_TRUE(test::contains(copcFromLasBytes(f3, no_cap).error().message, "max points per node 0"));
}

// --- Reading ---------------------------------------------------------------------------------------

// A 1.5M-point survey-like set with at most 10,000 points a node: the octree's shape (5 levels,
// leaves of a few thousand points) that a 16.7M-point set has with the default 100,000.
const std::string& bigSet() {
  static const std::string copc = [] {
    CopcWriteOptions options;
    options.max_points_per_node = 10000;
    Result<std::string> c = copcFromLasBytes(las14(surfaceRecords(1500000, 17, 2000), kOrigin), options);
    EXPECT_TRUE(c.ok()) << c.error().message;
    if (c) keepForExternalWalk("surface-1500000.copc.laz", *c);
    return c ? *c : std::string();
  }();
  return copc;
}

TEST(CopcRead, aSmallBoxReadsFewNodesAndExactlyTheirRecords) {
  const std::string& copc = bigSet();
  ASSERT_FALSE(copc.empty());
  const InputFile file = InputFile::fromMemory("big.copc.laz", copc);
  Result<CopcHeader> header = readCopcHeader(file);
  ASSERT_TRUE(header.ok()) << header.error().message;
  // 1% of the area: a 200 m × 200 m square of the 2 km × 2 km set, all heights.
  CopcQuery query;
  query.box.min[0] = kOrigin[0] + 1310, query.box.max[0] = kOrigin[0] + 1510;
  query.box.min[1] = kOrigin[1] + 330, query.box.max[1] = kOrigin[1] + 530;
  CopcNodeRead stats;
  Result<std::string> records = readCopcRecords(file, query, &stats);
  ASSERT_TRUE(records.ok()) << records.error().message;
  const std::vector<CopcNode> all = allNodes(file);
  std::printf("[ info ] 1%% box of 1.5M points: %llu of %zu nodes, %llu points, %llu of %zu bytes (%.1f%%)\n",
              static_cast<unsigned long long>(stats.nodes), all.size(), static_cast<unsigned long long>(stats.points),
              static_cast<unsigned long long>(stats.bytes), copc.size(), 100.0 * static_cast<double>(stats.bytes) / static_cast<double>(copc.size()));
  EXPECT_LT(stats.nodes, all.size() / 4);
  EXPECT_LT(stats.bytes, copc.size() / 10);
  EXPECT_EQ(records->size(), stats.points * 30);
  // Exactly the selected nodes' records, node after node in key order.
  Result<std::vector<CopcNode>> selected = readCopcNodes(file, *header, query);
  ASSERT_TRUE(selected.ok());
  std::string expected;
  uint64_t nodes = 0;
  for (const CopcNode& n : *selected) {
    if (n.points == 0) continue;
    expected += nodeRecords(copc, *header, n);
    ++nodes;
    const CopcBox cube = copcNodeCube(header->info, n.key);
    EXPECT_TRUE(cube.min[0] <= query.box.max[0] && cube.max[0] >= query.box.min[0]) << copcKeyName(n.key);
  }
  EXPECT_EQ(nodes, stats.nodes);
  EXPECT_TRUE(*records == expected);
  // Every point of the input inside the box is among them.
  const std::vector<std::string> got = sorted(*records, 30);
  Result<std::string> whole = decodeLaz(file, 2);
  ASSERT_TRUE(whole.ok());
  size_t inside = 0;
  for (size_t i = 0; i < whole->size(); i += 30) {
    const double x = at<int32_t>(*whole, i) * 0.001 + kOrigin[0], y = at<int32_t>(*whole, i + 4) * 0.001 + kOrigin[1];
    if (x < query.box.min[0] || x > query.box.max[0] || y < query.box.min[1] || y > query.box.max[1]) continue;
    ++inside;
    ASSERT_TRUE(std::binary_search(got.begin(), got.end(), whole->substr(i, 30))) << "record " << i / 30;
  }
  EXPECT_GT(inside, 10000u);
  for (unsigned threads : {1u, 3u}) {
    query.threads = threads;
    Result<std::string> again = readCopcRecords(file, query);
    ASSERT_TRUE(again.ok());
    EXPECT_TRUE(*again == *records);
  }
}

TEST(CopcRead, aResolutionStopsAtShallowLevels) {
  const std::string& copc = bigSet();
  ASSERT_FALSE(copc.empty());
  const InputFile file = InputFile::fromMemory("big.copc.laz", copc);
  Result<CopcHeader> header = readCopcHeader(file);
  ASSERT_TRUE(header.ok());
  const double spacing = header->info.spacing;
  int deepest = 0;
  for (const CopcNode& n : allNodes(file)) deepest = std::max(deepest, n.key.level);
  ASSERT_GE(deepest, 3);
  uint64_t previous = 0;
  for (int level = 0; level < deepest; ++level) {
    SCOPED_TRACE("level " + std::to_string(level));
    CopcQuery query;
    query.resolution = spacing / std::ldexp(1.0, level);
    Result<std::vector<CopcNode>> nodes = readCopcNodes(file, *header, query);
    ASSERT_TRUE(nodes.ok());
    for (const CopcNode& n : *nodes) EXPECT_LE(n.key.level, level);
    CopcNodeRead stats;
    Result<std::string> records = readCopcRecords(file, query, &stats);
    ASSERT_TRUE(records.ok());
    EXPECT_GT(stats.points, previous);
    EXPECT_LT(stats.points, header->point_count);
    previous = stats.points;
  }
  // A resolution coarser than the root's spacing reads the root alone.
  CopcQuery coarse;
  coarse.resolution = spacing * 10;
  CopcNodeRead stats;
  ASSERT_TRUE(readCopcRecords(file, coarse, &stats).ok());
  EXPECT_EQ(stats.nodes, 1u);
}

TEST(CopcRead, readsTheCopcFileOfAnotherWriter) {
  // laspy's simple.copc.laz (tests/data/laz/README.md): PDAL-style pages, 65 nodes of 4 levels.
  Result<InputFile> file = InputFile::open(std::string(DPOINT_TESTS_DIR) + "/data/laz/simple.copc.laz");
  ASSERT_TRUE(file.ok()) << file.error().message;
  EXPECT_TRUE(isCopc(*file));
  CopcNodeRead stats;
  Result<std::string> records = readCopcRecords(*file, CopcQuery{}, &stats);
  ASSERT_TRUE(records.ok()) << records.error().message;
  EXPECT_EQ(stats.points, 1065u);
  EXPECT_EQ(stats.nodes, 65u);
  Result<std::string> plain = decodeLaz(*file);
  ASSERT_TRUE(plain.ok()) << plain.error().message;
  EXPECT_TRUE(sorted(*records, 36) == sorted(*plain, 36));
}

TEST(CopcRead, isCopcOnlyForCopcFiles) {
  const std::string las = readFile(std::string(DPOINT_CORPUS_DIR) + "/las/simple1_4.las");
  EXPECT_FALSE(isCopc(InputFile::fromMemory("a.las", las)));
  EXPECT_FALSE(isCopc(InputFile::fromMemory("short", "LASF")));
  Result<std::string> copc = copcFromLasBytes(las);
  ASSERT_TRUE(copc.ok());
  EXPECT_TRUE(isCopc(InputFile::fromMemory("a.copc.laz", *copc)));
  Result<CopcHeader> not_copc = readCopcHeader(InputFile::fromMemory("a.las", las));
  ASSERT_FALSE(not_copc.ok());
  EXPECT_TRUE(test::contains(not_copc.error().message, "a.las: not COPC: no info VLR"));
}

// The message readCopcRecords gives for `copc` changed by `corrupt`.
std::string readError(std::string copc, const std::function<void(std::string&)>& corrupt) {
  corrupt(copc);
  const InputFile file = InputFile::fromMemory("bad.copc.laz", copc);
  Result<std::string> records = readCopcRecords(file, CopcQuery{});
  return records.ok() ? "(no error)" : records.error().message;
}

TEST(CopcRead, rejectsCorruptHierarchiesAndOffsetsByName) {
  CopcWriteOptions options;
  options.max_points_per_node = 300;
  options.page_levels = 1;
  options.page_min_nodes = 1;
  Result<std::string> made = copcFromLasBytes(las14(surfaceRecords(20000, 19, 100), kOrigin), options);
  ASSERT_TRUE(made.ok()) << made.error().message;
  const std::string& copc = *made;
  ASSERT_EQ(readError(copc, [](std::string&) {}), "(no error)");
  const size_t info = 375 + 54;
  const uint64_t root = at<uint64_t>(copc, info + 40);
  const uint64_t root_size = at<uint64_t>(copc, info + 48);
  size_t child_ref = 0;  // the root page's first reference to a child page
  for (uint64_t e = root; e < root + root_size && !child_ref; e += 32)
    if (at<int32_t>(copc, e + 28) == -1) child_ref = e;
  ASSERT_NE(child_ref, 0u);

  EXPECT_TRUE(test::contains(readError(copc, [&](std::string& c) { put<uint64_t>(c, info + 48, 33); }),
                             "bad.copc.laz: COPC info VLR: the root hierarchy page (33 bytes"));
  EXPECT_TRUE(test::contains(readError(copc, [&](std::string& c) { put<uint64_t>(c, info + 40, c.size()); }),
                             "not a whole number of 32-byte entries within the"));
  EXPECT_TRUE(test::contains(readError(copc, [&](std::string& c) { put<double>(c, info + 24, -1.0); }),
                             "is not positive and finite"));
  // A half size whose edge is infinite: every node's box had been NaN, and no point read.
  EXPECT_TRUE(test::contains(readError(copc, [&](std::string& c) { put<double>(c, info + 24, 1e308); }),
                             "is not positive and finite"));
  // The root node's chunk past the end of the file.
  EXPECT_TRUE(test::contains(readError(copc, [&](std::string& c) { put<uint64_t>(c, root + 16, c.size() - 10); }),
                             "entry 0 (node 0-0-0-0): its chunk ("));
  EXPECT_TRUE(test::contains(readError(copc, [&](std::string& c) { put<uint64_t>(c, root + 16, 100); }),
                             "is not within the point data"));
  EXPECT_TRUE(test::contains(readError(copc, [&](std::string& c) { put<int32_t>(c, root + 28, -7); }),
                             "entry 0 (node 0-0-0-0): point count -7 is below -1"));
  EXPECT_TRUE(test::contains(readError(copc, [&](std::string& c) { put<int32_t>(c, root + 4, 1); }),
                             "(node 0-1-0-0): not a node of an octree"));
  // A child page that points back at the root page.
  EXPECT_TRUE(test::contains(readError(copc, [&](std::string& c) { put<uint64_t>(c, child_ref + 16, root); }),
                             "is read a second time (the pages form a cycle)"));
  EXPECT_TRUE(test::contains(readError(copc, [&](std::string& c) { put<int32_t>(c, child_ref + 24, 31); }),
                             "its child page (31 bytes"));
  // A node's count off by one: the counts no longer add up.
  EXPECT_TRUE(test::contains(readError(copc, [&](std::string& c) { put<int32_t>(c, root + 28, at<int32_t>(c, root + 28) - 1); }),
                             "hierarchy: the nodes hold 19999 points, the header says 20000"));
  // So too where a view's query takes every node (a fine resolution, a box around the cube): a
  // damaged count had drawn "20000 of 0 points" with exit 0. A query that leaves nodes out cannot
  // tell.
  {
    size_t leaf = 0;  // a node with points in the first child page
    const uint64_t page = at<uint64_t>(copc, child_ref + 16);
    for (uint64_t e = page; e < page + static_cast<uint64_t>(at<int32_t>(copc, child_ref + 24)) && !leaf; e += 32)
      if (at<int32_t>(copc, e + 28) > 0) leaf = e;
    ASSERT_NE(leaf, 0u);
    std::string damaged = copc;
    put<int32_t>(damaged, leaf + 28, at<int32_t>(damaged, leaf + 28) - 1);
    const InputFile file = InputFile::fromMemory("bad.copc.laz", damaged);
    CopcQuery all_levels;
    all_levels.resolution = 1e-9;
    all_levels.box = CopcBox{{-1e9, -1e9, -1e9}, {1e9, 1e9, 1e9}};
    Result<std::string> read = readCopcRecords(file, all_levels);
    ASSERT_FALSE(read);
    EXPECT_TRUE(test::contains(read.error().message, "hierarchy: the nodes hold 19999 points, the header says 20000"));
    CopcQuery coarse;
    coarse.resolution = 1e9;  // the root alone
    Result<std::string> root_alone = readCopcRecords(file, coarse);
    EXPECT_TRUE(root_alone) << "a query of the root alone cannot check the count: " << root_alone.error().message;
  }
  // The root's chunk corrupted: the error names the node and its offset.
  const uint64_t chunk = at<uint64_t>(copc, root + 16);
  const std::string corrupt = readError(copc, [&](std::string& c) {
    for (size_t i = 40; i < 200; ++i) c[chunk + i] = static_cast<char>(c[chunk + i] ^ 0x5A);
  });
  EXPECT_TRUE(test::contains(corrupt, "bad.copc.laz: node 0-0-0-0 (")) << corrupt;
  EXPECT_TRUE(test::contains(corrupt, "bytes at byte " + std::to_string(chunk) + "): ")) << corrupt;
  // Truncated anywhere: an error, never a crash.
  for (size_t keep : {size_t{100}, size_t{500}, copc.size() / 2, copc.size() - 1}) {
    const std::string message = readError(copc, [&](std::string& c) { c.resize(keep); });
    EXPECT_NE(message, "(no error)") << keep;
    EXPECT_TRUE(test::contains(message, "bad.copc.laz")) << keep;
  }
}

}  // namespace
}  // namespace dpoint
