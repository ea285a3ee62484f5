#include "converters/tile_file.h"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <tuple>
#include <sstream>

#include "core/atomic_file.h"
#include "core/input_file.h"
#include "core/ordered_write.h"
#include "core/parallel.h"
#include "core/memory.h"
#include "core/text.h"
#include "converters/ply.h"

namespace dpoint {
namespace {

const std::string kTileComment = std::string("comment ") + kPlyTileCommentWord + " ";
constexpr const char* kOwnedComment = "comment dpoint-tile-owned ";
constexpr const char* kSignatureComment = "comment dpoint-tile-of ";
constexpr const char* kPadComment = "comment dpoint-tile-pad ";
constexpr size_t kMaxHeaderBytes = 1 << 16;
constexpr size_t kRowsPerBlock = size_t{1} << 16;  // rows read or written per block
constexpr size_t kFaceBytes = 1 + 3 * sizeof(uint32_t);
constexpr size_t kForeignBytes = 2 * sizeof(uint32_t);

bool startsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

// The header and where the data starts.
struct ParsedHeader {
  TileHeader header;
  uint64_t data_offset = 0;
};

Result<ParsedHeader> parseHeader(const std::string& path, std::FILE* file) {
  std::vector<char> buffer(kMaxHeaderBytes);
  const size_t got = std::fread(buffer.data(), 1, buffer.size(), file);
  const std::string text(buffer.data(), got);
  const size_t end = text.find("end_header\n");
  if (text.rfind("ply\n", 0) != 0) return Error{path + ": not a PLY file (no 'ply' line at the start)"};
  if (end == std::string::npos)
    return Error{path + ": no 'end_header' line in the first " + std::to_string(kMaxHeaderBytes) + " bytes"};
  std::istringstream lines(text.substr(0, end));
  std::vector<std::string> body;  // the lines that are not comments, numbered for messages
  std::vector<int> body_line;
  ParsedHeader out;
  TileHeader& h = out.header;
  bool has_tile = false, has_owned = false, has_signature = false;
  std::string line;
  int line_no = 0;
  auto bad = [&](int at, const std::string& why) { return Error{path + ": header line " + std::to_string(at) + ": " + why}; };
  while (std::getline(lines, line)) {
    ++line_no;
    if (startsWith(line, kTileComment.c_str())) {
      const std::string spec = line.substr(kTileComment.size());
      Result<TileSpec> t = parseTileSpec(kPlyTileCommentWord, spec);
      if (!t) return bad(line_no, "bad tile '" + spec + "'");
      h.tile = *t;
      has_tile = true;
    } else if (startsWith(line, kOwnedComment)) {
      uint64_t owned = 0;
      if (!parseDecimalU64(line.substr(std::strlen(kOwnedComment)), owned) || owned > UINT32_MAX)
        return bad(line_no, "bad owned-vertex count '" + line.substr(std::strlen(kOwnedComment)) + "'");
      h.owned = static_cast<uint32_t>(owned);
      has_owned = true;
    } else if (startsWith(line, kSignatureComment)) {
      h.signature = line.substr(std::strlen(kSignatureComment));
      has_signature = true;
    } else if (!startsWith(line, "comment")) {
      body.push_back(line);
      body_line.push_back(line_no);
    }
  }
  if (!has_tile) return Error{path + ": not a dpoint tile (no 'comment dpoint-tile I/N' in the header)"};
  if (!has_owned || !has_signature)
    return Error{path + ": the header lacks the '" + std::string(has_owned ? "dpoint-tile-of" : "dpoint-tile-owned") +
                 "' comment"};
  // The layout writeTile produces, line by line; a colour block is optional.
  size_t at = 0;
  auto expect = [&](const std::string& wanted) -> Status {
    if (at >= body.size()) return bad(line_no, "expected '" + wanted + "', found the end of the header");
    if (body[at] != wanted) return bad(body_line[at], "expected '" + wanted + "', found '" + body[at] + "'");
    ++at;
    return okStatus();
  };
  auto count = [&](const std::string& element, uint64_t& value) -> Status {
    const std::string prefix = "element " + element + " ";
    if (at >= body.size() || !startsWith(body[at], prefix.c_str()) ||
        !parseDecimalU64(body[at].substr(prefix.size()), value))
      return bad(at < body.size() ? body_line[at] : line_no,
                 "expected 'element " + element + " COUNT', found '" + (at < body.size() ? body[at] : "") + "'");
    ++at;
    return okStatus();
  };
  for (const std::string& wanted : {std::string("ply"), std::string("format binary_little_endian 1.0")})
    if (Status s = expect(wanted); !s) return s.error();
  if (Status s = count("vertex", h.vertices); !s) return s.error();
  for (const char* axis : {"x", "y", "z"})
    if (Status s = expect(std::string("property double ") + axis); !s) return s.error();
  h.colors = at < body.size() && body[at] == "property float red";
  if (h.colors)
    for (const char* c : {"red", "green", "blue"})
      if (Status s = expect(std::string("property float ") + c); !s) return s.error();
  if (Status s = count("face", h.faces); !s) return s.error();
  if (Status s = expect("property list uchar uint vertex_indices"); !s) return s.error();
  if (Status s = count("dpoint_foreign", h.foreign); !s) return s.error();
  for (const std::string& wanted : {std::string("property uint tile"), std::string("property uint index")})
    if (Status s = expect(wanted); !s) return s.error();
  if (at != body.size()) return bad(body_line[at], "unexpected '" + body[at] + "'");
  if (h.owned > h.vertices || h.vertices - h.owned != h.foreign)
    return Error{path + ": " + std::to_string(h.vertices) + " vertices, " + std::to_string(h.owned) + " owned and " +
                 std::to_string(h.foreign) + " foreign references do not add up"};
  if (h.vertices > UINT32_MAX) return Error{path + ": more than 2^32 vertices"};
  out.data_offset = end + std::strlen("end_header\n");
  return out;
}

Result<ParsedHeader> openTile(const std::string& path, File& file) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return Error{path + ": is a folder, not a tile (.ply)"};
  file.reset(std::fopen(path.c_str(), "rb"));
  if (!file) return cannotOpen(path, errno);
  Result<ParsedHeader> h = parseHeader(path, file.get());
  if (!h) return h.error();
  // The data must fill the rest of the file exactly.
  const uint64_t stride = 3 * sizeof(double) + (h->header.colors ? 3 * sizeof(float) : 0);
  const uint64_t expected = h->data_offset + h->header.vertices * stride + h->header.faces * kFaceBytes +
                            h->header.foreign * kForeignBytes;
  if (std::fseek(file.get(), 0, SEEK_END) != 0) return Error{path + ": cannot seek: " + std::strerror(errno)};
  const long size = std::ftell(file.get());
  if (size < 0 || static_cast<uint64_t>(size) != expected)
    return Error{path + ": " + std::to_string(size) + " bytes, but the header describes " + std::to_string(expected) +
                 " (a truncated or padded tile)"};
  if (std::fseek(file.get(), static_cast<long>(h->data_offset), SEEK_SET) != 0)
    return Error{path + ": cannot seek: " + std::strerror(errno)};
  return h;
}

// The header of a tile file with these counts. Its length does not depend on them: a comment of
// dots pads the four counts out to 20 digits each, so that a header laid out before they are known
// (TileRowStream) is as long as the real one, which then goes over it.
std::string tileHeader(TileSpec tile, const std::string& signature, bool colors, uint64_t owned, uint64_t vertices,
                       uint64_t faces, uint64_t foreign) {
  const std::string counts[4] = {std::to_string(owned), std::to_string(vertices), std::to_string(faces),
                                 std::to_string(foreign)};
  size_t pad = 0;
  for (const std::string& c : counts) pad += 20 - c.size();
  std::string header = "ply\nformat binary_little_endian 1.0\ncomment written by dpoint\n";
  header += kTileComment + std::to_string(tile.index) + "/" + std::to_string(tile.count) + "\n";
  header += kOwnedComment + counts[0] + "\n";
  header += kSignatureComment + signature + "\n";
  header += kPadComment + std::string(pad, '.') + "\n";
  header += "element vertex " + counts[1] + "\nproperty double x\nproperty double y\nproperty double z\n";
  if (colors) header += "property float red\nproperty float green\nproperty float blue\n";
  header += "element face " + counts[2] + "\nproperty list uchar uint vertex_indices\n";
  header += "element dpoint_foreign " + counts[3] + "\nproperty uint tile\nproperty uint index\nend_header\n";
  return header;
}

// The references' rows into `rows`: tile and index of each copy.
void foreignRows(std::span<const TileVertexRef> foreign, std::vector<char>& rows) {
  rows.resize(foreign.size() * kForeignBytes);
  for (size_t f = 0; f < foreign.size(); ++f) {
    const uint32_t row[2] = {foreign[f].tile, foreign[f].index};
    std::memcpy(&rows[f * kForeignBytes], row, sizeof row);
  }
}

}  // namespace

