// CSV writer (CsvRowWriter, and writeCsv on top of it): rows are formatted in chunks on all
// cores and written in order.
//
// Shortest round-trip output is std::to_chars(double) (Ryu in libstdc++): the fewest digits that
// parse back to the same double, so CSV -> PointSet -> CSV is byte- and bit-identical.
// Fixed output is formatFixed (core/fixed_format.h): printf("%.*f") rounding, exactly, as glibc
// does: the exact binary value rounded half to even. Colours are floats: shortest float form, or their exact double
// value in fixed form (as the seed printed its double colours with %.15f).
#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>

#include "core/atomic_file.h"
#include "converters/csv.h"
#include "core/fixed_format.h"
#include "core/parallel.h"
#include "core/text.h"

namespace dpoint {
namespace {

constexpr size_t kRowsPerChunk = 1u << 16;
constexpr int kMaxDecimals = 100;
// DBL_MAX in fixed form has 309 integer digits; plus sign, point, decimals and a separator.
constexpr size_t kMaxFieldChars = fixedFormatMaxChars(kMaxDecimals) + 1;

// Value i of a dimension: integers as integers, floats in shortest round-trip form of their own
// width (a float32 intensity is written "0.1", which reads back as the same float).
char* dimensionValue(char* p, char* limit, const Dimension& d, size_t i) {
  std::to_chars_result r{};
  switch (d.type) {
    case DimType::kF32: r = std::to_chars(p, limit, d.get<float>(i)); break;
    case DimType::kF64: r = std::to_chars(p, limit, d.get<double>(i)); break;
    case DimType::kU64: r = std::to_chars(p, limit, d.get<uint64_t>(i)); break;
    case DimType::kI64: r = std::to_chars(p, limit, d.get<int64_t>(i)); break;
    default: r = std::to_chars(p, limit, static_cast<int64_t>(d.value(i))); break;
  }
  assert(r.ec == std::errc());
  return r.ptr;
}

// A coordinate as the rows write it: shortest round trip (decimals < 0), `decimals` fixed digits, or
// with at_scale (decimals ≥ 0) the value at the file's step: "849087.70" is written "849087.7",
// "12.00" "12".
char* formatCoordinate(char* p, char* limit, double v, int decimals, bool at_scale) {
  if (at_scale && std::isfinite(v)) {
    char* end = formatFixed(p, v, decimals);
    if (decimals == 0) return end;
    while (end[-1] == '0') --end;
    return end[-1] == '.' ? end - 1 : end;
  }
  if (decimals >= 0 && std::isfinite(v)) return formatFixed(p, v, decimals);
  std::to_chars_result r = decimals < 0 ? std::to_chars(p, limit, v)
                                        : std::to_chars(p, limit, v, std::chars_format::fixed, decimals);
  assert(r.ec == std::errc());
  return r.ptr;
}

class RowFormatter {
 public:
  RowFormatter(const CsvLayout& layout, int decimals, bool at_scale)
      : decimals_(decimals), at_scale_(at_scale && decimals >= 0), planar_(layout.planar), colors_(layout.colors),
        separator_(layout.separator), color_full_scale_(layout.color_full_scale), pts_(layout.pts),
        zero_intensity_(layout.zero_intensity), offset_(layout.offset),
        offset_any_(layout.offset != glm::dvec3(0.0)), dimension_names_(layout.dimensions) {}

  std::string header() const {
    std::vector<std::string> names = {"x", "y"};
    if (!planar_) names.push_back("z");
    if (colors_) names.insert(names.end(), {"r", "g", "b"});
    std::string h = separator_ == ' ' ? "//x" : "x";  // CloudCompare's comment header for text exports
    for (size_t k = 1; k < names.size(); ++k) {
      h += separator_;
      h += names[k];
    }
    for (const std::string& name : dimension_names_) {
      h += separator_;
      h += name;
    }
    return h + "\n";
  }

