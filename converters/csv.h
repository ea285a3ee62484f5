// CSV point files: `x,y,z,r,g,b`, `x,y,z`, `x,y,r,g,b` or `x,y` (z = 0), with or without a header.
//
// Reading: LF or CRLF line ends, an optional UTF-8 BOM, spaces or tabs around fields, blank lines
// skipped. The first line decides the separator: semicolons where it has one (numbers may then
// have a decimal comma), else commas, else runs of spaces and tabs, as CloudCompare's ASCII export
// writes them; its `//X,Y,Z` header is read too. Header names in any case, with the common names
// of the axes (lon/lat/alt, E/N/H, easting/northing/elevation, …) and colours (red/green/blue). A header
// may name further columns after x,y,z or x,y,z,r,g,b (`x,y,z,intensity`): each is a dimension
// (double, or its known type where every value fits it; NaN allowed). A header with no rows after it is an empty set; a file without a header needs a
// row. PointSet::z_axis says whether the file had a z column. Numbers are parsed correctly rounded (fast_float): positions to double, colours to
// float. The file is read in blocks on all cores; every row goes to its preassigned index, so the
// result is the same for any thread count. Memory: the PointSet plus one block per thread; the
// set's size (from the line count) is checked against max_memory before it is allocated.
// Errors name the file, line, column and the bad text; the first error by line wins.
//
// Writing: doubles in shortest round-trip form (std::to_chars), or with `decimals` fixed digits
// after the point, rounded exactly like glibc printf("%.*f"). Colours as shortest floats.
// writeCsv writes a whole PointSet; CsvRowWriter (which writeCsv is built on) takes rows as they
// come, for writers that never hold the whole set (glTF input, converters/point_io.h).
#pragma once

#include <functional>
#include <span>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/input_file.h"
#include "core/point_set.h"
#include "core/progress.h"
#include "core/result.h"
#include "core/text.h"

