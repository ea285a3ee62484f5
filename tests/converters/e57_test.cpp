// ASTM E57 files (converters/e57.h), made here byte by byte as the standard lays them out: pages of
// 1020 bytes and a big-endian CRC-32C, an XML tree, and compressed vectors whose fields are packed
// bit by bit over data packets. libE57Format's own files and readings are the other half of the
// judgement (tests/converters/e57_judged_by_libe57format.py).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "converters/e57.h"
#include "core/dimensions.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::TempDir;
using test::writeFile;

constexpr uint64_t kPage = 1024, kLogical = 1020;

template <typename T>
void put(std::string& s, size_t at, T v) {
  std::memcpy(s.data() + at, &v, sizeof v);
}
template <typename T>
void append(std::string& s, T v) {
  s.append(reinterpret_cast<const char*>(&v), sizeof v);
}

uint64_t physicalOf(uint64_t logical) { return logical / kLogical * kPage + logical % kLogical; }

// Values packed as E57's bitpack codec packs an integer field: `bits` each, least significant bit
// first, value minus the minimum.
std::string packBits(const std::vector<int64_t>& values, int64_t minimum, unsigned bits) {
  std::string out((values.size() * bits + 7) / 8 + 8, '\0');
  uint64_t bit = 0;
  for (int64_t v : values) {
    const uint64_t raw = static_cast<uint64_t>(v) - static_cast<uint64_t>(minimum);
    for (unsigned b = 0; b < bits; ++b, ++bit)
      if ((raw >> b) & 1) out[bit / 8] = static_cast<char>(out[bit / 8] | (1 << (bit % 8)));
  }
  out.resize((values.size() * bits + 7) / 8);
  return out;
}

template <typename T>
std::string packRaw(const std::vector<T>& values) {
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

// A file: its logical bytes (the 48-byte header first), sections appended, then paged.
class E57File {
 public:
  E57File() : logical_(48, '\0') {}

  // A compressed vector section of these packets' bytes as they are.
  uint64_t rawSection(const std::string& packets) {
    align(4);
    const uint64_t start = logical_.size();
    logical_.append(32, '\0');
    logical_[start] = 1;
    logical_ += packets;
    put<uint64_t>(logical_, start + 8, logical_.size() - start);
    put<uint64_t>(logical_, start + 16, physicalOf(start + 32));
    return physicalOf(start);
  }

  // A compressed vector section of `streams` (one per prototype field, in order), each cut into
  // chunks of at most `chunk` bytes a packet; `extra_packets` puts an index packet and an empty
  // packet between the first two data packets; `in_turn` gives each stream's bytes only once the
  // streams before it have given all theirs. Returns its physical offset (the XML's fileOffset).
  uint64_t compressedVector(const std::vector<std::string>& streams, size_t chunk, bool extra_packets = false,
                            bool in_turn = false) {
    align(4);
    const uint64_t start = logical_.size();
    logical_.append(32, '\0');
    logical_[start] = 1;
    const uint64_t data = logical_.size();
    std::vector<size_t> at(streams.size(), 0);
    bool first = true;
    while (true) {
      bool more = false;
      for (size_t k = 0; k < streams.size(); ++k) more = more || at[k] < streams[k].size();
      if (!more) break;
      std::string packet;
      append<uint8_t>(packet, 1);
      append<uint8_t>(packet, 0);
      append<uint16_t>(packet, 0);  // its length, below
      append<uint16_t>(packet, static_cast<uint16_t>(streams.size()));
      std::vector<size_t> n(streams.size());
      size_t turn = 0;
      while (at[turn] == streams[turn].size()) ++turn;
      for (size_t k = 0; k < streams.size(); ++k) {
        n[k] = in_turn && k != turn ? 0 : std::min(chunk, streams[k].size() - at[k]);
        append<uint16_t>(packet, static_cast<uint16_t>(n[k]));
      }
      for (size_t k = 0; k < streams.size(); ++k) {
        packet += streams[k].substr(at[k], n[k]);
        at[k] += n[k];
      }
      while (packet.size() % 4 != 0) packet += '\0';
      put<uint16_t>(packet, 2, static_cast<uint16_t>(packet.size() - 1));
      logical_ += packet;
      if (first && extra_packets) {
        std::string index(32, '\0');  // an index packet of no entries, then an empty packet
        index[0] = 0;
        put<uint16_t>(index, 2, 31);
        logical_ += index;
        std::string empty(8, '\0');
        empty[0] = 2;
        put<uint16_t>(empty, 2, 7);
        logical_ += empty;
      }
      first = false;
    }
    put<uint64_t>(logical_, start + 8, logical_.size() - start);
    put<uint64_t>(logical_, start + 16, physicalOf(data));
    return physicalOf(start);
  }

  // The file's bytes with `xml` as its tree.
  std::string bytes(const std::string& xml) {
    align(4);
    const uint64_t xml_at = logical_.size();
    logical_ += xml;
    while (logical_.size() % kLogical != 0) logical_ += '\0';
    std::memcpy(logical_.data(), "ASTM-E57", 8);
    put<uint32_t>(logical_, 8, 1);
    put<uint32_t>(logical_, 12, 0);
    put<uint64_t>(logical_, 16, logical_.size() / kLogical * kPage);
    put<uint64_t>(logical_, 24, physicalOf(xml_at));
    put<uint64_t>(logical_, 32, xml.size());
    put<uint64_t>(logical_, 40, kPage);
    std::string out;
    for (size_t p = 0; p < logical_.size(); p += kLogical) {
      const std::string page = logical_.substr(p, kLogical);
      out += page;
      append<uint32_t>(out, __builtin_bswap32(crc32c(reinterpret_cast<const uint8_t*>(page.data()), page.size())));
    }
    return out;
  }

 private:
  void align(size_t n) {
    while (logical_.size() % n != 0) logical_ += '\0';
  }
  std::string logical_;
};

std::string scanXml(uint64_t offset, uint64_t records, const std::string& prototype, const std::string& extra = "") {
  return "<vectorChild type=\"Structure\">" + extra + "<points type=\"CompressedVector\" fileOffset=\"" +
         std::to_string(offset) + "\" recordCount=\"" + std::to_string(records) + "\"><prototype type=\"Structure\">" +
         prototype + "</prototype><codecs type=\"Vector\" allowHeterogeneousChildren=\"1\"/></points></vectorChild>";
}

std::string rootXml(const std::string& scans, const std::string& images = "") {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<e57Root type=\"Structure\" "
         "xmlns=\"http://www.astm.org/COMMIT/E57/2010-e57-v1.0\">\n<data3D type=\"Vector\" "
         "allowHeterogeneousChildren=\"1\">" +
         scans + "</data3D>\n<images2D type=\"Vector\" allowHeterogeneousChildren=\"1\">" + images + "</images2D>\n</e57Root>\n";
}

Result<PointSet> readBytes(const TempDir& dir, const std::string& bytes, E57ReadOptions options = {},
                           const std::string& name = "scan.e57") {
  const std::string path = dir.file(name);
  writeFile(path, bytes);
  return readE57(path, options);
}

TEST(E57, crc32cIsCastagnolis) {
  const std::string check = "123456789";  // the CRC catalogue's check value of CRC-32C
  EXPECT_EQ(crc32c(reinterpret_cast<const uint8_t*>(check.data()), check.size()), 0xE3069283u);
  std::string long_text(1000, 'a');
  for (size_t i = 0; i < long_text.size(); ++i) long_text[i] = static_cast<char>(i * 7);
  uint32_t c = 0xFFFFFFFFu;  // bit by bit
  for (char ch : long_text) {
    c ^= static_cast<uint8_t>(ch);
    for (int k = 0; k < 8; ++k) c = (c & 1) ? (c >> 1) ^ 0x82F63B78u : c >> 1;
  }
  EXPECT_EQ(crc32c(reinterpret_cast<const uint8_t*>(long_text.data()), long_text.size()), c ^ 0xFFFFFFFFu);
}

// Fields of 3, 13 and 64 bits and of none, cut into 7-byte chunks so that values straddle packets,
// with an index and an empty packet among the data packets.
TEST(E57, fieldsOfAnyBitWidthDecodeAcrossPackets) {
  TempDir dir;
  const size_t n = 1001;
  std::vector<int64_t> x(n), y(n), z(n), row(n);
  for (size_t i = 0; i < n; ++i) {
    x[i] = static_cast<int64_t>(i % 8) - 5;            // -5 .. 2: 3 bits
    y[i] = static_cast<int64_t>((i * 37) % 8000);      // 0 .. 7999 of 0 .. 8191: 13 bits
    z[i] = i % 2 ? INT64_MIN + static_cast<int64_t>(i) : INT64_MAX - static_cast<int64_t>(i);  // 64 bits
    row[i] = 7;                                        // a constant: 0 bits
  }
  E57File file;
  const uint64_t at = file.compressedVector({packBits(x, -5, 3), packBits(y, 0, 13), packBits(z, INT64_MIN, 64), ""}, 7, true);
  const std::string prototype =
      "<cartesianX type=\"Integer\" minimum=\"-5\" maximum=\"2\"/>"
      "<cartesianY type=\"ScaledInteger\" minimum=\"0\" maximum=\"8191\" scale=\"0.25\" offset=\"100\"/>"
      "<cartesianZ type=\"Integer\"/>"
      "<rowIndex type=\"Integer\" minimum=\"7\" maximum=\"7\"/>";
  Result<PointSet> points = readBytes(dir, file.bytes(rootXml(scanXml(at, n, prototype))));
  ASSERT_TRUE(points.ok()) << points.error().message;
  ASSERT_EQ(points->size(), n);
  const Dimension* r = points->dimensions.find("rowIndex");
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->type, DimType::kU8);
  for (size_t i = 0; i < n; ++i) {
    ASSERT_EQ(points->positions[i].x, static_cast<double>(x[i])) << i;
    ASSERT_EQ(points->positions[i].y, static_cast<double>(y[i]) * 0.25 + 100) << i;
    ASSERT_EQ(points->positions[i].z, static_cast<double>(z[i])) << i;
    ASSERT_EQ(r->value(i), 7.0);
  }
}

