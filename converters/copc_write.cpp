// COPC write (converters/copc.h says what and whence): parse the LAS 1.4 input, measure it
// (bounds, returns, GPS times), quantize every point to 32 bits per axis of the cube, thin level by
// level into the octree, compress one LAZ chunk per node on all cores, then lay out header, VLRs,
// chunks, chunk table and hierarchy pages. The reader is copc_read.cpp.
#include "converters/copc.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <optional>

#include "converters/copc_format.h"
#include "converters/laz_encode.h"
#include "core/bytes.h"
#include "core/interrupt.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "ops/point_order.h"

namespace dpoint {

using namespace copc_detail;

namespace {

std::string vlrHeader(const char* user, uint16_t record, uint16_t length, const char* description) {
  std::string h(kVlrHeaderBytes, '\0');
  std::memcpy(h.data() + 2, user, std::min<size_t>(16, std::strlen(user)));
  storeUnaligned<uint16_t>(h.data() + 18, record);
  storeUnaligned<uint16_t>(h.data() + 20, length);
  std::memcpy(h.data() + 22, description, std::min<size_t>(32, std::strlen(description)));
  return h;
}

std::string evlrHeader(const char* user, uint16_t record, uint64_t length, const char* description) {
  std::string h(kEvlrHeaderBytes, '\0');
  std::memcpy(h.data() + 2, user, std::min<size_t>(16, std::strlen(user)));
  storeUnaligned<uint16_t>(h.data() + 18, record);
  storeUnaligned<uint64_t>(h.data() + 20, length);
  std::memcpy(h.data() + 28, description, std::min<size_t>(32, std::strlen(description)));
  return h;
}

// --- The input -------------------------------------------------------------------------------------

struct LasInput {
  std::string_view header;  // the first 375 bytes
  int format = 0;
  uint16_t record_length = 0;
  uint64_t count = 0;
  const char* records = nullptr;
  std::vector<std::string_view> vlrs, evlrs;  // kept ones, header and data
  double scale[3] = {1, 1, 1}, offset[3] = {0, 0, 0};
};

Result<LasInput> parseLas14(std::string_view las) {
  if (las.size() < kHeader14 || las.substr(0, 4) != "LASF")
    return Error{"not a LAS 1.4 file (no 'LASF' header of 375 bytes)"};
  const char* h = las.data();
  const int major = static_cast<uint8_t>(h[kVersionMajorAt]), minor = static_cast<uint8_t>(h[kVersionMinorAt]);
  const uint16_t header_size = loadUnaligned<uint16_t>(h + kHeaderSizeAt);
  if (major != 1 || minor != 4 || header_size < kHeader14)
    return Error{"COPC is written from LAS 1.4 (a 375-byte header); this is LAS " + std::to_string(major) + "." +
                 std::to_string(minor) + " with a " + str(header_size) + "-byte header"};
  LasInput in;
  in.header = las.substr(0, kHeader14);
  const uint8_t raw_format = static_cast<uint8_t>(h[kFormatAt]);
  if (raw_format & 0xC0) return Error{"the records are compressed already (point format byte " + str(raw_format) + ")"};
  in.format = raw_format;
  if (in.format < 6 || in.format > 8)
    return Error{"COPC holds point formats 6 to 8 only, not " + str(raw_format)};
  in.record_length = loadUnaligned<uint16_t>(h + kRecordLengthAt);
  static constexpr uint16_t kBase[3] = {30, 36, 38};  // formats 6, 7, 8
  if (in.record_length < kBase[in.format - 6])
    return Error{"point record length " + str(in.record_length) + " is shorter than point format " +
                 str(raw_format) + "'s " + str(kBase[in.format - 6]) + " bytes"};
  const uint64_t point_offset = loadUnaligned<uint32_t>(h + kPointOffsetAt);
  in.count = loadUnaligned<uint64_t>(h + kCountAt);
  if (in.count == 0) in.count = loadUnaligned<uint32_t>(h + kLegacyCountAt);
  if (point_offset < header_size || point_offset > las.size())
    return Error{"header: the offset to point data " + str(point_offset) + " is outside the " + str(las.size()) +
                 "-byte file"};
  if (in.record_length == 0 || in.count > (las.size() - point_offset) / in.record_length)
    return Error{str(in.count) + " records of " + str(in.record_length) + " bytes run past the file's end"};
  if (in.count > UINT32_MAX) return Error{str(in.count) + " points: dpoint's COPC writer takes at most 2^32 - 1"};
  in.records = h + point_offset;
  for (size_t a = 0; a < 3; ++a) {
    in.scale[a] = loadUnaligned<double>(h + kScaleAt + 8 * a);
    in.offset[a] = loadUnaligned<double>(h + kOffsetAt + 8 * a);
    if (!std::isfinite(in.scale[a]) || in.scale[a] == 0 || !std::isfinite(in.offset[a]))
      return Error{"header: scale " + std::to_string(in.scale[a]) + " or offset " + std::to_string(in.offset[a]) +
                   " of axis " + "XYZ"[a] + " is 0 or not finite"};
  }

  // VLRs and EVLRs but laszip's and COPC's own (a COPC input's are rewritten).
  const auto kept = [](const char* header) { return userId(header) != "copc" && userId(header) != "laszip encoded"; };
  size_t at = header_size;
  const uint32_t vlr_count = loadUnaligned<uint32_t>(h + kVlrCountAt);
  for (uint32_t i = 0; i < vlr_count; ++i) {
    if (point_offset - at < kVlrHeaderBytes ||
        point_offset - at - kVlrHeaderBytes < loadUnaligned<uint16_t>(h + at + 20))
      return Error{"VLR " + str(i) + " at byte " + str(at) + " runs past the offset to point data " + str(point_offset)};
    const size_t bytes = kVlrHeaderBytes + loadUnaligned<uint16_t>(h + at + 20);
    if (kept(h + at)) in.vlrs.push_back(las.substr(at, bytes));
    at += bytes;
  }
  uint64_t evlr_at = loadUnaligned<uint64_t>(h + kEvlrStartAt);
  const uint32_t evlr_count = loadUnaligned<uint32_t>(h + kEvlrCountAt);
  if (evlr_count != 0 && evlr_at < point_offset + in.count * in.record_length)
    return Error{"header: the EVLRs' start " + str(evlr_at) + " lies inside the point records"};
  for (uint32_t i = 0; i < evlr_count; ++i) {
    if (evlr_at > las.size() || las.size() - evlr_at < kEvlrHeaderBytes ||
        las.size() - evlr_at - kEvlrHeaderBytes < loadUnaligned<uint64_t>(h + evlr_at + 20))
      return Error{"EVLR " + str(i) + " at byte " + str(evlr_at) + " runs past the file's end"};
    const uint64_t bytes = kEvlrHeaderBytes + loadUnaligned<uint64_t>(h + evlr_at + 20);
    if (kept(h + evlr_at)) in.evlrs.push_back(las.substr(evlr_at, bytes));
    evlr_at += bytes;
  }
  return in;
}

// What the header says of the records: bounds (as integers), points by return, GPS times.
struct RecordStats {
  int32_t lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, hi[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
  uint64_t by_return[15] = {};
  double gps_min = std::numeric_limits<double>::infinity(), gps_max = -std::numeric_limits<double>::infinity();

  void merge(const RecordStats& o) {
    for (size_t a = 0; a < 3; ++a) lo[a] = std::min(lo[a], o.lo[a]), hi[a] = std::max(hi[a], o.hi[a]);
    for (size_t r = 0; r < 15; ++r) by_return[r] += o.by_return[r];
    gps_min = std::min(gps_min, o.gps_min);
    gps_max = std::max(gps_max, o.gps_max);
  }
};

RecordStats measure(const LasInput& in, unsigned threads) {
  constexpr uint64_t kBlock = 1 << 16;
  std::vector<RecordStats> blocks(static_cast<size_t>((in.count + kBlock - 1) / kBlock));
  parallelFor(blocks.size(), threads, [&](size_t b, unsigned) {
    if (interrupted()) return;  // copcFromLasBytes stops
    RecordStats& s = blocks[b];
    const uint64_t end = std::min(in.count, (b + 1) * kBlock);
    for (uint64_t i = b * kBlock; i < end; ++i) {
      const char* r = in.records + i * in.record_length;
      for (size_t a = 0; a < 3; ++a) {
        const int32_t v = loadUnaligned<int32_t>(r + 4 * a);
        s.lo[a] = std::min(s.lo[a], v);
        s.hi[a] = std::max(s.hi[a], v);
      }
      const unsigned ret = static_cast<uint8_t>(r[14]) & 0x0Fu;  // formats 6-10: return number, bits 0-3
      if (ret != 0) ++s.by_return[ret - 1];
      const double t = loadUnaligned<double>(r + 22);
      // NaN times stay out of the range (min/max with NaN would depend on the order).
      if (t < s.gps_min) s.gps_min = t;
      if (t > s.gps_max) s.gps_max = t;
    }
  });
  RecordStats all;
  for (const RecordStats& s : blocks) all.merge(s);
  return all;
}

// --- The octree ------------------------------------------------------------------------------------

struct Node {
  CopcKey key;
  std::vector<uint32_t> points;  // input record indices, ascending
  std::array<int32_t, 8> children = {-1, -1, -1, -1, -1, -1, -1, -1};
  uint32_t subtree = 1;  // nodes in the subtree, this one included
};

// Each point's position in the cube as 32-bit fixed point per axis: node (level d) = q >> (32 − d).
struct Quantized {
  std::vector<uint32_t> q[3];
};

// The top 21 bits of each axis interleaved (z y x, from the top): the Morton curve's order.
uint64_t mortonKey(const Quantized& qz, uint32_t p) {
  return mortonInterleave(qz.q[0][p] >> 11, qz.q[1][p] >> 11, qz.q[2][p] >> 11);
}

// What LAZ's coding of a node's records in this order costs, roughly: the bits of each difference
// of x, y and z from the point before, and of each GPS time step (of the times' bit patterns) from
// the step before, as LAZ predicts a time from the last step. Enough to tell an order whose
// neighbours are near in space and time from one whose are not.
uint64_t orderCost(const char* records, uint16_t length, const std::vector<uint32_t>& order) {
  const auto bits = [](uint64_t a, uint64_t b) { return static_cast<uint64_t>(std::bit_width(a > b ? a - b : b - a)); };
  uint64_t total = 0, last_step = 0;
  for (size_t i = 1; i < order.size(); ++i) {
    const char* a = records + uint64_t{order[i - 1]} * length;
    const char* b = records + uint64_t{order[i]} * length;
    for (size_t k = 0; k < 3; ++k) {
      // Offset by 2^31: the int32 values as uint32, whose differences have the same magnitudes.
      total += bits(loadUnaligned<uint32_t>(a + 4 * k) ^ 0x80000000u, loadUnaligned<uint32_t>(b + 4 * k) ^ 0x80000000u);
    }
    const uint64_t step = loadUnaligned<uint64_t>(b + 22) - loadUnaligned<uint64_t>(a + 22);
    total += bits(step, last_step);
    last_step = step;
  }
  return total;
}

// A node's points in the order that codes smaller: the input's (a scanner's order keeps neighbours
// in space and time together; its leaves keep runs of it) or, where that order is scattered (a
// generator's, a shuffled file's), along the Morton curve. The choice depends on the data alone.
void chooseOrder(const Quantized& qz, const char* records, uint16_t length, std::vector<uint32_t>& points,
                 std::vector<std::pair<uint64_t, uint32_t>>& keys, std::vector<uint32_t>& morton) {
  keys.resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) keys[i] = {mortonKey(qz, points[i]), points[i]};
  std::sort(keys.begin(), keys.end());
  morton.resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) morton[i] = keys[i].second;
  if (orderCost(records, length, morton) < orderCost(records, length, points)) points.swap(morton);
}

// The hash that picks a cell's point: SplitMix64's finalizer of index and seed (any point of a cell
// is equally likely to be kept; ties, which a 32-bit hash has, go to the smaller index).
uint64_t priority(uint32_t index, uint64_t seed) {
  uint64_t z = index + seed * 0x9E3779B97F4A7C15u + 0x9E3779B97F4A7C15u;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9u;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBu;
  z ^= z >> 31;
  return (z & 0xFFFFFFFF00000000u) | index;
}

// Open addressing from a cell to the smallest priority offered for it.
class CellTable {
 public:
  void reset(size_t cells) {
    slots_.assign(std::bit_ceil(std::max<size_t>(16, 2 * cells)), Slot{});
    mask_ = slots_.size() - 1;
  }
  void offer(uint32_t cell, uint64_t key) {
    for (size_t i = (cell * 0x9E3779B1u) & mask_;; i = (i + 1) & mask_) {
      Slot& s = slots_[i];
      if (s.cell == cell + 1) {
        s.key = std::min(s.key, key);
        return;
      }
      if (s.cell == 0) {
        s = {cell + 1, key};
        return;
      }
    }
  }
  void winners(std::vector<uint64_t>& out) const {
    out.clear();
    for (const Slot& s : slots_)
      if (s.cell != 0) out.push_back(s.key);
  }

