// COPC (Cloud Optimized Point Cloud, specification 1.0, https://copc.io): a LAZ 1.4 file whose
// variable-sized chunks are the nodes of an octree, so that a reader fetches only the nodes a view
// needs, and every LAZ reader still reads the whole file as plain LAZ. dpoint's own code, from the
// specification's text (github.com/copcio/copcio.github.io) and what PDAL's writers.copc and
// copc.js (npm `copc`) do where it leaves a choice open.
//
// The format, as written and relied on here:
// - LAS 1.4 header (375 bytes), point formats 6, 7 or 8 (format byte | 0x80), then the "info" VLR
//   (user "copc", record 1, 160 bytes) first, at byte 375: the octree's cube (centre, half size),
//   the point spacing at the root (halved per level), the root hierarchy page's offset and size, the
//   GPS time range and 11 reserved zeros.
// - A laszip VLR with variable chunks (compressor 3, laz_layered.h): one chunk per octree node.
// - The hierarchy EVLR (user "copc", record 1000): pages of 32-byte entries, a key (level, x, y,
//   z: the node covers the cube's 1/2^level part at that cell) with the chunk's offset, byte size
//   and point count; a count of −1 points at a child page (offset and size of the page), 0 marks an
//   empty node. A child page holds its key's node and the subtree below it.
// - Every point lies in its node's cube; the sum of the nodes' counts is the header's.
//
// How dpoint lays out the cube: its edge the bounds' largest extent, its minimum corner theirs (a
// short axis then fills as few nodes as it can). How it thins (copcFromLasBytes): each node lays a grid of 2^grid_levels cells per edge over
// its cube (the root's cell size is the info VLR's spacing) and keeps, of the points that reach it,
// one per occupied cell: the one with the smallest hash of its index (a fair, unbiased pick, as
// Poisson-disk-like as a grid gets). Past `max_points_per_node` kept cells it keeps that many of
// them, again by hash. The rest go down to the eight children. A node reached by at most
// max_points_per_node points keeps them all and has no children. So every level is a uniform
// sample of the whole at its spacing, and the result depends on the input alone (not on threads).
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "converters/laz_decode.h"
#include "core/input_file.h"
#include "core/result.h"

namespace dpoint {

// An octree node: depth `level` (0: the root) and its cell among the 2^level per axis.
struct CopcKey {
  int32_t level = 0, x = 0, y = 0, z = 0;
  friend bool operator==(const CopcKey&, const CopcKey&) = default;
  friend auto operator<=>(const CopcKey&, const CopcKey&) = default;
};
// "level-x-y-z", as EPT and copc.js name nodes.
std::string copcKeyName(const CopcKey& key);

// The info VLR.
struct CopcInfo {
  double center[3] = {0, 0, 0};
  double halfsize = 0;
  double spacing = 0;  // between points at the root; spacing / 2^level at a level
  uint64_t root_hier_offset = 0, root_hier_size = 0;
  double gpstime_minimum = 0, gpstime_maximum = 0;
};

// A box in world coordinates, its faces included.
struct CopcBox {
  double min[3] = {-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                   -std::numeric_limits<double>::infinity()};
  double max[3] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                   std::numeric_limits<double>::infinity()};
};
// The cube a node covers.
CopcBox copcNodeCube(const CopcInfo& info, const CopcKey& key);

// --- Writing ---------------------------------------------------------------------------------------

struct CopcWriteOptions {
  unsigned threads = 0;                  // 0: all cores; the file does not depend on it
  uint32_t max_points_per_node = 100000;  // ≥ 1; a node at the deepest level may hold more
  int grid_levels = 7;                   // 1..10: each node thins on 2^7 = 128 cells per edge
  // Hierarchy pages, as PDAL pages them: a subtree starting `page_levels` below its page's root gets
  // a page of its own when it has more than `page_min_nodes` nodes (page_levels 0: one page).
  int page_levels = 4;
  uint32_t page_min_nodes = 50;
  uint64_t seed = 1;  // of the hash that picks the point kept in a cell
};

