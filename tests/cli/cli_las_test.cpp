// dpoint with LAS files as a user runs it (issue #13): convert, info, render, the LAZ refusal and
// --las-scale, with exit codes, messages and files left behind.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "converters/las_crs.h"
#include "converters/point_inputs.h"
#include "converters/point_io.h"
#include "core/text.h"
#include "las_bytes.h"
#include "test_support.h"

namespace dpoint {
namespace {

using test::firstLine;
using test::readFile;
using test::runDpoint;
using test::TempDir;
using test::writeFile;

const std::string kCorpus = std::string(DPOINT_CORPUS_DIR) + "/las/";
const std::string kLazCorpus = std::string(DPOINT_CORPUS_DIR) + "/laz/";

size_t distinctPositions(PositionArray p) {
  std::sort(p.begin(), p.end(), [](const glm::dvec3& a, const glm::dvec3& b) {
    return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
  });
  return static_cast<size_t>(std::unique(p.begin(), p.end()) - p.begin());
}

// Issue #34: LAS writing never merges distinct points silently. Without a LAS source or
// --las-scale, the scale is chosen so that they stay apart; an asked scale that merges says how many.
TEST(CliLas, lasOutputKeepsDistinctPointsApartOrSaysHowManyMerge) {
  TempDir dir;
  // A level-3 Menger sponge 1 mm wide at 1 km: 15,232 points 37 µm apart (8 positions at 0.001).
  ASSERT_EQ(runDpoint({"generate", "menger", "--level", "3", "--size", "0.001", "--offset", "1000,0,0", "-o",
                       dir.file("m3.ply"), "--quiet"}).exit_code, 0);
  test::CommandResult r = runDpoint({"convert", dir.file("m3.ply"), "-o", dir.file("m3.las")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("merged"), std::string::npos) << r.err;
  Result<PointSet> ply = readPoints(dir.file("m3.ply")), las = readPoints(dir.file("m3.las"));
  ASSERT_TRUE(ply && las);
  EXPECT_EQ(distinctPositions(las->positions), distinctPositions(ply->positions));
  for (size_t i = 0; i < ply->size(); i += 101)  // within half the scale (1e-5)
    for (int k = 0; k < 3; ++k) EXPECT_LE(std::fabs(las->positions[i][k] - ply->positions[i][k]), 0.5e-5);
  // At an asked 0.001 they merge, and the note counts them.
  r = runDpoint({"convert", dir.file("m3.ply"), "-o", dir.file("coarse.las"), "--las-scale", "0.001"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  las = readPoints(dir.file("coarse.las"));
  ASSERT_TRUE(las);
  const size_t merged = distinctPositions(ply->positions) - distinctPositions(las->positions);
  EXPECT_GT(merged, 0u);
  EXPECT_TRUE(test::contains(r.err, "coarse.las: " + std::to_string(merged) + " of 15232 points share their integers"));
  // generate -o .las takes the same path.
  r = runDpoint({"generate", "menger", "--level", "3", "--size", "0.001", "--offset", "1000,0,0", "-o", dir.file("g.las"), "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  las = readPoints(dir.file("g.las"));
  ASSERT_TRUE(las);
  EXPECT_EQ(distinctPositions(las->positions), distinctPositions(ply->positions));
}

TEST(CliLas, aMandelbulbKeepsEveryDistinctPointThroughLas) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"generate", "mandelbulb", "--resolution", "200", "-o", dir.file("bulb.ply"), "--quiet"}).exit_code, 0);
  ASSERT_EQ(runDpoint({"convert", dir.file("bulb.ply"), "-o", dir.file("bulb.las"), "--quiet"}).exit_code, 0);
  Result<PointSet> ply = readPoints(dir.file("bulb.ply")), las = readPoints(dir.file("bulb.las"));
  ASSERT_TRUE(ply && las);
  EXPECT_EQ(distinctPositions(las->positions), distinctPositions(ply->positions));
}

TEST(CliLas, convertLasToCsvWritesEveryPointWithItsColour) {
  TempDir dir;
  test::CommandResult r = runDpoint({"convert", kCorpus + "simple.las", "-o", dir.file("s.csv"), "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string csv = readFile(dir.file("s.csv"));
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1066);
  // The first record: X, Y, Z = 63701224, 84902831, 43166 at scale 0.01; colour 68, 77, 88 of 255.
  // Then every field of point format 1: intensity 143, return 1 of 1, scan direction 1, class 1,
  // scan angle -9, user data 132, point source 7326, GPS time 245380.78254962614.
  EXPECT_EQ(csv.rfind("x,y,z,r,g,b,intensity,return_number,number_of_returns,scan_direction,edge_of_flight_line,"
                      "classification,synthetic,key_point,withheld,scan_angle_rank,user_data,point_source_id,gps_time\n"
                      "637012.24,849028.31,431.66,0.26666668,0.3019608,0.34509805,143,1,1,1,0,1,0,0,0,-9,132,7326,"
                      "245380.78254962614\n",
                      0),
            0u)
      << csv.substr(0, 400);
  // --keep chooses the dimensions, in its order; --drop all leaves the coordinates and colours.
  ASSERT_EQ(runDpoint({"convert", kCorpus + "simple.las", "-o", dir.file("k.csv"), "-q", "--keep",
                       "classification,intensity"})
                .exit_code,
            0);
  EXPECT_EQ(firstLine(readFile(dir.file("k.csv"))), "x,y,z,r,g,b,classification,intensity\n");
  ASSERT_EQ(runDpoint({"convert", kCorpus + "simple.las", "-o", dir.file("d.csv"), "-q", "--drop", "all"}).exit_code, 0);
  EXPECT_EQ(firstLine(readFile(dir.file("d.csv"))), "x,y,z,r,g,b\n");
  ASSERT_EQ(runDpoint({"convert", kCorpus + "simple.las", "-o", dir.file("n.csv"), "-q", "--keep", "none", "--no-colors"})
                .exit_code,
            0);
  EXPECT_EQ(firstLine(readFile(dir.file("n.csv"))), "x,y,z\n");
  // A name the file lacks is a usage error that lists what it has; nothing is written.
  test::CommandResult bad = runDpoint({"convert", kCorpus + "simple.las", "-o", dir.file("bad.csv"), "--drop", "nir"});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_TRUE(test::contains(bad.err, "--drop nir: " + kCorpus + "simple.las has no dimension 'nir' (it has intensity, "))
      << bad.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("bad.csv")));
}

// LAS to PLY and to GLB as a user converts, read back. PLY stores double x, y, z: every position
// comes back bit for bit. GLB stores float32 offsets from the bounding box's centre (the node's
// translation, a double): each coordinate comes back within float's half-ulp of its offset (2^-24
// of at most half the box) plus the one double rounding of adding the centre back (2^-53 of it).
TEST(CliLas, convertLasToPlyAndGlbKeepsEveryPosition) {
  for (const char* name : {"simple1_4.las", "simple.las"}) {  // 16-bit and 8-bit colours; 1e-6 m and UTM-like
    SCOPED_TRACE(name);
    TempDir dir;
    Result<PointSet> las = readPoints(kCorpus + name);
    ASSERT_TRUE(las.ok()) << las.error().message;
    for (const char* output : {"out.ply", "out.glb"}) {
      test::CommandResult r = runDpoint({"convert", kCorpus + name, "-o", dir.file(output), "--quiet"});
      ASSERT_EQ(r.exit_code, 0) << output << ": " << r.err;
    }
    Result<PointSet> ply = readPoints(dir.file("out.ply"));
    ASSERT_TRUE(ply.ok()) << ply.error().message;
    EXPECT_EQ(ply->positions, las->positions);
    EXPECT_EQ(ply->hasColors(), las->hasColors());

    Result<PointSet> glb = readPoints(dir.file("out.glb"));
    ASSERT_TRUE(glb.ok()) << glb.error().message;
    ASSERT_EQ(glb->size(), las->size());
    const Box box = boundingBox(las->positions);
    const glm::dvec3 half = 0.5 * (box.max - box.min);
    double worst = 0.0;  // in units of the bound
    for (size_t i = 0; i < las->size(); ++i) {
      for (int k = 0; k < 3; ++k) {
        const double want = las->positions[i][k], got = glb->positions[i][k];
        const double bound = 0x1p-24 * half[k] * (1.0 + 0x1p-20) + 0x1p-53 * std::fabs(want);
        ASSERT_LE(std::fabs(got - want), bound) << "point " << i << " axis " << k;
        worst = std::max(worst, std::fabs(got - want) / bound);
      }
    }
    EXPECT_EQ(glb->colors, las->colors) << "float32 colours keep the LAS colours' floats";
    std::printf("%s: GLB positions within %.3g of the bound\n", name, worst);
  }
}

TEST(CliLas, csvToLasToCsvIsByteIdenticalOnTheScaleGrid) {
  TempDir dir;
  // Millimetre eastings and northings, heights of whole binary fractions.
  writeFile(dir.file("in.csv"),
            "x,y,z\n637012.241,5800843.145,265.125\n637999.999,5800000.001,0.5\n637500,5800500.25,-12.375\n");
  ASSERT_EQ(runDpoint({"convert", dir.file("in.csv"), "-o", dir.file("mid.las"), "--quiet"}).exit_code, 0);
  // The LAS file's fields (all 0 here) are dropped: only the coordinates are compared.
  test::CommandResult r =
      runDpoint({"convert", dir.file("mid.las"), "-o", dir.file("out.csv"), "--quiet", "--drop", "all"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(readFile(dir.file("out.csv")), readFile(dir.file("in.csv")));
  // A survey's coordinates (simple.las, scale 0.01), through CSV and back into LAS at its scale.
  ASSERT_EQ(runDpoint({"convert", kCorpus + "simple.las", "-o", dir.file("a.csv"), "--quiet"}).exit_code, 0);
  ASSERT_EQ(runDpoint({"convert", dir.file("a.csv"), "-o", dir.file("b.las"), "--las-scale", "0.01", "--quiet"})
                .exit_code,
            0);
  ASSERT_EQ(runDpoint({"convert", dir.file("b.las"), "-o", dir.file("c.csv"), "--quiet"}).exit_code, 0);
  EXPECT_EQ(readFile(dir.file("c.csv")), readFile(dir.file("a.csv")));
}

TEST(CliLas, infoPrintsTheLasHeader) {
  test::CommandResult r = runDpoint({"info", kCorpus + "simple1_4.las", "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* line : {"points:             22600\n",
                           "LAS:                version 1.4, point format 7, 36-byte records (0 extra bytes), 22600 points\n",
                           "LAS scale:          1.0000000000000002e-06 1.0000000000000002e-07 0.001\n",
                           "LAS offset:         1 1 0\n", "(hold the points)",
                           "LAS CRS:            Geographic Coordinate System, WKT\n"})
    EXPECT_NE(r.out.find(line), std::string::npos) << line << " in\n" << r.out;
  // The CRS as the file gives it: GeoTIFF keys' EPSG codes and citation, or none.
  for (const auto& [file, crs] : std::vector<std::pair<std::string, std::string>>{
           {kLazCorpus + "1815.las", "EPSG:6580 + EPSG:5703 (NAD83(2011)), GeoTIFF keys"},
           {kLazCorpus + "point-time.las", "EPSG:26910 (NAD83 / UTM zone 10N), GeoTIFF keys"},
           {kCorpus + "1_4_w_evlr.las", "NAD83(HARN) / New Mexico Central (ftUS), WKT"},
           {kCorpus + "simple.las", "none (no coordinate system records)"}}) {
    test::CommandResult info = runDpoint({"info", file, "--quiet"});
    EXPECT_NE(info.out.find("LAS CRS:            " + crs + "\n"), std::string::npos) << info.out;
  }
  // A real file whose header bounds are its raw integers: read, and the bounds called wrong.
  test::CommandResult wrong = runDpoint({"info", kCorpus + "simple1_3.las", "--json"});
  ASSERT_EQ(wrong.exit_code, 0) << wrong.err;
  for (const char* part : {"\"las\": {\"version\": \"1.3\", \"point_format\": 4, \"record_length\": 57, \"points\": 999",
                           "\"header_bounds_hold\": false", "\"points\": 999,", "\"crs\": \"no horizontal CRS + EPSG:5030, GeoTIFF keys\""})
    EXPECT_NE(wrong.out.find(part), std::string::npos) << part << " in\n" << wrong.out;
}

// --crs: the CRS given (EPSG:CODE, WKT, a file holding WKT) takes the place of the input's records (a
// note says so): an EPSG one as GeoTIFF keys in the LAS 1.2 file the input makes, any other as the
// WKT record of a LAS 1.4 file; a code PROJ does not know, a missing file and an output that holds
// no CRS are usage errors that write nothing.
TEST(CliLas, crsGivenIsWrittenAsKeysOrWkt) {
  TempDir dir;
  test::CommandResult r = runDpoint({"convert", kCorpus + "simple.las", "--crs", "EPSG:32633", "-o", dir.file("a.las")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  test::CommandResult info = runDpoint({"info", dir.file("a.las"), "--quiet"});
  EXPECT_NE(info.out.find("LAS:                version 1.2, point format 3"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("LAS CRS:            EPSG:32633 (WGS 84 / UTM zone 33N), GeoTIFF keys\n"), std::string::npos)
      << info.out;
  // A file holding WKT; the input's GeoTIFF keys replaced, with a note naming both.
  writeFile(dir.file("utm33.prj"), "PROJCS[\"mine\",GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,"
                                   "298.257223563]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]],"
                                   "PROJECTION[\"Transverse_Mercator\"],PARAMETER[\"central_meridian\",15],"
                                   "PARAMETER[\"scale_factor\",0.9996],PARAMETER[\"false_easting\",500000],UNIT[\"metre\",1]]\n");
  r = runDpoint({"convert", kLazCorpus + "point-time.las", "--crs", dir.file("utm33.prj"), "-o", dir.file("b.laz")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("the input's CRS (EPSG:26910 (NAD83 / UTM zone 10N), GeoTIFF keys) replaced by mine"),
            std::string::npos)
      << r.err;
  info = runDpoint({"info", dir.file("b.laz"), "--quiet"});
  EXPECT_NE(info.out.find("LAS CRS:            mine, WKT\n"), std::string::npos) << info.out;
  for (const auto& [args, message] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"--crs", "EPSG:999999", "-o", dir.file("c.las")}, "--crs 'EPSG:999999': not a coordinate reference system"},
           {{"--crs", dir.file("none.prj"), "-o", dir.file("c.las")}, "no such file"},
           {{"--crs", dir.path(), "-o", dir.file("c.las")}, "a folder, not a file holding a CRS"},
           {{"--crs", "/dev/zero", "-o", dir.file("c.las")}, "not a regular file, not a file holding a CRS"},
           // Options that would do nothing (a review finding: they passed silently).
           {{"--las-scale", "0.1", "-o", dir.file("c.ply")}, "--las-scale: only a LAS, LAZ or COPC output (.las, .laz, .copc.laz) has"},
           {{"--decimals", "3", "-o", dir.file("c.las")}, "--decimals: only a CSV output (.csv, .xyz, .txt, .asc, .pts, .ptx)"},
           {{"--keep", "intensity", "--drop", "intensity", "-o", dir.file("c.ply")}, "--keep and --drop: give one"},
           {{"--keep", "intensity", "--drop", "all", "-o", dir.file("c.ply")}, "--keep and --drop: give one"},
           {{"--crs", "EPSG:4326", "-o", dir.file("c.csv")},
            "only a LAS, LAZ, COPC, E57, PLY or PCD output (.las, .laz, .copc.laz, .e57, .ply, .pcd) holds"}}) {
    std::vector<std::string> command = {"convert", kCorpus + "simple.las"};
    command.insert(command.end(), args.begin(), args.end());
    test::CommandResult bad = runDpoint(command);
    EXPECT_EQ(bad.exit_code, 1) << bad.err;
    EXPECT_NE(bad.err.find(message), std::string::npos) << bad.err;
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("c.las")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("c.ply")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("c.csv")));
}

// E57's coordinateMetadata carries a CRS both ways: a LAS file's GeoTIFF keys become WKT there
// (PROJ's), read back by info and written to LAS as keys again; --crs sets it; text PROJ does not
// take goes to E57 as it is and is left out of LAS with a note; text XML cannot hold is left out.
TEST(CliLas, e57CarriesTheCoordinateSystemToAndFromLas) {
  TempDir dir;
  test::CommandResult r = runDpoint({"convert", kCorpus + "autzen.las", "-o", dir.file("a.e57")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  test::CommandResult info = runDpoint({"info", dir.file("a.e57"), "--quiet"});
  EXPECT_TRUE(test::contains(info.out, "CRS:                NAD83(HARN) / Oregon GIC Lambert (ft) (WKT)\n")) << info.out;
  ASSERT_EQ(runDpoint({"convert", dir.file("a.e57"), "-o", dir.file("a.las"), "-q"}).exit_code, 0);
  info = runDpoint({"info", dir.file("a.las"), "--quiet"});
  EXPECT_TRUE(test::contains(info.out, "LAS CRS:            EPSG:2994 (")) << info.out;

  ASSERT_EQ(runDpoint({"convert", kCorpus + "simple.las", "--crs", "EPSG:32633", "-o", dir.file("b.e57"), "-q"}).exit_code, 0);
  info = runDpoint({"info", dir.file("b.e57"), "--json", "--quiet"});
  EXPECT_TRUE(test::contains(info.out, "\"crs\": \"PROJCS[\\\"WGS 84 / UTM zone 33N\\\"")) << info.out;

  // Free text (a site grid's name, with "]]>", which ends XML character data): to E57 as it is,
  // not to LAS.
  PointSet site;
  site.positions = {{1.0, 2.0, 3.0}, {4.0, 5.0, 6.0}};
  site.crs = "site grid 7 ]]> north";
  ASSERT_TRUE(writePoints(dir.file("site.e57"), site).ok());
  Result<PointSet> back = readPoints(dir.file("site.e57"));
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(back->crs, site.crs);
  r = runDpoint({"convert", dir.file("site.e57"), "-o", dir.file("site.las")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(test::contains(r.err, "site.las: coordinate system not written: the input's coordinate system 'site grid 7 ]]> north'"))
      << r.err;
  info = runDpoint({"info", dir.file("site.las"), "--quiet"});
  EXPECT_TRUE(test::contains(info.out, "LAS CRS:            none")) << info.out;
  site.crs = "bad \x01 byte";
  std::vector<std::string> notices;
  WriteOptions write;
  write.notices = &notices;
  ASSERT_TRUE(writePoints(dir.file("bad.e57"), site, write).ok());
  ASSERT_EQ(notices.size(), 1u);
  EXPECT_TRUE(test::contains(notices[0], "coordinate system not written: its text 'bad \\x01 byte' holds a byte XML cannot hold (\\x01)"))
      << notices[0];
  EXPECT_EQ(readPoints(dir.file("bad.e57"))->crs, "");
}

// The coordinate system through PLY and PCD, whose headers carry it in hex comment lines (byte for
// byte: WKT over many lines, "]]>", UTF-8); a LAS source's to PCD as WKT, back to LAS as its EPSG
// code. Streamed info states it as the whole read does, and a LAS file's header facts. CSV and GLB
// hold none, and say so. (Before the build of 2026-12-02, E57 → PLY → LAS and LAS → PCD → LAS lost
// it without a word, and streamed info stated none.)
TEST(CliLas, theCoordinateSystemSurvivesPlyAndPcdAndStreamedInfoStatesIt) {
  TempDir dir;
  ASSERT_EQ(runDpoint({"convert", kCorpus + "autzen.las", "-o", dir.file("a.e57"), "-q"}).exit_code, 0);
  for (const char* via : {"a.ply", "a.pcd"}) {
    SCOPED_TRACE(via);
    ASSERT_EQ(runDpoint({"convert", dir.file("a.e57"), "-o", dir.file(via), "-q"}).exit_code, 0);
    EXPECT_EQ(readPoints(dir.file(via))->crs, readPoints(dir.file("a.e57"))->crs);
    ASSERT_EQ(runDpoint({"convert", dir.file(via), "-o", dir.file("back.las"), "-q"}).exit_code, 0);
    test::CommandResult info = runDpoint({"info", dir.file("back.las"), "--quiet"});
    EXPECT_TRUE(test::contains(info.out, "LAS CRS:            EPSG:2994 (")) << info.out;
  }
  // --crs in place of the source's, to PLY (whose LAS records then go) and PCD.
  for (const char* via : {"g.ply", "g.pcd"}) {
    SCOPED_TRACE(via);
    ASSERT_EQ(runDpoint({"convert", kCorpus + "autzen.las", "--crs", "EPSG:32633", "-o", dir.file(via), "-q"}).exit_code, 0);
    EXPECT_TRUE(test::contains(readPoints(dir.file(via))->crs, "PROJCS[\"WGS 84 / UTM zone 33N\""));
    EXPECT_FALSE(test::contains(readFile(dir.file(via)), "las crs"));
    ASSERT_EQ(runDpoint({"convert", dir.file(via), "-o", dir.file("g.las"), "-q"}).exit_code, 0);
    EXPECT_TRUE(test::contains(runDpoint({"info", dir.file("g.las"), "--quiet"}).out, "LAS CRS:            EPSG:32633 ("));
  }
  // What --crs replaces is said for every output that keeps a CRS (it was said for LAS alone), and
  // not where the input states none.
  for (const char* to : {"r.ply", "r.pcd", "r.e57", "r.las", "r.copc.laz"}) {
    SCOPED_TRACE(to);
    const test::CommandResult given = runDpoint({"convert", dir.file("a.e57"), "--crs", "EPSG:32633", "-o", dir.file(to)});
    ASSERT_EQ(given.exit_code, 0) << given.err;
    EXPECT_TRUE(test::contains(given.err, "the input's CRS (NAD83(HARN) / Oregon GIC Lambert (ft)) replaced by WGS 84 / UTM zone 33N"))
        << given.err;
    EXPECT_EQ(given.err.find("replaced by", given.err.find("replaced by") + 1), std::string::npos) << given.err;
  }
  // The input's own CRS given is no change, however PROJ names it (EPSG:2994's keys and its
  // database entry have two names): nothing said (a review finding).
  for (const char* to : {"same.ply", "same.las"}) {
    const test::CommandResult same = runDpoint({"convert", kCorpus + "autzen.las", "--crs", "EPSG:2994", "-o", dir.file(to)});
    ASSERT_EQ(same.exit_code, 0) << same.err;
    EXPECT_FALSE(test::contains(same.err, "replaced")) << to << ": " << same.err;
  }
  // Nor the input's own WKT given back, which PROJ rewrites renaming its datum.
  writeFile(dir.file("own.wkt"), readPoints(dir.file("a.e57"))->crs);
  const test::CommandResult own = runDpoint({"convert", dir.file("a.e57"), "--crs", dir.file("own.wkt"), "-o", dir.file("own.e57")});
  ASSERT_EQ(own.exit_code, 0) << own.err;
  EXPECT_FALSE(test::contains(own.err, "replaced")) << own.err;
  test::CommandResult plain = runDpoint({"convert", dir.file("r.ply"), "-o", dir.file("n.csv"), "-q"});
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  plain = runDpoint({"convert", dir.file("n.csv"), "--crs", "EPSG:32633", "-o", dir.file("n.ply")});
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_FALSE(test::contains(plain.err, "replaced")) << plain.err;
  test::CommandResult r = runDpoint({"convert", kCorpus + "autzen.las", "-o", dir.file("l.pcd")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_EQ(runDpoint({"convert", dir.file("l.pcd"), "-o", dir.file("l.las"), "-q"}).exit_code, 0);
  EXPECT_TRUE(test::contains(runDpoint({"info", dir.file("l.las"), "--quiet"}).out, "LAS CRS:            EPSG:2994 ("));

  // Any text, as it is, in both headers; a PLY line whose hex is bad leaves it out, not the file.
  PointSet site;
  site.positions = {{1.0, 2.0, 3.0}, {4.0, 5.0, 6.0}};
  site.crs = "LOCAL_CS[\"Höhe ]]> grid\",\n  UNIT[\"metre\",1]]\n" + std::string(1500, 'x');
  for (const char* name : {"s.ply", "s.pcd"}) {
    ASSERT_TRUE(writePoints(dir.file(name), site).ok());
    Result<PointSet> back = readPoints(dir.file(name));
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->crs, site.crs) << name;
    const std::string bytes = readFile(dir.file(name));
    for (size_t at = 0, end; (end = bytes.find('\n', at)) != std::string::npos && bytes.compare(at, 10, "end_header") != 0 &&
                             bytes.compare(at, 4, "DATA") != 0;
         at = end + 1)
      EXPECT_LT(end - at, 1024u) << name << ": a header line Open3D would stop at";
  }
  std::string ply = readFile(dir.file("s.ply"));
  ply.replace(ply.find("comment dpoint: crs ") + 20, 2, "zz");
  writeFile(dir.file("bad.ply"), ply);
  Result<PointSet> bad = readPoints(dir.file("bad.ply"));
  ASSERT_TRUE(bad) << bad.error().message;
  EXPECT_EQ(bad->crs, "");
  EXPECT_EQ(bad->positions, site.positions);

  // Streamed, as read whole.
  for (const char* name : {"a.e57", "a.ply"}) {
    const test::CommandResult whole = runDpoint({"info", dir.file(name), "--stream", "off", "--json", "--quiet"});
    const test::CommandResult streamed = runDpoint({"info", dir.file(name), "--stream", "on", "--json", "--quiet"});
    ASSERT_EQ(streamed.exit_code, 0) << streamed.err;
    const auto crsLine = [](const std::string& out) {
      const size_t at = out.find("\n  \"crs\": ");
      return at == std::string::npos ? std::string() : out.substr(at, out.find('\n', at + 1) - at);
    };
    EXPECT_TRUE(test::contains(crsLine(whole.out), "NAD83(HARN) / Oregon GIC Lambert (ft)")) << whole.out;
    EXPECT_EQ(crsLine(streamed.out), crsLine(whole.out)) << name;
  }
  for (const std::string& las : {kCorpus + "autzen.las", kCorpus + "simple.laz"}) {
    const auto lasLines = [](const std::string& out) { return out.substr(out.find("LAS:"), out.find("LAS CRS:") - out.find("LAS:")); };
    const test::CommandResult whole = runDpoint({"info", las, "--stream", "off", "--quiet"});
    const test::CommandResult streamed = runDpoint({"info", las, "--stream", "on", "--quiet"});
    ASSERT_TRUE(test::contains(streamed.out, "LAS CRS:")) << streamed.out;
    EXPECT_EQ(lasLines(streamed.out), lasLines(whole.out)) << las;
    const auto crsOf = [](const std::string& out) { return out.substr(out.find("LAS CRS:"), out.find('\n', out.find("LAS CRS:")) - out.find("LAS CRS:")); };
    EXPECT_EQ(crsOf(streamed.out), crsOf(whole.out)) << las;
  }

  for (const char* name : {"l.csv", "l.glb"}) {
    r = runDpoint({"convert", kCorpus + "autzen.las", "-o", dir.file(name)});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(test::contains(r.err, std::string(name) + ": coordinate system not written: ")) << r.err;
  }
  r = runDpoint({"convert", kCorpus + "simple.las", "-o", dir.file("none.csv")});  // no CRS records: nothing to say
  EXPECT_FALSE(test::contains(r.err, "coordinate system")) << r.err;
}

// One rule for a set's coordinate system (review findings, 2026-12-02): where a set states it both
// as text and as a LAS source's records, the text is its CRS for every writer and for `info` read
// whole or streamed; of several files, the first that states one (an empty file states none), a
// later other one said and left out; text a header cannot carry, or hex lines that are not whole,
// left out with a note, not half read.
TEST(CliLas, aSetsCoordinateSystemIsOneThingEverywhere) {
  TempDir dir;
  Result<PointSet> autzen = readPoints(kCorpus + "autzen.las");  // EPSG:2994 in GeoTIFF keys
  ASSERT_TRUE(autzen) << autzen.error().message;
  // Both: a PLY with the LAS frame's records and text (as a hand-edited file, or an old merge).
  std::string ply;
  {
    PointSet both = *autzen;
    ASSERT_TRUE(writePoints(dir.file("frame.ply"), both).ok());
    ply = readFile(dir.file("frame.ply"));
    ASSERT_TRUE(test::contains(ply, "comment dpoint: las crs "));
    std::string line = "comment dpoint: crs ";
    for (const char c : std::string("EPSG:32633")) appendHexDigits(line, static_cast<unsigned char>(c));
    ply.insert(ply.find("element vertex"), line + "\n");
    writeFile(dir.file("both.ply"), ply);
  }
  for (const char* mode : {"off", "on"}) {
    const test::CommandResult info = runDpoint({"info", dir.file("both.ply"), "--stream", mode, "--quiet"});
    EXPECT_TRUE(test::contains(info.out, "CRS:                EPSG:32633\n")) << mode << "\n" << info.out;
  }
  for (const char* out : {"both.las", "both.e57", "both.pcd"}) {
    const test::CommandResult r = runDpoint({"convert", dir.file("both.ply"), "-o", dir.file(out)});
    ASSERT_EQ(r.exit_code, 0) << out << r.err;
    EXPECT_FALSE(test::contains(r.err, "replaced")) << r.err;  // the set's CRS is the text: nothing replaced
    ASSERT_EQ(runDpoint({"convert", dir.file(out), "-o", dir.file("again.las"), "-q"}).exit_code, 0) << out;
    EXPECT_TRUE(test::contains(runDpoint({"info", dir.file("again.las"), "--quiet"}).out, "LAS CRS:            EPSG:32633 ("))
        << out;
  }

  // Records alone (a PLY from LAS, several files): info states them, whole and streamed.
  for (const char* mode : {"off", "on"}) {
    const test::CommandResult frame = runDpoint({"info", dir.file("frame.ply"), "--stream", mode, "--quiet"});
    EXPECT_TRUE(test::contains(frame.out, "CRS:                EPSG:2994 (")) << mode << "\n" << frame.out;
    const test::CommandResult two = runDpoint({"info", kCorpus + "autzen.las", kCorpus + "simple.las", "--stream", mode, "--quiet"});
    EXPECT_TRUE(test::contains(two.out, "CRS:                EPSG:2994 (")) << mode << "\n" << two.out;
    const test::CommandResult one = runDpoint({"info", kCorpus + "autzen.las", "--stream", mode, "--quiet"});
    EXPECT_FALSE(test::contains(one.out, "\nCRS:")) << one.out;  // its LAS CRS line says it
    EXPECT_TRUE(test::contains(one.out, "LAS CRS:            EPSG:2994 (")) << one.out;
  }
  // Text PROJ makes nothing of, over records: the text is the CRS, so LAS gets none, and says so.
  {
    std::string text_ply = ply;
    std::string line = "comment dpoint: crs ";
    for (const char c : std::string("hello, not a crs")) appendHexDigits(line, static_cast<unsigned char>(c));
    const size_t at = text_ply.find("comment dpoint: crs ");
    text_ply.replace(at, text_ply.find('\n', at) - at, line);
    writeFile(dir.file("text.ply"), text_ply);
    const test::CommandResult r = runDpoint({"convert", dir.file("text.ply"), "-o", dir.file("text.las")});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(test::contains(r.err, "text.las: coordinate system not written: the input's coordinate system 'hello, not a crs'"))
        << r.err;
    EXPECT_TRUE(test::contains(runDpoint({"info", dir.file("text.las"), "--quiet"}).out, "LAS CRS:            none"));
  }

  // Several files: the first that states one; an empty file states none; another is said.
  PointSet empty, b;
  empty.crs = "EPSG:4326";
  b.positions = {{1.0, 2.0, 3.0}, {2.0, 3.0, 4.0}};
  b.crs = "EPSG:32633";
  ASSERT_TRUE(writePoints(dir.file("empty.ply"), empty).ok());
  ASSERT_TRUE(writePoints(dir.file("b.ply"), b).ok());
  b.crs = "EPSG:32634";
  ASSERT_TRUE(writePoints(dir.file("c.ply"), b).ok());
  for (const char* mode : {"off", "on"}) {
    SCOPED_TRACE(mode);
    const test::CommandResult info =
        runDpoint({"info", dir.file("empty.ply"), dir.file("b.ply"), dir.file("c.ply"), "--stream", mode, "--json"});
    ASSERT_EQ(info.exit_code, 0) << info.err;
    EXPECT_TRUE(test::contains(info.out, "\"crs\": \"EPSG:32633\"")) << info.out;
    EXPECT_TRUE(test::contains(info.err, "c.ply: its coordinate system left out: the set takes " + dir.file("b.ply") +
                                             "'s, the first file's that states one"))
        << info.err;
    // A LAS file first: its records, not the later text.
    const test::CommandResult las = runDpoint({"info", kCorpus + "autzen.las", dir.file("b.ply"), "--stream", mode, "--json"});
    ASSERT_EQ(las.exit_code, 0) << las.err;
    EXPECT_TRUE(test::contains(las.out, "\"crs\": \"EPSG:2994 (")) << las.out;
    EXPECT_TRUE(test::contains(las.err, "b.ply: its coordinate system left out")) << las.err;
  }
  Result<PointSet> joined = readPointInputs({kCorpus + "autzen.las", dir.file("b.ply")});
  ASSERT_TRUE(joined);
  EXPECT_EQ(joined->crs, "");
  EXPECT_EQ(statedCrs(*joined).records.size(), statedCrs(*autzen).records.size());
  joined = readPointInputs({dir.file("b.ply"), kCorpus + "autzen.las"});
  ASSERT_TRUE(joined);
  EXPECT_EQ(joined->crs, "EPSG:32633");
  EXPECT_TRUE(statedCrs(*joined).records.empty());  // the text is its CRS, the frame's records gone

  // What a header cannot carry: more than 64 KiB, a byte that is not text. Written without it.
  for (const std::string& text : {std::string(kMostHeaderCrsBytes + 1, 'x'), std::string("Lambert \xe9tendu")}) {
    for (const char* name : {"t.ply", "t.pcd"}) {
      PointSet t = b;
      t.crs = text;
      std::vector<std::string> notices;
      WriteOptions write;
      write.notices = &notices;
      ASSERT_TRUE(writePoints(dir.file(name), t, write).ok());
      ASSERT_FALSE(notices.empty()) << name;
      EXPECT_TRUE(test::contains(notices.back(), "coordinate system not written: ")) << notices.back();
      EXPECT_EQ(readPoints(dir.file(name))->crs, "") << name;
    }
  }
  // Hex lines that are not whole: left out, with a note (a line with a second word dropped a piece).
  ply = readFile(dir.file("b.ply"));
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
           {"comment dpoint: crs 45", "comment dpoint: crs 45 x"}, {"comment dpoint: crs 45", "comment dpoint: crs 4"},
           {"comment dpoint: crs 45", "comment dpoint: crs zz"}, {"comment dpoint: crs 45", "comment dpoint: crs\ncomment dpoint: crs 45"}}) {
    std::string bad = ply;
    bad.replace(bad.find(from), from.size(), to);
    writeFile(dir.file("bad.ply"), bad);
    std::vector<std::string> notices;
    ReadOptions read;
    read.notices = &notices;
    Result<PointSet> back = readPoints(dir.file("bad.ply"), read);
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->crs, "") << to;
    EXPECT_EQ(back->positions, b.positions);
    ASSERT_EQ(notices.size(), 1u) << to;
    EXPECT_TRUE(test::contains(notices[0], "bad.ply: coordinate system left out: its 'comment dpoint: crs' lines are not hex"))
        << notices[0];
    const test::CommandResult streamed = runDpoint({"info", dir.file("bad.ply"), "--stream", "on"});  // said there too
    EXPECT_TRUE(test::contains(streamed.err, "bad.ply: coordinate system left out: its 'comment dpoint: crs' lines are not hex"))
        << streamed.err;
  }
  b.crs = "EPSG:32633";
  ASSERT_TRUE(writePoints(dir.file("b.pcd"), b).ok());
  std::string pcd = readFile(dir.file("b.pcd"));
  pcd.replace(pcd.find("# dpoint: crs 45"), 16, "# dpoint: crs 45 x");
  writeFile(dir.file("bad.pcd"), pcd);
  std::vector<std::string> notices;
  ReadOptions read;
  read.notices = &notices;
  Result<PointSet> back = readPoints(dir.file("bad.pcd"), read);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(back->crs, "");
  EXPECT_TRUE(std::any_of(notices.begin(), notices.end(), [](const std::string& n) {
    return test::contains(n, "bad.pcd: coordinate system left out: its '# dpoint: crs' lines are not hex");
  }));
}

// Streamed info reads the dimensions' ranges in its first pass, as the whole read gives them; where
// their columns do not fit --max-memory beside the blocks, it lists them without ranges and says
// so, rather than refusing a file it can describe (a review finding).
TEST(CliLas, streamedInfoGivesTheRangesOrSaysWhyNot) {
  const std::string path = kCorpus + "extrabytes.las";  // 27 dimensions, 49 bytes a point
  const test::CommandResult whole = runDpoint({"info", path, "--stream", "off"});
  const test::CommandResult streamed = runDpoint({"info", path, "--stream", "on", "--max-memory", "1M"});
  ASSERT_EQ(whole.exit_code, 0) << whole.err;
  ASSERT_EQ(streamed.exit_code, 0) << streamed.err;
  const auto dimensionLines = [](const std::string& out) {
    std::string lines;
    for (size_t at = out.find("dimension:"); at != std::string::npos; at = out.find("dimension:", at + 1))
      lines += out.substr(at, out.find('\n', at) + 1 - at);
    return lines;
  };
  EXPECT_TRUE(test::contains(dimensionLines(whole.out), "dimension:          intensity (uint16) 0 .. 254\n")) << whole.out;
  EXPECT_EQ(dimensionLines(whole.out), dimensionLines(streamed.out));
  const test::CommandResult small = runDpoint({"info", path, "--stream", "on", "--max-memory", "100K"});
  ASSERT_EQ(small.exit_code, 0) << small.err;
  EXPECT_TRUE(test::contains(small.out, "dimension:          intensity (uint16)\n")) << small.out;
  EXPECT_TRUE(test::contains(small.err, "extrabytes.las: the dimensions' ranges not read: their 49 bytes a point do not fit "
                                        "--max-memory beside the blocks"))
      << small.err;
}

// LAZ reads as the LAS it was compressed from (converters/laz_decode.h), by name or by its header.
TEST(CliLas, lazConvertsInfosAndRendersAsItsLas) {
  TempDir dir;
  const std::string laz = kCorpus + "simple.laz";
  ASSERT_EQ(runDpoint({"convert", laz, "-o", dir.file("z.csv"), "-q"}).exit_code, 0);
  ASSERT_EQ(runDpoint({"convert", kCorpus + "simple.las", "-o", dir.file("s.csv"), "-q"}).exit_code, 0);
  EXPECT_TRUE(readFile(dir.file("z.csv")) == readFile(dir.file("s.csv")));
  test::CommandResult info = runDpoint({"info", laz});
  EXPECT_EQ(info.exit_code, 0) << info.err;
  EXPECT_NE(info.out.find("points:             1065"), std::string::npos) << info.out;
  test::CommandResult render = runDpoint({"render", laz, "-o", dir.file("z.png"), "--width", "64", "--height", "48",
                                          "--color", "classification", "-q"});
  EXPECT_EQ(render.exit_code, 0) << render.err;
  // The same bytes under a .las name: the header says LAZ.
  writeFile(dir.file("hidden.las"), readFile(laz));
  ASSERT_EQ(runDpoint({"convert", dir.file("hidden.las"), "-o", dir.file("h.csv"), "-q"}).exit_code, 0);
  EXPECT_TRUE(readFile(dir.file("h.csv")) == readFile(dir.file("s.csv")));
}

TEST(CliLas, lasScaleTooFineForTheExtentExitsTwoNamingThePoint) {
  TempDir dir;
  // simple.las spans 3.4 km in x; at 1e-6 m only 2147 m fit from the offset.
  test::CommandResult r =
      runDpoint({"convert", kCorpus + "simple.las", "-o", dir.file("fine.las"), "--las-scale", "1e-6", "--quiet"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("fine.las: point "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("beyond LAS's 32-bit integers"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--las-scale"), std::string::npos) << r.err;
  EXPECT_TRUE(dir.entries().empty());
  EXPECT_EQ(runDpoint({"convert", kCorpus + "simple.las", "-o", dir.file("x.las"), "--las-scale", "0"}).exit_code, 1);
  EXPECT_EQ(runDpoint({"convert", kCorpus + "simple.las", "-o", dir.file("x.las"), "--las-scale", "-1"}).exit_code, 1);
  // At 0.01 (the file's own scale) it fits, and every field comes along: format 3, as the input.
  ASSERT_EQ(runDpoint({"convert", kCorpus + "simple.las", "-o", dir.file("ok.las"), "--las-scale", "0.01", "--quiet"})
                .exit_code,
            0);
  test::CommandResult info = runDpoint({"info", dir.file("ok.las"), "--quiet"});
  EXPECT_NE(info.out.find("version 1.2, point format 3, 34-byte records"), std::string::npos) << info.out;
}

TEST(CliLas, maxPointsRefusesALasFileByItsHeader) {
  TempDir dir;
  test::CommandResult r =
      runDpoint({"convert", kCorpus + "simple1_4.las", "-o", dir.file("x.csv"), "--max-points", "1000"});
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_NE(r.err.find("22600 points exceed --max-points 1000"), std::string::npos) << r.err;
}

// random2d's coordinates are arbitrary doubles: no decimal step keeps their digits, so x and y get
// the finest that fits their extent (about 2 units from a whole-number offset: 1e-9), and z, all
// 0, the coarsest (1).
TEST(CliLas, generateWritesLasAtTheFinestScaleItsExtentFits) {
  TempDir dir;
  test::CommandResult r = runDpoint({"generate", "random2d", "--count", "100", "--offset", "637000,5800000,0", "-o",
                                     dir.file("r.las"), "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  test::CommandResult info = runDpoint({"info", dir.file("r.las"), "--quiet"});
  EXPECT_NE(info.out.find("point format 0, 20-byte records (0 extra bytes), 100 points"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("LAS scale:          1e-09 1e-09 1\n"), std::string::npos) << info.out;
}

// A LAS file whose extra bytes record the reader cannot follow: every command that reads it says
// so on stderr, once, as a note (the bytes are read as they are), in memory and streamed; the
// build before said nothing.
TEST(CliLas, anExtraBytesRecordItCannotFollowIsANoteOfEveryCommand) {
  TempDir dir;
  PointSet set;
  set.positions = {{0, 0, 0}, {1, 2, 3}, {2, 1, 0}};
  set.dimensions.add("amplitude", DimType::kU16, 3);
  ASSERT_TRUE(writePoints(dir.file("good.las"), set));
  std::string file = readFile(dir.file("good.las"));
  const size_t d = test::descriptorAt(file);
  ASSERT_NE(d, std::string::npos);
  file[d + 2] = 42;
  writeFile(dir.file("broken.las"), file);
  const std::string note = "dpoint: note: " + dir.file("broken.las") + ": extra bytes descriptor 0 ('amplitude'): data type 42";
  const std::vector<std::vector<std::string>> commands = {
      {"convert", dir.file("broken.las"), "-o", dir.file("b.csv"), "-q"},
      {"info", dir.file("broken.las")},
      {"info", dir.file("broken.las"), "--stream", "on"},
      {"render", dir.file("broken.las"), "-o", dir.file("b.png"), "--width", "32", "--height", "24", "-q"},
      {"render", dir.file("broken.las"), "-o", dir.file("s.png"), "--width", "32", "--height", "24", "--stream", "on", "-q"}};
  for (const std::vector<std::string>& command : commands) {
    test::CommandResult r = runDpoint(command);
    ASSERT_EQ(r.exit_code, 0) << command[0] << " " << command.back() << ": " << r.err;
    EXPECT_TRUE(test::contains(r.err, note)) << command[0] << " " << command.back() << ": " << r.err;
    EXPECT_EQ(r.err.find(note), r.err.rfind(note)) << "once: " << r.err;
  }
  EXPECT_NE(readFile(dir.file("b.csv")).find("extra_byte_1"), std::string::npos);
  for (const char* command : {"convert", "info"}) {
    test::CommandResult r = command == std::string("info") ? runDpoint({"info", dir.file("good.las")})
                                                           : runDpoint({"convert", dir.file("good.las"), "-o", dir.file("g.csv"), "-q"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err.find("note:"), std::string::npos) << r.err;
  }
}

TEST(CliLas, rendersALasFile) {
  TempDir dir;
  test::CommandResult r = runDpoint({"render", kCorpus + "simple.las", "-o", dir.file("s.png"), "--width", "64",
                                     "--height", "48", "--frames", "1", "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(readFile(dir.file("s.png")).substr(0, 8), "\x89PNG\r\n\x1a\n");
}

// The renderer's colour sources for a survey: the file's RGB (auto), intensity, classification,
// elevation; the LAS-only ones are refused by name on other formats.
TEST(CliLas, renderColoursASurveyByEachSource) {
  TempDir dir;
  std::vector<std::string> pictures;
  for (const char* color : {"auto", "intensity", "classification", "elevation"}) {
    SCOPED_TRACE(color);
    const std::string png = dir.file(std::string(color) + ".png");
    test::CommandResult r = runDpoint({"render", kCorpus + "simple.las", "-o", png, "--color", color, "--validate",
                                       "--width", "160", "--height", "120", "--quiet"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    pictures.push_back(readFile(png));
  }
  for (size_t i = 0; i < pictures.size(); ++i)
    for (size_t j = i + 1; j < pictures.size(); ++j) EXPECT_FALSE(pictures[i] == pictures[j]) << i << " " << j;
  // Any dimension colours, from any format; a name the set lacks is refused with those it has.
  writeFile(dir.file("p.csv"), "x,y,z,temperature\n1,2,3,20.5\n2,3,4,21\n");
  test::CommandResult csv =
      runDpoint({"render", dir.file("p.csv"), "-o", dir.file("t.png"), "--color", "temperature", "--quiet"});
  EXPECT_EQ(csv.exit_code, 0) << csv.err;
  csv = runDpoint({"render", dir.file("p.csv"), "-o", dir.file("p.png"), "--color", "intensity"});
  EXPECT_EQ(csv.exit_code, 1);
  EXPECT_NE(csv.err.find("--color intensity: " + dir.file("p.csv") + " has no dimension 'intensity' (it has temperature)"),
            std::string::npos)
      << csv.err;
  EXPECT_FALSE(test::fileExists(dir.file("p.png")));
}


// The real-data hard case: one return of simple.las (853 km north, 0.01 m scale) in a window 1 m
// wide seen from above: float32's 6.25 cm spacing there moves it off its pixel; native does not.
TEST(CliLas, surveyReturnAtCentimetreScaleIsOffItsPixelInFp32Only) {
  TempDir dir;
  double off[2] = {-1, -1};
  int k = 0;
  for (const char* mode : {"fp32", "native"}) {
    test::CommandResult r = runDpoint({"render", kCorpus + "simple.las", "-o", dir.file("r.png"), "--mode", mode,
                                       "--error", "--ortho", "--view-center", "638435.2,853170.1", "--view-width", "1",
                                       "--width", "256", "--height", "256", "--validate", "--json", dir.file("r.json")});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string json = readFile(dir.file("r.json"));
    EXPECT_NE(json.find("\"points_visible\": 1,"), std::string::npos) << json;
    const size_t at = json.find("\"share_off_half_px\": ");
    ASSERT_NE(at, std::string::npos);
    off[k++] = std::stod(json.substr(at + 21));
  }
  EXPECT_EQ(off[0], 1.0) << "fp32: the return is off its pixel";
  EXPECT_EQ(off[1], 0.0) << "native: on it";
}

}  // namespace
}  // namespace dpoint