TEST(E57, theThreadCountDoesNotChangeThePoints) {
  TempDir dir;
  const size_t n = 200000;  // several decode blocks
  std::vector<double> x(n), y(n), z(n);
  for (size_t i = 0; i < n; ++i) {
    x[i] = 512345.678 + 1e-3 * static_cast<double>(i);
    y[i] = std::sin(static_cast<double>(i));
    z[i] = -static_cast<double>(i);
  }
  E57File file;
  const uint64_t at = file.compressedVector({packRaw(x), packRaw(y), packRaw(z)}, 20000);
  const std::string bytes = file.bytes(rootXml(scanXml(
      at, n, "<cartesianX type=\"Float\"/><cartesianY type=\"Float\" precision=\"double\"/><cartesianZ type=\"Float\"/>",
      "<pose type=\"Structure\"><rotation type=\"Structure\"><w type=\"Float\">2</w><x type=\"Float\"/><y "
      "type=\"Float\"/><z type=\"Float\"/></rotation></pose>")));
  E57ReadOptions one;
  one.threads = 1;
  Result<PointSet> a = readBytes(dir, bytes, one);
  E57ReadOptions three;
  three.threads = 3;
  Result<PointSet> b = readBytes(dir, bytes, three);
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a->size(), n);
  ASSERT_EQ(b->size(), n);
  // A rotation of (2, 0, 0, 0) is the identity once made a unit quaternion: every double as written.
  EXPECT_EQ(std::memcmp(a->positions.data(), b->positions.data(), n * sizeof(glm::dvec3)), 0);
  for (size_t i = 0; i < n; i += 997) {
    ASSERT_EQ(a->positions[i].x, x[i]);
    ASSERT_EQ(a->positions[i].y, y[i]);
    ASSERT_EQ(a->positions[i].z, z[i]);
  }
}

TEST(E57, coloursOfOtherLimitsAreNormalisedAndImagesAreSaid) {
  TempDir dir;
  const std::vector<float> x{1, 2, 3}, y{0, 0, 0}, z{0, 0, 0};
  const std::vector<int64_t> red{0, 512, 1023}, green{0, 0, 0}, blue{1023, 1023, 1023};
  E57File file;
  const uint64_t at = file.compressedVector(
      {packRaw(x), packRaw(y), packRaw(z), packBits(red, 0, 10), packBits(green, 0, 10), packBits(blue, 0, 10)}, 1000);
  const std::string prototype =
      "<cartesianX type=\"Float\" precision=\"single\"/><cartesianY type=\"Float\" precision=\"single\"/>"
      "<cartesianZ type=\"Float\" precision=\"single\"/><colorRed type=\"Integer\" minimum=\"0\" maximum=\"1023\"/>"
      "<colorGreen type=\"Integer\" minimum=\"0\" maximum=\"1023\"/><colorBlue type=\"Integer\" minimum=\"0\" "
      "maximum=\"1023\"/>";
  std::vector<std::string> notices;
  E57ReadOptions options;
  options.notices = &notices;
  Result<PointSet> points =
      readBytes(dir, file.bytes(rootXml(scanXml(at, 3, prototype), "<vectorChild type=\"Structure\"/>")), options);
  ASSERT_TRUE(points.ok()) << points.error().message;
  ASSERT_TRUE(points->hasColors());
  EXPECT_EQ(points->color_full_scale, 0);  // 10-bit colours are no integer scale a writer keeps
  EXPECT_FLOAT_EQ(points->colors[1].r, 512.0f / 1023.0f);
  EXPECT_FLOAT_EQ(points->colors[2].b, 1.0f);
  ASSERT_EQ(notices.size(), 1u);
  EXPECT_NE(notices[0].find("1 image (images2D)"), std::string::npos) << notices[0];
}

