// Leica's PTX text: scans one after another, each a ten-line header (the grid's columns and rows,
// the scanner's registered position and axes, and a 4x4 transformation) and then columns x rows
// lines of `x y z [intensity] [r g b]` in the scanner's own frame, a point with no echo written
// as 0 0 0.
//
// The file's line ends are counted once on all cores (LineIndex), which places every scan's
// header and rows without reading the rows; each scan's rows are then read by the CSV reader
// (readCsvRows over a slice of the file, its line numbers the file's), moved into the registered
// frame with the scan's transformation in double precision, and the points with no echo left out.
#include <fast_float/fast_float.h>

#include <algorithm>
#include <cstring>
#include <optional>

#include "converters/csv.h"
#include "converters/point_inputs.h"
#include "core/dimensions.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "core/text.h"

namespace dpoint {

bool isPtxPath(const std::string& path) { return lowerExtension(path) == ".ptx"; }

namespace {

constexpr size_t kIndexBlock = 8u << 20;
constexpr uint64_t kHeaderLines = 10;
// The longest line read: the CSV reader's limit (a row padded with spaces is still a row).
constexpr size_t kMaxPtxLine = 512u << 10;

bool isBlankChar(char c) { return c == ' ' || c == '\t' || c == '\r'; }

// Where every line of a file starts, from its line ends counted per block on all cores.
class LineIndex {
 public:
  static Result<LineIndex> build(const InputFile& file, unsigned threads, Progress* progress) {
    LineIndex index(file);
    const uint64_t size = file.size();
    const size_t blocks = static_cast<size_t>((size + kIndexBlock - 1) / kIndexBlock);
    index.ends_.assign(blocks + 1, 0);
    std::vector<std::optional<Error>> errors(blocks);
    std::vector<std::vector<char>> buffers(threads);
    char last = '\n';
    parallelFor(blocks, threads, [&](size_t b, unsigned worker) {
      std::vector<char>& buffer = buffers[worker];
      const uint64_t offset = uint64_t{b} * kIndexBlock;
      buffer.resize(static_cast<size_t>(std::min<uint64_t>(kIndexBlock, size - offset)));
      Result<size_t> got = file.readAt(offset, buffer.data(), buffer.size());
      if (!got || *got != buffer.size()) {
        errors[b] = got ? Error{file.path() + ": the file changed while it was read (shorter than its size); "
                                              "read it again once it is whole"}
                        : got.error();
        return;
      }
      index.ends_[b + 1] = static_cast<uint64_t>(std::count(buffer.begin(), buffer.end(), '\n'));
      if (b + 1 == blocks && !buffer.empty()) last = buffer.back();
      if (progress) progress->advance(buffer.size());
    });
    for (const std::optional<Error>& e : errors)
      if (e) return *e;
    for (size_t b = 0; b < blocks; ++b) index.ends_[b + 1] += index.ends_[b];
    index.lines_ = index.ends_.back() + (last != '\n' ? 1 : 0);
    return index;
  }

  // Lines in the file: its line ends, and a last line without one.
  uint64_t lines() const { return lines_; }

  // The byte where 0-based line `line` starts; the file's size for line lines(). Asked in
  // increasing order (the scans in turn), each block is read once: a cursor goes on from the
  // line asked before (a file of 65,535 one-point scans had read its 8 MiB block for each).
  Result<uint64_t> offsetOf(uint64_t line) {
    if (line == 0) return uint64_t{0};
    if (line >= lines_) return file_->size();
    // The line starts after the line-th line end, which lies in the block b where ends_[b] < line <= ends_[b + 1].
    const size_t b = static_cast<size_t>(std::lower_bound(ends_.begin() + 1, ends_.end(), line) - ends_.begin()) - 1;
    const uint64_t offset = uint64_t{b} * kIndexBlock;
    if (b != block_) {
      buffer_.resize(static_cast<size_t>(std::min<uint64_t>(kIndexBlock, file_->size() - offset)));
      Result<size_t> got = file_->readAt(offset, buffer_.data(), buffer_.size());
      if (!got) return got.error();
      buffer_.resize(*got);
      block_ = b;
      cursor_ = 0, cursor_line_ = ends_[b];
    } else if (line <= cursor_line_) {  // behind the cursor: from the block's start
      cursor_ = 0, cursor_line_ = ends_[b];
    }
    while (cursor_ < buffer_.size()) {
      const void* nl = std::memchr(buffer_.data() + cursor_, '\n', buffer_.size() - cursor_);
      if (!nl) break;
      cursor_ = static_cast<size_t>(static_cast<const char*>(nl) - buffer_.data()) + 1;
      if (++cursor_line_ == line) return offset + cursor_;
    }
    return Error{file_->path() + ": the file changed while it was read (its lines moved); read it again once it is whole"};
  }

