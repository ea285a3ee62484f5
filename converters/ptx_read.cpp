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
#include <array>
#include <cstring>
#include <optional>

#include "converters/csv.h"
#include "core/dimensions.h"
#include "core/parallel.h"
#include "core/text.h"

namespace dpoint {

bool isPtxPath(const std::string& path) { return lowerExtension(path) == ".ptx"; }

namespace {

constexpr size_t kIndexBlock = 8u << 20;
constexpr uint64_t kHeaderLines = 10;
// A header's ten lines of numbers, or a row: read this much at a time (a longer line is not PTX).
constexpr size_t kMaxPtxLine = 4096;

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

  // The byte where 0-based line `line` starts; the file's size for line lines().
  Result<uint64_t> offsetOf(uint64_t line) const {
    if (line == 0) return uint64_t{0};
    if (line >= lines_) return file_->size();
    // The line starts after the line-th line end, which lies in the block b where ends_[b] < line <= ends_[b + 1].
    const size_t b = static_cast<size_t>(std::lower_bound(ends_.begin() + 1, ends_.end(), line) - ends_.begin()) - 1;
    const uint64_t offset = uint64_t{b} * kIndexBlock;
    std::vector<char> buffer(static_cast<size_t>(std::min<uint64_t>(kIndexBlock, file_->size() - offset)));
    Result<size_t> got = file_->readAt(offset, buffer.data(), buffer.size());
    if (!got) return got.error();
    uint64_t wanted = line - ends_[b];
    for (size_t i = 0; i < *got; ++i)
      if (buffer[i] == '\n' && --wanted == 0) return offset + i + 1;
    return Error{file_->path() + ": the file changed while it was read (its lines moved); read it again once it is whole"};
  }