// A whole uncompressed LAS 1.4 file (point format 6, 7 or 8, extra bytes allowed) as a COPC file.
// Keeps the header's fields but those COPC sets (header size 375, the WKT bit of the global
// encoding, which LAS 1.4 requires of formats 6–10, bounds, counts by return, legacy counts 0 as
// for every format 6–10 file dpoint writes) and keeps every VLR and EVLR but a laszip or copc one
// (the info VLR first, the hierarchy EVLR first among the EVLRs). Records keep their bytes; their
// order is the nodes' (level by level), within a node the input's. Fails, naming what is wrong, for
// input that is not LAS 1.4, not of formats 6–8, compressed, with records or VLRs past its end, with
// a scale that is 0 or not finite, or with more than 2^32 − 1 points.
Result<std::string> copcFromLasBytes(std::string_view las14, const CopcWriteOptions& options = {});

// --- Reading ---------------------------------------------------------------------------------------

// True when the file starts like a COPC file: "LASF" and the info VLR (user "copc", record 1) at
// byte 375. Reads 400 bytes; never fails (an unreadable file is not COPC).
bool isCopc(const InputFile& file);

// What a COPC reader needs of the header and VLRs.
struct CopcHeader {
  CopcInfo info;
  int point_format = 0;
  uint32_t record_length = 0;
  uint64_t point_count = 0;
  uint64_t point_data_offset = 0;
  double scale[3] = {1, 1, 1}, offset[3] = {0, 0, 0};
  double min[3] = {0, 0, 0}, max[3] = {0, 0, 0};  // the header's bounds, as written
  LazInfo laz;
};
// Parses and checks the header, the info VLR and the laszip VLR. Errors start with the file's path.
Result<CopcHeader> readCopcHeader(const InputFile& file);

// One hierarchy entry with data (or an empty node: 0 points, offset and bytes 0).
struct CopcNode {
  CopcKey key;
  uint64_t offset = 0;
  int32_t bytes = 0;
  int32_t points = 0;
};

struct CopcQuery {
  CopcBox box;              // nodes whose cube meets it (everything by default)
  double resolution = 0;    // world units: levels down to the first whose spacing is ≤ it; 0: all
  // Where set, also only the nodes it accepts (a perspective view: its frustum and a resolution
  // that falls with the distance). It must accept a node's ancestors wherever it accepts the node
  // (a rejected node's subtree is not read).
  std::function<bool(const CopcBox& cube, int level)> select;
  unsigned threads = 0;     // 0: all cores
  uint64_t max_memory = 0;  // for the records; 0: defaultMemoryLimit()
};

// The hierarchy's nodes that `query` selects (with points or not), read lazily: a child page is
// read only when its key is selected. Sorted by key. When the query left no node or page out (a
// read of everything, or a view that takes the whole tree), checks that the nodes' points add up
// to the header's count. `bytes_read` (may be null) gets the pages' bytes.
// Hostile input: every entry is checked (key within its level, chunk within the file, a page read
// once, pages not adding up to more than the file); errors name the file, page and entry.
Result<std::vector<CopcNode>> readCopcNodes(const InputFile& file, const CopcHeader& header, const CopcQuery& query,
                                            uint64_t* bytes_read = nullptr);

// What a selective read read.
struct CopcNodeRead {
  uint64_t points = 0;  // records returned
  uint64_t bytes = 0;   // bytes read from the file: header, VLRs, hierarchy pages, chunks
  uint64_t nodes = 0;   // chunks decoded
};

// The uncompressed records (header.record_length bytes each) of every node readCopcNodes selects,
// node after node in key order, each node's as its chunk holds them; the chunks decoded on
// query.threads threads (the result does not depend on it). Points of a selected node outside the
// box are returned too: the caller clips. Errors name the file, the node and its byte offset.
// `stats` may be null.
Result<std::string> readCopcRecords(const InputFile& file, const CopcQuery& query, CopcNodeRead* stats = nullptr);

}  // namespace dpoint