 private:
  explicit LineIndex(const InputFile& file) : file_(&file) {}
  const InputFile* file_;
  std::vector<uint64_t> ends_;  // ends_[b]: line ends before block b
  uint64_t lines_ = 0;
  // offsetOf's block as read, and the place after its cursor_line_-th line end (counted from the file's start).
  std::vector<char> buffer_;
  size_t block_ = SIZE_MAX, cursor_ = 0;
  uint64_t cursor_line_ = 0;
};

// The text's fields, split at runs of spaces and tabs (a CR at the end passed over).
std::vector<std::string_view> fieldsOf(std::string_view text) {
  std::vector<std::string_view> fields;
  size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && isBlankChar(text[i])) ++i;
    const size_t start = i;
    while (i < text.size() && !isBlankChar(text[i])) ++i;
    if (i > start) fields.push_back(text.substr(start, i - start));
  }
  return fields;
}

// The text at `offset` holding its next `lines` lines where they are short: 1 KiB first (a scan's
// header and rows are short), then up to `lines` of the longest a PTX line may be.
Result<std::string> linesAt(const InputFile& file, uint64_t offset, size_t lines) {
  std::string text;
  for (const size_t bytes : {size_t{1024}, lines * kMaxPtxLine}) {
    text.resize(static_cast<size_t>(std::min<uint64_t>(bytes, file.size() - offset)));
    Result<size_t> got = file.readAt(offset, text.data(), text.size());
    if (!got) return got.error();
    text.resize(*got);
    if (static_cast<size_t>(std::count(text.begin(), text.end(), '\n')) >= lines || offset + text.size() >= file.size())
      break;
  }
  return text;
}

// The byte and 0-based line after the blank lines from `offset` (between scans, after the last),
// read 256 bytes, then 64 KiB at a time (a file of two million blank lines had read 4 KiB for each).
Status passBlankLines(const InputFile& file, uint64_t& offset, uint64_t& line) {
  std::string text;
  size_t chunk = 256;  // most scans follow with no blank line: a short read first
  while (offset < file.size()) {
    text.resize(static_cast<size_t>(std::min<uint64_t>(chunk, file.size() - offset)));
    chunk = std::max(chunk, size_t{64} << 10);
    Result<size_t> got = file.readAt(offset, text.data(), text.size());
    if (!got) return got.error();
    text.resize(*got);
    const bool last = offset + text.size() >= file.size();
    size_t pos = 0;
    bool text_found = false, cut = false;  // a line with text (the next scan's); a blank line going on past the chunk
    while (pos < text.size()) {
      const size_t nl = text.find('\n', pos);
      const size_t stop = nl == std::string::npos ? text.size() : nl;
      if (!std::all_of(text.begin() + static_cast<ptrdiff_t>(pos), text.begin() + static_cast<ptrdiff_t>(stop), isBlankChar)) {
        text_found = true;
        break;
      }
      if (nl == std::string::npos) {
        if (last) pos = text.size();  // blanks to the end of the file
        else cut = true;
        break;
      }
      pos = nl + 1;
      ++line;
    }
    offset += pos;
    if (text_found || last) break;
    // A blank line longer than the chunk: a larger one, up to the longest line read (then the
    // header's reader refuses it).
    if (cut && pos == 0) {
      if (chunk >= kMaxPtxLine) break;
      chunk = std::min(kMaxPtxLine, chunk * 4);
    }
  }
  return okStatus();
}

