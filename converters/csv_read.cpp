// CSV reader: two passes over fixed-size blocks, both on all cores.
//
// Pass 1 counts line ends per block, so every line's number (and so its row index) is known
// before parsing. Pass 2 parses each block's lines straight into the final, exactly sized
// arrays. A line belongs to the block in which it starts; a block reads past its end to finish
// its last line. Results therefore never depend on the thread count, and peak memory is the
// PointSet plus one block buffer per thread (no growth by doubling, no copy at the end).
#include <fast_float/fast_float.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>

#include "converters/csv.h"
#include "core/input_file.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "core/text.h"

namespace dpoint {

namespace {

// Colour columns hold floats 0..1, or integers 0..255 (or 0..65535) as spreadsheets and most point
// tools write them: where a value above 1 appears, every colour must be such an integer, and the set
// keeps the full scale (PointSet::color_full_scale), so 255,128,0 is written back as 255,128,0.
// `bytes`: every colour is a whole 0..255 value whatever the values (a PTX scan's). `rows_from`:
// with CsvReadOptions::rows_only, the line before the first row, so that a row is named by its line.
Status integerColors(const std::string& path, PointSet& points, bool always, bool bytes,
                     std::optional<uint64_t> rows_from, unsigned threads) {
  const auto at = [&](size_t i, int k) {
    return rows_from ? path + ":" + std::to_string(*rows_from + i + 1) + ": colour column " + std::to_string(k + 1) + ": "
                     : path + ": data row " + std::to_string(i + 1) + ", colour column " + std::to_string(k + 1) + ": ";
  };
  float largest = 0.0f;
  for (const glm::vec3& c : points.colors) largest = std::max({largest, c.r, c.g, c.b});
  if (!(largest > 1.0f) && !always && !bytes) {
    // Fractions 0..1: a negative one was clamped to 0 by every 8-bit writer in silence (a review finding).
    for (size_t i = 0; i < points.colors.size(); ++i)
      for (int k = 0; k < 3; ++k)
        if (points.colors[i][k] < 0.0f)
          return Error{at(i, k) + formatNumber(points.colors[i][k]) + " (colours as fractions are 0..1, as integers 0..255)"};
    return okStatus();
  }
  const float full = largest > 255.0f && !bytes ? 65535.0f : 255.0f;
  for (size_t i = 0; i < points.colors.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const float v = points.colors[i][k];
      if (!(v >= 0.0f && v <= full && v == std::floor(v)))
        return Error{at(i, k) + formatNumber(v) +
                     (bytes ? std::string(" (a colour here is a whole number of 0 to 255)")
                            : " among integer colours (values above 1 make every colour an integer 0.." + formatNumber(full) +
                                  "; colours as fractions are 0..1)")};
    }
  takeColorsAsIntegers(points, static_cast<uint16_t>(full), threads);
  return okStatus();
}


constexpr size_t kBlockSize = 8u << 20;
// Longest line accepted: a row of six fixed-format DBL_MAX values fits in about 2 KB, and one of a
// PCD feature of thousands of doubles (an FPFH is 33; a review made one of 6,000 that dpoint wrote
// and could not read back at 64 KiB) in a few hundred; anything longer is not a point row (and
// would otherwise make a block read unbounded).
constexpr size_t kMaxLineLength = 512u << 10;

// CsvReadOptions::rows_only's errors.
constexpr const char* kBlankRow = "a blank line where every line is a row";
constexpr const char* kCommentRow = "a comment line where every line is a row";

// The known layouts. 2D files written with colours have `x,y,r,g,b` (the writer's planar form),
// so that layout is read too.
enum class Known { kXy, kXyz, kXyRgb, kXyzRgb };
constexpr const char* kKnownText[] = {"x,y", "x,y,z", "x,y,r,g,b", "x,y,z,r,g,b"};

// What a row holds: one of the known layouts in its first columns, then, with a header only, any
// number of further columns, each a dimension (`x,y,z,intensity`). Fields are separated by
// commas, or by runs of spaces and tabs (CloudCompare's ASCII export).
struct Layout {
  Known known = Known::kXyz;
  int columns = 3;  // every row has exactly this many fields
  bool whitespace = false;
  // Without whitespace: ',' or ';' (the European spreadsheet export), where a number may then
  // have a decimal comma (1,5;2,25;3).
  char separator = ',';
  std::string text;  // the header's names, or the known layout's, for messages
  std::vector<std::string> dimensions;  // the further columns' names, as the header spells them
  // What each column holds (kRole*): by default the known layout's columns, then the dimensions
  // in order; a PTS file's intensity sits between z and the colours.
  std::vector<int> roles;
  bool integer_colors = false;  // colours are 0-255 whatever their values (PTS)
  // Header names taken as a known dimension's (knownSpelling): the name as spelled, and the known one.
  std::vector<std::pair<std::string, std::string>> renamed = {};
};
// A column's role: 0-2 x, y, z; 3-5 r, g, b; kRoleDimension + k the k-th dimension; kRoleSkip
// a column --columns says to pass over (`-`).
constexpr int kRoleDimension = 6, kRoleSkip = -1;
int positionColumns(Known known) { return known == Known::kXy || known == Known::kXyRgb ? 2 : 3; }
bool hasColors(Known known) { return known == Known::kXyRgb || known == Known::kXyzRgb; }
bool hasColorColumns(const Layout& layout) { return hasColors(layout.known); }

bool isBlank(char c) { return c == ' ' || c == '\t'; }

// The roles of the known layout's columns, then one for each dimension.
std::vector<int> defaultRoles(Known known, size_t dimensions) {
  std::vector<int> roles = {0, 1};
  if (positionColumns(known) == 3) roles.push_back(2);
  if (hasColors(known)) roles.insert(roles.end(), {3, 4, 5});
  for (size_t k = 0; k < dimensions; ++k) roles.push_back(kRoleDimension + static_cast<int>(k));
  return roles;
}

std::string excerpt(const char* begin, const char* end) {
  return printableExcerpt(std::string_view(begin, static_cast<size_t>(end - begin)));
}

// True when the decimal mantissa in [begin, end) has a non-zero digit: a value that parses to
// zero from such text has underflowed.
bool hasNonzeroMantissa(const char* begin, const char* end) {
  for (const char* p = begin; p < end; ++p) {
    if (*p == 'e' || *p == 'E') return false;
    if (*p >= '1' && *p <= '9') return true;
  }
  return false;
}

bool looksLikeInfinityText(const char* begin, const char* end) {
  if (begin < end && (*begin == '-' || *begin == '+')) ++begin;
  return end - begin >= 3 && (begin[0] == 'i' || begin[0] == 'I');
}

struct LineError {
  uint64_t line = 0;  // 1-based
  std::string message;
};

// Whether [begin, end) is an integer's text: an optional sign, then digits only.
bool isIntegerText(const char* begin, const char* end) {
  if (begin < end && (*begin == '-' || *begin == '+')) ++begin;
  return begin < end && std::all_of(begin, end, [](char c) { return c >= '0' && c <= '9'; });
}

// Attribute columns of integers past 2^53, which a double rounds (nanosecond time stamps, 64-bit
// ids: a review finding, 9007199254740993 was read as ...992). A field whose double is 2^53 or
// more is read again from its text as a 64-bit integer, into the column's `values_` (made at its
// first such field); a smaller one is its double, exact. The column becomes int64 (uint64 past
// 2^63) where every field is a 64-bit integer, else it stays double with a note.
class ExactColumns {
 public:
  static constexpr double kFirstInexact = 9007199254740992.0;  // 2^53: from here doubles skip integers

