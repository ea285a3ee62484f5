#include "converters/ply.h"

#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <algorithm>
#include <filesystem>
#include <sstream>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "core/text.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::contains;
using test::readFile;
using test::TempDir;
using test::writeFile;

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Positions that break a careless writer: signed zeros, subnormals, the extremes, non-representable decimals.
PointSet awkwardPoints() {
  const double values[] = {0.0,          -0.0,           std::numeric_limits<double>::denorm_min(),
                           -DBL_MIN / 3, DBL_MIN,        DBL_MAX,
                           -DBL_MAX,     1e-300,         0.1,
                           1.0 / 3.0,    6.378e6 + 1e-9, -123456789.125,
                           1e300};
  PointSet set;
  const size_t n = std::size(values);
  for (size_t i = 0; i < n; ++i) set.positions.push_back({values[i], values[(i + 1) % n], values[(i + 5) % n]});
  return set;
}

void expectSamePositions(const PointSet& a, const PointSet& b) {
  ASSERT_EQ(a.positions.size(), b.positions.size());
  for (size_t i = 0; i < a.positions.size(); ++i)
    for (int k = 0; k < 3; ++k)
      EXPECT_TRUE(sameBits(a.positions[i][k], b.positions[i][k]))
          << "point " << i << " axis " << k << ": " << a.positions[i][k] << " vs " << b.positions[i][k];
}

void expectSameColors(const PointSet& a, const PointSet& b) {
  ASSERT_EQ(a.colors.size(), b.colors.size());
  for (size_t i = 0; i < a.colors.size(); ++i)
    for (int k = 0; k < 3; ++k)
      EXPECT_TRUE(sameBits(a.colors[i][k], b.colors[i][k]))
          << "colour " << i << " channel " << k << ": " << a.colors[i][k] << " vs " << b.colors[i][k];
}

PointSet roundTrip(const PointSet& in, PlyEncoding encoding, PlyColorType color_type = PlyColorType::kUchar) {
  TempDir dir;
  const std::string path = dir.file("round.ply");
  PlyWriteOptions options;
  options.encoding = encoding;
  options.color_type = color_type;
  Status w = writePly(path, in, options);
  EXPECT_TRUE(w.ok()) << w.error().message;
  auto r = readPly(path);
  EXPECT_TRUE(r.ok()) << r.error().message;
  return r.ok() ? std::move(r).value() : PointSet{};
}

// Little-endian bytes for hand-built binary files.
struct Bytes {
  std::string data;
  template <typename T>
  Bytes& add(T value) {
    data.append(reinterpret_cast<const char*>(&value), sizeof value);
    return *this;
  }
};

Result<PointSet> readText(const TempDir& dir, const std::string& name, const std::string& bytes,
                          const PlyReadOptions& options = {}) {
  writeFile(dir.file(name), bytes);
  return readPly(dir.file(name), options);
}

const char kAsciiHeader[] =
    "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\nproperty double y\nproperty double z\nend_header\n";

// ---------------------------------------------------------------- round trips

TEST(Ply, plyBinaryRoundTripIsBitExact) {
  PointSet in = awkwardPoints();
  expectSamePositions(in, roundTrip(in, PlyEncoding::kBinary));
}

TEST(Ply, plyAsciiRoundTripIsBitExact) {
  PointSet in = awkwardPoints();
  expectSamePositions(in, roundTrip(in, PlyEncoding::kAscii));
}

TEST(Ply, plyUcharColorsRoundTripAsBytes) {
  PointSet in;
  for (int k = 0; k < 256; ++k) {
    in.positions.push_back({k, -k, 0.5 * k});
    in.colors.push_back({static_cast<float>(k) / 255.0f, static_cast<float>(255 - k) / 255.0f,
                         static_cast<float>((k * 7) % 256) / 255.0f});
  }
  for (PlyEncoding encoding : {PlyEncoding::kBinary, PlyEncoding::kAscii}) {
    PointSet out = roundTrip(in, encoding, PlyColorType::kUchar);
    expectSamePositions(in, out);
    expectSameColors(in, out);
  }
}

TEST(Ply, plyUcharColorsAreRoundedAndClamped) {
  PointSet in;
  in.positions.assign(4, {0, 0, 0});
  in.colors = {{-0.5f, 2.0f, 0.5f},
               {std::numeric_limits<float>::quiet_NaN(), 1.0f, 0.0f},
               {0.499f / 255, 1.501f / 255, 254.6f / 255},
               {0, 0, 0}};
  PointSet out = roundTrip(in, PlyEncoding::kBinary, PlyColorType::kUchar);
  ASSERT_EQ(out.colors.size(), 4u);
  EXPECT_EQ(out.colors[0], glm::vec3(0.0f, 1.0f, 128.0f / 255.0f));
  EXPECT_EQ(out.colors[1], glm::vec3(0.0f, 1.0f, 0.0f));
  EXPECT_EQ(out.colors[2], glm::vec3(0.0f, 2.0f / 255.0f, 1.0f));
}

TEST(Ply, plyFloatColorsRoundTripExactly) {
  PointSet in;
  const float values[] = {0.0f, 1.0f, 0.1f, 1.0f / 3.0f, 1e-45f, 0.999999f, 0.5f, 2.0f};
  for (size_t i = 0; i < std::size(values); ++i) {
    in.positions.push_back({static_cast<double>(i), 0.0, 0.0});
    in.colors.push_back({values[i], values[(i + 1) % std::size(values)], values[(i + 3) % std::size(values)]});
  }
  for (PlyEncoding encoding : {PlyEncoding::kBinary, PlyEncoding::kAscii}) {
    PointSet out = roundTrip(in, encoding, PlyColorType::kFloat);
    expectSamePositions(in, out);
    expectSameColors(in, out);
  }
}

// The colour type: auto writes a LAS source's 16-bit colours as ushort (every bit, with a note that
// Open3D and PCL read 8-bit ones), 8-bit ones as uchar; uchar is 8-bit whatever the source (the
// build before wrote ushort where uchar was asked, and Open3D read colours up to 255).
TEST(Ply, colourTypeAutoKeepsSixteenBitsAndUcharIsEightBits) {
  TempDir dir;
  PointSet wide;
  wide.positions = {{0, 0, 0}, {1, 1, 1}};
  wide.colors = {glm::vec3(25600.0f / 65535.0f, 0.5f, 1.0f), glm::vec3(0.0f, 1.0f / 65535.0f, 0.25f)};
  wide.color_full_scale = 65535;
  PointSet narrow = wide;
  narrow.color_full_scale = 255;
  const auto written = [&](const PointSet& set, PlyColorType type, std::vector<std::string>* notices) {
    PlyWriteOptions options;
    options.color_type = type;
    options.notices = notices;
    EXPECT_TRUE(writePly(dir.file("c.ply"), set, options).ok());
    const std::string bytes = readFile(dir.file("c.ply"));
    return bytes.substr(0, bytes.find("end_header"));
  };
  std::vector<std::string> notices;
  EXPECT_TRUE(contains(written(wide, PlyColorType::kAuto, &notices), "property ushort red\n"));
  ASSERT_EQ(notices.size(), 1u);
  EXPECT_TRUE(contains(notices[0], "c.ply: 16-bit colours written as ushort, every bit kept; Open3D and PCL take 8-bit"));
  Result<PointSet> back = readPly(dir.file("c.ply"));
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(colorInteger(back->colors[1].g, 65535.0), 1) << "every bit";
  notices.clear();
  EXPECT_TRUE(contains(written(wide, PlyColorType::kUchar, &notices), "property uchar red\n"));
  EXPECT_TRUE(notices.empty());
  back = readPly(dir.file("c.ply"));
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(colorInteger(back->colors[0].r, 255.0), 100);
  EXPECT_TRUE(contains(written(narrow, PlyColorType::kAuto, &notices), "property uchar red\n"));
  EXPECT_TRUE(contains(written(narrow, PlyColorType::kUshort, &notices), "property ushort red\n"));
  EXPECT_TRUE(notices.empty());
  EXPECT_EQ(*parsePlyColorType("ushort"), PlyColorType::kUshort);
  EXPECT_FALSE(parsePlyColorType("half"));
}

TEST(Ply, plyMeshRoundTripKeepsTriangles) {
  PointSet in;
  in.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  in.triangles = {0, 1, 2, 0, 3, 1, 3, 2, 1};
  for (PlyEncoding encoding : {PlyEncoding::kBinary, PlyEncoding::kAscii}) {
    PointSet out = roundTrip(in, encoding);
    expectSamePositions(in, out);
    EXPECT_EQ(out.triangles, in.triangles);
    EXPECT_TRUE(out.colors.empty());
  }
}

TEST(Ply, plyEmptyPointSetRoundTrips) {
  for (PlyEncoding encoding : {PlyEncoding::kBinary, PlyEncoding::kAscii}) {
    PointSet out = roundTrip(PointSet{}, encoding);
    EXPECT_EQ(out.size(), 0u);
  }
}

TEST(Ply, plyWriterHeaderIsStandard) {
  TempDir dir;
  PointSet in;
  // Not planar: a set whose z are all 0 gets a `comment dpoint: 2D` line (generated2dPlyConverts…).
  in.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 1}};
  in.colors = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  in.triangles = {0, 1, 2};
  ASSERT_TRUE(writePly(dir.file("a.ply"), in).ok());
  const std::string bytes = readFile(dir.file("a.ply"));
  const std::string header =
      "ply\nformat binary_little_endian 1.0\ncomment written by dpoint\nelement vertex 3\n"
      "property double x\nproperty double y\nproperty double z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\n"
      "element face 1\nproperty list uchar uint vertex_indices\nend_header\n";
  EXPECT_EQ(bytes.substr(0, header.size()), header);
  EXPECT_EQ(bytes.size(), header.size() + 3 * 27 + 13);

  PlyWriteOptions ascii;
  ascii.encoding = PlyEncoding::kAscii;
  ascii.color_type = PlyColorType::kFloat;
  ASSERT_TRUE(writePly(dir.file("b.ply"), in, ascii).ok());
  const std::string text = readFile(dir.file("b.ply"));
  EXPECT_TRUE(contains(text, "format ascii 1.0\n"));
  EXPECT_TRUE(contains(text, "property float red\n"));
  EXPECT_TRUE(contains(text, "end_header\n0 0 0 1 0 0\n1 0 0 0 1 0\n0 1 1 0 0 1\n3 0 1 2\n"));
}

// Random bit patterns with uchar-exact colours: finite values from subnormal to 2.
PointSet randomPoints(size_t n, uint64_t seed) {
  PointSet set;
  uint64_t state = seed;
  auto next = [&state] {
    state = state * 6364136223846793005u + 1442695040888963407u;
    return state;
  };
  for (size_t i = 0; i < n; ++i) {
    // ">> 2" clears the sign and the top exponent bit.
    const uint64_t bits[3] = {next() >> 2, next() >> 2, next() >> 2};
    glm::dvec3 p;
    std::memcpy(&p, bits, sizeof p);
    set.positions.push_back(p);
    set.colors.push_back(glm::vec3(static_cast<float>(next() % 256) / 255.0f));
  }
  return set;
}