 private:
  struct Slot {
    uint32_t cell = 0;  // cell + 1; 0: free
    uint64_t key = 0;
  };
  std::vector<Slot> slots_;
  size_t mask_ = 0;
};

struct Range {
  uint32_t begin = 0, end = 0;
};

struct Scratch {
  CellTable table;
  std::vector<uint64_t> winners;
};

// Thins one node at `level` reached by the points cur[r.begin, r.end) (ascending): fills `kept`
// and writes the others to next[r.begin, …) grouped by child octant, each group ascending.
void thinNode(const Quantized& qz, int level, const CopcWriteOptions& o, Range r, const uint32_t* cur, uint32_t* next,
              uint8_t* taken, Scratch& scratch, std::vector<uint32_t>& kept, std::array<Range, 8>& children) {
  const uint32_t n = r.end - r.begin;
  const uint32_t* in = cur + r.begin;
  const uint32_t *qx = qz.q[0].data(), *qy = qz.q[1].data(), *qz_ = qz.q[2].data();
  bool leaf = n <= o.max_points_per_node || level >= 32 - o.grid_levels;
  if (!leaf) {  // points that all quantize alike never part: one leaf holds them
    leaf = true;
    for (uint32_t i = 1; i < n && leaf; ++i)
      leaf = qx[in[i]] == qx[in[0]] && qy[in[i]] == qy[in[0]] && qz_[in[i]] == qz_[in[0]];
  }
  if (leaf) {
    kept.assign(in, in + n);
    return;
  }
  const int g = o.grid_levels;
  const int shift = 32 - level - g;
  const uint32_t mask = (1u << g) - 1;
  scratch.table.reset(std::min<size_t>(n, size_t{1} << (3 * g)));
  for (uint32_t i = 0; i < n; ++i) {
    if (i % 65536 == 0 && interrupted()) {  // a root of millions of points (buildOctree stops)
      kept.clear();
      return;
    }
    const uint32_t p = in[i];
    const uint32_t cell = ((qx[p] >> shift) & mask) | (((qy[p] >> shift) & mask) << g) |
                          (((qz_[p] >> shift) & mask) << (2 * g));
    scratch.table.offer(cell, priority(p, o.seed));
  }
  std::vector<uint64_t>& winners = scratch.winners;
  scratch.table.winners(winners);
  if (winners.size() > o.max_points_per_node) {
    std::nth_element(winners.begin(), winners.begin() + o.max_points_per_node, winners.end());
    winners.resize(o.max_points_per_node);
  }
  for (uint64_t k : winners) taken[static_cast<uint32_t>(k)] = 1;

  const int bit = 31 - level;
  const auto octant = [&](uint32_t p) {
    return ((qx[p] >> bit) & 1u) | (((qy[p] >> bit) & 1u) << 1) | (((qz_[p] >> bit) & 1u) << 2);
  };
  kept.clear();
  kept.reserve(winners.size());
  std::array<uint32_t, 8> count{};
  for (uint32_t i = 0; i < n; ++i) {
    if (taken[in[i]]) kept.push_back(in[i]);
    else ++count[octant(in[i])];
  }
  std::array<uint32_t, 8> at{};
  uint32_t start = r.begin;
  for (size_t c = 0; c < 8; ++c) {
    children[c] = {start, start + count[c]};
    at[c] = start;
    start += count[c];
  }
  for (uint32_t i = 0; i < n; ++i)
    if (!taken[in[i]]) next[at[octant(in[i])]++] = in[i];
}

// The octree, level by level (nodes of a level in parent order, then octant order): the nodes of a
// level are thinned in parallel, each only touching its own range, so the tree is the same for any
// thread count.
std::vector<Node> buildOctree(const Quantized& qz, uint32_t count, const CopcWriteOptions& o, unsigned threads) {
  std::vector<Node> nodes(1);
  std::vector<uint32_t> cur(count), next(count);
  for (uint32_t i = 0; i < count; ++i) cur[i] = i;
  std::vector<uint8_t> taken(count, 0);
  std::vector<std::pair<size_t, Range>> level = {{0, Range{0, count}}};
  std::vector<Scratch> scratch(threads);
  for (int depth = 0; !level.empty(); ++depth) {
    if (interrupted()) return {};  // the caller stops
    std::vector<std::array<Range, 8>> children(level.size());  // empty ranges where a node stopped
    parallelFor(level.size(), threads, [&](size_t i, unsigned worker) {
      if (interrupted()) return;
      thinNode(qz, depth, o, level[i].second, cur.data(), next.data(), taken.data(), scratch[worker],
               nodes[level[i].first].points, children[i]);
    });
    std::vector<std::pair<size_t, Range>> below;
    for (size_t i = 0; i < level.size(); ++i) {
      for (size_t c = 0; c < 8; ++c) {
        const Range r = children[i][c];
        if (r.end == r.begin) continue;
        const CopcKey& k = nodes[level[i].first].key;
        Node child;
        child.key = {k.level + 1, 2 * k.x + static_cast<int32_t>(c & 1), 2 * k.y + static_cast<int32_t>((c >> 1) & 1),
                     2 * k.z + static_cast<int32_t>(c >> 2)};
        nodes[level[i].first].children[c] = static_cast<int32_t>(nodes.size());
        below.emplace_back(nodes.size(), r);
        nodes.push_back(std::move(child));
      }
    }
    level = std::move(below);
    std::swap(cur, next);
  }
  for (size_t i = nodes.size(); i-- > 0;)
    for (int32_t c : nodes[i].children)
      if (c >= 0) nodes[i].subtree += nodes[static_cast<size_t>(c)].subtree;
  return nodes;
}

// --- Hierarchy pages -------------------------------------------------------------------------------

struct PageEntry {
  size_t node;
  int64_t page;  // ≥ 0: the entry points at that child page (count −1)
};

// PDAL's paging: a page holds its root and the subtree below it, except that a node `page_levels`
// below the root whose subtree has more than `page_min_nodes` nodes gets a page of its own.
class Pager {
 public:
  Pager(const std::vector<Node>& nodes, const CopcWriteOptions& o) : nodes_(nodes), o_(o) {}
  std::vector<std::vector<PageEntry>> pages;

