// The E57 reader (converters/e57.h): the paged file, its XML tree (pugixml), and each scan's
// compressed vector, whose packets are walked once to gather every field's bytes, then decoded on
// all cores (a field's values are at fixed bit offsets, so any record is found without the others).
#include "converters/e57.h"

#include <fast_float/fast_float.h>
#include <pugixml.hpp>

#include <algorithm>
#include <atomic>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <optional>
#include <tuple>
#include <type_traits>

#include "converters/point_inputs.h"
#include "core/bytes.h"
#include "core/dimensions.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "core/text.h"

namespace dpoint {

namespace {

// CRC-32C, reflected, by eight bytes at a time (slicing-by-8 tables).
struct Crc32cTables {
  uint32_t t[8][256];
  Crc32cTables() {
    for (uint32_t i = 0; i < 256; ++i) {
      uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? (c >> 1) ^ 0x82F63B78u : c >> 1;
      t[0][i] = c;
    }
    for (uint32_t i = 0; i < 256; ++i)
      for (int k = 1; k < 8; ++k) t[k][i] = (t[k - 1][i] >> 8) ^ t[0][t[k - 1][i] & 0xFF];
  }
};

#if defined(__x86_64__)
__attribute__((target("sse4.2"))) uint32_t crc32cSse42(const uint8_t* data, size_t size) {
  uint64_t crc = 0xFFFFFFFFu;
  for (; size >= 8; data += 8, size -= 8) {
    uint64_t word;
    std::memcpy(&word, data, 8);
    crc = __builtin_ia32_crc32di(crc, word);
  }
  uint32_t c = static_cast<uint32_t>(crc);
  for (; size > 0; ++data, --size) c = __builtin_ia32_crc32qi(c, *data);
  return c ^ 0xFFFFFFFFu;
}
#endif

}  // namespace

uint32_t crc32c(const uint8_t* data, size_t size) {
#if defined(__x86_64__)
  static const bool sse42 = __builtin_cpu_supports("sse4.2");
  if (sse42) return crc32cSse42(data, size);
#endif
  static const Crc32cTables tables;
  const auto& t = tables.t;
  uint32_t c = 0xFFFFFFFFu;
  for (; size >= 8; data += 8, size -= 8) {
    uint32_t lo;
    uint32_t hi;
    std::memcpy(&lo, data, 4);
    std::memcpy(&hi, data + 4, 4);
    lo ^= c;
    c = t[7][lo & 0xFF] ^ t[6][(lo >> 8) & 0xFF] ^ t[5][(lo >> 16) & 0xFF] ^ t[4][lo >> 24] ^ t[3][hi & 0xFF] ^
        t[2][(hi >> 8) & 0xFF] ^ t[1][(hi >> 16) & 0xFF] ^ t[0][hi >> 24];
  }
  for (; size > 0; ++data, --size) c = (c >> 8) ^ t[0][(c ^ *data) & 0xFF];
  return c ^ 0xFFFFFFFFu;
}

namespace {

constexpr uint64_t kFileHeaderBytes = 48;
constexpr uint64_t kSectionHeaderBytes = 32;
constexpr size_t kPagesPerRead = 1024;      // pages read and checked at a time by a worker
constexpr uint64_t kPacketWindow = 32u << 20;  // logical bytes of packets read at a time (E57ReadOptions::packet_window)
constexpr uint64_t kLeastWindow = 64u << 10;   // a packet's most
constexpr size_t kDecodeBlock = 1u << 16;   // records decoded at a time by a worker
constexpr uint64_t kMostConstantRecords = uint64_t{1} << 26;  // records of a scan whose fields take no bits
constexpr size_t kStreamPadding = 16;       // zero bytes after a field's bytes: a value read as 9 bytes

// The file as E57 lays it out: pages of page_ bytes, the last 4 a checksum of the others.
class PagedFile {
 public:
  static Result<PagedFile> open(const InputFile& file) {
    PagedFile paged(file);
    const std::string& path = file.path();
    uint8_t header[kFileHeaderBytes] = {};
    Result<size_t> got = file.readAt(0, header, sizeof header);
    if (!got) return got.error();
    if (*got < 8 || std::memcmp(header, "ASTM-E57", 8) != 0)
      return Error{path + ": not an E57 file (it does not begin with ASTM-E57)"};
    if (*got < kFileHeaderBytes) return Error{path + ": an E57 file cut short within its 48-byte header"};
    const uint32_t major = loadUnaligned<uint32_t>(header + 8);
    const uint64_t length = loadUnaligned<uint64_t>(header + 16);
    paged.xml_offset_ = loadUnaligned<uint64_t>(header + 24);
    paged.xml_length_ = loadUnaligned<uint64_t>(header + 32);
    paged.page_ = loadUnaligned<uint64_t>(header + 40);
    if (major != 1)
      return Error{path + ": E57 version " + std::to_string(major) + "." + std::to_string(loadUnaligned<uint32_t>(header + 12)) +
                   " (version 1 is read)"};
    if (paged.page_ < 64 || paged.page_ > (1u << 20) || (paged.page_ & (paged.page_ - 1)) != 0)
      return Error{path + ": E57 page size " + std::to_string(paged.page_) + " (a power of two from 64 to 1 MiB, 1024 as written)"};
    if (length > file.size())
      return Error{path + ": cut short: its header says " + std::to_string(length) + " bytes, the file has " +
                   std::to_string(file.size())};
    if (length % paged.page_ != 0)
      return Error{path + ": its length " + std::to_string(length) + " is not whole pages of " + std::to_string(paged.page_) +
                   " bytes"};
    paged.length_ = length;
    // The header's page first: a damaged page is named before what its bytes say is trusted.
    std::vector<uint8_t> first(static_cast<size_t>(paged.logicalPage()));
    if (length < paged.page_) return Error{path + ": cut short within its first page"};
    if (Status s = paged.read(0, first.data(), first.size(), 1, nullptr); !s) return s.error();
    if (paged.xml_length_ == 0) return Error{path + ": its XML section is empty"};
    if (paged.xml_offset_ >= length || paged.xml_length_ > paged.logicalLength() - paged.logicalOf(paged.xml_offset_))
      return Error{path + ": its XML section (at byte " + std::to_string(paged.xml_offset_) + ", " +
                   std::to_string(paged.xml_length_) + " bytes) lies past the end of the file"};
    return paged;
  }

  uint64_t page() const { return page_; }
  uint64_t logicalPage() const { return page_ - 4; }
  uint64_t physicalLength() const { return length_; }
  uint64_t logicalLength() const { return length_ / page_ * logicalPage(); }
  uint64_t logicalOf(uint64_t physical) const {
    return physical / page_ * logicalPage() + std::min(physical % page_, logicalPage());
  }
  uint64_t xmlOffset() const { return xml_offset_; }
  uint64_t xmlLength() const { return xml_length_; }
  const std::string& path() const { return file_->path(); }

  // Logical bytes [logical, logical + size) into out, every page they touch checked against its
  // checksum; on `threads` cores, `progress` advanced by the bytes read.
  Status read(uint64_t logical, uint8_t* out, uint64_t size, unsigned threads, Progress* progress) const {
    if (size == 0) return okStatus();
    if (logical > logicalLength() || size > logicalLength() - logical)
      return Error{path() + ": a section runs past the end of the file (logical bytes " + std::to_string(logical) + " to " +
                   std::to_string(logical + size) + " of " + std::to_string(logicalLength()) + "): cut short or damaged"};
    const uint64_t lp = logicalPage();
    const uint64_t first = logical / lp, last = (logical + size - 1) / lp;
    const size_t groups = static_cast<size_t>((last - first) / kPagesPerRead + 1);
    std::vector<std::optional<Error>> errors(groups);
    std::vector<std::vector<uint8_t>> buffers(parallelWorkers(groups, threads));
    parallelFor(groups, threads, [&](size_t g, unsigned worker) {
      const uint64_t p0 = first + uint64_t{g} * kPagesPerRead;
      const uint64_t p1 = std::min(last + 1, p0 + kPagesPerRead);
      std::vector<uint8_t>& buffer = buffers[worker];
      buffer.resize(static_cast<size_t>((p1 - p0) * page_));
      Result<size_t> got = file_->readAt(p0 * page_, buffer.data(), buffer.size());
      if (!got || *got != buffer.size()) {
        errors[g] = got ? Error{path() + ": the file changed while it was read (shorter than its size)"} : got.error();
        return;
      }
      for (uint64_t p = p0; p < p1; ++p) {
        const uint8_t* bytes = buffer.data() + (p - p0) * page_;
        const uint32_t stored = __builtin_bswap32(loadUnaligned<uint32_t>(bytes + lp));
        if (crc32c(bytes, static_cast<size_t>(lp)) != stored) {
          errors[g] = Error{path() + ": page " + std::to_string(p) + " (bytes " + std::to_string(p * page_) + " to " +
                            std::to_string((p + 1) * page_ - 1) + ") fails its CRC-32C checksum: the file is damaged"};
          return;
        }
        // This page's part of [logical, logical + size).
        const uint64_t begin = std::max(logical, p * lp), end = std::min(logical + size, (p + 1) * lp);
        std::memcpy(out + (begin - logical), bytes + (begin - p * lp), static_cast<size_t>(end - begin));
      }
      if (progress) progress->advance((p1 - p0) * lp);
    });
    for (std::optional<Error>& e : errors)
      if (e) return std::move(*e);
    return okStatus();
  }