// Files larger than the reader's block, so rows and lines straddle refills.
TEST(Ply, plyLargeFilesCrossBlockBoundaries) {
  const size_t n = 400000;
  PointSet in = randomPoints(n, 12345);
  for (size_t i = 0; i + 2 < n; i += 2)
    in.triangles.insert(in.triangles.end(), {uint32_t(i), uint32_t(i + 1), uint32_t(i + 2)});
  for (PlyEncoding encoding : {PlyEncoding::kBinary, PlyEncoding::kAscii}) {
    PointSet out = roundTrip(in, encoding);
    expectSamePositions(in, out);
    expectSameColors(in, out);
    EXPECT_EQ(out.triangles, in.triangles);
  }
}

// ---------------------------------------------------------------- binary vertices on several threads

// The reader decodes binary vertices in blocks of 1 MiB (kVertexBlockBytes in ply_read.cpp); the
// files below hold four or more blocks, so that several threads share them.
constexpr size_t kManyBlocksOf27 = 200000;  // 5.4 MB of double xyz + uchar rgb rows

PlyReadOptions withThreads(unsigned threads) {
  PlyReadOptions options;
  options.threads = threads;
  return options;
}

TEST(Ply, plyBinaryVerticesAreTheSameForAnyThreadCount) {
  TempDir dir;
  const PointSet in = randomPoints(kManyBlocksOf27, 777);
  ASSERT_TRUE(writePly(dir.file("many.ply"), in).ok());
  for (unsigned threads : {1u, 2u, 4u, 7u}) {
    SCOPED_TRACE("threads " + std::to_string(threads));
    auto r = readPly(dir.file("many.ply"), withThreads(threads));
    ASSERT_TRUE(r.ok()) << r.error().message;
    expectSamePositions(in, *r);
    expectSameColors(in, *r);
  }
}

// Colours made as the rows are written (PlyWriteOptions::colors_of) give the file the set with
// those colours gives, byte for byte: binary and ASCII, uchar and float colours, a mesh, chunks of
// rows over several threads.
TEST(Ply, plyColoursMadeAsWrittenGiveTheSameFile) {
  TempDir dir;
  PointSet coloured = randomPoints(kManyBlocksOf27, 778);
  coloured.triangles = {0, 1, 2, 2, 1, 3};
  auto colourOf = [](const glm::dvec3& p) {
    return glm::vec3(static_cast<float>(p.x * 0.37), 0.25f, static_cast<float>(std::fabs(p.z) * 0.61));
  };
  for (size_t i = 0; i < coloured.size(); ++i) coloured.colors[i] = colourOf(coloured.positions[i]);
  PointSet bare = coloured;
  bare.colors.clear();
  for (PlyEncoding encoding : {PlyEncoding::kBinary, PlyEncoding::kAscii}) {
    for (PlyColorType type : {PlyColorType::kUchar, PlyColorType::kFloat}) {
      SCOPED_TRACE(std::string(encoding == PlyEncoding::kAscii ? "ASCII" : "binary") +
                   (type == PlyColorType::kFloat ? ", float" : ", uchar"));
      PlyWriteOptions options;
      options.encoding = encoding;
      options.color_type = type;
      options.threads = 3;
      ASSERT_TRUE(writePly(dir.file("given.ply"), coloured, options).ok());
      options.colors_of = [&](const glm::dvec3* positions, size_t count, glm::vec3* colors) {
        for (size_t i = 0; i < count; ++i) colors[i] = colourOf(positions[i]);
      };
      ASSERT_TRUE(writePly(dir.file("made.ply"), bare, options).ok());
      const std::string given = readFile(dir.file("given.ply"));
      EXPECT_GT(given.size(), size_t{1} << 20);
      EXPECT_TRUE(given == readFile(dir.file("made.ply")));
    }
  }
}

// Positions made as the rows are written (PlyWriteOptions::positions_of), for a set that holds
// only its facts, give the file the set holding those positions gives, byte for byte: binary and
// ASCII, 3D and 2D (the "z is 0" comment from the facts), with colours made too, over 3 threads.
TEST(Ply, plyPositionsMadeAsWrittenGiveTheSameFile) {
  TempDir dir;
  const size_t n = 200003;  // a partial last chunk of rows
  for (bool planar : {false, true}) {
    auto at = [planar](size_t i) {
      return glm::dvec3(static_cast<double>(i) * 0.5 - 7.0, -1.0 / static_cast<double>(i + 1),
                        planar ? 0.0 : static_cast<double>(i % 7) * 1e9);
    };
    PointSet held;
    for (size_t i = 0; i < n; ++i) held.positions.push_back(at(i));
    PointSet facts;
    facts.z_axis = planar ? ZAxis::kAbsent : ZAxis::kPresent;
    for (PlyEncoding encoding : {PlyEncoding::kBinary, PlyEncoding::kAscii}) {
      for (bool colours : {false, true}) {
        SCOPED_TRACE(std::string(encoding == PlyEncoding::kAscii ? "ASCII" : "binary") + (planar ? ", 2D" : ", 3D") +
                     (colours ? ", colours made" : ""));
        PlyWriteOptions options;
        options.encoding = encoding;
        options.threads = 3;
        if (colours)
          options.colors_of = [](const glm::dvec3* positions, size_t count, glm::vec3* colors) {
            for (size_t i = 0; i < count; ++i) colors[i] = glm::vec3(static_cast<float>(positions[i].y), 0.5f, 0.0f);
          };
        ASSERT_TRUE(writePly(dir.file("held.ply"), held, options).ok());
        options.positions_of = {n, [&](size_t begin, size_t end, glm::dvec3* out) {
                                  for (size_t i = begin; i < end; ++i) out[i - begin] = at(i);
                                }};
        ASSERT_TRUE(writePly(dir.file("made.ply"), facts, options).ok());
        const std::string expected = readFile(dir.file("held.ply"));
        EXPECT_EQ(expected.find("z is 0") != std::string::npos, planar);
        EXPECT_TRUE(expected == readFile(dir.file("made.ply")));
      }
    }
  }
}

// The general path (not double xyz + uchar rgb) is parallel too: float xyz around a skipped
// property, ushort colours.
TEST(Ply, plyBinaryMixedTypesAreTheSameForAnyThreadCount) {
  TempDir dir;
  Bytes b;
  const size_t n = 250000;  // 24-byte rows: 5.7 MB
  b.data =
      "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(n) +
      "\nproperty float y\nproperty int flags\nproperty float x\nproperty float z\n"
      "property ushort red\nproperty ushort green\nproperty ushort blue\nproperty short pad\nend_header\n";
  PointSet expected;
  for (size_t i = 0; i < n; ++i) {
    const float x = static_cast<float>(i) * 0.1f, y = -static_cast<float>(i) / 3.0f;
    const float z = 1.0f / static_cast<float>(i + 1);
    const auto red = static_cast<uint16_t>(i), green = static_cast<uint16_t>(i * 7), blue = static_cast<uint16_t>(~i);
    b.add(y).add(static_cast<int32_t>(i)).add(x).add(z).add(red).add(green).add(blue).add(int16_t{-1});
    expected.positions.push_back({x, y, z});
    expected.colors.push_back({static_cast<float>(red) / 65535.0f, static_cast<float>(green) / 65535.0f,
                               static_cast<float>(blue) / 65535.0f});
  }
  writeFile(dir.file("mixed.ply"), b.data);
  for (unsigned threads : {1u, 4u}) {
    SCOPED_TRACE("threads " + std::to_string(threads));
    auto r = readPly(dir.file("mixed.ply"), withThreads(threads));
    ASSERT_TRUE(r.ok()) << r.error().message;
    expectSamePositions(expected, *r);
    expectSameColors(expected, *r);
  }
}

// Blocks hold 38836 rows of 27 bytes. Two layouts of bad rows, so that neither "the first error
// found wins" nor "the last one found wins" passes once blocks run at the same time: the earlier
// bad row found first (start of block 1, end of block 3) and found last (end of block 1, start of
// block 2). A second bad row in the first bad row's block must not replace it either.
TEST(Ply, plyFirstBadVertexWinsWhateverTheThreadCount) {
  constexpr size_t kBlock = 38836;
  const double inf = std::numeric_limits<double>::infinity();
  for (auto [first, later] : {std::pair<size_t, size_t>{kBlock + 1000, 4 * kBlock - 2},
                              std::pair<size_t, size_t>{2 * kBlock - 10, 2 * kBlock + 1}}) {
    SCOPED_TRACE("bad rows " + std::to_string(first) + " and " + std::to_string(later));
    TempDir dir;
    PointSet in = randomPoints(kManyBlocksOf27, 99);
    in.positions[first].z = inf;
    in.positions[first + 7].y = -inf;
    in.positions[later].x = std::numeric_limits<double>::quiet_NaN();
    ASSERT_TRUE(writePly(dir.file("bad.ply"), in).ok());
    const size_t header = readFile(dir.file("bad.ply")).find("end_header\n") + 11;
    for (unsigned threads : {1u, 2u, 4u, 7u, 2u, 4u, 7u, 2u, 4u, 7u}) {  // timing varies: several tries
      SCOPED_TRACE("threads " + std::to_string(threads));
      auto r = readPly(dir.file("bad.ply"), withThreads(threads));
      ASSERT_FALSE(r.ok());
      EXPECT_TRUE(contains(r.error().message, "bad.ply: byte " + std::to_string(header + first * 27) + ": vertex " +
                                                  std::to_string(first) + ": z is inf, not a finite number"));
    }
    PlyReadOptions allow = withThreads(4);
    allow.allow_nonfinite = true;
    auto r = readPly(dir.file("bad.ply"), allow);
    ASSERT_TRUE(r.ok()) << r.error().message;
    expectSamePositions(in, *r);
  }
}

TEST(Ply, plyRejectsTruncatedBinaryOfManyBlocks) {
  TempDir dir;
  const PointSet in = randomPoints(kManyBlocksOf27, 5);
  ASSERT_TRUE(writePly(dir.file("whole.ply"), in).ok());
  const std::string bytes = readFile(dir.file("whole.ply"));
  const size_t cut = bytes.size() - 3 * 27 - 5;  // inside the fourth row from the end
  writeFile(dir.file("cut.ply"), bytes.substr(0, cut));
  auto r = readPly(dir.file("cut.ply"), withThreads(4));
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "cut.ply: truncated at byte " + std::to_string(cut) +
                                              ": header line 4 declares 200000 'vertex' rows"));
}

