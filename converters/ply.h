// PLY point and mesh files (ASCII and binary little-endian; binary big-endian is read too).
//
// Reading: a `vertex` element with x, y, z of any numeric type (float and double are the usual
// ones), optional red, green, blue (uchar scaled by 1/255, or float/double taken as 0..1),
// other vertex properties skipped; an optional `face` element whose vertex_indices (or
// vertex_index) list is fan-triangulated. Other elements are skipped. Errors name the file and
// the header line, or the byte offset / ASCII line of the bad data; the first bad row in the
// file gives the error.
//
// Binary vertices without list properties (the usual case) are decoded in blocks on all cores,
// each row into its preassigned index, so the result is the same for any thread count. Memory:
// the PointSet plus one block per thread. Binary faces, and ASCII vertex and face rows, are read
// in blocks on all cores too, up to the first row of another kind (a binary face of another size
// than the first, a blank or bad line), from which one thread goes on; other elements are read on
// one thread. The
// header's counts are checked against the data that follows it and against max_memory before
// anything is allocated, and the triangles of the faces against max_memory as they are made.
//
// Writing: `double x,y,z`, colours as `uchar` (default, read by every tool) or `float`,
// and `face` lists of three `uint` indices for meshes.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/input_file.h"
#include "core/memory.h"
#include "core/point_set.h"
#include "core/progress.h"
#include "core/result.h"

namespace dpoint {

// The header comment word of a tile of `generate --tile` (`comment dpoint-tile I/N`,
// converters/tile_file.h): its float colours are generate's own, not read as fractions from a file.
inline constexpr const char* kPlyTileCommentWord = "dpoint-tile";

enum class PlyEncoding { kBinary, kAscii };
// The colour properties' type. kAuto: ushort for a set whose colours came as 16-bit integers
// (PointSet::color_full_scale 65535: LAS), so they keep every bit, else uchar; kUchar: 8-bit
// whatever the source (what Open3D and PCL read); kFloat: exact.
enum class PlyColorType { kAuto, kUchar, kUshort, kFloat };
// "auto", "uchar", "ushort" or "float"; nullopt for another word.
std::optional<PlyColorType> parsePlyColorType(const std::string& text);

struct PlyReadOptions {
  bool allow_nonfinite = false;
  Progress* progress = nullptr;  // thread-safe advance() is called from every reading thread
  unsigned threads = 0;          // 0: all cores (last, so that {allow_nonfinite, progress} still reads)
  // The caller wants positions and colours only (a renderer): reading stops after the vertex
  // element, so faces and any later element are neither read nor checked.
  bool points_only = false;
  uint64_t max_memory = 0;  // bytes for the point set (--max-memory); 0: defaultMemoryLimit()
  // The caller keeps no faces (a conversion to a point format): as points_only where the file's
  // size shows its face rows whole (binary, the face element last, triangles of a one-byte count
  // and 32-bit indices: 13 bytes each, the file ending with the last), so that a file cut short or
  // with bytes after its end is still refused; else the faces are read and checked as ever. The
  // triangles' indices are then not checked.
  bool faces_unkept = false;
  std::vector<std::string>* notices = nullptr;  // what the header held that is left out (a bad CRS)
};

// Colours of `count` rows whose positions are `positions` into colors[0 .. count), made on demand;
// called from several threads at once.
using ColorSource = std::function<void(const glm::dvec3* positions, size_t count, glm::vec3* colors)>;

struct PlyWriteOptions {
  PlyEncoding encoding = PlyEncoding::kBinary;
  PlyColorType color_type = PlyColorType::kAuto;
  Progress* progress = nullptr;
  unsigned threads = 0;  // rows formatted on this many cores (0: all); the bytes do not depend on it
  // Set, for a set without colours: the colours, made chunk by chunk as the rows are formatted
  // (a generator's noise colours then take no time of their own, nor 12 bytes a point); the file
  // is the one the set with those colours gives.
  ColorSource colors_of;
  // Set, for a set that holds no points but their facts (z axis, source): positions_of.count
  // vertex rows whose positions are made chunk by chunk as the rows are formatted (core/point_set.h);
  // the file is the one the set holding those positions gives. The set then has no colours,
  // triangles or dimensions (colours may come from colors_of).
  MadePositions positions_of;
  // When not null, gets a line for each dimension written under another name (plyPropertyNames).
  std::vector<std::string>* notices = nullptr;
  // When not null, the coordinate-system text the header states (`comment dpoint: crs` lines) in
  // place of the set's own (PointSet::crs): --crs's WKT, or none (empty) where the set's cannot go
  // in a header (writePoints). A LAS source's records are written where no text is.
  const std::string* crs = nullptr;
};

Result<PointSet> readPly(const std::string& path, const PlyReadOptions& options = {});
// The same from an opened file, or from bytes in memory (InputFile::fromMemory).
Result<PointSet> readPly(const InputFile& file, const PlyReadOptions& options = {});
Status writePly(const std::string& path, const PointSet& points, const PlyWriteOptions& options = {});
// The header writePly writes for a set with `facts`' source facts, colour scale and dimensions, but
// these counts, colours or none and z or none: for writers of the rows from elsewhere (the streamed
// tile merge, converters/tile_file.h), whose file must be writePly's byte for byte.
std::string plyHeader(const PointSet& facts, uint64_t vertices, uint64_t faces, bool colors, bool has_z,
                      const PlyWriteOptions& options);
// The property names plyHeader gives `dimensions`: one word each, none that the readers take for a
// position or a colour (x, y, z, red, green, blue; and, without `colors`, diffuse_red, diffuse_green
// and diffuse_blue when all three are there), none twice (writableNames); `renamed` gets a line
// for each name changed.
inline constexpr const char* kDiffuseNames[] = {"diffuse_red", "diffuse_green", "diffuse_blue"};
std::vector<std::string> plyPropertyNames(const Dimensions& dimensions, bool colors, std::vector<std::string>* renamed);

// How a PlyRowStream's file is laid out where it is not writePly's (a tile's part file,
// converters/tile_file.h): the vertex row's bytes, and the header for the counts (has_z: some vertex
// has a z other than +0); the elements after the faces are finish()'s `trailer`.
struct PlyRowLayout {
  size_t row_bytes = 24;
  std::function<std::string(uint64_t vertices, uint64_t faces, bool has_z)> header;
};

// A binary PLY mesh whose rows are made elsewhere and written as they come (a device's marching
// cubes: generators/escape_grid.h EscapeRowSink): vertex rows of x, y, z as doubles and, with
// colours, red, green, blue as bytes; face rows of the byte 3 and three uint ids. The header holds
// the counts, known only at the end, so it is laid out from estimates and the vertex rows are
// written after it as they come. The face rows wait in memory until the last vertex is written,
// then follow; the real header goes over the estimated one, and where its length differs (the
// counts' digits did) the vertex rows are moved first. The file is writePly's for the same mesh,
// byte for byte, or nothing (a failed or abandoned stream leaves no file).
class PlyRowStream {
 public:
  // Opens the output (AtomicFile); null where it is not a regular file (a pipe or a device, which
  // take no positional writes: write the set with writePly instead).
  static Result<std::unique_ptr<PlyRowStream>> create(const std::string& path, bool colors, unsigned threads,
                                                      Progress* progress);
  // The same with another layout; colors() says whether its rows carry colours.
  static Result<std::unique_ptr<PlyRowStream>> create(const std::string& path, bool colors, PlyRowLayout layout,
                                                      unsigned threads, Progress* progress);
  ~PlyRowStream();
  PlyRowStream(const PlyRowStream&) = delete;
  PlyRowStream& operator=(const PlyRowStream&) = delete;