 private:
  explicit PagedFile(const InputFile& file) : file_(&file) {}
  const InputFile* file_;
  uint64_t page_ = 1024, length_ = 0, xml_offset_ = 0, xml_length_ = 0;
};

bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

// A number of the XML tree: a Float's or an Integer's text (empty: 0), or an attribute; blanks
// about it passed over, a leading '+' taken as the text readers take it (afterPlusSign).
template <typename T>
std::optional<T> parseNumber(std::string_view text) {
  while (!text.empty() && isBlank(text.front())) text.remove_prefix(1);
  while (!text.empty() && isBlank(text.back())) text.remove_suffix(1);
  if (text.empty()) return T{0};
  const char* begin = afterPlusSign(text.data(), text.data() + text.size());
  const char* end = text.data() + text.size();
  T v{};
  if constexpr (std::is_floating_point_v<T>) {
    const auto r = fast_float::from_chars(begin, end, v);
    if (r.ec != std::errc() || r.ptr != end) return std::nullopt;
  } else {
    const auto r = std::from_chars(begin, end, v);
    if (r.ec != std::errc() || r.ptr != end) return std::nullopt;
  }
  return v;
}

// The element `name` of a Structure, as a number (its type Float, Integer or ScaledInteger);
// `fallback` when it is missing.
Result<double> numberOf(const pugi::xml_node& parent, const char* name, double fallback, const std::string& where) {
  const pugi::xml_node node = parent.child(name);
  if (!node) return fallback;
  const std::string type = node.attribute("type").value();
  const std::optional<double> v = parseNumber<double>(node.text().get());
  if (!v || (type != "Float" && type != "Integer" && type != "ScaledInteger"))
    return Error{where + "/" + name + ": " + quotedExcerpt(node.text().get()) + " of type " + quotedExcerpt(type) +
                 " is not a number"};
  if (type == "ScaledInteger") {
    const std::optional<double> scale = parseNumber<double>(node.attribute("scale").value());
    const std::optional<double> offset = parseNumber<double>(node.attribute("offset").value());
    if (!scale || !offset) return Error{where + "/" + name + ": a scale or offset that is not a number"};
    return *v * (node.attribute("scale") ? *scale : 1.0) + *offset;
  }
  return *v;
}

// A field of a prototype: how its values are packed.
enum class FieldKind { kFloat32, kFloat64, kInteger, kScaled };

struct Field {
  std::string name;
  FieldKind kind = FieldKind::kFloat64;
  int64_t minimum = INT64_MIN, maximum = INT64_MAX;
  double scale = 1.0, offset = 0.0;
  double float_minimum = -HUGE_VAL, float_maximum = HUGE_VAL;  // a Float's limits, where given
  unsigned bits = 64;                                           // per value
  // The packed values' bytes [first_byte, filled) of the field's stream, then at least
  // kStreamPadding bytes (PacketReader's rolling buffer).
  DimensionBytes bytes;
  uint64_t first_byte = 0, filled = 0;

  uint64_t neededBytes(uint64_t records) const { return (records * bits + 7) / 8; }
  const uint8_t* at(uint64_t byte) const { return bytes.data() + (byte - first_byte); }
  // Value i's packed bits (its bytes held).
  uint64_t raw(size_t i) const {
    const uint64_t bit = uint64_t{i} * bits;
    const uint8_t* p = at(bit / 8);
    const unsigned shift = static_cast<unsigned>(bit % 8);
    uint64_t v = loadUnaligned<uint64_t>(p) >> shift;
    if (shift != 0 && shift + bits > 64) v |= uint64_t{p[8]} << (64 - shift);
    return bits == 64 ? v : v & ((uint64_t{1} << bits) - 1);
  }
  // An integer field's value i (the packed bits count up from the minimum).
  int64_t integer(size_t i) const {
    return bits == 0 ? minimum : static_cast<int64_t>(static_cast<uint64_t>(minimum) + raw(i));
  }
  double value(size_t i) const {
    switch (kind) {
      case FieldKind::kFloat32: return static_cast<double>(loadUnaligned<float>(at(uint64_t{i} * 4)));
      case FieldKind::kFloat64: return loadUnaligned<double>(at(uint64_t{i} * 8));
      case FieldKind::kInteger: return static_cast<double>(integer(i));
      case FieldKind::kScaled: return static_cast<double>(integer(i)) * scale + offset;
    }
    return 0.0;
  }
};

// A prototype's field from its element.
Result<Field> fieldOf(const pugi::xml_node& node, const std::string& where) {
  Field f;
  f.name = node.name();
  const std::string type = node.attribute("type").value();
  const std::string at = where + "/" + f.name;
  // An attribute as a number of type T, `fallback` where it is missing.
  const auto attribute = [&]<typename T>(const char* name, T fallback) -> Result<T> {
    const pugi::xml_attribute a = node.attribute(name);
    if (!a) return fallback;
    const std::optional<T> v = parseNumber<T>(a.value());
    if (!v)
      return Error{at + ": " + name + " " + quotedExcerpt(a.value()) +
                   (std::is_floating_point_v<T> ? " is not a number" : " is not a 64-bit integer")};
    return *v;
  };
  if (type == "Float") {
    const std::string precision = node.attribute("precision").value();
    if (precision == "single") {
      f.kind = FieldKind::kFloat32;
      f.bits = 32;
    } else if (precision.empty() || precision == "double") {
      f.kind = FieldKind::kFloat64;
      f.bits = 64;
    } else {
      return Error{at + ": precision " + quotedExcerpt(precision) + " (single or double)"};
    }
    Result<double> lo = attribute("minimum", -HUGE_VAL);
    if (!lo) return lo.error();
    Result<double> hi = attribute("maximum", HUGE_VAL);
    if (!hi) return hi.error();
    f.float_minimum = *lo;
    f.float_maximum = *hi;
    return f;
  }
  if (type != "Integer" && type != "ScaledInteger")
    return Error{at + ": a field of type " + quotedExcerpt(type) +
                 (type == "Structure" || type == "Vector" ? " (nested fields are not read)" : "") +
                 " (a point's fields are Float, Integer or ScaledInteger)"};
  f.kind = type == "Integer" ? FieldKind::kInteger : FieldKind::kScaled;
  Result<int64_t> lo = attribute("minimum", int64_t{INT64_MIN});
  if (!lo) return lo.error();
  Result<int64_t> hi = attribute("maximum", int64_t{INT64_MAX});
  if (!hi) return hi.error();
  if (*hi < *lo) return Error{at + ": maximum " + std::to_string(*hi) + " is below minimum " + std::to_string(*lo)};
  f.minimum = *lo;
  f.maximum = *hi;
  const uint64_t range = static_cast<uint64_t>(*hi) - static_cast<uint64_t>(*lo);
  f.bits = static_cast<unsigned>(std::bit_width(range));
  if (f.kind == FieldKind::kScaled) {
    Result<double> scale = attribute("scale", 1.0);
    if (!scale) return scale.error();
    Result<double> offset = attribute("offset", 0.0);
    if (!offset) return offset.error();
    if (!(*scale != 0.0) || !std::isfinite(*scale) || !std::isfinite(*offset))
      return Error{at + ": scale " + formatNumber(*scale) + " and offset " + formatNumber(*offset) +
                   " (a finite, non-zero scale)"};
    f.scale = *scale;
    f.offset = *offset;
  }
  return f;
}

// The smallest dimension type that holds an integer field's limits.
DimType integerType(int64_t lo, int64_t hi) {
  if (lo >= 0) {
    const uint64_t h = static_cast<uint64_t>(hi);
    return h <= UINT8_MAX ? DimType::kU8 : h <= UINT16_MAX ? DimType::kU16 : h <= UINT32_MAX ? DimType::kU32 : DimType::kU64;
  }
  if (lo >= INT8_MIN && hi <= INT8_MAX) return DimType::kI8;
  if (lo >= INT16_MIN && hi <= INT16_MAX) return DimType::kI16;
  if (lo >= INT32_MIN && hi <= INT32_MAX) return DimType::kI32;
  return DimType::kI64;
}

// The dimension a field is kept as: its name and type.
std::pair<std::string, DimType> dimensionOf(const Field& f) {
  std::string name = f.name;
  if (name == "returnIndex" && f.kind == FieldKind::kInteger) name = dim::kReturnNumber;  // 0-based in E57, 1-based in LAS
  if (name == "returnCount" && f.kind == FieldKind::kInteger) name = dim::kNumberOfReturns;
  if (name == "nor:normalX" || name == "nor:normalY" || name == "nor:normalZ") {  // the normals extension's (CloudCompare's)
    name = std::string(1, 'n') + static_cast<char>('x' + (name.back() - 'X'));
  } else if (name.rfind("las:", 0) == 0) {  // the LAS extension's camelCase names as LAS's (pointSourceId → point_source_id)
    std::string snake;
    for (char c : name.substr(4)) {
      if (c >= 'A' && c <= 'Z') {
        snake += '_';
        snake += static_cast<char>(c - 'A' + 'a');
      } else {
        snake += c;
      }
    }
    name = snake;
  }
  switch (f.kind) {
    case FieldKind::kFloat32: return {name, DimType::kF32};
    case FieldKind::kFloat64:
    case FieldKind::kScaled: return {name, DimType::kF64};
    case FieldKind::kInteger: break;
  }
  if (f.name == "returnIndex" && f.minimum >= 0 && f.maximum < INT64_MAX) return {name, integerType(f.minimum + 1, f.maximum + 1)};
  return {name, integerType(f.minimum, f.maximum)};
}

// A scan as the XML tree describes it.
struct ScanInfo {
  std::string label;  // "data3D 2 ('station 1')"
  uint64_t section = 0, records = 0;
  std::vector<Field> fields;
  double rotation[4] = {1.0, 0.0, 0.0, 0.0};  // w x y z
  double translation[3] = {0.0, 0.0, 0.0};
  std::optional<double> color_limits[6];  // red, green, blue minimum and maximum, where given
  std::optional<double> intensity_limits[2];  // intensityMinimum, intensityMaximum, where given
};

Result<ScanInfo> scanInfoOf(const pugi::xml_node& scan, size_t index, const std::string& path) {
  ScanInfo info;
  const pugi::xml_node name = scan.child("name");
  info.label = "data3D " + std::to_string(index + 1) +
               (name && *name.text().get() ? " (" + quotedExcerpt(name.text().get()) + ")" : std::string());
  const std::string where = path + ": " + info.label;
  const pugi::xml_node points = scan.child("points");
  if (!points || std::string(points.attribute("type").value()) != "CompressedVector")
    return Error{where + ": no points (a CompressedVector)"};
  const std::optional<int64_t> offset = parseNumber<int64_t>(points.attribute("fileOffset").value());
  const std::optional<int64_t> records = parseNumber<int64_t>(points.attribute("recordCount").value());
  if (!offset || *offset < 0 || !points.attribute("fileOffset"))
    return Error{where + ": points: fileOffset " + quotedExcerpt(points.attribute("fileOffset").value()) + " is not a byte offset"};
  if (!records || *records < 0)
    return Error{where + ": points: recordCount " + quotedExcerpt(points.attribute("recordCount").value()) + " is not a count"};
  info.section = static_cast<uint64_t>(*offset);
  info.records = static_cast<uint64_t>(*records);
  const pugi::xml_node prototype = points.child("prototype");
  if (!prototype) return Error{where + ": points: no prototype"};
  for (const pugi::xml_node& child : prototype.children()) {
    if (child.type() != pugi::node_element) continue;
    Result<Field> f = fieldOf(child, where + ": points");
    if (!f) return f.error();
    for (const Field& other : info.fields)
      if (other.name == f->name) return Error{where + ": points: the field " + f->name + " twice"};
    info.fields.push_back(std::move(*f));
  }
  if (info.fields.empty()) return Error{where + ": points: a prototype of no fields"};
  // Fields of no bits (each a constant) make every record the same point and take no bytes: a
  // file of 1 KB could declare 2^35 of them, hours of streaming (a review finding).
  const bool no_bits = std::all_of(info.fields.begin(), info.fields.end(), [](const Field& f) { return f.bits == 0; });
  if (no_bits && info.records > kMostConstantRecords)
    return Error{where + ": points: " + std::to_string(info.records) +
                 " records whose fields all take no bits (each the same point, in no bytes): more than " +
                 std::to_string(kMostConstantRecords) + " such records are taken for a damaged count"};
  for (const pugi::xml_node& codec : points.child("codecs").children())
    if (codec.type() == pugi::node_element)
      return Error{where + ": points: a codec other than bitpack (" + quotedExcerpt(codec.name()) + "), which E57 does not define"};
  if (const pugi::xml_node pose = scan.child("pose")) {
    const char* q[4] = {"w", "x", "y", "z"};
    const char* t[3] = {"x", "y", "z"};
    const pugi::xml_node rotation = pose.child("rotation"), translation = pose.child("translation");
    for (int k = 0; k < 4 && rotation; ++k) {
      Result<double> v = numberOf(rotation, q[k], k == 0 ? 1.0 : 0.0, where + ": pose/rotation");
      if (!v) return v.error();
      info.rotation[k] = *v;
    }
    for (int k = 0; k < 3 && translation; ++k) {
      Result<double> v = numberOf(translation, t[k], 0.0, where + ": pose/translation");
      if (!v) return v.error();
      info.translation[k] = *v;
    }
    const double norm = std::sqrt(info.rotation[0] * info.rotation[0] + info.rotation[1] * info.rotation[1] +
                                  info.rotation[2] * info.rotation[2] + info.rotation[3] * info.rotation[3]);
    if (!(norm > 0.0) || !std::isfinite(norm) || !std::isfinite(info.translation[0]) ||
        !std::isfinite(info.translation[1]) || !std::isfinite(info.translation[2]))
      return Error{where + ": pose: a rotation of no length or a value that is not finite"};
    for (double& c : info.rotation) c /= norm;  // a unit quaternion, as E57 says it is, to the last bit
  }
  if (const pugi::xml_node limits = scan.child("intensityLimits")) {
    const char* names[2] = {"intensityMinimum", "intensityMaximum"};
    for (int k = 0; k < 2; ++k) {
      if (!limits.child(names[k])) continue;
      Result<double> v = numberOf(limits, names[k], 0.0, where + ": intensityLimits");
      if (!v) return v.error();
      info.intensity_limits[k] = *v;
    }
  }
  if (const pugi::xml_node limits = scan.child("colorLimits")) {
    const char* names[6] = {"colorRedMinimum", "colorRedMaximum", "colorGreenMinimum",
                            "colorGreenMaximum", "colorBlueMinimum", "colorBlueMaximum"};
    for (int k = 0; k < 6; ++k) {
      if (!limits.child(names[k])) continue;
      Result<double> v = numberOf(limits, names[k], 0.0, where + ": colorLimits");
      if (!v) return v.error();
      info.color_limits[k] = *v;
    }
  }
  return info;
}

const Field* findField(const ScanInfo& scan, std::string_view name) {
  for (const Field& f : scan.fields)
    if (f.name == name) return &f;
  return nullptr;
}

// The packets of a scan's compressed vector, read a window at a time in order: each field's bytes
// appended to its rolling buffer (Field::bytes), from which the records every field holds whole
// are decoded, then dropped (drop). Memory is a window and what the fields hold past the records
// decoded: about one window where a writer spreads the fields evenly over its packets, as writers
// do; a file that gives one field's values long before another's holds more, up to `budget`.
// A stream (E57PointStream) walks the packets once keeping where each begins (checkpoints), then
// starts a read at the packet before its first record (seek), keeping only the fields it decodes.
class PacketReader {
 public:
  PacketReader(const PagedFile& file, ScanInfo& scan, uint64_t window, unsigned threads, Progress* progress, uint64_t budget)
      : file_(file), scan_(scan), window_bytes_(window), threads_(threads), progress_(progress), budget_(budget),
        where_(file.path() + ": " + scan.label + ": points") {}

