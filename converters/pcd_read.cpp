// PCD reading (converters/pcd.h): the header, then ASCII rows on one thread, or binary rows (or the
// LZF-decompressed columns of binary_compressed) in blocks on all cores.
#include <lzf.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <optional>
#include <unordered_set>

#include <fast_float/fast_float.h>

#include "converters/las_crs.h"
#include "converters/pcd.h"
#include "core/bytes.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "core/text.h"

namespace dpoint {
namespace {

constexpr size_t kMaxHeader = size_t{1} << 20;  // a header longer than this is not a PCD file
constexpr uint64_t kBlock = uint64_t{1} << 16;   // points per decoded block
constexpr size_t kAsciiChunk = size_t{4} << 20;  // bytes of ASCII data per block
constexpr size_t kAsciiMaxLineBytes = size_t{4} << 20;  // an ASCII line longer than this is an error
// Values per point at most (PCL's widest descriptors, SHOT colour, have 1,344).
constexpr size_t kMaxValues = 65536;

enum class Role : uint8_t { kX, kY, kZ, kRgb, kSkip, kDimension };
enum class Data : uint8_t { kAscii, kBinary, kCompressed };

struct Field {
  std::string name;
  char type = 'F';  // I, U or F
  int size = 4;
  uint32_t count = 1;
  Role role = Role::kDimension;
  bool rgba = false;      // kRgb: the top byte is alpha
  size_t offset = 0;      // of the field in a binary row
  size_t dimension = 0;   // kDimension: the first of its `count` dimensions
  size_t bytes() const { return static_cast<size_t>(size) * count; }
};

struct Header {
  std::vector<Field> fields;
  uint64_t points = 0;
  Data data = Data::kBinary;
  uint64_t data_offset = 0;  // the first byte after the DATA line
  uint64_t lines = 0;        // the DATA line's number
  size_t row_bytes = 0;
  bool has_z = false, two_d = false, z_up = false, colors = false, alpha = false;
  HeaderCrsLines crs;  // `# dpoint: crs` lines
  std::string viewpoint;  // the VIEWPOINT line when it is not the identity
  std::optional<std::array<double, 7>> pose;  // its values
  std::vector<std::pair<std::string, DimType>> dimensions;
};

DimType dimTypeOf(char type, int size) {
  switch (type) {
    case 'F': return size == 4 ? DimType::kF32 : DimType::kF64;
    case 'U': return size == 1 ? DimType::kU8 : size == 2 ? DimType::kU16 : size == 4 ? DimType::kU32 : DimType::kU64;
    default: return size == 1 ? DimType::kI8 : size == 2 ? DimType::kI16 : size == 4 ? DimType::kI32 : DimType::kI64;
  }
}

// A field's value at p as a double (x, y and z).
double loadNumber(const uint8_t* p, char type, int size) {
  switch (type) {
    case 'F': return size == 4 ? static_cast<double>(loadUnaligned<float>(p)) : loadUnaligned<double>(p);
    case 'U':
      return size == 1   ? p[0]
             : size == 2 ? loadUnaligned<uint16_t>(p)
             : size == 4 ? loadUnaligned<uint32_t>(p)
                         : static_cast<double>(loadUnaligned<uint64_t>(p));
    default:
      return size == 1   ? static_cast<int8_t>(p[0])
             : size == 2 ? loadUnaligned<int16_t>(p)
             : size == 4 ? loadUnaligned<int32_t>(p)
                         : static_cast<double>(loadUnaligned<int64_t>(p));
  }
}

std::vector<std::string_view> tokensOf(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

std::string upper(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

class HeaderParser {
 public:
  explicit HeaderParser(const InputFile& file) : file_(file), path_(file.path()) {}

  Result<Header> parse() {
    if (file_.size() == 0) return Error{path_ + ": empty file, not a PCD file"};
    std::string head(static_cast<size_t>(std::min<uint64_t>(file_.size(), kMaxHeader)), '\0');
    Result<size_t> got = file_.readAt(0, head.data(), head.size());
    if (!got) return got.error();
    head.resize(*got);
    size_t pos = 0;
    while (true) {
      if (pos >= head.size())
        return Error{path_ + (head.size() == file_.size() ? ": the header ends without a DATA line"
                                                           : ": no DATA line in the first 1 MiB; not a PCD file")};
      size_t end = head.find('\n', pos);
      const bool last = end == std::string::npos;
      if (last) {
        if (head.size() < file_.size())  // the line runs past the first 1 MiB, long or not (a review finding)
          return Error{path_ + ": the header runs past its first 1 MiB (line " + std::to_string(line_ + 1) +
                       " does not end in it); not a PCD file a reader takes"};
        end = head.size();
      }
      const std::string_view text(head.data() + pos, end - pos);
      pos = last ? end : end + 1;
      ++line_;
      const std::vector<std::string_view> tokens = tokensOf(text);
      if (tokens.empty()) continue;
      if (tokens[0][0] == '#') {
        if (text.find("dpoint: 2D") != std::string_view::npos) header_.two_d = true;
        if (text.find("dpoint: up axis z") != std::string_view::npos) header_.z_up = true;
        // The coordinate system another format stated (pcd_write.cpp), in hex over lines in order;
        // left out where a line is bad.
        if (tokens.size() >= 3 && tokens[0] == "#" && tokens[1] == "dpoint:" && tokens[2] == "crs")
          header_.crs.add({tokens.begin() + 3, tokens.end()});
        continue;
      }
      Status s = entry(tokens);
      if (!s) return s.error();
      if (data_seen_) break;
    }
    header_.data_offset = pos;
    header_.lines = static_cast<uint64_t>(line_);
    if (Status s = finish(); !s) return s.error();
    return std::move(header_);
  }

 private:
  Error headerError(int line, const std::string& what) const {
    return Error{path_ + ": header line " + std::to_string(line) + ": " + what};
  }
  Error error(const std::string& what) const { return headerError(line_, what); }

  Result<uint64_t> count(std::string_view token, const std::string& key) const {
    uint64_t v = 0;
    if (!parseDecimalU64(token, v))
      return error(key + " " + quotedExcerpt(token) + (allDecimalDigits(token) ? " is 2^64 or more" : " is not a whole number"));
    return v;
  }

  Status entry(const std::vector<std::string_view>& tokens) {
    const std::string key = upper(tokens[0]);
    const std::vector<std::string_view> values(tokens.begin() + 1, tokens.end());
    if (!any_entry_ && key != "VERSION" && key != "FIELDS" && key != "COLUMNS")
      return Error{path_ + ": not a PCD file (header line " + std::to_string(line_) + " starts with " + quotedExcerpt(tokens[0]) +
                   ", not VERSION or FIELDS)"};
    any_entry_ = true;
    if (key == "VERSION") return okStatus();
    if (key == "FIELDS" || key == "COLUMNS") {  // COLUMNS: PCD 0.5
      if (values.empty()) return error("FIELDS names no field");
      names_.assign(values.begin(), values.end());
      fields_line_ = line_;
      return okStatus();
    }
    if (key == "SIZE" || key == "TYPE" || key == "COUNT") {
      if (names_.empty()) return error(key + " before FIELDS");
      if (values.size() != names_.size())
        return error(key + " has " + std::to_string(values.size()) + " values for the " + std::to_string(names_.size()) +
                     " FIELDS of line " + std::to_string(fields_line_));
      for (size_t k = 0; k < values.size(); ++k) {
        const std::string_view v = values[k];
        const std::string field = "field " + quotedExcerpt(names_[k]) + ": ";
        if (key == "TYPE") {
          const std::string t = upper(v);
          if (t != "I" && t != "U" && t != "F") return error(field + "TYPE " + quotedExcerpt(v) + " is not I, U or F");
          types_.resize(names_.size());
          types_[k] = t[0];
        } else {
          Result<uint64_t> n = count(v, key);
          if (!n) return n.error();
          if (key == "SIZE") {
            if (*n != 1 && *n != 2 && *n != 4 && *n != 8) return error(field + "SIZE " + quotedExcerpt(v) + " is not 1, 2, 4 or 8");
            sizes_.resize(names_.size());
            sizes_[k] = static_cast<int>(*n);
          } else {
            if (*n == 0 || *n > kMaxValues)
              return error(field + "COUNT " + quotedExcerpt(v) + " is not 1 to " + std::to_string(kMaxValues));
            counts_.resize(names_.size());
            counts_[k] = static_cast<uint32_t>(*n);
          }
        }
      }
      (key == "SIZE" ? size_line_ : key == "TYPE" ? type_line_ : count_line_) = line_;
      return okStatus();
    }
    if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS") {
      if (values.size() != 1) return error(key + " takes one number");
      Result<uint64_t> n = count(values[0], key);
      if (!n) return n.error();
      (key == "WIDTH" ? width_ : key == "HEIGHT" ? height_ : points_) = *n;
      (key == "WIDTH" ? width_line_ : key == "HEIGHT" ? height_line_ : points_line_) = line_;
      return okStatus();
    }
    if (key == "VIEWPOINT") {
      if (values.size() != 7) return error("VIEWPOINT takes 7 numbers (tx ty tz qw qx qy qz)");
      static constexpr std::array<double, 7> kIdentity = {0, 0, 0, 1, 0, 0, 0};
      std::array<double, 7> pose{};
      for (size_t k = 0; k < 7; ++k) {
        auto r = fast_float::from_chars(values[k].data(), values[k].data() + values[k].size(), pose[k]);
        if (r.ec != std::errc() || r.ptr != values[k].data() + values[k].size())
          return error("VIEWPOINT value " + quotedExcerpt(values[k]) + " is not a number");
      }
      if (pose != kIdentity) {
        header_.viewpoint = "VIEWPOINT";
        for (std::string_view v : values) (header_.viewpoint += ' ') += v;
        // A pose with nan or inf is no pose: the file is read, the viewpoint dropped (the note).
        if (std::all_of(pose.begin(), pose.end(), [](double v) { return std::isfinite(v); })) header_.pose = pose;
      }
      return okStatus();
    }
    if (key == "DATA") {
      const std::string d = values.empty() ? std::string() : std::string(values[0]);
      if (values.size() != 1 || (d != "ascii" && d != "binary" && d != "binary_compressed"))
        return error("DATA " + quotedExcerpt(d) + " is not ascii, binary or binary_compressed");
      header_.data = d == "ascii" ? Data::kAscii : d == "binary" ? Data::kBinary : Data::kCompressed;
      data_seen_ = true;
      return okStatus();
    }
    return error("unknown entry " + quotedExcerpt(tokens[0]) +
                 " (a PCD header has VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, POINTS and DATA)");
  }

  Status finish() {
    const int data_line = line_;
    if (names_.empty()) return headerError(data_line, "DATA before FIELDS: the header names no field");
    if (sizes_.empty()) return headerError(data_line, "the header has no SIZE line");
    if (types_.empty()) types_.assign(names_.size(), 'F');  // PCD 0.5 had no TYPE
    if (counts_.empty()) counts_.assign(names_.size(), 1);
    // A second FIELDS (or COLUMNS) line may name more fields than the earlier SIZE, TYPE or COUNT
    // gave values for.
    const struct {
      const char* key;
      size_t values;
      int line;
    } given[] = {{"SIZE", sizes_.size(), size_line_}, {"TYPE", types_.size(), type_line_}, {"COUNT", counts_.size(), count_line_}};
    for (const auto& g : given)
      if (g.values != names_.size())
        return headerError(g.line, std::string(g.key) + " has " + std::to_string(g.values) + " values for the " +
                                       std::to_string(names_.size()) + " FIELDS of line " + std::to_string(fields_line_));
    // POINTS, else WIDTH × HEIGHT (HEIGHT 1 when missing).
    if (width_line_ != 0 && points_line_ != 0) {
      const uint64_t h = height_line_ != 0 ? height_ : 1;
      if (width_ != 0 && (h > std::numeric_limits<uint64_t>::max() / width_ || width_ * h != points_))
        return headerError(points_line_, "POINTS " + std::to_string(points_) + " is not WIDTH × HEIGHT (" +
                                             std::to_string(width_) + " × " + std::to_string(h) + ")");
    }
    if (points_line_ != 0) {
      header_.points = points_;
    } else if (width_line_ != 0) {
      const uint64_t h = height_line_ != 0 ? height_ : 1;
      if (width_ != 0 && h > std::numeric_limits<uint64_t>::max() / width_)
        return headerError(width_line_, "WIDTH × HEIGHT overflows");
      header_.points = width_ * h;
    } else {
      return headerError(data_line, "the header has neither POINTS nor WIDTH: the point count is unknown");
    }
    bool seen[3] = {false, false, false};
    size_t offset = 0;
    for (size_t k = 0; k < names_.size(); ++k) {
      Field f;
      f.name = std::string(names_[k]);
      f.type = types_[k];
      f.size = sizes_[k];
      f.count = counts_[k];
      f.offset = offset;
      const std::string field = "field " + quotedExcerpt(f.name) + ": ";
      if (f.type == 'F' && f.size != 4 && f.size != 8)
        return headerError(size_line_, field + "TYPE F with SIZE " + std::to_string(f.size) + " (floats are 4 or 8 bytes)");
      if (f.name == "x" || f.name == "y" || f.name == "z") {
        const int axis = f.name[0] - 'x';
        f.role = static_cast<Role>(axis);
        if (seen[axis]) return headerError(fields_line_, "field " + quotedExcerpt(f.name) + " appears twice");
        seen[axis] = true;
      } else if (f.name == "rgb" || f.name == "rgba") {
        if (header_.colors) return headerError(fields_line_, "two colour fields (rgb, rgba)");
        if (f.size != 4) return headerError(size_line_, field + "SIZE " + std::to_string(f.size) + " (packed colours are 4 bytes)");
        f.role = Role::kRgb;
        f.rgba = f.name == "rgba";
        header_.colors = true;
        header_.alpha = f.rgba;
      } else if (f.name == "_") {
        f.role = Role::kSkip;
      } else {
        f.role = Role::kDimension;
      }
      if (f.role != Role::kDimension && f.role != Role::kSkip && f.count != 1)
        return headerError(count_line_, field + "COUNT " + std::to_string(f.count) + " (must be 1)");
      offset += f.bytes();
      header_.fields.push_back(std::move(f));
    }
    if (!seen[0] || !seen[1])
      return headerError(fields_line_, std::string("no ") + (seen[0] ? "y" : "x") + " field (FIELDS must name x and y)");
    header_.has_z = seen[2];
    header_.row_bytes = offset;
    // Dimensions: normals as dpoint names them, a field of COUNT n as n columns, alpha after.
    for (Field& f : header_.fields) {
      if (f.role != Role::kDimension) continue;
      f.dimension = header_.dimensions.size();
      std::string name = f.name == "normal_x" ? "nx" : f.name == "normal_y" ? "ny" : f.name == "normal_z" ? "nz" : f.name;
      for (uint32_t c = 0; c < f.count; ++c)
        header_.dimensions.emplace_back(f.count == 1 ? name : name + "_" + std::to_string(c), dimTypeOf(f.type, f.size));
    }
    if (header_.alpha) header_.dimensions.emplace_back("alpha", DimType::kU8);
    if (header_.dimensions.size() > kMaxValues)
      return headerError(count_line_ ? count_line_ : fields_line_,
                         std::to_string(header_.dimensions.size()) + " values per point; dpoint reads at most " +
                             std::to_string(kMaxValues));
    std::unordered_set<std::string_view> names;
    for (const auto& [name, type] : header_.dimensions)
      if (!names.insert(name).second)
        return headerError(fields_line_, "two fields give the attribute " + quotedExcerpt(name));
    return okStatus();
  }

  const InputFile& file_;
  const std::string& path_;
  Header header_;
  int line_ = 0;
  bool any_entry_ = false, data_seen_ = false;
  std::vector<std::string_view> names_;
  std::vector<int> sizes_;
  std::vector<char> types_;
  std::vector<uint32_t> counts_;
  uint64_t width_ = 0, height_ = 0, points_ = 0;
  int fields_line_ = 0, size_line_ = 0, type_line_ = 0, count_line_ = 0, width_line_ = 0, height_line_ = 0,
      points_line_ = 0;
};

// The point set being filled: point i's columns.
class Columns {
 public:
  explicit Columns(PointSet& points) : points_(points) {
    for (Dimension& d : points.dimensions.all()) {
      dims_.push_back(d.bytes.data());
      widths_.push_back(dimTypeSize(d.type));
    }
  }

  // Field f of point i from its bytes at p (one value after another, f.count of them).
  void store(const Field& f, const uint8_t* p, size_t i) {
    switch (f.role) {
      case Role::kX:
      case Role::kY:
      case Role::kZ: points_.positions[i][static_cast<int>(f.role)] = loadNumber(p, f.type, f.size); break;
      case Role::kRgb: storeColor(loadUnaligned<uint32_t>(p), i, f.rgba); break;
      case Role::kSkip: break;
      case Role::kDimension: {
        const size_t w = widths_[f.dimension];
        for (uint32_t c = 0; c < f.count; ++c) std::memcpy(dims_[f.dimension + c] + i * w, p + c * w, w);
        break;
      }
    }
  }
  void storeColor(uint32_t packed, size_t i, bool rgba) {
    points_.colors[i] = glm::vec3(static_cast<float>((packed >> 16) & 255u) / 255.0f,
                                  static_cast<float>((packed >> 8) & 255u) / 255.0f,
                                  static_cast<float>(packed & 255u) / 255.0f);
    if (rgba) dims_.back()[i] = static_cast<uint8_t>(packed >> 24);
  }
  uint8_t* dimension(size_t k) { return dims_[k]; }
  const glm::dvec3& position(size_t i) const { return points_.positions[i]; }

 private:
  PointSet& points_;
  std::vector<uint8_t*> dims_;
  std::vector<size_t> widths_;
};

class Reader {
 public:
  Reader(const InputFile& file, const PcdReadOptions& options) : file_(file), path_(file.path()), options_(options) {}

  Result<PointSet> read() {
    Result<Header> header = HeaderParser(file_).parse();
    if (!header) return header.error();
    h_ = std::move(*header);
    const uint64_t n = h_.points;
    const uint64_t remaining = file_.size() - h_.data_offset;
    // The data must be able to hold the points before anything is allocated.
    if (h_.data == Data::kBinary && h_.row_bytes != 0 && n > remaining / h_.row_bytes)
      return Error{path_ + ": truncated: POINTS " + std::to_string(n) + " need " + std::to_string(h_.row_bytes) +
                   " bytes each after the header (byte " + std::to_string(h_.data_offset) + "), the file has " +
                   std::to_string(remaining)};
    size_t dim_bytes = 0;
    for (const auto& [name, type] : h_.dimensions) dim_bytes += dimTypeSize(type);
    const uint64_t per_point = sizeof(glm::dvec3) + (h_.colors ? sizeof(glm::vec3) : 0) + dim_bytes;
    if (per_point != 0 && n > std::numeric_limits<uint64_t>::max() / 2 / per_point)
      return Error{path_ + ": POINTS " + std::to_string(n) + " is beyond any memory", ExitCode::kResourceLimit};
    size_t values = 0;
    for (const Field& f : h_.fields) values += f.count;
    // ASCII: each value takes a character and a separator. Checked only where the set would be large,
    // so that a small file's error names its line.
    if (h_.data == Data::kAscii && n * per_point > (uint64_t{16} << 20) && n > (remaining + 1) / (2 * values))
      return Error{path_ + ": truncated: POINTS " + std::to_string(n) + " rows of " + std::to_string(values) +
                   " values cannot fit in the " + std::to_string(remaining) + " bytes after the header"};
    uint32_t compressed = 0, uncompressed = 0;
    if (h_.data == Data::kCompressed) {
      uint8_t sizes[8];
      Result<size_t> got = file_.readAt(h_.data_offset, sizes, sizeof sizes);
      if (!got) return got.error();
      if (*got < sizeof sizes)
        return Error{path_ + ": truncated at byte " + std::to_string(file_.size()) +
                     ": binary_compressed data starts with its two sizes (8 bytes)"};
      compressed = loadUnaligned<uint32_t>(sizes);
      uncompressed = loadUnaligned<uint32_t>(sizes + 4);
      if (compressed > remaining - 8)
        return Error{path_ + ": truncated: the compressed data is " + std::to_string(compressed) + " bytes, the file has " +
                     std::to_string(remaining - 8) + " after the header"};
      if (n > uint64_t{0xFFFFFFFFu} / h_.row_bytes || uncompressed != n * h_.row_bytes)
        return Error{path_ + ": byte " + std::to_string(h_.data_offset + 4) + ": the uncompressed size " +
                     std::to_string(uncompressed) + " is not POINTS × bytes per point (" + std::to_string(n) + " × " +
                     std::to_string(h_.row_bytes) + ")"};
    }
    if (Status s = checkMemory(path_ + ": " + std::to_string(n) + " points",
                               n * per_point + uint64_t{compressed} + uncompressed, options_.max_memory);
        !s)
      return s.error();
    // LZF gives at most 88 bytes for 3 (a back-reference of 264): a header declaring more was taken
    // at its word, gigabytes allocated and filled before the short data were found out (a review
    // finding: 19 s and 3.5 GB for a 136-byte file). (No data at all has its own message.)
    if (compressed != 0 && uint64_t{uncompressed} > uint64_t{compressed} * 88)
      return Error{path_ + ": byte " + std::to_string(h_.data_offset + 4) + ": " + std::to_string(compressed) +
                   " bytes of LZF data cannot give the " + std::to_string(uncompressed) +
                   " the header declares (LZF expands at most 88 times)"};

    PointSet points;
    const size_t count = static_cast<size_t>(n);
    // Rows write the coordinates they have fields for: without a z field, z is 0 from here on (the
    // finiteness checks read it before the end), not whatever the unset memory held.
    if (h_.has_z)
      resizePrefaulted(points.positions, count, options_.threads);
    else
      points.positions.assign(count, glm::dvec3(0.0));
    if (h_.colors) points.colors.resize(count);
    // Every value of every column is stored by its row (Columns::store), so none is zeroed first.
    for (const auto& [name, type] : h_.dimensions) points.dimensions.appendUnset(name, type, count);
    points.color_full_scale = h_.colors ? 255 : 0;
    points.z_axis = h_.has_z && !h_.two_d ? ZAxis::kPresent : ZAxis::kAbsent;
    points.z_up = h_.z_up;
    points.crs = h_.crs.take(path_, "# dpoint: crs", options_.notices);
    if (options_.progress) options_.progress->start("reading " + path_, n);

    Columns columns(points);
    Status decoded = h_.data == Data::kAscii    ? readAscii(columns, n)
                     : h_.data == Data::kBinary ? readBinary(columns, n)
                                                : readCompressed(columns, n, compressed, uncompressed);
    if (!decoded) return decoded.error();
    if (options_.progress) options_.progress->finish();
    if (Status s = dropNanPoints(points); !s) return s.error();
    if (h_.has_z && h_.two_d)  // without a z field, z is 0 already
      for (glm::dvec3& p : points.positions) p.z = 0.0;
    points.viewpoint = h_.pose;
    if (options_.notices && !h_.viewpoint.empty())
      options_.notices->push_back(path_ + ": " + h_.viewpoint +
                                  " is not applied to the points (as PCL's loaders do not): they are in the sensor's "
                                  "frame" + (h_.pose ? "; a PCD output gets the viewpoint back, other formats have no place for it"
                                                     : "; it is not finite, so no output gets it"));
    return points;
  }

 private:
  // Where point i's row starts, for messages.
  std::string where(uint64_t i) const {
    if (h_.data == Data::kBinary) return "byte " + std::to_string(h_.data_offset + i * h_.row_bytes) + ": point " + std::to_string(i);
    return "point " + std::to_string(i) + " (of the decompressed data)";
  }

  // An infinite coordinate (NaN is an empty place, dropped) is an error unless allowed.
  static bool isInfinite(const glm::dvec3& p) { return std::isinf(p.x) || std::isinf(p.y) || std::isinf(p.z); }
  Status checkFinite(const glm::dvec3& p, const std::string& where) const {
    if (options_.allow_nonfinite) return okStatus();
    const int axis = std::isinf(p.x) ? 0 : std::isinf(p.y) ? 1 : 2;
    return Error{path_ + ": " + where + ": " + static_cast<char>('x' + axis) + " is " + (p[axis] > 0 ? "inf" : "-inf") +
                 ", not a finite number (--allow-nonfinite accepts it)"};
  }

  // Points whose x, y or z is NaN are the format's empty places (an organized cloud's pixels with no
  // return): dropped, counted in a notice. An infinite coordinate is an error unless allowed.
  Status dropNanPoints(PointSet& points) {
    const size_t n = points.size();
    size_t kept = 0;
    for (size_t i = 0; i < n; ++i) {
      const glm::dvec3& p = points.positions[i];
      if (std::isnan(p.x) || std::isnan(p.y) || (h_.has_z && std::isnan(p.z))) continue;
      if (h_.data != Data::kAscii && isInfinite(p))  // ASCII rows were checked as they were read
        if (Status s = checkFinite(p, where(i)); !s) return s;
      if (kept != i) {
        points.positions[kept] = p;
        if (!points.colors.empty()) points.colors[kept] = points.colors[i];
        for (Dimension& d : points.dimensions.all()) d.copyFrom(kept, d, i);
      }
      ++kept;
    }
    if (kept == n) return okStatus();
    points.positions.resize(kept);
    if (!points.colors.empty()) points.colors.resize(kept);
    points.dimensions.resize(kept);
    if (options_.notices)
      options_.notices->push_back(path_ + ": dropped " + std::to_string(n - kept) + " of " + std::to_string(n) +
                                  " points whose x, y or z is NaN (no return)");
    return okStatus();
  }

  Status readBinary(Columns& columns, uint64_t n) {
    const uint64_t blocks = (n + kBlock - 1) / kBlock;
    const unsigned threads = resolveThreads(options_.threads);
    std::vector<std::vector<uint8_t>> buffers(threads);
    std::vector<Status> status(static_cast<size_t>(blocks), okStatus());
    parallelFor(static_cast<size_t>(blocks), threads, [&](size_t b, unsigned worker) {
      const uint64_t first = b * kBlock, rows = std::min<uint64_t>(kBlock, n - first);
      std::vector<uint8_t>& buf = buffers[worker];
      buf.resize(static_cast<size_t>(rows * h_.row_bytes));
      Result<size_t> got = file_.readAt(h_.data_offset + first * h_.row_bytes, buf.data(), buf.size());
      if (!got) {
        status[b] = got.error();
        return;
      }
      for (uint64_t r = 0; r < rows; ++r) {
        const uint8_t* row = buf.data() + r * h_.row_bytes;
        for (const Field& f : h_.fields) columns.store(f, row + f.offset, static_cast<size_t>(first + r));
      }
      if (options_.progress) options_.progress->advance(rows);
    });
    for (Status& s : status)
      if (!s) return s;
    return okStatus();
  }

  Status readCompressed(Columns& columns, uint64_t n, uint32_t compressed, uint32_t uncompressed) {
    // No LZF data for a non-empty block: lzf_decompress would read a first byte that is not there.
    if (compressed == 0 && uncompressed != 0)
      return Error{path_ + ": byte " + std::to_string(h_.data_offset) + ": a compressed size of 0 for the " +
                   std::to_string(uncompressed) + " bytes the header declares"};
    std::vector<uint8_t> in(compressed), out(uncompressed);
    Result<size_t> got = file_.readAt(h_.data_offset + 8, in.data(), in.size());
    if (!got) return got.error();
    if (uncompressed != 0) {
      const unsigned int made = lzf_decompress(in.data(), compressed, out.data(), uncompressed);
      if (made != uncompressed)
        return Error{path_ + ": byte " + std::to_string(h_.data_offset + 8) + ": the LZF data " +
                     (made == 0 ? std::string("is corrupt") : "gives " + std::to_string(made) + " bytes") +
                     ", not the " + std::to_string(uncompressed) + " the header declares"};
    }
    std::vector<uint8_t>().swap(in);
    // The fields one after another: field f of point i at n · f.offset + i · f.bytes().
    const uint64_t blocks = (n + kBlock - 1) / kBlock;
    parallelFor(static_cast<size_t>(blocks), options_.threads, [&](size_t b, unsigned) {
      const uint64_t first = b * kBlock, last = std::min<uint64_t>(first + kBlock, n);
      for (const Field& f : h_.fields) {
        const uint8_t* column = out.data() + n * f.offset;
        for (uint64_t i = first; i < last; ++i) columns.store(f, column + i * f.bytes(), static_cast<size_t>(i));
      }
      if (options_.progress) options_.progress->advance(last - first);
    });
    return okStatus();
  }

  // ASCII rows on all cores, in blocks of the data. A first pass counts each block's lines and rows
  // (lines neither blank nor a # comment; a line belongs to the block it starts in), so that each
  // block knows its first line's number and its first row's point; the second parses its rows into
  // their points. Each block stops at its first error and the first by line is reported, as reading
  // the lines in order found it.
  Status readAscii(Columns& columns, uint64_t n) {
    std::vector<std::pair<const Field*, uint32_t>> slots;  // value column → field and component
    for (const Field& f : h_.fields)
      for (uint32_t c = 0; c < f.count; ++c) slots.emplace_back(&f, c);
    const uint64_t begin = h_.data_offset, size = file_.size();
    const size_t blocks = static_cast<size_t>((size - std::min(begin, size) + kAsciiChunk - 1) / kAsciiChunk);
    const unsigned threads = resolveThreads(options_.threads);
    std::vector<std::string> buffers(threads);
    auto isBlankByte = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
    // Reads block b with the byte before it and up to a longest line after it; calls line(text, k)
    // for the k-th line starting in the block (text without its newline) until it returns false.
    // Returns false, with `long_line` the index k, where a line does not end within kAsciiMaxLineBytes.
    auto forEachLine = [&](size_t b, unsigned worker, const auto& line, std::optional<uint64_t>& long_line,
                           Status& io) -> bool {
      const uint64_t start = begin + b * kAsciiChunk, stop_at = std::min<uint64_t>(start + kAsciiChunk, size);
      const uint64_t read_start = start == begin ? start : start - 1;
      const uint64_t read_end = std::min<uint64_t>(stop_at + kAsciiMaxLineBytes + 1, size);
      std::string& buffer = buffers[worker];
      buffer.resize(static_cast<size_t>(read_end - read_start));
      Result<size_t> got = file_.readAt(read_start, buffer.data(), buffer.size());
      if (!got) {
        io = got.error();
        return false;
      }
      if (*got != buffer.size()) {  // the file shrank since it was opened
        io = Error{path_ + ": the file changed while it was read (shorter than when it was opened)"};
        return false;
      }
      const char* data = buffer.data();
      const char* stop = data + (stop_at - read_start);  // lines must start before this
      const char* end = data + buffer.size();
      const char* p = data;
      if (read_start != start) {
        ++p;
        if (data[0] != '\n') {  // the line at `start` began in the block before
          const char* nl = static_cast<const char*>(std::memchr(p, '\n', static_cast<size_t>(stop - p)));
          if (!nl) return true;  // no line starts in this block
          p = nl + 1;
        }
      }
      for (uint64_t k = 0; p < stop; ++k) {
        const char* nl = static_cast<const char*>(std::memchr(p, '\n', static_cast<size_t>(end - p)));
        if (!nl && read_end < size) {
          long_line = k;
          return false;
        }
        const char* line_end = nl ? nl : end;
        if (!line(std::string_view(p, static_cast<size_t>(line_end - p)), k)) return false;
        if (!nl) break;
        p = nl + 1;
      }
      return true;
    };
    auto isRow = [&](std::string_view text) {
      size_t i = 0;
      while (i < text.size() && isBlankByte(text[i])) ++i;
      return i < text.size() && text[i] != '#';
    };

    // Pass 1: lines and rows per block; a line too long stops the count there.
    std::vector<uint64_t> lines(blocks + 1, 0), rows(blocks + 1, 0);
    std::vector<std::optional<uint64_t>> long_line(blocks);
    std::vector<Status> io(blocks, okStatus());
    parallelFor(blocks, threads, [&](size_t b, unsigned worker) {
      forEachLine(
          b, worker,
          [&](std::string_view text, uint64_t) {
            ++lines[b + 1];
            rows[b + 1] += isRow(text) ? 1 : 0;
            return true;
          },
          long_line[b], io[b]);
    });
    for (size_t b = 0; b < blocks; ++b) {
      if (!io[b]) return io[b];
      lines[b + 1] += lines[b];
      rows[b + 1] += rows[b];
    }
    // Lines from a too-long one on are not read; it is the error unless one before it fails.
    size_t last_block = blocks;
    uint64_t long_at = UINT64_MAX;  // its line number
    for (size_t b = 0; b < blocks && last_block == blocks; ++b)
      if (long_line[b]) {
        last_block = b;
        long_at = h_.lines + lines[b] + *long_line[b] + 1;
      }

    // Pass 2: each block's rows into their points.
    std::mutex error_mutex;
    std::optional<std::pair<uint64_t, Error>> first_error;  // line, error
    std::atomic<uint64_t> error_line{UINT64_MAX};
    auto fail = [&](uint64_t line, Error e) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (!first_error || line < first_error->first) {
        error_line = line;
        first_error = std::make_pair(line, std::move(e));
      }
    };
    parallelFor(std::min(blocks, last_block + 1), threads, [&](size_t b, unsigned worker) {
      if (h_.lines + lines[b] + 1 > error_line.load()) return;
      std::vector<std::string_view> tokens;
      uint8_t value[8];
      uint64_t point = rows[b];
      std::optional<uint64_t> unused_long;
      Status unused_io = okStatus();
      forEachLine(
          b, worker,
          [&](std::string_view text, uint64_t k) -> bool {
            const uint64_t line = h_.lines + lines[b] + k + 1;
            if (line >= long_at) return false;
            if (!isRow(text)) return true;
            tokens = tokensOf(text);
            if (point == n) {
              fail(line, Error{path_ + ": line " + std::to_string(line) + ": more rows than the header's POINTS " +
                               std::to_string(n)});
              return false;
            }
            if (tokens.size() != slots.size()) {
              fail(line, Error{path_ + ": line " + std::to_string(line) + ": " + std::to_string(tokens.size()) +
                               " values; the header's fields need " + std::to_string(slots.size())});
              return false;
            }
            for (size_t t = 0; t < slots.size(); ++t) {
              const auto [field, component] = slots[t];
              if (field->role == Role::kSkip) continue;
              if (Status s = parseValue(*field, tokens[t], value); !s) {
                fail(line, Error{path_ + ": line " + std::to_string(line) + ", column " + std::to_string(t + 1) +
                                 " (field " + quotedExcerpt(field->name) + "): " + quotedExcerpt(tokens[t]) + " " +
                                 s.error().message});
                return false;
              }
              if (field->role == Role::kDimension) {
                const size_t w = static_cast<size_t>(field->size);
                std::memcpy(columns.dimension(field->dimension + component) + point * w, value, w);
              } else {
                columns.store(*field, value, static_cast<size_t>(point));
              }
            }
            if (const glm::dvec3& p = columns.position(static_cast<size_t>(point)); isInfinite(p))
              if (Status s = checkFinite(p, "line " + std::to_string(line) + ": point " + std::to_string(point)); !s) {
                fail(line, s.error());
                return false;
              }
            ++point;
            return true;
          },
          unused_long, unused_io);
      if (options_.progress) options_.progress->advance(point - rows[b]);
    });
    if (first_error) return first_error->second;
    if (long_at != UINT64_MAX)
      return Error{path_ + ": line " + std::to_string(long_at) + ": longer than " + std::to_string(kAsciiMaxLineBytes) +
                   " bytes"};
    if (rows[blocks] < n)
      return Error{path_ + ": line " + std::to_string(h_.lines + lines[blocks]) + ": the file ends after " +
                   std::to_string(rows[blocks]) + " of the " + std::to_string(n) + " points the header declares"};
    return okStatus();
  }

  static Status parseValue(const Field& f, std::string_view token, uint8_t* out) {
    const char* b = token.data();
    const char* e = b + token.size();
    if (f.role == Role::kRgb && f.type != 'F') {  // rgba, or rgb as PCL 1.13 writes it in ASCII (TYPE U)
      uint64_t packed = 0;
      int32_t signed_packed = 0;
      if (parseDecimalU64(token, packed)) {
        if (packed > 0xFFFFFFFFu) return Error{"is beyond a packed 32-bit colour"};
        storeUnaligned(out, static_cast<uint32_t>(packed));
      } else if (allDecimalDigits(token)) {  // past 2^64
        return Error{"is beyond a packed 32-bit colour"};
      } else if (auto r = std::from_chars(b, e, signed_packed); r.ec == std::errc() && r.ptr == e) {
        storeUnaligned(out, signed_packed);
      } else {
        return Error{"is not a packed colour"};
      }
      return okStatus();
    }
    b = afterPlusSign(b, e);
    if (f.type == 'F') {
      // A number past the field's range is no infinity ("1e39" in an F 4 field was reported as
      // "y is inf"); below it, zero, as PCL's strtod reads it.
      const auto parse = [&](auto& v) -> Status {
        auto r = fast_float::from_chars(b, e, v);
        if (r.ec != std::errc() || r.ptr != e) return Error{"is not a number"};
        const bool written_infinite = std::find_if(b, e, [](char c) { return c == 'i' || c == 'I'; }) != e;
        if (std::isinf(v) && !written_infinite)
          return Error{"is out of the field's range (F " + std::to_string(f.size) + ")"};
        storeUnaligned(out, v);
        return okStatus();
      };
      if (f.size == 4) {
        float v = 0;
        return parse(v);
      }
      double v = 0;
      return parse(v);
    }
    // Integers: as written, or a float form with no fraction ("3.0", "1e3").
    int64_t i = 0;
    uint64_t u = 0;
    bool whole = false;
    if (f.type == 'U') {
      auto r = std::from_chars(b, e, u);
      whole = r.ec == std::errc() && r.ptr == e;
    } else {
      auto r = std::from_chars(b, e, i);
      whole = r.ec == std::errc() && r.ptr == e;
    }
    if (!whole) {
      double d = 0;
      auto r = fast_float::from_chars(b, e, d);
      if (r.ec != std::errc() || r.ptr != e) return Error{"is not a number"};
      if (!std::isfinite(d) || d != std::floor(d)) return Error{"is not a whole number (the field is TYPE " + std::string(1, f.type) + ")"};
      if (f.type == 'U') {
        if (d < 0 || d >= 18446744073709551616.0) return Error{"is out of the field's range"};
        u = static_cast<uint64_t>(d);
      } else {
        if (d < -9223372036854775808.0 || d >= 9223372036854775808.0) return Error{"is out of the field's range"};
        i = static_cast<int64_t>(d);
      }
    }
    const int bits = 8 * f.size;
    if (f.type == 'U') {
      if (bits < 64 && u >> bits) return Error{"is out of the field's range (U " + std::to_string(f.size) + ")"};
      switch (f.size) {
        case 1: out[0] = static_cast<uint8_t>(u); break;
        case 2: storeUnaligned(out, static_cast<uint16_t>(u)); break;
        case 4: storeUnaligned(out, static_cast<uint32_t>(u)); break;
        default: storeUnaligned(out, u); break;
      }
    } else {
      if (bits < 64 && (i < -(int64_t{1} << (bits - 1)) || i >= (int64_t{1} << (bits - 1))))
        return Error{"is out of the field's range (I " + std::to_string(f.size) + ")"};
      switch (f.size) {
        case 1: out[0] = static_cast<uint8_t>(static_cast<int8_t>(i)); break;
        case 2: storeUnaligned(out, static_cast<int16_t>(i)); break;
        case 4: storeUnaligned(out, static_cast<int32_t>(i)); break;
        default: storeUnaligned(out, i); break;
      }
    }
    return okStatus();
  }

  const InputFile& file_;
  const std::string& path_;
  const PcdReadOptions& options_;
  Header h_;
};

}  // namespace

Result<PcdEncoding> parsePcdEncoding(std::string_view text) {
  if (text == "ascii") return PcdEncoding::kAscii;
  if (text == "binary") return PcdEncoding::kBinary;
  if (text == "binary_compressed") return PcdEncoding::kBinaryCompressed;
  return Error{"PCD encoding " + quotedExcerpt(text) + " is not ascii, binary or binary_compressed", ExitCode::kUsage};
}

const char* pcdEncodingName(PcdEncoding encoding) {
  switch (encoding) {
    case PcdEncoding::kAscii: return "ascii";
    case PcdEncoding::kBinary: return "binary";
    case PcdEncoding::kBinaryCompressed: return "binary_compressed";
  }
  return "binary";
}

Result<PointSet> readPcd(const InputFile& file, const PcdReadOptions& options) { return Reader(file, options).read(); }

Result<PointSet> readPcd(const std::string& path, const PcdReadOptions& options) {
  Result<InputFile> file = InputFile::open(path);
  if (!file) return file.error();
  return readPcd(*file, options);
}

}  // namespace dpoint