// A scan's header: the grid and the transformation (row-vector form: p' = [x y z 1] M).
struct ScanHeader {
  uint64_t columns = 0, rows = 0;
  double m[4][4] = {};  // row-major, as the file writes it
};

// The ten lines from `offset` (0-based line `line`); `data` gets the byte after them.
Result<ScanHeader> readScanHeader(const InputFile& file, uint64_t offset, uint64_t line, uint64_t& data) {
  const std::string& path = file.path();
  Result<std::string> read = linesAt(file, offset, kHeaderLines);
  if (!read) return read.error();
  const std::string& text = *read;
  ScanHeader header;
  size_t pos = 0;
  constexpr const char* kWhat[] = {"the scan's column count",
                                   "the scan's row count",
                                   "the scanner's registered position (3 numbers)",
                                   "the scanner's registered x axis (3 numbers)",
                                   "the scanner's registered y axis (3 numbers)",
                                   "the scanner's registered z axis (3 numbers)",
                                   "the transformation's first row (4 numbers)",
                                   "the transformation's second row (4 numbers)",
                                   "the transformation's third row (4 numbers)",
                                   "the transformation's fourth row, the translation and 1 (4 numbers)"};
  for (uint64_t k = 0; k < kHeaderLines; ++k) {
    const std::string at = path + ":" + std::to_string(line + k + 1) + ": ";
    const size_t nl = text.find('\n', pos);
    const size_t cr = text.find('\r', pos);
    if (cr != std::string::npos && cr + 1 < std::min(nl, text.size()))
      return Error{at + "carriage returns inside a line: the file's lines end with CR alone (old Mac text); "
                        "convert them to LF or CR LF"};
    if (nl == std::string::npos && (text.size() - pos >= kMaxPtxLine || offset + text.size() < file.size()))
      return Error{at + "line longer than " + std::to_string(kMaxPtxLine) + " bytes where a PTX header has " + kWhat[k]};
    if (pos >= text.size() && nl == std::string::npos)
      return Error{at + "the file ends inside a scan's header, which has ten lines (here " + kWhat[k] + ")"};
    const std::string_view this_line(text.data() + pos, (nl == std::string::npos ? text.size() : nl) - pos);
    const std::vector<std::string_view> fields = fieldsOf(this_line);
    const size_t wanted = k < 2 ? 1 : k < 6 ? 3 : 4;
    const auto bad = [&](const std::string& why) {
      return Error{at + why + ": '" + printableExcerpt(std::string(this_line)) + "' where a PTX header has " + kWhat[k]};
    };
    if (fields.size() != wanted) return bad(countOf(fields.size(), "field"));
    if (k < 2) {
      uint64_t n = 0;
      if (!parseDecimalU64(std::string(fields[0]), n)) return bad("not a whole number of 0 to 2^64");
      (k == 0 ? header.columns : header.rows) = n;
    }
    for (size_t f = 0; f < fields.size() && k >= 2; ++f) {
      double v = 0.0;
      const auto [end, ec] = fast_float::from_chars(fields[f].data(), fields[f].data() + fields[f].size(), v);
      if (ec != std::errc() || end != fields[f].data() + fields[f].size() || !std::isfinite(v))
        return bad("field " + std::to_string(f + 1) + " is not a finite number");
      if (k >= 6) header.m[k - 6][f] = v;
    }
    if (k >= 6 && header.m[k - 6][3] != (k == 9 ? 1.0 : 0.0))
      return bad(std::string("its fourth number must be ") + (k == 9 ? "1" : "0") +
                 " (a rotation and translation; dpoint applies no projection)");
    pos = nl == std::string::npos ? text.size() : nl + 1;
  }
  data = offset + pos;
  return header;
}

