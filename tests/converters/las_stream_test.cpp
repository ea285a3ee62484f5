// LasPointStream (converters/las.h): LAS and LAZ files read a block at a time, as `render` and
// `info --stream` read them, give what readLas gives whole: every position, colour and streamed
// dimension, for every corpus file, in blocks that do not line up with LAZ's chunks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "converters/las.h"
#include "converters/point_inputs.h"
#include "converters/point_io.h"
#include "test_support.h"

namespace dpoint {
namespace {

std::vector<std::string> corpusFiles() {
  std::vector<std::string> files;
  for (const char* folder : {"/las", "/laz"})
    for (const auto& entry : std::filesystem::directory_iterator(std::string(DPOINT_CORPUS_DIR) + folder)) {
      const std::string ext = entry.path().extension().string();
      if (ext == ".las" || ext == ".laz") files.push_back(entry.path().string());
    }
  std::sort(files.begin(), files.end());
  return files;
}

TEST(LasStream, everyCorpusFileStreamsAsItReadsWhole) {
  const std::vector<std::string> files = corpusFiles();
  ASSERT_GE(files.size(), 20u);
  size_t laz = 0;
  for (const std::string& path : files) {
    SCOPED_TRACE(path);
    Result<PointSet> whole = readLas(path);
    ASSERT_TRUE(whole) << whole.error().message;
    Result<std::unique_ptr<LasPointStream>> opened = LasPointStream::open(path, 2);
    ASSERT_TRUE(opened) << opened.error().message;
    LasPointStream& stream = **opened;
    laz += stream.header().compressed ? 1 : 0;
    ASSERT_EQ(stream.count(), whole->size());
    EXPECT_EQ(stream.hasColors(), whole->hasColors());
    ASSERT_EQ(stream.dimensions().count(), whole->dimensions.count());
    std::vector<size_t> all;
    for (size_t k = 0; k < stream.dimensions().count(); ++k) all.push_back(k);
    stream.streamDimensions(all);
    PointSet block;
    const uint64_t step = 7777;  // across LAZ's 50,000-point chunks
    for (uint64_t first = 0; first < stream.count(); first += step) {
      const uint64_t n = std::min(step, stream.count() - first);
      ASSERT_TRUE(stream.read(first, n, block).ok());
      ASSERT_EQ(block.size(), n);
      for (uint64_t i = 0; i < n; ++i) {
        ASSERT_EQ(block.positions[i], whole->positions[first + i]) << "point " << first + i;
        if (whole->hasColors()) {
          ASSERT_EQ(block.colors[i], whole->colors[first + i]) << "point " << first + i;
        }
      }
      for (size_t k = 0; k < all.size(); ++k) {
        const Dimension& got = block.dimensions.all()[k];
        const Dimension& want = whole->dimensions.all()[k];
        ASSERT_EQ(got.name, want.name);
        const size_t w = dimTypeSize(want.type);
        ASSERT_TRUE(std::equal(got.bytes.begin(), got.bytes.end(), want.bytes.begin() + static_cast<ptrdiff_t>(first * w),
                               want.bytes.begin() + static_cast<ptrdiff_t>((first + n) * w)))
            << want.name;
      }
    }
  }
  EXPECT_GE(laz, 10u);
}

TEST(LasStream, renderAndInfoStreamLazAndLas) {
  const std::string laz = std::string(DPOINT_CORPUS_DIR) + "/laz/autzen_trim.laz";
  Result<std::unique_ptr<PointInputStream>> on = openPointStream({laz}, "on", 2);
  ASSERT_TRUE(on) << on.error().message;
  ASSERT_TRUE(*on);
  EXPECT_EQ((*on)->count(), 110000u);
  ASSERT_TRUE((*on)->streamDimensions({"classification"}).ok());
  PointSet block;
  ASSERT_TRUE((*on)->read(49990, 20, block).ok());  // across the first chunk's end
  ASSERT_EQ(block.dimensions.count(), 1u);
  // auto streams only sets larger than kStreamAbovePoints.
  Result<std::unique_ptr<PointInputStream>> automatic = openPointStream({laz}, "auto", 2);
  ASSERT_TRUE(automatic);
  EXPECT_FALSE(*automatic);
}

// Several dimensions at once from a mix of files (PLY, E57, LAS), as `info --stream` takes them
// for their ranges: every value the whole read has, in blocks across the files' ends, in the types
// the whole read gives; a name one file lacks changes nothing.
TEST(LasStream, severalDimensionsStreamFromAMixOfFilesAsTheWholeReadHasThem) {
  test::TempDir dir;
  Result<PointSet> autzen = readLas(std::string(DPOINT_CORPUS_DIR) + "/laz/autzen_trim.laz");
  ASSERT_TRUE(autzen) << autzen.error().message;
  autzen->positions.resize(3000), autzen->colors.resize(3000);  // of its 110,000
  for (Dimension& d : autzen->dimensions.all()) d.resize(3000);
  autzen->las.reset();
  const std::vector<std::string> paths{dir.file("autzen.ply"), std::string(DPOINT_TESTS_DIR) + "/data/e57/two_scans.e57",
                                       std::string(DPOINT_CORPUS_DIR) + "/las/simple.las"};
  ASSERT_TRUE(writePoints(paths[0], *autzen).ok());
  Result<PointSet> whole = readPointInputs(paths);
  ASSERT_TRUE(whole) << whole.error().message;
  Result<std::unique_ptr<PointInputStream>> opened = openPointStream(paths, "on", 2);
  ASSERT_TRUE(opened && *opened) << (opened ? "" : opened.error().message);
  PointInputStream& stream = **opened;
  ASSERT_EQ(stream.count(), whole->size());
  const Dimensions common = stream.commonDimensions();
  std::vector<std::string> names;
  for (const Dimension& d : common.all()) names.push_back(d.name);
  ASSERT_EQ(names, (std::vector<std::string>{"intensity", "point_source_id"}));
  EXPECT_EQ(common.find("intensity")->type, DimType::kF64);  // uint16 in PLY and LAS, float32 in E57
  EXPECT_EQ(common.find("point_source_id")->type, DimType::kU16);
  for (const Dimension& d : common.all()) EXPECT_EQ(d.type, whole->dimensions.find(d.name)->type) << d.name;

  const Status missing = stream.streamDimensions({"intensity", "classification"});  // not in the E57 file
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().code, ExitCode::kUsage);
  EXPECT_TRUE(test::contains(missing.error().message, "'classification'")) << missing.error().message;
  PointSet block;
  ASSERT_TRUE(stream.read(0, 10, block).ok());
  EXPECT_EQ(block.dimensions.count(), 0u);  // as before the refused call