Result<std::unique_ptr<TileRowStream>> TileRowStream::create(const std::string& path, TileSpec tile,
                                                             const std::string& signature, bool colors,
                                                             unsigned threads, Progress* progress) {
  assert(signature.find('\n') == std::string::npos);
  std::unique_ptr<TileRowStream> out(new TileRowStream);
  TileRowStream* self = out.get();
  PlyRowLayout layout;
  layout.row_bytes = colors ? kTileRowBytesColored : kTileRowBytes;
  // The owned count and the references' are finish()'s; the estimate's header is as long. A tile
  // with no vertices has no colours either, as writeTile's (then the header shrinks: nothing moves).
  layout.header = [self, tile, signature, colors](uint64_t vertices, uint64_t faces, bool) {
    return tileHeader(tile, signature, colors && vertices > 0, self->owned_, vertices, faces, self->foreign_);
  };
  Result<std::unique_ptr<PlyRowStream>> rows = PlyRowStream::create(path, colors, std::move(layout), threads, progress);
  if (!rows) return rows.error();
  if (!*rows) return std::unique_ptr<TileRowStream>();
  out->rows_ = std::move(*rows);
  return out;
}

Status TileRowStream::finish(uint32_t owned, std::span<const TileVertexRef> foreign) {
  assert(uint64_t{owned} + foreign.size() == rows_->vertices());
  owned_ = owned;
  foreign_ = foreign.size();
  std::vector<char> trailer;
  foreignRows(foreign, trailer);
  return rows_->finish({reinterpret_cast<const uint8_t*>(trailer.data()), trailer.size()});
}

