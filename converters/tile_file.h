// The part file of a tile (core/tile.h) and the merge of all parts into the whole set.
//
// The file of a tile is a binary little-endian PLY any reader takes as a mesh (owned vertices, then
// the copies; faces index into both): `double x, y, z`, optional `float red, green, blue` (float so
// that the colours come back exactly), `face` lists of 3 `uint`, and an element `dpoint_foreign` of
// `uint tile, uint index` rows, one per copy. Header comments carry `dpoint-tile I/N`,
// `dpoint-tile-owned COUNT` and `dpoint-tile-of SIGNATURE` (the generator and every option that
// shapes the data, so that parts of different runs are never welded together), then
// `dpoint-tile-pad` and dots that make the header's length independent of the counts.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/progress.h"
#include "core/result.h"
#include "core/tile.h"
#include "converters/ply.h"

namespace dpoint {

// Writes the tile file (atomically), its rows made on `threads` cores (0: all). `signature`: one
// line of text, no newline.
Status writeTile(const std::string& path, const PointTile& tile, const std::string& signature,
                 Progress* progress = nullptr, unsigned threads = 0);

// The same file from rows made elsewhere (a device's marching cubes: generators/escape_grid.h
// EscapeRowSink with float colours), written as they come: start and add as PlyRowStream's, with
// the vertex rows (x, y, z as doubles, with colours red, green, blue as floats:
// kTileRowBytesColored) of the owned vertices, then the copies; finish() takes the owned count and
// the copies' references. The file is writeTile's for the same tile, byte for byte, or nothing.
constexpr size_t kTileRowBytes = 24, kTileRowBytesColored = 36;
class TileRowStream {
 public:
  // Null where `path` takes no positional writes (PlyRowStream::create).
  static Result<std::unique_ptr<TileRowStream>> create(const std::string& path, TileSpec tile,
                                                       const std::string& signature, bool colors, unsigned threads,
                                                       Progress* progress);
  TileRowStream(const TileRowStream&) = delete;  // the header's maker points at this object
  TileRowStream& operator=(const TileRowStream&) = delete;

  Status start(uint64_t vertices, uint64_t faces) { return rows_->start(vertices, faces); }
  Status add(std::span<const uint8_t> vertex_rows, std::span<const uint8_t> face_rows) {
    return rows_->add(vertex_rows, face_rows);
  }
  Status finish(uint32_t owned, std::span<const TileVertexRef> foreign);
  // The rows written so far, and after finish whether they were moved (PlyRowStream's).
  const PlyRowStream& rows() const { return *rows_; }

 private:
  TileRowStream() = default;
  std::unique_ptr<PlyRowStream> rows_;
  uint64_t owned_ = 0, foreign_ = 0;  // the header's, until finish
};

// What a tile file's header says.
struct TileHeader {
  TileSpec tile;
  uint32_t owned = 0;
  std::string signature;
  uint64_t vertices = 0, faces = 0, foreign = 0;
  bool colors = false;
};

// True when the file starts like a tile file (a PLY whose header has a `dpoint-tile` comment);
// reads the header only.
bool isTileFile(const std::string& path);
// Errors (kBadInput) name the file and the header line or the byte offset.
Result<TileHeader> readTileHeader(const std::string& path);
Result<PointTile> readTile(const std::string& path);

// The whole set from all N tiles of one run, in any order of `paths`: owned vertices of tile 0, 1,
// ... concatenated, triangles with their indices offset, every copy of a foreign vertex checked
// against its owner. Errors (kBadInput) name the file: a missing, repeated or extra tile, tiles of
// different runs (signatures) or counts, a reference past its owner's vertices, a copy that differs
// from its owner; kResourceLimit past 2^32 vertices or over `max_memory` (0: half of RAM). The
// parts are read on `threads` cores (0: all), each block of rows straight into its place. Without
// `faces` (for a point format) the face rows are not read: the set has no triangles, and their
// bytes are neither held nor counted against max_memory (the tiles' sizes are still checked).
Result<PointSet> mergeTiles(const std::vector<std::string>& paths, uint64_t max_memory = 0,
                            Progress* progress = nullptr, unsigned threads = 0, bool faces = true);
// The copies' references of all N tiles of one run, in any order of `paths`, checked as mergeTiles
// checks them (every tile once, one run, each reference to an owned vertex that exists; but any
// number of vertices, 2^32 and more), by tile: refs[t][f] is the owner of tile t's copy f (its
// vertex owned + f). For a reader that streams the owned vertices (PointInputStream), to check
// each copy against its owner as that passes. It opens every file, and closes them on return.
Result<std::vector<std::vector<TileVertexRef>>> readTileCopyRefs(const std::vector<std::string>& paths,
                                                                 unsigned threads = 0);
// mergeTiles' error for a copy in `path` of the whole set's vertex `vertex` that differs from it.
Error tileCopyDiffers(const std::string& path, uint64_t vertex, bool same_position);

// The same merge streamed into the binary PLY file writePly would write of mergeTiles' set, byte
// for byte, without holding the set: every tile's rows are read, welded and made into the file's
// rows on options.threads cores and written in order, the copies checked against their owners on
// the way. For options that canMergeToPly accepts (binary, uchar colours).
bool canMergeToPly(const PlyWriteOptions& options);
// What it holds (the copies' rows, a few blocks a thread) is checked against max_memory (0: half of
// RAM), kResourceLimit above it.
Status mergeTilesToPly(const std::vector<std::string>& paths, const std::string& output, const PlyWriteOptions& options,
                       uint64_t max_memory = 0);

}  // namespace dpoint