// Whether the transformation's rotation part (its first three rows) is the identity: a translation
// alone, or nothing.
bool isTranslation(const double (&m)[4][4]) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      if (m[r][c] != (r == c ? 1.0 : 0.0)) return false;
  return true;
}

constexpr size_t kRows = size_t{1} << 16;
// What a scan read costs beyond its points' arrays (a point set, its dimension, allocations):
// counted against --max-memory, so that 65,535 one-point scans are not taken as 65,535 points.
constexpr uint64_t kScanBytes = 1024;

// Keeps the rows of `width` bytes whose keep[i] is set, in order, at the array's front: each block
// of rows closed up on its own (all cores), then the blocks moved down in turn. Returns the rows kept.
size_t keepRows(char* data, size_t width, const std::vector<uint8_t>& keep, unsigned threads) {
  const size_t n = keep.size(), blocks = (n + kRows - 1) / kRows;
  std::vector<size_t> kept(blocks, 0);
  parallelFor(blocks, threads, [&](size_t b, unsigned) {
    size_t out = b * kRows;
    for (size_t i = b * kRows, end = std::min(n, i + kRows); i < end; ++i)
      if (keep[i]) {
        if (out != i) std::memcpy(data + out * width, data + i * width, width);
        ++out;
      }
    kept[b] = out - b * kRows;
  });
  size_t at = 0;
  for (size_t b = 0; b < blocks; ++b) {
    if (at != b * kRows && kept[b] > 0) std::memmove(data + at * width, data + b * kRows * width, kept[b] * width);
    at += kept[b];
  }
  return at;
}

// The scan's rows moved into the registered frame (double precision), those with no echo (0 0 0
// in the scanner's frame) left out. Returns how many were left out.
size_t registerScan(PointSet& scan, const ScanHeader& header, unsigned threads) {
  const size_t n = scan.size();
  std::vector<uint8_t> keep(n);
  // A translation alone is added on the axes it moves, so that each coordinate is the row's plus
  // it, rounded once: -0 stays -0 on an axis it leaves, and an inf on one axis makes no NaN on the
  // others (as the product's inf · 0 would; a review finding, on PTX that dpoint writes).
  const bool translation = isTranslation(header.m);
  const auto& m = header.m;
  std::vector<size_t> dropped((n + kRows - 1) / kRows, 0);
  parallelFor(dropped.size(), threads, [&](size_t b, unsigned) {
    for (size_t i = b * kRows, end = std::min(n, i + kRows); i < end; ++i) {
      glm::dvec3& p = scan.positions[i];
      keep[i] = !(p.x == 0.0 && p.y == 0.0 && p.z == 0.0);
      dropped[b] += keep[i] ? 0 : 1;
      if (translation) {
        for (int c = 0; c < 3; ++c)
          if (m[3][c] != 0.0) p[c] += m[3][c];
        continue;
      }
      const glm::dvec3 q = p;
      for (int c = 0; c < 3; ++c) p[c] = q.x * m[0][c] + q.y * m[1][c] + q.z * m[2][c] + m[3][c];
    }
  });
  size_t none = 0;
  for (size_t d : dropped) none += d;
  if (none == 0) return 0;
  const size_t kept = keepRows(reinterpret_cast<char*>(scan.positions.data()), sizeof(glm::dvec3), keep, threads);
  scan.positions.resize(kept);
  if (scan.hasColors()) {
    keepRows(reinterpret_cast<char*>(scan.colors.data()), sizeof(glm::vec3), keep, threads);
    scan.colors.resize(kept);
  }
  for (Dimension& d : scan.dimensions.all()) keepRows(reinterpret_cast<char*>(d.bytes.data()), dimTypeSize(d.type), keep, threads);
  scan.dimensions.resize(kept);
  return none;
}

