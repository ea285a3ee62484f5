// Point attributes kept whole (issue #34): every field of a LAS record becomes a dimension, extra
// bytes their declared types, and LAS → LAS writes the same point records byte for byte; the
// filters carry the dimensions with their points.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "converters/csv.h"
#include "converters/gltf_dimensions.h"
#include "converters/gltf_read.h"
#include "converters/gltf_write.h"
#include "converters/las.h"
#include "converters/las_fields.h"
#include "converters/ply.h"
#include "converters/point_io.h"
#include "core/dimensions.h"
#include "ops/point_filters.h"
#include "ops/point_order.h"
#include "las_bytes.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::at;
using test::descriptorAt;
using test::readFile;
using test::TempDir;
using test::writeFile;

// The point records of a LAS file, its format and record length, read straight from the bytes.
struct Records {
  int format = 0;
  uint16_t length = 0;
  uint64_t count = 0;
  std::string bytes;
};
Records recordsOf(const std::string& path) {
  const std::string file = readFile(path);
  Records r;
  const uint32_t offset = at<uint32_t>(file, 96);
  r.format = static_cast<uint8_t>(file[104]);
  r.length = at<uint16_t>(file, 105);
  r.count = at<uint32_t>(file, 107);
  if (file[25] >= 4 && at<uint64_t>(file, 247) != 0) r.count = at<uint64_t>(file, 247);
  r.bytes = file.substr(offset, r.count * r.length);
  return r;
}

PlyWriteOptions plyOptions(PlyEncoding encoding) {
  PlyWriteOptions options;
  options.encoding = encoding;
  return options;
}

