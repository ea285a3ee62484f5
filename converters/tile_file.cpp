#include "converters/tile_file.h"

#include <algorithm>
#include <cassert>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <sstream>

#include "core/atomic_file.h"
#include "core/memory.h"
#include "core/text.h"

namespace dpoint {
namespace {

constexpr const char* kTileComment = "comment dpoint-tile ";
constexpr const char* kOwnedComment = "comment dpoint-tile-owned ";
constexpr const char* kSignatureComment = "comment dpoint-tile-of ";
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
    if (startsWith(line, kTileComment)) {
      const std::string spec = line.substr(std::strlen(kTileComment));
      Result<TileSpec> t = parseTileSpec("dpoint-tile", spec);
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
  file.reset(std::fopen(path.c_str(), "rb"));
  if (!file) return Error{path + ": cannot open: " + std::strerror(errno)};
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

Status readExactly(const std::string& path, std::FILE* file, void* data, size_t bytes) {
  if (std::fread(data, 1, bytes, file) != bytes) return Error{path + ": short read: " + std::strerror(errno)};
  return okStatus();
}

}  // namespace

Status writeTile(const std::string& path, const PointTile& tile, const std::string& signature, Progress* progress) {
  const PointSet& p = tile.points;
  assert(tile.owned <= p.size() && p.size() - tile.owned == tile.foreign.size());
  assert(signature.find('\n') == std::string::npos);
  assert(!p.hasColors() || p.colors.size() == p.size());
  Result<AtomicFile> file = AtomicFile::create(path);
  if (!file) return file.error();
  const size_t faces = p.triangles.size() / 3;
  std::string header = "ply\nformat binary_little_endian 1.0\ncomment written by dpoint\n";
  header += kTileComment + std::to_string(tile.tile.index) + "/" + std::to_string(tile.tile.count) + "\n";
  header += kOwnedComment + std::to_string(tile.owned) + "\n";
  header += kSignatureComment + signature + "\n";
  header += "element vertex " + std::to_string(p.size()) + "\nproperty double x\nproperty double y\nproperty double z\n";
  if (p.hasColors()) header += "property float red\nproperty float green\nproperty float blue\n";
  header += "element face " + std::to_string(faces) + "\nproperty list uchar uint vertex_indices\n";
  header += "element dpoint_foreign " + std::to_string(tile.foreign.size()) +
            "\nproperty uint tile\nproperty uint index\nend_header\n";
  if (Status s = file->write(header); !s) return s;
  if (progress) progress->start("writing " + path, p.size() + faces);

  std::vector<char> block;
  for (size_t first = 0; first < p.size(); first += kRowsPerBlock) {
    const size_t rows = std::min(kRowsPerBlock, p.size() - first);
    const size_t stride = sizeof(glm::dvec3) + (p.hasColors() ? sizeof(glm::vec3) : 0);
    block.resize(rows * stride);
    for (size_t i = 0; i < rows; ++i) {
      std::memcpy(&block[i * stride], &p.positions[first + i], sizeof(glm::dvec3));
      if (p.hasColors()) std::memcpy(&block[i * stride + sizeof(glm::dvec3)], &p.colors[first + i], sizeof(glm::vec3));
    }
    if (Status s = file->write(block.data(), block.size()); !s) return s;
    if (progress) progress->advance(rows);
  }
  for (size_t first = 0; first < faces; first += kRowsPerBlock) {
    const size_t rows = std::min(kRowsPerBlock, faces - first);
    block.resize(rows * kFaceBytes);
    for (size_t i = 0; i < rows; ++i) {
      block[i * kFaceBytes] = 3;
      std::memcpy(&block[i * kFaceBytes + 1], &p.triangles[3 * (first + i)], 3 * sizeof(uint32_t));
    }
    if (Status s = file->write(block.data(), block.size()); !s) return s;
    if (progress) progress->advance(rows);
  }
  for (const TileVertexRef& ref : tile.foreign) {
    const uint32_t row[2] = {ref.tile, ref.index};
    if (Status s = file->write(row, sizeof row); !s) return s;
  }
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

Result<PointTile> readTile(const std::string& path) {
  File file;
  Result<ParsedHeader> parsed = openTile(path, file);
  if (!parsed) return parsed.error();
  const TileHeader& h = parsed->header;
  PointTile tile;
  tile.tile = h.tile;
  tile.owned = h.owned;
  PointSet& p = tile.points;
  p.positions.resize(h.vertices);
  if (h.colors) p.colors.resize(h.vertices);
  const size_t stride = sizeof(glm::dvec3) + (h.colors ? sizeof(glm::vec3) : 0);
  std::vector<char> block;
  for (size_t first = 0; first < h.vertices; first += kRowsPerBlock) {
    const size_t rows = std::min<size_t>(kRowsPerBlock, h.vertices - first);
    block.resize(rows * stride);
    if (Status s = readExactly(path, file.get(), block.data(), block.size()); !s) return s.error();
    for (size_t i = 0; i < rows; ++i) {
      std::memcpy(&p.positions[first + i], &block[i * stride], sizeof(glm::dvec3));
      if (h.colors) std::memcpy(&p.colors[first + i], &block[i * stride + sizeof(glm::dvec3)], sizeof(glm::vec3));
    }
  }
  const uint64_t faces_offset = parsed->data_offset + h.vertices * stride;
  p.triangles.resize(3 * h.faces);
  for (size_t first = 0; first < h.faces; first += kRowsPerBlock) {
    const size_t rows = std::min<size_t>(kRowsPerBlock, h.faces - first);
    block.resize(rows * kFaceBytes);
    if (Status s = readExactly(path, file.get(), block.data(), block.size()); !s) return s.error();
    for (size_t i = 0; i < rows; ++i) {
      const uint64_t offset = faces_offset + (first + i) * kFaceBytes;
      if (block[i * kFaceBytes] != 3)
        return Error{path + ": byte " + std::to_string(offset) + ": face " + std::to_string(first + i) + " has " +
                     std::to_string(static_cast<unsigned char>(block[i * kFaceBytes])) + " corners, not 3"};
      uint32_t* t = &p.triangles[3 * (first + i)];
      std::memcpy(t, &block[i * kFaceBytes + 1], 3 * sizeof(uint32_t));
      for (int k = 0; k < 3; ++k)
        if (t[k] >= h.vertices)
          return Error{path + ": byte " + std::to_string(offset) + ": face " + std::to_string(first + i) +
                       " uses vertex " + std::to_string(t[k]) + " of " + std::to_string(h.vertices)};
    }
  }
  tile.foreign.resize(h.foreign);
  for (TileVertexRef& ref : tile.foreign) {
    uint32_t row[2];
    if (Status s = readExactly(path, file.get(), row, sizeof row); !s) return s.error();
    ref = {row[0], row[1]};
  }
  return tile;
}

Result<PointSet> mergeTiles(const std::vector<std::string>& paths, uint64_t max_memory, Progress* progress) {
  if (paths.empty()) return Error{"merge: no tiles given", ExitCode::kUsage};
  std::vector<TileHeader> headers;
  for (const std::string& path : paths) {
    Result<TileHeader> h = readTileHeader(path);
    if (!h) return h.error();
    headers.push_back(std::move(*h));
  }
  const uint32_t count = headers[0].tile.count;
  std::vector<int> by_index(count, -1);
  for (size_t i = 0; i < paths.size(); ++i) {
    const TileHeader& h = headers[i];
    if (h.tile.count != count)
      return Error{paths[i] + ": tile " + std::to_string(h.tile.index) + "/" + std::to_string(h.tile.count) + ", but " +
                   paths[0] + " is one of " + std::to_string(count)};
    if (h.signature != headers[0].signature)
      return Error{paths[i] + ": a tile of another run ('" + h.signature + "'), not of '" + headers[0].signature + "' (" +
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

  // Where each tile's owned vertices start in the whole set.
  std::vector<uint64_t> base(count + 1, 0);
  uint64_t faces = 0;
  for (uint32_t t = 0; t < count; ++t) {
    const TileHeader& h = headers[static_cast<size_t>(by_index[t])];
    base[t + 1] = base[t] + h.owned;
    faces += h.faces;
  }
  const uint64_t vertices = base[count];
  if (vertices > UINT32_MAX) return Error{"merge: more than 2^32 vertices", ExitCode::kResourceLimit};
  // Colours or none, alike in every tile that has points (an empty one has nothing to colour).
  int coloured = -1;
  for (size_t i = 0; i < paths.size(); ++i) {
    if (headers[i].vertices == 0) continue;
    if (coloured < 0) coloured = static_cast<int>(i);
    if (headers[i].colors != headers[static_cast<size_t>(coloured)].colors)
      return Error{paths[i] + ": " + (headers[i].colors ? "has" : "lacks") + " colours, unlike " +
                   paths[static_cast<size_t>(coloured)]};
  }
  const bool colors = coloured >= 0 && headers[static_cast<size_t>(coloured)].colors;
  const uint64_t bytes = vertices * (sizeof(glm::dvec3) + (colors ? sizeof(glm::vec3) : 0)) + faces * 3 * sizeof(uint32_t);
  if (Status s = checkMemory("merging " + std::to_string(count) + " tiles", bytes, max_memory); !s) return s.error();

  PointSet out;
  out.positions.reserve(vertices);
  if (colors) out.colors.reserve(vertices);
  out.triangles.reserve(3 * faces);
  struct Copy {
    uint32_t tile;  // the file holding it
    uint64_t at;    // its owner's index in the whole set
    glm::dvec3 position;
    glm::vec3 color;
  };
  std::vector<Copy> copies;
  if (progress) progress->start("merging", count);
  for (uint32_t t = 0; t < count; ++t) {
    const std::string& path = paths[static_cast<size_t>(by_index[t])];
    Result<PointTile> tile = readTile(path);
    if (!tile) return tile.error();
    const PointSet& p = tile->points;
    out.positions.insert(out.positions.end(), p.positions.begin(), p.positions.begin() + tile->owned);
    if (colors) out.colors.insert(out.colors.end(), p.colors.begin(), p.colors.begin() + tile->owned);
    std::vector<uint64_t> global(tile->foreign.size());
    for (size_t f = 0; f < tile->foreign.size(); ++f) {
      const TileVertexRef& ref = tile->foreign[f];
      if (ref.tile >= count || ref.tile == t || ref.index >= base[ref.tile + 1] - base[ref.tile])
        return Error{path + ": foreign vertex " + std::to_string(f) + " refers to vertex " + std::to_string(ref.index) +
                     " of tile " + std::to_string(ref.tile) + ", which does not exist"};
      global[f] = base[ref.tile] + ref.index;
      const size_t local = tile->owned + f;
      copies.push_back({t, global[f], p.positions[local], colors ? p.colors[local] : glm::vec3(0.0f)});
    }
    for (uint32_t index : p.triangles)
      out.triangles.push_back(static_cast<uint32_t>(index < tile->owned ? base[t] + index : global[index - tile->owned]));
    if (progress) progress->advance(1);
  }
  if (progress) progress->finish();
  // The weld is by identity; the copies must agree with their owners bit for bit.
  for (const Copy& c : copies) {
    const bool same_position = std::memcmp(&c.position, &out.positions[c.at], sizeof c.position) == 0;
    const bool same_color = !colors || std::memcmp(&c.color, &out.colors[c.at], sizeof c.color) == 0;
    if (!same_position || !same_color)
      return Error{paths[static_cast<size_t>(by_index[c.tile])] + ": its copy of vertex " + std::to_string(c.at) +
                   " differs from the owner's " + (same_position ? "colour" : "position") +
                   " (tiles of different builds or options?)"};
  }
  return out;
}

}  // namespace dpoint