  // The section's header, and its data's place.
  Status open() {
    if (scan_.section >= file_.physicalLength())
      return Error{where_ + ": its section at byte " + std::to_string(scan_.section) + " lies past the end of the file"};
    const uint64_t start = file_.logicalOf(scan_.section);
    uint8_t header[kSectionHeaderBytes];
    if (Status s = file_.read(start, header, sizeof header, 1, nullptr); !s) return s;
    if (header[0] != 1)
      return Error{where_ + ": the section at byte " + std::to_string(scan_.section) + " is not a compressed vector (id " +
                   std::to_string(header[0]) + ", not 1)"};
    const uint64_t length = loadUnaligned<uint64_t>(header + 8);
    const uint64_t data = loadUnaligned<uint64_t>(header + 16);
    if (length < kSectionHeaderBytes || length > file_.logicalLength() - start)
      return Error{where_ + ": its section's length " + std::to_string(length) + " runs past the end of the file"};
    end_ = start + length;
    at_ = file_.logicalOf(data);
    if (scan_.records == 0) return okStatus();
    if (at_ < start + kSectionHeaderBytes || at_ >= end_)
      return Error{where_ + ": its data (at byte " + std::to_string(data) + ") is not within its section"};
    uint64_t needed = 0;
    for (const Field& f : scan_.fields) needed += f.neededBytes(scan_.records);
    if (needed > end_ - at_)  // a count no section of this file holds, before anything is read
      return Error{where_ + ": " + std::to_string(scan_.records) + " records of its fields need " + std::to_string(needed) +
                   " bytes, but its section holds " + std::to_string(end_ - at_) + " (cut short or damaged)"};
    for (Field& f : scan_.fields) {
      f.first_byte = f.filled = 0;
      f.bytes.assign(kStreamPadding, uint8_t{0});
    }
    keep_.assign(scan_.fields.size(), 1);
    return okStatus();
  }

  // Only these fields' bytes are held (the others are counted, not copied): a stream's walk keeps
  // the invalid state alone, a read what it decodes.
  void keepOnly(const std::vector<const Field*>& fields) {
    for (size_t k = 0; k < scan_.fields.size(); ++k)
      keep_[k] = std::find(fields.begin(), fields.end(), &scan_.fields[k]) != fields.end();
  }
  // From now on a data packet's logical offset, then every field's bytes gathered before it, are
  // appended to `checkpoints` (1 + fields values), for the first packet and then for one at least
  // 256 KiB (and 32 times a checkpoint's own bytes) past the last: the index is a small share of
  // the file however small its packets (a review finding: 2M empty packets took 1 GB).
  void recordCheckpoints(std::vector<uint64_t>* checkpoints) {
    checkpoints_ = checkpoints;
    checkpoint_spacing_ = std::max<uint64_t>(256u << 10, 32 * 8 * (1 + scan_.fields.size()));
  }
  // Reading from a recorded checkpoint at or before record `record` (each field's bytes there no
  // more than the record's first byte): the packets from there, each field's bytes before the
  // record's passed over. open() first.
  void seek(const uint64_t* checkpoint, uint64_t record) {
    at_ = checkpoint[0];
    for (size_t k = 0; k < scan_.fields.size(); ++k) {
      Field& f = scan_.fields[k];
      f.filled = checkpoint[1 + k];
      f.first_byte = record * f.bits / 8;
    }
  }

  // The records every field holds whole (from the first): those that can be decoded.
  uint64_t ready() const {
    uint64_t ready = scan_.records;
    for (const Field& f : scan_.fields)
      if (f.bits != 0) ready = std::min(ready, f.filled * 8 / f.bits);
    return ready;
  }