namespace dpoint {

struct CsvReadOptions {
  unsigned threads = 0;          // 0: all cores
  bool allow_nonfinite = false;  // accept nan/inf values instead of rejecting them
  Progress* progress = nullptr;
  uint64_t max_memory = 0;       // bytes for the point set (--max-memory); 0: defaultMemoryLimit()
  // --columns: what each column holds, instead of the header's names or the count's layout: x, y, z,
  // r, g, b (red, green, blue), `-` to skip a column, any other name a dimension. A header line
  // is then skipped.
  std::vector<std::string> columns = {};
  // When not null, gets a line for what the reader could not keep as written (a column of integers
  // past 2^53 that also holds other values, read as doubles).
  std::vector<std::string>* notices = nullptr;
  // Tests: runs once the lines are counted, before they are parsed (to change the file in between).
  std::function<void()> between_passes = {};
  // Lines before the file's first in the messages' line numbers: a slice of a larger file (a PTX
  // scan's rows, InputFile::slice) names its lines as the file numbers them.
  uint64_t first_line = 0;
  // Every line is a row (a PTX scan's): with `columns`, no header line is passed over, and a
  // blank or comment line is an error naming it; a bad colour is named by its line too.
  bool rows_only = false;
  // Colours are whole numbers of 0 to 255, whatever the values (a PTX scan's): 1 is 1/255, and
  // 256 or 0.5 an error naming the row.
  bool colors_0_255 = false;
};

struct CsvWriteOptions {
  int decimals = -1;  // < 0: shortest round trip; else fixed digits after the point (0..40)
  unsigned threads = 0;
  Progress* progress = nullptr;
  // decimals is the input's coordinate step (LAS, lasStepDecimals): positions are written with
  // `decimals` digits and their trailing zeros trimmed (849087.70 → "849087.7"), colours in
  // shortest form. Ignored when decimals < 0.
  bool at_scale = false;
  // When not null, gets a line for each dimension written under another name (csvColumnNames).
  std::vector<std::string>* notices = nullptr;
};

Result<PointSet> readCsv(const std::string& path, const CsvReadOptions& options = {});
// The separator a written file gets: ' ' for a path ending .xyz, .txt or .asc (any case), else ','.
char csvSeparatorFor(const std::string& path);
// A path ending .pts (any case): Leica's PTS text, read and written by the CSV code.
bool isPtsPath(const std::string& path);
// The same from an opened file, or from bytes in memory (InputFile::fromMemory). A path ending
// .ptx is read by readPtx.
Result<PointSet> readCsv(const InputFile& file, const CsvReadOptions& options = {});
// The CSV reader itself, whatever the file's name (readPtx reads each scan's rows with it).
Result<PointSet> readCsvRows(const InputFile& file, const CsvReadOptions& options);

// A path ending .ptx (any case): Leica's PTX text, read by the CSV code (readPtx) and written by
// writeCsv as one scan.
bool isPtxPath(const std::string& path);
// Leica PTX (converters/ptx_read.cpp): scans, each a ten-line header (the grid's columns and
// rows, the scanner's registered position and axes, a 4x4 transformation in row-vector form, its
// fourth row the translation) and columns x rows rows of `x y z [intensity] [r g b]` in the
// scanner's frame. Each point is moved into the registered frame in double precision; a point
// with no echo (0 0 0) is left out, with a note counting them. Intensity is the dimension
// `intensity` as written (0..1 floats, float64), colours 0..255 integers; several scans are
// joined in order, each point's scan (from 1) in `point_source_id`, white for a scan without
// colours beside one with. Errors name the file and line. The line ends are counted once on all
// cores to place the scans; each scan's rows are then read as the CSV reader reads a file.
Result<PointSet> readPtx(const InputFile& file, const CsvReadOptions& options);

// Writes atomically (AtomicFile). Header `x,y` when the set has no z (PointSet::hasZ: a 2D
// source, or a set made in memory whose every z is +0.0), else `x,y,z`; `,r,g,b` when it has
// colours; then a column per dimension (integers as integers, floats in the shortest form of their
// width). Triangles are not stored in CSV.
Status writeCsv(const std::string& path, const PointSet& points, const CsvWriteOptions& options = {});

// The columns: `x,y` (planar: the set has no z, which is not written) or `x,y,z`, then `,r,g,b` when
// colors, then one column per dimension, named as the dimension.
struct CsvLayout {
  bool planar = false;
  bool colors = false;
  std::vector<std::string> dimensions;  // names; rows with dimensions are written by appendSet
  // ',' for .csv; ' ' for the text exports .xyz, .txt and .asc, whose header is then CloudCompare's
  // comment form `//x y z` (CsvRowWriter::create sets it from the path: csvSeparatorFor).
  char separator = ',';
  // Colours as integers of this full scale (255, 65535: PointSet::color_full_scale), 0 as floats 0..1.
  uint16_t color_full_scale = 0;
  // Leica's PTS (isPtsPath): the count of rows in place of the names, no renaming (the names are
  // not written), and the dimensions before the colours; writeCsv makes its layout (x y z,
  // intensity, r g b of 0..255).
  bool pts = false;
  // Leica's PTX (isPtxPath): a PTS layout of scans, each with its ten header lines (beginScan:
  // columns, the scan's rows; one row; the scanner at `offset`, its axes the world's, and the
  // translation `offset`), whose rows are the positions less `offset`, and whose rows carry an
  // intensity of 0 where the set has none (`zero_intensity`: CloudCompare refuses rows without
  // one). writeCsv makes its layout.
  bool ptx = false;
  glm::dvec3 offset{0.0};
  bool zero_intensity = false;
};

// The header names CsvRowWriter gives layout.dimensions (writableNames): none holding a separator
// (a comma, a semicolon, a space or a tab), a quote or a control character; none the reader takes
// for a position's or a colour's column (x, y, z, r, g, b in any case; red, green or blue among the
// first six columns); none twice. `renamed` gets a line for each name changed.
std::vector<std::string> csvColumnNames(const CsvLayout& layout, std::vector<std::string>* renamed);

// Rows appended in any number of calls give the same bytes as one writeCsv of all of them with
// the same layout: rows are formatted in chunks on all cores and written in order, so neither
// the split into calls nor the thread count shows in the output. Memory: a few chunks of rows
// and of text per thread. The file appears only at commit(); a writer destroyed before (an
// error mid-way) leaves nothing at the path (AtomicFile).
class CsvRowWriter {
 public:
  // Checks options.decimals, creates the output and writes the header. `rows`: the count to come,
  // for options.progress and for the free-space check (AtomicFile::checkSpace: at least two bytes
  // a value), so never more than will be written.
  static Result<CsvRowWriter> create(const std::string& path, CsvLayout layout, const CsvWriteOptions& options,
                                     uint64_t rows = 0);

  // colors: one per position when the layout has colours, else empty. Positions of a planar
  // layout must have z == +0.0 (z is not written).
  Status append(std::span<const glm::dvec3> positions, std::span<const glm::vec3> colors);
  // Every row of `points` (the layout's columns; before any append): what writeCsv writes. Its
  // dimensions are the layout's: all of them, or a PTS layout's intensity.
  Status appendSet(const PointSet& points);
  // Rows first … first + count - 1 of `points`, as appendSet writes them.
  Status appendRows(const PointSet& points, size_t first, size_t count);
  // A PTX layout: the next scan's header, `rows` points about `offset` (CsvLayout::ptx), whose rows
  // follow (appendRows).
  Status beginScan(uint64_t rows, const glm::dvec3& offset);
  // Writes the rows still held and moves the file into place.
  Status commit();

 private:
  CsvRowWriter(AtomicFile file, CsvLayout layout, const CsvWriteOptions& options);
  Status writeBatch(const glm::dvec3* positions, const glm::vec3* colors, size_t count,
                    const std::vector<const Dimension*>* dims = nullptr, size_t first = 0);
  Status flushPending();  // writes the rows held back for a whole batch

  AtomicFile file_;
  CsvLayout layout_;
  int decimals_;
  bool at_scale_;
  unsigned threads_;
  Progress* progress_;
  size_t batch_rows_;  // rows formatted in one parallel batch
  PositionArray pending_positions_;  // fewer than batch_rows_ rows from earlier calls
  std::vector<glm::vec3> pending_colors_;
  // One per chunk of a batch; grown without zeroing (std::string's resize zeroed 5% of a
  // PLY -> CSV conversion's time before each chunk's rows were formatted over it).
  std::vector<TextBuffer> texts_;
};

}  // namespace dpoint
