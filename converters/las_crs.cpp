#include "converters/las_crs.h"

#include <dlfcn.h>
#include <proj.h>
#include <proj_experimental.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include "core/bytes.h"
#include "core/text.h"

#ifndef DPOINT_PROJ_SONAME
#define DPOINT_PROJ_SONAME "libproj.so.25"
#endif

namespace dpoint {
namespace {

constexpr uint16_t kWktRecord = 2112, kGeoKeys = 34735, kGeoDoubles = 34736, kGeoAscii = 34737;
// GeoTIFF keys (GeoTIFF 1.1, section 7) the conversion and the summary read.
constexpr uint16_t kModelType = 1024, kRasterType = 1025, kCitation = 1026, kGeographicType = 2048, kGeographicCitation = 2049, kProjectedType = 3072,
                   kProjectedCitation = 3073, kProjLinearUnits = 3076, kVerticalType = 4096, kVerticalUnits = 4099;
constexpr uint16_t kUserDefined = 32767;

bool isLasfProjection(const LasVlr& vlr, uint16_t id) {
  return vlr.user_id == "LASF_Projection" && vlr.record_id == id;
}
bool isGeoTiffRecord(const LasVlr& vlr) {
  return vlr.user_id == "LASF_Projection" &&
         (vlr.record_id == kGeoKeys || vlr.record_id == kGeoDoubles || vlr.record_id == kGeoAscii);
}
bool isLiblasWkt(const LasVlr& vlr) { return vlr.user_id == "liblas" && vlr.record_id == kWktRecord; }

const LasVlr* findRecord(const std::vector<LasVlr>& vlrs, bool (*match)(const LasVlr&)) {
  for (const LasVlr& vlr : vlrs)
    if (match(vlr)) return &vlr;
  return nullptr;
}

// A WKT record's text: up to its first NUL, without surrounding blanks.
std::string wktText(const std::string& data) {
  std::string text = data.substr(0, data.find('\0'));
  const size_t first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return {};
  return text.substr(first, text.find_last_not_of(" \t\r\n") - first + 1);
}

// The GeoTIFF keys whose values sit in the directory (short values), and the ASCII ones (citations),
// of a LASF_Projection 34735 record and its 34737 parameters.
struct GeoKeys {
  std::map<uint16_t, uint16_t> shorts;
  std::map<uint16_t, std::string> ascii;