  // Formats `count` rows into out (replacing its content); colors is read only with a colour layout.
  // dims (one per name of the layout, or null without any) are read at rows first … first + count.
  void format(const glm::dvec3* positions, const glm::vec3* colors, size_t count, TextBuffer& out,
              const std::vector<const Dimension*>* dims = nullptr, size_t first = 0) const {
    const size_t fields = (planar_ ? 2u : 3u) + (colors_ ? 3u : 0u) + (dims ? dims->size() : 0u) + (zero_intensity_ ? 1u : 0u);
    const size_t row_max = fields * kMaxFieldChars;
    out.clear();
    out.reserve(count * fields * 24 + row_max);  // the shortest forms' size; grown only for long fixed-form rows
    for (size_t i = 0; i < count; ++i) {
      out.appendWith(row_max, [&](char* p, char* limit) {
        const glm::dvec3 v = offset_any_ ? positions[i] - offset_ : positions[i];
        p = number(p, limit, v.x);
        *p++ = separator_;
        p = number(p, limit, v.y);
        if (!planar_) {
          *p++ = separator_;
          p = number(p, limit, v.z);
        }
        const auto dimensions = [&] {
          if (dims)
            for (const Dimension* d : *dims) {
              *p++ = separator_;
              p = dimensionValue(p, limit, *d, first + i);
            }
        };
        if (pts_) dimensions();  // PTS: x y z intensity r g b
        if (zero_intensity_) {
          *p++ = separator_;
          *p++ = '0';
        }
        if (colors_) {
          const glm::vec3& c = colors[i];
          for (int k = 0; k < 3; ++k) {
            *p++ = separator_;
            p = color(p, limit, c[k]);
          }
        }
        if (!pts_) dimensions();
        *p++ = '\n';
        return p;
      });
    }
  }

 private:
  char* number(char* p, char* limit, double v) const { return formatCoordinate(p, limit, v, decimals_, at_scale_); }
  char* color(char* p, char* limit, float v) const {
    if (color_full_scale_) {  // the integers the colours were read as: 255 stays 255
      std::to_chars_result r = std::to_chars(p, limit, colorInteger(v, color_full_scale_));
      assert(r.ec == std::errc());
      return r.ptr;
    }
    if (decimals_ >= 0 && !at_scale_) return number(p, limit, static_cast<double>(v));
    std::to_chars_result r = std::to_chars(p, limit, v);
    assert(r.ec == std::errc());
    return r.ptr;
  }