Status writeTile(const std::string& path, const PointTile& tile, const std::string& signature, Progress* progress,
                 unsigned threads) {
  const PointSet& p = tile.points;
  assert(tile.owned <= p.size() && p.size() - tile.owned == tile.foreign.size());
  assert(signature.find('\n') == std::string::npos);
  assert(!p.hasColors() || p.colors.size() == p.size());
  Result<AtomicFile> file = AtomicFile::create(path);
  if (!file) return file.error();
  const size_t faces = p.triangles.size() / 3;
  const std::string header =
      tileHeader(tile.tile, signature, p.hasColors(), tile.owned, p.size(), faces, tile.foreign.size());
  if (Status s = file->write(header); !s) return s;
  if (progress) progress->start("writing " + path, p.size() + faces);

  // The vertex rows, the face rows and the copies' references, kRowsPerBlock rows a chunk, made on
  // all cores and written in order.
  const size_t stride = sizeof(glm::dvec3) + (p.hasColors() ? sizeof(glm::vec3) : 0);
  const size_t vertex_chunks = (p.size() + kRowsPerBlock - 1) / kRowsPerBlock;
  const size_t face_chunks = (faces + kRowsPerBlock - 1) / kRowsPerBlock;
  auto rowsOf = [&](size_t k) -> std::pair<size_t, size_t> {
    const size_t c = k < vertex_chunks ? k : k - vertex_chunks;
    const size_t total = k < vertex_chunks ? p.size() : faces;
    return {c * kRowsPerBlock, std::min(total, (c + 1) * kRowsPerBlock)};
  };
  Status written = writeChunksInOrder(
      *file, vertex_chunks + face_chunks + 1, threads,
      [&](size_t k, std::vector<char>& block) -> Status {
        if (k == vertex_chunks + face_chunks) {  // the references
          foreignRows(tile.foreign, block);
          return okStatus();
        }
        const auto [first, end] = rowsOf(k);
        if (k < vertex_chunks) {
          block.resize((end - first) * stride);
          for (size_t i = first; i < end; ++i) {
            char* row = &block[(i - first) * stride];
            std::memcpy(row, &p.positions[i], sizeof(glm::dvec3));
            if (p.hasColors()) std::memcpy(row + sizeof(glm::dvec3), &p.colors[i], sizeof(glm::vec3));
          }
          return okStatus();
        }
        block.resize((end - first) * kFaceBytes);
        for (size_t i = first; i < end; ++i) {
          char* row = &block[(i - first) * kFaceBytes];
          row[0] = 3;
          std::memcpy(row + 1, &p.triangles[3 * i], 3 * sizeof(uint32_t));
        }
        return okStatus();
      },
      [&](size_t k) {
        if (progress && k < vertex_chunks + face_chunks) progress->advance(rowsOf(k).second - rowsOf(k).first);
      });
  if (!written) return written;
  if (progress) progress->finish();
  return file->commit();
}

bool isTileFile(const std::string& path) {
  File file(std::fopen(path.c_str(), "rb"));
  if (!file) return false;
  char buffer[4096];
  const size_t got = std::fread(buffer, 1, sizeof buffer, file.get());
  const std::string text(buffer, got);
  const size_t end = text.find("end_header\n");
  return text.rfind("ply\n", 0) == 0 && text.find(std::string("\n") + kTileComment) < end;
}

Result<TileHeader> readTileHeader(const std::string& path) {
  File file;
  Result<ParsedHeader> h = openTile(path, file);
  if (!h) return h.error();
  return h->header;
}