// Leica's signed intensities are read as 0..1 from the scan's intensityLimits (LAS then writes them
// as 16 bits); integers of 0..65535 stay as they are.
TEST(E57, anIntensityOfOtherLimitsIsReadAsFractions) {
  TempDir dir;
  const std::vector<float> x{1, 2, 3}, y{0, 0, 0}, z{0, 0, 0};
  const std::vector<int64_t> signed_intensity{-2048, 0, 2047}, whole{0, 100, 2047};
  E57File file;
  const std::string xyz = "<cartesianX type=\"Float\" precision=\"single\"/><cartesianY type=\"Float\" "
                          "precision=\"single\"/><cartesianZ type=\"Float\" precision=\"single\"/>";
  const uint64_t a = file.compressedVector({packRaw(x), packRaw(y), packRaw(z), packBits(signed_intensity, -2048, 12)}, 1000);
  const uint64_t b = file.compressedVector({packRaw(x), packRaw(y), packRaw(z), packBits(whole, 0, 11)}, 1000);
  const std::string limits =
      "<intensityLimits type=\"Structure\"><intensityMinimum type=\"Integer\">-2048</intensityMinimum>"
      "<intensityMaximum type=\"Integer\">2047</intensityMaximum></intensityLimits>";
  const std::string xml =
      rootXml(scanXml(a, 3, xyz + "<intensity type=\"Integer\" minimum=\"-2048\" maximum=\"2047\"/>", limits) +
              scanXml(b, 3, xyz + "<intensity type=\"Integer\" minimum=\"0\" maximum=\"2047\"/>"));
  std::vector<std::string> notices;
  E57ReadOptions options;
  options.notices = &notices;
  Result<PointSet> points = readBytes(dir, file.bytes(xml), options);
  ASSERT_TRUE(points.ok()) << points.error().message;
  const Dimension* intensity = points->dimensions.find("intensity");
  ASSERT_NE(intensity, nullptr);
  EXPECT_EQ(intensity->type, DimType::kF32);  // the scans' types joined: float32 holds both
  EXPECT_EQ(intensity->value(0), 0.0);
  EXPECT_EQ(intensity->value(1), static_cast<double>(static_cast<float>(2048.0 / 4095.0)));
  EXPECT_EQ(intensity->value(2), 1.0);
  // The second scan's 0..2047 integers too, from their field's limits: one column of one meaning.
  EXPECT_EQ(intensity->value(4), static_cast<double>(static_cast<float>(100.0 / 2047.0)));
  EXPECT_EQ(points->dimensions.find("point_source_id")->value(5), 2.0);
  ASSERT_EQ(notices.size(), 2u);
  EXPECT_NE(notices[0].find("intensity of -2048..2047 (its intensityLimits) read as 0..1 values"), std::string::npos)
      << notices[0];
  EXPECT_NE(notices[1].find("intensity of 0..2047 (the field's limits) read as 0..1 values"), std::string::npos)
      << notices[1];

  // A file of 0..2047 integers alone keeps them (LAS holds them as they are).
  E57File whole_file;
  const uint64_t c = whole_file.compressedVector({packRaw(x), packRaw(y), packRaw(z), packBits(whole, 0, 11)}, 1000);
  Result<PointSet> kept = readBytes(
      dir, whole_file.bytes(rootXml(scanXml(c, 3, xyz + "<intensity type=\"Integer\" minimum=\"0\" maximum=\"2047\"/>"))));
  ASSERT_TRUE(kept.ok());
  EXPECT_EQ(kept->dimensions.find("intensity")->type, DimType::kU16);
  EXPECT_EQ(kept->dimensions.find("intensity")->value(1), 100.0);
}

// The writer says where an intensity's values will come back as 0..1 (their range written as the
// limits, by which readers take it): 10.5, 20, 30 had come back as 0, 0.49, 1 without a word. LAS's
// 0..65535 integers and 0..1 values are written without one.
TEST(E57, anIntensityReadersWillNormaliseIsSaidWhenWritten) {
  TempDir dir;
  PointSet set;
  set.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  Dimension& intensity = set.dimensions.add("intensity", DimType::kF64, 3);
  intensity.set<double>(0, 10.5), intensity.set<double>(1, 20), intensity.set<double>(2, 30);
  std::vector<std::string> notices;
  E57WriteOptions options;
  options.notices = &notices;
  ASSERT_TRUE(writeE57(dir.file("odd.e57"), set, options));
  ASSERT_EQ(notices.size(), 1u);
  EXPECT_EQ(notices[0], dir.file("odd.e57") + ": intensity of 10.5..30 written with that range as its limits: E57 "
                                              "readers take an intensity relative to its limits (dpoint reads it back "
                                              "as 0..1 values)");
  notices.clear();
  intensity.set<double>(0, 0.25), intensity.set<double>(1, 0.5), intensity.set<double>(2, 1);
  ASSERT_TRUE(writeE57(dir.file("fractions.e57"), set, options));
  PointSet whole = set;
  whole.dimensions = Dimensions();
  whole.dimensions.add("intensity", DimType::kU16, 3).set<uint16_t>(1, 500);
  ASSERT_TRUE(writeE57(dir.file("whole.e57"), whole, options));
  EXPECT_TRUE(notices.empty()) << notices[0];
}

TEST(E57, theJoinSaysWhatItFillsInAndManyEmptyRecordsAreAMemoryLimit) {
  TempDir dir;
  const std::vector<float> x{1, 2}, y{0, 0}, z{0, 0};
  const std::vector<int64_t> red{10, 20}, row{3, 4};
  const std::string xyz = "<cartesianX type=\"Float\" precision=\"single\"/><cartesianY type=\"Float\" "
                          "precision=\"single\"/><cartesianZ type=\"Float\" precision=\"single\"/>";
  const std::string rgb = "<colorRed type=\"Integer\" minimum=\"0\" maximum=\"255\"/><colorGreen type=\"Integer\" "
                          "minimum=\"0\" maximum=\"255\"/><colorBlue type=\"Integer\" minimum=\"0\" maximum=\"255\"/>";
  E57File file;
  const uint64_t a = file.compressedVector(
      {packRaw(x), packRaw(y), packRaw(z), packBits(red, 0, 8), packBits(red, 0, 8), packBits(red, 0, 8)}, 1000);
  const uint64_t b = file.compressedVector({packRaw(x), packRaw(y), packRaw(z), packBits(row, 0, 3)}, 1000);
  std::vector<std::string> notices;
  E57ReadOptions options;
  options.notices = &notices;
  Result<PointSet> points = readBytes(
      dir,
      file.bytes(rootXml(scanXml(a, 2, xyz + rgb) + scanXml(b, 2, xyz + "<rowIndex type=\"Integer\" minimum=\"0\" maximum=\"7\"/>"))),
      options);
  ASSERT_TRUE(points.ok()) << points.error().message;
  EXPECT_EQ(points->colors[2], glm::vec3(1.0f));
  EXPECT_EQ(points->dimensions.find("rowIndex")->value(0), 0.0);
  EXPECT_EQ(points->dimensions.find("rowIndex")->value(3), 4.0);
  ASSERT_EQ(notices.size(), 2u);
  EXPECT_NE(notices[0].find("data3D 2 without colours beside scans with: their points are white"), std::string::npos)
      << notices[0];
  EXPECT_NE(notices[1].find("data3D 1 without rowIndex beside scans with: 0 there"), std::string::npos) << notices[1];

  // The memory a tree declares is checked before any section is read: four scans of 2^56 points
  // each are a memory limit (their sum wrapped to 0 and passed). (Fields of no bits, which need no
  // bytes, cannot declare so many: aStreamsIndexIsSmallAndCountsOfNoBytesAreRefused.)
  E57File empty;
  const uint64_t e = empty.rawSection("");
  const std::string zero = "<cartesianX type=\"Integer\" minimum=\"0\" maximum=\"1\"/><cartesianY type=\"Integer\" "
                           "minimum=\"0\" maximum=\"1\"/><cartesianZ type=\"Integer\" minimum=\"0\" maximum=\"1\"/>";
  std::string scans;
  for (int k = 0; k < 4; ++k) scans += scanXml(e, uint64_t{1} << 56, zero);
  Result<PointSet> huge = readBytes(dir, empty.bytes(rootXml(scans)));
  ASSERT_FALSE(huge.ok());
  EXPECT_EQ(huge.error().code, ExitCode::kResourceLimit) << huge.error().message;
  EXPECT_EQ(huge.error().message.rfind(dir.file("scan.e57") + ": ", 0), 0u) << huge.error().message;
}