std::vector<std::string> corpusLasFiles() {
  std::vector<std::string> files;
  for (const char* folder : {"/las/", "/laz/"})
    for (const auto& e : std::filesystem::directory_iterator(std::string(DPOINT_CORPUS_DIR) + folder))
      if (e.path().extension() == ".las") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

TEST(LasDimensions, lasToLasWritesTheSamePointRecordsForEveryCorpusFile) {
  const std::vector<std::string> files = corpusLasFiles();
  ASSERT_GE(files.size(), 20u) << "the corpus LAS files are missing";
  TempDir dir;
  for (const std::string& path : files) {
    Result<PointSet> points = readLas(path);
    ASSERT_TRUE(points) << points.error().message;
    const std::string out = dir.file(std::filesystem::path(path).filename());
    ASSERT_TRUE(writeLas(out, *points)) << path;
    const Records in = recordsOf(path), written = recordsOf(out);
    EXPECT_EQ(written.format, in.format) << path;
    EXPECT_EQ(written.length, in.length) << path;
    EXPECT_EQ(written.count, in.count) << path;
    EXPECT_TRUE(written.bytes == in.bytes) << path << ": the point records differ";
  }
}

// Every dimension of `a` is in `b` with the same values (as numbers; types may widen).
void expectSameDimensions(const PointSet& a, const PointSet& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (const Dimension& d : a.dimensions.all()) {
    const Dimension* other = b.dimensions.find(d.name);
    ASSERT_TRUE(other) << what << ": lost " << d.name;
    size_t differ = 0;
    for (size_t i = 0; i < d.size(); ++i) {
      const double x = d.value(i), y = other->value(i);
      differ += x != y && !(std::isnan(x) && std::isnan(y));  // rand1_6.las has NaN GPS times
    }
    EXPECT_EQ(differ, 0u) << what << ": " << d.name;
  }
}

TEST(LasDimensions, lasToPlyToLasKeepsEveryFieldOfEveryCorpusFile) {
  TempDir dir;
  for (const std::string& path : corpusLasFiles()) {
    Result<PointSet> las = readLas(path);
    ASSERT_TRUE(las);
    for (PlyEncoding encoding : {PlyEncoding::kBinary, PlyEncoding::kAscii}) {
      const std::string what = path + (encoding == PlyEncoding::kAscii ? " (ASCII PLY)" : " (PLY)");
      ASSERT_TRUE(writePly(dir.file("p.ply"), *las, plyOptions(encoding))) << what;
      Result<PointSet> ply = readPly(dir.file("p.ply"));
      ASSERT_TRUE(ply) << ply.error().message;
      expectSameDimensions(*las, *ply, what);
      ASSERT_TRUE(writeLas(dir.file("back.las"), *ply)) << what;
      Result<PointSet> back = readLas(dir.file("back.las"));
      ASSERT_TRUE(back);
      expectSameDimensions(*las, *back, what + " -> LAS");
      EXPECT_EQ(back->positions, las->positions) << what;
      // The colours as the file stored them (16-bit words, or a file's 8-bit values).
      EXPECT_EQ(back->colors, las->colors) << what;
      EXPECT_EQ(back->color_full_scale, las->color_full_scale) << what;
      // (Not always the same record bytes: PLY has no 64-bit integers, so a uint64 extra byte comes
      // back as a double of the same value, and ASCII PLY writes every NaN as "nan".)
    }
  }
}

// Every position of `b` is the same integer of `source`'s LAS frame as `a`'s: the X, Y, Z fields
// value for value, where a format without that frame (CSV) brings the coordinates back as decimals.
void expectSameLasIntegers(const PointSet& a, const PointSet& b, const LasSource& source, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  size_t differ = 0;
  for (size_t i = 0; i < a.size(); ++i)
    for (int k = 0; k < 3; ++k)
      differ += std::nearbyint((a.positions[i][k] - source.offset[k]) / source.scale[k]) !=
                std::nearbyint((b.positions[i][k] - source.offset[k]) / source.scale[k]);
  EXPECT_EQ(differ, 0u) << what << ": coordinates moved";
}

TEST(LasDimensions, lasToCsvToLasKeepsEveryFieldOfEveryCorpusFile) {
  TempDir dir;
  for (const std::string& path : corpusLasFiles()) {
    Result<PointSet> las = readLas(path);
    ASSERT_TRUE(las);
    const std::string what = path + " (CSV)";
    ASSERT_TRUE(writeCsv(dir.file("p.csv"), *las)) << what;
    Result<PointSet> csv = readCsv(dir.file("p.csv"));
    ASSERT_TRUE(csv) << csv.error().message;
    expectSameDimensions(*las, *csv, what);
    EXPECT_EQ(csv->positions, las->positions) << what;  // shortest round-trip doubles
    ASSERT_TRUE(writeLas(dir.file("back.las"), *csv)) << what;
    Result<PointSet> back = readLas(dir.file("back.las"));
    ASSERT_TRUE(back);
    expectSameDimensions(*las, *back, what + " -> LAS");
    expectSameLasIntegers(*las, *back, *las->las, what + " -> LAS");
    // The colours' values (a file's 8-bit colours come back at 16 bits, the same fraction).
    EXPECT_EQ(back->colors, las->colors) << what;
    // Known dimensions come back in their own types: a class is a byte again.
    for (const Dimension& d : las->dimensions.all()) {
      if (!findKnownDimension(d.name)) continue;
      EXPECT_EQ(csv->dimensions.find(d.name)->type, d.type) << what << " " << d.name;
    }
  }
}

// GLB: each dimension an application-specific attribute (gltf_dimensions.h), read back in its type.
TEST(LasDimensions, lasToGlbToLasKeepsEveryFieldOfEveryCorpusFile) {
  TempDir dir;
  for (const std::string& path : corpusLasFiles()) {
    Result<PointSet> las = readLas(path);
    ASSERT_TRUE(las);
    if (las->size() == 0) continue;  // GLB cannot hold an empty set (tested in the CLI tests)
    const std::string what = path + " (GLB)";
    ASSERT_TRUE(writeGlb(dir.file("p.glb"), *las)) << what;
    Result<PointSet> glb = readGltf(dir.file("p.glb"));
    ASSERT_TRUE(glb) << glb.error().message;
    expectSameDimensions(*las, *glb, what);
    ASSERT_EQ(glb->dimensions.count(), las->dimensions.count()) << what;
    for (size_t k = 0; k < las->dimensions.count(); ++k) {
      EXPECT_EQ(glb->dimensions.all()[k].name, las->dimensions.all()[k].name) << what;
      EXPECT_EQ(glb->dimensions.all()[k].type, las->dimensions.all()[k].type) << what;
      EXPECT_TRUE(glb->dimensions.all()[k].bytes == las->dimensions.all()[k].bytes) << what << ": bits differ";
    }
    ASSERT_TRUE(writeLas(dir.file("back.las"), *glb)) << what;
    Result<PointSet> back = readLas(dir.file("back.las"));
    ASSERT_TRUE(back);
    expectSameDimensions(*las, *back, what + " -> LAS");
    expectSameLasIntegers(*las, *back, *las->las, what + " -> LAS");
    EXPECT_EQ(back->colors, las->colors) << what;
  }
}

TEST(LasDimensions, theKnownGltfAttributesAreTheNamesInUpperCase) {
  for (const KnownDimension& k : knownDimensions()) EXPECT_EQ(gltfAttributeName(k.name), k.gltf_attribute) << k.name;
}

TEST(LasDimensions, everyFieldOfARecordIsADimensionWithItsValue) {
  Result<PointSet> points = readLas(std::string(DPOINT_CORPUS_DIR) + "/las/simple.las");
  ASSERT_TRUE(points);
  const Records raw = recordsOf(std::string(DPOINT_CORPUS_DIR) + "/las/simple.las");
  const Dimensions& d = points->dimensions;
  ASSERT_TRUE(d.find(dim::kIntensity) && d.find(dim::kClassification) && d.find(dim::kGpsTime));
  for (size_t i = 0; i < points->size(); i += 97) {
    const size_t r = i * raw.length;
    EXPECT_EQ(d.find(dim::kIntensity)->get<uint16_t>(i), at<uint16_t>(raw.bytes, r + 12));
    EXPECT_EQ(d.find(dim::kReturnNumber)->get<uint8_t>(i), static_cast<uint8_t>(raw.bytes[r + 14]) & 7);
    EXPECT_EQ(d.find(dim::kNumberOfReturns)->get<uint8_t>(i), (static_cast<uint8_t>(raw.bytes[r + 14]) >> 3) & 7);
    EXPECT_EQ(d.find(dim::kClassification)->get<uint8_t>(i), static_cast<uint8_t>(raw.bytes[r + 15]) & 31);
    EXPECT_EQ(d.find(dim::kScanAngleRank)->get<int8_t>(i), static_cast<int8_t>(raw.bytes[r + 16]));
    EXPECT_EQ(d.find(dim::kPointSourceId)->get<uint16_t>(i), at<uint16_t>(raw.bytes, r + 18));
    EXPECT_EQ(d.find(dim::kGpsTime)->get<double>(i), at<double>(raw.bytes, r + 20));
  }
  // The first point: intensity 143, class 1.
  EXPECT_EQ(d.find(dim::kIntensity)->get<uint16_t>(0), 143);
  EXPECT_EQ(d.find(dim::kClassification)->get<uint8_t>(0), 1);
  ASSERT_TRUE(points->las);
  EXPECT_EQ(points->las->point_format, 3);
  EXPECT_EQ(points->las->scale, glm::dvec3(0.01));
}

TEST(LasDimensions, extraBytesBecomeDimensionsOfTheirDeclaredTypes) {
  Result<PointSet> points = readLas(std::string(DPOINT_CORPUS_DIR) + "/las/extrabytes.las");
  ASSERT_TRUE(points);
  // The file's VLR: Colors (3 × uint16, deprecated array), Reserved (undocumented), Flags
  // (2 × int8), Intensity (uint32), Time (uint64).
  const Dimensions& d = points->dimensions;
  ASSERT_TRUE(d.find("Colors_0") && d.find("Colors_2") && d.find("Flags_1") && d.find("Intensity") && d.find("Time"));
  EXPECT_EQ(d.find("Colors_1")->type, DimType::kU16);
  EXPECT_EQ(d.find("Flags_0")->type, DimType::kI8);
  EXPECT_EQ(d.find("Intensity")->type, DimType::kU32);
  EXPECT_EQ(d.find("Time")->type, DimType::kU64);
  EXPECT_TRUE(d.find(dim::kIntensity)) << "the LAS field keeps its own name beside the extra bytes' Intensity";
}

// A LAS file writeLas makes at `path` of points (0,0,0), (1,2,3), … with one dimension, `values`
// of `type` (an extra bytes field): its bytes, and where its extra bytes descriptor starts in them.
struct OneFieldLas {
  std::string bytes;
  size_t descriptor = std::string::npos;
};
OneFieldLas oneFieldLas(const std::string& path, const std::string& name, DimType type, const std::vector<double>& values) {
  PointSet set;
  for (size_t i = 0; i < values.size(); ++i) {
    const double k = static_cast<double>(i);
    set.positions.emplace_back(k, 2.0 * k, 3.0 * k);
  }
  Dimension& field = set.dimensions.add(name, type, values.size());
  for (size_t i = 0; i < values.size(); ++i) field.setValue(i, values[i]);
  if (!writeLas(path, set)) return {};
  OneFieldLas las{readFile(path)};
  las.descriptor = descriptorAt(las.bytes);
  return las;
}

// An extra bytes field with a scale and offset (options bits 3 and 4, as Riegl's amplitudes and
// deviations come) is its stored number · scale + offset, a float64 dimension, in every reader and
// so in every format written from it; LAS → LAS writes the same records and the same descriptor
// (its no-data value and description kept, its minimum and maximum the written set's). The build
// before read the stored numbers (5 for 100.5) and wrote the descriptor without its scale and
// offset, so other readers got 5 too.
TEST(LasDimensions, scaledExtraBytesAreTheirScaledValues) {
  TempDir dir;
  // The descriptor made a scaled one: 0.1 and 100, no-data 65535, min and max 5 and 7, a description.
  OneFieldLas written = oneFieldLas(dir.file("raw.las"), "amplitude", DimType::kU16, {5, 7, 65535});
  std::string& file = written.bytes;
  const size_t d = written.descriptor;
  ASSERT_NE(d, std::string::npos);
  ASSERT_EQ(file[d + 2], 3) << "uint16";
  file[d + 3] = 0x1F;
  const auto put = [&]<typename T>(size_t offset, T v) { std::memcpy(file.data() + d + offset, &v, sizeof v); };
  put(40, uint64_t{65535}), put(64, 100.5), put(88, 100.7), put(112, 0.1), put(136, 100.0);
  std::memcpy(file.data() + d + 160, "amplitude in dB", 15);
  writeFile(dir.file("scaled.las"), file);

  Result<PointSet> read = readLas(dir.file("scaled.las"));
  ASSERT_TRUE(read) << read.error().message;
  const Dimension* a = read->dimensions.find("amplitude");
  ASSERT_TRUE(a);
  EXPECT_EQ(a->type, DimType::kF64);
  EXPECT_EQ(a->get<double>(0), 5 * 0.1 + 100.0);
  EXPECT_EQ(a->get<double>(1), 7 * 0.1 + 100.0);

  // LAS → LAS (and LAZ): the same records, the same descriptor but its range (of 65535 now too).
  for (const char* name : {"back.las", "back.laz"}) {
    LasWriteOptions options;
    options.compress = std::string(name).ends_with(".laz");
    ASSERT_TRUE(writeLas(dir.file(name), *read, options));
    Result<PointSet> again = readLas(dir.file(name));
    ASSERT_TRUE(again);
    EXPECT_EQ(again->dimensions.find("amplitude")->get<double>(1), 7 * 0.1 + 100.0) << name;
  }
  const std::string back = readFile(dir.file("back.las"));
  EXPECT_TRUE(recordsOf(dir.file("back.las")).bytes == recordsOf(dir.file("scaled.las")).bytes);
  const size_t b = descriptorAt(back);
  ASSERT_NE(b, std::string::npos);
  EXPECT_EQ(back.compare(b, 64, file, d, 64), 0) << "type, options, name, no-data";
  // Min and max are doubles of the values, scale and offset applied (R15); the set's now reach the
  // no-data value's 6653.5.
  EXPECT_EQ(at<double>(back, b + 64), 5 * 0.1 + 100.0);
  EXPECT_EQ(at<double>(back, b + 88), 65535 * 0.1 + 100.0);
  EXPECT_EQ(back.compare(b + 112, 80, file, d + 112, 80), 0) << "scale, offset, description";

  // CSV has the values.
  ASSERT_TRUE(writeCsv(dir.file("a.csv"), *read));
  EXPECT_NE(readFile(dir.file("a.csv")).find(",100.5\n"), std::string::npos) << readFile(dir.file("a.csv"));

  // A scale of 0 says nothing: the field is read as stored, the other fields as they were (one such
  // descriptor made every field of the file undescribed bytes).
  {
    std::string zero = file;
    put(112, 0.0);
    writeFile(dir.file("zero.las"), file);
    file = zero;
    Result<PointSet> raw = readLas(dir.file("zero.las"));
    ASSERT_TRUE(raw);
    ASSERT_TRUE(raw->dimensions.find("amplitude"));
    EXPECT_EQ(raw->dimensions.find("amplitude")->type, DimType::kU16);
    EXPECT_EQ(raw->dimensions.find("amplitude")->value(1), 7.0);
  }

  // A scaled float32 field: its stored floats back through the scale, not rounded to whole
  // numbers (it was written as float64 and the record grew).
  {
    OneFieldLas float_las = oneFieldLas(dir.file("f.las"), "echo_width", DimType::kF32, {1.25, double(3.1f)});
    std::string& f = float_las.bytes;
    const size_t fd = float_las.descriptor;
    ASSERT_NE(fd, std::string::npos);
    ASSERT_EQ(f[fd + 2], 9) << "float32";
    f[fd + 3] = 0x08;
    const double half = 0.5;
    std::memcpy(f.data() + fd + 112, &half, sizeof half);
    writeFile(dir.file("f-scaled.las"), f);
    Result<PointSet> scaled = readLas(dir.file("f-scaled.las"));
    ASSERT_TRUE(scaled);
    EXPECT_EQ(scaled->dimensions.find("echo_width")->get<double>(1), double(3.1f) * 0.5);
    ASSERT_TRUE(writeLas(dir.file("f-back.las"), *scaled));
    EXPECT_TRUE(recordsOf(dir.file("f-back.las")).bytes == recordsOf(dir.file("f-scaled.las")).bytes);
  }

  // A value the scale cannot store: the dimension is written as float64, unscaled, exactly.
  read->dimensions.find("amplitude")->set<double>(2, 100.55);
  ASSERT_TRUE(writeLas(dir.file("wide.las"), *read));
  const std::string wide = readFile(dir.file("wide.las"));
  const size_t w = descriptorAt(wide);
  ASSERT_NE(w, std::string::npos);
  EXPECT_EQ(wide[w + 2], 10) << "float64";
  EXPECT_EQ(wide[w + 3], 0) << "no scale";
  Result<PointSet> wide_back = readLas(dir.file("wide.las"));
  ASSERT_TRUE(wide_back);
  EXPECT_EQ(wide_back->dimensions.find("amplitude")->get<double>(2), 100.55);
}

// An extra bytes record the reader cannot follow (a data type past LAS's 30, a descriptor past the
// record's extra bytes, a length that is not whole descriptors) leaves the bytes as they are, one
// dimension a byte, and says so through the notices, read whole or streamed; the build before
// read them so without a word.
TEST(LasDimensions, anExtraBytesRecordItCannotFollowIsReadAsBytesWithANotice) {
  TempDir dir;
  OneFieldLas good = oneFieldLas(dir.file("good.las"), "amplitude", DimType::kU16, {0x0102, 0x0304});
  std::string& file = good.bytes;
  const size_t d = good.descriptor;
  ASSERT_NE(d, std::string::npos);
  file[d + 2] = 31;
  writeFile(dir.file("broken.las"), file);

  std::vector<std::string> notices;
  LasReadOptions options;
  options.notices = &notices;
  Result<PointSet> read = readLas(dir.file("broken.las"), options);
  ASSERT_TRUE(read) << read.error().message;
  EXPECT_FALSE(read->dimensions.find("amplitude"));
  ASSERT_TRUE(read->dimensions.find("extra_byte_0") && read->dimensions.find("extra_byte_1"));
  EXPECT_EQ(read->dimensions.find("extra_byte_1")->get<uint8_t>(1), 0x03);
  ASSERT_EQ(notices.size(), 1u);
  EXPECT_EQ(notices[0], dir.file("broken.las") +
                            ": extra bytes descriptor 0 ('amplitude'): data type 31 is not one of LAS's 0 to 30; "
                            "its 2 extra bytes a point are read as they are (extra_byte_0, ...)");
  Result<std::unique_ptr<LasPointStream>> stream = LasPointStream::open(dir.file("broken.las"));
  ASSERT_TRUE(stream);
  EXPECT_EQ((*stream)->notices(), notices);
  EXPECT_TRUE((*stream)->dimensions().find("extra_byte_0"));

  // The file as written: no notice.
  notices.clear();
  ASSERT_TRUE(readLas(dir.file("good.las"), options));
  EXPECT_TRUE(notices.empty());
  stream = LasPointStream::open(dir.file("good.las"));
  ASSERT_TRUE(stream);
  EXPECT_TRUE((*stream)->notices().empty());
}

// A fuzz finding (las, 236 bytes): a record length of 5120 made 5100 extra_byte dimensions, named
// by pairwise checks that took over a second under the sanitizers. The widest record LAS allows:
// 65,515 undescribed bytes, each its own uniquely named dimension, kept through LAS → LAS.
TEST(LasDimensions, theWidestRecordsExtraBytesAreNamedOnce) {
  TempDir dir;
  std::string header(227, '\0');
  std::memcpy(header.data(), "LASF", 4);
  header[24] = 1, header[25] = 2;
  const auto put16 = [&](size_t at, uint16_t v) { std::memcpy(header.data() + at, &v, 2); };
  const auto put32 = [&](size_t at, uint32_t v) { std::memcpy(header.data() + at, &v, 4); };
  put16(94, 227);
  put32(96, 227);
  put16(105, 65535);  // point format 0: 20 bytes, then 65,515 extra
  put32(107, 1);
  const double scale = 0.01;
  for (int k = 0; k < 3; ++k) std::memcpy(header.data() + 131 + 8 * k, &scale, 8);
  std::string record(65535, '\0');
  record[20] = 7, record[65534] = 9;
  test::writeFile(dir.file("wide.las"), header + record);
  Result<PointSet> points = readLas(dir.file("wide.las"));
  ASSERT_TRUE(points) << points.error().message;
  ASSERT_TRUE(points->dimensions.find("extra_byte_0") && points->dimensions.find("extra_byte_65514"));
  EXPECT_EQ(points->dimensions.find("extra_byte_0")->get<uint8_t>(0), 7);
  EXPECT_EQ(points->dimensions.find("extra_byte_65514")->get<uint8_t>(0), 9);
  ASSERT_TRUE(writeLas(dir.file("back.las"), *points));
  EXPECT_TRUE(recordsOf(dir.file("back.las")).bytes == recordsOf(dir.file("wide.las")).bytes);
  // Undescribed as they came (a descriptor each had wrapped the VLR's 16-bit length): read back
  // as the same dimensions, without an extra bytes VLR.
  Result<PointSet> back = readLas(dir.file("back.las"));
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_TRUE(back->las->extra_bytes.empty());  // no descriptor
  EXPECT_EQ(back->dimensions.find("extra_byte_65514")->get<uint8_t>(0), 9);
}

// Undescribed bytes among described fields come back in offset order, and one whose name a
// descriptor already took gets a suffix (the fast path that names undescribed bytes without a
// lookup must not skip that case).
TEST(LasDimensions, undescribedBytesSitBetweenDescribedFieldsAndKeepTheirNamesUnique) {
  LasVlr vlr;
  vlr.user_id = "LASF_Spec";
  vlr.record_id = 4;
  vlr.data.assign(2 * 192, '\0');
  vlr.data[2] = 0, vlr.data[3] = 1;  // one undocumented byte: offset 0, kept as extra_byte_0
  vlr.data[192 + 2] = 3;             // uint16 at offsets 1-2, named as an undescribed byte would be
  std::memcpy(vlr.data.data() + 192 + 4, "extra_byte_3", 12);
  Result<std::vector<LasExtraField>> fields = lasExtraFields(&vlr, 5, lasFields(0));
  ASSERT_TRUE(fields) << fields.error().message;
  std::vector<std::string> names;
  std::vector<uint32_t> offsets;
  for (const LasExtraField& f : *fields) names.push_back(f.name), offsets.push_back(f.offset);
  EXPECT_EQ(names, (std::vector<std::string>{"extra_byte_0", "extra_byte_3", "extra_byte_3_2", "extra_byte_4"}));
  EXPECT_EQ(offsets, (std::vector<uint32_t>{0, 1, 3, 4}));
  EXPECT_EQ((*fields)[1].type, DimType::kU16);
}

TEST(LasDimensions, aSetWithoutLasSourceGetsTheSmallestFormatThatHoldsIt) {
  TempDir dir;
  PointSet set;
  set.positions = {{0, 0, 0}, {1, 2, 3}, {4, 5, 6}};
  set.dimensions.add(dim::kClassification, DimType::kU8, 3).set<uint8_t>(1, 6);
  set.dimensions.add("temperature", DimType::kF32, 3).set<float>(2, 21.5f);
  ASSERT_TRUE(writeLas(dir.file("a.las"), set));
  EXPECT_EQ(recordsOf(dir.file("a.las")).format, 0);
  Result<PointSet> back = readLas(dir.file("a.las"));
  ASSERT_TRUE(back);
  EXPECT_EQ(back->dimensions.find(dim::kClassification)->get<uint8_t>(1), 6);
  ASSERT_TRUE(back->dimensions.find("temperature"));
  EXPECT_EQ(back->dimensions.find("temperature")->get<float>(2), 21.5f);
  EXPECT_EQ(back->dimensions.find(dim::kReturnNumber)->get<uint8_t>(0), 1) << "return 1 of 1";

  // A class above 31 needs LAS 1.4's 8-bit field: format 6.
  set.dimensions.find(dim::kClassification)->set<uint8_t>(0, 64);
  set.dimensions.add(dim::kGpsTime, DimType::kF64, 3).set<double>(0, 12.25);
  ASSERT_TRUE(writeLas(dir.file("b.las"), set));
  EXPECT_EQ(recordsOf(dir.file("b.las")).format, 6);
  back = readLas(dir.file("b.las"));
  ASSERT_TRUE(back);
  EXPECT_EQ(back->dimensions.find(dim::kClassification)->get<uint8_t>(0), 64);
  EXPECT_EQ(back->dimensions.find(dim::kGpsTime)->get<double>(0), 12.25);
}

// The source's format is kept only where the set still has its colours, GPS time, NIR and wave
// packets: --no-colors and --drop gps_time leave the fields out, not zeros in them (a review
// finding). An angle in 0.006° steps needs format 6 (a legacy format's whole degrees clamped
// 30000 to 90). COPC takes a waveform format's base with its colours (5 had lost them; 9 and 10
// were refused).
TEST(LasDimensions, aFieldTheSetLacksIsLeftOutNotWrittenAsZeros) {
  TempDir dir;
  Result<PointSet> simple = readLas(std::string(DPOINT_CORPUS_DIR) + "/las/simple.las");  // format 3
  ASSERT_TRUE(simple);
  PointSet no_colours = *simple;
  no_colours.colors.clear();
  ASSERT_TRUE(writeLas(dir.file("nc.las"), no_colours));
  EXPECT_EQ(recordsOf(dir.file("nc.las")).format, 1);
  PointSet no_time = *simple;
  ASSERT_TRUE(no_time.dimensions.remove(dim::kGpsTime));
  ASSERT_TRUE(writeLas(dir.file("nt.las"), no_time));
  EXPECT_EQ(recordsOf(dir.file("nt.las")).format, 2);
  ASSERT_TRUE(writeLas(dir.file("same.las"), *simple));
  EXPECT_EQ(recordsOf(dir.file("same.las")).format, 3);

  PointSet angles;
  angles.positions = {{0, 0, 0}, {1, 1, 1}};
  angles.dimensions.add(dim::kScanAngle, DimType::kI16, 2).set<int16_t>(1, 30000);
  ASSERT_TRUE(writeLas(dir.file("angle.las"), angles));
  EXPECT_EQ(recordsOf(dir.file("angle.las")).format, 6);
  Result<PointSet> back = readLas(dir.file("angle.las"));
  ASSERT_TRUE(back);
  EXPECT_EQ(back->dimensions.find(dim::kScanAngle)->get<int16_t>(1), 30000);

  for (const auto& [source, copc] : std::vector<std::pair<int, int>>{{4, 6}, {5, 7}, {9, 6}, {10, 8}}) {
    SCOPED_TRACE("format " + std::to_string(source));
    PointSet set;
    set.positions = {{0, 0, 0}, {1, 1, 1}};
    LasSource las;
    las.point_format = source;
    las.version_minor = 4;
    set.las = las;
    for (const LasField& f : lasFields(source)) set.dimensions.add(f.name, f.type, 2);
    set.dimensions.find(dim::kWavePacketSize)->set<uint32_t>(1, 77);
    if (source == 5 || source == 10) set.colors = {{0.0f, 1.0f, 1.0f}, {1.0f, 0.0f, 0.0f}};
    if (source == 10) set.dimensions.find(dim::kNir)->set<uint16_t>(1, 4242);
    const std::string path = dir.file("w" + std::to_string(source) + ".copc.laz");
    ASSERT_TRUE(writePoints(path, set)) << path;
    Result<PointSet> read = readPoints(path);
    ASSERT_TRUE(read) << read.error().message;
    EXPECT_EQ(read->las->point_format, copc);
    EXPECT_EQ(read->hasColors(), !set.colors.empty());
    if (read->hasColors()) {
      EXPECT_EQ(read->colors[1], set.colors[1]);
    }
    EXPECT_EQ(read->dimensions.find(dim::kWavePacketSize)->value(1), 77.0);  // an extra bytes field
    if (source == 10) {
      EXPECT_EQ(read->dimensions.find(dim::kNir)->value(1), 4242.0);
    }
  }
}

// Each extra bytes field is a 192-byte descriptor in one VLR of 16-bit length: 341 fit, 342 are
// refused by name (they had wrapped the length, and no reader found the records after it).
TEST(LasDimensions, moreExtraBytesFieldsThanOneVlrDescribesAreRefused) {
  TempDir dir;
  PointSet set;
  set.positions = {{0, 0, 0}};
  for (int k = 0; k < 341; ++k) {
    std::string name = "d";  // not "d" + …: GCC 12's -Wrestrict false alarm
    name += std::to_string(k);
    set.dimensions.add(name, DimType::kU8, 1);
  }
  ASSERT_TRUE(writeLas(dir.file("341.laz"), set, [] { LasWriteOptions o; o.compress = true; return o; }()));
  Result<PointSet> back = readLas(dir.file("341.laz"));
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_TRUE(back->dimensions.find("d340"));
  set.dimensions.add("d341", DimType::kU8, 1);
  const Status refused = writeLas(dir.file("342.las"), set);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().message, dir.file("342.las") + ": 342 dimensions as LAS extra bytes, past the 341 whose "
                                                           "descriptors one VLR holds (leave some out with --drop NAME)");
  EXPECT_FALSE(std::filesystem::exists(dir.file("342.las")));
}