  // base_bytes: what the set needs without these columns, checked against max_memory with them.
  ExactColumns(size_t columns, size_t rows, uint64_t base_bytes, uint64_t max_memory)
      : rows_(rows), base_bytes_(base_bytes), max_memory_(max_memory), once_(new std::once_flag[columns]),
        values_(columns), not_integer_(new std::atomic<bool>[columns]()), refused_(new std::atomic<bool>[columns]()) {}

  // Row `row` of column k holds [begin, end), whose double is kFirstInexact or more.
  void read(size_t k, size_t row, const char* begin, const char* end) {
    if (!isIntegerText(begin, end)) {
      not_integer_[k].store(true, std::memory_order_relaxed);  // 1e20, inf, or a fraction past 2^53
      return;
    }
    std::call_once(once_[k], [&] {
      const uint64_t bytes = base_bytes_ + rows_ * sizeof(uint64_t) * (made_.fetch_add(1) + 1);
      if (checkMemory("", bytes, max_memory_)) values_[k].resize(rows_);
      else refused_[k] = true;
    });
    if (refused_[k].load(std::memory_order_relaxed)) return;
    if (*begin == '+') ++begin;
    std::from_chars_result got{};
    if (*begin == '-') {
      int64_t v = 0;
      got = std::from_chars(begin, end, v);
      values_[k][row] = static_cast<uint64_t>(v);
    } else {
      got = std::from_chars(begin, end, values_[k][row]);
    }
    if (got.ec != std::errc()) not_integer_[k].store(true, std::memory_order_relaxed);  // past 64 bits
  }

  // Makes each column read so int64 or uint64 where every value is a 64-bit integer, before the
  // rows of blank lines are closed up (`blank_rows`, passed over: a review finding, their unset
  // values were read); the others stay double, and `notices` says why.
  void apply(Dimensions& dimensions, const std::vector<std::vector<uint64_t>>& blank_rows, const std::string& path,
             std::vector<std::string>* notices) {
    for (size_t k = 0; k < values_.size(); ++k) {
      if (values_[k].empty() && !refused_[k]) continue;
      Dimension& d = dimensions.all()[k];
      const auto note = [&](const std::string& why) {
        if (notices)
          notices->push_back(path + ": column " + quotedExcerpt(d.name) +
                             " has integers past 2^53, read as the nearest double: " + why);
      };
      if (refused_[k]) {
        note("their 64-bit values need more memory than --max-memory allows");
        continue;
      }
      bool whole = !not_integer_[k], negative = false, above_int64 = false;
      double* doubles = reinterpret_cast<double*>(d.bytes.data());
      for (const auto& rows : blank_rows)
        for (const uint64_t row : rows) doubles[row] = 0.0;  // a row closed up after this
      std::vector<uint64_t>& exact = values_[k];
      for (size_t i = 0; i < rows_ && whole; ++i) {
        const double v = doubles[i];
        negative = negative || v < 0.0;
        if (std::fabs(v) >= kFirstInexact) {
          above_int64 = above_int64 || (v > 0.0 && exact[i] > static_cast<uint64_t>(std::numeric_limits<int64_t>::max()));
        } else if (v == std::trunc(v)) {  // false for NaN (an empty field)
          exact[i] = static_cast<uint64_t>(static_cast<int64_t>(v));
        } else {
          whole = false;
        }
      }
      if (!whole) {
        note("the column also holds fields that are no 64-bit integer (a fraction, an exponent such as 1e18, "
             "an empty field, nan or inf, or a number past 64 bits)");
      } else if (negative && above_int64) {
        note("the column holds values below 0 and above 2^63, which no 64-bit type holds");
      } else {
        d.type = above_int64 ? DimType::kU64 : DimType::kI64;
        std::memcpy(d.bytes.data(), exact.data(), rows_ * sizeof(uint64_t));
      }
      exact = {};
    }
  }

 private:
  size_t rows_;
  uint64_t base_bytes_, max_memory_;
  std::unique_ptr<std::once_flag[]> once_;
  std::vector<std::vector<uint64_t>> values_;  // per column: empty, or one value per row (two's complement)
  std::unique_ptr<std::atomic<bool>[]> not_integer_, refused_;
  std::atomic<uint64_t> made_{0};
};

// A field's number as the reader takes it: after a leading '+' (afterPlusSign), and with a decimal
// comma where fields are separated by semicolons ("1,5": the only comma a field can hold). The data
// rows and --columns' header test both read so.
template <typename T>
fast_float::from_chars_result parseField(const char* begin, const char* end, T& value, char separator) {
  begin = afterPlusSign(begin, end);
  const bool comma = separator == ';' && std::memchr(begin, ',', static_cast<size_t>(end - begin));
  return comma ? fast_float::from_chars_advanced(begin, end, value,
                                                 fast_float::parse_options{fast_float::chars_format::general, ','})
               : fast_float::from_chars(begin, end, value);
}

class LineParser {
 public:
  // dimensions: one column of doubles per further column of the layout.
  LineParser(const std::string& path, const Layout& layout, bool allow_nonfinite, std::vector<double*> dimensions,
             ExactColumns& exact)
      : path_(path), layout_(layout), allow_nonfinite_(allow_nonfinite), dimensions_(std::move(dimensions)),
        exact_(exact) {}