TEST(E57, aDamagedPageIsNamedAndAFileCutShortIsSaid) {
  TempDir dir;
  const size_t n = 600;
  std::vector<double> v(n, 1.5);
  E57File file;
  const uint64_t at = file.compressedVector({packRaw(v), packRaw(v), packRaw(v)}, 4000);
  const std::string good =
      file.bytes(rootXml(scanXml(at, n, "<cartesianX type=\"Float\"/><cartesianY type=\"Float\"/><cartesianZ type=\"Float\"/>")));
  ASSERT_TRUE(readBytes(dir, good).ok());
  std::string damaged = good;
  damaged[kPage * 2 + 100] ^= 0x10;
  Result<PointSet> bad = readBytes(dir, damaged);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("page 2 (bytes 2048 to 3071) fails its CRC-32C checksum"), std::string::npos)
      << bad.error().message;
  Result<PointSet> cut = readBytes(dir, good.substr(0, good.size() - kPage));
  ASSERT_FALSE(cut.ok());
  EXPECT_NE(cut.error().message.find("cut short"), std::string::npos) << cut.error().message;
  Result<PointSet> not_e57 = readBytes(dir, "ply\nformat ascii 1.0\n");
  ASSERT_FALSE(not_e57.ok());
  EXPECT_NE(not_e57.error().message.find("not an E57 file"), std::string::npos);
}

TEST(E57, badTreesAndPacketsAreNamed) {
  TempDir dir;
  const std::vector<double> v{1, 2, 3};
  const std::string xyz = "<cartesianX type=\"Float\"/><cartesianY type=\"Float\"/><cartesianZ type=\"Float\"/>";
  const auto message = [&](E57File& file, const std::string& xml) {
    Result<PointSet> points = readBytes(dir, file.bytes(xml));
    return points.ok() ? std::string("read") : points.error().message;
  };
  {
    E57File file;
    file.compressedVector({packRaw(v), packRaw(v), packRaw(v)}, 100);
    EXPECT_NE(message(file, "<?xml version=\"1.0\"?>\n<e57Root>\n<data3D>\n</e57Root>").find("its XML, line 4"),
              std::string::npos);
  }
  {
    E57File file;
    const std::vector<double> longer{1, 2, 3, 4, 5};  // two streams for three fields, bytes enough for three
    const uint64_t at = file.compressedVector({packRaw(longer), packRaw(longer)}, 100);
    EXPECT_NE(message(file, rootXml(scanXml(at, 3, xyz))).find("2 bytestreams for a prototype of 3 fields"), std::string::npos);
  }
  {
    E57File file;  // a data packet of 4 bytes at the section's end: its count and lengths are not there
    std::string packet(4, '\0');
    packet[0] = 1;
    put<uint16_t>(packet, 2, 3);
    std::string empty(20, '\0');  // an empty packet of 20 bytes first
    empty[0] = 2;
    put<uint16_t>(empty, 2, 19);
    const uint64_t at = file.rawSection(empty + packet);
    EXPECT_NE(message(file, rootXml(scanXml(at, 1, "<cartesianX type=\"Integer\" minimum=\"0\" maximum=\"1\"/>"
                                                     "<cartesianY type=\"Integer\" minimum=\"0\" maximum=\"1\"/>"
                                                     "<cartesianZ type=\"Integer\" minimum=\"0\" maximum=\"1\"/>")))
                  .find("is a data packet of 4 bytes, shorter than its 6-byte header"),
              std::string::npos);
  }
  {
    E57File file;  // a record count the section cannot hold: refused before its bytes are allocated
    const uint64_t at = file.compressedVector({packRaw(v), packRaw(v), packRaw(v)}, 100);
    EXPECT_NE(message(file, rootXml(scanXml(at, 1000000, xyz))).find("1000000 records of its fields need 24000000 bytes"),
              std::string::npos);
  }
  {
    E57File file;
    const uint64_t at = file.compressedVector({packRaw(v), packRaw(v), packRaw(v).substr(0, 16)}, 100);
    EXPECT_NE(message(file, rootXml(scanXml(at, 3, xyz))).find("the field cartesianZ ends after 2 of its 3 records"),
              std::string::npos);
  }
  {
    E57File file;
    const uint64_t at = file.compressedVector({packRaw(v), packRaw(v)}, 100);
    EXPECT_NE(message(file, rootXml(scanXml(at, 3, "<cartesianX type=\"Float\"/><intensity type=\"Float\"/>")))
                  .find("neither cartesianX, cartesianY and cartesianZ nor sphericalRange"),
              std::string::npos);
  }
  {
    E57File file;
    const uint64_t at = file.compressedVector({packRaw(v)}, 100);
    EXPECT_NE(message(file, rootXml(scanXml(at, 3, "<cartesianX type=\"String\"/>"))).find("a field of type 'String'"),
              std::string::npos);
  }
}

TEST(E57, aNonFiniteCoordinateIsRefusedUnlessAllowedAndInvalidPointsAreLeftOut) {
  TempDir dir;
  const std::vector<double> x{1, NAN, 3, NAN}, y{0, 0, 0, 0}, z{0, 0, 0, 0};
  const std::vector<int64_t> state{0, 0, 0, 2};
  E57File file;
  const uint64_t at = file.compressedVector({packRaw(x), packRaw(y), packRaw(z), packBits(state, 0, 2)}, 100);
  const std::string bytes = file.bytes(rootXml(scanXml(at, 4,
                                                       "<cartesianX type=\"Float\"/><cartesianY type=\"Float\"/>"
                                                       "<cartesianZ type=\"Float\"/><cartesianInvalidState type=\"Integer\" "
                                                       "minimum=\"0\" maximum=\"2\"/>",
                                                       "<name type=\"String\"><![CDATA[north]]></name>")));
  Result<PointSet> refused = readBytes(dir, bytes);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("data3D 1 ('north'): point 1 has a coordinate that is not finite"), std::string::npos)
      << refused.error().message;
  std::vector<std::string> notices;
  E57ReadOptions options;
  options.allow_nonfinite = true;
  options.notices = &notices;
  Result<PointSet> kept = readBytes(dir, bytes, options);
  ASSERT_TRUE(kept.ok());
  ASSERT_EQ(kept->size(), 3u);  // the point of state 2 is no point (its NaN is not refused)
  EXPECT_TRUE(std::isnan(kept->positions[1].x));
  EXPECT_EQ(kept->positions[2].x, 3.0);
  ASSERT_EQ(notices.size(), 1u);
  EXPECT_NE(notices[0].find("1 of its 4 points are marked invalid"), std::string::npos) << notices[0];
}

// Packets read a window at a time (64 KiB here): values straddling windows, fields whose records
// run ahead of others' (bytes given evenly, or one field's all before the next's), invalid points
// across windows; and the memory a file of fields in turn needs, refused where it is not left.
TEST(E57, windowsOfPacketsReadTheSamePointsAsOneRead) {
  TempDir dir;
  const size_t n = 100000;
  std::vector<int64_t> x(n), y(n), state(n);
  std::vector<double> z(n);
  for (size_t i = 0; i < n; ++i) {
    x[i] = static_cast<int64_t>(i % 8) - 5;
    y[i] = static_cast<int64_t>((i * 37) % 8000);
    z[i] = 1e6 + static_cast<double>(i) / 3;
    state[i] = i % 7 == 3 ? 1 : 0;
  }
  const std::vector<std::string> streams{packBits(x, -5, 3), packBits(y, 0, 13), packRaw(z), packBits(state, 0, 2)};
  const std::string prototype =
      "<cartesianX type=\"Integer\" minimum=\"-5\" maximum=\"2\"/>"
      "<cartesianY type=\"ScaledInteger\" minimum=\"0\" maximum=\"8191\" scale=\"0.25\" offset=\"100\"/>"
      "<cartesianZ type=\"Float\"/><cartesianInvalidState type=\"Integer\" minimum=\"0\" maximum=\"2\"/>";
  for (const bool in_turn : {false, true}) {
    E57File file;
    const uint64_t at = file.compressedVector(streams, in_turn ? 60000 : 1000, false, in_turn);
    const std::string bytes = file.bytes(rootXml(scanXml(at, n, prototype)));
    for (const unsigned threads : {1u, 3u}) {
      E57ReadOptions options;
      options.threads = threads;
      options.packet_window = 1;  // 64 KiB: about 20 windows
      Result<PointSet> points = readBytes(dir, bytes, options);
      ASSERT_TRUE(points.ok()) << points.error().message;
      size_t k = 0;
      for (size_t i = 0; i < n; ++i) {
        if (state[i] != 0) continue;
        ASSERT_LT(k, points->size());
        ASSERT_EQ(points->positions[k], glm::dvec3(static_cast<double>(x[i]), static_cast<double>(y[i]) * 0.25 + 100, z[i]))
            << "in turn " << in_turn << ", point " << i;
        ++k;
      }
      EXPECT_EQ(points->size(), k);
    }
    // Points of 24 bytes and windows of 64 KiB are what such a file needs, beside the fields'
    // bytes held until every field has given a record: 1 MB for fields in turn, 0.3 MB else.
    E57ReadOptions tight;
    tight.packet_window = 1;
    tight.max_memory = n * 24 + 2 * (64u << 10) + 500000;
    Result<PointSet> points = readBytes(dir, bytes, tight);
    if (in_turn) {
      ASSERT_FALSE(points.ok());
      EXPECT_EQ(points.error().code, ExitCode::kResourceLimit);
      EXPECT_NE(points.error().message.find("scan.e57: data3D 1: points: its fields' values are spread so unevenly"),
                std::string::npos)
          << points.error().message;
    } else {
      EXPECT_TRUE(points.ok()) << points.error().message;
    }
  }
}

