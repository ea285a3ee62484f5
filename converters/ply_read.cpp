// PLY reading (writing is in ply_write.cpp). Format: Greg Turk, "The PLY Polygon File Format" (1994), as written
// by rply, Open3D, MeshLab and PCL. Only little-endian hosts: binary rows are read and written
// with memcpy; a binary_big_endian file's rows are put in the host's order as each block is read
// (RowLayout::toHostOrder, and loadValue's and the triangle rows' swaps), then decoded alike.
//
// The header and every element are read in file order through one ByteReader, except the one
// that matters for speed: a binary `vertex` element without list properties. Its rows all have
// one size, so row i is at a known offset and goes to positions[i]: blocks of rows are read
// (pread, one buffer per thread) and decoded on all cores straight into the exactly sized arrays.
// The result therefore never depends on the thread count, and the first bad row in file order
// gives the error (a block stops at its own first bad row; blocks after a known bad row are not
// decoded; the lowest row wins). Memory: the PointSet plus one block per thread. Binary faces of
// the first row's size are decoded in blocks the same way, and ASCII vertex and face rows in two passes over
// 4 MiB blocks (newlines counted, then each block's lines parsed into their rows: readAsciiRows),
// each up to the first row of another kind, from which the row-by-row loop goes on. Vertices with
// lists and other elements stay serial.
#include "converters/las_crs.h"
#include "converters/ply.h"

#include <fast_float/fast_float.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cassert>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <optional>
#include <string_view>
#include <unordered_set>
#include <vector>

#include "core/bytes.h"
#include "core/input_file.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "core/text.h"

namespace dpoint {

static_assert(std::endian::native == std::endian::little, "binary PLY rows are copied as they are");
static_assert(sizeof(glm::dvec3) == 24 && sizeof(glm::vec3) == 12, "glm vectors must be packed");

namespace {

// Reads are in blocks this large: big enough that pread overhead vanishes, small enough that a
// multi-GB file is never held whole.
constexpr size_t kBlockBytes = size_t{8} << 20;
// Binary vertex rows are decoded in blocks of about this many bytes, one per task: large enough
// that a pread and a task hand-out per block cost nothing, small enough that a block is still in
// cache when it is decoded and that the last blocks keep every core busy.
constexpr size_t kVertexBlockBytes = size_t{1} << 20;
constexpr size_t kMaxHeaderLine = size_t{64} << 10;
constexpr size_t kMaxAsciiLine = size_t{64} << 20;

enum class Type : uint8_t { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

struct TypeInfo {
  std::string_view name;
  Type type;
};
constexpr TypeInfo kTypeNames[] = {
    {"char", Type::kInt8},   {"uchar", Type::kUint8},   {"short", Type::kInt16},     {"ushort", Type::kUint16},
    {"int", Type::kInt32},   {"uint", Type::kUint32},   {"float", Type::kFloat32},   {"double", Type::kFloat64},
    {"int8", Type::kInt8},   {"uint8", Type::kUint8},   {"int16", Type::kInt16},     {"uint16", Type::kUint16},
    {"int32", Type::kInt32}, {"uint32", Type::kUint32}, {"float32", Type::kFloat32}, {"float64", Type::kFloat64},
};

size_t typeSize(Type t) {
  constexpr size_t kSizes[] = {1, 1, 2, 2, 4, 4, 4, 8};
  return kSizes[static_cast<int>(t)];
}
std::string_view typeName(Type t) { return kTypeNames[static_cast<int>(t)].name; }
bool isInteger(Type t) { return t < Type::kFloat32; }

// A big-endian value's bytes reversed in place: the host's (little-endian) order.
inline void reverseBytes(char* p, size_t size) { std::reverse(p, p + size); }

// Every PLY scalar is exact in a double (integers are at most 32 bits).
inline double loadValue(Type t, const char* p) {
  switch (t) {
    case Type::kInt8: return loadUnaligned<int8_t>(p);
    case Type::kUint8: return loadUnaligned<uint8_t>(p);
    case Type::kInt16: return loadUnaligned<int16_t>(p);
    case Type::kUint16: return loadUnaligned<uint16_t>(p);
    case Type::kInt32: return loadUnaligned<int32_t>(p);
    case Type::kUint32: return loadUnaligned<uint32_t>(p);
    case Type::kFloat32: return loadUnaligned<float>(p);
    case Type::kFloat64: return loadUnaligned<double>(p);
  }
  return 0;
}

// loadValue of a value stored in big-endian order when `big_endian`.
inline double loadValue(Type t, const char* p, bool big_endian) {
  if (!big_endian) return loadValue(t, p);
  char bytes[8];
  std::memcpy(bytes, p, typeSize(t));
  reverseBytes(bytes, typeSize(t));
  return loadValue(t, bytes);
}

// Parses one ASCII token as a value of type `t`. float32 is parsed straight to float so that the
// value equals what a binary file would hold (no double rounding through double).
bool parseAscii(Type t, std::string_view token, double& out) {
  const char* last = token.data() + token.size();
  const char* first = afterPlusSign(token.data(), last);
  if (t == Type::kFloat32) {
    float f = 0;
    auto r = fast_float::from_chars(first, last, f);
    out = f;
    return r.ec == std::errc() && r.ptr == last;
  }
  if (t == Type::kFloat64) {
    auto r = fast_float::from_chars(first, last, out);
    return r.ec == std::errc() && r.ptr == last;
  }
  int64_t v = 0;
  auto r = std::from_chars(first, last, v);
  if (r.ec != std::errc() || r.ptr != last) return false;
  constexpr int64_t kMin[] = {INT8_MIN, 0, INT16_MIN, 0, INT32_MIN, 0};
  constexpr int64_t kMax[] = {INT8_MAX, UINT8_MAX, INT16_MAX, UINT16_MAX, INT32_MAX, UINT32_MAX};
  if (v < kMin[static_cast<int>(t)] || v > kMax[static_cast<int>(t)]) return false;
  out = static_cast<double>(v);
  return true;
}

std::string quote(std::string_view text) { return "'" + printableExcerpt(text) + "'"; }

std::string numberText(double v) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

// Takes the next whitespace-separated token off the front of `rest`; empty at the end. A plain
// loop: find_first_of calls memchr per character, which was a third of the ASCII read time.
std::string_view nextToken(std::string_view& rest) {
  auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  size_t begin = 0;
  while (begin < rest.size() && space(rest[begin])) ++begin;
  size_t end = begin;
  while (end < rest.size() && !space(rest[end])) ++end;
  std::string_view token = rest.substr(begin, end - begin);
  rest.remove_prefix(end);
  return token;
}

bool isBlank(std::string_view s) { return nextToken(s).empty(); }

// A polygon of n ≥ 3 corners as the n − 2 triangles of its fan (v0, vi, vi+1), into out: the
// triangulation of every face this reader takes (finishFace's, row by row, likewise).
void fanPolygon(const uint32_t* corners, size_t n, uint32_t* out) {
  for (size_t i = 1; i + 1 < n; ++i, out += 3) {
    out[0] = corners[0];
    out[1] = corners[i];
    out[2] = corners[i + 1];
  }
}

// Progress for rows read in parallel blocks up to a stop that the blocks find: each finished block
// counts its bytes (one past a later stop may count bytes the row-by-row loop reads again, so the
// bar can reach 100% a moment early, never more), and finish() adds what the rows taken cover
// beyond that. Bytes before `reported` were counted as they were read.
class BlockProgress {
 public:
  BlockProgress(Progress* progress, uint64_t reported) : progress_(progress), reported_(reported) {}
  void block(uint64_t from, uint64_t to) {  // thread-safe
    const uint64_t bytes = to - std::clamp(reported_, from, to);
    advanced_ += bytes;
    if (progress_) progress_->advance(bytes);
  }
  void finish(uint64_t begin, uint64_t end) {  // the rows taken: [begin, end)
    const uint64_t taken = end - std::clamp(reported_, begin, end);
    if (progress_ && taken > advanced_) progress_->advance(taken - advanced_);
  }

 private:
  Progress* progress_;
  const uint64_t reported_;
  std::atomic<uint64_t> advanced_{0};
};

// Element and property names go into messages as they are; a control byte in one would break the
// one-line rule, and no PLY writer makes such a name.
bool hasControlByte(std::string_view s) {
  return std::any_of(s.begin(), s.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; });
}

// A window onto the file, refilled in big blocks.
class ByteReader {
 public:
  enum class Line { kLine, kEnd, kTooLong };

  // The buffer starts at 64 KiB, which holds any header dpoint has seen, and doubles with each
  // refill up to kBlockBytes: a binary file's header read no longer zeroes and fills 8 MiB that its
  // rows, read on all cores from the file, never use (twice for a render: its probe and its read).
  ByteReader(const InputFile& file, Progress* progress)
      : file_(file), progress_(progress), buf_(std::min<uint64_t>(kFirstBytes, file.size() + 1)) {}

  uint64_t offset() const { return start_ + pos_; }
  // The file offset just past the bytes read so far (each reported once to the progress).
  uint64_t readEnd() const { return start_ + end_; }
  uint64_t remaining() const { return file_.size() > offset() ? file_.size() - offset() : 0; }
  size_t available() const { return end_ - pos_; }
  const char* data() const { return buf_.data() + pos_; }
  void consume(size_t n) { pos_ += n; }

  // Makes `n` bytes available unless the file ends first; returns how many are.
  Result<size_t> require(size_t n) {
    if (available() >= n) return available();
    return refill(n);
  }

  // The caller has checked that `n` bytes remain.
  void skip(uint64_t n) {
    if (n <= available()) return consume(static_cast<size_t>(n));
    start_ = start_ + end_ + (n - available());
    pos_ = end_ = 0;
  }