// A list property on the vertex element is named in a note (it was dropped without a word); the
// numbers after it are still read.
TEST(Ply, aVertexListPropertyIsNamedInANote) {
  TempDir dir;
  writeFile(dir.file("list.ply"), "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                                  "property float z\nproperty list uchar int idx\nproperty short s\nend_header\n"
                                  "1 2 3 2 10 11 -7\n4 5 6 0 32767\n");
  std::vector<std::string> notices;
  PlyReadOptions options;
  options.notices = &notices;
  Result<PointSet> set = readPly(dir.file("list.ply"), options);
  ASSERT_TRUE(set.ok()) << set.error().message;
  EXPECT_EQ(set->dimensions.find("s")->value(0), -7.0);
  EXPECT_EQ(set->dimensions.find("s")->value(1), 32767.0);
  ASSERT_EQ(notices.size(), 1u);
  EXPECT_EQ(notices[0], dir.file("list.ply") + ": vertex list properties not read (a dimension holds one number a point): idx");
}

// An element before the vertices may hold longer lists than the size check assumes (one count
// byte a row), so the vertex rows themselves run out: the whole rows are decoded, the cut reported.
TEST(Ply, plyRejectsVerticesCutAfterALongList) {
  TempDir dir;
  const size_t n = 200000;  // 24-byte rows
  const std::string header = "ply\nformat binary_little_endian 1.0\nelement face 1\n"
                             "property list uchar int vertex_indices\nelement vertex " + std::to_string(n) +
                             "\nproperty double x\nproperty double y\nproperty double z\nend_header\n";
  Bytes b;
  b.data = header;
  b.add(uint8_t{200});
  for (int32_t k = 0; k < 200; ++k) b.add(k);  // 801 bytes, where the size check counts 1
  // The size check passes (801 + 24 * (n - 33) + 5 >= 1 + 24 * n); the vertex data stops 5 bytes
  // into row n - 33 = 199967.
  for (size_t i = 0; i + 33 < n; ++i) b.add(static_cast<double>(i)).add(1.0).add(2.0);
  b.data += "12345";
  auto r = readText(dir, "cut.ply", b.data, withThreads(4));
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "cut.ply: truncated at byte " + std::to_string(b.data.size()) +
                                              ": expected 200000 'vertex' rows, the data ends in row 199967"));
  // A bad row before the cut comes first in the file, so it is the error.
  const size_t row = header.size() + 801 + 24 * 100000;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(b.data.data() + row + 8, &nan, sizeof nan);
  auto bad = readText(dir, "cut_nan.ply", b.data, withThreads(4));
  ASSERT_FALSE(bad.ok());
  EXPECT_TRUE(contains(bad.error().message, "cut_nan.ply: byte " + std::to_string(row) + ": vertex 100000: y is nan"));
}

// Every thread reports its blocks: the progress ends at 100%, not at the share of one thread. The
// file is larger than the 8 MiB the header read takes in (and reports) at once.
TEST(Ply, plyProgressCountsEveryBlock) {
  TempDir dir;
  ASSERT_TRUE(writePly(dir.file("many.ply"), randomPoints(3 * kManyBlocksOf27, 3)).ok());
  std::FILE* sink = std::tmpfile();
  ASSERT_NE(sink, nullptr);
  {
    Progress progress(sink, "");
    PlyReadOptions options = withThreads(4);
    options.progress = &progress;
    auto r = readPly(dir.file("many.ply"), options);
    ASSERT_TRUE(r.ok()) << r.error().message;
    progress.finish();
  }
  std::rewind(sink);
  std::string text(4096, '\0');
  text.resize(std::fread(text.data(), 1, text.size(), sink));
  std::fclose(sink);
  const std::string last = text.substr(text.rfind('\r') + 1);
  EXPECT_TRUE(contains(last, "reading " + dir.file("many.ply") + ": 100.0%")) << text;
}

// ---------------------------------------------------------------- foreign files

TEST(Ply, plyQuadFaceIsFanTriangulated) {
  TempDir dir;
  auto r = readText(dir, "quad.ply",
                    "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
                    "element face 2\nproperty list uchar int vertex_index\nend_header\n"
                    "0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 2 2\n4 0 1 2 3\n5 4 3 2 1 0\n");
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r->triangles, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 4, 3, 2, 4, 2, 1, 4, 1, 0}));

  Bytes b;
  b.data =
      "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
      "property double z\nelement face 1\nproperty list int ushort vertex_indices\nend_header\n";
  for (int i = 0; i < 4; ++i) b.add(double(i)).add(0.0).add(0.0);
  b.add(int32_t{4}).add(uint16_t{3}).add(uint16_t{2}).add(uint16_t{1}).add(uint16_t{0});
  auto binary = readText(dir, "quad_bin.ply", b.data);
  ASSERT_TRUE(binary.ok()) << binary.error().message;
  EXPECT_EQ(binary->triangles, (std::vector<uint32_t>{3, 2, 1, 3, 1, 0}));
}

