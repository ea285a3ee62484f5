// PLY writing: `double x,y,z`, uchar or float colours, `face` lists of three uint indices.
// Rows are formatted in chunks of 65,536 on all cores and written in order (core/ordered_write.h).
#include <algorithm>
#include <cassert>
#include <charconv>
#include <cstring>
#include <string_view>
#include <type_traits>
#include <vector>

#include "core/atomic_file.h"
#include "core/ordered_write.h"
#include "core/parallel.h"
#include "core/text.h"
#include "converters/ply.h"

namespace dpoint {

namespace {

constexpr size_t kRowsPerChunk = size_t{1} << 16;  // vertex or face rows a chunk
constexpr size_t kFaceBytes = 1 + 3 * sizeof(uint32_t);

// Colours leave as bytes (colorInteger of 255), or as 16-bit words for colours read so
// (PointSet::color_full_scale 65535: LAS).
uint8_t colorByte(float c) { return static_cast<uint8_t>(colorInteger(c, 255.0)); }
uint16_t colorWord(float c) { return colorInteger(c, 65535.0); }

// Header comments for the facts of the source that the values cannot tell (ply_read.cpp reads
// them back): a 2D set (its z are 0 but not a coordinate: read from 2D input, or made in memory with
// every z 0, as random2d and mandelbrot2d make theirs), and z as the up axis (LAS). Without the first,
// a 2D set written as PLY would come back as a 3D one and convert to a 3-column CSV.
std::string sourceFacts(const PointSet& points, bool has_z, bool colors, const std::string* given_crs) {
  // The text wins over a LAS source's records, as every writer takes them (converters/las_crs.h).
  const std::string& crs_text = given_crs ? *given_crs : points.crs;
  static constexpr size_t kCrsLineBytes = 400;  // 800 hex digits: a header line well under 1,024 bytes
  std::string facts;
  if (!has_z) facts += "comment dpoint: 2D (the source has x,y only; z is 0)\n";
  if (points.z_up) facts += "comment dpoint: up axis z\n";
  // Colours read as integers 0..255 from a text file (ply_read.cpp keeps them so for CSV).
  if (colors && points.color_full_scale == 255 && !points.las) facts += "comment dpoint: colours 0..255\n";
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
    facts += ' ';
    facts += std::to_string(l.global_encoding);  // bit 0: GPS times are adjusted standard time
    facts += '\n';
    // Its CRS records, byte for byte in hex, so that LAS → PLY → LAS keeps its coordinate system:
    // record K over lines "las crs K USER ID EXTENDED HEX" of at most 800 hex digits each ('-':
    // no bytes), as Open3D's PLY reader (RPly) stops at a header line over 1,024 bytes.
    static constexpr size_t kLineBytes = kCrsLineBytes;
    for (size_t k = 0; k < l.vlrs.size() && crs_text.empty(); ++k) {
      const LasVlr& vlr = l.vlrs[k];
      if (vlr.user_id.empty() || vlr.user_id.find_first_of(" \t\r\n") != std::string::npos) continue;
      const std::string head = "comment dpoint: las crs " + std::to_string(k) + ' ' + vlr.user_id + ' ' +
                               std::to_string(vlr.record_id) + ' ' + (vlr.extended ? '1' : '0') + ' ';
      std::vector<std::string> pieces = hexPieces(vlr.data, kLineBytes);
      if (pieces.empty()) pieces.emplace_back("-");
      for (const std::string& piece : pieces) facts += head + piece + '\n';
    }
  }
  // The coordinate system another format stated (E57's), byte for byte: lines "crs HEX" in order,
  // so that E57 → PLY → LAS keeps it.
  for (const std::string& piece : hexPieces(crs_text, kCrsLineBytes)) facts += "comment dpoint: crs " + piece + '\n';
  return facts;
}

template <typename T>
void appendNumber(TextBuffer& out, T value, char separator) {
  out.appendNumber(value);
  out.append(separator);
}

// Value i of a dimension in ASCII: integers as integers, floats in shortest round-trip form.
void appendDimension(TextBuffer& out, const Dimension& d, size_t i, char separator) {
  switch (d.type) {
    case DimType::kF32: appendNumber(out, d.get<float>(i), separator); break;
    case DimType::kF64: appendNumber(out, d.get<double>(i), separator); break;
    case DimType::kU64: appendNumber(out, d.get<uint64_t>(i), separator); break;
    case DimType::kI64: appendNumber(out, d.get<int64_t>(i), separator); break;
    default: appendNumber(out, static_cast<int64_t>(d.value(i)), separator); break;
  }
}

// Whether colours go as ushort (PlyColorType).
bool wordColors(PlyColorType type, const PointSet& facts) {
  return type == PlyColorType::kUshort || (type == PlyColorType::kAuto && facts.color_full_scale == 65535);
}

}  // namespace