  // The next line without its "\n" or "\r\n".
  Result<Line> nextLine(std::string_view& line, size_t max_bytes) {
    size_t scanned = 0;
    bool at_end = false;
    for (;;) {
      const size_t avail = available();
      const void* nl = std::memchr(data() + scanned, '\n', avail - scanned);
      if (nl || (at_end && avail > 0)) {  // a newline, or the last line of the file lacks one
        size_t len = nl ? static_cast<size_t>(static_cast<const char*>(nl) - data()) : avail;
        if (len > max_bytes) return Line::kTooLong;
        line = std::string_view(data(), len);
        consume(nl ? len + 1 : len);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        return Line::kLine;
      }
      if (avail > max_bytes) return Line::kTooLong;
      if (at_end) return Line::kEnd;
      scanned = avail;
      auto got = refill(avail + 1);
      if (!got.ok()) return got.error();
      at_end = available() == avail;
    }
  }

 private:
  Result<size_t> refill(size_t n) {
    size_t keep = available();
    std::memmove(buf_.data(), data(), keep);
    start_ += pos_;
    pos_ = 0;
    end_ = keep;
    if (buf_.size() < n || (filled_ && buf_.size() < kBlockBytes && buf_.size() <= file_.size()))
      buf_.resize(std::max(n, std::min(2 * buf_.size(), kBlockBytes)));
    filled_ = true;
    while (end_ < n) {
      auto got = file_.readAt(start_ + end_, buf_.data() + end_, buf_.size() - end_);
      if (!got.ok()) return got.error();
      if (*got == 0) break;
      end_ += *got;
      if (progress_) progress_->advance(*got);
    }
    return end_;
  }

  const InputFile& file_;
  Progress* progress_;
  static constexpr size_t kFirstBytes = size_t{64} << 10;
  std::vector<char> buf_;
  bool filled_ = false;  // a refill has happened: the next one doubles the buffer
  uint64_t start_ = 0;  // file offset of buf_[0]
  size_t pos_ = 0, end_ = 0;
};

struct Property {
  std::string name;
  Type type = Type::kFloat64;  // the scalar type, or the item type of a list
  bool is_list = false;
  Type count_type = Type::kUint8;
  int line = 0;
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> properties;
  int line = 0;
};

// What a property feeds; values land in `double values[kRoleCount]` indexed by role.
// kAttribute: a vertex property kept as a dimension (core/dimensions.h); its value goes to
// attribute_row_ instead (the slot in values_ is scratch).
enum Role : uint8_t { kSkip, kX, kY, kZ, kRed, kGreen, kBlue, kIndices, kAttribute, kRoleCount };

DimType dimTypeOf(Type t) {
  constexpr DimType kTypes[] = {DimType::kI8,  DimType::kU8,  DimType::kI16, DimType::kU16,
                                DimType::kI32, DimType::kU32, DimType::kF32, DimType::kF64};
  return kTypes[static_cast<int>(t)];
}

class PlyParser {
 public:
  PlyParser(const InputFile& file, const PlyReadOptions& options)
      : file_(file), path_(file.path()), options_(options), in_(file, options.progress) {}

  Result<PointSet> run() {
    if (options_.progress) options_.progress->start("reading " + path_, file_.size());
    if (Status s = parseHeader(); !s.ok()) return s.error();
    if (Status s = planElements(); !s.ok()) return s.error();
    if (Status s = checkSizes(); !s.ok()) return s.error();
    bool stopped = false;
    for (const Element& e : elements_) {
      Status s = readElement(e, e.name == "vertex" ? vertex_roles_
                                : e.name == "face" ? face_roles_
                                                   : std::vector<Role>(e.properties.size(), kSkip));
      if (!s.ok()) return s.error();
      if ((stopped = e.name == "vertex" && (options_.points_only || (options_.faces_unkept && facesWholeBySize(e)))))
        break;
    }
    if (Status s = stopped ? okStatus() : checkEnd(); !s.ok()) return s.error();
    // Ends the line here, as readCsv does: left open, it went on counting the caller's next work
    // as reading time.
    if (options_.progress) options_.progress->finish();
    return std::move(points_);
  }

  // PlyReadOptions::faces_unkept, after the vertex element `vertex`: whether the rest of the file is
  // exactly one element of whole triangle rows (a one-byte count, three 32-bit indices).
  bool facesWholeBySize(const Element& vertex) const {
    if (ascii_ || elements_.empty() || &elements_.back() == &vertex || elements_.back().name != "face" ||
        &elements_[elements_.size() - 2] != &vertex)
      return false;
    const Element& face = elements_.back();
    if (face.properties.size() != 1 || !face.properties[0].is_list || typeSize(face.properties[0].count_type) != 1 ||
        typeSize(face.properties[0].type) != 4)
      return false;
    const uint64_t rows = in_.remaining() / 13;
    return in_.remaining() % 13 == 0 && rows == face.count;
  }

  // PlyVertexStream: the header, then where the vertex rows start. Binary only, and every element
  // before the vertices of fixed-size rows, so that row r's offset is known without reading.
  Status openStream() {
    if (Status s = parseHeader(); !s.ok()) return s.error();
    if (Status s = planElements(); !s.ok()) return s.error();
    if (Status s = checkSizes(false); !s.ok()) return s.error();
    if (ascii_) return Error{path_ + ": an ASCII PLY file cannot be streamed; convert it to binary PLY first"};
    uint64_t offset = in_.offset();
    for (const Element& e : elements_) {
      const bool fixed =
          std::none_of(e.properties.begin(), e.properties.end(), [](const Property& p) { return p.is_list; });
      if (!fixed)
        return Error{path_ + ": element '" + e.name + "' (header line " + std::to_string(e.line) + ") has " +
                     (e.name == "vertex" ? std::string("a list property in its rows")
                                         : std::string("list rows before the vertices")) +
                     ", whose offsets are known only once read; such a file cannot be streamed (--stream off)"};
      if (e.name == "vertex") {
        stream_layout_ = vertexLayout(e, vertex_roles_);
        stream_begin_ = offset;
        return okStatus();
      }
      uint64_t row_bytes = 0;
      for (const Property& p : e.properties) row_bytes += typeSize(p.type);
      offset += row_bytes * e.count;  // bounded by checkSizes
    }
    return okStatus();  // planElements found a vertex element
  }
  uint64_t vertexCount() const { return vertex_count_; }
  const std::string& crs() const { return points_.crs; }  // the header's, once read
  const std::optional<LasSource>& las() const { return points_.las; }
  bool hasColors() const { return has_colors_; }
  bool floatColors() const { return has_colors_ && divisor_[kRed] == 1.0f && !tile_; }
  // The vertex properties that are dimensions (empty columns: names and types).
  const Dimensions& dimensions() const { return points_.dimensions; }
  // readStream fills these dimensions (indices into dimensions()) of each block too.
  void streamDimensions(std::vector<size_t> which) { streamed_dimensions_ = std::move(which); }
  uint64_t faceCount() const {
    for (const Element& e : elements_)
      if (e.name == "face") return e.count;
    return 0;
  }

  // Vertex rows [first, first + n) into `block`, in parallel blocks, with readPly's errors.
  Status readStream(uint64_t first, uint64_t n, PointSet& block) {
    assert(first <= vertex_count_ && n <= vertex_count_ - first);
    const RowLayout& layout = stream_layout_;
    block.triangles.clear();
    block.positions.resize(static_cast<size_t>(n));
    if (has_colors_) block.colors.resize(static_cast<size_t>(n));
    else block.colors.clear();
    const uint64_t block_rows = std::max<size_t>(1, kVertexBlockBytes / layout.row_bytes);
    const size_t blocks = static_cast<size_t>((n + block_rows - 1) / block_rows);
    std::mutex error_mutex;
    std::optional<Error> first_error;
    uint64_t error_row = UINT64_MAX;
    auto fail = [&](uint64_t row, Error error) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (row < error_row) error_row = row, first_error = std::move(error);
    };
    // The chosen dimensions, copied from each row in the host's (little-endian) order as the row
    // is decoded (one read of the rows for all of them).
    struct Copied {
      size_t offset, bytes;
      uint8_t* to;
    };
    std::vector<Copied> copied;
    std::vector<const Dimension*> like;
    for (size_t which : streamed_dimensions_) like.push_back(&points_.dimensions.all()[which]);
    block.dimensions.shapeUnset(like, static_cast<size_t>(n));
    for (size_t which : streamed_dimensions_) {
      const auto at = std::find_if(layout.attributes.begin(), layout.attributes.end(),
                                   [&](const RowLayout::Attribute& a) { return a.dimension == which; });
      assert(at != layout.attributes.end());
      copied.push_back({at->offset, at->bytes, nullptr});
    }
    for (size_t k = 0; k < copied.size(); ++k) copied[k].to = block.dimensions.all()[k].bytes.data();
    const unsigned threads = resolveThreads(options_.threads);
    std::vector<std::vector<char>> buffers(threads);
    glm::dvec3* positions = block.positions.data();
    glm::vec3* colors = has_colors_ ? block.colors.data() : nullptr;
    parallelFor(blocks, threads, [&](size_t b, unsigned worker) {
      const uint64_t from = first + b * block_rows, to = std::min(from + block_rows, first + n);
      const uint64_t offset = stream_begin_ + from * layout.row_bytes;
      std::vector<char>& buffer = buffers[worker];
      buffer.resize(static_cast<size_t>((to - from) * layout.row_bytes));
      Result<size_t> got = file_.readAt(offset, buffer.data(), buffer.size());
      if (!got) return fail(from, got.error());
      if (*got < buffer.size()) {  // the file shrank since it was opened
        const uint64_t whole = from + *got / layout.row_bytes;
        return fail(whole, Error{path_ + ": truncated at byte " + std::to_string(offset + *got) + ": expected " +
                                 std::to_string(vertex_count_) + " 'vertex' rows, the data ends in row " +
                                 std::to_string(whole)});
      }
      layout.toHostOrder(buffer.data(), static_cast<size_t>(to - from));
      const uint64_t bad = decodeVertices(layout, buffer.data(), from, to, positions, colors, first);
      if (bad != to) {
        double v[kRoleCount];
        layout.load(buffer.data() + (bad - from) * layout.row_bytes, v);
        return fail(bad, nonfiniteError(v, bad, stream_begin_ + bad * layout.row_bytes));
      }
      for (const Copied& c : copied)
        for (uint64_t r = from; r < to; ++r)
          std::memcpy(c.to + (r - first) * c.bytes, buffer.data() + (r - from) * layout.row_bytes + c.offset, c.bytes);
      if (options_.progress) options_.progress->advance(buffer.size());
    });
    if (first_error) return *first_error;
    return okStatus();
  }

