// PLY writing: `double x,y,z`, uchar or float colours, `face` lists of three uint indices.
// Rows are assembled into 1 MB chunks, then handed to AtomicFile.
#include <algorithm>
#include <charconv>
#include <cstring>
#include <string_view>
#include <vector>

#include "core/atomic_file.h"
#include "core/text.h"
#include "converters/ply.h"

namespace dpoint {

namespace {

constexpr size_t kWriteChunk = size_t{1} << 20;

// Colours leave as bytes (colorInteger of 255), or as 16-bit words for colours read so
// (PointSet::color_full_scale 65535: LAS).
uint8_t colorByte(float c) { return static_cast<uint8_t>(colorInteger(c, 255.0)); }
uint16_t colorWord(float c) { return colorInteger(c, 65535.0); }

// Header comments for the facts of the source that the values cannot tell (ply_read.cpp reads
// them back): a 2D set (its z are 0 but not a coordinate: read from 2D input, or made in memory with
// every z 0, as random2d and mandelbrot2d make theirs), and z as the up axis (LAS). Without the first,
// a 2D set written as PLY would come back as a 3D one and convert to a 3-column CSV.
std::string sourceFacts(const PointSet& points) {
  std::string facts;
  if (!points.hasZ()) facts += "comment dpoint: 2D (the source has x,y only; z is 0)\n";
  if (points.z_up) facts += "comment dpoint: up axis z\n";
  // Colours read as integers 0..255 from a text file (ply_read.cpp keeps them so for CSV).
  if (points.hasColors() && points.color_full_scale == 255 && !points.las) facts += "comment dpoint: colours 0..255\n";
  if (points.las) {  // ply_read.cpp reads it back, so that LAS → PLY → LAS keeps its coordinates
    const LasSource& l = *points.las;
    facts += "comment dpoint: las frame ";
    facts += std::to_string(l.point_format);
    facts += ' ';
    facts += std::to_string(l.version_minor);
    for (const glm::dvec3* v : {&l.scale, &l.offset})
      for (int k = 0; k < 3; ++k) {
        facts += ' ';
        facts += formatNumber((*v)[k]);
      }
    facts += '\n';
  }
  return facts;
}

class ChunkWriter {
 public:
  ChunkWriter(AtomicFile& file, Progress* progress) : file_(file), progress_(progress), buf_(kWriteChunk + 4096) {}
  void append(const void* data, size_t size) {
    if (used_ + size > buf_.size()) buf_.resize(used_ + size);
    std::memcpy(buf_.data() + used_, data, size);
    used_ += size;
  }
  void append(std::string_view text) { append(text.data(), text.size()); }
  // Ends a row; writes out a full chunk.
  Status endRow() {
    ++rows_;
    return used_ >= kWriteChunk ? flush() : okStatus();
  }
  Status flush() {
    Status s = file_.write(buf_.data(), used_);
    used_ = 0;
    if (progress_) progress_->advance(rows_);
    rows_ = 0;
    return s;
  }

