// A LAS file's CRS in point formats 6–10, which hold it as WKT alone (LAS 1.4 R15): GeoTIFF keys are
// made WKT through PROJ from their EPSG codes (the keys' linear unit and a vertical CRS included),
// libLAS's WKT record becomes the LAS one, a CRS that cannot be made WKT is left out with a note,
// and formats 0–5 keep their records as they were; a CRS given (`--crs`) is WKT in a LAS 1.4 file. tests/external/copc_reads_dpoint_copc.py has
// copc.js and pyproj read the WKT of the corpus's files written as COPC.
#include "converters/las_crs.h"

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "converters/las.h"
#include "converters/point_io.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::TempDir;

// A LASF_Projection 34735 record: the directory's header, then one entry a key (value in place).
LasVlr geoKeys(const std::vector<std::pair<uint16_t, uint16_t>>& keys) {
  std::vector<uint16_t> shorts = {1, 1, 0, static_cast<uint16_t>(keys.size())};
  for (const auto& [id, value] : keys) shorts.insert(shorts.end(), {id, 0, 1, value});
  std::string data(shorts.size() * 2, '\0');
  std::memcpy(data.data(), shorts.data(), data.size());
  return LasVlr{"LASF_Projection", 34735, "GeoTIFF GeoKeyDirectoryTag", data, false};
}

LasVlr wkt(const std::string& user, const std::string& text, bool extended = false) {
  return LasVlr{user, 2112, "WKT", text + '\0', extended};
}

bool has(const std::vector<LasVlr>& records, const std::string& user, uint16_t id) {
  for (const LasVlr& r : records)
    if (r.user_id == user && r.record_id == id) return true;
  return false;
}

const LasVlr* find(const std::vector<LasVlr>& records, const std::string& user, uint16_t id) {
  for (const LasVlr& r : records)
    if (r.user_id == user && r.record_id == id) return &r;
  return nullptr;
}

TEST(LasCrs, geoTiffKeysBecomeWktWithTheirUnitAndVerticalCrs) {
  // NAD83 / UTM zone 10N (metres in EPSG) whose keys say US survey feet, over NAVD88 height in feet.
  const LasWktCrs crs = lasWktCrs({geoKeys({{1024, 1}, {3072, 26910}, {3076, 9003}, {4096, 5703}, {4099, 9003}})}, false);
  ASSERT_EQ(crs.records.size(), 1u);
  const LasVlr& record = crs.records[0];
  EXPECT_EQ(record.user_id, "LASF_Projection");
  EXPECT_EQ(record.record_id, 2112);
  ASSERT_FALSE(record.data.empty());
  EXPECT_EQ(record.data.back(), '\0');  // LAS's WKT is a NUL-terminated string
  const std::string text = record.data.substr(0, record.data.size() - 1);
  EXPECT_EQ(text.rfind("COMPD_CS[\"NAD83 / UTM zone 10N + NAVD88 height", 0), 0u) << text;
  EXPECT_NE(text.find("UNIT[\"US survey foot\""), std::string::npos) << text;
  EXPECT_EQ(text.find("UNIT[\"metre\""), std::string::npos) << "every axis in the keys' unit: " << text;
  EXPECT_EQ(text.find('\n'), std::string::npos) << "one line";
  EXPECT_NE(crs.note.find("EPSG:26910 + EPSG:5703"), std::string::npos) << crs.note;
  EXPECT_NE(crs.note.find("written as WKT"), std::string::npos) << crs.note;
  EXPECT_NE(crs.note.find("EPSG:26910 in the keys' unit, US survey foot"), std::string::npos) << crs.note;
}

