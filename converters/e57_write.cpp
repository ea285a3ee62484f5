// The E57 writer (converters/e57.h): one scan, its records in data packets of whole 64-record
// groups (so that every field's chunk is whole bytes, whatever its bit width), packed on all cores
// a batch of packets at a time and paged with their CRC-32C as they are written.
#include <algorithm>
#include <bit>
#include <cinttypes>
#include <cmath>
#include <cstring>

#include "converters/e57.h"
#include "converters/las_crs.h"
#include "core/atomic_file.h"
#include "core/bytes.h"
#include "core/dimensions.h"
#include "core/parallel.h"
#include "core/text.h"

namespace dpoint {

namespace {

constexpr uint64_t kPage = 1024, kLogicalPage = 1020;
constexpr uint64_t kHeaderBytes = 48, kSectionHeaderBytes = 32;
constexpr uint64_t kMostPacket = 65536;
constexpr size_t kPacketsPerBatch = 256;

// The coordinate system the file states (E57WriteOptions::crs says which), as XML character data
// (CDATA, whose end marker is split where the text holds one); a LAS source's records made WKT as
// its writer makes them. Text that XML cannot hold (a control byte, a byte that is not UTF-8) is
// left out, with a note, as is a LAS coordinate system that cannot be made WKT.
std::string coordinateMetadata(const PointSet& points, const E57WriteOptions& options, std::vector<std::string>& notes) {
  std::string crs = !options.crs.empty() ? options.crs : points.crs;
  if (crs.empty() && points.las) {
    std::string why_not;
    crs = lasSourceWkt(*points.las, why_not);
    if (!why_not.empty()) notes.push_back("coordinate system not written: " + why_not);
  }
  if (const size_t bad = firstNonTextByte(crs); bad != std::string::npos) {
    std::string byte;
    appendHexByte(byte, static_cast<unsigned char>(crs[bad]));
    notes.push_back("coordinate system not written: its text " + quotedExcerpt(crs) + " holds a byte XML cannot hold (" +
                    byte + ")");
    return "";
  }
  std::string cdata;  // "]]>" as "]]" at the end of one section and ">" in the next
  size_t at = 0;
  for (size_t end; (end = crs.find("]]>", at)) != std::string::npos; at = end + 2) {
    cdata.append(crs, at, end + 2 - at);
    cdata += "]]><![CDATA[";
  }
  cdata.append(crs, at);
  return cdata;
}

uint64_t physicalOf(uint64_t logical) { return logical / kLogicalPage * kPage + logical % kLogicalPage; }

// A field of the prototype and where its values come from.
struct OutField {
  enum class Kind { kFloat32, kFloat64, kInteger } kind = Kind::kFloat64;
  std::string name;  // the XML element's
  int64_t minimum = 0, maximum = 0;  // an Integer's limits: its values' own
  unsigned bits = 64;
  // Where the values come from: a coordinate or colour channel (axis), or a dimension (plus `add`).
  enum class Source { kPosition, kColor, kDimension } source = Source::kPosition;
  int axis = 0;
  const Dimension* dimension = nullptr;
  int64_t add = 0;
  bool limited = false;  // a Float's limits known (the intensity's): written as its minimum and maximum
  double least = 0.0, most = 0.0;
};

// fn(i, value) for points [begin, end) of an Integer field, the source's type settled once a range.
template <typename T, typename Fn>
void eachStored(const Dimension& d, int64_t add, size_t begin, size_t end, Fn&& fn) {
  for (size_t i = begin; i < end; ++i) {
    T v;
    std::memcpy(&v, d.bytes.data() + i * sizeof(T), sizeof(T));
    fn(i, static_cast<int64_t>(v) + add);
  }
}
template <typename Fn>
void eachInteger(const OutField& f, const PointSet& points, uint16_t full, size_t begin, size_t end, Fn&& fn) {
  if (f.source == OutField::Source::kColor) {
    for (size_t i = begin; i < end; ++i) fn(i, static_cast<int64_t>(colorInteger(points.colors[i][f.axis], full)));
    return;
  }
  const Dimension& d = *f.dimension;
  switch (d.type) {
    case DimType::kU8: eachStored<uint8_t>(d, f.add, begin, end, fn); break;
    case DimType::kI8: eachStored<int8_t>(d, f.add, begin, end, fn); break;
    case DimType::kU16: eachStored<uint16_t>(d, f.add, begin, end, fn); break;
    case DimType::kI16: eachStored<int16_t>(d, f.add, begin, end, fn); break;
    case DimType::kU32: eachStored<uint32_t>(d, f.add, begin, end, fn); break;
    case DimType::kI32: eachStored<int32_t>(d, f.add, begin, end, fn); break;
    case DimType::kU64: eachStored<uint64_t>(d, f.add, begin, end, fn); break;  // at most 2^63 - 1 (checked)
    case DimType::kI64: eachStored<int64_t>(d, f.add, begin, end, fn); break;
    case DimType::kF32:
    case DimType::kF64: break;  // Float fields
  }
}

// camelCase of a LAS field's snake_case name (point_source_id → pointSourceId), as the E57 LAS
// extension names them.
std::string camelCase(const std::string& snake) {
  std::string out;
  bool upper = false;
  for (char c : snake) {
    if (c == '_') {
      upper = true;
      continue;
    }
    out += upper && c >= 'a' && c <= 'z' ? static_cast<char>(c - 'a' + 'A') : c;
    upper = false;
  }
  return out;
}

bool isNameChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' || c == '.' ||
         (static_cast<unsigned char>(c) & 0x80);  // UTF-8: XML names take letters of every script
}

// The fields E57 gives a meaning (its standard point record).
bool isStandardField(const std::string& name) {
  static const char* const kNames[] = {"cartesianX", "cartesianY", "cartesianZ", "cartesianInvalidState",
                                       "sphericalRange", "sphericalAzimuth", "sphericalElevation",
                                       "sphericalInvalidState", "colorRed", "colorGreen", "colorBlue", "isColorInvalid",
                                       "intensity", "isIntensityInvalid", "rowIndex", "columnIndex", "returnIndex",
                                       "returnCount", "timeStamp", "isTimeStampInvalid"};
  return std::any_of(std::begin(kNames), std::end(kNames), [&](const char* k) { return name == k; });
}
// Those an integer dimension of the same name is (as an E57 file read here gives it).
bool isStandardIndex(const std::string& name) {
  return name == "rowIndex" || name == "columnIndex" || name == "isColorInvalid" || name == "isIntensityInvalid" ||
         name == "isTimeStampInvalid";
}

// The least value of an integer dimension (of none, 0).
int64_t leastOf(const Dimension& d, unsigned threads) {
  const size_t n = d.size();
  constexpr size_t kBlock = 1u << 16;
  std::vector<double> least((n + kBlock - 1) / kBlock, 0.0);
  parallelFor(least.size(), threads, [&](size_t b, unsigned) {
    double m = d.value(b * kBlock);
    for (size_t i = b * kBlock, end = std::min(n, i + kBlock); i < end; ++i) m = std::min(m, d.value(i));
    least[b] = m;
  });
  return least.empty() ? 0 : static_cast<int64_t>(*std::min_element(least.begin(), least.end()));
}

// Appends logical bytes, writing each whole page with its checksum.
class PagedWriter {
 public:
  explicit PagedWriter(AtomicFile& file) : file_(file) { page_.reserve(kPage); }
  Status append(const uint8_t* data, size_t size) {
    while (size > 0) {
      const size_t take = std::min<size_t>(size, kLogicalPage - page_.size());
      page_.insert(page_.end(), data, data + take);
      data += take;
      size -= take;
      if (page_.size() == kLogicalPage)
        if (Status s = flush(); !s) return s;
    }
    return okStatus();
  }
  Status append(std::string_view text) { return append(reinterpret_cast<const uint8_t*>(text.data()), text.size()); }
  // 128 bits of what has been written: every whole page's checksum, the bytes of the page begun,
  // the prototype and the count (FNV-1a, twice with other seeds).
  std::pair<uint64_t, uint64_t> digest(const std::string& prototype, uint64_t count) const {
    uint64_t a = 1469598103934665603ull, b = 0x6c62272e07bb0142ull;
    const auto mix = [&](const void* data, size_t size) {
      for (size_t i = 0; i < size; ++i) {
        a = (a ^ static_cast<const uint8_t*>(data)[i]) * 1099511628211ull;
        b = (b ^ static_cast<const uint8_t*>(data)[i]) * 0x100000001b3ull + 0x9e3779b97f4a7c15ull;
      }
    };
    mix(crcs_.data(), crcs_.size() * sizeof(uint32_t));
    mix(page_.data(), page_.size());
    mix(prototype.data(), prototype.size());
    mix(&count, sizeof count);
    return {a, b};
  }
  // The last page, padded with zeros.
  Status finish() {
    if (page_.empty()) return okStatus();
    page_.resize(kLogicalPage, 0);
    return flush();
  }