 private:
  explicit LineIndex(const InputFile& file) : file_(&file) {}
  const InputFile* file_;
  std::vector<uint64_t> ends_;  // ends_[b]: line ends before block b
  uint64_t lines_ = 0;
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

// A scan's header: the grid and the transformation (row-vector form: p' = [x y z 1] M).
struct ScanHeader {
  uint64_t columns = 0, rows = 0;
  std::array<std::array<double, 4>, 4> m{};
};

// The ten lines from `offset` (0-based line `line`); `text` gets them, and `data` the byte after them.
Result<ScanHeader> readScanHeader(const InputFile& file, uint64_t offset, uint64_t line, uint64_t& data) {
  const std::string& path = file.path();
  std::string text(static_cast<size_t>(std::min<uint64_t>(kHeaderLines * kMaxPtxLine, file.size() - offset)), '\0');
  Result<size_t> got = file.readAt(offset, text.data(), text.size());
  if (!got) return got.error();
  text.resize(*got);
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
    if (nl == std::string::npos && (text.size() - pos >= kMaxPtxLine || offset + text.size() < file.size()))
      return Error{at + "line longer than " + std::to_string(kMaxPtxLine) + " bytes where a PTX header has " + kWhat[k]};
    const std::string_view this_line(text.data() + pos, (nl == std::string::npos ? text.size() : nl) - pos);
    if (pos >= text.size() && nl == std::string::npos)
      return Error{at + "the file ends inside a scan's header, which has ten lines (here " + kWhat[k] + ")"};
    const std::vector<std::string_view> fields = fieldsOf(this_line);
    const size_t wanted = k < 2 ? 1 : k < 6 ? 3 : 4;
    const auto bad = [&](const std::string& why) {
      return Error{at + why + ": '" + printableExcerpt(std::string(this_line)) + "' where a PTX header has " + kWhat[k]};
    };
    if (fields.size() != wanted) return bad(std::to_string(fields.size()) + (fields.size() == 1 ? " field" : " fields"));
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

bool isIdentity(const std::array<std::array<double, 4>, 4>& m) {
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      if (m[r][c] != (r == c ? 1.0 : 0.0)) return false;
  return true;
}

constexpr size_t kRows = size_t{1} << 16;

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
  const bool identity = isIdentity(header.m);
  const auto& m = header.m;
  std::vector<size_t> dropped((n + kRows - 1) / kRows, 0);
  parallelFor(dropped.size(), threads, [&](size_t b, unsigned) {
    for (size_t i = b * kRows, end = std::min(n, i + kRows); i < end; ++i) {
      glm::dvec3& p = scan.positions[i];
      keep[i] = !(p.x == 0.0 && p.y == 0.0 && p.z == 0.0);
      dropped[b] += keep[i] ? 0 : 1;
      if (identity) continue;
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

// The columns of the first row at `offset` (line `line`): x y z, an intensity, r g b.
Result<std::vector<std::string>> rowColumns(const InputFile& file, uint64_t offset, uint64_t line) {
  std::string text(static_cast<size_t>(std::min<uint64_t>(kMaxPtxLine, file.size() - offset)), '\0');
  Result<size_t> got = file.readAt(offset, text.data(), text.size());
  if (!got) return got.error();
  text.resize(std::min(*got, text.find('\n')));
  const size_t n = fieldsOf(text).size();
  const std::string at = file.path() + ":" + std::to_string(line + 1) + ": ";
  if (n == 3) return std::vector<std::string>{"x", "y", "z"};
  if (n == 4) return std::vector<std::string>{"x", "y", "z", "intensity"};
  if (n == 6) return std::vector<std::string>{"x", "y", "z", "r", "g", "b"};
  if (n == 7) return std::vector<std::string>{"x", "y", "z", "intensity", "r", "g", "b"};
  return Error{at + std::to_string(n) + " fields, where a PTX row has x y z, then an intensity, r g b or both (3, 4, 6 or 7)"};
}

// The scans in order as one set: each point's scan (from 1) in point_source_id; a dimension of
// different types in different scans (an intensity of whole numbers in one, narrowed to integers)
// float64 in all; colours white for a scan without beside one with, and integers of one scale
// where every scan's are.
PointSet joinScans(std::vector<PointSet> scans, unsigned threads) {
  std::vector<std::pair<std::string, DimType>> types;
  for (const PointSet& scan : scans)
    for (const Dimension& d : scan.dimensions.all()) {
      auto it = std::find_if(types.begin(), types.end(), [&](const auto& t) { return t.first == d.name; });
      if (it == types.end()) types.emplace_back(d.name, d.type);
      else if (it->second != d.type) it->second = DimType::kF64;
    }
  uint16_t full = 0;
  for (const PointSet& scan : scans) full = std::max(full, scan.color_full_scale);
  PointSet out;
  out.z_axis = ZAxis::kPresent;
  for (size_t s = 0; s < scans.size(); ++s) {
    PointSet& scan = scans[s];
    for (Dimension& d : scan.dimensions.all()) {
      const DimType type = std::find_if(types.begin(), types.end(), [&](const auto& t) { return t.first == d.name; })->second;
      if (d.type == type) continue;
      Dimension wide(d.name, type, scan.size());
      for (size_t i = 0; i < scan.size(); ++i) wide.setValue(i, d.value(i));
      d = std::move(wide);
    }
    Dimension& source = scan.dimensions.append(dim::kPointSourceId, DimType::kU16, scan.size());
    for (size_t i = 0; i < scan.size(); ++i) source.setValue(i, static_cast<double>(s + 1));
    // Colours read as fractions beside integers: integers still where they are k / full.
    if (full != 0 && scan.hasColors() && scan.color_full_scale != full) {
      const ColorsOffGrid off = colorsOffGrid(scan.colors, full, threads);
      if (off.rounded != 0 || off.clamped != 0) full = 0;
    }
    appendPoints(out, scan);
    scan = PointSet();  // its memory back before the next is appended
  }
  out.color_full_scale = full;
  return out;
}

}  // namespace

Result<PointSet> readPtx(const InputFile& file, const CsvReadOptions& options) {
  const std::string& path = file.path();
  if (file.size() == 0) return Error{path + ": empty file"};
  if (!options.columns.empty())
    return Error{path + ": --columns is for CSV and text files; a PTX file's rows are x y z, an intensity and r g b",
                 ExitCode::kUsage};
  const unsigned threads = resolveThreads(options.threads);
  if (options.progress) options.progress->start("indexing the lines of " + path, file.size());
  Result<LineIndex> index = LineIndex::build(file, threads, options.progress);
  if (!index) return index.error();
  if (options.progress) options.progress->finish();

  std::vector<PointSet> scans;
  uint64_t line = 0, offset = 0, no_echo = 0, rows_read = 0;
  while (line < index->lines()) {
    // Blank lines after the last scan (or between scans) are passed over.
    {
      std::string text(static_cast<size_t>(std::min<uint64_t>(kMaxPtxLine, file.size() - offset)), '\0');
      Result<size_t> got = file.readAt(offset, text.data(), text.size());
      if (!got) return got.error();
      text.resize(*got);
      const size_t nl = text.find('\n');
      if (std::all_of(text.begin(), nl == std::string::npos ? text.end() : text.begin() + static_cast<ptrdiff_t>(nl),
                      isBlankChar) &&
          (nl != std::string::npos || offset + text.size() == file.size())) {
        ++line;
        offset = nl == std::string::npos ? file.size() : offset + nl + 1;
        continue;
      }
    }
    uint64_t data = 0;
    Result<ScanHeader> header = readScanHeader(file, offset, line, data);
    if (!header) return header.error();
    const uint64_t first_row_line = line + kHeaderLines;
    const std::string scan_name = "scan " + std::to_string(scans.size() + 1) + " (line " + std::to_string(line + 1) + ")";
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
      Result<std::vector<std::string>> columns = rowColumns(file, data, first_row_line);
      if (!columns) return columns.error();
      CsvReadOptions each = options;
      each.columns = std::move(*columns);
      each.first_line = first_row_line;
      const InputFile rows = file.slice(data, *end - data);
      Result<PointSet> scan = readCsvRows(rows, each);
      if (!scan) return scan.error();
      if (scan->size() != points)  // blank or comment lines among the rows
        return Error{path + ":" + std::to_string(line + 1) + ": " + scan_name + " declares " + std::to_string(points) +
                     " points, but " + std::to_string(scan->size()) + " of its " + std::to_string(points) +
                     " lines are rows (a PTX scan has no blank or comment lines)"};
      rows_read += points;
      no_echo += registerScan(*scan, *header, threads);
      scans.push_back(std::move(*scan));
    }
    line = end_line;
    offset = *end;
  }
  if (scans.empty()) return Error{path + ": no scan with points (a PTX file is scans of a ten-line header and rows)"};
  if (no_echo > 0 && options.notices)
    options.notices->push_back(path + ": " + std::to_string(no_echo) + " of its " + std::to_string(rows_read) +
                               " rows are points with no echo (0 0 0 in the scanner's frame): left out");
  if (scans.size() == 1) return std::move(scans.front());
  if (scans.size() > 65535)
    return Error{path + ": " + std::to_string(scans.size()) + " scans, more than a point source id (1 to 65535) tells apart"};
  return joinScans(std::move(scans), options.threads);
}

}  // namespace dpoint