// What GDAL, libgeotiff and LAStools write: a projection by parameters on an EPSG geographic base
// (model type 1, ProjectedCSType 32767, GeographicType 4269) is no lat/lon CRS; GeoTIFF 1.0's
// ellipsoidal-height code 5030 leaves the vertical part out, not the projected CRS; keys beside a
// libLAS WKT record or an empty WKT record are the LAS 1.2 file's CRS.
TEST(LasCrs, keysAreReadAsGeoTiffMeansThem) {
  const LasWktCrs custom = lasWktCrs({geoKeys({{1024, 1}, {2048, 4269}, {3072, 32767}})}, false);
  EXPECT_TRUE(custom.records.empty());
  EXPECT_NE(custom.note.find("projection by parameters"), std::string::npos) << custom.note;
  EXPECT_NE(lasWktCrs({geoKeys({{1024, 1}, {2048, 4269}})}, false).note.find("name no projected CRS"), std::string::npos);
  const LasWktCrs ellipsoidal = lasWktCrs({geoKeys({{1024, 1}, {3072, 32632}, {4096, 5030}})}, false);
  ASSERT_EQ(ellipsoidal.records.size(), 1u) << ellipsoidal.note;
  EXPECT_EQ(ellipsoidal.records[0].data.rfind("PROJCS[\"WGS 84 / UTM zone 32N\"", 0), 0u);
  EXPECT_NE(ellipsoidal.note.find("vertical code 5030 left out"), std::string::npos) << ellipsoidal.note;
  const LasWktCrs beside = lasWktCrs({geoKeys({{1024, 1}, {3072, 26910}}), wkt("liblas", "PROJCS[\"WGS 84 / UTM zone 33N\"]")}, false);
  ASSERT_EQ(beside.records.size(), 1u);
  EXPECT_NE(beside.records[0].data.find("UTM zone 10N"), std::string::npos);
  const LasWktCrs empty = lasWktCrs({geoKeys({{1024, 1}, {3072, 26910}}), wkt("LASF_Projection", "")}, false);
  ASSERT_EQ(empty.records.size(), 1u);
  EXPECT_NE(empty.records[0].data.find("UTM zone 10N"), std::string::npos);
  EXPECT_EQ(lasCrsSummary({geoKeys({{1024, 1}, {2048, 4269}, {3072, 32767}})}, false), "a user-defined CRS, GeoTIFF keys");
}

TEST(LasCrs, aGeographicCrsIsMadeWktToo) {
  const LasWktCrs crs = lasWktCrs({geoKeys({{1024, 2}, {2048, 4326}, {2054, 9102}})}, false);
  ASSERT_EQ(crs.records.size(), 1u);
  EXPECT_EQ(crs.records[0].data.rfind("GEOGCS[\"WGS 84\"", 0), 0u) << crs.records[0].data;
}

TEST(LasCrs, aCrsWithoutAnEpsgCodeIsLeftOutWithANote) {
  for (const LasVlr& keys : {geoKeys({{1024, 1}, {3072, 32767}}), geoKeys({{1024, 1}}),
                             geoKeys({{1024, 1}, {3072, 60000}}), geoKeys({{1024, 1}, {3072, 26910}, {3076, 9102}})}) {
    const LasWktCrs crs = lasWktCrs({keys}, false);
    EXPECT_TRUE(crs.records.empty());
    EXPECT_NE(crs.note.find("left out and the file has no CRS"), std::string::npos) << crs.note;
  }
  // Why, in the note: no code, a code PROJ does not know, a unit that is an angle.
  EXPECT_NE(lasWktCrs({geoKeys({{3072, 32767}})}, false).note.find("by parameters"), std::string::npos);
  EXPECT_NE(lasWktCrs({geoKeys({{3072, 60000}})}, false).note.find("EPSG:60000 is not a CRS"), std::string::npos);
  EXPECT_NE(lasWktCrs({geoKeys({{3072, 26910}, {3076, 9102}})}, false).note.find("not a linear unit"), std::string::npos);
}

TEST(LasCrs, libLasWktBecomesTheLasRecordAndWktStaysAsItIs) {
  const std::string text = "PROJCS[\"NAD83 / UTM zone 10N\",GEOGCS[\"NAD83\"]]";
  const LasWktCrs from_liblas = lasWktCrs({geoKeys({{3072, 32767}}), wkt("liblas", text)}, false);
  ASSERT_EQ(from_liblas.records.size(), 1u);  // the keys are left out beside WKT
  EXPECT_EQ(from_liblas.records[0].user_id, "LASF_Projection");
  EXPECT_EQ(from_liblas.records[0].data, text + '\0');
  EXPECT_NE(from_liblas.note.find("libLAS's WKT record (NAD83 / UTM zone 10N)"), std::string::npos) << from_liblas.note;

  // A WKT record already there (an EVLR here) is kept as it is, with no note; the keys go.
  const LasWktCrs kept = lasWktCrs({geoKeys({{3072, 26910}}), wkt("LASF_Projection", text, true)}, true);
  ASSERT_EQ(kept.records.size(), 1u);
  EXPECT_TRUE(kept.records[0].extended);
  EXPECT_TRUE(kept.note.empty()) << kept.note;
  EXPECT_TRUE(lasWktCrs({}, false).records.empty());
  EXPECT_TRUE(lasWktCrs({}, false).note.empty());
}