 private:
  Error headerError(int line, const std::string& what) const {
    return Error{path_ + ": header line " + std::to_string(line) + ": " + what};
  }
  // `where` is the 1-based line for ASCII, the byte offset for binary.
  Error dataError(uint64_t where, const std::string& what) const {
    return Error{path_ + (ascii_ ? ": line " : ": byte ") + std::to_string(where) + ": " + what};
  }
  Error truncated(const Element& e, uint64_t row) const {
    return Error{path_ + ": truncated at byte " + std::to_string(file_.size()) + ": expected " +
                 std::to_string(e.count) + " '" + e.name + "' rows, the data ends in row " + std::to_string(row)};
  }

  Status parseHeader() {
    auto first = in_.require(4);
    if (!first.ok()) return first.error();
    if (*first == 0) return Error{path_ + ": empty file, not a PLY file"};
    const char* p = in_.data();
    if (*first < 3 || std::memcmp(p, "ply", 3) != 0 || (*first > 3 && p[3] != '\n' && p[3] != '\r'))
      return Error{path_ + ": not a PLY file (it does not start with a 'ply' line)"};
    bool have_format = false;
    std::unordered_set<std::string> element_names, property_names;  // the latter: the last element's
    for (int line_no = 1;; ++line_no) {
      std::string_view line;
      auto got = in_.nextLine(line, kMaxHeaderLine);
      if (!got.ok()) return got.error();
      if (*got == ByteReader::Line::kEnd) return headerError(line_no, "the file ends before 'end_header'");
      if (*got == ByteReader::Line::kTooLong) return headerError(line_no, "line too long (no 'end_header'?)");
      line_no_ = static_cast<uint64_t>(line_no);
      std::vector<std::string_view> w;
      for (auto rest = line, t = nextToken(rest); !t.empty(); t = nextToken(rest)) w.push_back(t);
      if (line_no == 1) continue;  // the magic, checked above
      if (w.empty()) return headerError(line_no, "empty line");
      const std::string_view key = w[0];
      if (key == "comment" && w.size() >= 2 && w[1] == kPlyTileCommentWord) tile_ = true;
      if (key == "comment" && w.size() >= 3 && w[1] == "dpoint:") {
        // The facts dpoint writes (ply_write.cpp): a 2D source, and z up.
        if (w[2] == "2D") points_.z_axis = ZAxis::kAbsent;
        if (w.size() == 5 && w[2] == "up" && w[3] == "axis" && w[4] == "z") points_.z_up = true;
        // Colours that came as integers 0..255 (a CSV's), so CSV → PLY → CSV writes them so again.
        if (w.size() == 4 && w[2] == "colours" && w[3] == "0..255") integer_colours_ = true;
        // A set read from LAS: its point format, version, scale and offset, and (since 2026-11-30)
        // its global encoding and CRS records, so that LAS → PLY → LAS writes the same coordinates
        // in the same format, its GPS times of the same kind, in its CRS. Ignored unless all of it
        // parses.
        if ((w.size() == 12 || w.size() == 13) && w[2] == "las" && w[3] == "frame") {
          LasSource las;
          double v[8];
          bool ok = true;
          for (size_t k = 0; k < 8; ++k) {
            const std::string_view t = w[4 + k];
            ok = ok && std::from_chars(t.data(), t.data() + t.size(), v[k]).ec == std::errc() && std::isfinite(v[k]);
          }
          if (ok && v[0] >= 0 && v[0] <= 10 && v[0] == std::floor(v[0]) && v[1] >= 0 && v[1] <= 4 && v[2] > 0 &&
              v[3] > 0 && v[4] > 0) {
            las.point_format = static_cast<int>(v[0]);
            las.version_minor = static_cast<int>(v[1]);
            las.scale = glm::dvec3(v[2], v[3], v[4]);
            las.offset = glm::dvec3(v[5], v[6], v[7]);
            unsigned encoding = 0;
            if (w.size() == 13 &&
                std::from_chars(w[12].data(), w[12].data() + w[12].size(), encoding).ec == std::errc() && encoding <= 0xFFFF)
              las.global_encoding = static_cast<uint16_t>(encoding);
            points_.las = las;
          }
        }
        // Its CRS records (after the frame, which they belong to): record K's bytes in hex over one
        // or more lines ('-': none). A record with a bad line is left out.
        if (w.size() == 9 && w[2] == "las" && w[3] == "crs" && points_.las) {
          size_t index = 0;
          uint16_t record_id = 0;
          const std::string_view hex = w[8] == "-" ? std::string_view() : w[8];
          bool ok = std::from_chars(w[4].data(), w[4].data() + w[4].size(), index).ec == std::errc() &&
                    std::from_chars(w[6].data(), w[6].data() + w[6].size(), record_id).ec == std::errc() &&
                    (w[7] == "0" || w[7] == "1") && hex.size() % 2 == 0 && w[5].size() <= 16 && index < 1024;
          std::string bytes;
          ok = ok && appendHexBytes(bytes, hex);
          if (crs_records_.size() <= index) crs_records_.resize(index + 1);
          auto& [vlr, good] = crs_records_[index];
          if (vlr.user_id.empty()) {  // its first line
            vlr = LasVlr{std::string(w[5]), record_id, {}, {}, w[7] == "1"};
            good = true;
          }
          good = good && ok && vlr.user_id == w[5] && vlr.record_id == record_id;
          vlr.data += bytes;
        }
        // The coordinate system another format stated, in hex over lines in order; left out where
        // a line is not one word of hex (a line with more words dropped a piece, a review finding).
        if (w[2] == "crs") crs_lines_.add({w.begin() + 3, w.end()});
      }
      if (key == "comment" || key == "obj_info") continue;
      if (key == "end_header") {
        if (points_.las)
          for (auto& [vlr, good] : crs_records_)
            if (good) points_.las->vlrs.push_back(std::move(vlr));
        points_.crs = crs_lines_.take(path_, "comment dpoint: crs", options_.notices);
        break;
      }
      if (key == "format") {
        if (w.size() != 3) return headerError(line_no, "expected 'format ENCODING 1.0', found " + quote(line));
        if (w[1] == "ascii")
          ascii_ = true;
        else if (w[1] == "binary_big_endian")
          big_endian_ = true;
        else if (w[1] != "binary_little_endian")
          return headerError(line_no, "unknown format " + quote(w[1]));
        if (w[2] != "1.0") return headerError(line_no, "unsupported format version " + quote(w[2]));
        have_format = true;
      } else if (key == "element") {
        Element e;
        if (w.size() != 3) return headerError(line_no, "expected 'element NAME COUNT', found " + quote(line));
        auto r = std::from_chars(w[2].data(), w[2].data() + w[2].size(), e.count);
        if (r.ec != std::errc() || r.ptr != w[2].data() + w[2].size())
          return headerError(line_no, "bad element count " + quote(w[2]));
        if (hasControlByte(w[1])) return headerError(line_no, "element name " + quote(w[1]) + " has a control character");
        e.name = w[1];
        e.line = line_no;
        // Names seen kept in sets: a header of 100k properties had taken 17 s comparing each with
        // every one before it (a review finding).
        if (!element_names.insert(e.name).second) return headerError(line_no, "second element " + quote(e.name));
        property_names.clear();
        elements_.push_back(std::move(e));
      } else if (key == "property") {
        if (elements_.empty()) return headerError(line_no, "property before any element");
        Property prop;
        prop.line = line_no;
        prop.is_list = w.size() > 1 && w[1] == "list";
        if (w.size() != (prop.is_list ? 5u : 3u))
          return headerError(
              line_no, "expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME', found " + quote(line));
        for (size_t k = prop.is_list ? 2 : 1; k + 1 < w.size(); ++k) {
          auto it = std::find_if(std::begin(kTypeNames), std::end(kTypeNames),
                                 [&](const TypeInfo& t) { return t.name == w[k]; });
          if (it == std::end(kTypeNames)) return headerError(line_no, "unsupported property type " + quote(w[k]));
          (k == 2 && prop.is_list ? prop.count_type : prop.type) = it->type;
        }
        if (prop.is_list && !isInteger(prop.count_type))
          return headerError(line_no, "list count type " + quote(w[2]) + " is not an integer type");
        if (hasControlByte(w.back()))
          return headerError(line_no, "property name " + quote(w.back()) + " has a control character");
        prop.name = w.back();
        if (!property_names.insert(prop.name).second) return headerError(line_no, "second property " + quote(prop.name));
        elements_.back().properties.push_back(std::move(prop));
      } else {
        return headerError(line_no, "unknown header keyword " + quote(key));
      }
    }
    if (!have_format) return headerError(static_cast<int>(line_no_), "the header has no 'format' line");
    return okStatus();
  }