  // Parses one line (without its line end, '\r' already removed) of row `row`. Returns false on error.
  bool parse(const char* begin, const char* end, uint64_t line, uint64_t row, glm::dvec3& position,
             glm::vec3& color, LineError& error) const {
    const char* p = begin;
    double values[3] = {0.0, 0.0, 0.0};
    float colors[3] = {0.0f, 0.0f, 0.0f};
    int column = 0;
    while (true) {
      while (p < end && isBlank(*p)) ++p;
      if (layout_.whitespace && p == end) break;  // trailing blanks end the row
      const char* number_begin = p;
      const char* field_end = layout_.whitespace ? std::find_if(p, end, isBlank) : nextSeparator(p, end);
      ++column;
      if (column > layout_.columns) {
        error = {line, lineText(line) + countMessage(begin, end)};
        return false;
      }
      const char* number_end = field_end;
      while (number_end > number_begin && isBlank(number_end[-1])) --number_end;
      const int role = layout_.roles[static_cast<size_t>(column - 1)];
      const bool empty = number_begin == number_end;
      double* dimension = role >= kRoleDimension ? &dimensions_[static_cast<size_t>(role - kRoleDimension)][row] : nullptr;
      bool ok = true;
      if (role == kRoleSkip) {
        // passed over, empty or not
      } else if (dimension) {
        // An attribute's empty field is a missing value, NaN (pandas writes NaN so).
        if (empty) *dimension = std::numeric_limits<double>::quiet_NaN();
        else ok = parseNumber(number_begin, number_end, *dimension, line, column, error);
        if (ok && std::fabs(*dimension) >= ExactColumns::kFirstInexact)  // rare
          exact_.read(static_cast<size_t>(role - kRoleDimension), row, number_begin, number_end);
      } else if (empty) {  // a position's or a colour's
        error = {line, lineText(line) + "column " + std::to_string(column) + ": empty field"};
        return false;
      } else {
        ok = role < 3 ? parseNumber(number_begin, number_end, values[role], line, column, error)
                      : parseNumber(number_begin, number_end, colors[role - 3], line, column, error);
      }
      if (!ok) return false;
      p = field_end;
      if (p == end) break;
      if (!layout_.whitespace) ++p;  // the separator
    }
    if (column != layout_.columns) {
      error = {line, lineText(line) + countMessage(begin, end)};
      return false;
    }
    position = glm::dvec3(values[0], values[1], values[2]);
    color = glm::vec3(colors[0], colors[1], colors[2]);
    return true;
  }

 private:
  const char* nextSeparator(const char* p, const char* end) const {
    const char* at = static_cast<const char*>(std::memchr(p, layout_.separator, static_cast<size_t>(end - p)));
    return at ? at : end;
  }

  std::string lineText(uint64_t line) const { return path_ + ":" + std::to_string(line) + ": "; }

  std::string countMessage(const char* begin, const char* end) const {
    size_t fields = 0;
    if (layout_.whitespace) {
      for (const char* p = begin; p < end;) {
        p = std::find_if_not(p, end, isBlank);
        if (p == end) break;
        ++fields;
        p = std::find_if(p, end, isBlank);
      }
    } else {
      fields = static_cast<size_t>(std::count(begin, end, layout_.separator)) + 1;
    }
    return std::to_string(fields) + " columns, expected " + std::to_string(layout_.columns) + " (" + printableExcerpt(layout_.text) + ")";
  }

  template <typename T>
  bool parseNumber(const char* begin, const char* end, T& value, uint64_t line, int column,
                   LineError& error) const {
    const auto result = parseField(begin, end, value, layout_.separator);
    // The message is built only on failure: this runs for every number of the file.
    auto fail = [&](const std::string& why) {
      error = {line, lineText(line) + "column " + std::to_string(column) + ": '" + excerpt(begin, end) + "' " + why};
      return false;
    };
    const char* type = sizeof(T) == 8 ? "double" : "float";
    if (result.ec != std::errc() || result.ptr != end) return fail("is not a number");
    if (std::isinf(value) && !looksLikeInfinityText(begin, end)) return fail(std::string("is out of ") + type + " range");
    if (value == T(0) && hasNonzeroMantissa(begin, end))
      return fail(std::string("is out of ") + type + " range (underflows to zero)");
    if (!allow_nonfinite_ && !std::isfinite(value)) {
      // An attribute may be NaN (a missing GPS time) or infinite, as PLY, PCD, GLB and E57 take it
      // and dpoint's own CSV writes it (a review finding: `inf` written, then refused).
      if (layout_.roles[static_cast<size_t>(column - 1)] >= kRoleDimension) return true;
      return fail("is not a finite number (--allow-nonfinite accepts it)");
    }
    return true;
  }

