// PCD writing (converters/pcd.h): the v0.7 header, then ASCII rows, binary rows, or the fields one
// after another compressed with LZF (liblzf), as PCL writes binary_compressed.
#include <lzf.h>

#include <algorithm>
#include <charconv>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <unordered_set>
#include <utility>
#include <vector>

#include "converters/pcd.h"
#include "core/atomic_file.h"
#include "core/bytes.h"
#include "core/ordered_write.h"
#include "core/text.h"

namespace dpoint {
namespace {

constexpr size_t kRowsPerWrite = size_t{1} << 14;

enum class Source : uint8_t { kX, kY, kZ, kRgb, kDimension };

struct OutField {
  std::string name;
  char type = 'F';
  int size = 4;
  Source source = Source::kDimension;
  const Dimension* dimension = nullptr;
};

// Fields written as one: a run of dimensions NAME_0 … NAME_n-1 of one type (a PCD field of COUNT n
// as the reader names its values: an FPFH's 33) is the field NAME with COUNT n again, which PCL's
// typed loaders look for. Binary and ASCII rows lay the values out as the n fields would;
// binary_compressed keeps each point's n values together.
struct FieldGroup {
  std::string name;
  size_t first = 0, count = 1;  // fields_[first, first + count)
};

// NAME where `name` is NAME_k, with k its index; nullopt otherwise.
std::optional<std::string> countBase(const std::string& name, size_t k) {
  std::string suffix(1, '_');  // appended: GCC 12's -Wrestrict misfires on "_" + std::string under -O2
  suffix += std::to_string(k);
  if (name.size() <= suffix.size() || name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
    return std::nullopt;
  return name.substr(0, name.size() - suffix.size());
}

char pcdTypeOf(DimType type) { return dimTypeIsFloat(type) ? 'F' : dimTypeIsSigned(type) ? 'I' : 'U'; }

// PCL's name of a dimension: its normals' own, the others their names.
std::string fieldName(const std::string& name) {
  if (name == "nx") return "normal_x";
  if (name == "ny") return "normal_y";
  if (name == "nz") return "normal_z";
  return name;
}

bool exactlyFloat(double v) { return static_cast<double>(static_cast<float>(v)) == v || v != v; }

class Writer {
 public:
  Writer(const std::string& path, const PointSet& points, const PcdWriteOptions& options)
      : path_(path), points_(points), options_(options), has_z_(points.hasZ()) {}

  Status write() {
    const size_t n = points_.size();
    if (points_.hasColors() && points_.colors.size() != n)
      return Error{"cannot write '" + path_ + "': " + std::to_string(points_.colors.size()) + " colours for " +
                   std::to_string(n) + " points"};
    if (Status s = plan(); !s) return s;
    for (const OutField& f : fields_) row_bytes_ += static_cast<size_t>(f.size);
    if (options_.encoding == PcdEncoding::kBinaryCompressed &&
        static_cast<uint64_t>(n) * row_bytes_ > std::numeric_limits<uint32_t>::max() / 17 * 16)
      return Error{"cannot write '" + path_ + "': binary_compressed holds at most 4 GiB of point data (its sizes are 32-bit); " +
                   std::to_string(n) + " points of " + std::to_string(row_bytes_) + " bytes are more: write binary"};
    Result<AtomicFile> file = AtomicFile::create(path_);
    if (!file) return file.error();
    const std::string head = header();
    // binary: the file's size; ASCII: at least a digit and a separator a value; compressed: unknown.
    if (options_.encoding != PcdEncoding::kBinaryCompressed) {
      const uint64_t row = options_.encoding == PcdEncoding::kBinary
                               ? row_bytes_
                               : AtomicFile::kLeastTextBytesPerValue * fields_.size();
      if (Status s = file->checkSpace(head.size() + uint64_t{n} * row); !s) return s;
    }
    if (Status s = file->write(head); !s) return s;
    if (options_.progress) options_.progress->start("writing " + path_, n);
    Status body = options_.encoding == PcdEncoding::kAscii    ? writeAscii(*file)
                  : options_.encoding == PcdEncoding::kBinary ? writeBinary(*file)
                                                              : writeCompressed(*file);
    if (!body) return body;
    return file->commit();
  }

 private:
  Status plan() {
    // x y z as float when every coordinate is one, else double.
    bool single = true;
    for (const glm::dvec3& p : points_.positions)
      if (!exactlyFloat(p.x) || !exactlyFloat(p.y) || !exactlyFloat(p.z)) {
        single = false;
        break;
      }
    for (int axis = 0; axis < 3; ++axis) fields_.push_back({std::string(1, static_cast<char>('x' + axis)), 'F', single ? 4 : 8, static_cast<Source>(axis), nullptr});
    if (!single && options_.notices)
      options_.notices->push_back(path_ + ": x, y and z written as double (PCD TYPE F SIZE 8) to keep every coordinate; "
                                  "PCL's typed loaders such as pcl::PointXYZ want float and leave double fields at 0, "
                                  "and Open3D reads them as 0 from binary data (it reads --pcd-encoding ascii exactly)");
    alpha_ = nullptr;
    if (points_.hasColors()) {
      const Dimension* alpha = points_.dimensions.find("alpha");
      alpha_ = alpha && alpha->type == DimType::kU8 ? alpha : nullptr;
      fields_.push_back({alpha_ ? "rgba" : "rgb", alpha_ ? 'U' : 'F', 4, Source::kRgb, nullptr});
    }
    // Field names are one word each, none the position's or colour's, none twice (writableNames).
    std::vector<std::string> names;
    std::vector<const Dimension*> dims;
    for (const Dimension& d : points_.dimensions.all())
      if (&d != alpha_) names.push_back(fieldName(d.name)), dims.push_back(&d);
    // normal_x is nx's where the set has both (a reader takes normal_x as nx), so the dimension
    // named normal_x is the one renamed: normal_taking(own) is the dimension (nx, ny, nz) that
    // takes the PCL name `own` from the dimension so named, or "".
    const auto normal_taking = [&](const std::string& own) {
      if (own != "normal_x" && own != "normal_y" && own != "normal_z") return std::string();
      std::string normal(1, 'n');  // appended: GCC 12's -Wrestrict misfires on "n" + std::string
      normal += own.back();
      return points_.dimensions.find(normal) ? normal : std::string();
    };
    names = writableNames(
        names, isSpaceOrControl,
        [&](const std::string& name, size_t k) {
          // "_" is PCD's padding: every reader passes over such a field.
          if (name == "x" || name == "y" || name == "z" || name == "rgb" || name == "rgba" || name == "_") return true;
          return name == dims[k]->name && !normal_taking(dims[k]->name).empty();
        },
        nullptr);
    // Each change named by the dimension's own name (writableNames would name PCL's: nx as normal_x).
    std::vector<std::string> renamed;
    for (size_t k = 0; k < dims.size(); ++k) {
      if (names[k] == fieldName(dims[k]->name)) continue;
      const std::string taker = normal_taking(dims[k]->name);
      renamed.push_back("dimension " + quotedExcerpt(dims[k]->name) + " written as " + quotedExcerpt(names[k]) +
                        (!taker.empty() ? " (" + taker + " is written as " + dims[k]->name + ", PCL's name for it)"
                                        : std::string(" (a PCD field's name is one word, not x, y, z, rgb, rgba or _)")));
    }
    for (size_t k = 0; k < dims.size(); ++k)
      fields_.push_back({names[k], pcdTypeOf(dims[k]->type), static_cast<int>(dimTypeSize(dims[k]->type)),
                         Source::kDimension, dims[k]});
    if (options_.notices && points_.hasColors() && points_.color_full_scale == 65535)
      options_.notices->push_back(path_ + ": 16-bit colours written as 8-bit (PCD's rgb holds 0..255 a channel)");
    if (options_.notices)
      for (const std::string& line : renamed)
        options_.notices->push_back(path_ + ": " + line);
    groupCounts();
    return okStatus();
  }

  // FieldGroup: each run of NAME_0, NAME_1, … of one type whose NAME is no other field's.
  void groupCounts() {
    std::unordered_set<std::string> names;
    for (const OutField& f : fields_) names.insert(f.name);
    for (size_t i = 0; i < fields_.size();) {
      const std::optional<std::string> base =
          fields_[i].source == Source::kDimension ? countBase(fields_[i].name, 0) : std::nullopt;
      size_t n = 1;
      if (base && !names.count(*base) && *base != "_")
        while (i + n < fields_.size() && fields_[i + n].source == Source::kDimension &&
               fields_[i + n].type == fields_[i].type && fields_[i + n].size == fields_[i].size &&
               countBase(fields_[i + n].name, n) == base)
          ++n;
      groups_.push_back({n > 1 ? *base : fields_[i].name, i, n});
      i += n;
    }
  }

  std::string header() const {
    const size_t n = points_.size();
    std::string h = "# .PCD v0.7 - Point Cloud Data file format\n# written by dpoint\n";
    if (!has_z_) h += "# dpoint: 2D (the source has x,y only; z is 0)\n";
    if (points_.z_up) h += "# dpoint: up axis z\n";
    // The coordinate system another format stated (E57's), byte for byte in hex over lines of at
    // most 800 digits (Open3D reads a header line of up to 1,024 bytes), for pcd_read.cpp.
    for (const std::string& piece : hexPieces(options_.crs ? *options_.crs : points_.crs, 400))
      h += "# dpoint: crs " + piece + '\n';
    h += "VERSION 0.7\nFIELDS";
    for (const FieldGroup& g : groups_) h += ' ' + g.name;
    h += "\nSIZE";
    for (const FieldGroup& g : groups_) h += ' ' + std::to_string(fields_[g.first].size);
    h += "\nTYPE";
    for (const FieldGroup& g : groups_) h += std::string(" ") + fields_[g.first].type;
    h += "\nCOUNT";
    for (const FieldGroup& g : groups_) h += ' ' + std::to_string(g.count);
    h += "\nWIDTH " + std::to_string(n) + "\nHEIGHT 1\nVIEWPOINT";
    for (const double v : points_.viewpoint.value_or(std::array<double, 7>{0, 0, 0, 1, 0, 0, 0})) h += ' ' + formatNumber(v);
    h += "\nPOINTS " + std::to_string(n) +
         "\nDATA " + pcdEncodingName(options_.encoding) + "\n";
    return h;
  }

  uint32_t packed(size_t i) const {
    const glm::vec3& c = points_.colors[i];
    uint32_t v = (uint32_t{colorInteger(c.r, 255.0)} << 16) | (uint32_t{colorInteger(c.g, 255.0)} << 8) |
                 colorInteger(c.b, 255.0);
    if (alpha_) v |= uint32_t{alpha_->get<uint8_t>(i)} << 24;
    return v;
  }

  // x, y or z of point i (z 0 for a 2D set).
  double coordinate(const OutField& f, size_t i) const {
    return f.source == Source::kZ && !has_z_ ? 0.0 : points_.positions[i][static_cast<int>(f.source)];
  }

  // Field f of point i as its bytes at out.
  void store(const OutField& f, size_t i, uint8_t* out) const {
    switch (f.source) {
      case Source::kX:
      case Source::kY:
      case Source::kZ: {
        const double v = coordinate(f, i);
        if (f.size == 4)
          storeUnaligned(out, static_cast<float>(v));
        else
          storeUnaligned(out, v);
        break;
      }
      case Source::kRgb: storeUnaligned(out, packed(i)); break;
      case Source::kDimension: {
        const size_t w = static_cast<size_t>(f.size);
        std::memcpy(out, f.dimension->bytes.data() + i * w, w);
        break;
      }
    }
  }

  Status writeBinary(AtomicFile& file) {
    const size_t n = points_.size();
    std::vector<uint8_t> rows;
    for (size_t first = 0; first < n; first += kRowsPerWrite) {
      const size_t count = std::min(kRowsPerWrite, n - first);
      rows.resize(count * row_bytes_);
      uint8_t* out = rows.data();
      for (size_t i = first; i < first + count; ++i)
        for (const OutField& f : fields_) {
          store(f, i, out);
          out += f.size;
        }
      if (Status s = file.write(rows.data(), rows.size()); !s) return s;
      if (options_.progress) options_.progress->advance(count);
    }
    return okStatus();
  }

  Status writeCompressed(AtomicFile& file) {
    const size_t n = points_.size();
    // The fields one after another (each field's values for every point, a point's COUNT values
    // together), then LZF.
    std::vector<uint8_t> columns(n * row_bytes_);
    uint8_t* out = columns.data();
    for (const FieldGroup& g : groups_)
      for (size_t i = 0; i < n; ++i)
        for (size_t k = g.first; k < g.first + g.count; ++k) {
          store(fields_[k], i, out);
          out += fields_[k].size;
        }
    std::vector<uint8_t> packed(columns.size() + columns.size() / 16 + 64);
    unsigned int made = 0;
    if (!columns.empty()) {
      made = lzf_compress(columns.data(), static_cast<unsigned int>(columns.size()), packed.data(),
                          static_cast<unsigned int>(packed.size()));
      if (made == 0) return Error{"cannot write '" + path_ + "': LZF compression failed"};
    }
    uint8_t sizes[8];
    storeUnaligned(sizes, static_cast<uint32_t>(made));
    storeUnaligned(sizes + 4, static_cast<uint32_t>(columns.size()));
    if (Status s = file.write(sizes, sizeof sizes); !s) return s;
    if (Status s = file.write(packed.data(), made); !s) return s;
    if (options_.progress) options_.progress->advance(n);
    return okStatus();
  }

  // A field's stored bytes as ASCII, by its PCD type: integers as integers, floats in shortest
  // round-trip form. So rgb (TYPE F) is the float whose bits are the colour, as PCL reads it, and
  // rgba (TYPE U) the integer.
  static void appendField(TextBuffer& text, const OutField& f, const uint8_t* p) {
    switch (f.type) {
      case 'F':
        if (f.size == 4)
          text.appendNumber(loadUnaligned<float>(p));
        else
          text.appendNumber(loadUnaligned<double>(p));
        break;
      case 'U':
        if (f.size == 8)
          text.appendNumber(loadUnaligned<uint64_t>(p));
        else
          text.appendNumber(f.size == 1 ? uint32_t{p[0]} : f.size == 2 ? uint32_t{loadUnaligned<uint16_t>(p)} : loadUnaligned<uint32_t>(p));
        break;
      default:
        if (f.size == 8)
          text.appendNumber(loadUnaligned<int64_t>(p));
        else
          text.appendNumber(f.size == 1   ? int32_t{static_cast<int8_t>(p[0])}
                            : f.size == 2 ? int32_t{loadUnaligned<int16_t>(p)}
                                          : loadUnaligned<int32_t>(p));
        break;
    }
  }

  // Rows formatted kAsciiRowsPerChunk at a time on all cores and written in order
  // (core/ordered_write.h): formatting the numbers was the whole cost, on one thread.
  Status writeAscii(AtomicFile& file) {
    constexpr size_t kAsciiRowsPerChunk = size_t{1} << 15;
    const size_t n = points_.size();
    auto rowsOf = [&](size_t k) { return std::make_pair(k * kAsciiRowsPerChunk, std::min(n, (k + 1) * kAsciiRowsPerChunk)); };
    return writeChunksInOrder(
        file, (n + kAsciiRowsPerChunk - 1) / kAsciiRowsPerChunk, options_.threads,
        [&](size_t k, std::vector<char>& bytes) -> Status {
          thread_local TextBuffer text;
          text.clear();
          const auto [first, last] = rowsOf(k);
          for (size_t i = first; i < last; ++i) {
            for (size_t f = 0; f < fields_.size(); ++f) {
              if (f) text.append(' ');
              uint8_t value[8];
              store(fields_[f], i, value);  // the binary writers' bytes, as text
              appendField(text, fields_[f], value);
            }
            text.append('\n');
          }
          bytes.assign(text.data(), text.data() + text.size());
          return okStatus();
        },
        [&](size_t k) {
          if (options_.progress) options_.progress->advance(rowsOf(k).second - rowsOf(k).first);
        });
  }

  const std::string& path_;
  const PointSet& points_;
  const PcdWriteOptions& options_;
  std::vector<OutField> fields_;
  std::vector<FieldGroup> groups_;
  const Dimension* alpha_ = nullptr;
  size_t row_bytes_ = 0;
  bool has_z_;  // PointSet::hasZ() once: for a set made in memory it looks at every point
};

}  // namespace

Status writePcd(const std::string& path, const PointSet& points, const PcdWriteOptions& options) {
  return Writer(path, points, options).write();
}

}  // namespace dpoint