TEST(Ply, plyReadsFloatXyz) {
  TempDir dir;
  Bytes b;
  b.data =
      "ply\nformat binary_little_endian 1.0\ncomment from a float writer\nelement vertex 2\n"
      "property float32 x\nproperty float32 y\nproperty float32 z\nend_header\n";
  b.add(0.1f).add(-2.5f).add(1e30f).add(0.0f).add(-0.0f).add(3.0f);
  auto r = readText(dir, "float.ply", b.data);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_EQ(r->size(), 2u);
  EXPECT_TRUE(sameBits(r->positions[0].x, static_cast<double>(0.1f)));
  EXPECT_EQ(r->positions[0].z, static_cast<double>(1e30f));
  EXPECT_TRUE(sameBits(r->positions[1].y, -0.0));
  EXPECT_FALSE(r->hasColors());

  // An ASCII float property means the float nearest the text, as a binary file would hold.
  auto a = readText(dir, "float.txt.ply",
                    "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                    "property float z\nend_header\n0.1 +2 -1e-3\n");
  ASSERT_TRUE(a.ok()) << a.error().message;
  EXPECT_TRUE(sameBits(a->positions[0].x, static_cast<double>(0.1f)));
  EXPECT_EQ(a->positions[0].y, 2.0);
  EXPECT_TRUE(sameBits(a->positions[0].z, static_cast<double>(-1e-3f)));
}

TEST(Ply, plyReadsAsciiWithExtraPropertiesAndElements) {
  TempDir dir;
  auto r = readText(dir, "extra.ply",
                    "ply\r\nformat ascii 1.0\r\ncomment hand written\r\nobj_info scanner 3\r\n"
                    "element camera 1\r\nproperty float view_px\r\nproperty list uchar float params\r\n"
                    "element vertex 3\r\nproperty int confidence\r\nproperty double x\r\nproperty double y\r\n"
                    "property double z\r\nproperty float nx\r\nproperty uchar red\r\nproperty uchar green\r\n"
                    "property uchar blue\r\nproperty uchar alpha\r\nproperty list uchar int tags\r\n"
                    "element edge 2\r\nproperty int vertex1\r\nproperty int vertex2\r\nend_header\r\n"
                    "0.5 3 1 2 3\r\n"
                    "7 1.5 -2.5 1e-300 0.1 255 0 51 128 2 4 5\r\n"
                    "\t-1  0  0.1  +3 0 0 255 0 255 0\r\n"
                    "\r\n"
                    "9 1 2 3 nan 1 2 3 4 1 99\r\n"
                    "0 1\r\n1 2\r\n\r\n");
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_EQ(r->size(), 3u);
  EXPECT_EQ(r->positions[0], glm::dvec3(1.5, -2.5, 1e-300));
  EXPECT_EQ(r->positions[1], glm::dvec3(0.0, 0.1, 3.0));
  EXPECT_EQ(r->positions[2], glm::dvec3(1, 2, 3));
  ASSERT_TRUE(r->hasColors());
  EXPECT_EQ(r->colors[0], glm::vec3(1.0f, 0.0f, 51.0f / 255.0f));
  EXPECT_EQ(r->colors[1], glm::vec3(0.0f, 1.0f, 0.0f));
  EXPECT_EQ(r->colors[2], glm::vec3(1.0f / 255.0f, 2.0f / 255.0f, 3.0f / 255.0f));
  EXPECT_TRUE(r->triangles.empty());
}

TEST(Ply, plyReadsBinaryWithExtraPropertiesAndElements) {
  TempDir dir;
  Bytes b;
  b.data =
      "ply\nformat binary_little_endian 1.0\nelement material 2\nproperty list uint double weights\n"
      "property short id\nelement vertex 2\nproperty uint8 flags\nproperty float64 x\n"
      "property list ushort int neighbours\nproperty int16 y\nproperty int32 z\nproperty ushort red\n"
      "property float green\nproperty double blue\nelement face 1\nproperty uchar kind\n"
      "property list uchar uint vertex_indices\nproperty list uchar float uv\nelement tail 3\n"
      "property char c\nend_header\n";
  b.add(uint32_t{2}).add(1.0).add(2.0).add(int16_t{7});
  b.add(uint32_t{0}).add(int16_t{8});
  b.add(uint8_t{1}).add(0.25).add(uint16_t{2}).add(int32_t{5}).add(int32_t{6}).add(int16_t{-3}).add(int32_t{7});
  b.add(uint16_t{65535}).add(0.5f).add(0.125);
  b.add(uint8_t{2}).add(-1e10).add(uint16_t{0}).add(int16_t{32767}).add(int32_t{-8});
  b.add(uint16_t{0}).add(2.0f).add(-1.0);
  b.add(uint8_t{9}).add(uint8_t{3}).add(uint32_t{1}).add(uint32_t{0}).add(uint32_t{1});
  b.add(uint8_t{2}).add(0.0f).add(1.0f);
  b.add(int8_t{1}).add(int8_t{2}).add(int8_t{3});
  auto r = readText(dir, "extra.ply", b.data);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_EQ(r->size(), 2u);
  EXPECT_EQ(r->positions[0], glm::dvec3(0.25, -3, 7));
  EXPECT_EQ(r->positions[1], glm::dvec3(-1e10, 32767, -8));
  EXPECT_EQ(r->colors[0], glm::vec3(1.0f, 0.5f, 0.125f));
  EXPECT_EQ(r->colors[1], glm::vec3(0.0f, 2.0f, -1.0f));  // float colours are taken as they are
  EXPECT_EQ(r->triangles, (std::vector<uint32_t>{1, 0, 1}));
}

TEST(Ply, plyAcceptsNanWhenAllowed) {
  TempDir dir;
  PlyReadOptions allow;
  allow.allow_nonfinite = true;
  auto r = readText(dir, "nan.ply", std::string(kAsciiHeader) + "1 nan 2\n-inf 0 inf\n", allow);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_TRUE(std::isnan(r->positions[0].y));
  EXPECT_EQ(r->positions[1].x, -std::numeric_limits<double>::infinity());
}

// ASCII rows are parsed in 4 MiB blocks on all cores up to the first row the row-by-row loop must
// take (a blank line, another polygon, a bad value), which goes on from there: the same points,
// triangles and errors (at their line) on any thread count, whatever block the row falls in.
TEST(Ply, asciiRowsAreReadInBlocksUpToTheFirstOtherRow) {
  TempDir dir;
  const uint64_t n = 250000, faces = n - 2;  // about 10 MB of vertex rows and 4 MB of faces
  const std::string header = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(n) +
                             "\nproperty double x\nproperty double y\nproperty double z\nproperty uchar red\n"
                             "property uchar green\nproperty uchar blue\nproperty float intensity\nelement face " +
                             std::to_string(faces) + "\nproperty list uchar int vertex_indices\nend_header\n";
  const uint64_t header_lines = 13;
  // Row i as text, with `change` applied to vertex row i or face row i.
  auto text = [&](const std::function<void(bool vertex, uint64_t row, std::string& line)>& change,
                  const char* newline = "\n") {
    std::string out = header;
    for (uint64_t i = 0; i < n; ++i) {
      std::string line = formatNumber(0.25 * static_cast<double>(i)) + " " + formatNumber(-static_cast<double>(i)) + " " +
                         formatNumber(1e6 + 0.125 * static_cast<double>(i)) + " " + std::to_string(i % 256) + " " +
                         std::to_string(i * 7 % 256) + " 3 " + formatNumber(0.5 * static_cast<double>(i));
      change(true, i, line);
      out += line + newline;
    }
    for (uint64_t f = 0; f < faces; ++f) {
      std::string line = "3 " + std::to_string(f) + " " + std::to_string(f + 1) + " " + std::to_string(f + 2);
      change(false, f, line);
      out += line + newline;
    }
    return out;
  };
  auto same = [](bool, uint64_t, std::string&) {};
  auto expectTheSet = [&](const Result<PointSet>& r, uint64_t extra_triangles) {
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(r->size(), n);
    ASSERT_EQ(r->triangles.size(), 3 * (faces + extra_triangles));
    bool good = true;
    for (uint64_t i = 0; i < n && good; ++i) {
      const double x = static_cast<double>(i);
      good = r->positions[i] == glm::dvec3(0.25 * x, -x, 1e6 + 0.125 * x) &&
             r->colors[i] == glm::vec3(static_cast<float>(i % 256) / 255.0f, static_cast<float>(i * 7 % 256) / 255.0f,
                                       3.0f / 255.0f) &&
             r->dimensions.all()[0].value(i) == 0.5 * x;
      EXPECT_TRUE(good) << "vertex " << i;
    }
    for (uint64_t f = 0; f < faces && good; ++f) {
      good = r->triangles[3 * f] == f && r->triangles[3 * f + 1] == f + 1 && r->triangles[3 * f + 2] == f + 2;
      EXPECT_TRUE(good) << "face " << f;
    }
  };
  for (unsigned threads : {1u, 2u, 7u}) {
    SCOPED_TRACE(threads);
    const PlyReadOptions options = withThreads(threads);
    expectTheSet(readText(dir, "clean.ply", text(same), options), 0);
    expectTheSet(readText(dir, "crlf.ply", text(same, "\r\n"), options), 0);
    // Blank lines among the rows are skipped.
    expectTheSet(readText(dir, "blank.ply", text([](bool vertex, uint64_t row, std::string& line) {
                                           if (row == (vertex ? 100000u : 3u)) line = " \t\n" + line;
                                         }),
                          options),
                 0);
    // A quad mesh: every row fanned into two triangles.
    auto quads = readText(dir, "quads.ply", text([&](bool vertex, uint64_t row, std::string& line) {
                                              if (!vertex)
                                                line = "4 " + std::to_string(row) + " " + std::to_string(row + 1) + " " +
                                                       std::to_string(row + 2) + " " + std::to_string((row + 3) % n);
                                            }),
                          options);
    ASSERT_TRUE(quads.ok()) << quads.error().message;
    ASSERT_EQ(quads->triangles.size(), 6 * faces);
    bool fanned = true;
    for (uint64_t f = 0; f < faces && fanned; ++f) {
      const uint32_t* t = &quads->triangles[6 * f];
      fanned = t[0] == f && t[1] == f + 1 && t[2] == f + 2 && t[3] == f && t[4] == f + 2 && t[5] == (f + 3) % n;
      EXPECT_TRUE(fanned) << "face " << f;
    }
    // Faces of mixed sizes: every seventh a pentagon, fanned into three triangles.
    auto mixed = readText(dir, "mixed.ply", text([&](bool vertex, uint64_t row, std::string& line) {
                                              if (!vertex && row % 7 == 0)
                                                line = "5 " + std::to_string(row) + " " + std::to_string(row + 1) + " " +
                                                       std::to_string(row + 2) + " " + std::to_string((row + 3) % n) +
                                                       " " + std::to_string((row + 4) % n);
                                            }),
                          options);
    ASSERT_TRUE(mixed.ok()) << mixed.error().message;
    std::vector<uint32_t> fans;
    for (uint32_t f = 0; f < faces; ++f) {
      fans.insert(fans.end(), {f, f + 1, f + 2});
      if (f % 7 == 0)
        fans.insert(fans.end(), {f, f + 2, static_cast<uint32_t>((f + 3) % n), f, static_cast<uint32_t>((f + 3) % n),
                                 static_cast<uint32_t>((f + 4) % n)});
    }
    EXPECT_TRUE(mixed->triangles == fans);
    // Past --max-memory in the middle of a block: the row that passes it named, as row by row.
    PlyReadOptions tight = options;
    const uint64_t vertex_bytes = n * (sizeof(glm::dvec3) + sizeof(glm::vec3) + sizeof(float));
    tight.max_memory = vertex_bytes + 12 * 300000;  // room for 300,000 triangles
    uint64_t passing = 0;
    for (uint64_t f = 0, t = 0; f < faces; ++f)
      if ((t += f % 7 == 0 ? 3 : 1) > 300000) {
        passing = f;
        break;
      }
    auto over = readText(dir, "mixed.ply", readFile(dir.file("mixed.ply")), tight);
    ASSERT_FALSE(over.ok());
    EXPECT_TRUE(contains(over.error().message, "mixed.ply: face " + std::to_string(passing) +
                                                   ": the faces' triangles needs about"))
        << over.error().message;
    // A quad among triangles is fanned into two; the rows after it are read as before.
    auto quad = readText(dir, "quad.ply", text([](bool vertex, uint64_t row, std::string& line) {
                                            if (!vertex && row == 150000) line = "4 150000 150001 150002 7";
                                          }),
                         options);
    ASSERT_TRUE(quad.ok()) << quad.error().message;
    ASSERT_EQ(quad->triangles.size(), 3 * (faces + 1));
    EXPECT_EQ(std::vector<uint32_t>(quad->triangles.begin() + 3 * 150000, quad->triangles.begin() + 3 * 150003),
              (std::vector<uint32_t>{150000, 150001, 150002, 150000, 150002, 7, 150001, 150002, 150003}));
    // Errors at their line, in a later block.
    auto bad = readText(dir, "bad.ply", text([](bool vertex, uint64_t row, std::string& line) {
                                          if (vertex && row == 200000) line = "1 abc 2 0 0 0 0";
                                          if (vertex && row == 210000) line = "1 2";  // after the first error: not it
                                        }),
                        options);
    ASSERT_FALSE(bad.ok());
    EXPECT_TRUE(contains(bad.error().message, "line " + std::to_string(header_lines + 200000 + 1) +
                                                  ": vertex 200000: 'y': 'abc' is not a valid double"))
        << bad.error().message;
    auto nan = readText(dir, "nan.ply", text([](bool vertex, uint64_t row, std::string& line) {
                                          if (vertex && row == 123456) line = "nan 0 0 0 0 0 0";
                                        }),
                        options);
    ASSERT_FALSE(nan.ok());
    EXPECT_TRUE(contains(nan.error().message, "line " + std::to_string(header_lines + 123456 + 1) +
                                                  ": vertex 123456: x is nan, not a finite number"))
        << nan.error().message;
    auto index = readText(dir, "index.ply", text([&](bool vertex, uint64_t row, std::string& line) {
                                              if (!vertex && row == 240000) line = "3 1 2 " + std::to_string(n + 5);
                                            }),
                          options);
    ASSERT_FALSE(index.ok());
    EXPECT_TRUE(contains(index.error().message, "line " + std::to_string(header_lines + n + 240000 + 1) +
                                                    ": face 240000: vertex index " + std::to_string(n + 5) +
                                                    " out of range"))
        << index.error().message;
    auto extra = readText(dir, "extra.ply", text([](bool vertex, uint64_t row, std::string& line) {
                                              if (!vertex && row == 5) line += " 9";
                                            }),
                          options);
    ASSERT_FALSE(extra.ok());
    EXPECT_TRUE(contains(extra.error().message, "face 5: more values than the header declares")) << extra.error().message;
  }
}

// ---------------------------------------------------------------- failures

// A fuzz finding (tests/corpus/ply/fuzz_float_colour_nan.ply): NaN float colours were read as they
// were, and the renderer turns colours into bytes. Colours now follow positions: finite unless
// allowed, and a double colour must fit a float. Binary (multithreaded and serial) and ASCII alike.
TEST(Ply, plyRejectsNonFiniteColoursAndDoubleColoursPastFloat) {
  TempDir dir;
  const std::string header = "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\nproperty double y\n"
                             "property double z\nproperty float red\nproperty double green\nproperty float blue\n"
                             "end_header\n";
  auto nan = readText(dir, "nan.ply", header + "0 0 0 0.5 0.5 0.5\n1 1 1 nan 0 0\n");
  ASSERT_FALSE(nan.ok());
  EXPECT_NE(nan.error().message.find("line 12: vertex 1: red is nan, not a finite number"), std::string::npos)
      << nan.error().message;
  auto huge = readText(dir, "huge.ply", header + "0 0 0 0.5 1e300 0.5\n1 1 1 0 0 0\n");
  ASSERT_FALSE(huge.ok());
  EXPECT_NE(huge.error().message.find("vertex 0: green is 1e+300, out of float range"), std::string::npos)
      << huge.error().message;
  std::string binary = "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                       "property float z\nproperty float red\nproperty float green\nproperty float blue\nend_header\n";
  const float row[6] = {0, 0, 0, 0.5f, std::numeric_limits<float>::infinity(), 0};
  binary.append(reinterpret_cast<const char*>(row), sizeof row);
  auto inf = readText(dir, "inf.ply", binary);
  ASSERT_FALSE(inf.ok());
  EXPECT_NE(inf.error().message.find("vertex 0: green is inf, not a finite number"), std::string::npos)
      << inf.error().message;
  PlyReadOptions allow;
  allow.allow_nonfinite = true;
  auto allowed = readText(dir, "nan.ply", header + "0 0 0 0.5 0.5 0.5\n1 1 1 nan 0 0\n", allow);
  ASSERT_TRUE(allowed.ok()) << allowed.error().message;
  EXPECT_TRUE(std::isnan(allowed->colors[1].r));
  EXPECT_FALSE(readText(dir, "huge.ply", header + "0 0 0 0.5 1e300 0.5\n1 1 1 0 0 0\n", allow).ok());
}

TEST(Ply, plyRejectsMissingFile) {
  TempDir dir;
  auto r = readPly(dir.file("nope.ply"));
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "nope.ply"));
  EXPECT_TRUE(contains(r.error().message, "not found"));
}