TEST(LasCrs, summaryNamesTheCrsWithoutProj) {
  EXPECT_EQ(lasCrsSummary({}, false), "");
  EXPECT_EQ(lasCrsSummary({geoKeys({{1024, 1}, {3072, 26910}, {4096, 5703}})}, false), "EPSG:26910 + EPSG:5703, GeoTIFF keys");
  EXPECT_EQ(lasCrsSummary({geoKeys({{3072, 32767}})}, false), "a user-defined CRS, GeoTIFF keys");
  EXPECT_EQ(lasCrsSummary({geoKeys({{3072, 26910}}), wkt("LASF_Projection", "PROJCS[\"A\",X]")}, true), "A, WKT");
  EXPECT_EQ(lasCrsSummary({geoKeys({{3072, 26910}}), wkt("LASF_Projection", "PROJCS[\"A\",X]")}, false),
            "EPSG:26910, GeoTIFF keys");  // a LAS 1.2 file's CRS is its keys
  EXPECT_EQ(lasCrsSummary({wkt("liblas", "PROJCS[\"B\",X]")}, false), "B, libLAS's WKT");
  // A LAS 1.2 file's CRS is its keys, whatever libLAS wrote beside them.
  EXPECT_EQ(lasCrsSummary({wkt("liblas", "PROJCS[\"B\",X]"), geoKeys({{3072, 26910}})}, false), "EPSG:26910, GeoTIFF keys");
}

// The writer: format 6 (COPC's, or --las14) gets the WKT and drops the keys, with a note in its
// report; format 1 keeps the keys as they were. Both read back as written.
TEST(LasCrs, theWriterPutsWktInFormat6AndKeepsKeysInFormat0) {
  TempDir dir;
  PointSet set;
  set.positions = {{500000.0, 4000000.0, 10.0}, {500001.5, 4000002.0, 11.0}};
  LasSource source;
  source.point_format = 0;  // a set without GPS time
  source.scale = glm::dvec3(0.01);
  source.vlrs = {geoKeys({{1024, 1}, {3072, 26910}, {3076, 9001}})};
  set.las = source;
  for (bool las14 : {false, true}) {
    SCOPED_TRACE(las14 ? "format 6" : "format 0");
    const std::string path = dir.file(las14 ? "six.las" : "zero.las");
    LasWriteReport report;
    LasWriteOptions options;
    options.las14 = las14;
    options.report = &report;
    ASSERT_TRUE(writeLas(path, set, options).ok());
    Result<PointSet> back = readLas(path);
    ASSERT_TRUE(back.ok()) << back.error().message;
    ASSERT_TRUE(back->las.has_value());
    EXPECT_EQ(back->las->point_format, las14 ? 6 : 0);
    const std::vector<LasVlr>& records = back->las->vlrs;
    EXPECT_EQ(has(records, "LASF_Projection", 34735), !las14);
    EXPECT_EQ(has(records, "LASF_Projection", 2112), las14);
    if (las14) {
      EXPECT_NE(find(records, "LASF_Projection", 2112)->data.find("NAD83 / UTM zone 10N"), std::string::npos);
      EXPECT_EQ(report.crs.rfind("point format 6 holds its CRS as WKT: the GeoTIFF keys' CRS, EPSG:26910", 0), 0u)
          << report.crs;
      EXPECT_EQ(back->las->global_encoding & 0x10, 0x10);
    } else {
      EXPECT_TRUE(report.crs.empty()) << report.crs;
    }
  }
}

