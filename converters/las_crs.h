// The coordinate reference system of a LAS file's CRS records (LasSource::vlrs), as the writer
// needs it and `info` shows it.
//
// LAS holds a CRS as GeoTIFF keys (LASF_Projection 34735, with its double (34736) and ASCII (34737)
// parameters) or as OGC WKT (LASF_Projection 2112; libLAS and early PDAL also wrote their own
// `liblas` 2112). Point formats 0–5 may use either; 6–10 must use WKT, and never both (LAS 1.4 R15,
// "Coordinate Reference System Information"). So a LAS 1.2 file's GeoTIFF keys become WKT when its
// points are written as format 6–10 (COPC's formats): from its libLAS WKT record where it has one,
// else from the EPSG codes of its keys through PROJ's database (the projected or geographic CRS,
// with the keys' linear unit, and a vertical CRS as a compound one), as OGC WKT 1 (the dialect LAS
// names). PROJ (libproj, Debian's libproj25) is loaded when a conversion needs it, not linked: every
// other run of dpoint starts without its forty libraries.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "core/point_set.h"
#include "core/result.h"
#include "core/text.h"

namespace dpoint {

// A record of the coordinate system: LASF_Projection's (GeoTIFF keys, OGC WKT), and libLAS's WKT
// record (liblas 2112), which files written by libLAS and early PDAL carry beside or instead of them.
bool isLasCrsRecord(const LasVlr& vlr);

// A set's coordinate system, as the set states it: text (PointSet::crs: an E57's, a PLY or PCD
// header's, the module's) or a LAS source's CRS records. Where a set has both, the text is its CRS
// (every writer and `info` take it so).
struct StatedCrs {
  std::string text;
  std::vector<LasVlr> records;  // isLasCrsRecord's, in order
  bool wkt_bit = false;         // the records' source says WKT (lasSaysWkt)
  bool any() const { return !text.empty() || !records.empty(); }
  bool sameAs(const StatedCrs& other) const;
  // For `info`: the text, else the records' lasCrsSummary; empty for none.
  std::string describe() const;
};
// A CRS in a few words, for a note: a WKT's name, other text quoted (an excerpt), else the records'
// lasCrsSummary.
std::string crsLabel(const StatedCrs& crs);
// Whether `stated` (its text, or its LAS records made WKT) is the CRS `wkt` gives, to PROJ's
// PJ_COMP_EQUIVALENT: names and identifiers aside (EPSG:2994's keys and its database entry are
// named two ways). False where either is none or PROJ cannot tell.
bool crsEquivalent(const StatedCrs& stated, const std::string& wkt);
StatedCrs statedCrs(const PointSet& points);
// A LAS source's CRS records, as statedCrs takes them (none for none).
StatedCrs statedCrs(const std::optional<LasSource>& source);

// What the writer of a point format 6–10 file does with the source's CRS records.
struct LasWktCrs {
  // The records to write instead of the source's CRS records: the source's own where they are
  // WKT already, else one LASF_Projection 2112 record; empty when no WKT could be made.
  std::vector<LasVlr> records;
  // One line for the user when the records changed ("the GeoTIFF keys (EPSG:26910, NAD83 / UTM zone
  // 10N) written as WKT"), or why the file has no CRS now; empty when nothing changed.
  std::string note;
};

// The CRS records for a file whose global encoding says WKT (point formats 6–10): `vlrs` are the
// source's CRS records (isLasCrsRecord's, VLRs and EVLRs), `wkt_bit` its global encoding's WKT bit.
// The source's CRS is its WKT record where that bit is set, else its GeoTIFF keys (made WKT), else
// a WKT record all the same, else libLAS's. Never fails: a CRS that cannot be made WKT is left
// out, with a note saying why.
LasWktCrs lasWktCrs(const std::vector<LasVlr>& vlrs, bool wkt_bit);

// The most bytes of coordinate-system text a PLY or PCD header carries: a WKT is a few KB, and a
// PCD reader takes a header of at most 1 MiB.
inline constexpr size_t kMostHeaderCrsBytes = 65536;

// Why coordinate-system text cannot go into a PLY or PCD header (more than kMostHeaderCrsBytes, a
// byte that is not text: firstNonTextByte), for a note; empty where it can.
std::string headerCrsProblem(const std::string& crs);

// A PLY or PCD header's coordinate-system lines (`comment dpoint: crs HEX`, `# dpoint: crs HEX`),
// read in order: the text, or none with a note where a line is not one word of hex or the text is
// not what a header carries (headerCrsProblem).
class HeaderCrsLines {
 public:
  // One line's words after "crs" (one: the hex).
  void add(const std::vector<std::string_view>& words) {
    seen_ = true;
    good_ = words.size() == 1 && appendHexBytes(text_, words[0]) && good_;
  }
  // The text; `spelled` names the lines in the note (`path: coordinate system left out: …`).
  std::string take(const std::string& path, const char* spelled, std::vector<std::string>* notices);

 private:
  std::string text_;
  bool seen_ = false, good_ = true;
};

// A LAS source's coordinate system as one WKT text, for a format that holds WKT (E57, PCD, PLY):
// its WKT record's, or its GeoTIFF keys made WKT by PROJ (lasWktCrs's choice). Empty where it has
// no CRS records, or (with why in `why_not`) none that can be made WKT.
std::string lasSourceWkt(const LasSource& source, std::string& why_not);

// The CRS that `text` gives (EPSG:CODE or another authority's code, WKT 1 or 2, PROJJSON, or the
// path of a file holding one, such as a .prj), as one line of OGC WKT 1 for a LAS WKT record
// (`--crs`). The error says why not, naming `option` and the text.
Result<std::string> crsAsWkt(const std::string& text, const std::string& option = "--crs");

// The GeoTIFF keys (LASF_Projection 34735, with the CRS's name in 34737) of `wkt` (crsAsWkt's),
// for a LAS 1.2 file: where it is an EPSG projected or 2D geographic CRS, alone or with an EPSG
// vertical CRS, as PROJ's database defines them (ProjectedCSType or GeographicType, the linear and
// vertical units, VerticalCSType); empty for any other CRS, which only WKT in LAS 1.4 holds.
std::vector<LasVlr> lasGeoKeyRecords(const std::string& wkt);

// A LAS WKT record (LASF_Projection 2112) holding `wkt`.
LasVlr lasWktRecord(const std::string& wkt);

// The name a WKT gives its CRS (its first quoted string); empty when it has none.
std::string wktName(const std::string& wkt);

// Whether a LAS source's CRS is WKT: its global encoding's WKT bit, or a point format 6–10, which
// takes WKT whatever the bit says.
inline bool lasSaysWkt(const LasSource& source) { return (source.global_encoding & 0x10) != 0 || source.point_format >= 6; }

// One line naming the CRS of these records without PROJ, for `info`: the WKT's name, or the GeoTIFF
// keys' EPSG codes and citation ("EPSG:26910 + EPSG:5703 (NAD83 / UTM zone 10N), GeoTIFF keys");
// empty when there are none.
std::string lasCrsSummary(const std::vector<LasVlr>& vlrs, bool wkt_bit);

}  // namespace dpoint