  const std::string& path_;
  const Layout& layout_;
  bool allow_nonfinite_;
  std::vector<double*> dimensions_;
  ExactColumns& exact_;
};

// The first line's separator: ';' where it has one (a semicolon file's numbers may hold decimal
// commas), else ',' where it has one, else 0: runs of spaces and tabs.
char separatorOf(std::string_view line) {
  if (line.find(';') != std::string_view::npos) return ';';
  return line.find(',') != std::string_view::npos ? ',' : '\0';
}

// Splits the first line into trimmed fields, lower case unless `spelled`: at its separator
// (separatorOf), else at runs of spaces and tabs.
std::vector<std::string> splitHeader(std::string_view line, bool spelled = false) {
  std::vector<std::string> fields;
  auto add = [&](std::string_view field) {
    while (!field.empty() && isBlank(field.front())) field.remove_prefix(1);
    while (!field.empty() && isBlank(field.back())) field.remove_suffix(1);
    // A quoted name (R's write.csv: "x","y","z").
    if (field.size() >= 2 && field.front() == '"' && field.back() == '"') field = field.substr(1, field.size() - 2);
    fields.push_back(spelled ? std::string(field) : lowerAscii(std::string(field)));
  };
  const char separator = separatorOf(line);
  if (separator == '\0') {
    for (size_t start = line.find_first_not_of(" \t"); start != std::string_view::npos;) {
      const size_t stop = line.find_first_of(" \t", start);
      add(line.substr(start, stop == std::string_view::npos ? stop : stop - start));
      start = stop == std::string_view::npos ? stop : line.find_first_not_of(" \t", stop);
    }
    return fields;
  }
  for (const std::string& field : splitAt(line, separator)) add(field);
  return fields;
}

// A first field that starts with a letter (other than nan/inf) marks a header line; so does
// CloudCompare's `//X,Y,Z`.
bool isHeaderLine(const std::vector<std::string>& fields) {
  const std::string& first = fields.front();
  if (first.rfind("//", 0) == 0) return true;
  if (first.empty() || !std::isalpha(static_cast<unsigned char>(first[0]))) return false;
  return first.rfind("nan", 0) != 0 && first.rfind("inf", 0) != 0;
}

// The known dimension (core/dimensions.h) a further column's header name spells another way, or
// "": CloudCompare's `Intensity` and `scalar_Intensity`, PDAL's `ReturnNumber`, `GpsTime`,
// `ScanDirectionFlag` and `Infrared` (their text exports). A review found CloudCompare's
// `Intensity` and `Classification` written to LAS as extra bytes beside zeros in LAS's fields.
std::string knownSpelling(std::string_view name) {
  const auto folded = [](std::string_view text) {
    std::string out;
    for (char c : text)
      if (c != '_' && c != ' ') out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
  };
  std::string key = folded(name);
  if (key.size() > 6 && folded(name.substr(0, 7)) == "scalar") key.erase(0, 6);  // `scalar_` or `scalar `
  static const std::pair<std::string_view, std::string_view> kAliases[] = {
      {"scandirectionflag", "scan_direction"}, {"infrared", "nir"}};
  for (const auto& [alias, known] : kAliases)
    if (key == alias) return std::string(known);
  for (const KnownDimension& k : knownDimensions())
    if (key == folded(k.name)) return k.name;
  return "";
}

// A header names one of the known layouts, then, after x,y,z or x,y,z,r,g,b, optionally further
// columns whose names are none of x, y, z, r, g, b (so `x,y,z,r,g` stays an error rather than
// x,y,z and two extras).
Result<Layout> layoutFromHeader(const std::string& path, std::vector<std::string> fields,
                                std::vector<std::string> spelled, uint64_t line, std::string_view text,
                                char separator) {
  if (fields.front().rfind("//", 0) == 0) fields.front().erase(0, 2);
  if (fields.front().empty() && fields.size() > 1) {  // `// X Y Z`: the marker alone
    fields.erase(fields.begin());
    spelled.erase(spelled.begin());
  }
  // The names people give the known columns (any case): geographic and surveyors' axes in the
  // first three columns, colour words in the three after the position (columns 3-5, or 2-4 in 2D). Further columns keep their
  // names (a column `h` after x,y,z stays a dimension `h`).
  static const std::vector<std::pair<std::string_view, std::string_view>> kAxes = {
      {"lon", "x"}, {"long", "x"}, {"longitude", "x"}, {"e", "x"}, {"east", "x"}, {"easting", "x"},
      {"rechtswert", "x"}, {"lat", "y"}, {"latitude", "y"}, {"n", "y"}, {"north", "y"}, {"northing", "y"},
      {"hochwert", "y"},
      {"alt", "z"}, {"altitude", "z"}, {"h", "z"}, {"height", "z"}, {"elevation", "z"}, {"elev", "z"},
      {"h\xc3\xb6he", "z"}, {"hoehe", "z"}};
  static const std::vector<std::pair<std::string_view, std::string_view>> kColours = {
      {"red", "r"}, {"green", "g"}, {"blue", "b"}};
  for (size_t k = 0; k < fields.size() && k < 6; ++k) {
    if (k < 3)
      for (const auto& [name, known] : kAxes)
        if (fields[k] == name) fields[k] = known;
    if (k >= 2)  // colours follow x,y (2D) or x,y,z
      for (const auto& [name, known] : kColours)
        if (fields[k] == name) fields[k] = known;
  }
  auto known_name = [](const std::string& f) {
    return f == "x" || f == "y" || f == "z" || f == "r" || f == "g" || f == "b";
  };
  std::string joined;
  for (const std::string& f : fields) joined += (joined.empty() ? "" : ",") + f;
  for (Known known : {Known::kXyzRgb, Known::kXyRgb, Known::kXyz, Known::kXy}) {
    const std::string_view prefix = kKnownText[static_cast<int>(known)];
    const size_t count = static_cast<size_t>(std::count(prefix.begin(), prefix.end(), ',')) + 1;
    if (fields.size() < count || joined.compare(0, prefix.size(), prefix) != 0) continue;
    if (joined.size() > prefix.size() && joined[prefix.size()] != ',') continue;
    // Further columns only after z: `x,y,w` is more likely a misspelt z than a 2D set with an extra.
    if (fields.size() > count && (known == Known::kXy || known == Known::kXyRgb)) break;
    if (std::any_of(fields.begin() + std::ptrdiff_t(count), fields.end(), known_name)) break;
    Layout layout{known, static_cast<int>(fields.size()), separator == '\0', separator ? separator : ',', joined, {}, {}, false};
    for (size_t k = count; k < spelled.size(); ++k) {
      std::string name = spelled[k];
      // A known dimension spelt another way takes its name, where no column has that name already.
      if (!findKnownDimension(name)) {
        const std::string as_known = knownSpelling(name);
        if (!as_known.empty() && std::find(spelled.begin(), spelled.end(), as_known) == spelled.end() &&
            std::find(layout.dimensions.begin(), layout.dimensions.end(), as_known) == layout.dimensions.end()) {
          layout.renamed.emplace_back(name, as_known);
          name = as_known;
        }
      }
      if (name.empty())
        return Error{path + ":" + std::to_string(line) + ": column " + std::to_string(k + 1) + " has no name"};
      if (std::find(layout.dimensions.begin(), layout.dimensions.end(), name) != layout.dimensions.end())
        return Error{path + ":" + std::to_string(line) + ": column " + std::to_string(k + 1) + " '" +
                     printableExcerpt(name) + "' is named twice"};
      layout.dimensions.push_back(name);
    }
    layout.roles = defaultRoles(known, layout.dimensions.size());
    return layout;
  }
  const std::string split = separator == ';'   ? "split at semicolons"
                            : separator == ',' ? "split at commas"
                                               : "split at spaces and tabs";
  return Error{path + ":" + std::to_string(line) + ": header '" + excerpt(text.data(), text.data() + text.size()) +
               "' (" + split + ") is not one of x,y | x,y,z | x,y,r,g,b | x,y,z,r,g,b, or their names " +
               "(lon,lat,alt | E,N,H | red,green,blue); further columns may follow; --columns names each column "
               "instead (e.g. y,x,z or -,x,y,z)"};
}

Result<Layout> layoutFromColumns(const std::string& path, size_t columns, uint64_t line, char separator) {
  auto layout = [&](Known known) {
    return Layout{known, static_cast<int>(columns), separator == '\0', separator ? separator : ',',
                  kKnownText[static_cast<int>(known)], {}, defaultRoles(known, 0), false};
  };
  if (columns == 2) return layout(Known::kXy);
  if (columns == 3) return layout(Known::kXyz);
  if (columns == 5) return layout(Known::kXyRgb);
  if (columns == 6) return layout(Known::kXyzRgb);
  return Error{path + ":" + std::to_string(line) + ": " + std::to_string(columns) +
               " columns without a header; expected 2 (x,y), 3 (x,y,z), 5 (x,y,r,g,b) or 6 (x,y,z,r,g,b); "
               "--columns names each, e.g. x,y,z,intensity"};
}

// A PTS file's rows (Leica Cyclone, FARO, CloudCompare): x y z, x y z intensity, x y z r g b or
// x y z intensity r g b, the colours 0-255.
Result<Layout> layoutFromPtsColumns(const std::string& path, size_t columns, uint64_t line, char separator) {
  Layout layout{Known::kXyz, static_cast<int>(columns), separator == '\0', separator ? separator : ',', "x y z", {}, {}, true};
  if (columns == 3 || columns == 4) layout.known = Known::kXyz;
  else if (columns == 6 || columns == 7) layout.known = Known::kXyzRgb;
  else
    return Error{path + ":" + std::to_string(line) + ": " + std::to_string(columns) +
                 " columns in a PTS row; expected 3 (x y z), 4 (x y z intensity), 6 (x y z r g b) or 7 (x y z intensity r g b)"};
  if (columns == 4 || columns == 7) layout.dimensions = {"intensity"};
  layout.roles = columns == 3 ? std::vector<int>{0, 1, 2}
                 : columns == 4 ? std::vector<int>{0, 1, 2, kRoleDimension}
                 : columns == 6 ? std::vector<int>{0, 1, 2, 3, 4, 5}
                                : std::vector<int>{0, 1, 2, kRoleDimension, 3, 4, 5};
  layout.text = columns == 3 ? "x y z" : columns == 4 ? "x y z intensity" : columns == 6 ? "x y z r g b" : "x y z intensity r g b";
  return layout;
}

// The layout --columns names (CsvReadOptions::columns).
Result<Layout> layoutFromNames(const std::vector<std::string>& names, char separator) {
  Layout layout{Known::kXyz, static_cast<int>(names.size()), separator == '\0', separator ? separator : ',', "", {}, {}, false};
  int seen[6] = {0, 0, 0, 0, 0, 0};
  for (const std::string& spelled : names) {
    std::string name = lowerAscii(spelled);
    if (name == "red") name = "r";
    if (name == "green") name = "g";
    if (name == "blue") name = "b";
    layout.text += (layout.text.empty() ? "" : ",") + spelled;
    const size_t known = std::string_view("xyzrgb").find(name.size() == 1 ? name[0] : '?');
    if (name == "-") {
      layout.roles.push_back(kRoleSkip);
    } else if (name.size() == 1 && known != std::string_view::npos) {
      if (seen[known]++)
        return Error{"--columns " + printableExcerpt(spelled) + ": named twice", ExitCode::kUsage};
      layout.roles.push_back(static_cast<int>(known));
    } else if (name.empty()) {
      return Error{"--columns: an empty name (use - to skip a column)", ExitCode::kUsage};
    } else {
      if (std::find(layout.dimensions.begin(), layout.dimensions.end(), spelled) != layout.dimensions.end())
        return Error{"--columns " + printableExcerpt(spelled) + ": named twice", ExitCode::kUsage};
      layout.roles.push_back(kRoleDimension + static_cast<int>(layout.dimensions.size()));
      layout.dimensions.push_back(spelled);
    }
  }
  const int colours = seen[3] + seen[4] + seen[5];
  if (!seen[0] || !seen[1])
    return Error{"--columns " + layout.text + ": names no x or no y (x,y[,z][,r,g,b], - to skip, others are dimensions)",
                 ExitCode::kUsage};
  if (colours != 0 && colours != 3)
    return Error{"--columns " + layout.text + ": colours need all of r, g and b", ExitCode::kUsage};
  layout.known = seen[2] ? (colours ? Known::kXyzRgb : Known::kXyz) : (colours ? Known::kXyRgb : Known::kXy);
  return layout;
}

// Whether a field of the first line reads as a number, as a data row's does (parseField).
bool isNumberField(std::string_view field, char separator) {
  double value = 0.0;
  const char* end = field.data() + field.size();
  const auto result = parseField(field.data(), end, value, separator);
  return result.ec == std::errc() && result.ptr == end;
}

// With --columns, a first line is a header where a column given as x, y or z does not hold a
// number (a row whose skipped first column is a label, `pt1,1,2,3`, is data: a review finding).
bool isNamedLine(const std::vector<std::string>& fields, const Layout& layout, char separator) {
  for (size_t k = 0; k < fields.size() && k < layout.roles.size(); ++k)
    if (layout.roles[k] >= 0 && layout.roles[k] < 3 && !isNumberField(fields[k], separator)) return true;
  return false;
}

// A line that is one whole number: a PTS file's point count.
bool isCountLine(const std::vector<std::string>& fields) {
  return fields.size() == 1 && !fields[0].empty() &&
         std::all_of(fields[0].begin(), fields[0].end(), [](char c) { return c >= '0' && c <= '9'; });
}

struct Header {
  Layout layout;
  uint64_t data_offset = 0;     // byte where the first data line (or blank lines) start
  uint64_t first_data_line = 0; // 0-based line index at data_offset
  bool named = false;           // the first line is a header: with no rows after it, the set is empty
  // A PTS file's count line: the points it declares, and its 1-based line number.
  std::optional<uint64_t> declared;
  uint64_t declared_line = 0;
};

// Finds the layout from the first non-blank line, skipping a UTF-8 BOM.
Result<Header> readHeader(const InputFile& file, const std::vector<std::string>& columns, uint64_t first_line,
                          bool rows_only) {
  std::string head(std::min<uint64_t>(file.size(), kMaxLineLength + 4), '\0');
  Result<size_t> got = file.readAt(0, head.data(), head.size());
  if (!got) return got.error();
  head.resize(*got);
  size_t pos = head.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;
  uint64_t line = first_line;
  const bool pts = isPtsPath(file.path());
  bool counted = false;
  std::optional<uint64_t> declared;
  uint64_t declared_line = 0;
  while (true) {
    if (pos >= head.size()) {
      if (head.size() == file.size() && declared == uint64_t{0}) {  // a PTS file of no points: its count line, 0
        Header header;
        header.layout = *layoutFromPtsColumns(file.path(), 3, line, ' ');
        header.data_offset = file.size();
        header.first_data_line = line;
        header.named = true;
        header.declared = declared;
        header.declared_line = declared_line;
        return header;
      }
      if (head.size() == file.size()) return Error{file.path() + ": no data rows"};
      return Error{file.path() + ":" + std::to_string(line + 1) + ": line longer than " +
                   std::to_string(kMaxLineLength) + " bytes"};
    }
    size_t nl = head.find('\n', pos);
    if (nl == std::string::npos) {
      if (head.size() < file.size())
        return Error{file.path() + ":" + std::to_string(line + 1) + ": line longer than " +
                     std::to_string(kMaxLineLength) + " bytes"};
      nl = head.size();
    }
    std::string_view text(head.data() + pos, nl - pos);
    if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
    if (text.find_first_not_of(" \t") == std::string_view::npos) {  // blank line before any data
      if (rows_only) return Error{file.path() + ":" + std::to_string(line + 1) + ": " + kBlankRow};
      pos = nl + 1;
      ++line;
      continue;
    }
    if (text.find('\0') != std::string_view::npos)
      return Error{file.path() + ":" + std::to_string(line + 1) + ": binary data, not CSV text ('" +
                   excerpt(text.data(), text.data() + text.size()) + "')"};
    if (text.find('\r') != std::string_view::npos)
      return Error{file.path() + ":" + std::to_string(line + 1) +
                   ": carriage returns inside a line: the file's lines end with CR alone (old Mac text); "
                   "convert them to LF or CR LF"};
    std::vector<std::string> fields = splitHeader(text);
    const char separator = separatorOf(text);
    if (pts && !counted && isCountLine(fields)) {  // the count line before a PTS file's rows
      counted = true;
      uint64_t n = 0;
      if (!parseDecimalU64(fields[0], n))
        return Error{file.path() + ":" + std::to_string(line + 1) + ": the count line " + printableExcerpt(fields[0]) +
                     " is 2^64 points or more"};
      declared = n, declared_line = line + 1;
      pos = nl + 1;
      ++line;
      continue;
    }
    Header header;
    header.declared = declared;
    header.declared_line = declared_line;
    // Where the rows start: after this line when it names the columns, else on it.
    const auto dataFrom = [&](bool named) {
      header.data_offset = named ? std::min<uint64_t>(nl + 1, file.size()) : pos;
      header.first_data_line = named ? line + 1 : line;
      header.named = named;
    };
    const size_t marker = text.find_first_not_of(" \t");
    if (text[marker] == '#' && rows_only) return Error{file.path() + ":" + std::to_string(line + 1) + ": " + kCommentRow};
    if (text[marker] == '#') {
      // A comment (numpy's savetxt writes its header as `# x,y,z`): the header where what follows
      // the '#' names the columns, else passed over.
      const std::string_view named = text.substr(marker + 1);
      std::vector<std::string> names = splitHeader(named);
      if (columns.empty() && !names.empty() && isHeaderLine(names)) {
        Result<Layout> layout = layoutFromHeader(file.path(), std::move(names), splitHeader(named, true), line + 1,
                                                 named, separatorOf(named));
        if (layout) {
          header.layout = *layout;
          dataFrom(true);
          return header;
        }
      }
      pos = nl + 1;
      ++line;
      continue;
    }
    if (!columns.empty()) {  // --columns: the names are given; a header line is passed over
      Result<Layout> layout = layoutFromNames(columns, separator);
      if (!layout) return layout.error();
      header.layout = *layout;
      dataFrom(!rows_only && isNamedLine(fields, header.layout, separator));
      return header;
    }
    // pandas' to_csv writes its index first, in a column without a name (`,x,y,z`): passed over.
    const bool index_column = separator != '\0' && fields.size() > 1 && fields.front().empty() &&
                              isHeaderLine(std::vector<std::string>(fields.begin() + 1, fields.end()));
    if (isHeaderLine(fields) || index_column) {
      std::vector<std::string> spelled = splitHeader(text, true);
      if (index_column) fields.erase(fields.begin()), spelled.erase(spelled.begin());
      Result<Layout> layout = layoutFromHeader(file.path(), std::move(fields), std::move(spelled), line + 1, text, separator);
      if (!layout) return layout.error();
      if (index_column) {
        layout->roles.insert(layout->roles.begin(), kRoleSkip);
        ++layout->columns;
        layout->text = "," + layout->text;
      }
      header.layout = *layout;
      dataFrom(true);  // a header only: an empty set
    } else {
      Result<Layout> layout = pts ? layoutFromPtsColumns(file.path(), fields.size(), line + 1, separator)
                                  : layoutFromColumns(file.path(), fields.size(), line + 1, separator);
      if (!layout) return layout.error();
      header.layout = *layout;
      dataFrom(false);
    }
    return header;
  }
}

// Whether text that parsed to `v` fits `type`. A float32 dimension written in its shortest form
// ("0.12345679") parses to the double nearest that text, not to the float: it fits when that is
// the float's own shortest text (a column parsed as float rounded 0.123456789012345 to float32).
bool textFits(DimType type, double v) {
  if (dimensionHolds(type, v)) return true;
  if (type != DimType::kF32) return false;
  char text[32];
  const auto written = std::to_chars(text, text + sizeof text, static_cast<float>(v));
  double back = 0.0;
  fast_float::from_chars(text, written.ptr, back);
  return back == v;
}

// A column named as a known dimension (core/dimensions.h) takes its type when every value fits it
// exactly (an intensity of whole numbers 0-65535 becomes uint16); any other stays double.
void narrowDimensions(Dimensions& dimensions, unsigned threads) {
  for (Dimension& d : dimensions.all()) {
    const KnownDimension* known = findKnownDimension(d.name);
    if (!known || known->type == DimType::kF64) continue;
    Dimension narrow(d.name, known->type, d.size());
    std::atomic<bool> fits{true};
    const size_t n = d.size(), block = 1u << 16;
    parallelFor((n + block - 1) / block, threads, [&](size_t b, unsigned) {
      for (size_t i = b * block; i < std::min(n, (b + 1) * block) && fits.load(std::memory_order_relaxed); ++i) {
        const double v = d.get<double>(i);
        if (!textFits(known->type, v)) {
          fits = false;
          return;
        }
        narrow.setValue(i, v);
      }
    });
    if (fits) d = std::move(narrow);
  }
}

}  // namespace

Result<PointSet> readCsv(const std::string& path, const CsvReadOptions& options) {
  Result<InputFile> opened = InputFile::open(path);
  if (!opened) return opened.error();
  return readCsv(*opened, options);
}

Result<PointSet> readCsv(const InputFile& file, const CsvReadOptions& options) {
  return isPtxPath(file.path()) ? readPtx(file, options) : readCsvRows(file, options);
}

Result<PointSet> readCsvRows(const InputFile& file, const CsvReadOptions& options) {
  const std::string& path = file.path();
  if (file.size() == 0) return Error{path + ": empty file"};
  Result<Header> header_result = readHeader(file, options.columns, options.first_line, options.rows_only);
  if (!header_result) return header_result.error();
  const Header header = *header_result;
  const Layout& layout = header.layout;
  PointSet points;
  points.z_axis = positionColumns(layout.known) == 3 ? ZAxis::kPresent : ZAxis::kAbsent;
  if (header.data_offset >= file.size()) {  // a header and nothing after it
    for (const std::string& name : layout.dimensions) {
      const KnownDimension* known = findKnownDimension(name);
      points.dimensions.append(name, known ? known->type : DimType::kF64, 0);
    }
    return points;
  }

  const uint64_t begin = header.data_offset, size = file.size();
  const size_t blocks = static_cast<size_t>((size - begin + kBlockSize - 1) / kBlockSize);
  const unsigned threads = resolveThreads(options.threads);
  if (options.progress) options.progress->start("reading " + path, 2 * (size - begin));

  // Pass 1: line ends per block.
  std::vector<uint64_t> newlines(blocks + 1, 0);
  std::vector<char> block_last(blocks, 0);  // each block's last byte, which decides where the next block's first line starts
  std::vector<std::optional<Error>> io_errors(blocks);
  {
    std::vector<std::vector<char>> buffers(threads);
    parallelFor(blocks, threads, [&](size_t b, unsigned worker) {
      std::vector<char>& buffer = buffers[worker];
      uint64_t offset = begin + b * kBlockSize;
      // The block's own length: a small file costs a small buffer, not a zeroed 8 MiB one.
      buffer.resize(static_cast<size_t>(std::min<uint64_t>(kBlockSize, size - offset)));
      Result<size_t> got = file.readAt(offset, buffer.data(), buffer.size());
      if (!got) {
        io_errors[b] = got.error();
        return;
      }
      newlines[b + 1] = static_cast<uint64_t>(std::count(buffer.data(), buffer.data() + *got, '\n'));
      if (*got > 0) block_last[b] = buffer[*got - 1];
      if (options.progress) options.progress->advance(*got);
    });
  }
  for (const auto& e : io_errors)
    if (e) return *e;
  for (size_t b = 0; b < blocks; ++b) newlines[b + 1] += newlines[b];

  // Lines from the data offset on: every newline ends one, plus a last line without a newline.
  const uint64_t lines = newlines[blocks] + (block_last.back() != '\n' ? 1 : 0);
  if (options.between_passes) options.between_passes();

  // Every line may be a row: a file of short lines (or of blank ones) asks for 24-36 bytes of
  // point set per 2-4 bytes of file, so the arrays are checked before they are made.
  const uint64_t row_bytes =
      sizeof(glm::dvec3) + (hasColorColumns(layout) ? sizeof(glm::vec3) : 0) + sizeof(double) * layout.dimensions.size();
  if (Status s = checkMemory(path + ": " + std::to_string(lines) + " lines", lines * row_bytes, options.max_memory); !s)
    return s.error();
  resizePrefaulted(points.positions, static_cast<size_t>(lines), threads);
  if (hasColorColumns(layout)) resizePrefaulted(points.colors, static_cast<size_t>(lines), threads);
  // Further columns are read as doubles, then narrowed to their known type where every value fits
  // it (narrowDimensions).
  std::vector<double*> columns;
  for (const std::string& name : layout.dimensions) {
    // Unset: a data row parses every column (or the read fails); a blank line's row is closed up below.
    Dimension& d = points.dimensions.appendUnset(name, DimType::kF64, static_cast<size_t>(lines));
    columns.push_back(reinterpret_cast<double*>(d.bytes.data()));
  }

  // Pass 2: parse. The first error by line number wins, whatever the thread count.
  ExactColumns exact(columns.size(), static_cast<size_t>(lines), lines * row_bytes, options.max_memory);
  const LineParser parser(path, layout, options.allow_nonfinite, columns, exact);
  const bool has_colors = hasColorColumns(layout);
  std::mutex error_mutex;
  std::optional<LineError> first_error;
  std::atomic<uint64_t> error_line{UINT64_MAX};
  std::vector<std::vector<uint64_t>> blank_rows(blocks);
  std::vector<std::vector<char>> buffers(threads);
  parallelFor(blocks, threads, [&](size_t b, unsigned worker) {
    const uint64_t block_start = begin + b * kBlockSize;
    const uint64_t block_end = std::min<uint64_t>(block_start + kBlockSize, size);
    uint64_t row = newlines[b];  // line index (relative to the data start) of the line at block_start
    if (header.first_data_line + row + 1 > error_line.load()) return;
    // Read one byte before (to know whether a line starts at block_start) and enough after.
    const uint64_t read_start = block_start == begin ? block_start : block_start - 1;
    const uint64_t read_end = std::min<uint64_t>(block_end + kMaxLineLength + 1, size);
    std::vector<char>& buffer = buffers[worker];
    buffer.resize(static_cast<size_t>(read_end - read_start));
    Result<size_t> got = file.readAt(read_start, buffer.data(), buffer.size());
    auto fail = [&](LineError e) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (!first_error || e.line < first_error->line) {
        error_line = e.line;
        first_error = std::move(e);
      }
    };
    if (!got) {
      fail({header.first_data_line + row + 1, got.error().message});
      return;
    }
    const char* data = buffer.data();
    const char* stop = data + (block_end - read_start);  // lines must start before this
    const char* end = data + *got;
    // The rows were sized and numbered from pass 1's count: a file that changed since (cut short,
    // or its lines moved) would leave rows unset or number them past the arrays, so it is refused.
    // A line's row comes from its block's line ends alone, and which block a line at a boundary
    // belongs to from the byte before it: both as pass 1 saw them, or the block refuses the file.
    if (*got != buffer.size() ||
        static_cast<uint64_t>(std::count(data + (block_start - read_start), stop, '\n')) != newlines[b + 1] - newlines[b] ||
        stop[-1] != block_last[b] || (read_start != block_start && data[0] != block_last[b - 1])) {
      fail({header.first_data_line + row + 1,
            path + ": the file changed while it was read (its lines are not the ones counted before reading "
                   "them); read it again once it is whole"});
      return;
    }
    const char* p = data;
    if (read_start != block_start) {
      ++p;
      if (data[0] != '\n') {  // the line at block_start began in the previous block
        const char* nl = static_cast<const char*>(std::memchr(p, '\n', static_cast<size_t>(stop - p)));
        if (!nl) return;  // no line starts in this block
        p = nl + 1;
        ++row;
      }
    }
    LineError error;
    glm::vec3 scratch_color;
    while (p < stop) {
      const uint64_t line_number = header.first_data_line + row + 1;
      const size_t window = static_cast<size_t>(std::min<ptrdiff_t>(end - p, static_cast<ptrdiff_t>(kMaxLineLength) + 1));
      const char* nl = static_cast<const char*>(std::memchr(p, '\n', window));
      const char* line_end = nl ? nl : end;
      if (static_cast<size_t>(line_end - p) > kMaxLineLength) {
        fail({line_number, path + ":" + std::to_string(line_number) + ": line longer than " +
                               std::to_string(kMaxLineLength) + " bytes"});
        return;
      }
      const char* text_end = line_end;
      if (text_end > p && text_end[-1] == '\r') --text_end;
      const char* first = p;
      while (first < text_end && isBlank(*first)) ++first;
      if ((first == text_end || *first == '#') && options.rows_only) {
        fail({line_number, path + ":" + std::to_string(line_number) + ": " + (first == text_end ? kBlankRow : kCommentRow)});
        return;
      }
      if (first == text_end || *first == '#') {  // a blank line, or a comment (numpy's savetxt, many exports)
        blank_rows[b].push_back(row);
      } else if (!parser.parse(p, text_end, line_number, row, points.positions[row],
                               has_colors ? points.colors[row] : scratch_color, error)) {
        fail(std::move(error));
        return;
      }
      ++row;
      if (!nl) break;
      p = nl + 1;
    }
    if (options.progress) options.progress->advance(block_end - block_start);
  });
  if (first_error) return Error{first_error->message};
  exact.apply(points.dimensions, blank_rows, path, options.notices);
  if (options.notices && !layout.renamed.empty()) {
    std::string list;
    for (const auto& [spelt, known] : layout.renamed) list += (list.empty() ? "" : ", ") + spelt + " as " + known;
    options.notices->push_back(path + ": columns read as the dimensions they name (LAS's fields where LAS is written): " + list);
  }