// A float intensity of 0..1 values (PTX's, a normalised one) is LAS's 16-bit intensity as a
// fraction of 65535, LAS and LAZ alike, and the report says so; one of whole numbers (0 and 1
// alone too) is written as it is. The build before refused 0.5 as no whole number.
TEST(LasDimensions, anIntensityOfFractionsIsWrittenAsSixteenBits) {
  TempDir dir;
  for (const bool compress : {false, true}) {
    for (const bool fractions : {true, false}) {
      PointSet set;
      set.positions = {{0, 0, 0}, {1, 2, 3}, {4, 5, 6}};
      Dimension& d = set.dimensions.add(dim::kIntensity, DimType::kF32, 3);
      d.setValue(1, fractions ? 0.5 : 0.0);
      d.setValue(2, 1.0);
      const std::string path = dir.file(compress ? "i.laz" : "i.las");
      LasWriteReport report;
      LasWriteOptions options;
      options.compress = compress;
      options.report = &report;
      ASSERT_TRUE(writeLas(path, set, options)) << compress;
      EXPECT_EQ(report.intensity_scaled, fractions);
      Result<PointSet> back = readLas(path);
      ASSERT_TRUE(back.ok()) << back.error().message;
      const Dimension* intensity = back->dimensions.find(dim::kIntensity);
      ASSERT_NE(intensity, nullptr);
      EXPECT_EQ(intensity->value(1), fractions ? 32768.0 : 0.0);  // round(0.5 · 65535)
      EXPECT_EQ(intensity->value(2), fractions ? 65535.0 : 1.0);
    }
  }
  // One value outside 0..1 among fractions: refused, the message naming it beside the first misfit.
  PointSet set;
  set.positions = {{0, 0, 0}, {1, 2, 3}, {4, 5, 6}};
  Dimension& d = set.dimensions.add(dim::kIntensity, DimType::kF64, 3);
  d.setValue(0, 0.5);
  d.setValue(2, -0.125);
  const Status s = writeLas(dir.file("neg.las"), set);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("point 0: intensity = 0.5 does not fit"), std::string::npos) << s.error().message;
  EXPECT_NE(s.error().message.find("(an intensity of 0..1 values is written as fractions of 65535, but point 2's is -0.125)"),
            std::string::npos)
      << s.error().message;
}