  std::optional<uint16_t> code(uint16_t key) const {  // an EPSG code: neither 0 nor user-defined
    const auto it = shorts.find(key);
    if (it == shorts.end() || it->second == 0 || it->second == kUserDefined) return std::nullopt;
    return it->second;
  }
  std::string text(uint16_t key) const {
    const auto it = ascii.find(key);
    return it == ascii.end() ? std::string() : it->second;
  }
};

std::optional<GeoKeys> geoKeys(const std::vector<LasVlr>& vlrs) {
  const LasVlr* dir = findRecord(vlrs, [](const LasVlr& v) { return isLasfProjection(v, kGeoKeys); });
  if (!dir || dir->data.size() < 8) return std::nullopt;
  const LasVlr* ascii = findRecord(vlrs, [](const LasVlr& v) { return isLasfProjection(v, kGeoAscii); });
  const char* d = dir->data.data();
  const size_t count = std::min<size_t>(loadUnaligned<uint16_t>(d + 6), dir->data.size() / 8 - 1);
  GeoKeys keys;
  for (size_t k = 1; k <= count; ++k) {
    const uint16_t id = loadUnaligned<uint16_t>(d + 8 * k), location = loadUnaligned<uint16_t>(d + 8 * k + 2);
    const uint16_t n = loadUnaligned<uint16_t>(d + 8 * k + 4), value = loadUnaligned<uint16_t>(d + 8 * k + 6);
    if (location == 0) {
      keys.shorts[id] = value;
    } else if (location == kGeoAscii && ascii && value < ascii->data.size()) {
      std::string text = ascii->data.substr(value, n);
      while (!text.empty() && (text.back() == '|' || text.back() == '\0' || text.back() == ' ')) text.pop_back();
      keys.ascii[id] = std::move(text);
    }
  }
  return keys;
}

// The horizontal EPSG code the keys give, as their model type says (1: projected, ProjectedCSType;
// 2: geographic, GeographicType; without one, whichever is there), with the linear unit key of a
// projected one; or why none.
struct Horizontal {
  uint16_t code = 0;
  std::optional<uint16_t> unit;
};
Result<Horizontal> horizontalOf(const GeoKeys& keys) {
  const auto model = keys.shorts.find(kModelType);
  const bool projected = model != keys.shorts.end() && model->second == 1;
  const bool geographic = model != keys.shorts.end() && model->second == 2;
  if (!geographic)
    if (std::optional<uint16_t> code = keys.code(kProjectedType)) return Horizontal{*code, keys.code(kProjLinearUnits)};
  if (projected) {
    return Error{keys.shorts.count(kProjectedType)
                     ? "the keys define their projection by parameters, not by an EPSG code, and dpoint makes WKT of "
                       "EPSG codes only"
                     : "the keys say projected but name no projected CRS"};
  }
  if (std::optional<uint16_t> code = keys.code(kGeographicType)) return Horizontal{*code, std::nullopt};
  if (keys.shorts.count(kGeographicType) || keys.shorts.count(kProjectedType))
    return Error{"the keys define their CRS by parameters, not by an EPSG code, and dpoint makes WKT of EPSG codes only"};
  return Error{"the keys name no horizontal CRS"};
}

std::string epsg(uint16_t code) { return "EPSG:" + std::to_string(code); }

// "EPSG:26910 + EPSG:5703" or "user-defined", and the keys' citation in brackets where they have one.
std::string keysName(const GeoKeys& keys) {
  Result<Horizontal> horizontal = horizontalOf(keys);
  std::string name = horizontal                               ? epsg(horizontal->code)
                     : keys.shorts.count(kProjectedType) || keys.shorts.count(kGeographicType) ? "a user-defined CRS"
                                                                                                : "no horizontal CRS";
  if (std::optional<uint16_t> vertical = keys.code(kVerticalType)) name += " + " + epsg(*vertical);
  for (uint16_t key : {kProjectedCitation, kCitation, kGeographicCitation}) {  // the first that names something
    const std::string citation = keys.text(key);
    if (!citation.empty() && lowerAscii(citation) != "unknown") return name + " (" + citation + ")";
  }
  return name;
}

// --- PROJ, loaded on first use -------------------------------------------------------------------

struct ProjApi {
  decltype(&proj_context_create) context_create = nullptr;
  decltype(&proj_context_destroy) context_destroy = nullptr;
  decltype(&proj_log_level) log_level = nullptr;
  decltype(&proj_create) create = nullptr;
  decltype(&proj_is_crs) is_crs = nullptr;
  decltype(&proj_create_from_database) create_from_database = nullptr;
  decltype(&proj_destroy) destroy = nullptr;
  decltype(&proj_get_name) get_name = nullptr;
  decltype(&proj_get_type) get_type = nullptr;
  decltype(&proj_as_wkt) as_wkt = nullptr;
  decltype(&proj_crs_get_coordinate_system) crs_get_coordinate_system = nullptr;
  decltype(&proj_cs_get_axis_info) cs_get_axis_info = nullptr;
  decltype(&proj_cs_get_axis_count) cs_get_axis_count = nullptr;
  decltype(&proj_get_source_crs) get_source_crs = nullptr;
  decltype(&proj_uom_get_info_from_database) uom_get_info_from_database = nullptr;
  decltype(&proj_crs_alter_cs_linear_unit) crs_alter_cs_linear_unit = nullptr;
  decltype(&proj_create_compound_crs) create_compound_crs = nullptr;
  decltype(&proj_get_id_auth_name) get_id_auth_name = nullptr;
  decltype(&proj_get_id_code) get_id_code = nullptr;
  decltype(&proj_crs_get_sub_crs) crs_get_sub_crs = nullptr;
  decltype(&proj_is_equivalent_to) is_equivalent_to = nullptr;
  std::string error;  // why PROJ cannot be used; empty when it can
};

ProjApi loadProj() {
  ProjApi api;
  void* library = dlopen(DPOINT_PROJ_SONAME, RTLD_NOW | RTLD_LOCAL);
  if (!library) {
    api.error = std::string("PROJ (" DPOINT_PROJ_SONAME ", Debian's libproj25) cannot be loaded: ") + dlerror();
    return api;
  }
  const auto bind = [&](auto& function, const char* name) {
    function = reinterpret_cast<std::remove_reference_t<decltype(function)>>(dlsym(library, name));
    if (!function && api.error.empty()) api.error = std::string(DPOINT_PROJ_SONAME " has no ") + name;
  };
  bind(api.context_create, "proj_context_create");
  bind(api.context_destroy, "proj_context_destroy");
  bind(api.log_level, "proj_log_level");
  bind(api.create, "proj_create");
  bind(api.is_crs, "proj_is_crs");
  bind(api.create_from_database, "proj_create_from_database");
  bind(api.destroy, "proj_destroy");
  bind(api.get_name, "proj_get_name");
  bind(api.get_type, "proj_get_type");
  bind(api.as_wkt, "proj_as_wkt");
  bind(api.crs_get_coordinate_system, "proj_crs_get_coordinate_system");
  bind(api.cs_get_axis_info, "proj_cs_get_axis_info");
  bind(api.cs_get_axis_count, "proj_cs_get_axis_count");
  bind(api.get_source_crs, "proj_get_source_crs");
  bind(api.uom_get_info_from_database, "proj_uom_get_info_from_database");
  bind(api.crs_alter_cs_linear_unit, "proj_crs_alter_cs_linear_unit");
  bind(api.create_compound_crs, "proj_create_compound_crs");
  bind(api.get_id_auth_name, "proj_get_id_auth_name");
  bind(api.get_id_code, "proj_get_id_code");
  bind(api.crs_get_sub_crs, "proj_crs_get_sub_crs");
  bind(api.is_equivalent_to, "proj_is_equivalent_to");
  return api;  // the library stays loaded for the process
}

const ProjApi& projApi() {
  static const ProjApi api = loadProj();
  return api;
}

// One conversion's PROJ context and objects, destroyed with it.
class Proj {
 public:
  explicit Proj(const ProjApi& api) : api_(api), context_(api.context_create()) {
    if (context_) api_.log_level(context_, PJ_LOG_NONE);  // errors come back as values, not on stderr
  }
  ~Proj() {
    for (PJ* object : objects_) api_.destroy(object);
    if (context_) api_.context_destroy(context_);
  }
  Proj(const Proj&) = delete;
  Proj& operator=(const Proj&) = delete;