  int decimals_;
  bool at_scale_;  // CsvWriteOptions::at_scale
  bool planar_;
  bool colors_;
  char separator_;
  uint16_t color_full_scale_;
  bool pts_;
  bool zero_intensity_;
  glm::dvec3 offset_;
  bool offset_any_;
  const std::vector<std::string>& dimension_names_;
};

// A PTX scan's ten header lines (one scan of `rows` points, as columns of one row each): the
// scanner's registered position `offset`, its axes the world's, and the transformation in row-vector
// form, the identity but for the translation `offset` (p' = [x y z 1] M).
std::string ptxHeader(uint64_t rows, const glm::dvec3& offset) {
  std::string t;
  for (int k = 0; k < 3; ++k) {
    char buffer[32];  // a whole number below 2^52
    const std::to_chars_result r = std::to_chars(buffer, buffer + sizeof buffer, offset[k], std::chars_format::fixed);
    assert(r.ec == std::errc());
    t += k ? " " : "";
    t.append(buffer, r.ptr);
  }
  return std::to_string(rows) + "\n" + (rows ? "1" : "0") + "\n" + t + "\n1 0 0\n0 1 0\n0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n" + t +
         " 1\n";
}

Status checkDecimals(int decimals) {
  if (decimals > kMaxDecimals)
    return Error{"--decimals " + std::to_string(decimals) + " is above the limit of " + std::to_string(kMaxDecimals),
                 ExitCode::kUsage};
  return okStatus();
}

}  // namespace

std::vector<std::string> csvColumnNames(const CsvLayout& layout, std::vector<std::string>* renamed) {
  const size_t first = (layout.planar ? 2 : 3) + (layout.colors ? 3 : 0);  // the first dimension's column
  return writableNames(
      layout.dimensions,
      [](char c) { return isSpaceOrControl(c) || c == ',' || c == ';' || c == '"'; },
      [&](const std::string& name, size_t k) {
        const std::string l = lowerAscii(name);
        if (l == "x" || l == "y" || l == "z" || l == "r" || l == "g" || l == "b") return true;
        return first + k < 6 && (l == "red" || l == "green" || l == "blue");
      },
      renamed);
}

Result<CsvRowWriter> CsvRowWriter::create(const std::string& path, CsvLayout layout,
                                          const CsvWriteOptions& options, uint64_t rows) {
  if (Status s = checkDecimals(options.decimals); !s) return s.error();
  Result<AtomicFile> file = AtomicFile::create(path);
  if (!file) return file.error();
  layout.separator = layout.pts ? ' ' : csvSeparatorFor(path);
  std::vector<std::string> renamed;
  if (!layout.pts) layout.dimensions = csvColumnNames(layout, &renamed);
  if (options.notices)
    for (const std::string& line : renamed)
      options.notices->push_back(path + ": " + line +
                                 " (a column's name holds no separator, and x, y, z, r, g and b name the position's and "
                                 "colour's columns)");
  CsvRowWriter writer(std::move(*file), layout, options);
  // PTX: each scan writes its own header (beginScan).
  const std::string header = layout.ptx   ? std::string()
                             : layout.pts ? std::to_string(rows) + "\n"
                                          : RowFormatter(layout, options.decimals, options.at_scale).header();
  // At least a digit and a separator a value: refused at once where the disk cannot hold even that.
  const uint64_t values = (layout.planar ? 2 : 3) + (layout.colors ? 3 : 0) + layout.dimensions.size() +
                          (layout.zero_intensity ? 1 : 0);
  if (Status s = writer.file_.checkSpace(header.size() + rows * values * AtomicFile::kLeastTextBytesPerValue); !s)
    return s.error();
  if (!header.empty())
    if (Status s = writer.file_.write(header); !s) return s.error();
  if (options.progress) options.progress->start("writing " + path, rows);
  return writer;
}

CsvRowWriter::CsvRowWriter(AtomicFile file, CsvLayout layout, const CsvWriteOptions& options)
    : file_(std::move(file)),
      layout_(layout),
      decimals_(options.decimals),
      at_scale_(options.at_scale),
      threads_(resolveThreads(options.threads)),
      progress_(options.progress) {
  // Chunks are formatted a batch at a time (a few per thread) and written in order, so memory
  // stays at a few megabytes per thread whatever the number of rows.
  texts_.resize(std::max<size_t>(1, 2 * size_t(threads_)));
  batch_rows_ = texts_.size() * kRowsPerChunk;
}

Status CsvRowWriter::writeBatch(const glm::dvec3* positions, const glm::vec3* colors, size_t count,
                                const std::vector<const Dimension*>* dims, size_t first) {
  assert(count <= batch_rows_);
  const RowFormatter formatter(layout_, decimals_, at_scale_);
  const size_t chunks = (count + kRowsPerChunk - 1) / kRowsPerChunk;
  parallelFor(chunks, threads_, [&](size_t k, unsigned) {
    const size_t begin = k * kRowsPerChunk;
    formatter.format(positions + begin, colors ? colors + begin : nullptr,
                     std::min(count, begin + kRowsPerChunk) - begin, texts_[k], dims, first + begin);
  });
  for (size_t k = 0; k < chunks; ++k) {
    if (Status s = file_.write(texts_[k].data(), texts_[k].size()); !s) return s;
  }
  if (progress_) progress_->advance(count);
  return okStatus();
}

Status CsvRowWriter::append(std::span<const glm::dvec3> positions, std::span<const glm::vec3> colors) {
  assert(colors.size() == (layout_.colors ? positions.size() : 0));
  assert(layout_.dimensions.empty());  // rows with dimensions come whole, through appendSet
  const size_t n = positions.size();
  const auto colorsAt = [&](size_t at) { return layout_.colors ? colors.data() + at : nullptr; };
  size_t at = 0;
  // Rows held from earlier calls are topped up to a full batch first: batches stay full (all
  // cores busy) however small the caller's blocks are.
  if (!pending_positions_.empty()) {
    at = std::min(n, batch_rows_ - pending_positions_.size());
    pending_positions_.insert(pending_positions_.end(), positions.begin(), positions.begin() + std::ptrdiff_t(at));
    if (layout_.colors)
      pending_colors_.insert(pending_colors_.end(), colors.begin(), colors.begin() + std::ptrdiff_t(at));
    if (pending_positions_.size() < batch_rows_) return okStatus();
    if (Status s = flushPending(); !s) return s;
  }
  // Whole batches straight from the caller's arrays.
  for (; n - at >= batch_rows_; at += batch_rows_)
    if (Status s = writeBatch(positions.data() + at, colorsAt(at), batch_rows_); !s) return s;
  pending_positions_.assign(positions.begin() + std::ptrdiff_t(at), positions.end());
  if (layout_.colors) pending_colors_.assign(colors.begin() + std::ptrdiff_t(at), colors.end());
  return okStatus();
}

Status CsvRowWriter::flushPending() {
  if (pending_positions_.empty()) return okStatus();
  Status s = writeBatch(pending_positions_.data(), layout_.colors ? pending_colors_.data() : nullptr,
                        pending_positions_.size());
  pending_positions_.clear();
  pending_colors_.clear();
  return s;
}

Status CsvRowWriter::beginScan(uint64_t rows, const glm::dvec3& offset) {
  assert(layout_.ptx && pending_positions_.empty());
  layout_.offset = offset;
  return file_.write(ptxHeader(rows, offset));
}

Status CsvRowWriter::appendSet(const PointSet& points) { return appendRows(points, 0, points.size()); }

Status CsvRowWriter::appendRows(const PointSet& points, size_t first, size_t count) {
  assert(pending_positions_.empty() && first <= points.size() && count <= points.size() - first);
  std::vector<const Dimension*> dims;
  if (!layout_.pts)
    for (const Dimension& d : points.dimensions.all()) dims.push_back(&d);
  else if (const Dimension* intensity = points.dimensions.find(dim::kIntensity); intensity && !layout_.zero_intensity)
    dims.push_back(intensity);
  assert(dims.size() == layout_.dimensions.size());
  for (size_t at = first, end = first + count; at < end; at += batch_rows_)
    if (Status s = writeBatch(points.positions.data() + at, layout_.colors ? points.colors.data() + at : nullptr,
                              std::min(batch_rows_, end - at), &dims, at);
        !s)
      return s;
  return okStatus();
}

Status CsvRowWriter::commit() {
  if (Status s = flushPending(); !s) return s;
  if (progress_) progress_->finish();
  return file_.commit();
}

namespace {

// Whether a PTX row of these coordinates (the point less the translation) reads as 0 0 0, which PTX
// readers take for a cell with no echo: as the rows format it (`decimals` < 0: shortest round
// trip, where only ±0 is; else fixed digits, where a value that rounds to zero is too).
bool zeroRow(const glm::dvec3& v, int decimals, bool at_scale) {
  for (int k = 0; k < 3; ++k) {
    if (v[k] == 0.0) continue;
    if (decimals < 0 || !std::isfinite(v[k]) || std::fabs(v[k]) >= 1.0) return false;
    char text[kMaxFieldChars];
    const char* end = formatCoordinate(text, text + sizeof text, v[k], decimals, at_scale);
    if (std::find_if(static_cast<const char*>(text), end, [](char c) { return c >= '1' && c <= '9'; }) != end) return false;
  }
  return true;
}

// PTX's translation for points [first, last): each axis's bounds centre, rounded to a whole unit,
// where every coordinate on it less that and added back is itself, bit for bit (so the rows, small
// numbers a reader may hold as float32, read back to the same doubles; -0 too); else 0 on that
// axis. A whole unit is a multiple of every coordinate's step below 2^52, so a coordinate within
// its own magnitude of the centre passes; one far from it (a point at 1e-9 in a set centred at 1e6)
// does not. None where a coordinate is not finite (a reader's matrix product makes inf · 0 NaN on
// the other axes). Where a point's row would read as no echo (zeroRow: a point on the translation,
// or rounded onto it), the translation one unit off on an axis where that is exact, if one is.
// `zero_rows` gets the count of such rows left.
glm::dvec3 ptxOffset(const PositionArray& positions, size_t first, size_t last, int decimals, bool at_scale,
                     unsigned threads, size_t& zero_rows) {
  bool nonfinite = false;
  const Box box = finiteBox(positions, first, last, threads, &nonfinite);
  glm::dvec3 offset(0.0);
  for (int k = 0; k < 3 && !nonfinite; ++k) {
    const double lo = box.min[k], hi = box.max[k];
    const double centre = std::nearbyint(lo / 2 + hi / 2);
    if (lo <= hi && std::fabs(centre) < 0x1p52) offset[k] = centre + 0.0;  // never -0
  }
  constexpr size_t kBlock = 1u << 16;
  const size_t blocks = (last - first + kBlock - 1) / kBlock;
  const unsigned workers = resolveThreads(threads);
  // Per axis, whether some coordinate does not come back through `t` bit for bit; and the rows
  // that would read as 0 0 0.
  const auto check = [&](const glm::dvec3& t, glm::ivec3& inexact) {
    std::vector<glm::ivec3> bad(workers, glm::ivec3(0));
    std::vector<size_t> zeros(workers, 0);
    parallelFor(blocks, workers, [&](size_t b, unsigned w) {
      for (size_t i = first + b * kBlock, end = std::min(last, i + kBlock); i < end; ++i) {
        const glm::dvec3& p = positions[i];
        for (int k = 0; k < 3; ++k)
          if (t[k] != 0.0 && std::bit_cast<uint64_t>((p[k] - t[k]) + t[k]) != std::bit_cast<uint64_t>(p[k]))
            bad[w][k] = 1;
        zeros[w] += zeroRow(p - t, decimals, at_scale);
      }
    });
    inexact = glm::ivec3(0);
    for (const glm::ivec3& axes : bad) inexact |= axes;
    size_t n = 0;
    for (size_t z : zeros) n += z;
    return n;
  };
  glm::ivec3 inexact(0);
  size_t zeros = check(offset, inexact);
  if (inexact != glm::ivec3(0)) {
    for (int k = 0; k < 3; ++k)
      if (inexact[k]) offset[k] = 0.0;
    zeros = check(offset, inexact);
  }
  for (int k = 0; k < 3 && zeros != 0 && !nonfinite; ++k)
    for (const double step : {1.0, -1.0}) {
      glm::dvec3 t = offset;
      t[k] += step;
      if (std::fabs(t[k]) >= 0x1p52) continue;
      glm::ivec3 off(0);
      const size_t left = check(t, off);
      if (off == glm::ivec3(0) && left < zeros) {
        offset = t;
        zeros = left;
        break;
      }
    }
  zero_rows = zeros;
  return offset;
}

// PTS (Leica Cyclone, FARO, CloudCompare): the point count, then a row per point, x y z, its
// intensity where the set has one, and r g b as 0-255 integers where it has colours. PTX
// (Leica's scans): a scan of the points of each point_source_id (pointSourceRuns), each with its own
// ptxOffset, each row x y z less it, an intensity (0 where the set has none) and r g b as PTS's.
// Neither row has room for other dimensions: they are not written.
Status writePtsOrPtx(const std::string& path, const PointSet& points, const CsvWriteOptions& options, bool ptx) {
  const char* format = ptx ? "PTX" : "PTS";
  const Dimension* intensity = points.dimensions.find(dim::kIntensity);
  CsvLayout layout{false, points.hasColors(), {}};  // z always, 0 for a 2D set
  layout.color_full_scale = 255;
  layout.pts = true;
  if (intensity) layout.dimensions.push_back(intensity->name);
  layout.ptx = ptx;
  layout.zero_intensity = ptx && !intensity;
  const std::vector<SourceRun> scans = ptx ? pointSourceRuns(points) : std::vector<SourceRun>{{0, points.size(), 0.0}};
  Result<CsvRowWriter> writer = CsvRowWriter::create(path, std::move(layout), options, points.size());
  if (!writer) return writer.error();
  size_t at_origin = 0;  // PTX rows of 0 0 0
  glm::dvec3 origin(0.0);  // the first such scan's
  if (ptx) {
    for (const auto& [first, end, id] : scans) {
      size_t here = 0;
      const glm::dvec3 offset = ptxOffset(points.positions, first, end, options.decimals,
                                          options.at_scale && options.decimals >= 0, options.threads, here);
      if (Status s = writer->beginScan(end - first, offset); !s) return s;
      if (Status s = writer->appendRows(points, first, end - first); !s) return s;
      if (here != 0 && at_origin == 0) origin = offset;
      at_origin += here;
    }
  } else if (Status s = writer->appendSet(points); !s) {
    return s;
  }
  if (Status s = writer->commit(); !s) return s;
  // What PTS and PTX cannot hold, said once the file is there.
  if (options.notices) {
    const Dimension* as_scans = scans.size() > 1 ? points.dimensions.find(dim::kPointSourceId) : nullptr;
    std::string dropped;
    for (const Dimension& d : points.dimensions.all())
      if (&d != intensity && &d != as_scans) dropped += (dropped.empty() ? "" : ", ") + d.name;
    if (!dropped.empty())
      options.notices->push_back(path + ": " + format + " holds x, y, z, intensity and r, g, b only: " + dropped +
                                 " left out");
    if (points.hasColors() && points.color_full_scale == 65535)
      options.notices->push_back(path + ": 16-bit colours written as 8-bit (" + format + " holds 0..255)");
    if (ptx && !intensity && points.size() != 0)
      options.notices->push_back(path + ": the set has no intensity: each row's is 0 (a PTX row carries one; "
                                        "CloudCompare refuses rows without)");
    if (at_origin != 0)
      options.notices->push_back(path + ": " + countOf(at_origin, "point") + " at " +
                                 (scans.size() == 1 ? "the scan's origin (" : "its scan's origin (the first at (") +
                                 formatNumber(origin.x) + ", " + formatNumber(origin.y) + ", " + formatNumber(origin.z) +
                                 (scans.size() == 1 ? ")" : "))") +
                                 (options.decimals >= 0 ? ", to the rows' " + countOf(static_cast<uint64_t>(options.decimals), "decimal") + "," : std::string()) +
                                 " written as 0 0 0, which PTX readers (dpoint's, CloudCompare's) take for a cell "
                                 "with no echo and leave out");
    // The reader numbers the scans 1, 2, … in point_source_id: said where the ids were others.
    bool renumbered = false;
    if (scans.size() > 1)
      for (size_t k = 0; k < scans.size(); ++k) renumbered = renumbered || scans[k].id != static_cast<double>(k + 1);
    if (renumbered)
      options.notices->push_back(path + ": point_source_id written as " + countOf(scans.size(), "scan") +
                                 ", one for each id in the set's order, which PTX readers number 1 to " +
                                 std::to_string(scans.size()) + " (its ids were " + formatNumber(scans[0].id) + ", " +
                                 formatNumber(scans[1].id) + (scans.size() > 2 ? ", …)" : ")"));
  }
  return okStatus();
}

}  // namespace

bool isPtsPath(const std::string& path) { return lowerExtension(path) == ".pts"; }

Status writeCsv(const std::string& path, const PointSet& points, const CsvWriteOptions& options) {
  if (Status s = checkDecimals(options.decimals); !s) return s;
  if (!points.colors.empty() && points.colors.size() != points.positions.size())
    return Error{"point set has " + std::to_string(points.colors.size()) + " colours for " +
                 std::to_string(points.positions.size()) + " points"};
  if (isPtsPath(path) || isPtxPath(path)) return writePtsOrPtx(path, points, options, isPtxPath(path));
  CsvLayout layout{!points.hasZ(), points.hasColors(), {}};
  // Integers where the colours came as integers from a text file or a PLY's 16-bit ones; a LAS
  // file's colours stay 0..1 values, as they always were in CSV.
  layout.color_full_scale = points.las ? 0 : points.color_full_scale;
  for (const Dimension& d : points.dimensions.all()) layout.dimensions.push_back(d.name);
  Result<CsvRowWriter> writer = CsvRowWriter::create(path, std::move(layout), options, points.size());
  if (!writer) return writer.error();
  if (Status s = writer->appendSet(points); !s) return s;
  return writer->commit();
}

char csvSeparatorFor(const std::string& path) {
  const std::string ext = lowerExtension(path);
  return ext == ".xyz" || ext == ".txt" || ext == ".asc" ? ' ' : ',';
}

}  // namespace dpoint