  // Windows of packets gathered until ready() grows: an error where the section ends first (a
  // field cut short), a packet is malformed, or the fields would hold more than the budget. With
  // `records`, a window of about the bytes those records take (a stream's small read), at least
  // the least window (a packet's most) and at most the reader's.
  Status next(uint64_t records = UINT64_MAX) {
    const uint64_t before = ready();
    uint64_t want = window_bytes_;
    if (records != UINT64_MAX) {
      uint64_t bits = 0;
      for (const Field& f : scan_.fields) bits += f.bits;
      // Their bytes and a seventh more (packet headers, fields a little ahead of others).
      const uint64_t bytes = records > UINT64_MAX / 16 / std::max<uint64_t>(bits, 1) ? UINT64_MAX : records * bits / 7;
      want = std::clamp<uint64_t>(bytes, kLeastWindow, window_bytes_);
    }
    while (!done() && ready() == before && at_ < end_) {
      const uint64_t size = std::min(want, end_ - at_);
      window_.resize(static_cast<size_t>(size));
      if (Status s = file_.read(at_, window_.data(), size, threads_, nullptr); !s) return s;
      Result<uint64_t> used = gather(size);
      if (!used) return used.error();
      if (*used == 0) break;  // fewer than 4 bytes left: the check below names the field cut short
      at_ += *used;
    }
    if (!done() && ready() == before)
      for (const Field& f : scan_.fields)
        if (f.filled < f.neededBytes(scan_.records))
          return Error{where_ + ": the field " + f.name + " ends after " + std::to_string(f.filled * 8 / std::max(1u, f.bits)) +
                       " of its " + std::to_string(scan_.records) + " records (the file is cut short or damaged)"};
    for (Field& f : scan_.fields)  // the padding a value read as 9 bytes may touch
      std::fill_n(f.bytes.data() + held(f), kStreamPadding, uint8_t{0});
    return okStatus();
  }

  // Records before `records` are decoded: their bytes are dropped (a partly used byte is kept).
  void drop(uint64_t records) {
    for (Field& f : scan_.fields) {
      const uint64_t keep = records * f.bits / 8;  // the byte record `records` begins in
      if (keep <= f.first_byte) continue;
      const size_t shift = static_cast<size_t>(std::min(keep, f.filled) - std::min(f.first_byte, f.filled));
      std::memmove(f.bytes.data(), f.bytes.data() + shift, held(f) - shift);
      f.first_byte = keep;
    }
  }

  bool done() const {
    for (const Field& f : scan_.fields)
      if (f.filled < f.neededBytes(scan_.records)) return false;
    return true;
  }

 private:
  // The whole packets at the window's start gathered; the bytes they take (0: none is whole).
  Result<uint64_t> gather(uint64_t size) {
    const size_t streams = scan_.fields.size();
    uint64_t pos = 0, taken = 0;
    while (pos + 4 <= size && !done()) {
      const uint8_t* packet = window_.data() + pos;
      const uint64_t packet_length = uint64_t{loadUnaligned<uint16_t>(packet + 2)} + 1;
      const auto packet_at = [&] { return where_ + ": the packet at logical byte " + std::to_string(at_ + pos); };
      if (packet_length > end_ - (at_ + pos)) return Error{packet_at() + " runs past its section (cut short or damaged)"};
      if (pos + packet_length > size) break;  // the next window starts with it
      if (packet[0] == 0 || packet[0] == 2) {  // an index or empty packet
        pos += packet_length;
        continue;
      }
      if (packet[0] != 1) return Error{packet_at() + " is of type " + std::to_string(packet[0]) + " (0, 1 or 2)"};
      if (checkpoints_ && (checkpoints_->empty() || at_ + pos - checkpoints_->end()[-static_cast<ptrdiff_t>(
                                                                  1 + scan_.fields.size())] >= checkpoint_spacing_)) {
        checkpoints_->push_back(at_ + pos);
        for (const Field& f : scan_.fields) checkpoints_->push_back(f.filled);
      }
      if (packet_length < 6)
        return Error{packet_at() + " is a data packet of " + std::to_string(packet_length) +
                     " bytes, shorter than its 6-byte header"};
      const uint64_t count = loadUnaligned<uint16_t>(packet + 4);
      if (count != streams)
        return Error{packet_at() + " has " + countOf(count, "bytestream") + " for a prototype of " + countOf(streams, "field")};
      uint64_t offset = 6 + 2 * count;
      if (offset > packet_length)
        return Error{packet_at() + ": its " + countOf(count, "buffer length") + " overrun the packet (" +
                     std::to_string(packet_length) + " bytes)"};
      for (size_t k = 0; k < streams; ++k) {
        const uint64_t n = loadUnaligned<uint16_t>(packet + 6 + 2 * k);
        if (offset + n > packet_length)
          return Error{packet_at() + ": its buffers (" + std::to_string(offset + n) + " bytes) overrun the packet (" +
                       std::to_string(packet_length) + ")"};
        Field& f = scan_.fields[k];
        const uint64_t needed = f.neededBytes(scan_.records);
        const uint64_t take = std::min(n, needed - std::min(f.filled, needed));  // a last word may be padded past the values
        if (take > 0) {
          if (Status s = append(f, keep_[k] != 0, packet + offset, take); !s) return s.error();
          taken += take;
        }
        offset += n;
      }
      pos += packet_length;
    }
    if (progress_) progress_->advance(taken);
    return pos;
  }

  // The bytes a field holds: [first_byte, filled), none while a seek passes over bytes before them.
  static size_t held(const Field& f) { return static_cast<size_t>(f.filled > f.first_byte ? f.filled - f.first_byte : 0); }

  Status append(Field& f, bool keep, const uint8_t* bytes, uint64_t n) {
    if (f.filled < f.first_byte) {  // before a seek's record
      const uint64_t skip = std::min(n, f.first_byte - f.filled);
      f.filled += skip;
      bytes += skip;
      n -= skip;
    }
    if (!keep) {
      f.filled += n;
      f.first_byte = std::max(f.first_byte, f.filled);
      return okStatus();
    }
    if (n == 0) return okStatus();
    const uint64_t held = PacketReader::held(f);
    if (held + n + kStreamPadding > f.bytes.size()) {
      uint64_t all = 0;
      for (const Field& other : scan_.fields) all += other.bytes.size();
      const uint64_t others = all - f.bytes.size(), need = held + n + kStreamPadding;
      if (others + need > budget_)
        return Error{where_ + ": its fields' values are spread so unevenly over its packets that " +
                         std::to_string(others + need) + " bytes of them would be held at once, more than " +
                         "the memory limit leaves (--max-memory)",
                     ExitCode::kResourceLimit};
      const uint64_t grown = std::clamp<uint64_t>(2 * f.bytes.size(), need, budget_ - others);  // doubled, within the budget
      f.bytes.resize(static_cast<size_t>(grown));
    }
    std::memcpy(f.bytes.data() + held, bytes, static_cast<size_t>(n));
    f.filled += n;
    return okStatus();
  }

  const PagedFile& file_;
  ScanInfo& scan_;
  uint64_t window_bytes_;
  unsigned threads_;
  Progress* progress_;
  uint64_t budget_;
  std::string where_;
  uint64_t at_ = 0, end_ = 0;
  DimensionBytes window_;  // unset as sized: the file's bytes overwrite it
  std::vector<char> keep_;
  std::vector<uint64_t>* checkpoints_ = nullptr;
  uint64_t checkpoint_spacing_ = 0;
};

uint64_t windowOf(const E57ReadOptions& options) {
  return options.packet_window == 0 ? kPacketWindow : std::max(options.packet_window, kLeastWindow);
}

// The colour channel of a field: an integer 0..full keeps its scale; else normalised by limits.
struct ColorChannel {
  const Field* field = nullptr;
  double lo = 0.0, hi = 1.0;
};

// The range an intensity is normalised from, to 0..1: the scan's intensityLimits, else the field's
// own limits. None where its values are LAS's already (integers of 0..65535, unless `fractions`),
// where the range is 0..1 (as FARO's float intensities are) or where none is known (a float
// without limits).
struct IntensityRange {
  double lo = 0.0, hi = 1.0;
  const char* source = "";
};
bool isLasIntensity(const Field& f) { return f.kind == FieldKind::kInteger && f.minimum >= 0 && f.maximum <= 65535; }

// `fractions`: some scan of the file has an intensity that is no 0..65535 integer, so that every
// scan's is read as 0..1 (one column of one meaning; integers beside fractions go nowhere).
std::optional<IntensityRange> intensityRange(const Field& f, const ScanInfo& scan, bool fractions) {
  if (isLasIntensity(f) && !fractions) return std::nullopt;
  double lo = 0.0, hi = 0.0;
  const bool limits = scan.intensity_limits[0] && scan.intensity_limits[1];
  if (limits) {
    lo = *scan.intensity_limits[0];
    hi = *scan.intensity_limits[1];
  } else if (f.kind == FieldKind::kInteger) {
    lo = static_cast<double>(f.minimum);
    hi = static_cast<double>(f.maximum);
  } else if (f.kind == FieldKind::kScaled) {
    lo = static_cast<double>(f.minimum) * f.scale + f.offset;
    hi = static_cast<double>(f.maximum) * f.scale + f.offset;
    if (hi < lo) std::swap(lo, hi);
  } else {
    lo = f.float_minimum;
    hi = f.float_maximum;
  }
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi) || (lo == 0.0 && hi == 1.0)) return std::nullopt;
  return IntensityRange{lo, hi, limits ? "its intensityLimits" : "the field's limits"};
}