// A value its LAS field cannot hold as it is (a fraction, or beyond the field's bits or type) is
// refused, naming the point, the dimension and the field's range, and nothing is written, as LAS
// and as LAZ: the build before rounded, clamped or masked it silently (return 20 was written as 4,
// intensity 0.25 as 0, 70000 as 65535). A whole value in range is written, whatever its type, and
// an intensity of 0..1 values as a fraction of 65535 (above).
TEST(LasDimensions, aValueItsFieldCannotHoldIsRefused) {
  TempDir dir;
  struct Case {
    const char* name;
    DimType type;
    double value;
    const char* says;
  };
  for (const Case& c : {Case{dim::kReturnNumber, DimType::kU8, 20, "return_number = 20 does not fit LAS point format 6's "
                                                                   "return_number, a whole number 0..15 (4 bits)"},
                        Case{dim::kScannerChannel, DimType::kU8, 5, "0..3 (2 bits)"},
                        Case{dim::kSynthetic, DimType::kU8, 2, "0..1 (1 bit)"},
                        Case{dim::kIntensity, DimType::kF64, 1.25, "intensity = 1.25 does not fit LAS point format 0's "
                                                                   "intensity, a whole number 0..65535 (uint16)"},
                        Case{dim::kIntensity, DimType::kF64, 70000, "0..65535 (uint16)"},
                        Case{dim::kPointSourceId, DimType::kI32, -5, "0..65535 (uint16)"},
                        Case{dim::kScanAngleRank, DimType::kI16, 200, "-128..127 (int8)"}}) {
    for (const bool compress : {false, true}) {
      PointSet set;
      set.positions = {{0, 0, 0}, {1, 2, 3}, {4, 5, 6}};
      Dimension& d = set.dimensions.add(c.name, c.type, 3);
      d.setValue(0, 1.0);
      d.setValue(2, c.value);
      const std::string path = dir.file(compress ? "bad.laz" : "bad.las");
      std::filesystem::remove(path);  // the case before wrote one
      LasWriteOptions options;
      options.compress = compress;
      const Status s = writeLas(path, set, options);
      ASSERT_FALSE(s) << c.name << " " << c.value;
      EXPECT_EQ(s.error().code, ExitCode::kBadInput);
      EXPECT_NE(s.error().message.find(path + ": point 2: "), std::string::npos) << s.error().message;
      EXPECT_NE(s.error().message.find(c.says), std::string::npos) << s.error().message;
      EXPECT_NE(s.error().message.find(std::string("--drop ") + c.name), std::string::npos) << s.error().message;
      EXPECT_FALSE(std::filesystem::exists(path));
      // The same dimension with a whole value in range is written and read back.
      d.setValue(2, 1.0);
      ASSERT_TRUE(writeLas(path, set, options)) << c.name;
      Result<PointSet> back = readLas(path);
      ASSERT_TRUE(back);
      EXPECT_EQ(back->dimensions.find(c.name)->value(2), 1.0) << c.name;
    }
  }
}

