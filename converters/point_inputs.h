// Several input files read as one point set (`dpoint render` and `dpoint info` with several
// inputs, e.g. the tiles of `dpoint generate --tile`).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "converters/las_crs.h"
#include "converters/point_io.h"
#include "core/point_set.h"
#include "core/result.h"

namespace dpoint {

// The files one after another, as one set: points concatenated in the order given, triangles
// offset to their file's first point. Tiles of one run, all N of them (converters/tile_file.h), are welded as
// `dpoint merge` welds them, so the set is the whole one, each seam vertex once; any other mix of
// files is read file by file (a tile then brings its copies of seam vertices too). Colours: kept
// when every file with points has them, none when none has; in a mix, the files without get white,
// the colour the renderer gives a set without colours. One path is readPoints(path). Errors are
// the files' own, naming the file. A whole tile set is checked against options.max_memory (as
// mergeTiles checks it), and with points_only or faces_unkept its face rows are not read.
Result<PointSet> readPointInputs(const std::vector<std::string>& paths, const ReadOptions& options = {});

// Scans of one file (PTX's, E57's data3D) as one set, in order: each point's scan number in
// point_source_id (uint16), but for scans of number 0 (where the file has its own ids); colours
// white for a scan without beside one with; a dimension of different types in different scans
// widened as appendPoints widens it; the colours' integer scale the scans' own where they agree,
// else 65535 (which holds 8-bit values exactly).
struct NumberedScan {
  uint64_t number = 0;  // 1 to 65535, or 0: no point_source_id added
  PointSet points;
};
PointSet joinScans(std::vector<NumberedScan> scans);

// Several inputs read as one set: no file given twice (a usage error), and no tile twice among
// tiles of one count (bad input): either had given a set too large with no word. `whole` when the
// paths are the tiles of one run, all N of them, each once (converters/tile_file.h), which are
// read as the merged set; a tile set with tiles left out is read file by file, by design (the
// tiles made so far), and so are one path's tile. `tiles`: how many of the paths are tiles.
struct InputSet {
  bool whole = false;
  size_t tiles = 0;
  std::vector<std::pair<std::string, uint64_t>> in_tile_order;  // whole: tile t's path and owned vertices
};
Result<InputSet> checkInputSet(const std::vector<std::string>& paths);

// One or several binary PLY, LAS, LAZ or E57 files as one stream of points (render's --stream): the points
// readPointInputs(paths) gives, in its order, a block at a time (positions and colours, no
// triangles). A complete tile set streams each tile's owned vertices in tile order (the merged
// set, each seam vertex once, each of its copies checked against it as it is read: a copy that
// differs is mergeTiles' error); other files stream whole, one after another. Colours as in
// readPointInputs: white for the files without in a mix. open() reads the headers (and a tile
// set's copies); errors (ASCII PLY, another format, a bad header) name the file. The copies are
// held for the whole stream: over `max_memory` (0: half of RAM) they are refused before they are
// read (kResourceLimit), as mergeTiles refuses them. A PLY's non-finite coordinate is its reader's
// error unless `allow_nonfinite` (info's --allow-nonfinite), as readPointInputs takes it. LAZ
// chunks are decoded only where their claimed records fit `chunk_memory` (0: half of RAM).
class PointInputStream {
 public:
  static Result<std::unique_ptr<PointInputStream>> open(const std::vector<std::string>& paths, unsigned threads,
                                                        uint64_t max_memory = 0, bool allow_nonfinite = false,
                                                        uint64_t chunk_memory = 0);
  ~PointInputStream();
  uint64_t count() const { return count_; }
  bool hasColors() const { return has_colors_; }
  // Faces in the files' headers: the merged set's triangles for a tile set (each triangle is in
  // one tile), the triangles readPointInputs would give otherwise (as far as every face is one).
  uint64_t faceCount() const { return faces_; }
  // The coordinate system of the first file that states one (readPointInputs's rule): text (a PLY
  // or E57 file's PointSet::crs) or a LAS source's records (converters/las_crs.h).
  const StatedCrs& crs() const { return crs_; }
  // Host bytes held for the whole stream beside its blocks: a tile set's copies, E57 files' packet
  // indexes (0 for other files), and what they are, for a message.
  uint64_t heldBytes() const { return held_bytes_; }
  std::string heldWhat() const {
    return copies_ && e57_index_ ? "seam copies and E57 packet indexes" : copies_ ? "seam copies" : "E57 packet indexes";
  }
  // What the readers read past in the headers, one line each (ReadOptions::notices), and a float
  // PLY's colours read as 0..255 values from its first rows; after the blocks are read, also what
  // they met (float PLY colours above 1, clamped, or a row's colours unlike the first rows': once
  // a file).
  const std::vector<std::string>& notices() const { return notices_; }
  // The first file's dimensions (PLY vertex properties), as empty columns.
  const Dimensions& dimensions() const;
  // The dimensions every file has, as empty columns: each of the first file's type where that holds
  // every later file's values (dimTypeHolds), else float64, as readPointInputs joins them (and as
  // streamDimensions takes them).
  Dimensions commonDimensions() const;
  // From now on read() also gives each block the dimensions `names`, in that order (float64 where
  // the files' types differ), and no others (none: no dimensions). Every file must have each:
  // else an error naming the dimension (kUsage), and the dimensions streamed are as they were.
  Status streamDimensions(const std::vector<std::string>& names);
  // Points [first, first + n) into `block` (resized to n).
  Status read(uint64_t first, uint64_t n, PointSet& block);

