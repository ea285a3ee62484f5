// CSV writer: rows are formatted in chunks on all cores and written in order.
//
// Shortest round-trip output is std::to_chars(double) (Ryu in libstdc++): the fewest digits that
// parse back to the same double, so CSV -> PointSet -> CSV is byte- and bit-identical.
// Fixed output is formatFixed (core/fixed_format.h): printf("%.*f") rounding, exactly, as glibc
// does: the exact binary value rounded half to even. Colours are floats: shortest float form, or their exact double
// value in fixed form (as the seed printed its double colours with %.15f).
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>

#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/fixed_format.h"
#include "core/parallel.h"

namespace dpoint {
namespace {

constexpr size_t kRowsPerChunk = 1u << 16;
constexpr int kMaxDecimals = 100;
// DBL_MAX in fixed form has 309 integer digits; plus sign, point, decimals and a separator.
constexpr size_t kMaxFieldChars = fixedFormatMaxChars(kMaxDecimals) + 1;

class RowFormatter {
 public:
  RowFormatter(const PointSet& points, int decimals)
      : points_(points), decimals_(decimals), planar_(points.isPlanar()), colors_(points.hasColors()) {}

  std::string header() const {
    std::string h = planar_ ? "x,y" : "x,y,z";
    if (colors_) h += ",r,g,b";
    return h + "\n";
  }

  // Formats rows [begin, end) into out (replacing its content).
  void format(size_t begin, size_t end, std::string& out) const {
    const size_t fields = (planar_ ? 2u : 3u) + (colors_ ? 3u : 0u);
    const size_t row_max = fields * kMaxFieldChars;
    // Start from the shortest-form size and grow only for long fixed-form rows.
    if (out.size() < (end - begin) * fields * 24 + row_max) out.resize((end - begin) * fields * 24 + row_max);
    size_t used = 0;
    for (size_t i = begin; i < end; ++i) {
      if (out.size() - used < row_max) out.resize(2 * out.size());
      char* p = out.data() + used;
      char* const limit = out.data() + out.size();
      const glm::dvec3& v = points_.positions[i];
      p = number(p, limit, v.x);
      *p++ = ',';
      p = number(p, limit, v.y);
      if (!planar_) {
        *p++ = ',';
        p = number(p, limit, v.z);
      }
      if (colors_) {
        const glm::vec3& c = points_.colors[i];
        for (int k = 0; k < 3; ++k) {
          *p++ = ',';
          p = color(p, limit, c[k]);
        }
      }
      *p++ = '\n';
      used = static_cast<size_t>(p - out.data());
    }
    out.resize(used);
  }

 private:
  char* number(char* p, char* limit, double v) const {
    if (decimals_ >= 0 && std::isfinite(v)) return formatFixed(p, v, decimals_);
    std::to_chars_result r = decimals_ < 0 ? std::to_chars(p, limit, v)
                                           : std::to_chars(p, limit, v, std::chars_format::fixed, decimals_);
    assert(r.ec == std::errc());
    return r.ptr;
  }
  char* color(char* p, char* limit, float v) const {
    if (decimals_ >= 0) return number(p, limit, static_cast<double>(v));
    std::to_chars_result r = std::to_chars(p, limit, v);
    assert(r.ec == std::errc());
    return r.ptr;
  }

  const PointSet& points_;
  int decimals_;
  bool planar_;
  bool colors_;
};

}  // namespace

Status writeCsv(const std::string& path, const PointSet& points, const CsvWriteOptions& options) {
  if (options.decimals > kMaxDecimals)
    return Error{"--decimals " + std::to_string(options.decimals) + " is above the limit of " +
                     std::to_string(kMaxDecimals),
                 ExitCode::kUsage};
  if (!points.colors.empty() && points.colors.size() != points.positions.size())
    return Error{"point set has " + std::to_string(points.colors.size()) + " colours for " +
                 std::to_string(points.positions.size()) + " points"};
  Result<AtomicFile> file = AtomicFile::create(path);
  if (!file) return file.error();

  const RowFormatter formatter(points, options.decimals);
  if (Status s = file->write(formatter.header()); !s) return s;

  const unsigned threads = resolveThreads(options.threads);
  const size_t n = points.size();
  const size_t chunks = (n + kRowsPerChunk - 1) / kRowsPerChunk;
  // Chunks are formatted a batch at a time (a few per thread) and written in order, so memory
  // stays at a few megabytes per thread whatever the size of the set.
  const size_t batch = std::max<size_t>(1, 2 * threads);
  std::vector<std::string> texts(batch);
  if (options.progress) options.progress->start("writing " + path, n);
  for (size_t first = 0; first < chunks; first += batch) {
    const size_t count = std::min(batch, chunks - first);
    parallelFor(count, threads, [&](size_t k, unsigned) {
      const size_t chunk = first + k;
      formatter.format(chunk * kRowsPerChunk, std::min(n, (chunk + 1) * kRowsPerChunk), texts[k]);
    });
    for (size_t k = 0; k < count; ++k) {
      if (Status s = file->write(texts[k]); !s) return s;
    }
    if (options.progress) options.progress->advance(std::min(n, (first + count) * kRowsPerChunk) - first * kRowsPerChunk);
  }
  if (options.progress) options.progress->finish();
  return file->commit();
}

}  // namespace dpoint