// The columns of a scan's rows from its first (at `offset`, 0-based line `line`): x y z, an
// intensity, r g b. Where its second and third rows agree with each other and not with the first,
// the first is the odd one (the CSV reader would blame the second); else the CSV reader names the
// first row unlike the first.
Result<std::vector<std::string>> rowColumns(const InputFile& file, uint64_t offset, uint64_t line, uint64_t rows) {
  Result<std::string> read = linesAt(file, offset, 3);
  if (!read) return read.error();
  const std::string_view text = *read;
  std::vector<std::string_view> lines;  // up to three rows, as far as the scan has them
  for (size_t pos = 0; lines.size() < std::min<uint64_t>(rows, 3) && pos <= text.size();) {
    const size_t nl = std::min(text.find('\n', pos), text.size());
    lines.push_back(text.substr(pos, nl - pos));
    pos = nl + 1;
  }
  // A blank or comment line is the CSV reader's to name (CsvReadOptions::rows_only).
  const auto width = [](std::string_view text_line) {
    const std::vector<std::string_view> fields = fieldsOf(text_line);
    return fields.empty() || fields.front().front() == '#' ? std::optional<size_t>() : fields.size();
  };
  std::vector<std::optional<size_t>> widths;
  for (std::string_view l : lines) widths.push_back(width(l));
  const std::optional<size_t> n = widths.empty() ? std::nullopt : widths[0];
  if (widths.size() == 3 && n && widths[1] && widths[1] == widths[2] && *widths[1] != *n)
    return Error{file.path() + ":" + std::to_string(line + 1) + ": " + countOf(*n, "field") + ", where the scan's next rows have " +
                 std::to_string(*widths[1]) + " (a PTX scan's rows are alike: x y z, then an intensity, r g b or both)"};
  size_t row = 0;  // the first row with a width
  while (row < widths.size() && !widths[row]) ++row;
  const size_t w = row < widths.size() ? *widths[row] : 3;
  if (w == 3) return std::vector<std::string>{"x", "y", "z"};
  if (w == 4) return std::vector<std::string>{"x", "y", "z", "intensity"};
  if (w == 6) return std::vector<std::string>{"x", "y", "z", "r", "g", "b"};
  if (w == 7) return std::vector<std::string>{"x", "y", "z", "intensity", "r", "g", "b"};
  return Error{file.path() + ":" + std::to_string(line + row + 1) + ": " + countOf(w, "field") +
               ", where a PTX row has x y z, then an intensity, r g b or both (3, 4, 6 or 7)"};
}

}  // namespace