// --crs: any definition PROJ reads becomes one line of WKT 1; where GeoTIFF keys cannot say it (here
// a CRS without an EPSG code; las_geotiff_test.cpp has those that can) the writer puts it in a LAS
// 1.4 file with the WKT bit, in place of the source's records, whatever the point format.
TEST(LasCrs, aGivenCrsIsWktInALas14File) {
  Result<std::string> wgs84 = crsAsWkt("EPSG:4326");
  ASSERT_TRUE(wgs84.ok()) << wgs84.error().message;
  EXPECT_EQ(wgs84->rfind("GEOGCS[\"WGS 84\"", 0), 0u) << *wgs84;
  Result<std::string> from_wkt2 = crsAsWkt(
      "GEOGCRS[\"WGS 84\",DATUM[\"World Geodetic System 1984\",ELLIPSOID[\"WGS 84\",6378137,298.257223563]],"
      "CS[ellipsoidal,2],AXIS[\"latitude\",north,ANGLEUNIT[\"degree\",0.0174532925199433]],"
      "AXIS[\"longitude\",east,ANGLEUNIT[\"degree\",0.0174532925199433]]]");
  ASSERT_TRUE(from_wkt2.ok()) << from_wkt2.error().message;
  EXPECT_EQ(from_wkt2->rfind("GEOGCS[\"WGS 84\"", 0), 0u) << *from_wkt2;
  // A 3D geographic CRS as WKT 1 holds it: the 2D one and ellipsoidal heights.
  Result<std::string> wgs84_3d = crsAsWkt("EPSG:4979");
  ASSERT_TRUE(wgs84_3d.ok()) << wgs84_3d.error().message;
  EXPECT_EQ(wgs84_3d->rfind("COMPD_CS[", 0), 0u) << *wgs84_3d;
  // A .prj with a UTF-8 byte order mark, by a name with a '+'.
  TempDir prj;
  test::writeFile(prj.file("utm+33.prj"), "\xEF\xBB\xBF" + *crsAsWkt("EPSG:32633"));
  Result<std::string> from_file = crsAsWkt(prj.file("utm+33.prj"));
  ASSERT_TRUE(from_file.ok()) << from_file.error().message;
  EXPECT_EQ(*from_file, *crsAsWkt("EPSG:32633"));
  // A horizontal CRS with a vertical one, in PROJ's EPSG:H+V form.
  Result<std::string> compound = crsAsWkt("EPSG:6580+5703");
  ASSERT_TRUE(compound.ok()) << compound.error().message;
  EXPECT_EQ(compound->rfind("COMPD_CS[", 0), 0u) << *compound;
  // A vertical CRS alone places no x or y: refused, pointing at the compound form.
  Result<std::string> vertical = crsAsWkt("EPSG:5703");
  ASSERT_FALSE(vertical.ok());
  EXPECT_NE(vertical.error().message.find("a vertical CRS alone"), std::string::npos) << vertical.error().message;
  EXPECT_NE(vertical.error().message.find("EPSG:6580+5703"), std::string::npos) << vertical.error().message;
  for (const std::string& bad : {std::string("EPSG:999999"), std::string("PROJCS["), std::string("+proj=tmerc +nonsense"),
                                 std::string("no-such-file.prj"), std::string(""), std::string("  "), prj.path(),
                                 std::string("EPSG:5703"),
                                 // the same bound to a geoid model, as GDAL writes a .prj
                                 std::string("VERT_CS[\"NAVD88 height\",VERT_DATUM[\"North American Vertical Datum 1988\",2005,"
                                             "EXTENSION[\"PROJ4_GRIDS\",\"g2012a_conus.gtx\"]],UNIT[\"metre\",1],"
                                             "AXIS[\"Gravity-related height\",UP]]"),
                                 // a one-axis engineering CRS
                                 std::string("ENGCRS[\"height only\",EDATUM[\"site\"],CS[vertical,1],"
                                             "AXIS[\"height (H)\",up,LENGTHUNIT[\"metre\",1]]]")}) {
    Result<std::string> wkt = crsAsWkt(bad);
    EXPECT_FALSE(wkt.ok()) << bad;
    if (!wkt.ok()) {
      EXPECT_EQ(wkt.error().code, ExitCode::kUsage) << bad;
    }
  }

  TempDir dir;
  PointSet set;
  set.positions = {{500000.0, 4000000.0, 10.0}};
  LasSource source;
  source.point_format = 0;  // a set without GPS time
  source.vlrs = {geoKeys({{1024, 1}, {3072, 26910}})};
  set.las = source;
  LasWriteReport report;
  LasWriteOptions options;
  options.crs_wkt = *from_wkt2;  // no EPSG code: WKT
  options.report = &report;
  ASSERT_TRUE(writeLas(dir.file("given.las"), set, options).ok());
  Result<PointSet> back = readLas(dir.file("given.las"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->las->point_format, 0);
  EXPECT_EQ(back->las->version_minor, 4);
  EXPECT_EQ(back->las->global_encoding & 0x10, 0x10);
  ASSERT_EQ(back->las->vlrs.size(), 1u);
  EXPECT_EQ(back->las->vlrs[0].data, *from_wkt2 + '\0');
  EXPECT_EQ(report.crs, "");  // writePoints says what it replaced, as for every format
  std::vector<std::string> notices;
  WriteOptions write;
  write.las_crs = *from_wkt2;
  write.notices = &notices;
  ASSERT_TRUE(writePoints(dir.file("given2.las"), set, write).ok());
  ASSERT_EQ(notices.size(), 1u);
  EXPECT_EQ(notices[0], dir.file("given2.las") + ": the input's CRS (EPSG:26910, GeoTIFF keys) "
                                                  "replaced by WGS 84");
}

// LAS → PLY → LAS keeps the CRS records byte for byte (header comments, in lines Open3D's PLY reader
// takes: open3d_reads_ply_and_glb.py), VLRs and EVLRs, two records of one id included; a damaged
// record's line leaves that record out and the file reads.
TEST(LasCrs, plyCarriesTheCrsRecordsOfItsLasSource) {
  TempDir dir;
  const std::string corpus = std::string(DPOINT_CORPUS_DIR);
  for (const std::string& source : {corpus + "/las/autzen.las", corpus + "/las/1_4_w_evlr.las", corpus + "/laz/1815.las"}) {
    SCOPED_TRACE(source);
    Result<PointSet> las = readPoints(source);
    ASSERT_TRUE(las.ok()) << las.error().message;
    ASSERT_FALSE(las->las->vlrs.empty());
    ASSERT_TRUE(writePoints(dir.file("c.ply"), *las).ok());
    Result<PointSet> ply = readPoints(dir.file("c.ply"));
    ASSERT_TRUE(ply.ok()) << ply.error().message;
    ASSERT_TRUE(ply->las.has_value());
    ASSERT_EQ(ply->las->vlrs.size(), las->las->vlrs.size());
    for (size_t k = 0; k < las->las->vlrs.size(); ++k) {
      const LasVlr &a = las->las->vlrs[k], &b = ply->las->vlrs[k];
      EXPECT_EQ(a.user_id, b.user_id);
      EXPECT_EQ(a.record_id, b.record_id);
      EXPECT_EQ(a.extended, b.extended);
      EXPECT_EQ(a.data, b.data) << k;
    }
    EXPECT_EQ(lasCrsSummary(ply->las->vlrs, lasSaysWkt(*ply->las)), lasCrsSummary(las->las->vlrs, lasSaysWkt(*las->las)));
  }
  // autzen's PLY with its second record's first line damaged: the others come back.
  Result<PointSet> autzen = readPoints(corpus + "/las/autzen.las");
  ASSERT_TRUE(autzen.ok());
  ASSERT_TRUE(writePoints(dir.file("a.ply"), *autzen).ok());
  std::string bytes = test::readFile(dir.file("a.ply"));
  const size_t line = bytes.find("comment dpoint: las crs 1 ");
  ASSERT_NE(line, std::string::npos);
  bytes[bytes.find('\n', line) - 1] = 'x';  // not a hex digit
  test::writeFile(dir.file("a.ply"), bytes);
  Result<PointSet> damaged = readPoints(dir.file("a.ply"));
  ASSERT_TRUE(damaged.ok()) << damaged.error().message;
  EXPECT_EQ(damaged->las->vlrs.size(), autzen->las->vlrs.size() - 1);
}

}  // namespace
}  // namespace dpoint