  PJ_CONTEXT* context() const { return context_; }
  PJ* keep(PJ* object) {
    if (object) objects_.push_back(object);
    return object;
  }

  // The EPSG CRS `code`, with its coordinate system's linear unit made EPSG unit `unit` (the
  // GeoTIFF keys' ProjLinearUnits or VerticalUnits) where that is given and differs.
  Result<PJ*> crs(uint16_t code, std::optional<uint16_t> unit, std::string* changed) {
    const std::string text = std::to_string(code);
    PJ* crs = keep(api_.create_from_database(context_, "EPSG", text.c_str(), PJ_CATEGORY_CRS, 0, nullptr));
    if (!crs) return Error{epsg(code) + " is not a CRS in PROJ's database"};
    if (!unit) return crs;
    PJ* cs = keep(api_.crs_get_coordinate_system(context_, crs));
    const char* unit_code = nullptr;
    if (!cs || !api_.cs_get_axis_info(context_, cs, 0, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, &unit_code))
      return crs;  // no axis to say its unit (a compound CRS has none of its own)
    const std::string wanted = std::to_string(*unit);
    if (unit_code && wanted == unit_code) return crs;
    const char* name = nullptr;
    double factor = 0.0;
    const char* category = nullptr;
    if (!api_.uom_get_info_from_database(context_, "EPSG", wanted.c_str(), &name, &factor, &category) || !category ||
        std::strcmp(category, "linear") != 0)
      return Error{"its linear unit EPSG:" + wanted + " is not a linear unit in PROJ's database"};
    PJ* altered = keep(api_.crs_alter_cs_linear_unit(context_, crs, name, factor, "EPSG", wanted.c_str()));
    if (!altered) return Error{"PROJ cannot give " + epsg(code) + " the linear unit EPSG:" + wanted};
    if (changed) *changed += std::string(changed->empty() ? "" : "; ") + epsg(code) + " in the keys' unit, " + name;
    return altered;
  }