  ASSERT_TRUE(stream.streamDimensions(names).ok());
  const uint64_t step = 1777;  // blocks across the files' ends
  for (uint64_t first = 0; first < stream.count(); first += step) {
    const uint64_t n = std::min(step, stream.count() - first);
    ASSERT_TRUE(stream.read(first, n, block).ok());
    ASSERT_EQ(block.dimensions.count(), names.size());
    for (size_t k = 0; k < names.size(); ++k) {
      const Dimension& got = block.dimensions.all()[k];
      const Dimension* want = whole->dimensions.find(names[k]);
      ASSERT_NE(want, nullptr);
      ASSERT_EQ(got.name, names[k]);
      ASSERT_EQ(got.type, common.all()[k].type);
      for (uint64_t i = 0; i < n; ++i) ASSERT_EQ(got.value(i), want->value(first + i)) << names[k] << " point " << first + i;
    }
  }
  ASSERT_TRUE(stream.streamDimensions({}).ok());
  ASSERT_TRUE(stream.read(0, 10, block).ok());
  EXPECT_EQ(block.dimensions.count(), 0u);

  // A type that holds the later files' values is kept, as the whole read keeps it (before the
  // build of 2026-12-02 the stream made it float64): uint16 then uint8 stays uint16; uint8 then
  // int8 becomes float64 in both.
  {
    std::vector<std::string> pair{dir.file("wide.ply"), dir.file("narrow.ply")};
    for (size_t f = 0; f < 2; ++f) {
      PointSet set;
      set.positions = {{0.0, 0.0, double(f)}, {1.0, 1.0, double(f)}};
      set.dimensions.append("d", f == 0 ? DimType::kU16 : DimType::kU8, 2).setValue(1, 200.0 + double(f));
      set.dimensions.append("e", f == 0 ? DimType::kU8 : DimType::kI8, 2).setValue(1, f == 0 ? 250.0 : -5.0);
      ASSERT_TRUE(writePoints(pair[f], set).ok());
    }
    Result<PointSet> joined = readPointInputs(pair);
    ASSERT_TRUE(joined) << joined.error().message;
    Result<std::unique_ptr<PointInputStream>> two = openPointStream(pair, "on", 2);
    ASSERT_TRUE(two && *two);
    for (const char* name : {"d", "e"}) {
      const DimType want = std::string(name) == "d" ? DimType::kU16 : DimType::kF64;
      EXPECT_EQ(joined->dimensions.find(name)->type, want) << name;
      EXPECT_EQ((*two)->commonDimensions().find(name)->type, want) << name;
    }
    ASSERT_TRUE((*two)->streamDimensions({"d", "e"}).ok());
    ASSERT_TRUE((*two)->read(0, 4, block).ok());
    for (size_t k = 0; k < 2; ++k)
      for (size_t i = 0; i < 4; ++i) EXPECT_EQ(block.dimensions.all()[k].value(i), joined->dimensions.all()[k].value(i));
  }