  // Gives each vertex and face property its role and checks the types they need.
  Status planElements() {
    const Element* vertex = nullptr;
    for (const Element& e : elements_) {
      if (e.name == "vertex") vertex = &e;
      if (e.name == "vertex") vertex_roles_.assign(e.properties.size(), kSkip);
      if (e.name == "face") face_roles_.assign(e.properties.size(), kSkip);
    }
    if (!vertex) return Error{path_ + ": the header declares no 'vertex' element"};
    int found[kRoleCount] = {};
    constexpr std::string_view kNames[] = {"", "x", "y", "z", "red", "green", "blue"};
    // Colours are red, green, blue, or else diffuse_red, diffuse_green, diffuse_blue (older
    // scanners' and MeshLab's name for them, which Blender and MeshLab read as colours too).
    const auto take = [&](std::string_view prefix, int first, int last) -> Status {
      for (size_t k = 0; k < vertex->properties.size(); ++k) {
        const Property& p = vertex->properties[k];
        for (int role = first; role <= last; ++role) {
          if (p.name.size() != prefix.size() + kNames[role].size() || !p.name.starts_with(prefix) ||
              !p.name.ends_with(kNames[role]))
            continue;
          if (p.is_list) return headerError(p.line, "vertex property '" + p.name + "' is a list, not a number");
          if (role >= kRed) {
            if (p.type == Type::kUint8)
              divisor_[role] = 255.0f;
            else if (p.type == Type::kUint16)
              divisor_[role] = 65535.0f;
            else if (isInteger(p.type))
              return headerError(p.line, "unsupported colour type '" + std::string(typeName(p.type)) + "' for '" +
                                             p.name + "' (uchar, ushort, float or double)");
          }
          vertex_roles_[k] = static_cast<Role>(role);
          found[role] = p.line;
        }
      }
      return okStatus();
    };
    if (Status s = take("", kX, kBlue); !s) return s;
    // The diffuse names are taken whole only: all three, each a number of a colour's type (uchar,
    // ushort, float, double); else they stay dimensions, as they were before they were taken (a
    // review finding: a lone diffuse_red was refused, an int one too).
    const bool diffuse = !found[kRed] && !found[kGreen] && !found[kBlue] && [&] {
      for (int role = kRed; role <= kBlue; ++role)
        if (std::none_of(vertex->properties.begin(), vertex->properties.end(), [&](const Property& p) {
              return p.name == "diffuse_" + std::string(kNames[role]) && !p.is_list &&
                     (p.type == Type::kUint8 || p.type == Type::kUint16 || !isInteger(p.type));
            }))
          return false;
      return true;
    }();
    if (diffuse)
      if (Status s = take("diffuse_", kRed, kBlue); !s) return s;
    // Every other number of a vertex is a dimension of its own type, in the header's order (a
    // repeated name keeps its first property; a set of names, as a header may list thousands).
    std::unordered_set<std::string> named;
    for (size_t k = 0; k < vertex->properties.size(); ++k) {
      const Property& p = vertex->properties[k];
      if (vertex_roles_[k] != kSkip || p.is_list || !named.insert(p.name).second) continue;
      vertex_roles_[k] = kAttribute;
      attribute_of_.resize(vertex->properties.size(), SIZE_MAX);
      attribute_of_[k] = points_.dimensions.count();
      points_.dimensions.append(p.name, dimTypeOf(p.type), 0);
    }
    // A list on a vertex holds several numbers a point, which no dimension does: said, not dropped
    // without a word (a review finding).
    std::string lists;
    for (const Property& p : vertex->properties)
      if (p.is_list) lists += (lists.empty() ? "" : ", ") + p.name;
    if (!lists.empty() && options_.notices)
      options_.notices->push_back(path_ + ": vertex list properties not read (a dimension holds one number a point): " +
                                  lists);
    attribute_row_.assign(points_.dimensions.count(), 0.0);
    // x and y are needed; without z the file is 2D (z = 0).
    if (!found[kZ]) points_.z_axis = ZAxis::kAbsent;
    else if (points_.z_axis == ZAxis::kUnknown) points_.z_axis = ZAxis::kPresent;
    for (int role = kX; role <= kY; ++role)
      if (!found[role])
        return headerError(vertex->line, "element 'vertex' has no '" + std::string(kNames[role]) + "' property");
    has_colors_ = found[kRed] || found[kGreen] || found[kBlue];
    // Integer colours keep their width (PointSet::color_full_scale): 16-bit colours stay 16-bit, a
    // LAS file's 8-bit ones (its frame in a comment) go back to LAS as 8-bit values, and a CSV's
    // 0..255 integers (a comment too) back to CSV as integers; other 8-bit colours are 0..1 values
    // stored in a byte (dpoint's own), written to LAS at 16 bits, as the LAS specification asks.
    if (has_colors_ && divisor_[kRed] == divisor_[kGreen] && divisor_[kGreen] == divisor_[kBlue] &&
        (divisor_[kRed] == 65535.0f || (divisor_[kRed] == 255.0f && (points_.las || integer_colours_))))
      points_.color_full_scale = static_cast<uint16_t>(divisor_[kRed]);
    // Colours of a 0..1 scale that an integer writer may round (PointSet::colors_read_as_fractions),
    // except a tile's, which generate made.
    points_.colors_read_as_fractions = has_colors_ && points_.color_full_scale == 0 && !tile_;
    if (has_colors_ && !(found[kRed] && found[kGreen] && found[kBlue]))
      return headerError(std::max({found[kRed], found[kGreen], found[kBlue]}),
                         "vertex colours need all of red, green and blue");
    for (const Element& e : elements_) {
      if (e.name != "face") continue;
      for (size_t k = 0; k < e.properties.size(); ++k) {
        const Property& p = e.properties[k];
        if (p.name != "vertex_indices" && p.name != "vertex_index") continue;
        if (!p.is_list) return headerError(p.line, "face property '" + p.name + "' is not a list");
        if (!isInteger(p.type))
          return headerError(p.line, "face index type '" + std::string(typeName(p.type)) + "' is not an integer type");
        if (std::count(face_roles_.begin(), face_roles_.end(), kIndices))
          return headerError(p.line, "face has both vertex_indices and vertex_index");
        face_roles_[k] = kIndices;
      }
      if (e.count && !std::count(face_roles_.begin(), face_roles_.end(), kIndices))
        return headerError(e.line, "element 'face' has no vertex_indices list");
      if (e.count && vertex->count > UINT32_MAX)
        return headerError(e.line, "a mesh may have at most 2^32 - 1 vertices");
    }
    vertex_count_ = vertex->count;
    return okStatus();
  }

  // A hostile header must not make us allocate: every row needs some bytes, so the counts are
  // bounded by the data that follows the header.
  // `held`: the vertices are to be held whole (a read), so they must fit the memory limit; a
  // stream (openStream) holds a block at a time, and a file larger than memory is what it is for
  // (a review finding: `info --stream on` of a PLY of 3e9 points was refused as 67 GiB).
  Status checkSizes(bool held = true) {
    const uint64_t data_bytes = in_.remaining();
    uint64_t needed = 0;
    for (const Element& e : elements_) {
      uint64_t row = 0;
      for (const Property& p : e.properties)  // an ASCII value is at least one character and a separator
        row += ascii_ ? 2 : typeSize(p.is_list ? p.count_type : p.type);
      uint64_t bytes = 0;
      const bool overflow =
          __builtin_mul_overflow(row, e.count, &bytes) || __builtin_add_overflow(needed, bytes, &needed);
      if (overflow || needed > data_bytes + (ascii_ ? 1 : 0))  // the last ASCII line may lack its newline
        return Error{path_ + ": truncated at byte " + std::to_string(file_.size()) + ": header line " +
                     std::to_string(e.line) + " declares " + std::to_string(e.count) + " '" + e.name +
                     "' rows, needing at least " + (overflow ? "2^64" : std::to_string(needed)) +
                     " bytes of data, but only " + std::to_string(data_bytes) + " follow the header"};
    }
    // What the data bounds may still be more than memory: 24-36 bytes of point set per vertex
    // from as little as 3 bytes of file.
    memory_limit_ = options_.max_memory ? options_.max_memory : defaultMemoryLimit();
    vertex_bytes_ = vertex_count_ * (sizeof(glm::dvec3) + (has_colors_ ? sizeof(glm::vec3) : 0) +
                                     points_.dimensions.bytesPerPoint());
    if (!held) return okStatus();
    return checkMemory(path_ + ": " + std::to_string(vertex_count_) + " vertices", vertex_bytes_, memory_limit_);
  }