  // Blank lines left holes; close them (rare, so a single ordered pass is fine).
  size_t holes = 0;
  for (const auto& rows : blank_rows) holes += rows.size();
  if (holes > 0) {
    std::vector<uint64_t> all;
    all.reserve(holes);
    for (const auto& rows : blank_rows) all.insert(all.end(), rows.begin(), rows.end());
    size_t out = 0, next_hole = 0;
    for (size_t i = 0; i < points.positions.size(); ++i) {
      if (next_hole < all.size() && all[next_hole] == i) {
        ++next_hole;
        continue;
      }
      points.positions[out] = points.positions[i];
      if (!points.colors.empty()) points.colors[out] = points.colors[i];
      for (Dimension& d : points.dimensions.all()) d.copyFrom(out, d, i);
      ++out;
    }
    // No shrink_to_fit: it would copy the whole set to give back a few slots.
    points.positions.resize(out);
    if (!points.colors.empty()) points.colors.resize(out);
    points.dimensions.resize(out);
  }
  narrowDimensions(points.dimensions, threads);
  if (Status s = integerColors(path, points, layout.integer_colors, options.colors_0_255,
                               options.rows_only ? std::optional<uint64_t>(options.first_line) : std::nullopt, threads);
      !s)
    return s.error();
  if (points.positions.empty() && !header.named) return Error{path + ": no data rows"};
  // A count line that is not the rows' count: a file cut short, or rows added (a review finding:
  // a count of 1e11 over one row was taken without a word).
  if (header.declared && *header.declared != points.size())
    return Error{path + ":" + std::to_string(header.declared_line) + ": the count line declares " +
                 std::to_string(*header.declared) + " points, but the file has " + std::to_string(points.size()) + " rows"};
  if (options.progress) options.progress->finish();
  return points;
}

}  // namespace dpoint