Result<PointSet> readPtx(const InputFile& file, const CsvReadOptions& options) {
  const std::string& path = file.path();
  if (file.size() == 0) return Error{path + ": empty file"};
  if (!options.columns.empty())
    return Error{path + ": --columns is for CSV and text files; a PTX file's rows are x y z, an intensity and r g b",
                 ExitCode::kUsage};
  const unsigned threads = resolveThreads(options.threads);
  const uint64_t limit = options.max_memory != 0 ? options.max_memory : defaultMemoryLimit();
  Progress* progress = options.progress;
  if (progress) progress->start("indexing the lines of " + path, file.size());
  Result<LineIndex> index = LineIndex::build(file, threads, progress);
  if (!index) return index.error();
  if (progress) progress->finish();
  if (progress) progress->start("reading " + path, file.size());

  std::vector<NumberedScan> scans;
  uint64_t line = 0, offset = 0, no_echo = 0, rows_read = 0, held = 0, number = 0;
  {  // a UTF-8 byte order mark, as an editor may leave
    char bom[3] = {};
    Result<size_t> got = file.readAt(0, bom, 3);
    if (!got) return got.error();
    if (*got == 3 && std::memcmp(bom, "\xEF\xBB\xBF", 3) == 0) offset = 3;
  }
  while (true) {
    const uint64_t before = offset;
    if (Status s = passBlankLines(file, offset, line); !s) return s.error();
    if (offset >= file.size()) break;
    uint64_t data = 0;
    Result<ScanHeader> header = readScanHeader(file, offset, line, data);
    if (!header) return header.error();
    ++number;
    const uint64_t first_row_line = line + kHeaderLines;
    const std::string scan_name = "scan " + std::to_string(number) + " (line " + std::to_string(line + 1) + ")";
    if (header->columns != 0 && header->rows > (UINT64_MAX - first_row_line) / header->columns)
      return Error{path + ":" + std::to_string(line + 1) + ": " + scan_name + " declares " + std::to_string(header->columns) +
                   " x " + std::to_string(header->rows) + " points, more than any file holds"};
    const uint64_t points = header->columns * header->rows;
    const uint64_t end_line = first_row_line + points;
    if (end_line > index->lines())
      return Error{path + ":" + std::to_string(line + 1) + ": " + scan_name + " declares " +
                   std::to_string(header->columns) + " x " + std::to_string(header->rows) + " = " + std::to_string(points) +
                   " points, but the file has " + std::to_string(index->lines() - std::min(index->lines(), first_row_line)) +
                   " lines after its header (cut short?)"};
    Result<uint64_t> end = index->offsetOf(end_line);
    if (!end) return end.error();
    if (points > 0) {
      if (number > 65535)
        return Error{path + ":" + std::to_string(line + 1) + ": " + scan_name +
                     ": more scans than a point source id (1 to 65535) tells apart"};
      Result<std::vector<std::string>> columns = rowColumns(file, data, first_row_line, points);
      if (!columns) return columns.error();
      // The whole file's rows against the limit, not each scan's alone.
      const bool colors = columns->size() >= 6;
      const uint64_t row_bytes = sizeof(glm::dvec3) + (colors ? sizeof(glm::vec3) : 0) +
                                 sizeof(double) * (columns->size() % 3 == 1 ? 1 : 0);
      if (points > (UINT64_MAX - held) / row_bytes)
        return Error{path + ": " + std::to_string(rows_read + points) + " rows, more than memory holds", ExitCode::kResourceLimit};
      if (Status s = checkMemory(path + ": " + std::to_string(rows_read + points) + " rows of " + countOf(number, "scan"),
                                 held + points * row_bytes, limit);
          !s)
        return s.error();
      CsvReadOptions each = options;
      each.columns = std::move(*columns);
      each.first_line = first_row_line;
      each.rows_only = true;
      each.colors_0_255 = true;
      each.progress = nullptr;
      each.max_memory = limit - held;
      const InputFile rows = file.slice(data, *end - data);
      Result<PointSet> scan = readCsvRows(rows, each);
      if (!scan) {  // which scan, and how many rows it declares (a scan cut short fails at the next header)
        Error error = scan.error();
        error.message += " (in " + scan_name + ", which declares " + std::to_string(header->columns) + " x " +
                         std::to_string(header->rows) + " rows)";
        return error;
      }
      if (scan->size() != points)  // rows_only makes every line a row: the file changed
        return Error{path + ": the file changed while it was read (its lines moved); read it again once it is whole"};
      rows_read += points;
      no_echo += registerScan(*scan, *header, threads);
      held += heldBytes(*scan) + kScanBytes;
      scans.push_back({number, std::move(*scan)});
    }
    line = end_line;
    offset = *end;
    if (progress) progress->advance(offset - before);
  }
  if (progress) progress->finish();
  if (number == 0) return Error{path + ": no scan (a PTX file is scans of a ten-line header and their rows)"};
  if (no_echo > 0 && options.notices)
    options.notices->push_back(path + ": " + std::to_string(no_echo) + " of its " + std::to_string(rows_read) +
                               " rows are points with no echo (0 0 0 in the scanner's frame): left out");
  if (scans.empty()) {  // scans of no rows: an empty set, as an empty LAS file is
    PointSet none;
    none.z_axis = ZAxis::kPresent;
    return none;
  }
  if (scans.size() == 1) return std::move(scans.front().points);
  return joinScans(std::move(scans));
}

}  // namespace dpoint