  Status readElement(const Element& e, const std::vector<Role>& roles) {
    if (e.properties.empty() || e.count == 0) return okStatus();
    const bool is_vertex = e.name == "vertex";
    const bool fixed =
        std::none_of(e.properties.begin(), e.properties.end(), [](const Property& p) { return p.is_list; });
    if (!ascii_ && fixed && !is_vertex && e.name != "face") {  // skipped whole, without reading it
      uint64_t row_bytes = 0;
      for (const Property& p : e.properties) row_bytes += typeSize(p.type);
      if (row_bytes * e.count > in_.remaining())
        return truncated(e, in_.remaining() / row_bytes);  // bounded by checkSizes
      in_.skip(row_bytes * e.count);
      return okStatus();
    }
    if (!ascii_ && fixed && is_vertex) return readFixedVertices(e, roles);
    if (is_vertex) {
      // reserve, not resize: each page is touched once, by the parsed value (bounded by checkSizes).
      points_.positions.reserve(e.count);
      if (has_colors_) points_.colors.reserve(e.count);
    } else if (e.name == "face") {
      // A face is at least a count and three indices; fewer is an error found while reading.
      uint64_t min_face = 8;
      for (size_t k = 0; k < e.properties.size(); ++k)
        if (roles[k] == kIndices && !ascii_)
          min_face = typeSize(e.properties[k].count_type) + 3 * typeSize(e.properties[k].type);
      const uint64_t room = (memory_limit_ - vertex_bytes_) / (3 * sizeof(uint32_t));  // checkSizes: ≥ 0
      points_.triangles.reserve(3 * std::min({e.count, in_.remaining() / min_face, room}));
    }
    uint64_t first_row = 0;
    if (ascii_) first_row = readAsciiRows(e, roles);
    else if (e.name == "face") first_row = readTriangleRows(e, roles);
    for (uint64_t row = first_row; row < e.count; ++row) {
      uint64_t where = 0;
      Status s = ascii_ ? readAsciiRow(e, roles, row, where) : readBinaryRow(e, roles, row, where);
      if (!s.ok()) return s;
      if (is_vertex && !storeVertex(values_)) return nonfiniteError(values_, row, where);
      if (e.name == "face") s = finishFace(row, where);
      if (!s.ok()) return s;
    }
    return okStatus();
  }

  // Binary faces as dpoint and most tools write them: the face element's one property a list of a
  // one-byte count and 32-bit indices, every row with the first row's count k (3: triangles, 4:
  // quads, ...), so a row is 1 + 4k bytes and gives k − 2 triangles (finishFace's fan). Rows are
  // decoded in parallel blocks up to the first that has another count or an index naming no
  // vertex, the file's end (or a read that fails) or what --max-memory leaves for triangles.
  // Returns how many rows were done; the row-by-row loop goes on from there and reports any error
  // at its row, as it does for every row of other layouts. 207M faces took 6-10 s on one thread (H200).
  uint64_t readTriangleRows(const Element& e, const std::vector<Role>& roles) {
    if (e.properties.size() != 1 || roles[0] != kIndices || !points_.triangles.empty()) return 0;
    const Property& p = e.properties[0];
    if (!p.is_list || typeSize(p.count_type) != 1 || (p.type != Type::kInt32 && p.type != Type::kUint32)) return 0;
    Result<size_t> first_count = in_.require(1);
    if (!first_count || *first_count < 1) return 0;
    const uint8_t k = static_cast<uint8_t>(in_.data()[0]);
    if (k < 3) return 0;
    const uint64_t kRow = 1 + uint64_t{k} * sizeof(uint32_t), per_row = k - 2u;
    // finishFace's memory check passes while vertex_bytes_ + 12 bytes a triangle ≤ memory_limit_.
    const uint64_t room = (memory_limit_ - std::min(memory_limit_, vertex_bytes_)) / (3 * sizeof(uint32_t));
    const uint64_t rows = std::min({e.count, in_.remaining() / kRow, room / per_row});
    if (rows == 0) return 0;
    const unsigned threads = resolveThreads(options_.threads);
    resizePrefaulted(points_.triangles, static_cast<size_t>(3 * per_row * rows), threads);
    uint32_t* out = points_.triangles.data();
    const bool is_signed = p.type == Type::kInt32;
    const uint64_t vertices = vertex_count_;
    const uint64_t begin = in_.offset();
    const uint64_t block_rows = std::max<uint64_t>(1, kVertexBlockBytes / kRow);
    std::atomic<uint64_t> stop{rows};  // no row from here on is taken
    auto stopAt = [&](uint64_t row) { lowerAtomic(stop, row); };
    BlockProgress progress(options_.progress, in_.readEnd());
    std::vector<std::vector<char>> buffers(threads);
    parallelFor(static_cast<size_t>((rows + block_rows - 1) / block_rows), threads, [&](size_t b, unsigned worker) {
      const uint64_t first = b * block_rows, last = std::min(first + block_rows, rows);
      if (first >= stop.load()) return;
      std::vector<char>& buffer = buffers[worker];
      buffer.resize(static_cast<size_t>((last - first) * kRow));
      const uint64_t offset = begin + first * kRow;
      Result<size_t> got = file_.readAt(offset, buffer.data(), buffer.size());
      if (!got) return stopAt(first);  // the loop reads it again and reports the error
      const uint64_t whole = first + *got / kRow;
      const char* q = buffer.data();
      uint32_t index[255];
      for (uint64_t r = first; r < whole; ++r, q += kRow) {
        std::memcpy(index, q + 1, k * sizeof(uint32_t));
        if (big_endian_)
          for (unsigned i = 0; i < k; ++i) reverseBytes(reinterpret_cast<char*>(&index[i]), sizeof(uint32_t));
        bool good = static_cast<uint8_t>(q[0]) == k;
        for (unsigned i = 0; i < k; ++i)
          good = good && (!is_signed || static_cast<int32_t>(index[i]) >= 0) && index[i] < vertices;
        if (!good) return stopAt(r);
        fanPolygon(index, k, out + 3 * per_row * r);
      }
      if (whole < last) return stopAt(whole);
      progress.block(offset, offset + buffer.size());
    });
    const uint64_t done = stop.load();
    progress.finish(begin, begin + done * kRow);
    points_.triangles.resize(static_cast<size_t>(3 * per_row * done));
    in_.skip(done * kRow);
    return done;
  }