TEST(Ply, plyRejectsFolder) {
  TempDir dir;
  auto r = readPly(dir.path());
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, dir.path()));
  EXPECT_TRUE(contains(r.error().message, "folder"));
}

TEST(Ply, plyRejectsEmptyFile) {
  TempDir dir;
  auto r = readText(dir, "empty.ply", "");
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "empty.ply: empty file"));
}

TEST(Ply, plyRejectsMissingMagic) {
  TempDir dir;
  auto r = readText(dir, "csv.ply", "x,y,z\n1,2,3\n");
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "csv.ply: not a PLY file"));
  auto g = readText(dir, "garbage.ply",
                    std::string("\x7f"
                                "ELF\0\0\0\x01\x02",
                                9) +
                        std::string(100000, '\xff'));
  ASSERT_FALSE(g.ok());
  EXPECT_TRUE(contains(g.error().message, "garbage.ply: not a PLY file"));
  auto p = readText(dir, "plyx.ply", "plyfoo\nformat ascii 1.0\n");
  ASSERT_FALSE(p.ok());
  EXPECT_TRUE(contains(p.error().message, "plyx.ply: not a PLY file"));
}

TEST(Ply, plyRejectsMissingEndHeader) {
  TempDir dir;
  auto r = readText(dir, "cut.ply", "ply\nformat ascii 1.0\nelement vertex 1\n");
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "cut.ply: header line 4: the file ends before 'end_header'"));
}

// Big-endian is read (bigEndianBinaryReadsAsLittleEndianDoes); another encoding is refused.
TEST(Ply, plyRejectsAnUnknownEncoding) {
  TempDir dir;
  auto big = readText(dir, "big.ply",
                      "ply\nformat binary_big_endian 1.0\nelement vertex 0\nproperty float x\nproperty float y\nend_header\n");
  ASSERT_TRUE(big.ok()) << big.error().message;
  auto r = readText(dir, "odd.ply", "ply\nformat binary_middle_endian 1.0\nelement vertex 0\nend_header\n");
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "odd.ply: header line 2: unknown format 'binary_middle_endian'")) << r.error().message;
}

TEST(Ply, plyRejectsUnknownHeaderKeyword) {
  TempDir dir;
  auto r = readText(dir, "kw.ply", "ply\nformat ascii 1.0\nelemnt vertex 1\nend_header\n");
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "kw.ply: header line 3: unknown header keyword 'elemnt'"));
}

// A repeated element, or a property repeated within one element, is refused; the same name in two
// elements is not a repeat (the names are kept in sets, per element for properties).
TEST(Ply, plyRejectsRepeatedNamesOnly) {
  TempDir dir;
  auto prop = readText(dir, "p.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty double x\nproperty double y\n"
                                     "property double z\nproperty double y\nend_header\n1 2 3 4\n");
  ASSERT_FALSE(prop.ok());
  EXPECT_TRUE(contains(prop.error().message, "p.ply: header line 7: second property 'y'")) << prop.error().message;
  auto element = readText(dir, "e.ply", "ply\nformat ascii 1.0\nelement vertex 0\nproperty double x\nproperty double y\n"
                                        "property double z\nelement vertex 0\nend_header\n");
  ASSERT_FALSE(element.ok());
  EXPECT_TRUE(contains(element.error().message, "e.ply: header line 7: second element 'vertex'")) << element.error().message;
  auto two = readText(dir, "two.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty double x\nproperty double y\n"
                                      "property double z\nelement extra 1\nproperty double x\nend_header\n1 2 3\n4\n");
  EXPECT_TRUE(two.ok()) << two.error().message;
}

TEST(Ply, plyRejectsUnsupportedPropertyType) {
  TempDir dir;
  auto r = readText(dir, "cloud.ply",
                    "ply\nformat ascii 1.0\nelement vertex 1\nproperty double x\nproperty float128 y\n"
                    "property double z\nend_header\n1 2 3\n");
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "cloud.ply: header line 5: unsupported property type 'float128'"));
  auto list = readText(dir, "list.ply",
                       "ply\nformat ascii 1.0\nelement vertex 0\nproperty double x\nproperty double y\n"
                       "property double z\nelement face 0\nproperty list float int vertex_indices\nend_header\n");
  ASSERT_FALSE(list.ok());
  EXPECT_TRUE(contains(list.error().message, "list.ply: header line 8: list count type 'float'"));
}

TEST(Ply, plyRejectsMissingX) {
  TempDir dir;
  auto r = readText(dir, "nox.ply",
                    "ply\nformat ascii 1.0\nelement vertex 1\nproperty double y\nproperty double z\n"
                    "end_header\n1 2\n");
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "nox.ply: header line 3: element 'vertex' has no 'x' property"));
  auto none =
      readText(dir, "novertex.ply", "ply\nformat ascii 1.0\nelement point 1\nproperty double x\nend_header\n1\n");
  ASSERT_FALSE(none.ok());
  EXPECT_TRUE(contains(none.error().message, "novertex.ply: the header declares no 'vertex' element"));
}

TEST(Ply, plyRejectsPartialColors) {
  TempDir dir;
  auto r = readText(dir, "rg.ply",
                    "ply\nformat ascii 1.0\nelement vertex 1\nproperty double x\nproperty double y\n"
                    "property double z\nproperty uchar red\nproperty uchar green\nend_header\n1 2 3 4 5\n");
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "rg.ply: header line 8: vertex colours need all of red, green and blue"));
}