// dpoint's own E57 files (libE57Format's reading of one is tests/data/e57/written): every field
// back as it was, the same bytes on any thread count.
TEST(E57, aWrittenSetReadsBackWithEveryFieldOnAnyThreadCount) {
  TempDir dir;
  PointSet set;
  const size_t n = 5000;  // several packets
  set.positions.resize(n);
  set.colors.resize(n);
  set.color_full_scale = 65535;
  set.dimensions.reserve(9);  // the references below outlive each append
  Dimension& intensity = set.dimensions.append("intensity", DimType::kU16, n);
  Dimension& returns = set.dimensions.append("return_number", DimType::kU8, n);
  Dimension& count = set.dimensions.append("number_of_returns", DimType::kU8, n);
  Dimension& classification = set.dimensions.append("classification", DimType::kU8, n);
  Dimension& time = set.dimensions.append("gps_time", DimType::kF64, n);
  Dimension& nx = set.dimensions.append("nx", DimType::kF32, n);
  Dimension& mine = set.dimensions.append("my value", DimType::kI32, n);
  Dimension& big = set.dimensions.append("big", DimType::kU64, n);
  Dimension& low = set.dimensions.append("low", DimType::kI64, n);
  for (size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i);
    set.positions[i] = glm::dvec3(512345.678 + t * 1e-3, 5412345.25 - t * 1e-7, std::sin(t));
    set.colors[i] = glm::vec3(static_cast<float>(i % 65536) / 65535.0f, static_cast<float>(i * 7 % 65536) / 65535.0f, 1.0f);
    intensity.set<uint16_t>(i, static_cast<uint16_t>(i * 13));
    returns.set<uint8_t>(i, static_cast<uint8_t>(1 + i % 3));
    count.set<uint8_t>(i, 3);
    classification.set<uint8_t>(i, static_cast<uint8_t>(2 + i % 5));
    time.set<double>(i, 245380.78254962614 + t * 1e-6);
    nx.set<float>(i, static_cast<float>(std::cos(t)));
    mine.set<int32_t>(i, -70000 + static_cast<int32_t>(i));
    big.set<uint64_t>(i, (uint64_t{1} << 62) + i);
    low.set<int64_t>(i, INT64_MIN + static_cast<int64_t>(i));
  }
  std::vector<std::string> notices;
  E57WriteOptions one;
  one.threads = 1;
  one.notices = &notices;
  ASSERT_TRUE(writeE57(dir.file("one.e57"), set, one).ok());
  E57WriteOptions three;
  three.threads = 3;
  ASSERT_TRUE(writeE57(dir.file("three.e57"), set, three).ok());
  EXPECT_EQ(test::readFile(dir.file("one.e57")), test::readFile(dir.file("three.e57")));
  ASSERT_EQ(notices.size(), 1u);
  EXPECT_NE(notices[0].find("dimension 'my value' written as 'my_value'"), std::string::npos) << notices[0];

  Result<PointSet> back = readE57(dir.file("one.e57"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  ASSERT_EQ(back->size(), n);
  EXPECT_EQ(back->color_full_scale, 65535);
  EXPECT_EQ(std::memcmp(back->positions.data(), set.positions.data(), n * sizeof(glm::dvec3)), 0);
  for (size_t i = 0; i < n; i += 7)
    for (int k = 0; k < 3; ++k) ASSERT_NEAR(back->colors[i][k], set.colors[i][k], 1e-7f) << i;
  for (const Dimension& d : set.dimensions.all()) {
    const std::string name = d.name == "my value" ? "my_value" : d.name;
    const Dimension* b = back->dimensions.find(name);
    ASSERT_NE(b, nullptr) << name;
    for (size_t i = 0; i < n; i += 7) {
      if (d.type == DimType::kU64) ASSERT_EQ(b->get<uint64_t>(i), d.get<uint64_t>(i)) << name;
      else if (d.type == DimType::kI64) ASSERT_EQ(b->get<int64_t>(i), d.get<int64_t>(i)) << name;
      else ASSERT_EQ(b->value(i), d.value(i)) << name << " " << i;
    }
  }
  // Integers pack in the bits their values need: the classification's 2..6 in 3.
  const std::string bytes = test::readFile(dir.file("one.e57"));
  EXPECT_NE(bytes.find("<las:classification type=\"Integer\" minimum=\"2\" maximum=\"6\"/>"), std::string::npos);
  EXPECT_NE(bytes.find("<returnIndex type=\"Integer\" minimum=\"0\" maximum=\"2\"/>"), std::string::npos);
  EXPECT_NE(bytes.find("<nor:normalX type=\"Float\" precision=\"single\"/>"), std::string::npos);

  // A mesh's triangles are not written (said); an empty set is an empty file of one scan.
  PointSet mesh;
  mesh.positions = {glm::dvec3(0.0), glm::dvec3(1.0, 0.0, 0.0), glm::dvec3(0.0, 1.0, 0.0)};
  mesh.triangles = {0, 1, 2};
  notices.clear();
  ASSERT_TRUE(writeE57(dir.file("mesh.e57"), mesh, one).ok());
  ASSERT_EQ(notices.size(), 1u);
  EXPECT_NE(notices[0].find("triangles not written"), std::string::npos);
  EXPECT_EQ(readE57(dir.file("mesh.e57"))->size(), 3u);
  ASSERT_TRUE(writeE57(dir.file("empty.e57"), PointSet()).ok());
  Result<PointSet> empty = readE57(dir.file("empty.e57"));
  ASSERT_TRUE(empty.ok()) << empty.error().message;
  EXPECT_EQ(empty->size(), 0u);
}

// More fields than one 64-record group of fits in a 64 KiB packet (300 doubles: 150 KiB a group)
// split each group over packets by fields; every value reads back, whole and streamed, on any
// thread count. (libE57Format read such a file, 305 fields, every sum and sampled record equal.)
// A set of more fields than a packet's header can list is refused, naming them.
TEST(E57, aGroupOfManyFieldsIsSplitOverPacketsByFields) {
  TempDir dir;
  PointSet set;
  const size_t n = 1000, doubles = 300;
  set.positions.resize(n);
  set.dimensions.reserve(doubles + 2);
  const auto named = [](char letter, size_t k) {  // (GCC 12 warns of "d" + std::to_string(k) in error)
    char name[24];
    std::snprintf(name, sizeof name, "%c%zu", letter, k);
    return std::string(name);
  };
  for (size_t k = 0; k < doubles; ++k) set.dimensions.append(named('d', k), DimType::kF64, n);
  Dimension& small = set.dimensions.append("small", DimType::kU8, n);  // 3 bits: a chunk of 24 bytes a group
  Dimension& wide = set.dimensions.append("wide", DimType::kI32, n);
  for (size_t i = 0; i < n; ++i) {
    set.positions[i] = glm::dvec3(6378137.0 + static_cast<double>(i) * 1e-3, static_cast<double>(i), -1.5);
    for (size_t k = 0; k < doubles; ++k) set.dimensions.all()[k].set<double>(i, static_cast<double>(i * 1000 + k) + 0.25);
    small.set<uint8_t>(i, static_cast<uint8_t>(i % 7));
    wide.set<int32_t>(i, static_cast<int32_t>(i * 2654435761u));
  }
  E57WriteOptions one, three;
  one.threads = 1, three.threads = 3;
  ASSERT_TRUE(writeE57(dir.file("one.e57"), set, one).ok());
  ASSERT_TRUE(writeE57(dir.file("three.e57"), set, three).ok());
  EXPECT_EQ(test::readFile(dir.file("one.e57")), test::readFile(dir.file("three.e57")));
  for (const size_t window : {size_t{0}, size_t{1} << 16}) {
    E57ReadOptions options;
    options.packet_window = window;
    Result<PointSet> back = readE57(dir.file("one.e57"), options);
    ASSERT_TRUE(back.ok()) << back.error().message;
    ASSERT_EQ(back->size(), n);
    EXPECT_EQ(std::memcmp(back->positions.data(), set.positions.data(), n * sizeof(glm::dvec3)), 0);
    ASSERT_EQ(back->dimensions.count(), set.dimensions.count());
    for (const Dimension& d : set.dimensions.all()) {
      const Dimension* b = back->dimensions.find(d.name);
      ASSERT_NE(b, nullptr) << d.name;
      for (size_t i = 0; i < n; ++i) ASSERT_EQ(b->value(i), d.value(i)) << d.name << " " << i;
    }
  }
  Result<std::unique_ptr<E57PointStream>> stream = E57PointStream::open(dir.file("one.e57"));
  ASSERT_TRUE(stream) << stream.error().message;
  std::vector<size_t> all((*stream)->dimensions().count());
  for (size_t k = 0; k < all.size(); ++k) all[k] = k;
  (*stream)->streamDimensions(all);
  PointSet block;
  ASSERT_TRUE((*stream)->read(333, 400, block).ok());
  for (size_t k = 0; k < all.size(); ++k)
    for (size_t i = 0; i < 400; ++i)
      ASSERT_EQ(block.dimensions.all()[k].value(i), set.dimensions.all()[k].value(333 + i)) << k << " " << i;

  PointSet wider;
  wider.positions.resize(1);
  for (size_t k = 0; k < 33000; ++k) wider.dimensions.append(named('v', k), DimType::kU8, 1);
  const Status refused = writeE57(dir.file("wider.e57"), wider);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().code, ExitCode::kUsage);
  EXPECT_TRUE(test::contains(refused.error().message, "33003 fields")) << refused.error().message;
  EXPECT_FALSE(std::filesystem::exists(dir.file("wider.e57")));
}

