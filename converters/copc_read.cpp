// COPC selective read (converters/copc.h says what and whence): header, info and laszip VLRs, the
// hierarchy pages a query needs, and the chunks of the nodes it selects. The writer is
// copc_write.cpp.
#include "converters/copc.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <set>

#include "converters/copc_format.h"
#include "core/bytes.h"
#include "core/memory.h"
#include "core/parallel.h"

namespace dpoint {

using namespace copc_detail;

std::string copcKeyName(const CopcKey& key) {
  return std::to_string(key.level) + "-" + std::to_string(key.x) + "-" + std::to_string(key.y) + "-" +
         std::to_string(key.z);
}

CopcBox copcNodeCube(const CopcInfo& info, const CopcKey& key) {
  const double size = std::ldexp(2 * info.halfsize, -key.level);
  const int32_t cell[3] = {key.x, key.y, key.z};
  CopcBox box;
  for (size_t a = 0; a < 3; ++a) {
    const double lo = info.center[a] - info.halfsize;
    box.min[a] = lo + cell[a] * size;
    box.max[a] = lo + (cell[a] + 1.0) * size;
  }
  return box;
}

// --- Reading ---------------------------------------------------------------------------------------

namespace {

// The bytes [at, at + n) of the file, or an Error saying what was cut short.
Status readExactly(const InputFile& file, uint64_t at, void* out, size_t n, const std::string& what) {
  if (at > file.size() || file.size() - at < n)
    return Error{file.path() + ": truncated: " + what + " (" + str(n) + " bytes at byte " + str(at) +
                 ") runs past the end of the " + str(file.size()) + "-byte file"};
  Result<size_t> got = file.readAt(at, out, n);
  if (!got) return got.error();
  if (*got != n) return Error{file.path() + ": truncated: " + what + " ends at the file's end"};
  return okStatus();
}

Result<CopcHeader> readHeader(const InputFile& file, uint64_t& bytes_read) {
  const std::string& path = file.path();
  char h[kHeader14 + kVlrHeaderBytes + kInfoBytes];
  if (Status s = readExactly(file, 0, h, sizeof h, "the header and COPC info VLR"); !s) return s.error();
  bytes_read += sizeof h;
  if (std::memcmp(h, "LASF", 4) != 0) return Error{path + ": not a LAS/LAZ file (it does not start with 'LASF')"};
  if (h[kVersionMajorAt] != 1 || h[kVersionMinorAt] != 4)
    return Error{path + ": not COPC: LAS " + std::to_string(h[kVersionMajorAt]) + "." +
                 std::to_string(h[kVersionMinorAt]) + ", COPC is LAS 1.4"};
  const char* vlr = h + kHeader14;
  if (loadUnaligned<uint16_t>(h + kHeaderSizeAt) != kHeader14 || userId(vlr) != "copc" ||
      loadUnaligned<uint16_t>(vlr + 18) != kInfoRecord)
    return Error{path + ": not COPC: no info VLR (user 'copc', record 1) at byte 375"};
  if (loadUnaligned<uint16_t>(vlr + 20) != kInfoBytes)
    return Error{path + ": COPC info VLR: " + str(loadUnaligned<uint16_t>(vlr + 20)) + " bytes, not 160"};
  CopcHeader hd;
  const uint8_t raw_format = static_cast<uint8_t>(h[kFormatAt]);
  hd.point_format = raw_format & 0x3F;
  if ((raw_format & 0x80) == 0 || hd.point_format < 6 || hd.point_format > 8)
    return Error{path + ": COPC: point format byte " + str(raw_format) + " is not a compressed format 6, 7 or 8"};
  hd.record_length = loadUnaligned<uint16_t>(h + kRecordLengthAt);
  hd.point_data_offset = loadUnaligned<uint32_t>(h + kPointOffsetAt);
  hd.point_count = loadUnaligned<uint64_t>(h + kCountAt);
  if (hd.point_count == 0) hd.point_count = loadUnaligned<uint32_t>(h + kLegacyCountAt);
  for (size_t a = 0; a < 3; ++a) {
    hd.scale[a] = loadUnaligned<double>(h + kScaleAt + 8 * a);
    hd.offset[a] = loadUnaligned<double>(h + kOffsetAt + 8 * a);
    hd.max[a] = loadUnaligned<double>(h + kMaxXAt + 16 * a);  // max x, min x, max y, min y, …
    hd.min[a] = loadUnaligned<double>(h + kMaxXAt + 16 * a + 8);
  }
  const char* d = vlr + kVlrHeaderBytes;
  CopcInfo& info = hd.info;
  for (size_t a = 0; a < 3; ++a) info.center[a] = loadUnaligned<double>(d + 8 * a);
  info.halfsize = loadUnaligned<double>(d + 24);
  info.spacing = loadUnaligned<double>(d + 32);
  info.root_hier_offset = loadUnaligned<uint64_t>(d + 40);
  info.root_hier_size = loadUnaligned<uint64_t>(d + 48);
  info.gpstime_minimum = loadUnaligned<double>(d + 56);
  info.gpstime_maximum = loadUnaligned<double>(d + 64);
  const auto finite = [](double x) { return std::isfinite(x); };
  // The cube's edge and faces finite too: a half size of 1e308 made every node's box NaN, and no
  // point was read (a review finding).
  bool faces = finite(2 * info.halfsize);
  for (size_t a = 0; a < 3; ++a)
    faces = faces && finite(info.center[a] - info.halfsize) && finite(info.center[a] + info.halfsize);
  if (!finite(info.center[0]) || !finite(info.center[1]) || !finite(info.center[2]) || !finite(info.halfsize) ||
      !(info.halfsize > 0) || !faces || !finite(info.spacing) || !(info.spacing > 0))
    return Error{path + ": COPC info VLR: the cube (half size " + std::to_string(info.halfsize) + ") or spacing (" +
                 std::to_string(info.spacing) + ") is not positive and finite"};
  if (info.root_hier_size == 0 || info.root_hier_size % kEntryBytes != 0 ||
      info.root_hier_offset > file.size() || file.size() - info.root_hier_offset < info.root_hier_size)
    return Error{path + ": COPC info VLR: the root hierarchy page (" + str(info.root_hier_size) + " bytes at byte " +
                 str(info.root_hier_offset) + ") is not a whole number of 32-byte entries within the " +
                 str(file.size()) + "-byte file"};

  // The laszip VLR, among the VLRs after the info VLR.
  const uint32_t vlr_count = loadUnaligned<uint32_t>(h + kVlrCountAt);
  uint64_t at = kHeader14 + kVlrHeaderBytes + kInfoBytes;
  bool found = false;
  for (uint32_t i = 1; i < vlr_count && !found; ++i) {
    char v[kVlrHeaderBytes];
    if (at + kVlrHeaderBytes > hd.point_data_offset)
      return Error{path + ": VLR " + str(i) + " at byte " + str(at) + " runs past the offset to point data " +
                   str(hd.point_data_offset)};
    if (Status s = readExactly(file, at, v, sizeof v, "VLR " + str(i)); !s) return s.error();
    bytes_read += sizeof v;
    const uint16_t bytes = loadUnaligned<uint16_t>(v + 20);
    if (at + kVlrHeaderBytes + bytes > hd.point_data_offset)
      return Error{path + ": VLR " + str(i) + " (" + str(bytes) + " bytes at byte " + str(at + kVlrHeaderBytes) +
                   ") runs past the offset to point data " + str(hd.point_data_offset)};
    if (loadUnaligned<uint16_t>(v + 18) == kLaszipRecord && userId(v) == "laszip encoded") {
      std::string data(bytes, '\0');
      if (Status s = readExactly(file, at + kVlrHeaderBytes, data.data(), bytes, "the laszip VLR"); !s)
        return s.error();
      bytes_read += bytes;
      Result<LazInfo> laz = parseLaszipVlr(data);
      if (!laz) return Error{path + ": " + laz.error().message};
      hd.laz = std::move(*laz);
      found = true;
    }
    at += kVlrHeaderBytes + bytes;
  }
  if (!found) return Error{path + ": COPC: no laszip VLR (user 'laszip encoded', record 22204)"};
  if (Status s = checkLazItems(hd.laz, hd.point_format, hd.record_length); !s)
    return Error{path + ": " + s.error().message};
  return hd;
}

// The deepest level a query reads: the first whose spacing is at most the resolution.
int deepestLevel(double spacing, double resolution) {
  if (!(resolution > 0)) return INT32_MAX;
  int level = 0;
  for (double s = spacing; s > resolution && level < 64; s /= 2) ++level;
  return level;
}

bool meets(const CopcBox& a, const CopcBox& b) {
  for (size_t i = 0; i < 3; ++i)
    if (!(a.min[i] <= b.max[i] && a.max[i] >= b.min[i])) return false;
  return true;
}

}  // namespace

bool isCopc(const InputFile& file) {
  char h[kHeader14 + kVlrHeaderBytes];
  Result<size_t> got = file.readAt(0, h, sizeof h);
  if (!got || *got != sizeof h) return false;
  return std::memcmp(h, "LASF", 4) == 0 && userId(h + kHeader14) == "copc" &&
         loadUnaligned<uint16_t>(h + kHeader14 + 18) == kInfoRecord;
}

Result<CopcHeader> readCopcHeader(const InputFile& file) {
  uint64_t bytes = 0;
  return readHeader(file, bytes);
}

Result<std::vector<CopcNode>> readCopcNodes(const InputFile& file, const CopcHeader& header, const CopcQuery& query,
                                            uint64_t* bytes_read) {
  const std::string& path = file.path();
  const int deepest = deepestLevel(header.info.spacing, query.resolution);
  struct Pending {
    uint64_t offset, size;
    std::string name;  // for messages
  };
  std::vector<Pending> queue = {{header.info.root_hier_offset, header.info.root_hier_size, "the root page"}};
  std::set<uint64_t> seen;
  uint64_t page_bytes = 0;
  std::vector<CopcNode> nodes;
  std::string page;
  bool skipped = false;  // a node or page the query left out
  for (size_t next = 0; next < queue.size(); ++next) {
    const Pending pending = queue[next];
    const std::string where = path + ": hierarchy: " + pending.name + " (" + str(pending.size) + " bytes at byte " +
                              str(pending.offset) + ")";
    if (!seen.insert(pending.offset).second) return Error{where + " is read a second time (the pages form a cycle)"};
    page_bytes += pending.size;
    if (page_bytes > file.size())
      return Error{where + ": the pages read add up to " + str(page_bytes) + " bytes, more than the file's " +
                   str(file.size()) + " (pages overlap)"};
    page.resize(static_cast<size_t>(pending.size));
    if (Status s = readExactly(file, pending.offset, page.data(), page.size(), pending.name + " of the hierarchy"); !s)
      return s.error();
    for (size_t j = 0; j < page.size() / kEntryBytes; ++j) {
      const char* e = page.data() + j * kEntryBytes;
      CopcNode node;
      node.key = {loadUnaligned<int32_t>(e), loadUnaligned<int32_t>(e + 4), loadUnaligned<int32_t>(e + 8),
                  loadUnaligned<int32_t>(e + 12)};
      node.offset = loadUnaligned<uint64_t>(e + 16);
      node.bytes = loadUnaligned<int32_t>(e + 24);
      node.points = loadUnaligned<int32_t>(e + 28);
      const std::string entry = where + ", entry " + str(j) + " (node " + copcKeyName(node.key) + "): ";
      const CopcKey& k = node.key;
      if (k.level < 0 && node.points == 0 && node.offset == 0 && node.bytes == 0) continue;  // an unused slot
      const int64_t cells = k.level >= 0 && k.level <= 30 ? int64_t{1} << k.level : 0;
      if (cells == 0 || k.x < 0 || k.y < 0 || k.z < 0 || k.x >= cells || k.y >= cells || k.z >= cells)
        return Error{entry + "not a node of an octree (levels 0 to 30, cells 0 to 2^level - 1)"};
      if (node.points < -1) return Error{entry + "point count " + std::to_string(node.points) + " is below -1"};
      if (node.points == -1) {
        if (node.bytes <= 0 || node.bytes % static_cast<int32_t>(kEntryBytes) != 0 || node.offset > file.size() ||
            file.size() - node.offset < static_cast<uint64_t>(node.bytes))
          return Error{entry + "its child page (" + std::to_string(node.bytes) + " bytes at byte " + str(node.offset) +
                       ") is not a whole number of 32-byte entries within the " + str(file.size()) + "-byte file"};
      } else if (node.points > 0) {
        if (node.bytes <= 0 || node.offset < header.point_data_offset + 8 || node.offset > file.size() ||
            file.size() - node.offset < static_cast<uint64_t>(node.bytes))
          return Error{entry + "its chunk (" + std::to_string(node.bytes) + " bytes at byte " + str(node.offset) +
                       ") is not within the point data (bytes " + str(header.point_data_offset + 8) + " to " +
                       str(file.size()) + ")"};
      }
      const CopcBox cube = copcNodeCube(header.info, k);
      if (k.level > deepest || !meets(cube, query.box) || (query.select && !query.select(cube, k.level))) {
        skipped = true;
        continue;
      }
      if (node.points == -1) {
        queue.push_back({node.offset, static_cast<uint64_t>(node.bytes), "the page of node " + copcKeyName(k)});
      } else {
        nodes.push_back(node);
      }
    }
  }
  std::sort(nodes.begin(), nodes.end(), [](const CopcNode& a, const CopcNode& b) { return a.key < b.key; });
  for (size_t i = 1; i < nodes.size(); ++i)
    if (nodes[i].key == nodes[i - 1].key)
      return Error{path + ": hierarchy: node " + copcKeyName(nodes[i].key) + " has two entries"};
  // Where the query left no node or page out (every read, and a view that takes the whole tree),
  // the nodes' points are the header's: a damaged hierarchy or count had drawn part of the set,
  // or "131074 of 0 points", with exit 0 (a review finding).
  if (!skipped) {
    uint64_t total = 0;
    for (const CopcNode& n : nodes) total += static_cast<uint64_t>(std::max(n.points, 0));
    if (total != header.point_count)
      return Error{path + ": hierarchy: the nodes hold " + str(total) + " points, the header says " +
                   str(header.point_count)};
  }
  if (bytes_read) *bytes_read = page_bytes;
  return nodes;
}

Result<std::string> readCopcRecords(const InputFile& file, const CopcQuery& query, CopcNodeRead* stats) {
  const std::string& path = file.path();
  uint64_t bytes_read = 0;
  Result<CopcHeader> header = readHeader(file, bytes_read);
  if (!header) return header.error();
  const CopcHeader& hd = *header;
  uint64_t page_bytes = 0;
  Result<std::vector<CopcNode>> selected = readCopcNodes(file, hd, query, &page_bytes);
  if (!selected) return selected.error();
  bytes_read += page_bytes;
  std::vector<CopcNode> nodes;
  for (const CopcNode& n : *selected)
    if (n.points > 0) nodes.push_back(n);

  // The memory the records take (a node's count is at most 2^31 - 1: the sum cannot overflow).
  const uint64_t length = hd.record_length;
  uint64_t total = 0, largest = 0;
  for (const CopcNode& n : nodes) {
    total += static_cast<uint64_t>(n.points);
    largest = std::max(largest, static_cast<uint64_t>(n.bytes));
  }
  const unsigned threads = parallelWorkers(nodes.size(), query.threads);
  if (total > (UINT64_MAX - largest * threads) / length)  // counts of a hostile hierarchy
    return Error{path + ": " + str(total) + " points of " + str(length) + " bytes overflow 64 bits",
                 ExitCode::kResourceLimit};
  if (Status s = checkMemory(path + ": reading " + str(total) + " points of " + str(nodes.size()) + " COPC nodes",
                             total * length + largest * threads, query.max_memory);
      !s)
    return s.error();
  std::string records(static_cast<size_t>(total * length), '\0');

  // The nodes' chunks, decoded as decodeLaz decodes a file's (the first failing node's error).
  std::vector<LazChunk> chunks;
  chunks.reserve(nodes.size());
  for (const CopcNode& n : nodes)
    chunks.push_back({n.offset, static_cast<uint64_t>(n.bytes), static_cast<uint64_t>(n.points)});
  if (Status s = decodeLazChunkList(file, hd.laz, chunks, hd.record_length, records.data(), threads, [&](size_t i) {
        const CopcNode& n = nodes[i];
        return path + ": node " + copcKeyName(n.key) + " (" + std::to_string(n.points) + " points, " +
               std::to_string(n.bytes) + " bytes at byte " + str(n.offset) + "): ";
      });
      !s)
    return s.error();
  if (stats) {
    stats->points = total;
    stats->nodes = nodes.size();
    stats->bytes = bytes_read;
    for (const CopcNode& n : nodes) stats->bytes += static_cast<uint64_t>(n.bytes);
  }
  return records;
}

}  // namespace dpoint