  // One PLY file's every dimension, its own types, from one read of its rows.
  Result<std::unique_ptr<PointInputStream>> ply = openPointStream({paths[0]}, "on", 2);
  ASSERT_TRUE(ply && *ply);
  names.clear();
  for (const Dimension& d : autzen->dimensions.all()) names.push_back(d.name);
  ASSERT_GE(names.size(), 10u);
  ASSERT_TRUE((*ply)->streamDimensions(names).ok());
  ASSERT_TRUE((*ply)->read(1000, 1500, block).ok());
  ASSERT_EQ(block.dimensions.count(), names.size());
  for (size_t k = 0; k < names.size(); ++k) {
    const Dimension& got = block.dimensions.all()[k];
    const Dimension& want = autzen->dimensions.all()[k];
    ASSERT_EQ(got.type, want.type) << want.name;
    const size_t w = dimTypeSize(want.type);
    EXPECT_TRUE(std::equal(got.bytes.begin(), got.bytes.end(), want.bytes.begin() + static_cast<ptrdiff_t>(1000 * w)))
        << want.name;
  }
}

}  // namespace
}  // namespace dpoint

namespace dpoint {
namespace {

// A LAZ file whose chunk claims 50M points: the stream's colour sample had allocated the claim
// (3.7 GB from a 98 KB file, past --max-memory); the chunks are now checked against the limit
// before they are decoded, and the sample takes 4096 records of a chunk.
TEST(LasStream, aChunkClaimingMorePointsThanTheLimitIsRefusedBeforeItIsAllocated) {
  test::TempDir dir;
  Result<PointSet> simple = readLas(std::string(DPOINT_CORPUS_DIR) + "/las/simple.las");  // format 3: colours
  ASSERT_TRUE(simple);
  LasWriteOptions laz;
  laz.compress = true;
  ASSERT_TRUE(writeLas(dir.file("simple.laz"), *simple, laz));
  std::string file = test::readFile(dir.file("simple.laz"));
  const size_t vlr = file.find("laszip encoded");
  ASSERT_NE(vlr, std::string::npos);
  const size_t data = vlr - 2 + 54;  // the VLR's header is 54 bytes, its user id at 2
  const uint32_t chunk = 0xFFFFFFFEu, count = 50000000u;
  std::memcpy(&file[data + 12], &chunk, 4);  // the laszip VLR's chunk size
  std::memcpy(&file[107], &count, 4);        // the legacy point count (LAS 1.2)
  test::writeFile(dir.file("claims.laz"), file);
  Result<std::unique_ptr<LasPointStream>> stream = LasPointStream::open(dir.file("claims.laz"), 1, 64u << 20);
  ASSERT_FALSE(stream);
  EXPECT_EQ(stream.error().code, ExitCode::kResourceLimit);
  EXPECT_TRUE(test::contains(stream.error().message, "claims.laz: decoding LAZ chunks 0 to 0 (50000000 points) needs about"))
      << stream.error().message;
  // The file as written streams: the sample is a chunk's first 4096 records.
  Result<std::unique_ptr<LasPointStream>> fine = LasPointStream::open(dir.file("simple.laz"), 1, 64u << 20);
  ASSERT_TRUE(fine) << fine.error().message;
  EXPECT_TRUE((*fine)->hasColors());
}

}  // namespace
}  // namespace dpoint