 private:
  const ProjApi& api_;
  PJ_CONTEXT* context_;
  std::vector<PJ*> objects_;
};

// WKT 1 of `crs`: one line; a 3D geographic CRS as a compound of its 2D one and ellipsoidal
// heights, as WKT 1 has no 3D geographic CRS (GDAL writes the same).
const char* wkt1(const ProjApi& api, Proj& proj, PJ* crs) {
  const char* const options[] = {"MULTILINE=NO", "ALLOW_ELLIPSOIDAL_HEIGHT_AS_VERTICAL_CRS=YES", nullptr};
  return api.as_wkt(proj.context(), crs, PJ_WKT1_GDAL, options);
}

// The keys' CRS as OGC WKT 1, or why not. `changed` gets what the WKT says other than the codes (a
// unit of the keys', a vertical code left out).
Result<std::string> keysAsWkt(const GeoKeys& keys, std::string* changed) {
  Result<Horizontal> horizontal = horizontalOf(keys);
  if (!horizontal) return horizontal.error();
  const ProjApi& api = projApi();
  if (!api.error.empty()) return Error{api.error};
  Proj proj(api);
  if (!proj.context()) return Error{"PROJ cannot make a context"};
  Result<PJ*> crs = proj.crs(horizontal->code, horizontal->unit, changed);
  if (!crs) return crs.error();
  PJ* result = *crs;
  if (std::optional<uint16_t> vertical_code = keys.code(kVerticalType)) {
    // GeoTIFF 1.0's codes 5001-5035 are ellipsoidal heights, no EPSG vertical CRS: such a code (or
    // one PROJ does not know) leaves the vertical part out, not the whole CRS.
    Result<PJ*> vertical = proj.crs(*vertical_code, keys.code(kVerticalUnits), changed);
    if (vertical && api.get_type(*vertical) == PJ_TYPE_VERTICAL_CRS) {
      const std::string name = std::string(api.get_name(*crs)) + " + " + api.get_name(*vertical);
      result = proj.keep(api.create_compound_crs(proj.context(), name.c_str(), *crs, *vertical));
      if (!result) return Error{"PROJ cannot combine " + epsg(horizontal->code) + " and " + epsg(*vertical_code)};
    } else if (changed) {
      *changed += std::string(changed->empty() ? "" : "; ") + "its vertical code " + std::to_string(*vertical_code) +
                  " left out: not a vertical CRS in PROJ's database";
    }
  }
  const char* wkt = wkt1(api, proj, result);
  if (!wkt) return Error{"PROJ cannot write " + keysName(keys) + " as WKT 1"};
  return std::string(wkt);
}

}  // namespace

bool isLasCrsRecord(const LasVlr& vlr) { return vlr.user_id == "LASF_Projection" || isLiblasWkt(vlr); }

std::string wktName(const std::string& wkt) {
  const size_t open = wkt.find('"');
  if (open == std::string::npos) return {};
  const size_t close = wkt.find('"', open + 1);
  return close == std::string::npos ? std::string() : wkt.substr(open + 1, close - open - 1);
}

LasVlr lasWktRecord(const std::string& wkt) {
  const bool extended = wkt.size() >= 65535;  // a VLR holds at most 65535 bytes; an EVLR more
  return LasVlr{"LASF_Projection", kWktRecord, "OGC WKT coordinate system", wkt + '\0', extended};
}

namespace {

// An EPSG code a GeoTIFF key holds (1-32766), from an authority's name and code.
std::optional<uint16_t> keyCode(const char* authority, const char* code) {
  if (!authority || !code || std::strcmp(authority, "EPSG") != 0) return std::nullopt;
  char* end = nullptr;
  const long value = std::strtol(code, &end, 10);
  if (*end != '\0' || value < 1 || value >= kUserDefined) return std::nullopt;
  return static_cast<uint16_t>(value);
}

// The EPSG code of `object` where it has one that a GeoTIFF key holds (1-32766), and PROJ's database
// defines it as the object says (axis order aside): a WKT that names EPSG:32633 but changes its
// parameters keeps its WKT.
std::optional<uint16_t> epsgCode(const ProjApi& api, Proj& proj, PJ* object) {
  const char* code = api.get_id_code(object, 0);
  const std::optional<uint16_t> value = keyCode(api.get_id_auth_name(object, 0), code);
  if (!value) return std::nullopt;
  PJ* defined = proj.keep(api.create_from_database(proj.context(), "EPSG", code, PJ_CATEGORY_CRS, 0, nullptr));
  if (!defined || !api.is_equivalent_to(object, defined, PJ_COMP_EQUIVALENT_EXCEPT_AXIS_ORDER_GEOGCRS))
    return std::nullopt;
  return value;
}

// The EPSG code of the unit of `crs`'s first axis, where it has one a key holds.
std::optional<uint16_t> axisUnit(const ProjApi& api, Proj& proj, PJ* crs) {
  PJ* cs = proj.keep(api.crs_get_coordinate_system(proj.context(), crs));
  const char* authority = nullptr;
  const char* code = nullptr;
  if (!cs || !api.cs_get_axis_info(proj.context(), cs, 0, nullptr, nullptr, nullptr, nullptr, nullptr, &authority, &code))
    return std::nullopt;
  return keyCode(authority, code);
}

}  // namespace

std::vector<LasVlr> lasGeoKeyRecords(const std::string& wkt) {
  const ProjApi& api = projApi();
  if (!api.error.empty()) return {};
  Proj proj(api);
  if (!proj.context()) return {};
  PJ* crs = proj.keep(api.create(proj.context(), wkt.c_str()));
  if (!crs || !api.is_crs(crs)) return {};
  PJ* horizontal = crs;
  PJ* vertical = nullptr;
  if (api.get_type(crs) == PJ_TYPE_COMPOUND_CRS) {
    horizontal = proj.keep(api.crs_get_sub_crs(proj.context(), crs, 0));
    vertical = proj.keep(api.crs_get_sub_crs(proj.context(), crs, 1));
    if (!horizontal || !vertical || api.get_type(vertical) != PJ_TYPE_VERTICAL_CRS) return {};
  }
  const PJ_TYPE type = api.get_type(horizontal);
  if (type != PJ_TYPE_PROJECTED_CRS && type != PJ_TYPE_GEOGRAPHIC_2D_CRS) return {};
  const std::optional<uint16_t> code = epsgCode(api, proj, horizontal);
  if (!code) return {};
  std::map<uint16_t, uint16_t> keys = {{kModelType, type == PJ_TYPE_PROJECTED_CRS ? 1 : 2}, {kRasterType, 1}};
  keys[type == PJ_TYPE_PROJECTED_CRS ? kProjectedType : kGeographicType] = *code;
  if (type == PJ_TYPE_PROJECTED_CRS)
    if (std::optional<uint16_t> unit = axisUnit(api, proj, horizontal)) keys[kProjLinearUnits] = *unit;
  if (vertical) {
    const std::optional<uint16_t> vertical_code = epsgCode(api, proj, vertical);
    if (!vertical_code) return {};
    keys[kVerticalType] = *vertical_code;
    if (std::optional<uint16_t> unit = axisUnit(api, proj, vertical)) keys[kVerticalUnits] = *unit;
  }
  // The citation: the CRS's name, '|'-ended as GeoTIFF's ASCII parameters are.
  const char* name = api.get_name(crs);
  std::string ascii = std::string(name ? name : "") + "|";
  // The directory (GeoTIFF 1.1, 7.1): version 1.1.0 and the key count, then each key in order of
  // its number: id, where its value is (0: in place; 34737: the ASCII parameters), count, value.
  std::string directory;
  const auto put = [&](uint16_t a, uint16_t b, uint16_t c, uint16_t d) {
    for (uint16_t v : {a, b, c, d}) directory.append(reinterpret_cast<const char*>(&v), 2);
  };
  keys[kCitation] = 0;  // placed in order below
  put(1, 1, 0, static_cast<uint16_t>(keys.size()));
  for (const auto& [id, value] : keys) {
    if (id == kCitation) put(id, kGeoAscii, static_cast<uint16_t>(ascii.size()), 0);
    else put(id, 0, 1, value);
  }
  return {LasVlr{"LASF_Projection", kGeoKeys, "GeoTIFF GeoKeyDirectoryTag", directory, false},
          LasVlr{"LASF_Projection", kGeoAscii, "GeoTIFF GeoAsciiParamsTag", ascii + '\0', false}};
}

Result<std::string> crsAsWkt(const std::string& text, const std::string& option) {
  const std::string what = option + " " + quotedExcerpt(text);
  if (text.find_first_not_of(" \t\r\n") == std::string::npos)
    return Error{what + ": empty; give EPSG:CODE, WKT, or a file holding WKT", ExitCode::kUsage};
  // A regular file by that name holds the definition (a .prj); else the text is one.
  std::string definition = text;
  std::error_code error;
  if (std::filesystem::is_regular_file(text, error)) {
    constexpr uintmax_t kMaxBytes = uintmax_t{1} << 20;
    if (std::filesystem::file_size(text, error) > kMaxBytes)
      return Error{what + ": a file over 1 MiB, not a CRS definition", ExitCode::kUsage};
    std::ifstream file{text, std::ios::binary};
    std::ostringstream read;
    read << file.rdbuf();
    if (!file) return Error{what + ": cannot be read", ExitCode::kUsage};
    definition = read.str();
    if (definition.rfind("\xEF\xBB\xBF", 0) == 0) definition.erase(0, 3);  // a UTF-8 byte order mark
  } else if (std::filesystem::exists(text, error)) {  // a folder or a device (a review finding: "no such file")
    return Error{what + ": " + (std::filesystem::is_directory(text, error) ? "a folder" : "not a regular file") +
                     ", not a file holding a CRS",
                 ExitCode::kUsage};
  } else if (text.find_first_of("[:{+") == std::string::npos) {
    return Error{what + ": no such file, and not EPSG:CODE, WKT, PROJJSON or a PROJ string", ExitCode::kUsage};
  }
  const ProjApi& api = projApi();
  if (!api.error.empty()) return Error{what + ": " + api.error, ExitCode::kUsage};
  Proj proj(api);
  if (!proj.context()) return Error{what + ": PROJ cannot make a context", ExitCode::kUsage};
  PJ* crs = proj.keep(api.create(proj.context(), definition.c_str()));
  if (!crs || !api.is_crs(crs))
    return Error{what + ": not a coordinate reference system PROJ knows (give EPSG:CODE, WKT, PROJJSON, a PROJ "
                        "string with +type=crs, or a file holding one)",
                 ExitCode::kUsage};
  // A height system alone says nothing of x and y, which every LAS point has: a vertical CRS, also
  // one bound to a transformation (GDAL writes a .prj with geoid grids so), or a one-axis one.
  const PJ* placed = crs;
  if (api.get_type(crs) == PJ_TYPE_BOUND_CRS)
    if (const PJ* source = proj.keep(api.get_source_crs(proj.context(), crs))) placed = source;
  int axes = 2;
  if (api.get_type(placed) != PJ_TYPE_COMPOUND_CRS)
    if (const PJ* cs = proj.keep(api.crs_get_coordinate_system(proj.context(), placed)))
      axes = api.cs_get_axis_count(proj.context(), cs);
  if (api.get_type(placed) == PJ_TYPE_VERTICAL_CRS || axes == 1)
    return Error{what + ": a vertical CRS alone, which places no x or y; give the horizontal CRS, or both "
                        "(EPSG:HORIZONTAL+VERTICAL, e.g. EPSG:6580+5703)",
                 ExitCode::kUsage};
  const char* wkt = wkt1(api, proj, crs);
  if (!wkt) return Error{what + ": PROJ cannot write it as WKT 1, the WKT LAS takes", ExitCode::kUsage};
  return std::string(wkt);
}

namespace {

// A WKT's name for a message: at most 100 characters.
std::string shortName(const std::string& wkt) {
  std::string name = wktName(wkt);
  if (name.size() > 100) name = name.substr(0, 97) + "...";
  return name.empty() ? std::string("unnamed") : name;
}

bool isLasWkt(const LasVlr& v) { return isLasfProjection(v, kWktRecord) && !wktText(v.data).empty(); }
bool isLiblasText(const LasVlr& v) { return isLiblasWkt(v) && !wktText(v.data).empty(); }

}  // namespace

StatedCrs statedCrs(const std::optional<LasSource>& source) {
  StatedCrs stated;
  if (!source) return stated;
  for (const LasVlr& vlr : source->vlrs)
    if (isLasCrsRecord(vlr)) stated.records.push_back(vlr);
  stated.wkt_bit = lasSaysWkt(*source);
  return stated;
}

StatedCrs statedCrs(const PointSet& points) {
  StatedCrs stated = statedCrs(points.las);
  stated.text = points.crs;
  return stated;
}

std::string StatedCrs::describe() const {
  if (!text.empty() || records.empty()) return text;
  return lasCrsSummary(records, wkt_bit);
}

bool crsEquivalent(const StatedCrs& stated, const std::string& wkt) {
  std::string mine = stated.text;
  if (mine.empty() && !stated.records.empty()) {
    std::string why_not;
    LasSource frame;
    frame.vlrs = stated.records;
    frame.global_encoding = stated.wkt_bit ? 0x10 : 0;
    mine = lasSourceWkt(frame, why_not);
  }
  if (mine.empty() || wkt.empty()) return false;
  if (mine == wkt) return true;
  const ProjApi& api = projApi();
  if (!api.error.empty()) return false;
  Proj proj(api);
  if (!proj.context()) return false;
  const PJ* a = proj.keep(api.create(proj.context(), mine.c_str()));
  const PJ* b = proj.keep(api.create(proj.context(), wkt.c_str()));
  if (a && b && api.is_equivalent_to(a, b, PJ_COMP_EQUIVALENT)) return true;
  // The same definition as PROJ writes it (`wkt` is --crs's, made by crsAsWkt): PROJ renames a
  // datum on the way ("NAD_1983_HARN" becomes "NAD83 (High Accuracy Reference Network)"), which
  // the comparison above counts as a difference (a review finding).
  const Result<std::string> written = crsAsWkt(mine, "the input's CRS");
  return written && *written == wkt;
}

std::string crsLabel(const StatedCrs& crs) {
  if (crs.text.empty()) return crs.describe();
  const std::string name = wktName(crs.text);
  return !name.empty() && firstNonTextByte(name) == std::string::npos ? name : quotedExcerpt(crs.text);
}

bool StatedCrs::sameAs(const StatedCrs& other) const {
  if (text != other.text || records.size() != other.records.size()) return false;
  for (size_t k = 0; k < records.size(); ++k) {
    const LasVlr &a = records[k], &b = other.records[k];
    if (a.user_id != b.user_id || a.record_id != b.record_id || a.data != b.data) return false;
  }
  return true;
}

std::string headerCrsProblem(const std::string& crs) {
  if (crs.size() > kMostHeaderCrsBytes)
    return "its " + std::to_string(crs.size()) + " bytes are more than a header holds (" +
           std::to_string(kMostHeaderCrsBytes) + ")";
  if (const size_t bad = firstNonTextByte(crs); bad != std::string::npos) {
    std::string byte;
    appendHexByte(byte, static_cast<unsigned char>(crs[bad]));
    return "its text " + quotedExcerpt(crs) + " holds a byte that is not text (" + byte + ")";
  }
  return "";
}

std::string HeaderCrsLines::take(const std::string& path, const char* spelled, std::vector<std::string>* notices) {
  if (!seen_) return "";
  const std::string why = !good_ ? "its '" + std::string(spelled) + "' lines are not hex, one word a line" : headerCrsProblem(text_);
  if (why.empty()) return std::move(text_);
  if (notices) notices->push_back(path + ": coordinate system left out: " + why);
  return "";
}

std::string lasSourceWkt(const LasSource& source, std::string& why_not) {
  const StatedCrs stated = statedCrs(std::optional<LasSource>(source));
  if (stated.records.empty()) return "";
  LasWktCrs wkt = lasWktCrs(stated.records, stated.wkt_bit);
  const auto it = std::find_if(wkt.records.begin(), wkt.records.end(), [](const LasVlr& r) { return r.record_id == 2112; });
  if (it != wkt.records.end()) return std::string(it->data.c_str());  // up to a NUL that ends it
  why_not = !wkt.note.empty() ? wkt.note : "the LAS source's is not WKT and PROJ made none of it";
  return "";
}

LasWktCrs lasWktCrs(const std::vector<LasVlr>& vlrs, bool wkt_bit) {
  // The source's CRS, as LAS says which record holds it: the WKT record where the global encoding
  // says WKT, else the GeoTIFF keys (a LAS 1.2 file's), else a WKT record all the same, else
  // libLAS's. The result holds one WKT record and no GeoTIFF keys.
  LasWktCrs out;
  const LasVlr* wkt = findRecord(vlrs, isLasWkt);
  const std::optional<GeoKeys> keys = geoKeys(vlrs);
  const auto keep = [&](bool (*except)(const LasVlr&)) {  // every record but the CRS ones, and `except`'s
    for (const LasVlr& vlr : vlrs)
      if (!isGeoTiffRecord(vlr) && !isLasfProjection(vlr, kWktRecord) && !isLiblasWkt(vlr)) out.records.push_back(vlr);
    if (except)
      if (const LasVlr* record = findRecord(vlrs, except)) out.records.push_back(*record);
  };
  if (wkt && (wkt_bit || !keys)) {
    keep(isLasWkt);
    return out;
  }
  std::string why;
  if (keys) {
    std::string changed;
    Result<std::string> text = keysAsWkt(*keys, &changed);
    if (text) {
      keep(nullptr);
      out.records.push_back(lasWktRecord(*text));
      out.note = "the GeoTIFF keys' CRS, " + keysName(*keys) + ", written as WKT (" + shortName(*text) + ")";
      if (!changed.empty()) out.note += ": " + changed;
      return out;
    }
    why = text.error().message;
  }
  if (wkt) {
    keep(isLasWkt);
    out.note = "its WKT record (" + shortName(wktText(wkt->data)) + ") kept, the GeoTIFF keys (" + keysName(*keys) +
               ") left out: " + why;
    return out;
  }
  if (const LasVlr* liblas = findRecord(vlrs, isLiblasText)) {
    keep(nullptr);
    const std::string text = wktText(liblas->data);
    out.records.push_back(lasWktRecord(text));
    out.note = "libLAS's WKT record (" + shortName(text) + ") written as the LAS WKT record (LASF_Projection 2112)";
    if (keys) out.note += "; the GeoTIFF keys (" + keysName(*keys) + ") left out: " + why;
    return out;
  }
  keep(nullptr);
  if (keys) out.note = "the GeoTIFF keys' CRS, " + keysName(*keys) + ", is left out and the file has no CRS: " + why;
  return out;
}

std::string lasCrsSummary(const std::vector<LasVlr>& vlrs, bool wkt_bit) {
  // As lasWktCrs chooses: the WKT record where the global encoding says WKT, else the GeoTIFF keys,
  // else a WKT record, else libLAS's.
  const LasVlr* wkt = findRecord(vlrs, isLasWkt);
  const std::optional<GeoKeys> keys = geoKeys(vlrs);
  if (wkt && (wkt_bit || !keys)) return shortName(wktText(wkt->data)) + ", WKT";
  if (keys) return keysName(*keys) + ", GeoTIFF keys";
  if (const LasVlr* liblas = findRecord(vlrs, isLiblasText)) return shortName(wktText(liblas->data)) + ", libLAS's WKT";
  return {};
}

}  // namespace dpoint