// Coordinates so large that LAS's integers at any decimal scale reach beyond double's range are
// refused, exit 2, nothing written: the build before wrote a file its own reader then refused.
TEST(LasDimensions, coordinatesBeyondWhatLasHoldsAreRefused) {
  TempDir dir;
  PointSet set;
  set.positions = {{1e308, 0, 0}, {-1e308, 0, 0}};
  const Status s = writeLas(dir.file("big.las"), set);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().code, ExitCode::kBadInput);
  EXPECT_NE(s.error().message.find("x spans -1e+308 .. 1e+308"), std::string::npos) << s.error().message;
  EXPECT_FALSE(std::filesystem::exists(dir.file("big.las")));
  set.positions = {{1e300, 0, 0}, {-1e300, 0, 0}};  // still within reach: written and read back
  ASSERT_TRUE(writeLas(dir.file("wide.las"), set));
  Result<PointSet> back = readLas(dir.file("wide.las"));
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_NEAR(back->positions[0].x, 1e300, 1e291);  // within a step of the scale
}

TEST(LasDimensions, mortonOrderAndUniqueCarryEachPointsAttributes) {
  PointSet set;
  Dimension& id = set.dimensions.add("id", DimType::kU32, 0);
  for (uint32_t i = 0; i < 5000; ++i) {
    set.positions.push_back({double((i * 7919) % 5000), double((i * 104729) % 4999), double(i % 13)});
    id.resize(i + 1);
    id.set<uint32_t>(i, i);
  }
  const PositionArray before = set.positions;
  reorderPoints(set, PointOrder::kMorton, 2);
  ASSERT_EQ(set.dimensions.find("id")->size(), 5000u);
  bool moved = false;
  for (size_t i = 0; i < set.size(); ++i) {
    const uint32_t was = set.dimensions.find("id")->get<uint32_t>(i);
    EXPECT_EQ(set.positions[i], before[was]);
    moved |= was != i;
  }
  EXPECT_TRUE(moved);
  set.positions.push_back(set.positions[10]);  // a duplicate: unique keeps the first point's id
  set.dimensions.resize(set.size());
  set.dimensions.find("id")->set<uint32_t>(set.size() - 1, 99999);
  dropDuplicatePositions(set);
  EXPECT_EQ(set.size(), 5000u);
  EXPECT_EQ(set.dimensions.find("id")->size(), 5000u);
  EXPECT_NE(set.dimensions.find("id")->get<uint32_t>(10), 99999u);
}

}  // namespace
}  // namespace dpoint