// How a scan's records become points: positions from the cartesian (or spherical) fields moved by
// the pose, the invalid state, the colour channels, and every other field as a dimension (its
// name, type and, for an intensity read as 0..1, its range). Its functions read the fields' held
// bytes (PacketReader), so any record held is decoded without the others, on any thread.
class ScanDecoder {
 public:
  static Result<ScanDecoder> of(const std::string& path, const ScanInfo& scan, bool intensity_fractions) {
    ScanDecoder d;
    d.where_ = path + ": " + scan.label;
    const Field* c[3] = {findField(scan, "cartesianX"), findField(scan, "cartesianY"), findField(scan, "cartesianZ")};
    const Field* s[3] = {findField(scan, "sphericalRange"), findField(scan, "sphericalAzimuth"),
                         findField(scan, "sphericalElevation")};
    d.cartesian_ = c[0] && c[1] && c[2];
    if (!d.cartesian_ && !(s[0] && s[1] && s[2]))
      return Error{d.where_ + ": its points have neither cartesianX, cartesianY and cartesianZ nor sphericalRange, "
                              "sphericalAzimuth and sphericalElevation"};
    for (int k = 0; k < 3; ++k) d.xyz_[k] = d.cartesian_ ? c[k] : s[k];
    d.invalid_ = findField(scan, d.cartesian_ ? "cartesianInvalidState" : "sphericalInvalidState");
    const Field* rgb[3] = {findField(scan, "colorRed"), findField(scan, "colorGreen"), findField(scan, "colorBlue")};
    d.colors_ = rgb[0] && rgb[1] && rgb[2];
    if (!d.colors_ && (rgb[0] || rgb[1] || rgb[2]))
      return Error{d.where_ + ": its points have some of colorRed, colorGreen and colorBlue, not all three"};

    // Colours: an integer 0..255 or 0..65535 keeps its scale; other limits are normalised.
    if (d.colors_) {
      bool integer_scale = true;
      for (int k = 0; k < 3; ++k) {
        const Field& f = *rgb[k];
        ColorChannel& channel = d.channel_[k];
        channel.field = &f;
        const bool integer = f.kind == FieldKind::kInteger;
        channel.lo = scan.color_limits[2 * k]          ? *scan.color_limits[2 * k]
                     : integer                         ? static_cast<double>(f.minimum)
                     : f.kind == FieldKind::kScaled    ? static_cast<double>(f.minimum) * f.scale + f.offset
                     : std::isfinite(f.float_minimum)  ? f.float_minimum
                                                       : 0.0;
        channel.hi = scan.color_limits[2 * k + 1]      ? *scan.color_limits[2 * k + 1]
                     : integer                         ? static_cast<double>(f.maximum)
                     : f.kind == FieldKind::kScaled    ? static_cast<double>(f.maximum) * f.scale + f.offset
                     : std::isfinite(f.float_maximum)  ? f.float_maximum
                                                       : 1.0;
        if (!(channel.hi > channel.lo))
          return Error{d.where_ + ": " + f.name + "'s limits " + formatNumber(channel.lo) + " to " + formatNumber(channel.hi) +
                       " are no range"};
        integer_scale = integer_scale && integer && channel.lo == 0.0 && channel.hi == d.channel_[0].hi &&
                        (channel.hi == 255.0 || channel.hi == 65535.0);
      }
      if (integer_scale) d.full_ = static_cast<uint16_t>(d.channel_[0].hi);
    }

    // The other fields as dimensions.
    for (const Field& f : scan.fields) {
      const bool used = &f == d.xyz_[0] || &f == d.xyz_[1] || &f == d.xyz_[2] || &f == d.invalid_ ||
                        (d.colors_ && (&f == rgb[0] || &f == rgb[1] || &f == rgb[2]));
      if (used) continue;
      Kept kept;
      kept.field = &f;
      std::tie(kept.name, kept.type) = dimensionOf(f);
      for (const Kept& other : d.kept_)
        if (other.name == kept.name)
          return Error{d.where_ + ": the fields " + f.name + " and another are both kept as the dimension " + kept.name};
      if (kept.name == dim::kIntensity && (kept.normalised = intensityRange(f, scan, intensity_fractions)))
        kept.type = DimType::kF32;
      kept.return_index = f.name == "returnIndex" && f.kind == FieldKind::kInteger && kept.name == dim::kReturnNumber;
      d.kept_.push_back(std::move(kept));
    }

    const double* q = scan.rotation;
    d.identity_ = q[0] == 1.0 && q[1] == 0.0 && q[2] == 0.0 && q[3] == 0.0 && scan.translation[0] == 0.0 &&
                  scan.translation[1] == 0.0 && scan.translation[2] == 0.0;
    // The rotation matrix of the unit quaternion (w, x, y, z).
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    const double m[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                            {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                            {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
    std::memcpy(d.m_, m, sizeof m);
    std::memcpy(d.t_, scan.translation, sizeof d.t_);
    return d;
  }

  // A dimension a field is kept as.
  struct Kept {
    const Field* field = nullptr;
    std::string name;
    DimType type = DimType::kF64;
    std::optional<IntensityRange> normalised;  // an intensity read as 0..1
    bool return_index = false;                 // returnIndex, kept 1-based as return_number
  };

  const std::string& where() const { return where_; }
  bool hasColors() const { return colors_; }
  uint16_t colorFullScale() const { return full_; }
  bool hasInvalidState() const { return invalid_ != nullptr; }
  const Field* invalidField() const { return invalid_; }
  const std::vector<Kept>& kept() const { return kept_; }

  // Record i is a point (its invalid state 0: an Integer as E57 has it, or a Float of another writer).
  bool valid(size_t i) const { return !invalid_ || invalid_->value(i) == 0.0; }
  glm::dvec3 position(size_t i) const {
    glm::dvec3 p(xyz_[0]->value(i), xyz_[1]->value(i), xyz_[2]->value(i));
    if (!cartesian_) {
      const double r = p.x, az = p.y, el = p.z;
      p = glm::dvec3(r * std::cos(el) * std::cos(az), r * std::cos(el) * std::sin(az), r * std::sin(el));
    }
    if (!identity_)
      p = glm::dvec3(m_[0][0] * p.x + m_[0][1] * p.y + m_[0][2] * p.z + t_[0],
                     m_[1][0] * p.x + m_[1][1] * p.y + m_[1][2] * p.z + t_[1],
                     m_[2][0] * p.x + m_[2][1] * p.y + m_[2][2] * p.z + t_[2]);
    return p;
  }
  glm::vec3 color(size_t i) const {
    glm::vec3 color;
    for (int k = 0; k < 3; ++k) {
      const ColorChannel& c = channel_[k];
      const double v = c.field->value(i);
      color[k] = static_cast<float>(full_ != 0 ? v / full_ : (v - c.lo) / (c.hi - c.lo));
    }
    return color;
  }
  // Kept field d's value i into `out`, as its dimension's type.
  void store(size_t d, size_t i, uint8_t* out) const {
    const Kept& k = kept_[d];
    const Field& f = *k.field;
    if (k.normalised) {
      const float a = static_cast<float>((f.value(i) - k.normalised->lo) / (k.normalised->hi - k.normalised->lo));
      std::memcpy(out, &a, 4);
    } else if (f.kind == FieldKind::kInteger) {
      // + 1 in unsigned arithmetic: a returnIndex up to INT64_MAX is a uint64 column (dimensionOf).
      const int64_t v = static_cast<int64_t>(static_cast<uint64_t>(f.integer(i)) + (k.return_index ? 1u : 0u));
      switch (k.type) {  // the type holds the field's limits (integerType)
        case DimType::kU8: *out = static_cast<uint8_t>(v); break;
        case DimType::kI8: { const int8_t a = static_cast<int8_t>(v); std::memcpy(out, &a, 1); break; }
        case DimType::kU16: { const uint16_t a = static_cast<uint16_t>(v); std::memcpy(out, &a, 2); break; }
        case DimType::kI16: { const int16_t a = static_cast<int16_t>(v); std::memcpy(out, &a, 2); break; }
        case DimType::kU32: { const uint32_t a = static_cast<uint32_t>(v); std::memcpy(out, &a, 4); break; }
        case DimType::kI32: { const int32_t a = static_cast<int32_t>(v); std::memcpy(out, &a, 4); break; }
        default: std::memcpy(out, &v, 8); break;  // U64, I64: the same bits
      }
    } else if (k.type == DimType::kF32) {
      const float a = loadUnaligned<float>(f.at(uint64_t{i} * 4));
      std::memcpy(out, &a, 4);
    } else {
      const double a = f.value(i);
      std::memcpy(out, &a, 8);
    }
  }
  // The error for record i's coordinate that is not finite.
  Error nonfiniteError(size_t i, uint64_t point) const {
    return Error{where_ + ": point " + std::to_string(point) + " has a coordinate that is not finite (" +
                 formatNumber(xyz_[0]->value(i)) + ", " + formatNumber(xyz_[1]->value(i)) + ", " +
                 formatNumber(xyz_[2]->value(i)) + "); --allow-nonfinite keeps it"};
  }

 private:
  std::string where_;
  const Field* xyz_[3] = {};
  bool cartesian_ = true;
  const Field* invalid_ = nullptr;
  bool colors_ = false;
  ColorChannel channel_[3];
  uint16_t full_ = 0;
  std::vector<Kept> kept_;
  bool identity_ = true;
  double m_[3][3] = {}, t_[3] = {};
};

// Whether some scan holding records has an intensity that is no 0..65535 integer: then every
// scan's is read as 0..1 (intensityRange's `fractions`).
bool intensityFractions(const std::vector<ScanInfo>& scans) {
  return std::any_of(scans.begin(), scans.end(), [](const ScanInfo& scan) {
    const Field* f = findField(scan, "intensity");
    return scan.records > 0 && f && !isLasIntensity(*f);
  });
}

// The range a scan's intensity is read as 0..1 from, added to `ranges` once (for the note).
void addIntensityRange(const ScanDecoder& decoder, std::vector<std::string>& ranges) {
  for (const ScanDecoder::Kept& k : decoder.kept()) {
    if (!k.normalised) continue;
    const std::string range =
        formatNumber(k.normalised->lo) + ".." + formatNumber(k.normalised->hi) + " (" + k.normalised->source + ")";
    if (std::find(ranges.begin(), ranges.end(), range) == ranges.end()) ranges.push_back(range);
  }
}

// The scan's points: positions in the file's frame, colours, dimensions; the invalid ones left
// out. Its packets read a window at a time (PacketReader), each window's records decoded on all
// cores; the fields' bytes may hold up to `budget` bytes at once.
Result<PointSet> pointsOf(const PagedFile& file, ScanInfo& scan, const E57ReadOptions& options, uint64_t budget,
                          bool intensity_fractions, uint64_t& left_out, std::vector<std::string>& intensity_ranges) {
  Result<ScanDecoder> decoder = ScanDecoder::of(file.path(), scan, intensity_fractions);
  if (!decoder) return decoder.error();
  const ScanDecoder& dec = *decoder;
  const unsigned threads = resolveThreads(options.threads);
  const size_t n = static_cast<size_t>(scan.records);
  PointSet points;
  points.z_axis = ZAxis::kPresent;
  points.positions.resize(n);
  if (dec.hasColors()) points.colors.resize(n);
  addIntensityRange(dec, intensity_ranges);
  for (const ScanDecoder::Kept& k : dec.kept()) {
    points.dimensions.appendUnset(k.name, k.type, n);
  }
  PacketReader reader(file, scan, windowOf(options), threads, options.progress, budget);
  if (Status status = reader.open(); !status) return status.error();
  size_t decoded = 0, kept_points = 0;
  while (decoded < n) {
    if (Status status = reader.next(); !status) return status.error();
    const size_t ready = static_cast<size_t>(reader.ready());
    const size_t blocks = (ready - decoded + kDecodeBlock - 1) / kDecodeBlock;
    std::atomic<size_t> first_nonfinite{SIZE_MAX};
    parallelFor(blocks, threads, [&](size_t b, unsigned) {
      const size_t begin = decoded + b * kDecodeBlock, end = std::min(ready, begin + kDecodeBlock);
      for (size_t i = begin; i < end; ++i) {
        const glm::dvec3 p = dec.position(i);
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
          if (dec.valid(i)) lowerAtomic(first_nonfinite, i);
        }
        points.positions[i] = p;
        if (dec.hasColors()) points.colors[i] = dec.color(i);
      }
      for (size_t d = 0; d < dec.kept().size(); ++d) {
        Dimension& dim = points.dimensions.all()[d];
        const size_t width = dimTypeSize(dim.type);
        for (size_t i = begin; i < end; ++i) dec.store(d, i, dim.bytes.data() + i * width);
      }
    });
    if (first_nonfinite.load() != SIZE_MAX && !options.allow_nonfinite)
      return dec.nonfiniteError(first_nonfinite.load(), first_nonfinite.load());
    // The points with an invalid state left out, in order (while the window's fields are held).
    if (dec.hasInvalidState()) {
      for (size_t i = decoded; i < ready; ++i) {
        if (!dec.valid(i)) continue;
        if (kept_points != i) {
          points.positions[kept_points] = points.positions[i];
          if (dec.hasColors()) points.colors[kept_points] = points.colors[i];
          for (Dimension& d : points.dimensions.all()) d.copyFrom(kept_points, d, i);
        }
        ++kept_points;
      }
    }
    reader.drop(ready);
    decoded = ready;
  }
  for (Field& f : scan.fields) DimensionBytes().swap(f.bytes);
  points.color_full_scale = dec.colorFullScale();
  if (dec.hasInvalidState()) {
    left_out += n - kept_points;
    points.positions.resize(kept_points);
    if (dec.hasColors()) points.colors.resize(kept_points);
    points.dimensions.resize(kept_points);
  }
  return points;
}

// What the XML tree says: the scans, and how many images it holds (not read).
struct FileTree {
  std::vector<ScanInfo> scans;
  size_t images = 0;
  std::string crs;  // coordinateMetadata, trimmed
};

Result<FileTree> readTree(const PagedFile& file, unsigned threads) {
  const std::string& path = file.path();
  std::string xml(static_cast<size_t>(file.xmlLength()), '\0');
  if (Status s = file.read(file.logicalOf(file.xmlOffset()), reinterpret_cast<uint8_t*>(xml.data()), xml.size(), threads,
                           nullptr);
      !s)
    return s.error();
  pugi::xml_document doc;
  const pugi::xml_parse_result parsed = doc.load_buffer(xml.data(), xml.size(), pugi::parse_default, pugi::encoding_utf8);
  if (!parsed) {
    const auto offset = static_cast<size_t>(std::max<ptrdiff_t>(0, parsed.offset));
    const std::string_view before(xml.data(), std::min(offset, xml.size()));
    const size_t line = 1 + static_cast<size_t>(std::count(before.begin(), before.end(), '\n'));
    return Error{path + ": its XML, line " + std::to_string(line) + ": " + parsed.description()};
  }
  const pugi::xml_node root = doc.child("e57Root");
  if (!root) return Error{path + ": its XML has no e57Root"};
  FileTree tree;
  size_t index = 0;
  for (const pugi::xml_node& child : root.child("data3D").children()) {
    if (child.type() != pugi::node_element) continue;
    Result<ScanInfo> info = scanInfoOf(child, index++, path);
    if (!info) return info.error();
    tree.scans.push_back(std::move(*info));
  }
  for (const pugi::xml_node& child : root.child("images2D").children())
    if (child.type() == pugi::node_element) ++tree.images;
  for (const pugi::xml_node& part : root.child("coordinateMetadata").children())  // every text and CDATA section
    if (part.type() == pugi::node_pcdata || part.type() == pugi::node_cdata) tree.crs += part.value();
  const size_t first = tree.crs.find_first_not_of(" \t\r\n"), last = tree.crs.find_last_not_of(" \t\r\n");
  tree.crs = first == std::string::npos ? std::string() : tree.crs.substr(first, last - first + 1);
  return tree;
}

// What a scan brings to a join (joinScans): its number, whether it has colours, its dimensions.
struct ScanFacts {
  uint64_t number = 0;
  bool colors = false;
  std::vector<std::string> dimensions;
};

// One note for each thing the join of `scans` fills in: white for the scans without colours beside
// scans with, 0 for a dimension some scans lack.
void noteJoinFillIns(const std::string& path, const std::vector<ScanFacts>& scans, std::vector<std::string>& notices) {
  const auto lacking = [&](const auto& has) {
    std::string numbers;
    size_t count = 0;
    for (const ScanFacts& scan : scans)
      if (!has(scan)) numbers += (count++ == 0 ? "" : ", ") + std::to_string(scan.number);
    return count == scans.size() ? std::string() : numbers;
  };
  if (const std::string none = lacking([](const ScanFacts& f) { return f.colors; }); !none.empty())
    notices.push_back(path + ": data3D " + none + " without colours beside scans with: their points are white");
  std::vector<std::string> names;
  for (const ScanFacts& scan : scans)
    for (const std::string& name : scan.dimensions)
      if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
  for (const std::string& name : names)
    if (const std::string none = lacking([&](const ScanFacts& f) {
          return std::find(f.dimensions.begin(), f.dimensions.end(), name) != f.dimensions.end();
        });
        !none.empty())
      notices.push_back(path + ": data3D " + none + " without " + name + " beside scans with: 0 there");
}

// What a read of a file met, for its notes.
struct FileFacts {
  uint64_t left_out = 0, records = 0;  // points marked invalid, of the records
  size_t images = 0, scans = 0, scans_with_records = 0;
};

// The notes of a file read whole or streamed: points left out, intensities read as 0..1, images
// not read, no points.
void noteFile(const std::string& path, const FileFacts& facts, const std::vector<std::string>& intensity_ranges,
              std::vector<std::string>& notices) {
  if (facts.left_out > 0)
    notices.push_back(path + ": " + std::to_string(facts.left_out) + " of its " + std::to_string(facts.records) +
                      " points are marked invalid (no point, or a direction alone): left out");
  for (const std::string& range : intensity_ranges)
    notices.push_back(path + ": intensity of " + range + " read as 0..1 values, as LAS normalises it");
  if (facts.images > 0)
    notices.push_back(path + ": its " + countOf(facts.images, "image") + " (images2D) " +
                      (facts.images == 1 ? "is" : "are") + " not read");
  if (facts.scans_with_records == 0)
    notices.push_back(path + ": " + (facts.scans == 0 ? std::string("no scan (data3D is empty)")
                                                      : "its " + countOf(facts.scans, "scan") +
                                                            (facts.scans == 1 ? " holds" : " hold") + " no points"));
}

// Bytes held per point of a scan: positions, colours and, at most, 8 for each other field (the
// fields' packed values are held a window at a time: PacketReader).
uint64_t bytesPerRecord(const ScanInfo& scan) {
  uint64_t bytes = sizeof(glm::dvec3);
  bool colors = false;
  for (const Field& f : scan.fields) {
    if (f.name.rfind("color", 0) == 0) colors = true;
    else if (f.name.rfind("cartesian", 0) != 0 && f.name.rfind("spherical", 0) != 0) bytes += 8;
  }
  return bytes + (colors ? sizeof(glm::vec3) : 0);
}

}  // namespace

Result<PointSet> readE57(const InputFile& file, const E57ReadOptions& options) {
  const std::string& path = file.path();
  if (file.size() == 0) return Error{path + ": empty file"};
  Result<PagedFile> paged = PagedFile::open(file);
  if (!paged) return paged.error();
  const unsigned threads = resolveThreads(options.threads);
  const uint64_t limit = options.max_memory != 0 ? options.max_memory : defaultMemoryLimit();

  Result<FileTree> tree = readTree(*paged, threads);
  if (!tree) return tree.error();
  std::vector<ScanInfo>& scans = tree->scans;
  const size_t images = tree->images;

  uint64_t total = 0, held = 0, bytes_to_read = 0;
  for (const ScanInfo& scan : scans) {
    if (scan.records > (UINT64_MAX / 2) / bytesPerRecord(scan) || scan.records > UINT64_MAX / 128 ||
        total + scan.records < total)
      return Error{path + ": " + scan.label + " declares " + std::to_string(scan.records) + " points, more than memory holds",
                   ExitCode::kResourceLimit};
    total += scan.records;
    const uint64_t bytes = scan.records * bytesPerRecord(scan);  // at most 2^63 (above)
    held = held > UINT64_MAX - bytes ? UINT64_MAX : held + bytes;  // many scans of 2^56 records of no bits
    for (const Field& f : scan.fields) bytes_to_read += f.neededBytes(scan.records);
  }
  // Beside the points: a window of packets, and about as much of the fields' bytes (PacketReader).
  // (A window is no larger than the file: a small file is not charged 64 MiB, a review finding.)
  const uint64_t window = std::min(windowOf(options), paged->logicalLength());
  held = std::min(held, UINT64_MAX - 2 * window) + 2 * window;
  if (Status s = checkMemory(path + ": " + std::to_string(total) + " points in " + countOf(scans.size(), "scan"), held, limit); !s)
    return s.error();
  const uint64_t field_budget = limit - held + window;  // what the fields' bytes may take
  // Scan numbers go to point_source_id where two or more scans hold points: the last such must fit.
  size_t with_points = 0, last_with_points = 0;
  for (size_t k = 0; k < scans.size(); ++k)
    if (scans[k].records > 0) {
      ++with_points;
      last_with_points = k + 1;
    }
  if (with_points > 1 && last_with_points > 65535)
    return Error{path + ": " + scans[last_with_points - 1].label +
                 " holds points, and its number is past what a point source id (1 to 65535) holds"};

  Progress* progress = options.progress;
  if (progress) progress->start("reading " + path, bytes_to_read);
  std::vector<NumberedScan> read;
  uint64_t left_out = 0;
  std::vector<std::string> intensity_ranges;  // those normalised to 0..1, each once
  const bool intensity_fractions = intensityFractions(scans);
  for (size_t k = 0; k < scans.size(); ++k) {
    ScanInfo& scan = scans[k];
    if (scan.records == 0) continue;
    Result<PointSet> points = pointsOf(*paged, scan, options, field_budget, intensity_fractions, left_out, intensity_ranges);
    if (!points) return points.error();
    read.push_back({k + 1, std::move(*points)});
  }
  if (progress) progress->finish();
  if (options.notices) noteFile(path, {left_out, total, images, scans.size(), read.size()}, intensity_ranges, *options.notices);
  if (read.empty()) {
    PointSet none;
    none.z_axis = ZAxis::kPresent;
    none.crs = tree->crs;
    return none;
  }
  if (read.size() == 1) {
    read.front().points.crs = tree->crs;
    return std::move(read.front().points);
  }
  // The file's own point source ids (an E57 written from LAS) are kept as they are, 0 for the scans
  // without (scan numbers there could be ids of the others).
  const bool own_ids = std::any_of(read.begin(), read.end(), [](const NumberedScan& scan) {
    return scan.points.dimensions.find(dim::kPointSourceId) != nullptr;
  });
  if (options.notices) {  // what the join fills in
    std::vector<ScanFacts> facts;
    for (const NumberedScan& scan : read) {
      facts.push_back({scan.number, scan.points.hasColors(), {}});
      for (const Dimension& d : scan.points.dimensions.all()) facts.back().dimensions.push_back(d.name);
    }
    noteJoinFillIns(path, facts, *options.notices);
  }
  if (own_ids)
    for (NumberedScan& scan : read) scan.number = 0;
  PointSet joined = joinScans(std::move(read));
  joined.crs = tree->crs;
  return joined;
}

Result<PointSet> readE57(const std::string& path, const E57ReadOptions& options) {
  Result<InputFile> file = InputFile::open(path);
  if (!file) return file.error();
  return readE57(*file, options);
}


Result<uint64_t> e57RecordCount(const std::string& path) {
  Result<InputFile> file = InputFile::open(path);
  if (!file) return file.error();
  if (file->size() == 0) return Error{path + ": empty file"};
  Result<PagedFile> paged = PagedFile::open(*file);
  if (!paged) return paged.error();
  Result<FileTree> tree = readTree(*paged, 1);
  if (!tree) return tree.error();
  uint64_t records = 0;
  for (const ScanInfo& scan : tree->scans) records = records > UINT64_MAX - scan.records ? UINT64_MAX : records + scan.records;
  return records;
}

// ---- E57PointStream -------------------------------------------------------------------------------

namespace {
constexpr uint64_t kValidBlock = uint64_t{1} << 16;  // records a count of points is kept for
}  // namespace

struct E57PointStream::State {
  // A scan that holds records, with what its reads need. Never moved: its decoder points into
  // its fields.
  struct Scan {
    ScanInfo info;
    std::optional<ScanDecoder> decoder;
    uint64_t number = 0;  // its point_source_id, 0: none added
    uint64_t first = 0;   // its first point in the stream
    uint64_t points = 0;  // its records that are points
    std::vector<uint64_t> checkpoints;   // each data packet: its logical offset, then every field's bytes before it
    std::vector<uint64_t> valid_before;  // points before every kValidBlock-th record; empty: every record is one
    std::vector<size_t> dimension_of;    // by kept field: its index in dimensions_, SIZE_MAX if none
  };