namespace {

// A tile opened for reading its rows from any thread: the parsed header and the file.
struct OpenTile {
  ParsedHeader parsed;
  std::unique_ptr<InputFile> file;
  uint64_t stride() const { return 3 * sizeof(double) + (parsed.header.colors ? 3 * sizeof(float) : 0); }
  uint64_t facesAt() const { return parsed.data_offset + parsed.header.vertices * stride(); }
  uint64_t foreignAt() const { return facesAt() + parsed.header.faces * kFaceBytes; }
};

Result<OpenTile> openForRows(const std::string& path) {
  OpenTile t;
  {
    File header_file;
    Result<ParsedHeader> parsed = openTile(path, header_file);
    if (!parsed) return parsed.error();
    t.parsed = std::move(*parsed);
  }
  Result<InputFile> file = InputFile::open(path);
  if (!file) return file.error();
  t.file = std::make_unique<InputFile>(std::move(*file));
  return t;
}

Status readBytesAt(const InputFile& file, uint64_t offset, std::vector<char>& bytes, size_t size) {
  bytes.resize(size);
  Result<size_t> got = file.readAt(offset, bytes.data(), size);
  if (!got) return got.error();
  if (*got != size)
    return Error{file.path() + ": short read at byte " + std::to_string(offset + *got) + " (the file shrank while read)"};
  return okStatus();
}

// Vertex rows [first, first + rows) of a tile into positions[0, rows) and, with colours, colors.
// Vertex rows [first, first + rows) of a tile, as read into `bytes`: finite, as the PLY reader
// has every vertex (the build before merged a tile's NaN into a file that dpoint then refused).
Status finiteRows(const OpenTile& t, uint64_t first, size_t rows, const char* bytes) {
  const size_t stride = t.stride();
  for (size_t i = 0; i < rows; ++i) {
    double p[3];
    std::memcpy(p, bytes + i * stride, sizeof p);
    for (size_t k = 0; k < 3; ++k)
      if (!std::isfinite(p[k]))
        return Error{t.file->path() + ": byte " + std::to_string(t.parsed.data_offset + (first + i) * stride + 8 * k) +
                     ": vertex " + std::to_string(first + i) + ": " + "xyz"[k] + " is " + formatNumber(p[k]) +
                     ", not a finite number"};
  }
  return okStatus();
}

Status readVertexRows(const OpenTile& t, uint64_t first, size_t rows, glm::dvec3* positions, glm::vec3* colors,
                      std::vector<char>& bytes) {
  const size_t stride = t.stride();
  if (Status s = readBytesAt(*t.file, t.parsed.data_offset + first * stride, bytes, rows * stride); !s) return s;
  for (size_t i = 0; i < rows; ++i) {
    std::memcpy(&positions[i], &bytes[i * stride], sizeof(glm::dvec3));
    if (colors) std::memcpy(&colors[i], &bytes[i * stride + sizeof(glm::dvec3)], sizeof(glm::vec3));
  }
  return finiteRows(t, first, rows, bytes.data());
}

// Face rows [first, first + rows) of a tile into out[0, 3·rows), each index through remap after
// checking the row (three corners, each below the tile's vertex count).
template <typename Remap>
Status readFaceRows(const OpenTile& t, uint64_t first, size_t rows, uint32_t* out, std::vector<char>& bytes,
                    const Remap& remap) {
  const std::string& path = t.file->path();
  const uint64_t vertices = t.parsed.header.vertices;
  const uint64_t at = t.facesAt() + first * kFaceBytes;
  if (Status s = readBytesAt(*t.file, at, bytes, rows * kFaceBytes); !s) return s;
  for (size_t i = 0; i < rows; ++i) {
    const char* row = &bytes[i * kFaceBytes];
    if (row[0] != 3)
      return Error{path + ": byte " + std::to_string(at + i * kFaceBytes) + ": face " + std::to_string(first + i) +
                   " has " + std::to_string(static_cast<unsigned char>(row[0])) + " corners, not 3"};
    uint32_t corner[3];
    std::memcpy(corner, row + 1, sizeof corner);
    for (size_t k = 0; k < 3; ++k) {
      if (corner[k] >= vertices)
        return Error{path + ": byte " + std::to_string(at + i * kFaceBytes) + ": face " + std::to_string(first + i) +
                     " uses vertex " + std::to_string(corner[k]) + " of " + std::to_string(vertices)};
      out[3 * i + k] = remap(corner[k]);
    }
  }
  return okStatus();
}

Status readForeignRows(const OpenTile& t, std::vector<TileVertexRef>& foreign) {
  std::vector<char> bytes;
  const uint64_t count = t.parsed.header.foreign;
  if (Status s = readBytesAt(*t.file, t.foreignAt(), bytes, count * kForeignBytes); !s) return s;
  foreign.resize(count);
  for (size_t f = 0; f < count; ++f) {
    uint32_t row[2];
    std::memcpy(row, &bytes[f * kForeignBytes], sizeof row);
    foreign[f] = {row[0], row[1]};
  }
  return okStatus();
}

// The first error of `errors` (in item order), or ok.
Status firstError(const std::vector<Status>& errors) {
  for (const Status& s : errors)
    if (!s) return s;
  return okStatus();
}

}  // namespace

Result<PointTile> readTile(const std::string& path) {
  Result<OpenTile> t = openForRows(path);
  if (!t) return t.error();
  const TileHeader& h = t->parsed.header;
  PointTile tile;
  tile.tile = h.tile;
  tile.owned = h.owned;
  PointSet& p = tile.points;
  p.positions.resize(h.vertices);
  if (h.colors) p.colors.resize(h.vertices);
  std::vector<char> bytes;
  for (size_t first = 0; first < h.vertices; first += kRowsPerBlock) {
    const size_t rows = std::min<size_t>(kRowsPerBlock, h.vertices - first);
    if (Status s = readVertexRows(*t, first, rows, &p.positions[first], h.colors ? &p.colors[first] : nullptr, bytes); !s)
      return s.error();
  }
  p.triangles.resize(3 * h.faces);
  for (size_t first = 0; first < h.faces; first += kRowsPerBlock) {
    const size_t rows = std::min<size_t>(kRowsPerBlock, h.faces - first);
    if (Status s = readFaceRows(*t, first, rows, &p.triangles[3 * first], bytes, [](uint32_t i) { return i; }); !s)
      return s.error();
  }
  if (Status s = readForeignRows(*t, tile.foreign); !s) return s.error();
  return tile;
}