 private:
  AtomicFile& file_;
  Progress* progress_;
  std::vector<char> buf_;
  size_t used_ = 0;
  uint64_t rows_ = 0;
};

template <typename T>
void appendNumber(ChunkWriter& out, T value, char separator) {
  char text[40];
  auto r = std::to_chars(text, text + sizeof text - 1, value);  // shortest round-trip form
  *r.ptr = separator;
  out.append(text, static_cast<size_t>(r.ptr + 1 - text));
}

// Value i of a dimension in ASCII: integers as integers, floats in shortest round-trip form.
void appendDimension(ChunkWriter& out, const Dimension& d, size_t i, char separator) {
  switch (d.type) {
    case DimType::kF32: appendNumber(out, d.get<float>(i), separator); break;
    case DimType::kF64: appendNumber(out, d.get<double>(i), separator); break;
    case DimType::kU64: appendNumber(out, d.get<uint64_t>(i), separator); break;
    case DimType::kI64: appendNumber(out, d.get<int64_t>(i), separator); break;
    default: appendNumber(out, static_cast<int64_t>(d.value(i)), separator); break;
  }
}

}  // namespace

Status writePly(const std::string& path, const PointSet& points, const PlyWriteOptions& options) {
  const size_t n = points.size();
  if (points.hasColors() && points.colors.size() != n)
    return Error{"cannot write '" + path + "': " + std::to_string(points.colors.size()) + " colours for " +
                 std::to_string(n) + " points"};
  if (points.triangles.size() % 3 != 0)
    return Error{"cannot write '" + path + "': triangle index count is not a multiple of 3"};
  for (uint32_t index : points.triangles)
    if (index >= n)
      return Error{"cannot write '" + path + "': triangle index " + std::to_string(index) + " out of range (" +
                   std::to_string(n) + " points)"};
  auto file = AtomicFile::create(path);
  if (!file.ok()) return file.error();
  const bool ascii = options.encoding == PlyEncoding::kAscii;
  const bool float_colors = options.color_type == PlyColorType::kFloat;
  // Integer colours as wide as they were read: 16-bit LAS colours as ushort, others as uchar.
  const bool word_colors = !float_colors && points.color_full_scale == 65535;
  const size_t faces = points.triangles.size() / 3;

  std::string header = std::string("ply\nformat ") + (ascii ? "ascii" : "binary_little_endian") +
                       " 1.0\ncomment written by dpoint\n" + sourceFacts(points) + "element vertex " + std::to_string(n) +
                       "\nproperty double x\nproperty double y\nproperty double z\n";
  if (points.hasColors())
    for (const char* c : {"red", "green", "blue"})
      header += std::string("property ") + (float_colors ? "float " : word_colors ? "ushort " : "uchar ") + c + "\n";
  // Dimensions as properties of their own type; PLY has no 64-bit integers, so those go as double
  // (exact below 2^53).
  for (const Dimension& d : points.dimensions.all()) {
    const char* type = plyTypeName(d.type);
    header += "property ";
    header += type ? type : "double";
    header += ' ';
    header += d.name;
    header += '\n';
  }
  if (faces) header += "element face " + std::to_string(faces) + "\nproperty list uchar uint vertex_indices\n";
  header += "end_header\n";

  if (options.progress) options.progress->start("writing " + path, n + faces);
  ChunkWriter out(*file, options.progress);
  out.append(header);
  for (size_t i = 0; i < n; ++i) {
    const glm::dvec3& p = points.positions[i];
    const bool attributes = !points.dimensions.empty();
    if (ascii) {
      appendNumber(out, p.x, ' ');
      appendNumber(out, p.y, ' ');
      appendNumber(out, p.z, points.hasColors() || attributes ? ' ' : '\n');
      if (points.hasColors()) {
        const glm::vec3& c = points.colors[i];
        for (int k = 0; k < 3; ++k) {
          const char sep = k == 2 && !attributes ? '\n' : ' ';
          if (float_colors)
            appendNumber(out, c[k], sep);
          else if (word_colors)
            appendNumber(out, static_cast<unsigned>(colorWord(c[k])), sep);
          else
            appendNumber(out, static_cast<unsigned>(colorByte(c[k])), sep);
        }
      }
      const std::vector<Dimension>& dims = points.dimensions.all();
      for (size_t k = 0; k < dims.size(); ++k) appendDimension(out, dims[k], i, k + 1 == dims.size() ? '\n' : ' ');
    } else {
      out.append(&p, sizeof p);
      if (points.hasColors()) {
        const glm::vec3& c = points.colors[i];
        if (float_colors) {
          out.append(&c, sizeof c);
        } else if (word_colors) {
          const uint16_t rgb[3] = {colorWord(c.r), colorWord(c.g), colorWord(c.b)};
          out.append(rgb, sizeof rgb);
        } else {
          const uint8_t rgb[3] = {colorByte(c.r), colorByte(c.g), colorByte(c.b)};
          out.append(rgb, sizeof rgb);
        }
      }
      for (const Dimension& d : points.dimensions.all()) {
        if (plyTypeName(d.type)) {
          const size_t w = dimTypeSize(d.type);
          out.append(d.bytes.data() + i * w, w);
        } else {
          const double v = d.value(i);
          out.append(&v, sizeof v);
        }
      }
    }
    if (Status s = out.endRow(); !s.ok()) return s;
  }
  for (size_t f = 0; f < faces; ++f) {
    const uint32_t* t = &points.triangles[3 * f];
    if (ascii) {
      out.append("3 ");
      for (int k = 0; k < 3; ++k) appendNumber(out, t[k], k == 2 ? '\n' : ' ');
    } else {
      const uint8_t three = 3;
      out.append(&three, 1);
      out.append(t, 3 * sizeof(uint32_t));
    }
    if (Status s = out.endRow(); !s.ok()) return s;
  }
  if (Status s = out.flush(); !s.ok()) return s;
  return file->commit();
}

}  // namespace dpoint