 private:
  PointInputStream() = default;
  struct Part;
  struct TileCopies;
  // A complete tile set's copies of seam vertices, each checked against its owner as the owner's
  // block is read (as mergeTiles checks them): a tile of another build is an error, not a seam.
  Status checkCopies(size_t part, uint64_t first, const PointSet& rows) const;
  // A float-colour PLY part's block with a channel above 1: said once a part (notices_).
  void noteColorsAboveOne(Part& part, const glm::vec3* colors, size_t n);
  // A float-colour PLY part whose first rows' colours are whole numbers above 1 (wholeColorScale):
  // each block's colours divided by their scale as a whole read divides them; a row of `first` on
  // whose colour is not such a value is said once a part.
  void takeStreamedColors(Part& part, glm::vec3* colors, size_t n, uint64_t first);
  std::vector<Part> parts_;  // in stream order
  std::unique_ptr<TileCopies> copies_;  // null but for a complete tile set
  uint64_t count_ = 0, faces_ = 0, held_bytes_ = 0;
  StatedCrs crs_;
  bool has_colors_ = false;
  bool e57_index_ = false;  // held_bytes_ counts E57 packet indexes
  unsigned threads_ = 0;
  std::vector<Dimension> streamed_;  // streamDimensions' names and types, no values
  std::vector<std::string> notices_;
  PointSet scratch_;
};

// --stream auto|on|off of render and info: the stream when `stream` is "on", or "auto" and the
// paths are binary PLY, LAS, LAZ or E57 files of more than kStreamAbovePoints points together; nullptr when the
// set is to be read whole. With "on", input that cannot be streamed is an error (an ASCII PLY, a
// bad header: the reader's; another format: kUsage). In memory such a set would take 36 B a point
// (2.4 GB at 2^26) before the upload's own. With "on", a tile set whose copies alone do not fit
// `max_memory` is refused before they are read (kResourceLimit); under "auto" they are held to the
// default limit, and the caller's checkStreamMemory counts them once the stream is chosen.
inline constexpr uint64_t kStreamAbovePoints = uint64_t{1} << 26;
Result<std::unique_ptr<PointInputStream>> openPointStream(const std::vector<std::string>& paths,
                                                          const std::string& stream, unsigned threads,
                                                          uint64_t max_memory = 0, bool allow_nonfinite = false);

}  // namespace dpoint