// A review of the writer: names that E57 gives a meaning, a dimension named like a colour, the
// intensity's range, the GUIDs, bounds of non-finite sets, LAS's return 0, a float invalid state.
TEST(E57, standardNamesAreRenamedAndEveryValueComesBack) {
  TempDir dir;
  PointSet set;
  const size_t n = 300;
  set.positions.resize(n);
  set.dimensions.reserve(6);  // the references below outlive each append
  Dimension& color_index = set.dimensions.append("color_index", DimType::kI32, n);
  Dimension& return_index = set.dimensions.append("returnIndex", DimType::kF64, n);
  Dimension& red = set.dimensions.append("colorRed", DimType::kU32, n);
  Dimension& state = set.dimensions.append("cartesianInvalidState", DimType::kU8, n);
  Dimension& returns = set.dimensions.append("return_number", DimType::kU8, n);
  Dimension& intensity = set.dimensions.append("intensity", DimType::kF32, n);
  for (size_t i = 0; i < n; ++i) {
    set.positions[i] = glm::dvec3(static_cast<double>(i), 0.0, i == 7 ? NAN : 1.0);
    color_index.set<int32_t>(i, -500 + static_cast<int32_t>(i) * 7);
    return_index.set<double>(i, 0.5 * static_cast<double>(i));
    red.set<uint32_t>(i, 1000 * static_cast<uint32_t>(i));
    state.set<uint8_t>(i, static_cast<uint8_t>(i % 2));
    returns.set<uint8_t>(i, static_cast<uint8_t>(i % 3));  // LAS's 0: no returnIndex of -1
    intensity.set<float>(i, static_cast<float>(i) / 300.0f);
  }
  std::vector<std::string> notices;
  E57WriteOptions options;
  options.notices = &notices;
  ASSERT_TRUE(writeE57(dir.file("a.e57"), set, options).ok());
  EXPECT_EQ(notices.size(), 3u);  // returnIndex, colorRed, cartesianInvalidState renamed
  Result<PointSet> back = readE57(dir.file("a.e57"), E57ReadOptions{0, nullptr, 0, true, nullptr});
  ASSERT_TRUE(back.ok()) << back.error().message;
  ASSERT_EQ(back->size(), n);  // no point taken for invalid
  EXPECT_FALSE(back->hasColors());
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{{"color_index", "color_index"},
                                                                                {"returnIndex", "returnIndex_2"},
                                                                                {"colorRed", "colorRed_2"},
                                                                                {"cartesianInvalidState", "cartesianInvalidState_2"},
                                                                                {"return_number", "return_number"},
                                                                                {"intensity", "intensity"}}) {
    const Dimension* b = back->dimensions.find(to);
    ASSERT_NE(b, nullptr) << to;
    for (size_t i = 0; i < n; ++i) ASSERT_EQ(b->value(i), set.dimensions.find(from)->value(i)) << to << " " << i;
  }
  const std::string bytes = test::readFile(dir.file("a.e57"));
  // The intensity's range for readers that normalise by it, also as its Float's limits.
  EXPECT_NE(bytes.find("<intensity type=\"Float\" precision=\"single\" minimum=\"0\" maximum=\"1\"/>"), std::string::npos);
  EXPECT_NE(bytes.find("<intensityMaximum type=\"Float\">1</intensityMaximum>"), std::string::npos);
  // Bounds of the finite coordinates (z: 1, not NaN).
  EXPECT_NE(bytes.find("<zMinimum type=\"Float\">1</zMinimum>"), std::string::npos);
  // GUIDs from the content: one value changed, other GUIDs.
  const auto guidOf = [](const std::string& file) {
    const size_t at = file.find("<guid type=\"String\"><![CDATA[");
    return file.substr(at + 29, 36);
  };
  set.dimensions.find("color_index")->set<int32_t>(150, 1);
  ASSERT_TRUE(writeE57(dir.file("b.e57"), set).ok());
  EXPECT_NE(guidOf(bytes), guidOf(test::readFile(dir.file("b.e57"))));
  EXPECT_EQ(guidOf(bytes)[14], '5');  // an RFC 4122 version 5 UUID

  // Another writer's Float invalid state: 0.0 is valid.
  E57File file;
  const std::vector<double> x{1, 2, 3}, flags{0, 1, 0};
  const uint64_t at = file.compressedVector({packRaw(x), packRaw(x), packRaw(x), packRaw(flags)}, 1000);
  Result<PointSet> two = readBytes(dir, file.bytes(rootXml(scanXml(
      at, 3, "<cartesianX type=\"Float\"/><cartesianY type=\"Float\"/><cartesianZ type=\"Float\"/>"
             "<cartesianInvalidState type=\"Float\"/>"))));
  ASSERT_TRUE(two.ok()) << two.error().message;
  ASSERT_EQ(two->size(), 2u);
  EXPECT_EQ(two->positions[1].x, 3.0);
}