  // ASCII rows as most tools write them, in parallel blocks: vertex rows of single values, and faces
  // whose one property is the list of indices, of any size up to 1024 (fanned into triangles as
  // finishFace does). The newlines of the rest of the file are counted per block on all cores,
  // which gives each block the row of the first line that ends in it; each block then parses its
  // lines (readAsciiRow's tokens and values) into their rows. Parsing stops at the first row that
  // is blank, does not parse, is not acceptable or names no vertex, or at what --max-memory leaves
  // for triangles. Returns how many rows were done; the row-by-row loop goes on from there and
  // reports any error at its line.
  uint64_t readAsciiRows(const Element& e, const std::vector<Role>& roles) {
    const bool is_vertex = e.name == "vertex";
    if (is_vertex) {
      if (!points_.positions.empty() ||
          std::any_of(e.properties.begin(), e.properties.end(), [](const Property& p) { return p.is_list; }))
        return 0;
    } else if (e.name != "face" || e.properties.size() != 1 || roles[0] != kIndices || !e.properties[0].is_list ||
               !points_.triangles.empty()) {
      return 0;
    }
    constexpr uint64_t kBlock = uint64_t{4} << 20;
    const uint64_t begin = in_.offset(), bytes = in_.remaining();
    const size_t blocks = static_cast<size_t>((bytes + kBlock - 1) / kBlock);
    if (blocks == 0) return 0;
    const unsigned threads = resolveThreads(options_.threads);
    std::vector<std::vector<char>> buffers(threads);
    // Pass 1: the newlines of each block, and the offset just past its last one (0: none).
    std::vector<uint64_t> newlines(blocks, 0), after_last(blocks, 0);
    std::atomic<bool> unread{false};
    parallelFor(blocks, threads, [&](size_t b, unsigned worker) {
      const uint64_t from = begin + b * kBlock, n = std::min(kBlock, bytes - b * kBlock);
      std::vector<char>& buffer = buffers[worker];
      buffer.resize(static_cast<size_t>(n));
      Result<size_t> got = file_.readAt(from, buffer.data(), buffer.size());
      if (!got || *got < buffer.size()) {
        unread = true;  // the loop reads it again and reports why
        return;
      }
      newlines[b] = static_cast<uint64_t>(std::count(buffer.begin(), buffer.end(), '\n'));  // in vector lanes
      if (newlines[b] > 0) {
        const void* last = memrchr(buffer.data(), '\n', buffer.size());
        after_last[b] = from + static_cast<uint64_t>(static_cast<const char*>(last) - buffer.data()) + 1;
      }
    });
    if (unread) return 0;
    // Block b's lines: rows first_row[b] .. + newlines[b], from line_start[b] to after_last[b].
    std::vector<uint64_t> first_row(blocks), line_start(blocks);
    uint64_t lines = 0, start = begin;
    for (size_t b = 0; b < blocks; ++b) {
      first_row[b] = lines;
      line_start[b] = start;
      lines += newlines[b];
      if (newlines[b] > 0) start = after_last[b];
    }
    const uint64_t rows = std::min(e.count, lines);
    if (rows == 0) return 0;
    std::atomic<uint64_t> stop{rows};  // no row from here on is taken
    auto stopAt = [&](uint64_t row) { lowerAtomic(stop, row); };
    BlockProgress progress(options_.progress, in_.readEnd());
    // take(text, row) for block b's lines in order, until it returns false (the rows then stop
    // there), the text is blank, or the rows reach the stop. True when every line was taken. A line
    // that began more than a block before its block's end is left to the loop (which reports one
    // longer than kMaxAsciiLine).
    auto eachLine = [&](size_t b, unsigned worker, const auto& take) {
      const uint64_t first = first_row[b];
      if (newlines[b] == 0 || first >= stop.load()) return false;
      if (after_last[b] - line_start[b] > 2 * kBlock) {
        stopAt(first);
        return false;
      }
      std::vector<char>& buffer = buffers[worker];
      buffer.resize(static_cast<size_t>(after_last[b] - line_start[b]));
      Result<size_t> got = file_.readAt(line_start[b], buffer.data(), buffer.size());
      if (!got || *got < buffer.size()) {
        stopAt(first);
        return false;
      }
      const char* q = buffer.data();
      const char* const end = buffer.data() + buffer.size();
      for (uint64_t row = first; row < first + newlines[b]; ++row) {
        if (row >= stop.load(std::memory_order_relaxed)) return false;
        const char* nl = static_cast<const char*>(std::memchr(q, '\n', static_cast<size_t>(end - q)));
        std::string_view line(q, static_cast<size_t>(nl - q));
        q = nl + 1;
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        if (isBlank(line) || !take(line, row)) {
          stopAt(row);
          return false;
        }
      }
      return true;
    };
    auto blockDone = [&](size_t b) { progress.block(line_start[b], after_last[b]); };

    uint64_t triangles_taken = 0;  // faces: the triangles of the rows taken
    if (is_vertex) {
      resizePrefaulted(points_.positions, static_cast<size_t>(rows), threads);
      if (has_colors_) resizePrefaulted(points_.colors, static_cast<size_t>(rows), threads);
      points_.dimensions.resizeUnset(static_cast<size_t>(rows));  // every row's values are set below
      // One line's values into row `row`; false where the row-by-row loop must take it.
      auto parseVertex = [&](std::string_view rest, uint64_t row) {
        double v[kRoleCount] = {};
        double attributes[64];
        if (attribute_row_.size() > std::size(attributes)) return false;
        for (size_t k = 0; k < e.properties.size(); ++k) {
          const std::string_view token = nextToken(rest);
          double value = 0;
          if (token.empty() || !parseAscii(e.properties[k].type, token, value)) return false;
          v[roles[k]] = value;
          if (roles[k] == kAttribute) attributes[attribute_of_[k]] = value;
        }
        if (!nextToken(rest).empty() || !positionAcceptable(v) || (has_colors_ && !colourAcceptable(v))) return false;
        points_.positions[row] = glm::dvec3(v[kX], v[kY], v[kZ]);
        if (has_colors_) points_.colors[row] = colorOf(v);
        for (size_t a = 0; a < attribute_row_.size(); ++a) points_.dimensions.all()[a].setValue(row, attributes[a]);
        return true;
      };
      parallelFor(blocks, threads, [&](size_t b, unsigned worker) {
        if (eachLine(b, worker, parseVertex)) blockDone(b);
      });
    } else {
      // Faces, fanned as finishFace fans them. First every row of the first row's size (a triangle
      // or quad mesh), each to its own slots; then, from a row of another size on, rows of any
      // size: pass 2a counts each block's triangles from its rows' first values, which places
      // each block's first triangle, and pass 2b parses the rows into their triangles. A row that
      // does not parse or names no vertex stops the rows there, its block's earlier ones kept.
      const Property& list = e.properties[0];
      constexpr double kMaxCorners = 1024;  // larger polygons go to the loop
      auto cornersOf = [&](std::string_view& rest, uint64_t& corners) {
        double count = 0;
        // A row of n indices holds at least 2n − 1 characters: a bad count claims no more memory.
        const double most = std::min(kMaxCorners, static_cast<double>(rest.size()) / 2);
        if (!parseAscii(list.count_type, nextToken(rest), count) || !(count >= 3 && count <= most)) return false;
        corners = static_cast<uint64_t>(count);
        return true;
      };
      const double vertices = static_cast<double>(vertex_count_);
      // The fan of a row whose count was read, into t (fanPolygon's, made as the indices are
      // parsed: gathering them first for fanPolygon was 7% slower); false when an index is bad or
      // a value extra.
      auto fan = [&](std::string_view& rest, uint64_t corners, uint32_t* t) {
        uint32_t first = 0, previous = 0;
        for (uint64_t i = 0; i < corners; ++i) {
          double index = 0;
          const std::string_view token = nextToken(rest);
          if (token.empty() || !parseAscii(list.type, token, index) || !(index >= 0 && index < vertices)) return false;
          const uint32_t v = static_cast<uint32_t>(index);
          if (i == 0) first = v;
          if (i >= 2) {  // (v0, vi−1, vi)
            t[0] = first;
            t[1] = previous;
            t[2] = v;
            t += 3;
          }
          previous = v;
        }
        return nextToken(rest).empty();
      };
      // finishFace's memory check passes while vertex_bytes_ + 12 bytes a triangle ≤ memory_limit_;
      // past it the rows are the loop's, which names the row.
      const uint64_t room = (memory_limit_ - std::min(memory_limit_, vertex_bytes_)) / (3 * sizeof(uint32_t));
      uint64_t size = 0;  // the first row's indices
      {
        std::vector<char>& buffer = buffers[0];
        buffer.resize(static_cast<size_t>(std::min<uint64_t>(bytes, 4096)));
        Result<size_t> got = file_.readAt(begin, buffer.data(), buffer.size());
        std::string_view line(buffer.data(), got ? *got : 0);
        line = line.substr(0, line.find('\n'));
        if (!cornersOf(line, size)) size = 0;
      }
      uint64_t from = 0;         // the rows before it are taken
      bool out_of_room = false;  // the rows from `from` on would pass --max-memory
      if (size != 0) {
        const uint64_t per_row = size - 2, fixed_rows = std::min(rows, room / per_row);
        stopAt(fixed_rows);
        resizePrefaulted(points_.triangles, static_cast<size_t>(3 * per_row * fixed_rows), threads);
        parallelFor(blocks, threads, [&](size_t b, unsigned worker) {
          const bool whole = eachLine(b, worker, [&](std::string_view rest, uint64_t row) {
            uint64_t corners = 0;
            return cornersOf(rest, corners) && corners == size &&
                   fan(rest, corners, points_.triangles.data() + 3 * per_row * row);
          });
          if (whole) blockDone(b);
        });
        from = stop.load();
        triangles_taken = per_row * from;
        points_.triangles.resize(static_cast<size_t>(3 * triangles_taken));
        out_of_room = from == fixed_rows && fixed_rows < rows;
      }
      if (from < rows && !out_of_room) {
        stop = rows;  // the row at `from` may be of another size: the rows from it, of any size
        auto after = [&](size_t b) { return first_row[b] + newlines[b] > from; };  // holds rows from `from` on
        std::vector<uint64_t> block_triangles(blocks, 0);
        parallelFor(blocks, threads, [&](size_t b, unsigned worker) {
          if (!after(b)) return;
          uint64_t t = 0;
          eachLine(b, worker, [&](std::string_view rest, uint64_t row) {
            uint64_t corners = 0;
            if (row < from) return true;
            if (!cornersOf(rest, corners)) return false;
            t += corners - 2;
            return true;
          });
          block_triangles[b] = t;  // of its rows from `from` on, before its stop
        });
        std::vector<uint64_t> first_triangle(blocks, 0);
        uint64_t total = triangles_taken;
        for (size_t b = 0; b < blocks && first_row[b] < stop.load(); ++b) {
          if (!after(b)) continue;
          first_triangle[b] = total;
          if (total + block_triangles[b] > room) {
            stopAt(std::max(from, first_row[b]));
            break;
          }
          total += block_triangles[b];
        }
        if (stop.load() > from) {
          // Grown once, its new pages faulted in on all cores (a resize alone zeroes them on one).
          points_.triangles.reserve(static_cast<size_t>(3 * total));
          const size_t kept = points_.triangles.size();
          prefaultForWrite(points_.triangles.data() + kept, (static_cast<size_t>(3 * total) - kept) * sizeof(uint32_t),
                           threads);
          points_.triangles.resize(static_cast<size_t>(3 * total));
          std::vector<uint64_t> placed(blocks, 0);
          parallelFor(blocks, threads, [&](size_t b, unsigned worker) {
            if (!after(b)) return;
            uint32_t* t = points_.triangles.data() + 3 * first_triangle[b];
            const bool whole = eachLine(b, worker, [&](std::string_view rest, uint64_t row) {
              uint64_t corners = 0;
              if (row < from) return true;
              if (!cornersOf(rest, corners) || !fan(rest, corners, t)) return false;
              t += 3 * (corners - 2);
              placed[b] += corners - 2;
              return true;
            });
            if (whole) blockDone(b);
          });
          // The rows before the stop: every block's before its block, and its block's own.
          for (size_t b = 0; b < blocks && first_row[b] < stop.load(); ++b) triangles_taken += placed[b];
        }
      }
    }
    const uint64_t done = stop.load();
    if (!is_vertex) {
      points_.triangles.resize(static_cast<size_t>(3 * triangles_taken));
    } else if (done < rows) {
      points_.positions.resize(static_cast<size_t>(done));
      if (has_colors_) points_.colors.resize(static_cast<size_t>(done));
      points_.dimensions.resize(static_cast<size_t>(done));
    }
    if (done == 0) return 0;
    // The offset just past row done − 1's newline: found in its block.
    size_t b = static_cast<size_t>(std::upper_bound(first_row.begin(), first_row.end(), done - 1) - first_row.begin()) - 1;
    while (newlines[b] == 0) --b;
    uint64_t end = after_last[b];
    if (first_row[b] + newlines[b] > done) {
      std::vector<char>& buffer = buffers[0];
      buffer.resize(static_cast<size_t>(after_last[b] - line_start[b]));
      Result<size_t> got = file_.readAt(line_start[b], buffer.data(), buffer.size());
      if (!got || *got < buffer.size()) {  // read a moment ago: the file changed; the loop says so
        if (is_vertex) {
          points_.positions.clear();
          points_.colors.clear();
          points_.dimensions.resize(0);
        } else {
          points_.triangles.clear();
        }
        return 0;
      }
      const char* q = buffer.data();
      for (uint64_t row = first_row[b]; row < done; ++row)
        q = static_cast<const char*>(std::memchr(q, '\n', static_cast<size_t>(buffer.data() + buffer.size() - q))) + 1;
      end = line_start[b] + static_cast<uint64_t>(q - buffer.data());
    }
    progress.finish(begin, end);
    in_.skip(end - begin);
    line_no_ += done;
    return done;
  }