namespace {

// All N tiles of one run, checked against each other and taken in tile order, with where each
// tile's owned vertices and faces start in the whole set and its copies' owners in it.
struct TileSet {
  std::vector<OpenTile> opened;        // in the order of the paths
  std::vector<const OpenTile*> tile;   // tile[t]: tile t
  std::vector<uint64_t> base, face_base;  // count + 1 each
  std::vector<std::vector<TileVertexRef>> foreign;
  std::vector<std::vector<uint32_t>> global;  // global[t][f]: the whole set's index of tile t's copy f
  bool colors = false;
  uint32_t count() const { return static_cast<uint32_t>(tile.size()); }
  uint64_t vertices() const { return base.back(); }
  uint64_t faces() const { return face_base.back(); }
  const std::string& path(uint32_t t) const { return tile[t]->file->path(); }
  // The whole set's index of vertex i of tile t: its own, or the owner's of a copy (the weld).
  uint32_t weld(uint32_t t, uint32_t i) const {
    const uint64_t owned = tile[t]->parsed.header.owned;
    return i < owned ? static_cast<uint32_t>(base[t] + i) : global[t][i - owned];
  }
};

// `merged`: the set is to be merged, so its vertices must be addressable by 32-bit indices; a
// stream of the owned vertices (readTileCopyRefs) has no such limit and no use for `global`.
Result<TileSet> openTileSet(const std::vector<std::string>& paths, unsigned threads, bool merged = true) {
  if (paths.empty()) return Error{"merge: no tiles given", ExitCode::kUsage};
  TileSet set;
  for (const std::string& path : paths) {
    Result<OpenTile> t = openForRows(path);
    if (!t) return t.error();
    set.opened.push_back(std::move(*t));
  }
  auto headerOf = [&](size_t i) -> const TileHeader& { return set.opened[i].parsed.header; };
  const uint32_t count = headerOf(0).tile.count;
  std::vector<int> by_index(count, -1);
  for (size_t i = 0; i < paths.size(); ++i) {
    const TileHeader& h = headerOf(i);
    if (h.tile.count != count)
      return Error{paths[i] + ": tile " + std::to_string(h.tile.index) + "/" + std::to_string(h.tile.count) + ", but " +
                   paths[0] + " is one of " + std::to_string(count)};
    if (h.signature != headerOf(0).signature)
      return Error{paths[i] + ": a tile of another run ('" + h.signature + "'), not of '" + headerOf(0).signature + "' (" +
                   paths[0] + ")"};
    int& slot = by_index[h.tile.index];
    if (slot >= 0) return Error{paths[i] + ": tile " + std::to_string(h.tile.index) + " again (also " + paths[static_cast<size_t>(slot)] + ")"};
    slot = static_cast<int>(i);
  }
  std::string missing;
  for (uint32_t t = 0; t < count; ++t)
    if (by_index[t] < 0) missing += (missing.empty() ? "" : ", ") + std::to_string(t);
  if (!missing.empty())
    return Error{"merge: missing tile(s) " + missing + " of 0.." + std::to_string(count - 1) + " (" +
                 std::to_string(paths.size()) + " given, from " + paths[0] + ")"};
  set.tile.resize(count);
  for (uint32_t t = 0; t < count; ++t) set.tile[t] = &set.opened[static_cast<size_t>(by_index[t])];

  set.base.assign(count + 1, 0);
  set.face_base.assign(count + 1, 0);
  for (uint32_t t = 0; t < count; ++t) {
    set.base[t + 1] = set.base[t] + set.tile[t]->parsed.header.owned;
    set.face_base[t + 1] = set.face_base[t] + set.tile[t]->parsed.header.faces;
  }
  if (merged && set.vertices() > UINT32_MAX) return Error{"merge: more than 2^32 vertices", ExitCode::kResourceLimit};
  // Colours or none, alike in every tile that has points (an empty one has nothing to colour).
  int coloured = -1;
  for (size_t i = 0; i < paths.size(); ++i) {
    if (headerOf(i).vertices == 0) continue;
    if (coloured < 0) coloured = static_cast<int>(i);
    if (headerOf(i).colors != headerOf(static_cast<size_t>(coloured)).colors)
      return Error{paths[i] + ": " + (headerOf(i).colors ? "has" : "lacks") + " colours, unlike " +
                   paths[static_cast<size_t>(coloured)]};
  }
  set.colors = coloured >= 0 && headerOf(static_cast<size_t>(coloured)).colors;

  // The references of every tile's copies, as indices in the whole set.
  set.foreign.resize(count);
  set.global.resize(count);
  std::vector<Status> errors(count, okStatus());
  parallelFor(count, threads, [&](size_t t, unsigned) {
    std::vector<TileVertexRef>& foreign = set.foreign[t];
    if (Status s = readForeignRows(*set.tile[t], foreign); !s) {
      errors[t] = s;
      return;
    }
    if (merged) set.global[t].resize(foreign.size());
    for (size_t f = 0; f < foreign.size(); ++f) {
      const TileVertexRef& ref = foreign[f];
      if (ref.tile >= count || ref.tile == t || ref.index >= set.base[ref.tile + 1] - set.base[ref.tile]) {
        errors[t] = Error{set.path(static_cast<uint32_t>(t)) + ": foreign vertex " + std::to_string(f) + " refers to vertex " +
                          std::to_string(ref.index) + " of tile " + std::to_string(ref.tile) + ", which does not exist"};
        return;
      }
      if (merged) set.global[t][f] = static_cast<uint32_t>(set.base[ref.tile] + ref.index);
    }
  });
  if (Status s = firstError(errors); !s) return s.error();
  return set;
}

Error copyDiffers(const TileSet& set, uint32_t t, uint32_t at, bool same_position) {
  return tileCopyDiffers(set.path(t), at, same_position);
}

// A work item of the merge: kRowsPerBlock vertex or face rows of one tile.
struct RowBlock {
  uint32_t tile;
  bool faces;
  uint64_t first;
  size_t rows;
};

// The blocks of rows [0, rows) of every tile (rows(t): how many), in tile order.
template <typename Rows>
void addBlocks(const TileSet& set, bool faces, const Rows& rows, std::vector<RowBlock>& blocks) {
  for (uint32_t t = 0; t < set.count(); ++t)
    for (uint64_t first = 0; first < rows(t); first += kRowsPerBlock)
      blocks.push_back({t, faces, first, static_cast<size_t>(std::min<uint64_t>(kRowsPerBlock, rows(t) - first))});
}

}  // namespace