  size_t addPage(size_t root) {
    const size_t id = pages.size();
    pages.emplace_back();
    pages[id].push_back({root, -1});
    addChildren(root, nodes_[root].key.level + o_.page_levels, id);
    return id;
  }

 private:
  void addChildren(size_t parent, int stop, size_t page) {
    for (int32_t c : nodes_[parent].children) {
      if (c < 0) continue;
      const size_t child = static_cast<size_t>(c);
      if (o_.page_levels == 0 || nodes_[child].key.level != stop || nodes_[child].subtree <= o_.page_min_nodes) {
        pages[page].push_back({child, -1});
        addChildren(child, stop, page);
      } else {
        const size_t child_page = addPage(child);
        pages[page].push_back({child, static_cast<int64_t>(child_page)});
      }
    }
  }
  const std::vector<Node>& nodes_;
  const CopcWriteOptions& o_;
};

void putEntry(std::string& out, const CopcKey& key, uint64_t offset, int32_t bytes, int32_t points) {
  char e[kEntryBytes];
  storeUnaligned<int32_t>(e, key.level);
  storeUnaligned<int32_t>(e + 4, key.x);
  storeUnaligned<int32_t>(e + 8, key.y);
  storeUnaligned<int32_t>(e + 12, key.z);
  storeUnaligned<uint64_t>(e + 16, offset);
  storeUnaligned<int32_t>(e + 24, bytes);
  storeUnaligned<int32_t>(e + 28, points);
  out.append(e, kEntryBytes);
}
}  // namespace