  // Where a binary vertex row keeps its values.
  struct RowLayout {
    struct Field {
      size_t offset;
      Type type;
      Role role;
    };
    std::vector<Field> fields;
    struct Attribute {
      size_t offset, bytes, dimension;
    };
    std::vector<Attribute> attributes;  // copied as they are into their dimension's column
    size_t row_bytes = 0, at[kRoleCount] = {};
    std::vector<std::pair<size_t, size_t>> swapped;  // a big-endian file: each wider value's offset and size
    bool packed = true;     // adjacent double x, y, z and uchar colours: what dpoint and most tools write
    float byte_color[256];  // k / 255.0f, the same rounding as colorOf

    // A big-endian file's rows into the host's order, in place (nothing for a little-endian one).
    void toHostOrder(char* rows, size_t count) const {
      if (swapped.empty()) return;
      for (size_t r = 0; r < count; ++r, rows += row_bytes)
        for (const auto& [offset, size] : swapped) reverseBytes(rows + offset, size);
    }

    void load(const char* row, double* v) const {
      v[kZ] = 0.0;  // a 2D file has no z property
      for (const Field& f : fields) v[f.role] = loadValue(f.type, row + f.offset);
    }
  };

  RowLayout vertexLayout(const Element& e, const std::vector<Role>& roles) const {
    RowLayout layout;
    for (size_t k = 0; k < e.properties.size(); layout.row_bytes += typeSize(e.properties[k++].type)) {
      if (big_endian_ && roles[k] != kSkip && typeSize(e.properties[k].type) > 1)
        layout.swapped.push_back({layout.row_bytes, typeSize(e.properties[k].type)});
      if (roles[k] == kSkip) continue;
      if (roles[k] == kAttribute) {
        layout.attributes.push_back({layout.row_bytes, typeSize(e.properties[k].type), attribute_of_[k]});
        continue;
      }
      layout.fields.push_back({layout.row_bytes, e.properties[k].type, roles[k]});
      layout.at[roles[k]] = layout.row_bytes;
      layout.packed = layout.packed && e.properties[k].type == (roles[k] <= kZ ? Type::kFloat64 : Type::kUint8);
    }
    layout.packed = layout.packed && layout.at[kY] == layout.at[kX] + 8 && layout.at[kZ] == layout.at[kX] + 16;
    for (int k = 0; k < 256; ++k) layout.byte_color[k] = static_cast<float>(k) / 255.0f;
    return layout;
  }

  // The hot path: binary rows of one size, decoded in blocks on all cores (see the top comment).
  Status readFixedVertices(const Element& e, const std::vector<Role>& roles) {
    const RowLayout layout = vertexLayout(e, roles);

    // checkSizes bounds the rows by the file size, but elements before this one may hold longer
    // lists than it assumed: decode the whole rows there are, then report the cut.
    const size_t row_bytes = layout.row_bytes;
    const uint64_t begin = in_.offset();
    const uint64_t rows = std::min<uint64_t>(e.count, in_.remaining() / row_bytes);
    const uint64_t block_rows = std::max<size_t>(1, kVertexBlockBytes / row_bytes);
    const size_t blocks = static_cast<size_t>((rows + block_rows - 1) / block_rows);
    const unsigned threads = resolveThreads(options_.threads);
    BlockProgress progress(options_.progress, in_.readEnd());  // every block's rows are taken, or the read fails
    // Sized, not reserved: every block writes its own slots.
    resizePrefaulted(points_.positions, static_cast<size_t>(rows), threads);
    if (has_colors_) resizePrefaulted(points_.colors, static_cast<size_t>(rows), threads);
    points_.dimensions.resizeUnset(static_cast<size_t>(rows));  // every row's bytes are copied in below
    std::vector<uint8_t*> columns;
    for (Dimension& d : points_.dimensions.all()) columns.push_back(d.bytes.data());

    std::mutex error_mutex;
    std::optional<Error> first_error;
    std::atomic<uint64_t> error_row{UINT64_MAX};
    auto fail = [&](uint64_t row, Error error) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (row < error_row.load()) {
        error_row = row;
        first_error = std::move(error);
      }
    };
    glm::dvec3* positions = points_.positions.data();
    glm::vec3* colors = has_colors_ ? points_.colors.data() : nullptr;
    std::vector<std::vector<char>> buffers(threads);
    parallelFor(blocks, threads, [&](size_t b, unsigned worker) {
      const uint64_t first = b * block_rows, last = std::min(first + block_rows, rows);
      if (first > error_row.load()) return;  // cannot hold the first error
      const uint64_t offset = begin + first * row_bytes;
      std::vector<char>& buffer = buffers[worker];
      buffer.resize(static_cast<size_t>((last - first) * row_bytes));
      Result<size_t> got = file_.readAt(offset, buffer.data(), buffer.size());
      if (!got) return fail(first, got.error());
      if (*got < buffer.size()) {  // the file shrank since it was opened
        const uint64_t whole = first + *got / row_bytes;
        return fail(whole, truncated(e, whole));
      }
      layout.toHostOrder(buffer.data(), static_cast<size_t>(last - first));
      const uint64_t bad = decodeVertices(layout, buffer.data(), first, last, positions, colors, 0, columns.data());
      if (bad != last) {
        double v[kRoleCount];
        layout.load(buffer.data() + (bad - first) * row_bytes, v);
        return fail(bad, nonfiniteError(v, bad, begin + bad * row_bytes));
      }
      progress.block(offset, offset + buffer.size());
    });
    if (first_error) return *first_error;
    if (rows < e.count) return truncated(e, rows);
    in_.skip(rows * row_bytes);
    return okStatus();
  }

  // Decodes rows [first, last) from `data` (row `first` at data[0]) into positions[row − base] and,
  // when not null, colors[row − base]. Returns the first unacceptable row, or `last`. Runs on
  // several threads.
  uint64_t decodeVertices(const RowLayout& layout, const char* data, uint64_t first, uint64_t last,
                          glm::dvec3* positions, glm::vec3* colors, uint64_t base,
                          uint8_t* const* columns = nullptr) const {
    const char* p = data;
    for (uint64_t row = first; row < last; ++row, p += layout.row_bytes) {
      double v[kRoleCount];  // local, so that stores into the point arrays cannot alias it
      const uint64_t at = row - base;
      if (columns)
        for (const RowLayout::Attribute& a : layout.attributes)
          std::memcpy(columns[a.dimension] + at * a.bytes, p + a.offset, a.bytes);
      if (layout.packed) {
        std::memcpy(&v[kX], p + layout.at[kX], 3 * sizeof(double));
        if (!positionAcceptable(v)) return row;  // uchar colours always are
        positions[at] = glm::dvec3(v[kX], v[kY], v[kZ]);
        if (colors)
          colors[at] = glm::vec3(layout.byte_color[static_cast<uint8_t>(p[layout.at[kRed]])],
                                  layout.byte_color[static_cast<uint8_t>(p[layout.at[kGreen]])],
                                  layout.byte_color[static_cast<uint8_t>(p[layout.at[kBlue]])]);
      } else {
        layout.load(p, v);
        if (!positionAcceptable(v) || (colors && !colourAcceptable(v))) return row;
        positions[at] = glm::dvec3(v[kX], v[kY], v[kZ]);
        if (colors) colors[at] = colorOf(v);
      }
    }
    return last;
  }

  Status readBinaryRow(const Element& e, const std::vector<Role>& roles, uint64_t row, uint64_t& where) {
    where = in_.offset();
    polygon_.clear();
    for (size_t k = 0; k < e.properties.size(); ++k) {
      const Property& p = e.properties[k];
      const size_t size = typeSize(p.is_list ? p.count_type : p.type);
      auto avail = in_.require(size);
      if (!avail.ok()) return avail.error();
      if (*avail < size) return truncated(e, row);
      const double value = loadValue(p.is_list ? p.count_type : p.type, in_.data(), big_endian_);
      in_.consume(size);
      if (!p.is_list) {
        values_[roles[k]] = value;
        if (roles[k] == kAttribute) attribute_row_[attribute_of_[k]] = value;
        continue;
      }
      if (value < 0) return dataError(where, e.name + " " + std::to_string(row) + ": negative list length");
      const uint64_t bytes = static_cast<uint64_t>(value) * typeSize(p.type);
      if (bytes > in_.remaining()) return truncated(e, row);
      if (roles[k] != kIndices) {
        in_.skip(bytes);
        continue;
      }
      auto got = in_.require(static_cast<size_t>(bytes));
      if (!got.ok()) return got.error();
      for (const char* q = in_.data(); q != in_.data() + bytes; q += typeSize(p.type))
        polygon_.push_back(loadValue(p.type, q, big_endian_));
      in_.consume(static_cast<size_t>(bytes));
    }
    return okStatus();
  }