// The points of `whole` [first, first + n) equal `block`'s: positions and colours bit for bit, and
// every dimension's value.
void expectBlockOf(const PointSet& whole, const PointSet& block, uint64_t first, uint64_t n, const std::string& what) {
  ASSERT_EQ(block.size(), n) << what;
  ASSERT_EQ(std::memcmp(block.positions.data(), whole.positions.data() + first, n * sizeof(glm::dvec3)), 0) << what;
  ASSERT_EQ(block.hasColors(), whole.hasColors()) << what;
  if (whole.hasColors()) {
    ASSERT_EQ(std::memcmp(block.colors.data(), whole.colors.data() + first, n * sizeof(glm::vec3)), 0) << what;
  }
  ASSERT_EQ(block.dimensions.count(), whole.dimensions.count()) << what;
  for (size_t d = 0; d < whole.dimensions.count(); ++d) {
    const Dimension& a = whole.dimensions.all()[d];
    const Dimension& b = block.dimensions.all()[d];
    ASSERT_EQ(b.name, a.name) << what;
    ASSERT_EQ(b.type, a.type) << what << " " << a.name;
    const size_t w = dimTypeSize(a.type);
    ASSERT_EQ(std::memcmp(b.bytes.data(), a.bytes.data() + first * w, n * w), 0) << what << " " << a.name;
  }
}

// A stream (render's and info's --stream) gives readE57's points block by block, in blocks of
// any size and in any order: libE57Format's files (poses, invalid points, a spherical scan, two
// scans joined with their numbers and what the join fills in), dpoint's own, and a file of
// packets given field by field, read 64 KiB at a time.
TEST(E57, aStreamGivesWhatReadE57GivesInAnyBlocks) {
  TempDir dir;
  std::vector<std::string> paths;
  for (const char* name : {"two_scans.e57", "spherical.e57", "bunnyInt32.e57", "ColouredCubeFloat.e57",
                           "ColourRepresentation.e57", "written/1.2-with-color.e57", "ZeroPoints.e57"})
    paths.push_back(std::string(DPOINT_TESTS_DIR) + "/data/e57/" + name);
  {
    const size_t n = 30000;
    std::vector<int64_t> x(n), state(n);
    std::vector<double> y(n);
    for (size_t i = 0; i < n; ++i) {
      x[i] = static_cast<int64_t>(i % 8) - 5;
      y[i] = 1e6 + static_cast<double>(i) / 3;
      state[i] = (i / 500) % 3 == 1 || i % 11 == 0 ? 1 : 0;  // runs of invalid records, and single ones
    }
    E57File file;
    const uint64_t at = file.compressedVector({packBits(x, -5, 3), packRaw(y), packRaw(y), packBits(state, 0, 1), packRaw(y)},
                                              4000, false, true);
    const std::string prototype =
        "<cartesianX type=\"Integer\" minimum=\"-5\" maximum=\"2\"/><cartesianY type=\"Float\"/>"
        "<cartesianZ type=\"Float\"/><cartesianInvalidState type=\"Integer\" minimum=\"0\" maximum=\"1\"/>"
        "<timeStamp type=\"Float\"/>";
    paths.push_back(dir.file("in_turn.e57"));
    writeFile(paths.back(), file.bytes(rootXml(scanXml(at, n, prototype))));
  }
  {
    // A scan with colours whose every point is invalid beside one without: no colours, no note
    // of white (the stream said "data3D 2 without colours" where the whole read did not).
    const std::vector<double> x{1, 2}, y{0, 0};
    const std::vector<int64_t> invalid{1, 2}, red{10, 20};
    E57File file;
    const uint64_t a = file.compressedVector({packRaw(x), packRaw(y), packRaw(y), packBits(invalid, 0, 2), packBits(red, 0, 8),
                                              packBits(red, 0, 8), packBits(red, 0, 8)},
                                             100);
    const uint64_t b = file.compressedVector({packRaw(x), packRaw(y), packRaw(y)}, 100);
    const std::string xyz = "<cartesianX type=\"Float\"/><cartesianY type=\"Float\"/><cartesianZ type=\"Float\"/>";
    const std::string colors =
        "<cartesianInvalidState type=\"Integer\" minimum=\"0\" maximum=\"2\"/>"
        "<colorRed type=\"Integer\" minimum=\"0\" maximum=\"255\"/><colorGreen type=\"Integer\" minimum=\"0\" "
        "maximum=\"255\"/><colorBlue type=\"Integer\" minimum=\"0\" maximum=\"255\"/>";
    paths.push_back(dir.file("invalid_coloured.e57"));
    writeFile(paths.back(), file.bytes(rootXml(scanXml(a, 2, xyz + colors) + scanXml(b, 2, xyz))));
  }
  for (const std::string& path : paths) {
    E57ReadOptions options;
    options.packet_window = 1;  // 64 KiB
    std::vector<std::string> whole_notices, notices;
    options.notices = &whole_notices;
    Result<PointSet> whole = readE57(path, options);
    ASSERT_TRUE(whole.ok()) << whole.error().message;
    options.notices = nullptr;
    options.threads = 3;
    Result<std::unique_ptr<E57PointStream>> stream = E57PointStream::open(path, options);
    ASSERT_TRUE(stream.ok()) << stream.error().message;
    E57PointStream& s = **stream;
    ASSERT_EQ(s.count(), whole->size()) << path;
    EXPECT_EQ(s.hasColors(), whole->hasColors()) << path;
    EXPECT_EQ(s.notices(), whole_notices) << path;
    ASSERT_EQ(s.dimensions().count(), whole->dimensions.count()) << path;
    std::vector<size_t> all;
    for (size_t d = 0; d < s.dimensions().count(); ++d) {
      EXPECT_EQ(s.dimensions().all()[d].name, whole->dimensions.all()[d].name) << path;
      EXPECT_EQ(s.dimensions().all()[d].type, whole->dimensions.all()[d].type) << path;
      all.push_back(d);
    }
    s.streamDimensions(all);
    const uint64_t count = s.count();
    PointSet block;
    ASSERT_TRUE(s.read(0, count, block).ok()) << path;
    expectBlockOf(*whole, block, 0, count, path + " whole");
    for (const uint64_t size : {uint64_t{1}, uint64_t{7}, uint64_t{999}, uint64_t{4096}}) {
      if (count == 0) break;
      // In order, then from the end backwards, then a stride that jumps about.
      std::vector<uint64_t> firsts;
      for (uint64_t f = 0; f < count && firsts.size() < 200; f += size) firsts.push_back(f);
      for (uint64_t k = 0; k < 50 && k * size < count; ++k) firsts.push_back(count - std::min(count, (k + 1) * size));
      for (uint64_t k = 0; k < 50; ++k) firsts.push_back(k * 7919 * size % count);
      for (const uint64_t f : firsts) {
        const uint64_t n = std::min(size, count - f);
        Status st = s.read(f, n, block);
        ASSERT_TRUE(st.ok()) << st.error().message;
        expectBlockOf(*whole, block, f, n, path + " at " + std::to_string(f) + " size " + std::to_string(size));
      }
    }
  }
}