 private:
  Status flush() {
    const uint32_t crc = __builtin_bswap32(crc32c(page_.data(), page_.size()));
    crcs_.push_back(crc);
    page_.resize(kPage);
    std::memcpy(page_.data() + kLogicalPage, &crc, 4);
    Status s = file_.write(page_.data(), page_.size());
    page_.clear();
    return s;
  }
  AtomicFile& file_;
  std::vector<uint8_t> page_;
  std::vector<uint32_t> crcs_;  // 4 bytes a KiB written
};

// Placeholders of the GUIDs' 36 characters in the XML, replaced once the points are written.
constexpr const char* kFileGuidMarker = "00000000-0000-0000-0000-00000000file";
constexpr const char* kScanGuidMarker = "00000000-0000-0000-0000-00000000scan";

// 128 bits as an RFC 4122 UUID of version 5 (made from a name: here, the file's content).
std::string uuidText(uint64_t hi, uint64_t lo) {
  hi = (hi & ~0xF000ull) | 0x5000ull;                      // version 5
  lo = (lo & 0x3FFFFFFFFFFFFFFFull) | 0x8000000000000000ull;  // the RFC 4122 variant
  char text[40];
  std::snprintf(text, sizeof text, "%08" PRIx64 "-%04" PRIx64 "-%04" PRIx64 "-%04" PRIx64 "-%012" PRIx64, hi >> 32,
                (hi >> 16) & 0xFFFF, hi & 0xFFFF, lo >> 48, lo & uint64_t{0xFFFFFFFFFFFF});
  return text;
}


}  // namespace

