// libgeotiff (Debian's libgeotiff-dev, the library libLAS and PDAL read LAS GeoTIFF keys with) judges
// the GeoTIFF keys `convert --crs` writes into a LAS 1.2 file: this test finds the records in the
// file's bytes itself, gives them to libgeotiff as TIFF tags (its simple-tags interface) and reads
// back the model, the EPSG codes, the unit and the citation through libgeotiff's own key parser
// and normalizer (GTIFGetDefn, which looks the codes up in PROJ's database).
#include <geotiff/geo_normalize.h>
#include <geotiff/geo_simpletags.h>
#include <geotiff/geotiff.h>
#include <geotiff/geovalues.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "converters/las.h"
#include "converters/las_crs.h"
#include "test_support.h"

namespace dpoint {
namespace {

template <typename T>
T at(const std::string& bytes, size_t offset) {
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof(T));
  return v;
}

// The LASF_Projection records of a LAS file, by record id, from its bytes (LAS 1.2 R2, tables 3-4:
// the header's size at byte 94, the VLR count at 100; a VLR's 54-byte header, then its data).
std::map<uint16_t, std::string> projectionRecords(const std::string& file) {
  std::map<uint16_t, std::string> records;
  size_t offset = at<uint16_t>(file, 94);
  const uint32_t count = at<uint32_t>(file, 100);
  for (uint32_t k = 0; k < count && offset + 54 <= file.size(); ++k) {
    const std::string user(file.data() + offset + 2, strnlen(file.data() + offset + 2, 16));
    const uint16_t id = at<uint16_t>(file, offset + 18), length = at<uint16_t>(file, offset + 20);
    if (user == "LASF_Projection") records[id] = file.substr(offset + 54, length);
    offset += 54 + length;
  }
  return records;
}

struct Judged {
  int model = 0, pcs = 0, gcs = 0, vertical = 0, vertical_units = 0;
  double length_in_meters = 0.0;
  std::string citation, pcs_name;
};

// What libgeotiff reads of a LAS file's GeoTIFF keys.
Judged judge(const std::string& path) {
  const std::string file = test::readFile(path);
  std::map<uint16_t, std::string> records = projectionRecords(file);
  Judged out;
  if (!records.count(34735)) return out;
  std::string& keys = records[34735];
  ST_TIFF* tags = ST_Create();
  ST_SetKey(tags, 34735, static_cast<int>(keys.size() / 2), STT_SHORT, keys.data());
  if (records.count(34737))
    ST_SetKey(tags, 34737, static_cast<int>(records[34737].size()), STT_ASCII, records[34737].data());
  GTIF* gtif = GTIFNewSimpleTags(tags);
  EXPECT_NE(gtif, nullptr);
  if (gtif) {
    GTIFDefn defn;
    if (GTIFGetDefn(gtif, &defn)) {
      out.model = defn.Model, out.pcs = defn.PCS, out.gcs = defn.GCS;
      out.length_in_meters = defn.UOMLengthInMeters;
    }
    unsigned short value = 0;
    if (GTIFKeyGet(gtif, VerticalCSTypeGeoKey, &value, 0, 1)) out.vertical = value;
    if (GTIFKeyGet(gtif, VerticalUnitsGeoKey, &value, 0, 1)) out.vertical_units = value;
    char citation[256] = {};
    if (GTIFKeyGet(gtif, GTCitationGeoKey, citation, 0, sizeof citation)) out.citation = citation;
    char* name = nullptr;
    if (out.pcs && GTIFGetPCSInfo(out.pcs, &name, nullptr, nullptr, nullptr) && name) {
      out.pcs_name = name;
      GTIFFreeMemory(name);
    }
    GTIFFree(gtif);
  }
  ST_Destroy(tags);
  return out;
}

// `--crs` with an EPSG CRS, and no point format, count or source that needs LAS 1.4: GeoTIFF keys in
// a LAS 1.2 file, which libgeotiff reads as the same CRS; dpoint reads them back as the same codes.
TEST(LasGeoTiff, aGivenEpsgCrsIsGeoTiffKeysThatLibgeotiffReads) {
  test::TempDir dir;
  PointSet set;
  set.positions = {{500000.0, 4000000.0, 10.0}, {500001.5, 4000002.0, 11.0}};
  struct Case {
    const char* crs;
    int model, pcs, gcs, vertical, vertical_units;
    double length_in_meters;
    const char* pcs_name;
    const char* citation;
    const char* summary;
  };
  const Case cases[] = {
      {"EPSG:32633", ModelTypeProjected, 32633, 4326, 0, 0, 1.0, "WGS 84 / UTM zone 33N", "WGS 84 / UTM zone 33N",
       "EPSG:32633 (WGS 84 / UTM zone 33N), GeoTIFF keys"},
      // A foot-based State Plane zone: the unit (US survey foot) comes with it.
      {"EPSG:2227", ModelTypeProjected, 2227, 4269, 0, 0, 0.3048006096012192, "NAD83 / California zone 3 (ftUS)",
       "NAD83 / California zone 3 (ftUS)", "EPSG:2227 (NAD83 / California zone 3 (ftUS)), GeoTIFF keys"},
      {"EPSG:4326", ModelTypeGeographic, 0, 4326, 0, 0, 0.0, "", "WGS 84", "EPSG:4326 (WGS 84), GeoTIFF keys"},
      {"EPSG:6580+5703", ModelTypeProjected, 6580, 6318, 5703, 9001, 1.0,
       "NAD83(2011) / Texas Centric Lambert Conformal", "NAD83(2011) / Texas Centric Lambert Conformal + NAVD88 height",
       "EPSG:6580 + EPSG:5703 (NAD83(2011) / Texas Centric Lambert Conformal + NAVD88 height), GeoTIFF keys"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.crs);
    Result<std::string> wkt = crsAsWkt(c.crs);
    ASSERT_TRUE(wkt.ok()) << wkt.error().message;
    LasWriteOptions options;
    options.crs_wkt = *wkt;
    const std::string path = dir.file("given.las");
    ASSERT_TRUE(writeLas(path, set, options).ok());
    const std::string bytes = test::readFile(path);
    EXPECT_EQ(bytes[25], 2) << "LAS 1.2";
    EXPECT_EQ(at<uint16_t>(bytes, 6) & 0x10, 0) << "no WKT bit";
    const Judged judged = judge(path);
    EXPECT_EQ(judged.model, c.model);
    if (c.pcs) {
      EXPECT_EQ(judged.pcs, c.pcs);
      EXPECT_EQ(judged.pcs_name, c.pcs_name);
      EXPECT_DOUBLE_EQ(judged.length_in_meters, c.length_in_meters);
    }
    EXPECT_EQ(judged.gcs, c.gcs);
    EXPECT_EQ(judged.vertical, c.vertical);
    EXPECT_EQ(judged.vertical_units, c.vertical_units);
    EXPECT_EQ(judged.citation, c.citation);
    Result<PointSet> back = readLas(path);
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back->las->version_minor, 2);
    EXPECT_EQ(lasCrsSummary(back->las->vlrs, lasSaysWkt(*back->las)), c.summary);
  }
}