// diffuse_red, diffuse_green, diffuse_blue (older scanners' and MeshLab's names) are the colours
// where red, green and blue are absent; beside them they stay a dimension. The build before read
// them as three dimensions, and the set had no colours.
TEST(Ply, diffuseColoursAreColoursWhereRedGreenBlueAreAbsent) {
  TempDir dir;
  const std::string head = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n";
  auto r = readText(dir, "d.ply",
                    head + "property uchar diffuse_red\nproperty uchar diffuse_green\nproperty uchar diffuse_blue\n"
                           "property uchar alpha\nend_header\n0 0 0 255 0 51 255\n1 0 0 0 102 0 128\n");
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_TRUE(r->hasColors());
  EXPECT_EQ(r->colors[0], glm::vec3(1.0f, 0.0f, 0.2f));
  EXPECT_EQ(r->colors[1], glm::vec3(0.0f, 0.4f, 0.0f));
  ASSERT_EQ(r->dimensions.count(), 1u);
  EXPECT_EQ(r->dimensions.all()[0].name, "alpha");
  auto both = readText(dir, "both.ply",
                       head + "property float red\nproperty float green\nproperty float blue\nproperty uchar diffuse_red\n"
                              "end_header\n0 0 0 1 0 0 7\n1 0 0 0 1 0 9\n");
  ASSERT_TRUE(both.ok()) << both.error().message;
  EXPECT_EQ(both->colors[1], glm::vec3(0.0f, 1.0f, 0.0f));
  ASSERT_NE(both->dimensions.find("diffuse_red"), nullptr);
  EXPECT_EQ(both->dimensions.find("diffuse_red")->value(1), 9.0);
  // Taken whole only: a lone diffuse_red, or int ones, stay dimensions as before (a review finding:
  // the first version refused them).
  auto half = readText(dir, "half.ply", head + "property uchar diffuse_red\nend_header\n0 0 0 1\n1 0 0 2\n");
  ASSERT_TRUE(half.ok()) << half.error().message;
  EXPECT_FALSE(half->hasColors());
  ASSERT_NE(half->dimensions.find("diffuse_red"), nullptr);
  auto ints = readText(dir, "ints.ply",
                       head + "property int diffuse_red\nproperty int diffuse_green\nproperty int diffuse_blue\n"
                              "end_header\n0 0 0 5 7 9\n1 0 0 100 1000 3\n");
  ASSERT_TRUE(ints.ok()) << ints.error().message;
  EXPECT_FALSE(ints->hasColors());
  EXPECT_EQ(ints->dimensions.count(), 3u);
  // Written and read back, they stay dimensions; beside colours they keep their names too.
  ASSERT_TRUE(writePly(dir.file("ints-out.ply"), *ints, PlyWriteOptions{}).ok());
  auto back = readPly(dir.file("ints-out.ply"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_FALSE(back->hasColors());
  ASSERT_EQ(back->dimensions.count(), 3u);
  EXPECT_EQ(back->dimensions.all()[1].value(1), 1000.0);
  // int ones read back as dimensions anyway: their names are kept (the first renaming version
  // renamed them too, a review finding).
  EXPECT_NE(back->dimensions.find("diffuse_green"), nullptr);
  EXPECT_EQ(readFile(dir.file("ints-out.ply")).find("diffuse_green_2"), std::string::npos);
  // Three of a colour's type are renamed, judged by the names as written: "diffuse blue" is written
  // diffuse_blue (the first version judged the names before that, a review finding).
  PointSet floats;
  floats.positions = {glm::dvec3(1, 2, 3)};
  for (const char* name : {"diffuse_red", "diffuse_green", "diffuse blue"})
    floats.dimensions.add(name, DimType::kF32, 1).setValue(0, 0.25);
  std::vector<std::string> notices;
  PlyWriteOptions noted;
  noted.notices = &notices;
  ASSERT_TRUE(writePly(dir.file("floats.ply"), floats, noted).ok());
  auto floats_back = readPly(dir.file("floats.ply"));
  ASSERT_TRUE(floats_back.ok()) << floats_back.error().message;
  EXPECT_FALSE(floats_back->hasColors());
  EXPECT_EQ(floats_back->dimensions.count(), 3u);
  EXPECT_EQ(notices.size(), 3u);
  PointSet coloured = *ints;
  coloured.colors.assign(coloured.size(), glm::vec3(0.5f));
  ASSERT_TRUE(writePly(dir.file("coloured.ply"), coloured, PlyWriteOptions{}).ok());
  auto kept = readPly(dir.file("coloured.ply"));
  ASSERT_TRUE(kept.ok()) << kept.error().message;
  ASSERT_NE(kept->dimensions.find("diffuse_green"), nullptr);
  EXPECT_EQ(kept->dimensions.find("diffuse_green")->value(1), 1000.0);
  // Binary rows, and the stream, take them too.
  PointSet set;
  set.positions = {glm::dvec3(1, 2, 3)};
  set.colors = {glm::vec3(1.0f, 0.0f, 0.2f)};
  ASSERT_TRUE(writePly(dir.file("b.ply"), set, PlyWriteOptions{}).ok());
  std::string bytes = test::readFile(dir.file("b.ply"));
  for (const char* name : {"red", "green", "blue"}) {
    const std::string from = std::string("property uchar ") + name + "\n";
    bytes.replace(bytes.find(from), from.size(), std::string("property uchar diffuse_") + name + "\n");
  }
  test::writeFile(dir.file("db.ply"), bytes);
  auto binary = readPly(dir.file("db.ply"));
  ASSERT_TRUE(binary.ok()) << binary.error().message;
  EXPECT_EQ(binary->colors, set.colors);
  auto stream = PlyVertexStream::open(dir.file("db.ply"));
  ASSERT_TRUE(stream.ok()) << stream.error().message;
  EXPECT_TRUE((*stream)->hasColors());
}

// A binary little-endian PLY's bytes as binary_big_endian: every value wider than a byte reversed,
// walking the header's elements (fixed properties and lists alike).
std::string asBigEndian(const std::string& little) {
  const size_t end = little.find("end_header\n") + 11;
  std::string header = little.substr(0, end);
  header.replace(header.find("binary_little_endian"), 20, "binary_big_endian");
  const auto size = [](const std::string& type) -> size_t {
    if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
    if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
    if (type == "double" || type == "float64") return 8;
    return 4;
  };
  struct Property {
    size_t count_size = 0, size = 0;  // count_size: a list's
  };
  std::vector<std::pair<uint64_t, std::vector<Property>>> elements;
  std::istringstream lines(little.substr(0, end));
  for (std::string line; std::getline(lines, line);) {
    std::istringstream w(line);
    std::string key, a, b, c;
    w >> key >> a >> b >> c;
    if (key == "element") elements.push_back({std::stoull(b), {}});
    if (key == "property") elements.back().second.push_back(a == "list" ? Property{size(b), size(c)} : Property{0, size(a)});
  }
  std::string body = little.substr(end);
  size_t at = 0;
  for (const auto& [count, properties] : elements)
    for (uint64_t r = 0; r < count; ++r)
      for (const Property& p : properties) {
        uint64_t items = 1;
        if (p.count_size) {
          items = static_cast<uint8_t>(body[at]);  // one-byte counts, as dpoint writes them
          at += p.count_size;
        }
        for (uint64_t i = 0; i < items; ++i, at += p.size) std::reverse(body.begin() + at, body.begin() + at + p.size);
      }
  EXPECT_EQ(at, body.size());
  return header + body;
}

// binary_big_endian (older tools' and hosts' files) reads as the same file in little-endian order
// does: positions, colours of each width, dimensions of every type, triangles; whole, streamed,
// and through the row-by-row path of a vertex with a list. The build before refused it.
TEST(Ply, bigEndianBinaryReadsAsLittleEndianDoes) {
  TempDir dir;
  PointSet set;
  set.positions = {glm::dvec3(1.5, -2.25, 6378137.125), glm::dvec3(0.1, 0.2, 0.3), glm::dvec3(-1e300, 4, 5),
                   glm::dvec3(7, 8, 9)};
  set.colors = {glm::vec3(1, 0, 0.2f), glm::vec3(0, 0.4f, 1), glm::vec3(0.6f, 0.8f, 0), glm::vec3(1, 1, 1)};
  set.triangles = {0, 1, 2, 1, 2, 3};
  for (DimType type : {DimType::kU8, DimType::kI16, DimType::kU16, DimType::kI32, DimType::kU32, DimType::kF32,
                       DimType::kF64}) {
    std::string name = "d";  // appended: GCC 12 warns falsely on "d" + string (bug 105651)
    name += std::to_string(static_cast<int>(type));
    Dimension& d = set.dimensions.add(name, type, set.size());
    for (size_t i = 0; i < set.size(); ++i) d.setValue(i, 100.0 * static_cast<double>(i) + 7.0);
  }
  for (PlyColorType colours : {PlyColorType::kUchar, PlyColorType::kUshort, PlyColorType::kFloat}) {
    SCOPED_TRACE(static_cast<int>(colours));
    PlyWriteOptions options;
    options.color_type = colours;
    ASSERT_TRUE(writePly(dir.file("le.ply"), set, options).ok());
    writeFile(dir.file("be.ply"), asBigEndian(readFile(dir.file("le.ply"))));
    auto le = readPly(dir.file("le.ply"));
    auto be = readPly(dir.file("be.ply"));
    ASSERT_TRUE(le.ok()) << le.error().message;
    ASSERT_TRUE(be.ok()) << be.error().message;
    EXPECT_EQ(be->positions, le->positions);
    EXPECT_EQ(be->colors, le->colors);
    EXPECT_EQ(be->triangles, le->triangles);
    ASSERT_EQ(be->dimensions.count(), le->dimensions.count());
    for (size_t k = 0; k < le->dimensions.count(); ++k) EXPECT_EQ(be->dimensions.all()[k].bytes, le->dimensions.all()[k].bytes) << k;
    auto stream = PlyVertexStream::open(dir.file("be.ply"));
    ASSERT_TRUE(stream.ok()) << stream.error().message;
    PointSet block;
    ASSERT_TRUE((*stream)->read(1, 3, block).ok());
    EXPECT_EQ(block.positions, PositionArray(le->positions.begin() + 1, le->positions.end()));
    EXPECT_EQ(block.colors, ColorArray(le->colors.begin() + 1, le->colors.end()));
  }
  // A vertex with a list property goes row by row: its values too.
  const std::string listed = "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty double x\n"
                             "property list uchar int extra\nproperty float y\nproperty double z\nend_header\n";
  std::string row(8 + 1 + 8 + 4 + 8, '\0');
  const double x = 6378137.5, z = -0.125;
  const float y = 3.75f;
  const int32_t extra[2] = {-5, 9};
  std::memcpy(&row[0], &x, 8);
  row[8] = 2;
  std::memcpy(&row[9], extra, 8);
  std::memcpy(&row[17], &y, 4);
  std::memcpy(&row[21], &z, 8);
  writeFile(dir.file("list-be.ply"), asBigEndian(listed + row));
  auto listed_be = readPly(dir.file("list-be.ply"));
  ASSERT_TRUE(listed_be.ok()) << listed_be.error().message;
  EXPECT_EQ(listed_be->positions[0], glm::dvec3(x, 3.75, z));
}

TEST(Ply, plyRejectsTruncatedBinary) {
  TempDir dir;
  PointSet in = awkwardPoints();
  in.colors.assign(in.size(), glm::vec3(0.5f));
  ASSERT_TRUE(writePly(dir.file("whole.ply"), in).ok());
  const std::string bytes = readFile(dir.file("whole.ply"));
  // Cut inside the fifth vertex (27 bytes a row).
  const size_t header = bytes.find("end_header\n") + 11;
  const size_t cut = header + 4 * 27 + 10;
  auto r = readText(dir, "cut.ply", bytes.substr(0, cut));
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "cut.ply: truncated at byte " + std::to_string(cut)));
  EXPECT_TRUE(contains(r.error().message,
                       "header line 4 declares 13 'vertex' rows, needing at least 351 bytes of data, but only 118"));
}

TEST(Ply, plyRejectsTruncatedFaceList) {
  TempDir dir;
  PointSet in;
  in.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  in.triangles = {0, 1, 2, 2, 1, 0};
  ASSERT_TRUE(writePly(dir.file("mesh.ply"), in).ok());
  const std::string bytes = readFile(dir.file("mesh.ply"));
  auto r = readText(dir, "mesh_cut.ply", bytes.substr(0, bytes.size() - 2));
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "mesh_cut.ply: truncated at byte " + std::to_string(bytes.size() - 2)));
  EXPECT_TRUE(contains(r.error().message, "'face' rows, the data ends in row 1"));
}

TEST(Ply, plyRejectsTruncatedAscii) {
  TempDir dir;
  auto r = readText(dir, "short.ply", std::string(kAsciiHeader) + "1.5 2.5 3.5\n4 5\n");
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "short.ply: line 9: vertex 1: missing value for 'z'"));
  auto lines = readText(dir, "lines.ply", std::string(kAsciiHeader) + "1 2 3\n\n\n\n\n\n\n\n");
  ASSERT_FALSE(lines.ok());
  EXPECT_TRUE(contains(lines.error().message, "lines.ply: line"));
  EXPECT_TRUE(contains(lines.error().message, "the file ends after 1 of 2 'vertex' rows"));
}

TEST(Ply, plyRejectsMalformedAsciiNumber) {
  TempDir dir;
  auto r = readText(dir, "bad.ply", std::string(kAsciiHeader) + "1 2 3\n4 5,0 6\n");
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "bad.ply: line 9: vertex 1: 'y': '5,0' is not a valid double"));
  auto range = readText(dir, "range.ply",
                        "ply\nformat ascii 1.0\nelement vertex 1\nproperty double x\nproperty double y\n"
                        "property double z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
                        "end_header\n1 2 3 0 256 0\n");
  ASSERT_FALSE(range.ok());
  EXPECT_TRUE(contains(range.error().message, "range.ply: line 11: vertex 0: 'green': '256' is not a valid uchar"));
  auto extra = readText(dir, "extra.ply", std::string(kAsciiHeader) + "1 2 3 4\n5 6 7\n");
  ASSERT_FALSE(extra.ok());
  EXPECT_TRUE(
      contains(extra.error().message, "extra.ply: line 8: vertex 0: more values than the header declares, '4'"));
}

TEST(Ply, plyRejectsDataAfterLastElement) {
  TempDir dir;
  auto r = readText(dir, "more.ply", std::string(kAsciiHeader) + "1 2 3\n4 5 6\n7 8 9\n");
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "more.ply: line 10: data after the last element"));
  Bytes b;
  b.data =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n";
  const size_t end = b.data.size() + 12;
  b.add(1.0f).add(2.0f).add(3.0f).add(4.0f);
  auto binary = readText(dir, "more_bin.ply", b.data);
  ASSERT_FALSE(binary.ok());
  EXPECT_TRUE(
      contains(binary.error().message, "more_bin.ply: byte " + std::to_string(end) + ": 4 bytes of data after"));
}

TEST(Ply, plyRejectsIndexOutOfRange) {
  TempDir dir;
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\n"
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
  auto r = readText(dir, "mesh.ply", header + "3 0 1 2\n3 0 1 3\n");
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(
      contains(r.error().message, "mesh.ply: line 14: face 1: vertex index 3 out of range (the file has 3 vertices)"));
  auto negative = readText(dir, "neg.ply", header + "3 0 -1 2\n3 0 1 2\n");
  ASSERT_FALSE(negative.ok());
  EXPECT_TRUE(contains(negative.error().message, "neg.ply: line 13: face 0: vertex index -1 out of range"));

  Bytes b;
  b.data =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty double x\nproperty double y\n"
      "property double z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n";
  b.add(0.0).add(0.0).add(0.0);
  const size_t face_at = b.data.size();
  b.add(uint8_t{3}).add(uint32_t{0}).add(uint32_t{0}).add(uint32_t{4000000000u});
  auto binary = readText(dir, "mesh_bin.ply", b.data);
  ASSERT_FALSE(binary.ok());
  EXPECT_TRUE(contains(binary.error().message, "mesh_bin.ply: byte " + std::to_string(face_at) +
                                                   ": face 0: vertex index 4000000000 out of range"));
}