std::optional<PlyColorType> parsePlyColorType(const std::string& text) {
  if (text == "auto") return PlyColorType::kAuto;
  if (text == "uchar") return PlyColorType::kUchar;
  if (text == "ushort") return PlyColorType::kUshort;
  if (text == "float") return PlyColorType::kFloat;
  return std::nullopt;
}

std::vector<std::string> plyPropertyNames(const Dimensions& dimensions, bool colors, std::vector<std::string>* renamed) {
  std::vector<std::string> names;
  for (const Dimension& d : dimensions.all()) names.push_back(d.name);
  const auto isDiffuse = [](const std::string& name) {
    return std::find(std::begin(kDiffuseNames), std::end(kDiffuseNames), name) != std::end(kDiffuseNames);
  };
  // The names as written, with the diffuse ones reserved or not.
  const auto written = [&](bool diffuse, std::vector<std::string>* lines) {
    return writableNames(
        names, isSpaceOrControl,
        [&](const std::string& name, size_t) {
          return name == "x" || name == "y" || name == "z" || name == "red" || name == "green" || name == "blue" ||
                 (diffuse && isDiffuse(name));
        },
        lines);
  };
  // A set without colours whose three diffuse names come out as written, each of a colour's type
  // (uchar, ushort, float, or double, as 64-bit integers go), would read back with them as its
  // colours: they are renamed then, and only then (names as cleaned: "diffuse blue" is written
  // diffuse_blue; int ones stay dimensions when read, and keep their names).
  const std::vector<std::string> plain = written(false, nullptr);
  const bool diffuse = !colors && std::all_of(std::begin(kDiffuseNames), std::end(kDiffuseNames), [&](const char* n) {
    const auto at = std::find(plain.begin(), plain.end(), n);
    if (at == plain.end()) return false;
    const DimType type = dimensions.all()[static_cast<size_t>(at - plain.begin())].type;
    return type == DimType::kU8 || type == DimType::kU16 || type == DimType::kF32 || type == DimType::kF64 ||
           plyTypeName(type) == nullptr;
  });
  return diffuse || renamed ? written(diffuse, renamed) : plain;
}

std::string plyHeader(const PointSet& facts, uint64_t vertices, uint64_t faces, bool colors, bool has_z,
                      const PlyWriteOptions& options) {
  const bool ascii = options.encoding == PlyEncoding::kAscii;
  const bool float_colors = options.color_type == PlyColorType::kFloat;
  const bool word_colors = wordColors(options.color_type, facts);
  std::string header = std::string("ply\nformat ") + (ascii ? "ascii" : "binary_little_endian") +
                       " 1.0\ncomment written by dpoint\n" + sourceFacts(facts, has_z, colors, options.crs) + "element vertex " +
                       std::to_string(vertices) + "\nproperty double x\nproperty double y\nproperty double z\n";
  if (colors)
    for (const char* c : {"red", "green", "blue"})
      header += std::string("property ") + (float_colors ? "float " : word_colors ? "ushort " : "uchar ") + c + "\n";
  // Dimensions as properties of their own type; PLY has no 64-bit integers, so those go as double
  // (exact below 2^53).
  const std::vector<std::string> names = plyPropertyNames(facts.dimensions, colors, nullptr);
  for (size_t k = 0; k < names.size(); ++k) {
    const char* type = plyTypeName(facts.dimensions.all()[k].type);
    header += "property ";
    header += type ? type : "double";
    header += ' ';
    header += names[k];
    header += '\n';
  }
  if (faces) header += "element face " + std::to_string(faces) + "\nproperty list uchar uint vertex_indices\n";
  header += "end_header\n";
  return header;
}