// Where the keys cannot say it (no EPSG code, a 3D geographic CRS, a WKT that names an EPSG code but
// changes it) or the file needs LAS 1.4 anyway (point format 6-10), the CRS is WKT in LAS 1.4, as
// before; libgeotiff then finds no keys.
TEST(LasGeoTiff, aCrsTheKeysCannotSayIsWktInLas14) {
  test::TempDir dir;
  PointSet set;
  set.positions = {{500000.0, 4000000.0, 10.0}};
  Result<std::string> utm = crsAsWkt("EPSG:32633");
  ASSERT_TRUE(utm.ok());
  std::string altered = *utm;
  const size_t meridian = altered.find("\"central_meridian\",15");
  ASSERT_NE(meridian, std::string::npos) << altered;
  altered.replace(meridian, 21, "\"central_meridian\",16");
  for (const auto& [name, crs, las14] :
       std::vector<std::tuple<std::string, std::string, bool>>{{"no code", "+proj=utm +zone=33 +datum=WGS84 +type=crs", false},
                                                               {"3D geographic", "EPSG:4979", false},
                                                               {"altered", altered, false},
                                                               {"format 6", "EPSG:32633", true}}) {
    SCOPED_TRACE(name);
    Result<std::string> wkt = crsAsWkt(crs);
    ASSERT_TRUE(wkt.ok()) << wkt.error().message;
    EXPECT_TRUE(las14 || lasGeoKeyRecords(*wkt).empty());
    LasWriteOptions options;
    options.crs_wkt = *wkt;
    options.las14 = las14;
    const std::string path = dir.file("wkt.las");
    ASSERT_TRUE(writeLas(path, set, options).ok());
    const std::string bytes = test::readFile(path);
    EXPECT_EQ(bytes[25], 4) << "LAS 1.4";
    EXPECT_EQ(at<uint16_t>(bytes, 6) & 0x10, 0x10) << "the WKT bit";
    const std::map<uint16_t, std::string> records = projectionRecords(bytes);
    EXPECT_FALSE(records.count(34735));
    EXPECT_TRUE(records.count(2112));
    EXPECT_EQ(judge(path).model, 0);
  }
}

}  // namespace
}  // namespace dpoint