// Binary triangles (a uchar count of 3, 32-bit indices) are read in parallel blocks of about 80K
// rows, up to the first row that is another polygon or names no vertex; the rows after are read one
// at a time as before. Over several blocks and thread counts: the same triangles, a quad's fan, and
// each error at its row and byte.
// A binary PLY's header for `faces` rows of uchar-counted `index_type` lists, and its `vertices`
// rows (v, 0.5, −1): the start of the face-block tests' files.
Bytes facesFileStart(const std::string& index_type, uint32_t vertices, uint64_t faces) {
  Bytes b;
  b.data = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(vertices) +
           "\nproperty double x\nproperty double y\nproperty double z\nelement face " + std::to_string(faces) +
           "\nproperty list uchar " + index_type + " vertex_indices\nend_header\n";
  for (uint32_t v = 0; v < vertices; ++v) b.add(double(v)).add(0.5).add(-1.0);
  return b;
}
// Face row r's four corners in those files.
std::array<uint32_t, 4> cornersOf(uint64_t r, uint32_t vertices) {
  const auto at = [&](uint64_t k) { return static_cast<uint32_t>((r + k) % vertices); };
  return {at(0), at(1), at(7), at(3)};
}

// Faces of another size than three, every row like the first (a quad mesh): read in blocks too,
// each fanned as the row-by-row loop fans it, up to the first row of another size or a bad index.
TEST(Ply, binaryQuadsAreReadInBlocksUpToTheFirstOtherRow) {
  TempDir dir;
  static constexpr uint32_t kVertices = 1000;
  static constexpr uint64_t kFaces = 200000;  // four blocks of 17-byte rows
  auto file = [&](uint64_t triangle_row, uint64_t bad_row, std::vector<uint32_t>& expected, size_t& faces_at) {
    Bytes b = facesFileStart("uint", kVertices, kFaces);
    faces_at = b.data.size();
    expected.clear();
    for (uint64_t r = 0; r < kFaces; ++r) {
      const auto [a, c, d, e] = cornersOf(r, kVertices);
      if (r == triangle_row) {
        b.add(uint8_t{3}).add(a).add(c).add(d);
        expected.insert(expected.end(), {a, c, d});
      } else {
        b.add(uint8_t{4}).add(a).add(c).add(r == bad_row ? kVertices + 2 : d).add(e);
        expected.insert(expected.end(), {a, c, d, a, d, e});
      }
    }
    return b.data;
  };
  std::vector<uint32_t> expected;
  size_t faces_at = 0;
  for (unsigned threads : {1u, 2u, 4u}) {
    SCOPED_TRACE(threads);
    auto quads = readText(dir, "quads.ply", file(UINT64_MAX, UINT64_MAX, expected, faces_at), withThreads(threads));
    ASSERT_TRUE(quads.ok()) << quads.error().message;
    EXPECT_EQ(quads->triangles.size(), 6 * kFaces);
    EXPECT_TRUE(quads->triangles == expected);
    auto mixed = readText(dir, "mixed.ply", file(150000, UINT64_MAX, expected, faces_at), withThreads(threads));
    ASSERT_TRUE(mixed.ok()) << mixed.error().message;
    EXPECT_TRUE(mixed->triangles == expected);
    auto bad = readText(dir, "bad.ply", file(UINT64_MAX, 170000, expected, faces_at), withThreads(threads));
    ASSERT_FALSE(bad.ok());
    EXPECT_TRUE(contains(bad.error().message, "bad.ply: byte " + std::to_string(faces_at + 170000 * 17) +
                                                  ": face 170000: vertex index 1002 out of range"))
        << bad.error().message;
  }
}

TEST(Ply, binaryTrianglesAreReadInBlocksUpToTheFirstOtherRow) {
  TempDir dir;
  static constexpr uint32_t kVertices = 1000;
  static constexpr uint64_t kFaces = 300000;  // four blocks
  auto file = [&](const char* index_type, uint64_t quad_row, uint64_t bad_row, int64_t bad_index,
                  std::vector<uint32_t>& expected, size_t& faces_at) {
    Bytes b = facesFileStart(index_type, kVertices, kFaces);
    faces_at = b.data.size();
    expected.clear();
    for (uint64_t r = 0; r < kFaces; ++r) {
      const auto [a, c, d, e] = cornersOf(r, kVertices);
      if (r == quad_row) {
        b.add(uint8_t{4}).add(a).add(c).add(d).add(e);
        expected.insert(expected.end(), {a, c, d, a, d, e});
      } else if (r == bad_row) {
        b.add(uint8_t{3}).add(a).add(static_cast<uint32_t>(bad_index)).add(d);
      } else {
        b.add(uint8_t{3}).add(a).add(c).add(d);
        expected.insert(expected.end(), {a, c, d});
      }
    }
    return b.data;
  };
  std::vector<uint32_t> expected;
  size_t faces_at = 0;
  for (unsigned threads : {1u, 2u, 4u}) {
    PlyReadOptions options;
    options.threads = threads;
    for (const char* type : {"int", "uint"}) {
      auto plain = readText(dir, "tri.ply", file(type, UINT64_MAX, UINT64_MAX, 0, expected, faces_at), options);
      ASSERT_TRUE(plain.ok()) << plain.error().message;
      EXPECT_EQ(plain->triangles, expected) << type << ", " << threads << " threads";
      auto quad = readText(dir, "quad.ply", file(type, 200000, UINT64_MAX, 0, expected, faces_at), options);
      ASSERT_TRUE(quad.ok()) << quad.error().message;
      EXPECT_EQ(quad->triangles.size(), 3 * (kFaces + 1));
      EXPECT_EQ(quad->triangles, expected) << type << ", " << threads << " threads";
      auto far = readText(dir, "far.ply", file(type, UINT64_MAX, 250000, kVertices, expected, faces_at), options);
      ASSERT_FALSE(far.ok());
      EXPECT_TRUE(contains(far.error().message, "far.ply: byte " + std::to_string(faces_at + 250000 * 13) +
                                                    ": face 250000: vertex index 1000 out of range (the file has 1000 vertices)"))
          << far.error().message;
    }
    auto negative = readText(dir, "neg.ply", file("int", 100, 123456, -1, expected, faces_at), options);
    ASSERT_FALSE(negative.ok());
    EXPECT_TRUE(contains(negative.error().message, "neg.ply: byte " + std::to_string(faces_at + 123456 * 13 + 4) +
                                                       ": face 123456: vertex index -1 out of range"))
        << negative.error().message;
    std::string cut = file("uint", UINT64_MAX, UINT64_MAX, 0, expected, faces_at);
    cut.resize(cut.size() - 5);
    auto truncated = readText(dir, "cut.ply", cut, options);
    ASSERT_FALSE(truncated.ok());
    EXPECT_TRUE(contains(truncated.error().message, "cut.ply: truncated at byte " + std::to_string(cut.size()) +
                                                        ": expected 300000 'face' rows, the data ends in row 299999"))
        << truncated.error().message;
  }
}

// A renderer asks for points only: the vertices and colours come back, and reading stops before
// the faces (a bad index there goes unseen, as the option says).
TEST(Ply, pointsOnlyStopsAfterTheVertices) {
  TempDir dir;
  PointSet in;
  in.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  in.colors = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  in.triangles = {0, 1, 2};
  ASSERT_TRUE(writePly(dir.file("mesh.ply"), in).ok());
  PlyReadOptions options;
  options.points_only = true;
  Result<PointSet> points = readPly(dir.file("mesh.ply"), options);
  ASSERT_TRUE(points.ok()) << points.error().message;
  EXPECT_EQ(points->positions, in.positions);
  EXPECT_EQ(points->colors, in.colors);
  EXPECT_TRUE(points->triangles.empty());
  Result<PointSet> whole = readPly(dir.file("mesh.ply"));
  ASSERT_TRUE(whole.ok());
  EXPECT_EQ(whole->triangles, in.triangles);

  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";
  const std::string path = dir.file("bad_face.ply");
  writeFile(path, header);
  EXPECT_FALSE(readPly(path).ok());
  Result<PointSet> vertices = readPly(path, options);
  ASSERT_TRUE(vertices.ok()) << vertices.error().message;
  EXPECT_EQ(vertices->size(), 3u);
}

TEST(Ply, plyRejectsFaceWithTwoVertices) {
  TempDir dir;
  auto r = readText(dir, "line.ply",
                    "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\nproperty double y\nproperty double z\n"
                    "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n2 0 1\n");
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "line.ply: line 12: face 0 has 2 vertices; a face needs at least 3"));
}

TEST(Ply, plyRejectsNanWithLine) {
  TempDir dir;
  auto r = readText(dir, "nan.ply", std::string(kAsciiHeader) + "1 2 3\n4 nan 6\n");
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "nan.ply: line 9: vertex 1: y is nan, not a finite number"));
  auto overflow = readText(dir, "big.ply", std::string(kAsciiHeader) + "1e400 2 3\n4 5 6\n");
  ASSERT_FALSE(overflow.ok());
  EXPECT_TRUE(contains(overflow.error().message, "big.ply: line 8: vertex 0: x is inf"));
}

TEST(Ply, plyRejectsNonfiniteBinaryWithOffset) {
  TempDir dir;
  PointSet in;
  in.positions = {{1, 2, 3}, {4, 5, -std::numeric_limits<double>::infinity()}};
  ASSERT_TRUE(writePly(dir.file("inf.ply"), in).ok());
  auto r = readPly(dir.file("inf.ply"));
  ASSERT_FALSE(r.ok());
  const size_t row = readFile(dir.file("inf.ply")).find("end_header\n") + 11 + 24;
  EXPECT_TRUE(contains(r.error().message, "inf.ply: byte " + std::to_string(row) + ": vertex 1: z is -inf"));
  PlyReadOptions allow;
  allow.allow_nonfinite = true;
  auto ok = readPly(dir.file("inf.ply"), allow);
  ASSERT_TRUE(ok.ok()) << ok.error().message;
  EXPECT_TRUE(std::isinf(ok->positions[1].z));

  // Float rows take the general path, which must check as well.
  Bytes b;
  b.data =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n";
  const size_t third = b.data.size() + 24;
  b.add(1.0f).add(2.0f).add(3.0f).add(4.0f).add(5.0f).add(6.0f);
  b.add(std::numeric_limits<float>::quiet_NaN()).add(0.0f).add(0.0f);
  auto f = readText(dir, "nan_float.ply", b.data);
  ASSERT_FALSE(f.ok());
  EXPECT_TRUE(contains(f.error().message, "nan_float.ply: byte " + std::to_string(third) + ": vertex 2: x is nan"));
}