Error tileCopyDiffers(const std::string& path, uint64_t vertex, bool same_position) {
  return Error{path + ": its copy of vertex " + std::to_string(vertex) + " differs from the owner's " +
               (same_position ? "colour" : "position") + " (tiles of different builds or options?)"};
}

Result<std::vector<std::vector<TileVertexRef>>> readTileCopyRefs(const std::vector<std::string>& paths, unsigned threads) {
  Result<TileSet> set = openTileSet(paths, threads, false);
  if (!set) return set.error();
  return std::move(set->foreign);  // the files close here
}

Result<PointSet> mergeTiles(const std::vector<std::string>& paths, uint64_t max_memory, Progress* progress,
                            unsigned threads, bool with_faces) {
  Result<TileSet> opened = openTileSet(paths, threads);
  if (!opened) return opened.error();
  const TileSet& set = *opened;
  const uint32_t count = set.count();
  const bool colors = set.colors;
  const uint64_t vertices = set.vertices(), faces = with_faces ? set.faces() : 0;
  uint64_t copies = 0;  // held beside the set until checked against their owners
  for (uint32_t t = 0; t < count; ++t) copies += set.foreign[t].size();
  const uint64_t bytes = (vertices + copies) * (sizeof(glm::dvec3) + (colors ? sizeof(glm::vec3) : 0)) +
                         faces * 3 * sizeof(uint32_t);
  if (Status s = checkMemory(describeInputs(paths) + ": merging " + std::to_string(count) + " tiles", bytes, max_memory); !s)
    return s.error();

  // Every tile's rows, kRowsPerBlock at a time on all cores, straight to their places: owned
  // vertices into the set, copies beside it (checked below), faces through the weld.
  PointSet out;
  resizePrefaulted(out.positions, vertices, threads);
  if (colors) resizePrefaulted(out.colors, vertices, threads);
  resizePrefaulted(out.triangles, 3 * faces, threads);
  std::vector<PositionArray> copy_positions(count);
  std::vector<std::vector<glm::vec3>> copy_colors(count);
  for (uint32_t t = 0; t < count; ++t) {
    copy_positions[t].resize(set.foreign[t].size());
    if (colors) copy_colors[t].resize(set.foreign[t].size());
  }
  std::vector<RowBlock> blocks;
  addBlocks(set, false, [&](uint32_t t) { return set.tile[t]->parsed.header.vertices; }, blocks);
  if (with_faces) addBlocks(set, true, [&](uint32_t t) { return set.tile[t]->parsed.header.faces; }, blocks);
  uint64_t all_rows = 0;  // every tile's vertex rows (copies included) and faces
  for (const RowBlock& block : blocks) all_rows += block.rows;
  if (progress) progress->start("merging " + std::to_string(count) + " tiles", all_rows);
  std::vector<Status> errors(blocks.size(), okStatus());
  const unsigned workers = resolveThreads(threads);
  std::vector<std::vector<char>> buffers(workers);
  parallelFor(blocks.size(), workers, [&](size_t k, unsigned worker) {
    const RowBlock& block = blocks[k];
    const OpenTile& t = *set.tile[block.tile];
    const uint64_t owned = t.parsed.header.owned;
    std::vector<char>& buffer = buffers[worker];
    Status s = okStatus();
    if (block.faces) {
      s = readFaceRows(t, block.first, block.rows, &out.triangles[3 * (set.face_base[block.tile] + block.first)], buffer,
                       [&](uint32_t i) { return set.weld(block.tile, i); });
    } else {
      // The rows below `owned` go into the set, the others among the copies.
      uint64_t first = block.first;
      size_t rows = block.rows;
      if (first < owned) {
        const size_t mine = static_cast<size_t>(std::min<uint64_t>(rows, owned - first));
        const uint64_t at = set.base[block.tile] + first;
        s = readVertexRows(t, first, mine, &out.positions[at], colors ? &out.colors[at] : nullptr, buffer);
        first += mine;
        rows -= mine;
      }
      if (s && rows > 0) {
        const uint64_t at = first - owned;
        s = readVertexRows(t, first, rows, &copy_positions[block.tile][at],
                           colors ? &copy_colors[block.tile][at] : nullptr, buffer);
      }
    }
    errors[k] = s;
    if (progress) progress->advance(block.rows);
  });
  if (progress) progress->finish();
  if (Status s = firstError(errors); !s) return s.error();

  // The weld is by identity; the copies must agree with their owners bit for bit.
  std::vector<Status> differ(count, okStatus());
  parallelFor(count, threads, [&](size_t t, unsigned) {
    for (size_t f = 0; f < set.global[t].size(); ++f) {
      const uint32_t at = set.global[t][f];
      const bool same_position = std::memcmp(&copy_positions[t][f], &out.positions[at], sizeof(glm::dvec3)) == 0;
      const bool same_color = !colors || std::memcmp(&copy_colors[t][f], &out.colors[at], sizeof(glm::vec3)) == 0;
      if (!same_position || !same_color) {
        differ[t] = copyDiffers(set, static_cast<uint32_t>(t), at, same_position);
        return;
      }
    }
  });
  if (Status s = firstError(differ); !s) return s.error();
  return out;
}