  std::optional<InputFile> file;
  std::optional<PagedFile> paged;
  E57ReadOptions options;
  uint64_t window = kPacketWindow, budget = 0;
  std::vector<std::unique_ptr<Scan>> scans;
  uint64_t count = 0, held = 0;
  bool colors = false;
  size_t source_id = SIZE_MAX;  // the index of point_source_id in dimensions where it is the scan numbers
  Dimensions dimensions;
  std::vector<std::string> notices;
  std::string crs;  // coordinateMetadata, as readE57 keeps it
  std::vector<size_t> streamed;  // dimensions read() fills, by index
  // Where the last read ended: the scan, its next record and the point that record may be.
  size_t at_scan = SIZE_MAX;
  uint64_t at_record = 0, at_point = 0;
  std::unique_ptr<PacketReader> reader;

  // The fields a read decodes of `scan`: positions, invalid state, colours, the streamed dimensions.
  std::vector<const Field*> neededFields(const Scan& scan) const {
    std::vector<const Field*> fields;
    for (const Field& f : scan.info.fields) {
      const auto kept = std::find_if(scan.decoder->kept().begin(), scan.decoder->kept().end(),
                                     [&](const ScanDecoder::Kept& k) { return k.field == &f; });
      if (kept == scan.decoder->kept().end()) {  // a position, invalid state or colour field
        fields.push_back(&f);
        continue;
      }
      const size_t d = scan.dimension_of[static_cast<size_t>(kept - scan.decoder->kept().begin())];
      if (std::find(streamed.begin(), streamed.end(), d) != streamed.end()) fields.push_back(&f);
    }
    return fields;
  }