TEST(Ply, plyRejectsHugeElementCountWithoutAllocating) {
  TempDir dir;
  // Reserving these rows would need ~10^19 bytes: the check against the file size must come first.
  const std::string huge =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000000000\nproperty double x\n"
      "property double y\nproperty double z\nend_header\n0123456789";
  auto r = readText(dir, "huge.ply", huge);
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "huge.ply: truncated at byte " + std::to_string(huge.size()) +
                                              ": header line 3 declares 1000000000000000000 'vertex' rows, "
                                              "needing at least 2^64 bytes of data, but only 10 follow"));
  const std::string many_faces =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty double x\nproperty double y\n"
      "property double z\nelement face 18446744073709551615\nproperty list uchar int vertex_indices\n"
      "end_header\n1 2 3\n3 0 0 0\n";
  auto faces = readText(dir, "faces.ply", many_faces);
  ASSERT_FALSE(faces.ok());
  EXPECT_TRUE(contains(faces.error().message, "faces.ply: truncated at byte " + std::to_string(many_faces.size()) +
                                                  ": header line 7 declares 18446744073709551615 'face' rows"));
  auto overflow =
      readText(dir, "count.ply", "ply\nformat ascii 1.0\nelement vertex 99999999999999999999\nend_header\n");
  ASSERT_FALSE(overflow.ok());
  EXPECT_TRUE(contains(overflow.error().message, "count.ply: header line 3: bad element count '99999999999999999999'"));
}

TEST(Ply, plyFailedWriteLeavesNothing) {
  TempDir dir;
  PointSet in = awkwardPoints();
  const std::string path = dir.file("missing/out.ply");
  Status s = writePly(path, in);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.error().message, path));
  EXPECT_TRUE(dir.entries().empty());

  in.triangles = {0, 1, 99};
  Status bad = writePly(dir.file("bad.ply"), in);
  ASSERT_FALSE(bad.ok());
  EXPECT_TRUE(contains(bad.error().message, "bad.ply"));
  EXPECT_TRUE(contains(bad.error().message, "triangle index 99 out of range"));
  EXPECT_TRUE(dir.entries().empty());
}

// ---------------------------------------------------------------- streamed vertices

// dpoint render of a file larger than memory: any range, read in any order of ranges, holds the
// rows readPly reads, with colours, for any thread count.
TEST(Ply, plyVertexStreamReadsAnyRangeAsReadPlyDoes) {
  TempDir dir;
  const PointSet in = randomPoints(kManyBlocksOf27, 11);  // with colours: 27-byte rows
  ASSERT_TRUE(writePly(dir.file("s.ply"), in).ok());
  auto whole = readPly(dir.file("s.ply"));
  ASSERT_TRUE(whole.ok()) << whole.error().message;
  for (unsigned threads : {1u, 3u}) {
    auto stream = PlyVertexStream::open(dir.file("s.ply"), withThreads(threads));
    ASSERT_TRUE(stream.ok()) << stream.error().message;
    EXPECT_EQ((*stream)->count(), in.size());
    EXPECT_TRUE((*stream)->hasColors());
    PointSet block, expected;
    for (auto [first, n] : {std::pair<size_t, size_t>{0, 1}, {0, 100000}, {99999, 70001}, {in.size() - 3, 3},
                            {12345, 0}}) {
      SCOPED_TRACE(std::to_string(first) + "+" + std::to_string(n));
      ASSERT_TRUE((*stream)->read(first, n, block).ok());
      expected.positions.assign(whole->positions.begin() + std::ptrdiff_t(first),
                                whole->positions.begin() + std::ptrdiff_t(first + n));
      expected.colors.assign(whole->colors.begin() + std::ptrdiff_t(first),
                             whole->colors.begin() + std::ptrdiff_t(first + n));
      expectSamePositions(expected, block);
      expectSameColors(expected, block);
    }
  }
  // A file larger than the memory limit is what a stream is for: it opens and reads where readPly
  // refuses (the stream took readPly's memory check and refused a PLY of 3e9 points).
  PlyReadOptions small = withThreads(1);
  small.max_memory = 1 << 20;
  EXPECT_FALSE(readPly(dir.file("s.ply"), small).ok());
  auto stream = PlyVertexStream::open(dir.file("s.ply"), small);
  ASSERT_TRUE(stream.ok()) << stream.error().message;
  PointSet block;
  ASSERT_TRUE((*stream)->read(in.size() - 10, 10, block).ok());
  EXPECT_EQ(block.positions.back(), in.positions.back());
}

// Its errors are readPly's, with whole-file row numbers and byte offsets.
TEST(Ply, plyVertexStreamNamesBadRowsAndRefusesWhatCannotBeStreamed) {
  TempDir dir;
  PointSet in = randomPoints(kManyBlocksOf27, 12);
  in.positions[150001].y = std::numeric_limits<double>::infinity();
  ASSERT_TRUE(writePly(dir.file("bad.ply"), in).ok());
  const size_t header = readFile(dir.file("bad.ply")).find("end_header\n") + 11;
  auto stream = PlyVertexStream::open(dir.file("bad.ply"));
  ASSERT_TRUE(stream.ok()) << stream.error().message;
  PointSet block;
  EXPECT_TRUE((*stream)->read(0, 150000, block).ok());
  Status bad = (*stream)->read(150000, 10, block);
  ASSERT_FALSE(bad.ok());
  EXPECT_TRUE(contains(bad.error().message, "bad.ply: byte " + std::to_string(header + 150001 * 27) +
                                                ": vertex 150001: y is inf, not a finite number"));
  // ASCII rows have no fixed offsets, nor have vertices after a list element.
  writeFile(dir.file("a.ply"), std::string(kAsciiHeader) + "1 2 3\n4 5 6\n");
  auto ascii = PlyVertexStream::open(dir.file("a.ply"));
  ASSERT_FALSE(ascii.ok());
  EXPECT_TRUE(contains(ascii.error().message, "a.ply: an ASCII PLY file cannot be streamed"));
  Bytes b;
  b.data = "ply\nformat binary_little_endian 1.0\nelement note 1\nproperty list uchar uchar text\n"
           "element vertex 1\nproperty double x\nproperty double y\nproperty double z\nend_header\n";
  b.add(uint8_t{1}).add(uint8_t{65}).add(1.0).add(2.0).add(3.0);
  writeFile(dir.file("list.ply"), b.data);
  auto listed = PlyVertexStream::open(dir.file("list.ply"));
  ASSERT_FALSE(listed.ok());
  EXPECT_TRUE(contains(listed.error().message, "list.ply: element 'note' (header line 3) has list rows before"));
  // A header check of readPly's: counts beyond the file.
  writeFile(dir.file("short.ply"), "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n"
                                   "property double x\nproperty double y\nproperty double z\nend_header\n");
  auto huge = PlyVertexStream::open(dir.file("short.ply"));
  ASSERT_FALSE(huge.ok());
  EXPECT_TRUE(contains(huge.error().message, "short.ply: truncated at byte"));
}


// PlyRowStream: the rows of writePly's file fed back in uneven pieces make writePly's file again,
// whatever counts the header was laid out for (the vertex rows are moved where the digits differ).
TEST(Ply, rowStreamWritesWritePlysFileWhateverTheEstimate) {
  TempDir dir;
  for (const bool colors : {true, false}) {
    for (const bool planar : {false, true}) {
      PointSet mesh;
      const size_t n = 1000;
      for (size_t i = 0; i < n; ++i) {
        const double t = static_cast<double>(i);
        mesh.positions.push_back({std::sin(t) * 1e6, t * 0.1 - 3.0, planar ? 0.0 : std::cos(t) + 1e-300});
        if (colors) mesh.colors.push_back({std::fmod(t * 0.37f, 1.3f) - 0.1f, 0.5f, 1.0f});
      }
      for (uint32_t f = 0; f + 2 < n; ++f)
        for (uint32_t k : {f, f + 2, f + 1}) mesh.triangles.push_back(k);
      ASSERT_TRUE(writePly(dir.file("want.ply"), mesh).ok());
      const std::string want = readFile(dir.file("want.ply"));
      const size_t header = want.find("end_header\n") + 11;
      const size_t row_bytes = colors ? 27 : 24, faces = mesh.triangles.size() / 3;
      ASSERT_EQ(want.size(), header + n * row_bytes + faces * PlyRowStream::kFaceRowBytes);
      const auto* rows = reinterpret_cast<const uint8_t*>(want.data() + header);
      const auto* face_rows = rows + n * row_bytes;
      struct Estimate {
        uint64_t vertices, faces;
        bool moved;
      };
      for (const Estimate e : {Estimate{n, faces, false}, Estimate{1234, 567, false}, Estimate{n / 20, faces / 20, true},
                               Estimate{n * 20, faces, true}, Estimate{0, 0, true}}) {
        SCOPED_TRACE(std::to_string(colors) + " " + std::to_string(planar) + " " + std::to_string(e.vertices) + " " +
                     std::to_string(e.faces));
        std::filesystem::remove(dir.file("got.ply"));
        Result<std::unique_ptr<PlyRowStream>> stream = PlyRowStream::create(dir.file("got.ply"), colors, 3, nullptr);
        ASSERT_TRUE(stream.ok() && *stream);
        ASSERT_TRUE((*stream)->start(e.vertices, e.faces).ok());
        // Pieces of 0, 1, 300 and the rest of the vertices, with a third of the faces each.
        size_t v = 0, f = 0;
        for (const size_t piece : {size_t{0}, size_t{1}, size_t{300}, n - 301}) {
          const size_t fs = piece == n - 301 ? faces - f : faces / 3;
          ASSERT_TRUE((*stream)
                          ->add({rows + v * row_bytes, piece * row_bytes},
                                {face_rows + f * PlyRowStream::kFaceRowBytes, fs * PlyRowStream::kFaceRowBytes})
                          .ok());
          v += piece;
          f += fs;
        }
        EXPECT_FALSE(std::filesystem::exists(dir.file("got.ply")));  // nothing before finish
        ASSERT_TRUE((*stream)->finish().ok());
        const bool moved = plyHeader(PointSet(), e.vertices, e.faces, colors, true, {}).size() !=
                           plyHeader(PointSet(), n, faces, colors, !planar, {}).size();
        EXPECT_EQ(moved, e.moved || planar);  // the cases are what they say
        EXPECT_EQ((*stream)->moved(), moved);
        EXPECT_EQ((*stream)->vertices(), n);
        EXPECT_EQ((*stream)->faces(), faces);
        EXPECT_TRUE(readFile(dir.file("got.ply")) == want);
      }
    }
  }
}

// A stream that is not finished leaves no file.
TEST(Ply, rowStreamAbandonedLeavesNothing) {
  TempDir dir;
  {
    Result<std::unique_ptr<PlyRowStream>> stream = PlyRowStream::create(dir.file("x.ply"), false, 0, nullptr);
    ASSERT_TRUE(stream.ok() && *stream);
    ASSERT_TRUE((*stream)->start(10, 10).ok());
    const std::vector<uint8_t> rows(24 * 3, 0);
    ASSERT_TRUE((*stream)->add(rows, {}).ok());
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("x.ply")));
  // A pipe or a device takes no positional writes: no stream.
  Result<std::unique_ptr<PlyRowStream>> null = PlyRowStream::create("/dev/null", false, 0, nullptr);
  ASSERT_TRUE(null.ok());
  EXPECT_EQ(null->get(), nullptr);
}

}  // namespace
}  // namespace dpoint