Status writeE57(const std::string& path, const PointSet& points, const E57WriteOptions& options) {
  const size_t n = points.size();
  const unsigned threads = resolveThreads(options.threads);
  std::vector<std::string> notes;

  // The prototype: x, y, z as doubles (every coordinate kept), colours, then the dimensions.
  std::vector<OutField> fields;
  for (int axis = 0; axis < 3; ++axis) {
    OutField f;
    f.name = std::string("cartesian") + static_cast<char>('X' + axis);
    f.axis = axis;
    fields.push_back(std::move(f));
  }
  const uint16_t full = points.color_full_scale == 65535 ? 65535 : 255;
  if (points.hasColors()) {
    const char* names[3] = {"colorRed", "colorGreen", "colorBlue"};
    for (int k = 0; k < 3; ++k) {
      OutField f;
      f.kind = OutField::Kind::kInteger;
      f.name = names[k];
      f.maximum = full;
      f.source = OutField::Source::kColor;
      f.axis = k;
      fields.push_back(std::move(f));
    }
  }
  bool las_namespace = false, normals_namespace = false;
  std::vector<std::string> taken;
  for (const OutField& f : fields) taken.push_back(f.name);
  // First the dimensions that are E57 fields of their own (intensity, returns, normals, LAS's),
  // then the others under XML names that are none of those and no standard field of another
  // meaning (a float returnIndex or a cartesianInvalidState of a CSV would be read as E57's).
  std::vector<std::string> names(points.dimensions.count());
  std::vector<int64_t> adds(points.dimensions.count(), 0);
  for (size_t k = 0; k < names.size(); ++k) {
    const Dimension& d = points.dimensions.all()[k];
    const KnownDimension* known = findKnownDimension(d.name);
    const bool integer = !dimTypeIsFloat(d.type);
    if (d.name == dim::kIntensity) {
      names[k] = "intensity";
    } else if (d.name == dim::kReturnNumber && integer && leastOf(d, threads) >= 1) {  // 0-based in E57
      names[k] = "returnIndex";
      adds[k] = -1;
    } else if (d.name == dim::kNumberOfReturns && integer) {
      names[k] = "returnCount";
    } else if (d.name == dim::kNormalX || d.name == dim::kNormalY || d.name == dim::kNormalZ) {
      names[k] = std::string("nor:normal") + static_cast<char>('X' + (d.name.back() - 'x'));
      normals_namespace = true;
    } else if (known && known->las_field && d.name != dim::kReturnNumber) {
      names[k] = "las:" + camelCase(d.name);
      las_namespace = true;
    } else if ((isStandardIndex(d.name) && integer) || (d.name == "timeStamp")) {
      names[k] = d.name;  // an E57 reading's own rowIndex, columnIndex, timeStamp, is…Invalid
    } else {
      continue;
    }
    taken.push_back(names[k]);
  }
  for (size_t k = 0; k < names.size(); ++k) {
    if (!names[k].empty()) continue;
    const Dimension& d = points.dimensions.all()[k];
    std::string name = d.name;  // an XML name: letters, digits, _ - . and UTF-8, not a digit first
    for (char& c : name)
      if (!isNameChar(c)) c = '_';
    if (name.empty() || !((name[0] >= 'a' && name[0] <= 'z') || (name[0] >= 'A' && name[0] <= 'Z') || name[0] == '_' ||
                          (static_cast<unsigned char>(name[0]) & 0x80)))
      name = "_" + name;
    const std::string base = name;
    for (int n2 = 2; isStandardField(name) || std::find(taken.begin(), taken.end(), name) != taken.end(); ++n2)
      name = base + "_" + std::to_string(n2);
    if (name != d.name)
      notes.push_back("dimension " + quotedExcerpt(d.name) + " written as " + quotedExcerpt(name) +
                      " (an E57 field's name is an XML name, none taken or a standard field's of another meaning)");
    names[k] = name;
    taken.push_back(name);
  }
  for (size_t k = 0; k < names.size(); ++k) {
    const Dimension& d = points.dimensions.all()[k];
    OutField f;
    f.name = names[k];
    const int64_t add = adds[k];
    const Dimension* dp = &d;
    f.source = OutField::Source::kDimension;
    f.dimension = dp;
    f.add = add;
    if (d.type == DimType::kF32 || d.type == DimType::kF64) {
      f.kind = d.type == DimType::kF32 ? OutField::Kind::kFloat32 : OutField::Kind::kFloat64;
      f.bits = d.type == DimType::kF32 ? 32 : 64;
    } else {
      f.kind = OutField::Kind::kInteger;
      if (d.type == DimType::kU64)
        for (size_t i = 0; i < n; ++i)
          if (dp->get<uint64_t>(i) > static_cast<uint64_t>(INT64_MAX))
            return Error{path + ": point " + std::to_string(i) + ": " + d.name + " = " + std::to_string(dp->get<uint64_t>(i)) +
                         " is past an E57 integer's 2^63 - 1"};
    }
    fields.push_back(std::move(f));
  }

  // An Integer's limits are its values' own, so that it packs in as few bits as they need.
  for (OutField& f : fields) {
    if (f.kind != OutField::Kind::kInteger) continue;
    constexpr size_t kBlock = 1u << 16;
    const size_t blocks = (n + kBlock - 1) / kBlock;
    std::vector<int64_t> lo(blocks, INT64_MAX), hi(blocks, INT64_MIN);
    parallelFor(blocks, threads, [&](size_t b, unsigned) {
      int64_t least = INT64_MAX, most = INT64_MIN;
      eachInteger(f, points, full, b * kBlock, std::min(n, (b + 1) * kBlock), [&](size_t, int64_t v) {
        least = std::min(least, v);
        most = std::max(most, v);
      });
      lo[b] = least;
      hi[b] = most;
    });
    f.minimum = n == 0 ? 0 : *std::min_element(lo.begin(), lo.end());
    f.maximum = n == 0 ? 0 : *std::max_element(hi.begin(), hi.end());
    if (f.source == OutField::Source::kColor) {  // colours keep their scale's limits, as readers take them for it
      f.minimum = 0;
      f.maximum = full;
    }
    f.bits = static_cast<unsigned>(std::bit_width(static_cast<uint64_t>(f.maximum) - static_cast<uint64_t>(f.minimum)));
  }

  // Packets of whole 64-record groups: every field's chunk is whole 8-byte words. Where one group
  // of every field does not fit in a packet (more than about 120 double fields), each group is
  // split over several packets by fields: a packet holds the group's chunks of some fields and
  // none of the others, so that a reader holds at most one group's bytes ahead of any field.
  uint64_t group_bytes = 0;  // one group's bytes of every field
  for (const OutField& f : fields) group_bytes += f.bits * 8;  // 64 records · bits / 8
  const uint64_t header_bytes = 6 + 2 * fields.size();
  if (header_bytes + 64 * 8 + 4 > kMostPacket)  // a packet's header lists every field's length
    return Error{path + ": " + std::to_string(fields.size()) + " fields, more than an E57 packet (64 KiB) can list; "
                 "leave some dimensions out (--drop)", ExitCode::kUsage};
  const uint64_t room = kMostPacket - header_bytes - 4;  // for the chunks
  std::vector<std::pair<size_t, size_t>> slices;  // each packet's fields [first, last), in a group split by fields
  if (header_bytes + group_bytes + 4 > kMostPacket) {
    uint64_t bytes = 0;
    for (size_t k = 0; k < fields.size(); ++k) {
      if (slices.empty() || bytes + fields[k].bits * 8 > room) slices.emplace_back(k, k), bytes = 0;
      slices.back().second = k + 1;
      bytes += fields[k].bits * 8;
    }
  } else {
    slices.emplace_back(0, fields.size());
  }
  const uint64_t groups_per_packet =
      slices.size() > 1 ? 1 : group_bytes == 0 ? UINT64_MAX : std::max<uint64_t>(1, room / group_bytes);
  const uint64_t records_per_packet = groups_per_packet == UINT64_MAX ? UINT64_MAX : groups_per_packet * 64;
  // The scans: one for each point_source_id whose points lie together (an E57 or PTX file of
  // several scans reads so), else one; each its own compressed vector, its packets numbered from 0.
  const std::vector<SourceRun> scans = pointSourceRuns(points);
  const auto packetsOf = [&](const SourceRun& scan) -> uint64_t {
    const uint64_t records = scan.end - scan.first;
    return records == 0 || group_bytes == 0 ? 0 : (records + records_per_packet - 1) / records_per_packet * slices.size();
  };
  // Packet p of a scan: records [begin, end) of fields [first, last).
  struct Packet {
    size_t begin, end, first, last;
  };
  const auto packetOf = [&](const SourceRun& scan, uint64_t p) {
    const uint64_t records = scan.first + p / slices.size() * records_per_packet;
    const auto& [first, last] = slices[static_cast<size_t>(p % slices.size())];
    return Packet{static_cast<size_t>(records),
                  static_cast<size_t>(std::min<uint64_t>(scan.end, records + records_per_packet)), first, last};
  };
  const auto packetBytes = [&](const Packet& packet, std::vector<uint64_t>* chunks) {
    uint64_t bytes = header_bytes;
    for (size_t k = 0; k < fields.size(); ++k) {
      const uint64_t records = k >= packet.first && k < packet.last ? packet.end - packet.begin : 0;
      const uint64_t chunk = (records * fields[k].bits + 63) / 64 * 8;
      if (chunks) chunks->push_back(chunk);
      bytes += chunk;
    }
    return (bytes + 3) / 4 * 4;
  };
  // A scan of no points (a set of none): one empty data packet, as libE57Format writes one (its
  // Simple API reads the data packet at the data offset).
  const std::string no_points("\x01\x00\x07\x00\x00\x00\x00\x00", 8);
  std::vector<uint64_t> sections, section_at;  // each scan's section: its bytes, its logical offset
  for (const SourceRun& scan : scans) {
    uint64_t section = kSectionHeaderBytes + (scan.end == scan.first ? no_points.size() : 0);
    for (uint64_t p = 0, count = packetsOf(scan); p < count; ++p) section += packetBytes(packetOf(scan, p), nullptr);
    section_at.push_back(sections.empty() ? kHeaderBytes : section_at.back() + sections.back());
    sections.push_back(section);
  }

  // The XML tree, from the bounds and the fields.
  // Each scan's bounds of its finite coordinates (--allow-nonfinite sets may have others).
  std::vector<Box> bounds;
  for (const SourceRun& scan : scans) bounds.push_back(finiteBox(points.positions, scan.first, scan.end, threads));
  // The intensity's range, by which readers (PDAL, CloudCompare) normalise it: LAS's 0..65535 for
  // integers that fit, 0..1 for floats of 0..1, else the values' own; a Float's also as its limits
  // (libE57Format's Simple API takes a Float intensity's range from them).
  for (OutField& f : fields) {
    if (f.name != "intensity") continue;
    if (f.kind == OutField::Kind::kInteger) {
      const bool las = f.minimum >= 0 && f.maximum <= 65535;
      f.least = las ? 0.0 : static_cast<double>(f.minimum);
      f.most = las ? 65535.0 : static_cast<double>(f.maximum);
      f.limited = true;
      continue;
    }
    f.least = HUGE_VAL;
    f.most = -HUGE_VAL;
    for (size_t i = 0; i < n; ++i) {
      const double v = f.dimension->value(i);
      if (!std::isfinite(v)) continue;
      f.least = std::min(f.least, v);
      f.most = std::max(f.most, v);
    }
    if (f.least >= 0.0 && f.most <= 1.0) f.least = 0.0, f.most = 1.0;
    f.limited = f.least <= f.most;  // some finite value
  }
  // Said where the values are neither LAS's 0..65535 integers nor 0..1: readers take an intensity
  // relative to its limits, and dpoint's reads it back as 0..1 (a review found 10.5, 20, 30 come
  // back as 0, 0.49, 1 without a word).
  for (const OutField& f : fields)
    if (f.name == "intensity" && f.limited && !(f.least == 0.0 && (f.most == 1.0 || f.most == 65535.0)))
      notes.push_back("intensity of " + formatNumber(f.least) + ".." + formatNumber(f.most) +
                      " written with that range as its limits: E57 readers take an intensity relative to its limits "
                      "(dpoint reads it back as 0..1 values)");
  std::string prototype;
  for (const OutField& f : fields) {
    prototype += "          <" + f.name;
    if (f.kind == OutField::Kind::kInteger)
      prototype += " type=\"Integer\" minimum=\"" + std::to_string(f.minimum) + "\" maximum=\"" + std::to_string(f.maximum) + "\"/>\n";
    else
      prototype += std::string(" type=\"Float\" precision=\"") + (f.kind == OutField::Kind::kFloat32 ? "single" : "double") +
                   (f.limited ? "\" minimum=\"" + formatNumber(f.least) + "\" maximum=\"" + formatNumber(f.most) : std::string()) +
                   "\"/>\n";
  }
  std::string xml = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<e57Root type=\"Structure\" "
                    "xmlns=\"http://www.astm.org/COMMIT/E57/2010-e57-v1.0\"";
  if (las_namespace) xml += " xmlns:las=\"http://www.astm.org/COMMIT/E57/2010-las-v1.0\"";
  if (normals_namespace) xml += " xmlns:nor=\"http://www.libe57.org/E57_EXT_surface_normals.txt\"";
  xml += ">\n  <formatName type=\"String\"><![CDATA[ASTM E57 3D Imaging Data File]]></formatName>\n";
  xml += "  <guid type=\"String\"><![CDATA[" + std::string(kFileGuidMarker) + "]]></guid>\n";
  xml += "  <versionMajor type=\"Integer\">1</versionMajor>\n  <versionMinor type=\"Integer\">0</versionMinor>\n";
  xml += "  <e57LibraryVersion type=\"String\"><![CDATA[dpoint]]></e57LibraryVersion>\n";
  xml += "  <coordinateMetadata type=\"String\"><![CDATA[" + coordinateMetadata(points, options, notes) +
         "]]></coordinateMetadata>\n";
  xml += "  <data3D type=\"Vector\" allowHeterogeneousChildren=\"1\">\n";
  for (size_t s = 0; s < scans.size(); ++s) {
    xml += "    <vectorChild type=\"Structure\">\n";
    xml += "      <guid type=\"String\"><![CDATA[" + std::string(kScanGuidMarker) + "]]></guid>\n";
    const Box& box = bounds[s];
    if (box.min.x <= box.max.x && box.min.y <= box.max.y && box.min.z <= box.max.z) {
      xml += "      <cartesianBounds type=\"Structure\">\n";
      const char* axes[3] = {"x", "y", "z"};
      for (int k = 0; k < 3; ++k) {
        xml += std::string("        <") + axes[k] + "Minimum type=\"Float\">" + formatNumber(box.min[k]) + "</" + axes[k] + "Minimum>\n";
        xml += std::string("        <") + axes[k] + "Maximum type=\"Float\">" + formatNumber(box.max[k]) + "</" + axes[k] + "Maximum>\n";
      }
      xml += "      </cartesianBounds>\n";
    }
    for (const OutField& f : fields)
      if (f.name == "intensity" && f.limited) {
        const char* type = f.kind == OutField::Kind::kInteger ? "Integer" : "Float";
        xml += std::string("      <intensityLimits type=\"Structure\">\n        <intensityMinimum type=\"") + type + "\">" +
               formatNumber(f.least) + "</intensityMinimum>\n        <intensityMaximum type=\"" + type + "\">" +
               formatNumber(f.most) + "</intensityMaximum>\n      </intensityLimits>\n";
      }
    if (points.hasColors()) {
      xml += "      <colorLimits type=\"Structure\">\n";
      for (const char* c : {"Red", "Green", "Blue"}) {
        xml += std::string("        <color") + c + "Minimum type=\"Integer\">0</color" + c + "Minimum>\n";
        xml += std::string("        <color") + c + "Maximum type=\"Integer\">" + std::to_string(full) + "</color" + c + "Maximum>\n";
      }
      xml += "      </colorLimits>\n";
    }
    xml += "      <points type=\"CompressedVector\" fileOffset=\"" + std::to_string(physicalOf(section_at[s])) +
           "\" recordCount=\"" + std::to_string(scans[s].end - scans[s].first) +
           "\">\n        <prototype type=\"Structure\">\n" + prototype +
           "        </prototype>\n        <codecs type=\"Vector\" allowHeterogeneousChildren=\"1\">\n        </codecs>\n"
           "      </points>\n    </vectorChild>\n";
  }
  xml += "  </data3D>\n  <images2D type=\"Vector\" allowHeterogeneousChildren=\"1\">\n  </images2D>\n</e57Root>\n";

  // The header: the file's length, the XML's place and length.
  const uint64_t xml_logical = section_at.back() + sections.back();
  const uint64_t logical_end = xml_logical + xml.size();
  const uint64_t file_length = (logical_end + kLogicalPage - 1) / kLogicalPage * kPage;
  std::string header(kHeaderBytes, '\0');
  std::memcpy(header.data(), "ASTM-E57", 8);
  storeUnaligned<uint32_t>(header.data() + 8, 1);
  storeUnaligned<uint32_t>(header.data() + 12, 0);
  storeUnaligned<uint64_t>(header.data() + 16, file_length);
  storeUnaligned<uint64_t>(header.data() + 24, physicalOf(xml_logical));
  storeUnaligned<uint64_t>(header.data() + 32, xml.size());
  storeUnaligned<uint64_t>(header.data() + 40, kPage);
  Result<AtomicFile> out = AtomicFile::create(path);
  if (!out) return out.error();
  if (Status s = out->checkSpace(file_length); !s) return s;
  PagedWriter writer(*out);
  if (Status s = writer.append(header); !s) return s;
  Progress* progress = options.progress;
  if (progress) progress->start("writing " + path, n);
  std::vector<std::string> batch;
  for (size_t s = 0; s < scans.size(); ++s) {
    const SourceRun& scan = scans[s];
    // The section's header: its length, its data's place.
    std::string section_header(kSectionHeaderBytes, '\0');
    section_header[0] = 1;
    storeUnaligned<uint64_t>(section_header.data() + 8, sections[s]);
    storeUnaligned<uint64_t>(section_header.data() + 16, physicalOf(section_at[s] + kSectionHeaderBytes));
    if (Status status = writer.append(section_header); !status) return status;
    const uint64_t packets = packetsOf(scan);
    for (uint64_t first = 0; first < packets; first += kPacketsPerBatch) {
      const size_t count = static_cast<size_t>(std::min<uint64_t>(kPacketsPerBatch, packets - first));
      batch.resize(count);
      parallelFor(count, threads, [&](size_t b, unsigned) {
        std::vector<uint64_t> chunks;
        const Packet packet_of = packetOf(scan, first + b);
        std::string& packet = batch[b];
        packet.assign(static_cast<size_t>(packetBytes(packet_of, &chunks)), '\0');
        packet[0] = 1;
        storeUnaligned<uint16_t>(packet.data() + 2, static_cast<uint16_t>(packet.size() - 1));
        storeUnaligned<uint16_t>(packet.data() + 4, static_cast<uint16_t>(fields.size()));
        size_t at = static_cast<size_t>(header_bytes);
        const auto [begin, end, first_field, last_field] = packet_of;
        for (size_t k = 0; k < fields.size(); ++k) {
          storeUnaligned<uint16_t>(packet.data() + 6 + 2 * k, static_cast<uint16_t>(chunks[k]));
          if (k < first_field || k >= last_field) continue;  // none of this field here
          const OutField& f = fields[k];
          uint8_t* bytes = reinterpret_cast<uint8_t*>(packet.data()) + at;
          if (f.source == OutField::Source::kPosition) {
            for (size_t i = begin; i < end; ++i) std::memcpy(bytes + (i - begin) * 8, &points.positions[i][f.axis], 8);
          } else if (f.kind != OutField::Kind::kInteger) {  // a float dimension: its bytes as they are
            const size_t width = f.kind == OutField::Kind::kFloat64 ? 8 : 4;
            std::memcpy(bytes, f.dimension->bytes.data() + begin * width, (end - begin) * width);
          } else if (f.bits > 0) {  // least significant bit first, the value less the minimum
            uint64_t word = 0;
            unsigned filled = 0;
            size_t out_byte = 0;
            const unsigned bits = f.bits;
            const uint64_t minimum = static_cast<uint64_t>(f.minimum);
            eachInteger(f, points, full, begin, end, [&](size_t, int64_t v) {
              const uint64_t raw = static_cast<uint64_t>(v) - minimum;
              word |= raw << filled;
              if (filled + bits >= 64) {
                std::memcpy(bytes + out_byte, &word, 8);
                out_byte += 8;
                const unsigned used = 64 - filled;
                word = used == 64 ? 0 : raw >> used;
                filled = filled + bits - 64;
              } else {
                filled += bits;
              }
            });
            if (filled > 0) std::memcpy(bytes + out_byte, &word, std::min<size_t>(8, chunks[k] - out_byte));
          }
          at += static_cast<size_t>(chunks[k]);
        }
      });
      for (size_t b = 0; b < count; ++b) {
        if (Status status = writer.append(batch[b]); !status) return status;
        if (const Packet packet = packetOf(scan, first + b); progress && packet.last == fields.size())
          progress->advance(packet.end - packet.begin);
      }
    }
    if (scan.end == scan.first)
      if (Status status = writer.append(no_points); !status) return status;
  }
  if (progress) progress->finish();
  // The GUIDs, from what is written: the pages' checksums so far and the bytes of the last.
  const auto [guid_hi, guid_lo] = writer.digest(prototype, n);
  const std::string file_guid = uuidText(guid_hi, guid_lo);
  xml.replace(xml.find(kFileGuidMarker), file_guid.size(), file_guid);
  size_t at = 0;
  for (size_t s = 0; s < scans.size(); ++s) {  // each scan's its own: s in the 62 bits uuidText keeps whole
    const std::string scan_guid = uuidText(guid_lo, guid_hi + s);
    at = xml.find(kScanGuidMarker, at);
    xml.replace(at, scan_guid.size(), scan_guid);
  }
  if (Status s = writer.append(xml); !s) return s;
  if (Status s = writer.finish(); !s) return s;
  if (Status s = out->commit(); !s) return s;
  if (options.notices) {
    for (const std::string& note : notes) options.notices->push_back(path + ": " + note);
    if (points.isMesh()) options.notices->push_back(path + ": triangles not written (an E57 file holds points)");
  }
  return okStatus();
}

}  // namespace dpoint