// Whether a 64-bit integer reads back from a double as itself.
template <typename T>
bool doubleHolds(T v) {
  const double d = static_cast<double>(v);
  const bool in_range = std::is_unsigned_v<T> ? d < 18446744073709551616.0 : d < 9223372036854775808.0;
  return in_range && static_cast<T>(d) == v;  // (2^64 or 2^63: v rounded up past T, so not held)
}

Status writePly(const std::string& path, const PointSet& points, const PlyWriteOptions& options) {
  const MadePositions& made = options.positions_of;
  assert(!made || (points.positions.empty() && !points.hasColors() && !points.isMesh() && points.dimensions.empty()));
  const size_t n = made ? made.count : points.size();
  assert(!(options.colors_of && points.hasColors()));
  const bool colors = points.hasColors() || options.colors_of;
  if (points.hasColors() && points.colors.size() != n)
    return Error{"cannot write '" + path + "': " + std::to_string(points.colors.size()) + " colours for " +
                 std::to_string(n) + " points"};
  if (points.triangles.size() % 3 != 0)
    return Error{"cannot write '" + path + "': triangle index count is not a multiple of 3"};
  if (options.notices && colors && options.color_type == PlyColorType::kAuto && wordColors(options.color_type, points))
    options.notices->push_back(path + ": 16-bit colours written as ushort, every bit kept; Open3D and PCL take 8-bit "
                               "PLY colours (--ply-colors uchar)");
  if (options.notices) {
    std::vector<std::string> renamed;
    plyPropertyNames(points.dimensions, colors, &renamed);
    for (const std::string& line : renamed)
      options.notices->push_back(path + ": " + line +
                                 " (a PLY property's name is one word, not x, y, z, red, green or blue, nor "
                                 "diffuse_red, diffuse_green and diffuse_blue where the set has no colours)");
    // PLY has no 64-bit integers: such a dimension goes as double, which past 2^53 loses digits (a
    // review finding: ids 2^53 + 1 came back as 2^53 without a word).
    for (const Dimension& d : points.dimensions.all()) {
      if (d.type != DimType::kU64 && d.type != DimType::kI64) continue;
      for (size_t i = 0; i < d.size(); ++i) {
        const bool exact = d.type == DimType::kU64 ? doubleHolds(d.get<uint64_t>(i)) : doubleHolds(d.get<int64_t>(i));
        if (exact) continue;
        options.notices->push_back(path + ": dimension " + quotedExcerpt(d.name) + " (" + dimTypeName(d.type) +
                                   ") written as double, as PLY has no 64-bit integers: values past 2^53 lose digits "
                                   "(the first: point " + std::to_string(i) + "); LAS, PCD and GLB keep them");
        break;
      }
    }
  }
  // Every index below n, checked before anything is written; the first bad one is named.
  if (const size_t bad = points.firstBadTriangleIndex(options.threads); bad < points.triangles.size())
    return Error{"cannot write '" + path + "': triangle index " + std::to_string(points.triangles[bad]) +
                 " out of range (" + std::to_string(n) + " points)"};
  auto file = AtomicFile::create(path);
  if (!file.ok()) return file.error();
  const bool ascii = options.encoding == PlyEncoding::kAscii;
  const bool float_colors = options.color_type == PlyColorType::kFloat;
  // Integer colours as wide as they were read: 16-bit LAS colours as ushort, others as uchar.
  const bool word_colors = wordColors(options.color_type, points);
  const size_t faces = points.triangles.size() / 3;

  const std::string header = plyHeader(points, n, faces, colors, points.hasZ(), options);

  const std::vector<Dimension>& dims = points.dimensions.all();
  const bool attributes = !dims.empty();
  const size_t color_bytes = !colors ? 0 : float_colors ? 12 : word_colors ? 6 : 3;
  size_t vertex_bytes = sizeof(glm::dvec3) + color_bytes;
  for (const Dimension& d : dims) vertex_bytes += plyTypeName(d.type) ? dimTypeSize(d.type) : sizeof(double);
  // The file's size in binary; in ASCII at least a digit and a separator a value: refused at once
  // where the disk cannot hold it (a generated set's rows are made as they are written).
  const uint64_t values = 3 + (colors ? 3 : 0) + dims.size();
  const uint64_t text = AtomicFile::kLeastTextBytesPerValue;
  const uint64_t least = header.size() + (ascii ? uint64_t{n} * values * text + uint64_t{faces} * 8
                                                 : uint64_t{n} * vertex_bytes + uint64_t{faces} * kFaceBytes);
  if (Status s = file->checkSpace(least); !s) return s;
  if (options.progress) options.progress->start("writing " + path, n + faces);

  // Chunk 0 is the header, then the vertex rows and the face rows kRowsPerChunk at a time.
  const size_t vertex_chunks = (n + kRowsPerChunk - 1) / kRowsPerChunk;
  const size_t face_chunks = (faces + kRowsPerChunk - 1) / kRowsPerChunk;
  auto rowsOf = [&](size_t k) -> std::pair<size_t, size_t> {  // [begin, end) of vertices or faces
    const size_t c = k - 1 < vertex_chunks ? k - 1 : k - 1 - vertex_chunks;
    const size_t total = k - 1 < vertex_chunks ? n : faces;
    return {c * kRowsPerChunk, std::min(total, (c + 1) * kRowsPerChunk)};
  };
  // The chunk's positions, at [i − begin]: the set's, or made now by positions_of.
  auto chunkPositions = [&](size_t begin, size_t end) -> const glm::dvec3* {
    if (!made) return points.positions.data() + begin;
    thread_local PositionArray chunk;
    chunk.resize(end - begin);
    made.make(begin, end, chunk.data());
    return chunk.data();
  };
  // The chunk's colours, at [i − begin]: the set's, or made now by colors_of.
  auto chunkColors = [&](const glm::dvec3* positions, size_t begin, size_t end) -> const glm::vec3* {
    if (!options.colors_of) return colors ? points.colors.data() + begin : nullptr;
    thread_local std::vector<glm::vec3> chunk;
    chunk.resize(end - begin);
    options.colors_of(positions, end - begin, chunk.data());
    return chunk.data();
  };
  auto vertexRows = [&](size_t begin, size_t end, std::vector<char>& bytes) {
    const glm::dvec3* chunk_positions = chunkPositions(begin, end);
    const glm::vec3* chunk_colors = chunkColors(chunk_positions, begin, end);
    if (!ascii) {
      bytes.resize((end - begin) * vertex_bytes);
      char* row = bytes.data();
      for (size_t i = begin; i < end; ++i) {
        std::memcpy(row, &chunk_positions[i - begin], sizeof(glm::dvec3));
        char* at = row + sizeof(glm::dvec3);
        if (colors) {
          const glm::vec3& c = chunk_colors[i - begin];
          if (float_colors) {
            std::memcpy(at, &c, sizeof c);
          } else if (word_colors) {
            const uint16_t rgb[3] = {colorWord(c.r), colorWord(c.g), colorWord(c.b)};
            std::memcpy(at, rgb, sizeof rgb);
          } else {
            at[0] = static_cast<char>(colorByte(c.r));
            at[1] = static_cast<char>(colorByte(c.g));
            at[2] = static_cast<char>(colorByte(c.b));
          }
          at += color_bytes;
        }
        for (const Dimension& d : dims) {
          if (plyTypeName(d.type)) {
            const size_t w = dimTypeSize(d.type);
            std::memcpy(at, d.bytes.data() + i * w, w);
            at += w;
          } else {
            const double v = d.value(i);
            std::memcpy(at, &v, sizeof v);
            at += sizeof v;
          }
        }
        row += vertex_bytes;
      }
      return;
    }
    // ASCII rows, whose length is known once formatted: into a per-thread TextBuffer, then the
    // chunk's bytes in one copy.
    thread_local TextBuffer out;
    out.clear();
    for (size_t i = begin; i < end; ++i) {
      const glm::dvec3& p = chunk_positions[i - begin];
      appendNumber(out, p.x, ' ');
      appendNumber(out, p.y, ' ');
      appendNumber(out, p.z, colors || attributes ? ' ' : '\n');
      if (colors) {
        const glm::vec3& c = chunk_colors[i - begin];
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
      for (size_t k = 0; k < dims.size(); ++k) appendDimension(out, dims[k], i, k + 1 == dims.size() ? '\n' : ' ');
    }
    bytes.assign(out.data(), out.data() + out.size());
  };
  auto faceRows = [&](size_t begin, size_t end, std::vector<char>& bytes) {
    if (!ascii) {
      bytes.resize((end - begin) * kFaceBytes);
      char* row = bytes.data();
      for (size_t f = begin; f < end; ++f, row += kFaceBytes) {
        row[0] = 3;
        std::memcpy(row + 1, &points.triangles[3 * f], 3 * sizeof(uint32_t));
      }
      return;
    }
    thread_local TextBuffer out;
    out.clear();
    for (size_t f = begin; f < end; ++f) {
      out.append("3 ");
      for (size_t k = 0; k < 3; ++k) appendNumber(out, points.triangles[3 * f + k], k == 2 ? '\n' : ' ');
    }
    bytes.assign(out.data(), out.data() + out.size());
  };
  const Status written = writeChunksInOrder(
      *file, 1 + vertex_chunks + face_chunks, options.threads,
      [&](size_t k, std::vector<char>& bytes) -> Status {
        if (k == 0) {
          bytes.assign(header.begin(), header.end());
          return okStatus();
        }
        const auto [begin, end] = rowsOf(k);
        if (k - 1 < vertex_chunks)
          vertexRows(begin, end, bytes);
        else
          faceRows(begin, end, bytes);
        return okStatus();
      },
      [&](size_t k) {
        if (k > 0 && options.progress) options.progress->advance(rowsOf(k).second - rowsOf(k).first);
      });
  if (!written) return written;
  return file->commit();
}

Result<std::unique_ptr<PlyRowStream>> PlyRowStream::create(const std::string& path, bool colors, unsigned threads,
                                                           Progress* progress) {
  // writePly's layout for a generated surface (no source facts), colours as bytes.
  PlyRowLayout layout;
  layout.row_bytes = colors ? 27 : 24;
  layout.header = [colors](uint64_t vertices, uint64_t faces, bool has_z) {
    return plyHeader(PointSet(), vertices, faces, colors, has_z, PlyWriteOptions());
  };
  return create(path, colors, std::move(layout), threads, progress);
}

Result<std::unique_ptr<PlyRowStream>> PlyRowStream::create(const std::string& path, bool colors, PlyRowLayout layout,
                                                           unsigned threads, Progress* progress) {
  Result<AtomicFile> file = AtomicFile::create(path);
  if (!file) return file.error();
  if (!file->positional()) return std::unique_ptr<PlyRowStream>();
  return std::unique_ptr<PlyRowStream>(new PlyRowStream(std::move(*file), colors, std::move(layout), threads, progress));
}

PlyRowStream::PlyRowStream(AtomicFile file, bool colors, PlyRowLayout layout, unsigned threads, Progress* progress)
    : file_(std::move(file)), colors_(colors), layout_(std::move(layout)), threads_(threads), progress_(progress) {}

PlyRowStream::~PlyRowStream() = default;

Status PlyRowStream::start(uint64_t vertices, uint64_t faces) {
  assert(!started_);
  started_ = true;
  header_bytes_ = layout_.header(vertices, faces, true).size();
  // The counts are a sample's estimate: refused at once only where the disk cannot hold half the
  // file they make, so that an estimate a little high never refuses a file that would fit.
  const uint64_t estimate = header_bytes_ + vertices * rowBytes() + faces * kFaceRowBytes;
  if (Status s = file_.checkSpace(estimate / 2); !s) return s;
  // Address space only: the pages are touched as the rows arrive.
  faces_.reserve(static_cast<size_t>(static_cast<double>(faces) * 1.1 * kFaceRowBytes));
  adviseHugePages(faces_.data(), faces_.capacity());
  return okStatus();
}

Status PlyRowStream::add(std::span<const uint8_t> vertex_rows, std::span<const uint8_t> face_rows) {
  assert(started_);
  const size_t row_bytes = rowBytes();
  assert(vertex_rows.size() % row_bytes == 0 && face_rows.size() % kFaceRowBytes == 0);
  const uint64_t vertices = vertex_rows.size() / row_bytes;
  // isPlanar's test, usually settled by the first row: a z that is not +0.
  for (uint64_t v = 0; v < vertices && !has_z_; ++v) {
    uint64_t z;
    std::memcpy(&z, vertex_rows.data() + v * row_bytes + 16, sizeof z);
    has_z_ = z != 0;
  }
  const size_t at = faces_.size();
  faces_.resize(at + face_rows.size());  // not zeroed (DefaultInitAllocator)
  // The vertex rows written on one worker while the others copy the face rows in pieces of 4 MiB.
  constexpr size_t kPiece = size_t{4} << 20;
  const size_t pieces = (face_rows.size() + kPiece - 1) / kPiece;
  Status written = okStatus();
  parallelFor(1 + pieces, std::min(8u, resolveThreads(threads_)), [&](size_t item, unsigned) {
    if (item == 0) {
      written = file_.writeAt(header_bytes_ + vertices_ * row_bytes, vertex_rows.data(), vertex_rows.size());
      return;
    }
    const size_t from = (item - 1) * kPiece, n = std::min(kPiece, face_rows.size() - from);
    std::memcpy(faces_.data() + at + from, face_rows.data() + from, n);
  });
  vertices_ += vertices;
  return written;
}

Status PlyRowStream::finish(std::span<const uint8_t> trailer) {
  assert(started_);
  const size_t row_bytes = rowBytes();
  const uint64_t vertex_bytes = vertices_ * row_bytes;
  const std::string header = layout_.header(vertices_, faces(), has_z_);
  const bool move = header.size() != header_bytes_;
  if (progress_) progress_->start("writing " + file_.path(), faces() + (move ? vertices_ : 0));
  // Moves the vertex rows from header_bytes_ to header.size(), a block at a time from the end that
  // goes first, so that no block is written over before it is read.
  if (move) {
    moved_ = vertex_bytes > 0;
    constexpr uint64_t kBlock = uint64_t{64} << 20;
    std::vector<char> block(static_cast<size_t>(std::min(kBlock, std::max<uint64_t>(vertex_bytes, 1))));
    const bool later = header.size() > header_bytes_;
    for (uint64_t done = 0; done < vertex_bytes;) {
      const uint64_t n = std::min(kBlock, vertex_bytes - done);
      const uint64_t from = later ? vertex_bytes - done - n : done;  // within the rows
      if (Status s = file_.readAt(header_bytes_ + from, block.data(), n); !s) return s;
      if (Status s = file_.writeAt(header.size() + from, block.data(), n); !s) return s;
      done += n;
      if (progress_) progress_->advance(n / row_bytes);
    }
  }
  if (Status s = file_.writeAt(0, header.data(), header.size()); !s) return s;
  constexpr size_t kBlock = size_t{64} << 20;
  for (size_t at = 0; at < faces_.size(); at += kBlock) {
    const size_t n = std::min(kBlock, faces_.size() - at);
    if (Status s = file_.writeAt(header.size() + vertex_bytes + at, faces_.data() + at, n); !s) return s;
    if (progress_) progress_->advance(n / kFaceRowBytes);
  }
  const uint64_t trailer_at = header.size() + vertex_bytes + faces_.size();
  if (!trailer.empty())
    if (Status s = file_.writeAt(trailer_at, trailer.data(), trailer.size()); !s) return s;
  if (Status s = file_.resize(trailer_at + trailer.size()); !s) return s;
  if (progress_) progress_->finish();
  return file_.commit();
}

}  // namespace dpoint