bool canMergeToPly(const PlyWriteOptions& options) {
  return options.encoding == PlyEncoding::kBinary &&
         (options.color_type == PlyColorType::kUchar || options.color_type == PlyColorType::kAuto);  // tiles' colours are 8-bit
}

Status mergeTilesToPly(const std::vector<std::string>& paths, const std::string& output, const PlyWriteOptions& options,
                       uint64_t max_memory) {
  assert(canMergeToPly(options));
  Result<TileSet> opened = openTileSet(paths, options.threads);
  if (!opened) return opened.error();
  const TileSet& set = *opened;
  const uint32_t count = set.count();
  const bool colors = set.colors;
  const size_t in_stride = sizeof(glm::dvec3) + (colors ? sizeof(glm::vec3) : 0);
  const size_t out_stride = sizeof(glm::dvec3) + (colors ? 3 : 0);
  {
    // What it holds: every copy's row and references, and per thread a block read and two made.
    uint64_t copies = 0;
    for (uint32_t t = 0; t < count; ++t) copies += set.foreign[t].size();
    const uint64_t threads = resolveThreads(options.threads);
    const uint64_t bytes = copies * (in_stride + 2 * sizeof(TileVertexRef) + 3 * sizeof(uint32_t)) +
                           threads * kRowsPerBlock * (in_stride + 2 * std::max(out_stride, kFaceBytes));
    if (Status s = checkMemory(describeInputs(paths) + ": merging " + std::to_string(count) + " tiles into " + output, bytes,
                               max_memory);
        !s)
      return s;
  }

  // The copies' rows as read, and per owning tile the copies of its vertices by index (then by
  // copying tile and copy): each block of owned rows checks the copies of its rows as it goes.
  std::vector<std::vector<char>> copy_rows(count);
  struct Copy {
    uint32_t index;  // among the owner's owned vertices
    uint32_t tile;   // the tile holding the copy
    uint32_t f;      // its copy number there
  };
  std::vector<std::vector<Copy>> copies_of(count);
  {
    std::vector<Status> errors(count, okStatus());
    parallelFor(count, options.threads, [&](size_t t, unsigned) {
      const OpenTile& tile = *set.tile[t];
      errors[t] = readBytesAt(*tile.file, tile.parsed.data_offset + tile.parsed.header.owned * in_stride, copy_rows[t],
                              set.foreign[t].size() * in_stride);
    });
    if (Status s = firstError(errors); !s) return s;
    for (uint32_t t = 0; t < count; ++t)
      for (size_t f = 0; f < set.foreign[t].size(); ++f)
        copies_of[set.foreign[t][f].tile].push_back({set.foreign[t][f].index, t, static_cast<uint32_t>(f)});
    parallelFor(count, options.threads, [&](size_t u, unsigned) {
      std::sort(copies_of[u].begin(), copies_of[u].end(), [](const Copy& a, const Copy& b) {
        return a.index != b.index ? a.index < b.index : a.tile != b.tile ? a.tile < b.tile : a.f < b.f;
      });
    });
  }

  std::vector<RowBlock> blocks;
  addBlocks(set, false, [&](uint32_t t) { return set.tile[t]->parsed.header.owned; }, blocks);
  const size_t vertex_blocks = blocks.size();
  addBlocks(set, true, [&](uint32_t t) { return set.tile[t]->parsed.header.faces; }, blocks);

  // Whether every z is +0.0 (PointSet::isPlanar): the header says so. A 3D set shows a z early.
  std::atomic<bool> planar{true};
  {
    std::vector<Status> errors(vertex_blocks, okStatus());
    const unsigned workers = resolveThreads(options.threads);
    std::vector<std::vector<char>> buffers(workers);
    parallelFor(vertex_blocks, workers, [&](size_t k, unsigned worker) {
      if (!planar.load(std::memory_order_relaxed)) return;
      const RowBlock& block = blocks[k];
      const OpenTile& tile = *set.tile[block.tile];
      std::vector<char>& bytes = buffers[worker];
      if (Status s = readBytesAt(*tile.file, tile.parsed.data_offset + block.first * in_stride, bytes,
                                 block.rows * in_stride);
          !s) {
        errors[k] = s;
        return;
      }
      for (size_t i = 0; i < block.rows; ++i) {
        uint64_t z;
        std::memcpy(&z, &bytes[i * in_stride + 2 * sizeof(double)], sizeof z);
        if (z != 0) {
          planar.store(false, std::memory_order_relaxed);
          return;
        }
      }
    });
    if (Status s = firstError(errors); !s) return s;
  }

  struct Differ {
    uint32_t tile, f, at;
    bool same_position;
  };
  std::optional<Differ> differ;
  std::mutex differ_mutex;

  Result<AtomicFile> file = AtomicFile::create(output);
  if (!file) return file.error();
  const std::string header = plyHeader(PointSet{}, set.vertices(), set.faces(), colors, !planar.load(), options);
  Progress* progress = options.progress;
  if (progress) progress->start("merging " + std::to_string(count) + " tiles into " + output, set.vertices() + set.faces());

  const Status written = writeChunksInOrder(
      *file, 1 + blocks.size(), options.threads,
      [&](size_t k, std::vector<char>& bytes) -> Status {
        if (k == 0) {
          bytes.assign(header.begin(), header.end());
          return okStatus();
        }
        const RowBlock& block = blocks[k - 1];
        const OpenTile& tile = *set.tile[block.tile];
        if (block.faces) {  // the tile's rows, each index through the weld in place
          std::vector<uint32_t> corners(3 * block.rows);
          Status s = readFaceRows(tile, block.first, block.rows, corners.data(), bytes,
                                  [&](uint32_t i) { return set.weld(block.tile, i); });
          if (!s) return s;
          for (size_t i = 0; i < block.rows; ++i) std::memcpy(&bytes[i * kFaceBytes + 1], &corners[3 * i], 12);
          return okStatus();
        }
        thread_local std::vector<char> in;
        if (Status s = readBytesAt(*tile.file, tile.parsed.data_offset + block.first * in_stride, in,
                                   block.rows * in_stride);
            !s)
          return s;
        if (Status s = finiteRows(tile, block.first, block.rows, in.data()); !s) return s;
        // The copies of these rows, bit for bit the owner's. A copy that differs is kept (the
        // first by copying tile and copy, as mergeTiles reports it) and reported once every
        // block has been read, so that a read or face error comes first, as it does there.
        const std::vector<Copy>& copies = copies_of[block.tile];
        auto copy = std::lower_bound(copies.begin(), copies.end(), block.first,
                                     [](const Copy& c, uint64_t index) { return c.index < index; });
        for (; copy != copies.end() && copy->index < block.first + block.rows; ++copy) {
          const char* owner = &in[(copy->index - block.first) * in_stride];
          const char* mine = &copy_rows[copy->tile][size_t{copy->f} * in_stride];
          const bool same_position = std::memcmp(owner, mine, sizeof(glm::dvec3)) == 0;
          if (same_position && std::memcmp(owner, mine, in_stride) == 0) continue;
          std::lock_guard lock(differ_mutex);
          const Differ found{copy->tile, copy->f, static_cast<uint32_t>(set.base[block.tile] + copy->index), same_position};
          if (!differ || std::tie(found.tile, found.f) < std::tie(differ->tile, differ->f)) differ = found;
        }
        bytes.resize(block.rows * out_stride);
        for (size_t i = 0; i < block.rows; ++i) {
          const char* row = &in[i * in_stride];
          char* to = &bytes[i * out_stride];
          std::memcpy(to, row, sizeof(glm::dvec3));
          if (colors) {
            float c[3];
            std::memcpy(c, row + sizeof(glm::dvec3), sizeof c);
            for (size_t j = 0; j < 3; ++j) to[sizeof(glm::dvec3) + j] = static_cast<char>(colorInteger(c[j], 255.0));
          }
        }
        return okStatus();
      },
      [&](size_t k) {
        if (k > 0 && progress) progress->advance(blocks[k - 1].rows);
      });
  if (!written) return written;
  if (differ) return copyDiffers(set, differ->tile, differ->at, differ->same_position);
  if (progress) progress->finish();
  return file->commit();
}

}  // namespace dpoint