// What a stream's open holds and refuses (review findings): its packet index stays a small share
// of the file however small the packets (2M empty packets took 1 GB); a scan whose fields take no
// bits cannot declare more than 2^26 records (a 1 KB file streamed 2^35 for hours); a small file's
// whole read is not charged a 32 MiB window twice (--max-memory 64M refused every E57).
TEST(E57, aStreamsIndexIsSmallAndCountsOfNoBytesAreRefused) {
  TempDir dir;
  {
    std::string packets;
    const size_t empty = 50000;
    for (size_t k = 0; k < empty; ++k) {  // data packets of three empty bytestreams: 12 bytes each
      std::string p(12, '\0');
      p[0] = 1;
      put<uint16_t>(p, 2, 11);
      put<uint16_t>(p, 4, 3);
      packets += p;
    }
    std::string last(12 + 24, '\0');  // then one point
    last[0] = 1;
    put<uint16_t>(last, 2, static_cast<uint16_t>(last.size() - 1));
    put<uint16_t>(last, 4, 3);
    for (int k = 0; k < 3; ++k) put<uint16_t>(last, 6 + 2 * static_cast<size_t>(k), 8);
    for (int k = 0; k < 3; ++k) put<double>(last, 12 + 8 * static_cast<size_t>(k), 1.5 + k);
    packets += last;
    E57File file;
    const uint64_t at = file.rawSection(packets);
    const std::string bytes =
        file.bytes(rootXml(scanXml(at, 1, "<cartesianX type=\"Float\"/><cartesianY type=\"Float\"/><cartesianZ type=\"Float\"/>")));
    writeFile(dir.file("empty_packets.e57"), bytes);
    Result<std::unique_ptr<E57PointStream>> stream = E57PointStream::open(dir.file("empty_packets.e57"));
    ASSERT_TRUE(stream.ok()) << stream.error().message;
    EXPECT_LE((*stream)->heldBytes(), bytes.size() / 32);
    PointSet block;
    ASSERT_TRUE((*stream)->read(0, 1, block).ok());
    EXPECT_EQ(block.positions.at(0), glm::dvec3(1.5, 2.5, 3.5));
  }
  {
    E57File file;
    const uint64_t at = file.compressedVector({"", "", ""}, 100);
    const std::string prototype =
        "<cartesianX type=\"Integer\" minimum=\"1\" maximum=\"1\"/><cartesianY type=\"Integer\" minimum=\"2\" "
        "maximum=\"2\"/><cartesianZ type=\"Integer\" minimum=\"3\" maximum=\"3\"/>";
    writeFile(dir.file("constant.e57"), file.bytes(rootXml(scanXml(at, uint64_t{1} << 35, prototype))));
    Result<std::unique_ptr<E57PointStream>> stream = E57PointStream::open(dir.file("constant.e57"));
    ASSERT_FALSE(stream.ok());
    EXPECT_NE(stream.error().message.find("34359738368 records whose fields all take no bits"), std::string::npos)
        << stream.error().message;
    E57File small;
    std::string packet(12, '\0');  // one data packet of three empty bytestreams
    packet[0] = 1;
    put<uint16_t>(packet, 2, 11);
    put<uint16_t>(packet, 4, 3);
    const uint64_t at2 = small.rawSection(packet);
    writeFile(dir.file("constant_small.e57"), small.bytes(rootXml(scanXml(at2, 1000, prototype))));
    E57ReadOptions tight;
    tight.max_memory = 1u << 20;  // 1 MiB: 1000 points of 24 bytes, and windows no larger than the file
    Result<PointSet> read = readE57(dir.file("constant_small.e57"), tight);
    ASSERT_TRUE(read.ok()) << read.error().message;
    ASSERT_EQ(read->size(), 1000u);
    EXPECT_EQ(read->positions[999], glm::dvec3(1, 2, 3));
  }
}

// A set read from several scans (each point's scan in point_source_id, in runs) is written as those
// scans, each its own data3D child with its own bounds and records, and read back with the same
// ids; ids whose points are not together make one scan. (libE57Format read such a file:
// tests/data/e57/written/two_scans.)
TEST(E57, eachPointSourceIdsRunIsAScan) {
  TempDir dir;
  PointSet set;
  set.positions = {{1.0, 2.0, 3.0}, {1.5, 2.5, 3.5}, {500.0, 600.0, 70.0}, {501.0, 601.0, 71.0}, {502.0, 602.0, 72.0}};
  Dimension& ids = set.dimensions.add(dim::kPointSourceId, DimType::kU16, 5);
  for (size_t i = 0; i < 5; ++i) ids.setValue(i, i < 2 ? 9.0 : 4.0);
  ASSERT_TRUE(writeE57(dir.file("two.e57"), set).ok());
  // The file's logical bytes: each 1,024-byte page less its 4-byte checksum.
  const auto logical = [](const std::string& file) {
    std::string out;
    for (size_t at = 0; at < file.size(); at += 1024) out.append(file, at, std::min<size_t>(1020, file.size() - at));
    return out;
  };
  const std::string bytes = logical(test::readFile(dir.file("two.e57")));
  EXPECT_TRUE(test::contains(bytes, "recordCount=\"2\"")) << "the first scan's two records";
  EXPECT_TRUE(test::contains(bytes, "recordCount=\"3\"")) << "the second scan's three";
  EXPECT_TRUE(test::contains(bytes, "<xMinimum type=\"Float\">500</xMinimum>")) << "the second scan's bounds";
  Result<PointSet> back = readE57(dir.file("two.e57"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->positions, set.positions);
  for (size_t i = 0; i < 5; ++i) EXPECT_EQ(back->dimensions.find(dim::kPointSourceId)->value(i), ids.value(i)) << i;

  // Every NaN is one id (a review finding: each NaN point was a scan of its own).
  PointSet nan_set;
  nan_set.positions = set.positions;
  Dimension& nan_ids = nan_set.dimensions.add(dim::kPointSourceId, DimType::kF64, 5);
  for (size_t i = 0; i < 5; ++i) nan_ids.set<double>(i, i < 3 ? std::nan("") : 2.0);
  EXPECT_EQ(pointSourceRuns(nan_set).size(), 2u);

  // More runs than a point source id numbers (65,535): one scan, which the reader can read; and
  // every scan's GUID its own (a review finding: they repeated past 4,096 scans).
  PointSet many;
  many.positions.resize(65536);
  Dimension& each = many.dimensions.add(dim::kPointSourceId, DimType::kU16, 65536);
  for (size_t i = 0; i < 65536; ++i) many.positions[i] = glm::dvec3(static_cast<double>(i), 0.0, 0.0), each.setValue(i, double(i));
  EXPECT_EQ(pointSourceRuns(many).size(), 1u);
  many.positions.resize(5000);
  many.dimensions.resize(5000);
  ASSERT_TRUE(writeE57(dir.file("many.e57"), many).ok());
  const std::string xml = logical(test::readFile(dir.file("many.e57")));
  std::set<std::string> guids;
  size_t scans = 0;
  for (size_t at = 0; (at = xml.find("<guid type=\"String\"><![CDATA[", at)) != std::string::npos; ++at, ++scans)
    guids.insert(xml.substr(at + 30, 36));
  EXPECT_EQ(scans, 5001u);  // the file's and 5,000 scans'
  EXPECT_EQ(guids.size(), scans);

  ids.setValue(4, 9.0);  // 9's points in two places: one scan
  ASSERT_TRUE(writeE57(dir.file("one.e57"), set).ok());
  EXPECT_TRUE(test::contains(logical(test::readFile(dir.file("one.e57"))), "recordCount=\"5\""));
  back = readE57(dir.file("one.e57"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->dimensions.find(dim::kPointSourceId)->value(4), 9.0);
}

}  // namespace
}  // namespace dpoint