  // Once, before add: lays the header out for these estimated counts. Fails (exit 4) where the disk
  // cannot hold half the file they make (AtomicFile::checkSpace).
  Status start(uint64_t vertices, uint64_t faces);
  // The next rows: the vertex rows, written now after the ones before; the face rows, kept. Whole
  // rows (rowBytes() and kFaceRowBytes each). From one thread at a time.
  Status add(std::span<const uint8_t> vertex_rows, std::span<const uint8_t> face_rows);
  // The face rows, then `trailer` (the layout's elements after them), and the real header, then the
  // file is committed.
  Status finish(std::span<const uint8_t> trailer = {});

  bool started() const { return started_; }
  bool colors() const { return colors_; }
  size_t rowBytes() const { return layout_.row_bytes; }  // a vertex row: x, y, z, and the colours
  uint64_t vertices() const { return vertices_; }
  uint64_t faces() const { return faces_.size() / kFaceRowBytes; }
  // After finish: whether the vertex rows were moved (the estimate had other digits).
  bool moved() const { return moved_; }

  static constexpr size_t kFaceRowBytes = 13;

 private:
  PlyRowStream(AtomicFile file, bool colors, PlyRowLayout layout, unsigned threads, Progress* progress);

  AtomicFile file_;
  bool colors_ = false;
  PlyRowLayout layout_;
  unsigned threads_ = 0;
  Progress* progress_ = nullptr;
  bool started_ = false, moved_ = false;
  bool has_z_ = false;          // some vertex has a z other than +0 (PointSet::isPlanar)
  size_t header_bytes_ = 0;     // the estimated header's length: where the vertex rows begin
  uint64_t vertices_ = 0;
  std::vector<uint8_t, DefaultInitAllocator<uint8_t>> faces_;
};

// The vertices of a binary PLY file a range at a time, for a renderer drawing a file larger than
// memory should hold. open() reads the header with readPly's checks; an ASCII file, or one with
// list rows before its vertices (whose offsets are unknown until read), fails naming why. read()
// replaces `block` with vertex rows [first, first + n) (first + n ≤ count(), asserted): positions,
// and colours when hasColors(), with readPly's values and errors (whole-file row numbers), decoded
// on options.threads cores. Elements after the vertices are not read. read() may be called from
// one thread at a time.
class PlyVertexStream {
 public:
  static Result<std::unique_ptr<PlyVertexStream>> open(const std::string& path, const PlyReadOptions& options = {});
  ~PlyVertexStream();
  uint64_t count() const;
  bool hasColors() const;
  // Colours of a float or double type in a file not of `generate --tile`: 0..1 by PLY's rule, but
  // some tools write 0..255 values there, which readPoints reads whole as such (wholeColorScale)
  // and a stream can only clamp block by block.
  bool floatColors() const;
  uint64_t faceCount() const;  // the header's `face` rows (0 without the element)
  // The coordinate system its header states (`comment dpoint: crs`, as readPly's PointSet::crs), and
  // a LAS source's frame and records (`comment dpoint: las frame` and `las crs`, as readPly's
  // PointSet::las).
  const std::string& crs() const;
  const std::optional<LasSource>& las() const;
  // The vertex properties that are dimensions, as empty columns (names and types).
  const Dimensions& dimensions() const;
  // From now on read() also fills these of dimensions() (by index) into the block; none by default.
  void streamDimensions(std::vector<size_t> which);
  Status read(uint64_t first, uint64_t n, PointSet& block);

 private:
  PlyVertexStream() = default;
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace dpoint