  // A reader of scan s from its point `point` on: at_record and at_point set to the record of the
  // kValidBlock (or the record itself) at or before it.
  Status startAt(size_t s, uint64_t point) {
    Scan& scan = *scans[s];
    reader.reset();
    if (at_scan < scans.size())  // the last read's scan gives its fields' bytes back (a review finding:
      for (Field& f : scans[at_scan]->info.fields) DimensionBytes().swap(f.bytes);  // every scan's: 65,535 took 476 s)
    uint64_t record = point, before = point;
    if (!scan.valid_before.empty()) {
      const size_t b = static_cast<size_t>(
          std::upper_bound(scan.valid_before.begin(), scan.valid_before.end(), point) - scan.valid_before.begin() - 1);
      record = b * kValidBlock;
      before = scan.valid_before[b];
    }
    // The last packet at whose start every field has given no more than the record's first byte.
    const size_t stride = 1 + scan.info.fields.size();
    const size_t packets = scan.checkpoints.size() / stride;
    size_t lo = 0, hi = packets;  // the first packet past it: in (lo, hi]
    while (hi - lo > 1) {
      const size_t mid = lo + (hi - lo) / 2;
      const uint64_t* c = scan.checkpoints.data() + mid * stride;
      bool before_record = true;
      for (size_t k = 0; k < scan.info.fields.size() && before_record; ++k)
        before_record = c[1 + k] <= record * scan.info.fields[k].bits / 8;
      (before_record ? lo : hi) = mid;
    }
    reader = std::make_unique<PacketReader>(*paged, scan.info, window, resolveThreads(options.threads), nullptr, budget);
    if (Status st = reader->open(); !st) return st;
    reader->keepOnly(neededFields(scan));
    if (packets > 0) reader->seek(scan.checkpoints.data() + lo * stride, record);
    at_scan = s;
    at_record = record;
    at_point = before;
    return okStatus();
  }
};

E57PointStream::E57PointStream() : state_(std::make_unique<State>()) {}
E57PointStream::~E57PointStream() = default;
uint64_t E57PointStream::count() const { return state_->count; }
bool E57PointStream::hasColors() const { return state_->colors; }
const Dimensions& E57PointStream::dimensions() const { return state_->dimensions; }
const std::vector<std::string>& E57PointStream::notices() const { return state_->notices; }
const std::string& E57PointStream::crs() const { return state_->crs; }
uint64_t E57PointStream::heldBytes() const { return state_->held; }
void E57PointStream::streamDimensions(std::vector<size_t> which) {
  state_->streamed = std::move(which);
  state_->at_scan = SIZE_MAX;  // the next read keeps those fields too
}

Result<std::unique_ptr<E57PointStream>> E57PointStream::open(const std::string& path, const E57ReadOptions& options) {
  Result<InputFile> file = InputFile::open(path);
  if (!file) return file.error();
  return open(std::move(*file), options);
}

Result<std::unique_ptr<E57PointStream>> E57PointStream::open(InputFile input, const E57ReadOptions& options) {
  std::unique_ptr<E57PointStream> stream(new E57PointStream());
  State& st = *stream->state_;
  const std::string path = input.path();
  if (input.size() == 0) return Error{path + ": empty file"};
  st.file.emplace(std::move(input));
  Result<PagedFile> paged = PagedFile::open(*st.file);
  if (!paged) return paged.error();
  st.paged.emplace(std::move(*paged));
  st.options = options;
  st.window = windowOf(options);
  const unsigned threads = resolveThreads(options.threads);
  const uint64_t limit = options.max_memory != 0 ? options.max_memory : defaultMemoryLimit();
  st.budget = limit / 4;  // the fields' bytes of a block's packets: a window's worth as writers spread them
  Result<FileTree> tree = readTree(*st.paged, threads);
  if (!tree) return tree.error();
  st.crs = tree->crs;
  const bool intensity_fractions = intensityFractions(tree->scans);
  size_t with_records = 0;
  for (size_t k = 0; k < tree->scans.size(); ++k) {
    if (tree->scans[k].records == 0) continue;
    if (tree->scans[k].records > UINT64_MAX / 128)
      return Error{path + ": " + tree->scans[k].label + " declares " + std::to_string(tree->scans[k].records) +
                       " points, more than memory holds",
                   ExitCode::kResourceLimit};
    auto scan = std::make_unique<State::Scan>();
    scan->info = std::move(tree->scans[k]);
    scan->number = k + 1;
    st.scans.push_back(std::move(scan));
    ++with_records;
  }
  if (with_records > 1 && st.scans.back()->number > 65535)
    return Error{path + ": " + st.scans.back()->info.label +
                 " holds points, and its number is past what a point source id (1 to 65535) holds"};
  uint64_t bytes_to_read = 0;
  for (const std::unique_ptr<State::Scan>& scan : st.scans)
    for (const Field& f : scan->info.fields) bytes_to_read += f.neededBytes(scan->info.records);
  Progress* progress = options.progress;
  if (progress) progress->start("indexing " + path, bytes_to_read);
  uint64_t left_out = 0, total = 0;
  std::vector<std::string> intensity_ranges;
  bool own_ids = false;
  for (std::unique_ptr<State::Scan>& scan_ptr : st.scans) {
    State::Scan& scan = *scan_ptr;
    Result<ScanDecoder> decoder = ScanDecoder::of(path, scan.info, intensity_fractions);
    if (!decoder) return decoder.error();
    scan.decoder.emplace(std::move(*decoder));
    const ScanDecoder& dec = *scan.decoder;
    addIntensityRange(dec, intensity_ranges);
    for (const ScanDecoder::Kept& k : dec.kept()) own_ids = own_ids || k.name == dim::kPointSourceId;
    // The walk: every packet's place, and the invalid state's points counted.
    PacketReader reader(*st.paged, scan.info, st.window, threads, progress, st.budget);
    if (Status s = reader.open(); !s) return s.error();
    reader.keepOnly(dec.hasInvalidState() ? std::vector<const Field*>{dec.invalidField()} : std::vector<const Field*>{});
    reader.recordCheckpoints(&scan.checkpoints);
    const uint64_t n = scan.info.records;
    uint64_t decoded = 0, points = 0;
    while (decoded < n) {
      if (Status s = reader.next(); !s) return s.error();
      const uint64_t ready = reader.ready();
      if (dec.hasInvalidState())
        for (uint64_t i = decoded; i < ready; ++i) {
          if (i % kValidBlock == 0) scan.valid_before.push_back(points);
          points += dec.valid(static_cast<size_t>(i));
        }
      else
        points = ready;
      reader.drop(ready);
      decoded = ready;
      const uint64_t index = st.held + (scan.checkpoints.size() + scan.valid_before.size()) * sizeof(uint64_t);
      if (index > limit / 2)
        return Error{path + ": " + scan.info.label + ": its packets' index would take more than " + formatBytes(index) +
                         ", more than half the memory limit (--max-memory; --stream off reads the file whole)",
                     ExitCode::kResourceLimit};
    }
    if (dec.hasInvalidState()) scan.valid_before.push_back(points);
    for (Field& f : scan.info.fields) DimensionBytes().swap(f.bytes);
    scan.checkpoints.shrink_to_fit();
    scan.points = points;
    scan.first = st.count;
    st.count += points;
    total += n;
    left_out += n - points;
    st.colors = st.colors || (points > 0 && dec.hasColors());
    st.held += (scan.checkpoints.size() + scan.valid_before.size()) * sizeof(uint64_t);
  }
  if (progress) progress->finish();

  // The dimensions as the join makes them (joinScans, appendPoints): each name once, in the order
  // met, the scan numbers after the first scan's where several scans hold records and none has
  // ids, a type kept where it holds a later scan's, else float64.
  std::vector<ScanFacts> facts;
  for (std::unique_ptr<State::Scan>& scan : st.scans) {
    facts.push_back({scan->number, scan->points > 0 && scan->decoder->hasColors(), {}});  // as a read scan's hasColors()
    for (const ScanDecoder::Kept& k : scan->decoder->kept()) {
      facts.back().dimensions.push_back(k.name);
      size_t d = 0;
      for (; d < st.dimensions.count(); ++d)
        if (st.dimensions.all()[d].name == k.name) break;
      if (d == st.dimensions.count()) st.dimensions.append(k.name, k.type, 0);
      else if (!dimTypeHolds(st.dimensions.all()[d].type, k.type)) st.dimensions.all()[d].type = DimType::kF64;
      scan->dimension_of.push_back(d);
    }
    if (scan == st.scans.front() && st.scans.size() > 1 && !own_ids) {
      st.source_id = st.dimensions.count();
      st.dimensions.append(dim::kPointSourceId, DimType::kU16, 0);
    }
  }
  noteFile(path, {left_out, total, tree->images, tree->scans.size(), st.scans.size()}, intensity_ranges, st.notices);
  if (st.scans.size() > 1) noteJoinFillIns(path, facts, st.notices);
  return stream;
}

Status E57PointStream::read(uint64_t first, uint64_t n, PointSet& block) {
  State& st = *state_;
  assert(first <= st.count && n <= st.count - first);
  block.triangles.clear();
  block.z_axis = ZAxis::kPresent;
  block.positions.resize(static_cast<size_t>(n));
  block.colors.resize(st.colors ? static_cast<size_t>(n) : 0);
  std::vector<const Dimension*> like;
  for (size_t d : st.streamed) like.push_back(&st.dimensions.all()[d]);
  block.dimensions.shapeUnset(like, static_cast<size_t>(n));
  std::vector<Dimension*> out_dims;
  for (Dimension& d : block.dimensions.all()) out_dims.push_back(&d);
  const unsigned threads = resolveThreads(st.options.threads);
  std::vector<uint64_t> records;  // of the current window: those read into the block, less `base`
  uint64_t done = 0;
  while (done < n) {
    const uint64_t point = first + done;
    // The scan holding the point: the last whose first point is at or before it, with points.
    size_t s = static_cast<size_t>(std::upper_bound(st.scans.begin(), st.scans.end(), point,
                                                    [](uint64_t p, const std::unique_ptr<State::Scan>& scan) {
                                                      return p < scan->first;
                                                    }) -
                                   st.scans.begin() - 1);
    while (st.scans[s]->points == 0 || point >= st.scans[s]->first + st.scans[s]->points) ++s;
    State::Scan& scan = *st.scans[s];
    const uint64_t local = point - scan.first;
    if (st.at_scan != s || st.at_point > local || (st.at_point != local && scan.valid_before.empty()) ||
        (!scan.valid_before.empty() && local - st.at_point > kValidBlock)) {
      if (Status status = st.startAt(s, local); !status) return status;
    }
    const ScanDecoder& dec = *scan.decoder;
    const uint64_t want = std::min(n - done, scan.points - local);
    uint64_t taken = 0, skip = local - st.at_point;
    while (taken < want) {
      if (st.reader->ready() <= st.at_record)
        if (Status status = st.reader->next(want - taken + skip); !status) return status;
      const uint64_t ready = st.reader->ready();
      const uint64_t base = st.at_record;
      records.clear();
      uint64_t r = st.at_record;
      for (; r < ready && taken + records.size() < want; ++r) {
        if (!dec.valid(static_cast<size_t>(r))) continue;
        if (skip > 0) {
          --skip;
          ++st.at_point;
          continue;
        }
        records.push_back(r - base);
      }
      const size_t got = records.size();
      const uint64_t at = done + taken;
      std::atomic<size_t> first_nonfinite{SIZE_MAX};
      const size_t blocks = (got + kDecodeBlock - 1) / kDecodeBlock;
      parallelFor(blocks, threads, [&](size_t b, unsigned) {
        const size_t begin = b * kDecodeBlock, end = std::min(got, begin + kDecodeBlock);
        for (size_t k = begin; k < end; ++k) {
          const size_t i = static_cast<size_t>(base + records[k]);
          const glm::dvec3 p = dec.position(i);
          if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) lowerAtomic(first_nonfinite, k);
          block.positions[static_cast<size_t>(at) + k] = p;
          if (st.colors) block.colors[static_cast<size_t>(at) + k] = dec.hasColors() ? dec.color(i) : glm::vec3(1.0f);
        }
        for (size_t o = 0; o < out_dims.size(); ++o) {
          Dimension& dim = *out_dims[o];
          const size_t d = st.streamed[o];
          const size_t width = dimTypeSize(dim.type);
          if (d == st.source_id) {
            for (size_t k = begin; k < end; ++k) dim.setValue(static_cast<size_t>(at) + k, static_cast<double>(scan.number));
            continue;
          }
          const auto kept = std::find(scan.dimension_of.begin(), scan.dimension_of.end(), d);
          if (kept == scan.dimension_of.end()) {  // a dimension this scan lacks: 0, as the join fills it
            std::fill_n(dim.bytes.data() + (static_cast<size_t>(at) + begin) * width, (end - begin) * width, uint8_t{0});
            continue;
          }
          const size_t kd = static_cast<size_t>(kept - scan.dimension_of.begin());
          if (dec.kept()[kd].type == dim.type) {
            for (size_t k = begin; k < end; ++k)
              dec.store(kd, static_cast<size_t>(base + records[k]), dim.bytes.data() + (static_cast<size_t>(at) + k) * width);
          } else {  // widened to float64 where the scans' types differ
            Dimension one(dim.name, dec.kept()[kd].type, 1);
            for (size_t k = begin; k < end; ++k) {
              dec.store(kd, static_cast<size_t>(base + records[k]), one.bytes.data());
              dim.setValue(static_cast<size_t>(at) + k, one.value(0));
            }
          }
        }
      });
      if (first_nonfinite.load() != SIZE_MAX && !st.options.allow_nonfinite) {
        const size_t k = first_nonfinite.load();
        return dec.nonfiniteError(static_cast<size_t>(base + records[k]), base + records[k]);
      }
      taken += got;
      st.at_point += got;
      st.at_record = r;
      st.reader->drop(r);
    }
    done += taken;
  }
  return okStatus();
}

}  // namespace dpoint