  Status readAsciiRow(const Element& e, const std::vector<Role>& roles, uint64_t row, uint64_t& where) {
    std::string_view line;
    do {
      auto got = in_.nextLine(line, kMaxAsciiLine);
      if (!got.ok()) return got.error();
      ++line_no_;
      if (*got == ByteReader::Line::kTooLong) return dataError(line_no_, "line too long");
      if (*got == ByteReader::Line::kEnd)
        return Error{path_ + ": line " + std::to_string(line_no_) + ": the file ends after " + std::to_string(row) +
                     " of " + std::to_string(e.count) + " '" + e.name + "' rows"};
    } while (isBlank(line));
    where = line_no_;
    polygon_.clear();
    std::string_view rest = line;
    auto parse = [&](const Property& p, Type t, double& out) -> Status {
      std::string_view token = nextToken(rest);
      if (token.empty())
        return dataError(where, e.name + " " + std::to_string(row) + ": missing value for '" + p.name + "'");
      if (!parseAscii(t, token, out))
        return dataError(where, e.name + " " + std::to_string(row) + ": '" + p.name + "': " + quote(token) +
                                    " is not a valid " + std::string(typeName(t)));
      return okStatus();
    };
    for (size_t k = 0; k < e.properties.size(); ++k) {
      const Property& p = e.properties[k];
      double value = 0;
      if (Status s = parse(p, p.is_list ? p.count_type : p.type, value); !s.ok()) return s;
      if (!p.is_list) {
        values_[roles[k]] = value;
        if (roles[k] == kAttribute) attribute_row_[attribute_of_[k]] = value;
        continue;
      }
      if (value < 0) return dataError(where, e.name + " " + std::to_string(row) + ": negative list length");
      for (double i = 0; i < value; ++i) {
        double item = 0;
        if (Status s = parse(p, p.type, item); !s.ok()) return s;
        if (roles[k] == kIndices) polygon_.push_back(item);
      }
    }
    if (std::string_view extra = nextToken(rest); !extra.empty())
      return dataError(where,
                       e.name + " " + std::to_string(row) + ": more values than the header declares, " + quote(extra));
    return okStatus();
  }

  // Per row, so no Status: a position must be finite unless allowed, and so must a colour (the
  // renderer turns colours into bytes; the CSV reader refuses them alike). A double colour must
  // also fit a float: converting one that does not is undefined.
  bool positionAcceptable(const double* v) const {
    return options_.allow_nonfinite || (std::isfinite(v[kX]) && std::isfinite(v[kY]) && std::isfinite(v[kZ]));
  }
  bool colourChannelAcceptable(double c) const {
    return std::isfinite(c) ? std::fabs(c) <= double(FLT_MAX) : options_.allow_nonfinite;
  }
  bool colourAcceptable(const double* v) const {
    return colourChannelAcceptable(v[kRed]) && colourChannelAcceptable(v[kGreen]) && colourChannelAcceptable(v[kBlue]);
  }
  glm::vec3 colorOf(const double* v) const {
    return glm::vec3(static_cast<float>(v[kRed]) / divisor_[kRed], static_cast<float>(v[kGreen]) / divisor_[kGreen],
                     static_cast<float>(v[kBlue]) / divisor_[kBlue]);
  }
  bool storeVertex(const double* v) {
    if (!positionAcceptable(v) || (has_colors_ && !colourAcceptable(v))) return false;
    points_.positions.emplace_back(v[kX], v[kY], v[kZ]);
    if (has_colors_) points_.colors.push_back(colorOf(v));
    const size_t row = points_.positions.size() - 1;
    for (size_t a = 0; a < attribute_row_.size(); ++a) {
      Dimension& d = points_.dimensions.all()[a];
      d.resize(row + 1);
      d.setValue(row, attribute_row_[a]);
    }
    return true;
  }

  // Why row `row` was not acceptable: the first bad position axis, else the first bad colour.
  Error nonfiniteError(const double* v, uint64_t row, uint64_t where) const {
    if (positionAcceptable(v)) {
      static constexpr const char* kChannel[] = {"red", "green", "blue"};
      int c = kRed;
      while (c < kBlue && colourChannelAcceptable(v[c])) ++c;
      return dataError(where, "vertex " + std::to_string(row) + ": " + kChannel[c - kRed] + " is " + numberText(v[c]) +
                                  (std::isfinite(v[c]) ? ", out of float range" : ", not a finite number"));
    }
    const double x = v[kX], y = v[kY], z = v[kZ];
    const char axis = std::isfinite(x) ? (std::isfinite(y) ? 'z' : 'y') : 'x';
    const double bad = axis == 'x' ? x : axis == 'y' ? y : z;
    return dataError(
        where, "vertex " + std::to_string(row) + ": " + axis + " is " + numberText(bad) + ", not a finite number");
  }

  // Fan triangulation (v0, vi, vi+1): exact for the convex polygons PLY writers emit.
  Status finishFace(uint64_t row, uint64_t where) {
    if (polygon_.size() < 3)
      return dataError(where, "face " + std::to_string(row) + " has " + std::to_string(polygon_.size()) +
                                  " vertices; a face needs at least 3");
    for (double index : polygon_)
      if (index < 0 || index >= static_cast<double>(vertex_count_))
        return dataError(where, "face " + std::to_string(row) + ": vertex index " +
                                    std::to_string(static_cast<int64_t>(index)) + " out of range (the file has " +
                                    std::to_string(vertex_count_) + " vertices)");
    // A face of n indices (1 byte each, at least) becomes 3(n - 2) of 4 bytes: checked as it grows.
    const uint64_t triangle_bytes = (points_.triangles.size() + 3 * (polygon_.size() - 2)) * sizeof(uint32_t);
    if (vertex_bytes_ + triangle_bytes > memory_limit_)
      return checkMemory(path_ + ": face " + std::to_string(row) + ": the faces' triangles",
                         vertex_bytes_ + triangle_bytes, memory_limit_)
          .error();
    for (size_t i = 1; i + 1 < polygon_.size(); ++i)
      for (double index : {polygon_[0], polygon_[i], polygon_[i + 1]})
        points_.triangles.push_back(static_cast<uint32_t>(index));
    return okStatus();
  }

  Status checkEnd() {
    if (!ascii_) {
      if (in_.remaining() == 0) return okStatus();
      return dataError(in_.offset(), std::to_string(in_.remaining()) + " bytes of data after the last element");
    }
    for (;;) {
      std::string_view line;
      auto got = in_.nextLine(line, kMaxAsciiLine);
      if (!got.ok()) return got.error();
      if (*got == ByteReader::Line::kEnd) return okStatus();
      ++line_no_;
      if (*got == ByteReader::Line::kTooLong || !isBlank(line))
        return dataError(line_no_, "data after the last element (the header's counts are too small?)");
    }
  }

  const InputFile& file_;
  const std::string& path_;
  const PlyReadOptions& options_;
  ByteReader in_;
  bool ascii_ = false;
  bool big_endian_ = false;  // format binary_big_endian: every wider value's bytes reversed as read
  std::vector<Element> elements_;
  std::vector<Role> vertex_roles_, face_roles_;
  bool has_colors_ = false;
  bool integer_colours_ = false;  // the header's `comment dpoint: colours 0..255`
  bool tile_ = false;  // the header's `comment dpoint-tile I/N` (kPlyTileCommentWord)
  std::vector<std::pair<LasVlr, bool>> crs_records_;  // the header's `las crs` records, each whole or not
  HeaderCrsLines crs_lines_;  // the header's `crs` lines
  float divisor_[kRoleCount] = {1, 1, 1, 1, 1, 1, 1, 1};
  uint64_t vertex_count_ = 0;
  uint64_t memory_limit_ = 0;  // --max-memory, resolved (checkSizes)
  uint64_t vertex_bytes_ = 0;  // what the vertices take in the point set
  uint64_t line_no_ = 0;  // the last line read (header, then ASCII data)
  double values_[kRoleCount] = {};
  std::vector<size_t> attribute_of_;  // per vertex property: its dimension's index (kAttribute only)
  std::vector<double> attribute_row_;  // the dimensions' values of the row being read (ASCII, lists)
  std::vector<double> polygon_;  // indices of the current face (exact in double)
  PointSet points_;
  RowLayout stream_layout_;  // PlyVertexStream
  std::vector<size_t> streamed_dimensions_;  // PlyVertexStream: the dimensions each block gets
  uint64_t stream_begin_ = 0;
};

}  // namespace

Result<PointSet> readPly(const std::string& path, const PlyReadOptions& options) {
  auto file = InputFile::open(path);
  if (!file.ok()) return file.error();
  return readPly(*file, options);
}

Result<PointSet> readPly(const InputFile& file, const PlyReadOptions& options) {
  PlyParser parser(file, options);
  return parser.run();
}

struct PlyVertexStream::State {
  State(InputFile opened, const PlyReadOptions& read) : file(std::move(opened)), options(read), parser(file, options) {}
  InputFile file;
  PlyReadOptions options;
  PlyParser parser;
};

Result<std::unique_ptr<PlyVertexStream>> PlyVertexStream::open(const std::string& path, const PlyReadOptions& options) {
  auto file = InputFile::open(path);
  if (!file.ok()) return file.error();
  std::unique_ptr<PlyVertexStream> stream(new PlyVertexStream);
  stream->state_ = std::make_unique<State>(std::move(*file), options);
  if (Status status = stream->state_->parser.openStream(); !status) return status.error();
  return stream;
}

PlyVertexStream::~PlyVertexStream() = default;
uint64_t PlyVertexStream::count() const { return state_->parser.vertexCount(); }
bool PlyVertexStream::hasColors() const { return state_->parser.hasColors(); }
bool PlyVertexStream::floatColors() const { return state_->parser.floatColors(); }
uint64_t PlyVertexStream::faceCount() const { return state_->parser.faceCount(); }
const std::string& PlyVertexStream::crs() const { return state_->parser.crs(); }
const std::optional<LasSource>& PlyVertexStream::las() const { return state_->parser.las(); }
const Dimensions& PlyVertexStream::dimensions() const { return state_->parser.dimensions(); }
void PlyVertexStream::streamDimensions(std::vector<size_t> which) { state_->parser.streamDimensions(std::move(which)); }
Status PlyVertexStream::read(uint64_t first, uint64_t n, PointSet& block) {
  return state_->parser.readStream(first, n, block);
}

}  // namespace dpoint