// --- Writing ---------------------------------------------------------------------------------------

Result<std::string> copcFromLasBytes(std::string_view las14, const CopcWriteOptions& options) {
  if (options.max_points_per_node == 0 || options.max_points_per_node > INT32_MAX)
    return Error{"COPC: max points per node " + str(options.max_points_per_node) + " is not between 1 and 2^31 - 1"};
  if (options.grid_levels < 1 || options.grid_levels > 10)
    return Error{"COPC: grid levels " + std::to_string(options.grid_levels) + " is not between 1 and 10"};
  if (options.page_levels < 0) return Error{"COPC: page levels " + std::to_string(options.page_levels) + " is negative"};
  Result<LasInput> parsed = parseLas14(las14);
  if (!parsed) return parsed.error();
  const LasInput& in = *parsed;
  const unsigned threads = resolveThreads(options.threads);
  const uint32_t count = static_cast<uint32_t>(in.count);
  const RecordStats stats = measure(in, threads);
  if (interrupted()) return interruptedError();

  // The cube: its edge the bounds' largest extent (a point or none: one scale step, so that the
  // spacing is positive), its corner the bounds' minimum. Not centred on the bounds as PDAL does:
  // a short axis (a survey's heights) then starts at a node face instead of straddling the cube's
  // middle, which every level splits, so its points fill half as many nodes.
  double lo[3], hi[3];
  CopcInfo info;
  for (size_t a = 0; a < 3; ++a) {
    const double u = count ? stats.lo[a] * in.scale[a] + in.offset[a] : 0;
    const double v = count ? stats.hi[a] * in.scale[a] + in.offset[a] : 0;
    lo[a] = std::min(u, v);  // a negative scale swaps them
    hi[a] = std::max(u, v);
    info.halfsize = std::max(info.halfsize, (hi[a] - lo[a]) / 2);
  }
  if (!(info.halfsize > 0))
    info.halfsize = std::max({std::abs(in.scale[0]), std::abs(in.scale[1]), std::abs(in.scale[2])}) / 2;
  for (size_t a = 0; a < 3; ++a) info.center[a] = lo[a] + info.halfsize;
  info.spacing = 2 * info.halfsize / static_cast<double>(1u << options.grid_levels);
  if (count != 0 && stats.gps_min <= stats.gps_max) {
    info.gpstime_minimum = stats.gps_min;
    info.gpstime_maximum = stats.gps_max;
  }

  // Fixed point: t = (x − cube min) / edge in [0, 1], q = ⌊t·2^32⌋ clamped; rounding moves a point
  // across a cell face by ~1e-16 of the cube at most, far inside the half scale step readers allow.
  Quantized qz;
  for (size_t a = 0; a < 3; ++a) qz.q[a].resize(count);
  parallelFor((count + 65535) / 65536, threads, [&](size_t b, unsigned) {
    if (interrupted()) return;
    const uint32_t end = static_cast<uint32_t>(std::min<uint64_t>(count, (b + 1) * 65536));
    for (uint32_t i = static_cast<uint32_t>(b * 65536); i < end; ++i) {
      const char* r = in.records + uint64_t{i} * in.record_length;
      for (size_t a = 0; a < 3; ++a) {
        const double x = loadUnaligned<int32_t>(r + 4 * a) * in.scale[a] + in.offset[a];
        const double t = (x - (info.center[a] - info.halfsize)) / (2 * info.halfsize) * 4294967296.0;
        qz.q[a][i] = t <= 0 ? 0u : t >= 4294967295.0 ? 4294967295u : static_cast<uint32_t>(t);
      }
    }
  });
  // Each pass stops at a signal (bench/scripts/interrupt_latency.py: a COPC write of 6M points
  // on one thread ran 4 s without a poll, past the watcher's grace).
  if (interrupted()) return interruptedError();
  std::vector<Node> nodes;
  if (count != 0) {
    nodes = buildOctree(qz, count, options, threads);
    if (interrupted()) return interruptedError();
  } else {
    nodes.resize(1);  // the root, empty
  }

  // One chunk per node, compressed in parallel.
  Result<LazInfo> laz = lazInfoForFormat(in.format, in.record_length, kLazVariableChunks);
  if (!laz) return laz.error();
  std::vector<std::vector<uint8_t>> coded(nodes.size());
  std::vector<std::string> gathered(threads);
  std::vector<std::vector<std::pair<uint64_t, uint32_t>>> keys(threads);
  std::vector<std::vector<uint32_t>> morton(threads);
  parallelFor(nodes.size(), threads, [&](size_t i, unsigned worker) {
    std::vector<uint32_t>& points = nodes[i].points;
    if (points.empty() || interrupted()) return;
    chooseOrder(qz, in.records, in.record_length, points, keys[worker], morton[worker]);
    std::string& buffer = gathered[worker];
    buffer.resize(points.size() * in.record_length);
    for (size_t k = 0; k < points.size(); ++k)
      std::memcpy(buffer.data() + k * in.record_length, in.records + uint64_t{points[k]} * in.record_length,
                  in.record_length);
    coded[i] = encodeLazChunk(*laz, buffer.data(), points.size());
  });
  if (interrupted()) return interruptedError();

  // Layout: header, info VLR, the kept VLRs, the laszip VLR, the chunk table's offset, the chunks,
  // the chunk table, the hierarchy EVLR, the kept EVLRs.
  std::string vlrs = vlrHeader("copc", kInfoRecord, kInfoBytes, "COPC info");
  const size_t info_at = kHeader14 + vlrs.size();
  vlrs.append(kInfoBytes, '\0');
  for (std::string_view v : in.vlrs) vlrs += v;
  const std::string laz_data = laszipVlrData(*laz);
  vlrs += vlrHeader("laszip encoded", kLaszipRecord, static_cast<uint16_t>(laz_data.size()), "dpoint COPC (LASzip 3.4)");
  vlrs += laz_data;
  const uint64_t point_offset = kHeader14 + vlrs.size();
  if (point_offset > UINT32_MAX) return Error{"COPC: the VLRs outgrow the 32-bit offset to point data"};
  std::vector<LazChunk> chunks;
  std::vector<uint64_t> chunk_at(nodes.size(), 0);
  uint64_t at = point_offset + 8;
  for (size_t i = 0; i < nodes.size(); ++i) {
    if (nodes[i].points.empty()) continue;
    if (nodes[i].points.size() > INT32_MAX || coded[i].size() > INT32_MAX)
      return Error{"COPC: node " + copcKeyName(nodes[i].key) + " holds " + str(nodes[i].points.size()) +
                   " points in " + str(coded[i].size()) + " bytes, past the hierarchy's 32-bit fields"};
    chunk_at[i] = at;
    chunks.push_back({at, coded[i].size(), nodes[i].points.size()});
    at += coded[i].size();
  }
  const uint64_t table_at = at;
  const std::string table = encodeLazChunkTable(*laz, chunks);
  const uint64_t evlr_at = table_at + table.size();

  Pager pager(nodes, options);
  pager.addPage(0);
  const uint64_t pages_at = evlr_at + kEvlrHeaderBytes;
  std::vector<uint64_t> page_at(pager.pages.size());
  uint64_t page_end = pages_at;
  for (size_t p = 0; p < pager.pages.size(); ++p) {
    page_at[p] = page_end;
    page_end += kEntryBytes * pager.pages[p].size();
  }
  std::string hierarchy = evlrHeader("copc", kHierarchyRecord, page_end - pages_at, "EPT hierarchy");
  for (const std::vector<PageEntry>& page : pager.pages) {
    for (const PageEntry& e : page) {
      const Node& node = nodes[e.node];
      if (e.page >= 0) {
        const size_t p = static_cast<size_t>(e.page);
        putEntry(hierarchy, node.key, page_at[p], static_cast<int32_t>(kEntryBytes * pager.pages[p].size()), -1);
      } else {
        putEntry(hierarchy, node.key, chunk_at[e.node], static_cast<int32_t>(coded[e.node].size()),
                 static_cast<int32_t>(node.points.size()));
      }
    }
  }
  info.root_hier_offset = pages_at;
  info.root_hier_size = kEntryBytes * pager.pages[0].size();

  std::string out(in.header);
  char* h = out.data();
  storeUnaligned<uint16_t>(h + kGlobalEncodingAt, loadUnaligned<uint16_t>(h + kGlobalEncodingAt) | kWktBit);
  storeUnaligned<uint16_t>(h + kHeaderSizeAt, static_cast<uint16_t>(kHeader14));
  storeUnaligned<uint32_t>(h + kPointOffsetAt, static_cast<uint32_t>(point_offset));
  storeUnaligned<uint32_t>(h + kVlrCountAt, static_cast<uint32_t>(in.vlrs.size() + 2));
  h[kFormatAt] = static_cast<char>(in.format | 0x80);
  storeUnaligned<uint32_t>(h + kLegacyCountAt, 0);
  for (size_t r = 0; r < 5; ++r) storeUnaligned<uint32_t>(h + kLegacyByReturnAt + 4 * r, 0);
  for (size_t a = 0; a < 3; ++a) {
    storeUnaligned<double>(h + kMaxXAt + 16 * a, hi[a]);
    storeUnaligned<double>(h + kMaxXAt + 16 * a + 8, lo[a]);
  }
  storeUnaligned<uint64_t>(h + kWaveformAt, 0);
  storeUnaligned<uint64_t>(h + kEvlrStartAt, evlr_at);
  storeUnaligned<uint32_t>(h + kEvlrCountAt, static_cast<uint32_t>(in.evlrs.size() + 1));
  storeUnaligned<uint64_t>(h + kCountAt, in.count);
  for (size_t r = 0; r < 15; ++r) storeUnaligned<uint64_t>(h + kByReturnAt + 8 * r, stats.by_return[r]);

  char* v = vlrs.data() + (info_at - kHeader14);
  for (size_t a = 0; a < 3; ++a) storeUnaligned<double>(v + 8 * a, info.center[a]);
  storeUnaligned<double>(v + 24, info.halfsize);
  storeUnaligned<double>(v + 32, info.spacing);
  storeUnaligned<uint64_t>(v + 40, info.root_hier_offset);
  storeUnaligned<uint64_t>(v + 48, info.root_hier_size);
  storeUnaligned<double>(v + 56, info.gpstime_minimum);
  storeUnaligned<double>(v + 64, info.gpstime_maximum);

  uint64_t evlr_bytes = 0;
  for (std::string_view e : in.evlrs) evlr_bytes += e.size();
  out.reserve(static_cast<size_t>(page_end + evlr_bytes));
  out += vlrs;
  char table_offset[8];
  storeUnaligned<int64_t>(table_offset, static_cast<int64_t>(table_at));
  out.append(table_offset, 8);
  for (const std::vector<uint8_t>& c : coded) out.append(reinterpret_cast<const char*>(c.data()), c.size());
  out += table;
  out += hierarchy;
  for (std::string_view e : in.evlrs) out += e;
  assert(out.size() == page_end + evlr_bytes);
  return out;
}

}  // namespace dpoint
