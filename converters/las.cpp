// LAS reading and writing (converters/las.h says what and why). Field offsets follow the public header
// block and point record tables of LAS 1.4 R15; the 1.0–1.3 headers are prefixes of the 1.4 one.
// Only little-endian hosts: fields are copied out of the bytes with memcpy.
#include "converters/las.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cassert>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <optional>
#include <unordered_set>
#include <vector>

#include <glm/common.hpp>

#include "converters/las_crs.h"
#include "converters/las_fields.h"
#include "converters/laz_decode.h"
#include "converters/laz_encode.h"
#include "core/atomic_file.h"
#include "core/bytes.h"
#include "core/input_file.h"
#include "core/interrupt.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "core/random.h"
#include "core/text.h"
#include "ops/colormap.h"

namespace dpoint {

static_assert(std::endian::native == std::endian::little, "LAS fields are little-endian, copied as they are");

namespace {

// Public header block: byte offsets of the fields used here.
constexpr size_t kVersionMajorAt = 24, kVersionMinorAt = 25, kSystemIdAt = 26, kSoftwareAt = 58;
constexpr size_t kHeaderSizeAt = 94, kPointOffsetAt = 96, kVlrCountAt = 100, kFormatAt = 104;
constexpr size_t kRecordLengthAt = 105, kLegacyCountAt = 107, kLegacyByReturnAt = 111;
constexpr size_t kScaleAt = 131, kOffsetAt = 155, kBoundsAt = 179;  // bounds: max x, min x, max y, ...
constexpr size_t kEvlrStartAt = 235, kEvlrCountAt = 243, kCountAt = 247;  // LAS 1.4
constexpr size_t kVlrHeaderBytes = 54, kEvlrHeaderBytes = 60;
// Header sizes: 1.0–1.2, 1.3 (adds the waveform packet start), 1.4 (EVLRs, 64-bit counts).
constexpr uint32_t kHeaderSize12 = 227, kHeaderSize13 = 235, kHeaderSize14 = 375;

// Point records: base sizes (where red sits is lasRgbOffset, las_fields.h). Intensity is
// at byte 12 in every format; classification is the low five bits of byte 15 in formats 0–5 (the
// top three are the synthetic, key-point and withheld flags) and all of byte 16 in formats 6–10.
constexpr std::array<uint32_t, 11> kBaseLength = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
constexpr size_t kIntensityAt = 12;

// Records are read and decoded in blocks of about this many bytes, one per task: large enough that
// a pread and a task hand-out cost nothing, small enough that every core stays busy to the end.
constexpr size_t kBlockBytes = size_t{1} << 20;
// The writer encodes this many points per task.
constexpr size_t kWriteBlockPoints = size_t{1} << 15;

constexpr char kAxis[3] = {'x', 'y', 'z'};

std::string num(double v) { return formatNumber(v); }
std::string str(uint64_t v) { return std::to_string(v); }

// A fixed-size text field up to its first NUL, made printable.
std::string textField(const char* p, size_t size) {
  return printableExcerpt(std::string_view(p, strnlen(p, size)));
}

// Whether every coordinate an axis with this scale and offset can store is finite: every stored
// integer is within ±2^31. The reader refuses a header where it is not; the writer never makes one.
bool frameIsFinite(double scale, double offset) {
  return std::isfinite(std::fabs(scale) * 2147483648.0 + std::fabs(offset));
}

Result<LasHeader> parseHeader(const InputFile& file) {
  const std::string& path = file.path();
  char h[kHeaderSize14] = {};
  Result<size_t> got = file.readAt(0, h, sizeof h);
  if (!got) return got.error();
  if (*got == 0) return Error{path + ": empty file, not a LAS file"};
  if (*got < 4 || std::memcmp(h, "LASF", 4) != 0)
    return Error{path + ": not a LAS file (it does not start with 'LASF')"};
  const auto truncatedHeader = [&](uint32_t needed, const std::string& what) {
    return Error{path + ": truncated header: the file has " + str(file.size()) + " bytes, " + what + " " +
                 str(needed)};
  };
  if (*got < kHeaderSize12) return truncatedHeader(kHeaderSize12, "a LAS header at least");

  LasHeader hd;
  hd.version_major = static_cast<uint8_t>(h[kVersionMajorAt]);
  hd.version_minor = static_cast<uint8_t>(h[kVersionMinorAt]);
  const std::string version = std::to_string(hd.version_major) + "." + std::to_string(hd.version_minor);
  if (hd.version_major != 1 || hd.version_minor > 4)
    return Error{path + ": header: version " + version + " is not supported (LAS 1.0 to 1.4)"};
  const uint32_t needed = hd.version_minor >= 4 ? kHeaderSize14 : hd.version_minor == 3 ? kHeaderSize13 : kHeaderSize12;
  if (*got < needed) return truncatedHeader(needed, "a LAS " + version + " header");
  hd.header_size = loadUnaligned<uint16_t>(h + kHeaderSizeAt);
  if (hd.header_size < needed)
    return Error{path + ": header: header size " + str(hd.header_size) + " is smaller than LAS " + version + "'s " +
                 str(needed) + " bytes"};
  hd.generating_software = textField(h + kSoftwareAt, 32);
  hd.file_source_id = loadUnaligned<uint16_t>(h + 4);
  hd.global_encoding = loadUnaligned<uint16_t>(h + 6);

  const uint8_t raw_format = static_cast<uint8_t>(h[kFormatAt]);
  hd.compressed = (raw_format & 0xC0) != 0;  // LAZ marks its records with bit 7 (old writers: 6)
  hd.point_format = raw_format & 0x3F;
  if (hd.point_format > 10)
    return Error{path + ": header: point data format " + str(raw_format) + " is not one of LAS's formats 0 to 10"};
  hd.record_length = loadUnaligned<uint16_t>(h + kRecordLengthAt);
  const uint32_t base = lasBaseRecordLength(hd.point_format);
  if (hd.record_length < base)
    return Error{path + ": header: point record length " + str(hd.record_length) + " is shorter than point format " +
                 str(raw_format) + "'s " + str(base) + " bytes"};
  hd.point_offset = loadUnaligned<uint32_t>(h + kPointOffsetAt);
  hd.vlr_count = loadUnaligned<uint32_t>(h + kVlrCountAt);
  if (hd.point_offset < hd.header_size)
    return Error{path + ": header: offset to point data " + str(hd.point_offset) + " lies inside the " +
                 str(hd.header_size) + "-byte header"};

  for (int k = 0; k < 3; ++k) {
    const std::string axis(1, kAxis[k]);
    const double scale = loadUnaligned<double>(h + kScaleAt + 8 * k), offset = loadUnaligned<double>(h + kOffsetAt + 8 * k);
    const double max = loadUnaligned<double>(h + kBoundsAt + 16 * k), min = loadUnaligned<double>(h + kBoundsAt + 16 * k + 8);
    if (!std::isfinite(scale) || scale == 0.0)
      return Error{path + ": header: " + axis + " scale " + num(scale) + " is not a finite, non-zero number"};
    if (!std::isfinite(offset))
      return Error{path + ": header: " + axis + " offset " + num(offset) + " is not a finite number"};
    if (!std::isfinite(min) || !std::isfinite(max))
      return Error{path + ": header: " + axis + " bounds " + num(min) + " .. " + num(max) + " are not finite numbers"};
    if (!frameIsFinite(scale, offset))
      return Error{path + ": header: " + axis + " scale " + num(scale) + " and offset " + num(offset) +
                   " give coordinates beyond double's range"};
    hd.scale[k] = scale;
    hd.offset[k] = offset;
    hd.min[k] = min;
    hd.max[k] = max;
  }

  const uint32_t legacy = loadUnaligned<uint32_t>(h + kLegacyCountAt);
  hd.point_count = legacy;
  if (hd.version_minor >= 4) {
    hd.evlr_count = loadUnaligned<uint32_t>(h + kEvlrCountAt);
    const uint64_t count = loadUnaligned<uint64_t>(h + kCountAt);
    if (count != 0 && legacy != 0 && count != legacy)
      return Error{path + ": header: legacy point count " + str(legacy) + " disagrees with the 64-bit count " +
                   str(count)};
    if (count != 0) hd.point_count = count;
  }
  if (hd.point_offset > file.size())
    return Error{path + ": truncated: the offset to point data " + str(hd.point_offset) + " is past the end of the " +
                 str(file.size()) + "-byte file"};
  const uint64_t available = file.size() - hd.point_offset;
  if (!hd.compressed && hd.point_count > available / hd.record_length)
    return Error{path + ": truncated: the header declares " + str(hd.point_count) + " points of " +
                 str(hd.record_length) + " bytes from byte " + str(hd.point_offset) + ", but only " + str(available) +
                 " bytes follow (room for " + str(available / hd.record_length) + " points)"};
  return hd;
}


// Decodes the point records into a PointSet (see the top of las.h for the colour rules).
// A record's position: X·scale + offset per axis, two roundings, as PDAL, laspy and loaders.gl
// compute it (no FMA: the project builds with -ffp-contract=off).
glm::dvec3 recordPosition(const char* p, const glm::dvec3& scale, const glm::dvec3& offset) {
  return glm::dvec3(static_cast<double>(loadUnaligned<int32_t>(p)) * scale.x + offset.x,
                    static_cast<double>(loadUnaligned<int32_t>(p + 4)) * scale.y + offset.y,
                    static_cast<double>(loadUnaligned<int32_t>(p + 8)) * scale.z + offset.z);
}

// Field f of `record` into point i of its dimension, as stored (a bit field shifted down).
void copyField(const LasField& f, const char* record, Dimension& d, size_t i) {
  if (f.bits) {
    d.set<uint8_t>(i, static_cast<uint8_t>((static_cast<uint8_t>(record[f.offset]) >> f.shift) & ((1u << f.bits) - 1)));
  } else {
    const size_t w = dimTypeSize(f.type);
    std::memcpy(d.bytes.data() + i * w, record + f.offset, w);
  }
}

// An extra bytes field at `at` into point i of its dimension: as stored, or scaled.
void copyExtra(const LasExtraField& f, const char* at, Dimension& d, size_t i) {
  if (f.scaled) {
    d.set<double>(i, loadDimValue(f.type, reinterpret_cast<const uint8_t*>(at)) * f.value_scale + f.value_offset);
    return;
  }
  const size_t w = dimTypeSize(d.type);
  std::memcpy(d.bytes.data() + i * w, at, w);
}

class LasReader {
 public:
  LasReader(const InputFile& file, const LasHeader& header, LasColorSource source, const LasReadOptions& options,
            const std::vector<LasExtraField>& extra)
      : file_(file), h_(header), source_(source), options_(options), fields_(lasFields(header.point_format)),
        extra_(extra) {
    rgb_at_ = lasRgbOffset(h_.point_format);
    class_at_ = h_.point_format >= 6 ? 16 : 15;
    class_mask_ = h_.point_format >= 6 ? 0xFF : 0x1F;
    extra_at_ = lasBaseRecordLength(h_.point_format);
    for (size_t c = 0; c < palette_.size(); ++c) palette_[c] = lasClassColor(static_cast<uint8_t>(c));
  }

  Result<PointSet> run() {
    const size_t count = static_cast<size_t>(h_.point_count);  // bounded by the file size
    const size_t length = h_.record_length;
    if (options_.progress) options_.progress->start("reading " + file_.path(), count * length);
    PointSet points;
    points.z_axis = ZAxis::kPresent;  // every record has Z, whatever its values
    points.z_up = true;               // LAS is z-up (elevation)
    points.positions.resize(count);
    if (source_ != LasColorSource::kNone) points.colors.resize(count);
    // Every field of the record, and each extra byte field, as a dimension (core/dimensions.h).
    // (lasExtraFields made every name unique.) Unset: decode() writes every field of every point
    // (the columns are a dozen, hundreds of MB at 16M points, no longer zeroed on one thread first).
    points.dimensions.reserve(fields_.size() + extra_.size());
    for (const LasField& f : fields_) points.dimensions.appendUnset(f.name, f.type, count);
    for (const LasExtraField& f : extra_) points.dimensions.appendUnset(f.name, f.dimensionType(), count);
    columns_.clear();  // pointers once every column is in place (adding one may move the others)
    columns_.reserve(points.dimensions.count());
    for (Dimension& d : points.dimensions.all()) columns_.push_back(&d);
    const size_t block_points = std::max<size_t>(1, kBlockBytes / length);
    const size_t blocks = (count + block_points - 1) / block_points;
    const unsigned threads = resolveThreads(options_.threads);
    std::vector<uint16_t> block_max(blocks, 0);  // the largest colour channel or intensity per block
    std::vector<std::vector<char>> buffers(threads);
    std::mutex error_mutex;
    std::optional<Error> first_error;
    size_t error_block = SIZE_MAX;
    parallelFor(blocks, threads, [&](size_t b, unsigned worker) {
      const size_t first = b * block_points, last = std::min(first + block_points, count);
      std::vector<char>& buffer = buffers[worker];
      buffer.resize((last - first) * length);
      const uint64_t at = h_.point_offset + uint64_t{first} * length;
      Result<size_t> got = file_.readAt(at, buffer.data(), buffer.size());
      if (!got || *got < buffer.size()) {  // an I/O error, or the file shrank since it was opened
        std::lock_guard<std::mutex> lock(error_mutex);
        if (b < error_block) {
          error_block = b;
          first_error = got ? Error{file_.path() + ": truncated: the file ends in point " +
                                    str(first + *got / length) + " of " + str(count)}
                            : got.error();
        }
        return;
      }
      block_max[b] = decode(buffer.data(), first, last, points);
      if (options_.progress) options_.progress->advance(buffer.size());
    });
    if (first_error) return *first_error;
    uint16_t largest = 0;
    for (uint16_t m : block_max) largest = std::max(largest, m);
    normalize(points, largest, threads);
    if (source_ == LasColorSource::kRgb) points.color_full_scale = largest > 255 ? 65535 : 255;
    if (options_.progress) options_.progress->finish();
    return points;
  }

 private:
  // Records [first, last) from `data` into the point set; returns the largest raw colour channel
  // (kRgb) or intensity (kIntensity) seen, 0 for the other sources.
  uint16_t decode(const char* data, size_t first, size_t last, PointSet& points) const {
    const glm::dvec3 scale = h_.scale, offset = h_.offset;
    glm::dvec3* positions = points.positions.data();
    glm::vec3* colors = points.colors.data();
    uint16_t largest = 0;
    const char* p = data;
    for (size_t i = first; i < last; ++i, p += h_.record_length) {
      positions[i] = recordPosition(p, scale, offset);
      decodeFields(p, i);
      switch (source_) {
        case LasColorSource::kRgb: {
          const uint16_t r = loadUnaligned<uint16_t>(p + rgb_at_), g = loadUnaligned<uint16_t>(p + rgb_at_ + 2),
                         b = loadUnaligned<uint16_t>(p + rgb_at_ + 4);
          largest = std::max({largest, r, g, b});
          colors[i] = glm::vec3(r, g, b);  // raw for now; normalize() divides
          break;
        }
        case LasColorSource::kIntensity: {
          const uint16_t v = loadUnaligned<uint16_t>(p + kIntensityAt);
          largest = std::max(largest, v);
          colors[i] = glm::vec3(v);
          break;
        }
        case LasColorSource::kClassification:
          colors[i] = palette_[static_cast<uint8_t>(p[class_at_]) & class_mask_];
          break;
        case LasColorSource::kAuto:
        case LasColorSource::kNone:
          break;
      }
    }
    return largest;
  }

  // Turns the raw colours or intensities into 0..1: a float division of an exact integer, so each
  // channel is the correctly rounded quotient.
  void normalize(PointSet& points, uint16_t largest, unsigned threads) const {
    float divisor = 0.0f;
    if (source_ == LasColorSource::kRgb) divisor = largest > 255 ? 65535.0f : 255.0f;
    if (source_ == LasColorSource::kIntensity) divisor = static_cast<float>(largest);
    if (divisor == 0.0f) return;  // no colours, a palette, or every intensity 0 (already black)
    const size_t chunk = size_t{1} << 16;
    parallelFor((points.colors.size() + chunk - 1) / chunk, threads, [&](size_t c, unsigned) {
      const size_t end = std::min(points.colors.size(), (c + 1) * chunk);
      for (size_t i = c * chunk; i < end; ++i) points.colors[i] /= divisor;
    });
  }

  // The record's fields and extra bytes into point i's dimensions, as stored (bit fields shifted down).
  void decodeFields(const char* record, size_t i) const {
    for (size_t k = 0; k < fields_.size(); ++k) copyField(fields_[k], record, *columns_[k], i);
    for (size_t k = 0; k < extra_.size(); ++k)
      copyExtra(extra_[k], record + extra_at_ + extra_[k].offset, *columns_[fields_.size() + k], i);
  }

  const InputFile& file_;
  const LasHeader& h_;
  LasColorSource source_;
  const LasReadOptions& options_;
  const std::vector<LasField>& fields_;
  const std::vector<LasExtraField>& extra_;  // the caller's, which outlives the reader
  std::vector<Dimension*> columns_;  // fields_ then extra_, into the point set being read
  uint32_t extra_at_ = 0;
  size_t rgb_at_ = 0, class_at_ = 15;
  uint8_t class_mask_ = 0x1F;
  std::array<glm::vec3, 256> palette_;
};

// One axis of the writer: offset, and the integer a coordinate is stored as.
double quantize(double x, double offset, double scale) { return std::round((x - offset) / scale); }
bool fitsInt32(double q) { return q >= -2147483648.0 && q <= 2147483647.0; }

// True when every coordinate on axis k reads back as itself (X·scale + offset, as a reader computes
// it) when stored under `offset`. Stops at the first that does not.
bool readsBackExactly(const PositionArray& positions, int k, double offset, double scale, unsigned threads) {
  std::atomic<bool> miss{false};
  const size_t n = positions.size();
  parallelFor((n + kWriteBlockPoints - 1) / kWriteBlockPoints, threads, [&](size_t b, unsigned) {
    const size_t last = std::min(n, (b + 1) * kWriteBlockPoints);
    for (size_t i = b * kWriteBlockPoints; i < last && !miss.load(std::memory_order_relaxed); ++i)
      if (quantize(positions[i][k], offset, scale) * scale + offset != positions[i][k]) miss = true;
  });
  return !miss;
}

// The offset of axis k: the first of lasOffsetFor (a whole number: decimal data at large
// coordinates reads back exactly), 0 (data read from the many files whose offset is 0, as PDAL
// writes them by default), floor(min / scale) · scale and the middle of the extent as a whole
// number (an extent of nearly 2^32 steps) under which the extremes fit the 32-bit integers and
// every coordinate reads back as the same double; else the first of them under which the
// extremes fit; else lasOffsetFor.
// Measured on simple.las (scale 0.01, offset 0) written at 0.01: x, y, z offsets of 0 read every
// point back; the whole-number offsets missed 111, 137 and 164 of 1065, the rounded multiples 315,
// 459 and 430.
double chooseOffset(const PositionArray& positions, int k, double min, double max, double scale,
                    unsigned threads) {
  const double first = lasOffsetFor(min, scale);
  std::optional<double> fitting;
  for (double offset : {first, 0.0, std::floor(min / scale) * scale, lasOffsetFor(min / 2 + max / 2, scale)}) {
    if (!fitsInt32(quantize(min, offset, scale)) || !fitsInt32(quantize(max, offset, scale))) continue;
    if (readsBackExactly(positions, k, offset, scale, threads)) return offset;
    if (!fitting) fitting = offset;
  }
  return fitting.value_or(first);
}

// Distinct positions minus distinct integer triples at this scale and offset: how many points
// would read back on top of another. Points that merge share their triple, and equal positions
// share it too, so the points are split into buckets by a hash of their triple (on all cores) and
// each bucket, sorted on its own, counts its distinct positions less its distinct triples. 48 bytes
// a point for the time of the count. (Two sorts of the whole set on one thread took 30% of writing
// a 1.55M-point LAS on 2 cores.)
uint64_t mergedPoints(const PositionArray& positions, const glm::dvec3& scale, const glm::dvec3& offset,
                      unsigned threads) {
  struct Entry {
    std::array<int64_t, 3> stored;
    std::array<double, 3> exact;
  };
  const size_t n = positions.size();
  threads = resolveThreads(threads);
  const size_t buckets = size_t{threads} * 64;
  const size_t chunks = std::max<size_t>(1, std::min<size_t>((n + 65535) / 65536, size_t{threads} * 8));
  const size_t chunk_points = (n + chunks - 1) / chunks;
  auto stored = [&](size_t i) {
    std::array<int64_t, 3> q;
    for (int k = 0; k < 3; ++k) q[static_cast<size_t>(k)] = static_cast<int64_t>(quantize(positions[i][k], offset[k], scale[k]));
    return q;
  };
  auto bucketOf = [&](const std::array<int64_t, 3>& q) {
    const uint64_t h = splitmixMix(static_cast<uint64_t>(q[0]) ^
                                   splitmixMix(static_cast<uint64_t>(q[1]) ^ splitmixMix(static_cast<uint64_t>(q[2]))));
    return static_cast<size_t>(h % buckets);
  };
  // at[c · buckets + b]: where chunk c's points of bucket b go (bucket-major, then chunk order).
  // Each pass stops at a signal, every 4,096 points (6M points on one thread had run 0.5 s past
  // the watcher's grace: bench/scripts/interrupt_latency.py); the caller then stops.
  std::vector<size_t> at(chunks * buckets, 0);
  parallelFor(chunks, threads, [&](size_t c, unsigned) {
    for (size_t i = c * chunk_points, end = std::min(n, (c + 1) * chunk_points); i < end; ++i) {
      if (i % 4096 == 0 && interrupted()) return;
      ++at[c * buckets + bucketOf(stored(i))];
    }
  });
  if (interrupted()) return 0;
  std::vector<size_t> bucket_start(buckets + 1, 0);
  size_t sum = 0;
  for (size_t b = 0; b < buckets; ++b) {
    bucket_start[b] = sum;
    for (size_t c = 0; c < chunks; ++c) {
      const size_t count = at[c * buckets + b];
      at[c * buckets + b] = sum;
      sum += count;
    }
  }
  bucket_start[buckets] = sum;
  std::vector<Entry, DefaultInitAllocator<Entry>> entries(n);  // every one written by the scatter
  // Faulted in on all cores first, in order: the scatter's random writes faulted a page at a time
  // on one core each (a 2 MiB page zeroed per fault, most of the pass on the 2-core VM).
  prefaultForWrite(entries.data(), n * sizeof(Entry), threads);
  if (interrupted()) return 0;
  parallelFor(chunks, threads, [&](size_t c, unsigned) {
    for (size_t i = c * chunk_points, end = std::min(n, (c + 1) * chunk_points); i < end; ++i) {
      if (i % 4096 == 0 && interrupted()) return;  // the first chunk faults in a page a point
      const std::array<int64_t, 3> q = stored(i);
      entries[at[c * buckets + bucketOf(q)]++] = {q, {positions[i].x, positions[i].y, positions[i].z}};
    }
  });
  if (interrupted()) return 0;
  std::atomic<uint64_t> merged{0};
  parallelFor(buckets, threads, [&](size_t b, unsigned) {
    if (interrupted()) return;
    const auto first = entries.begin() + static_cast<ptrdiff_t>(bucket_start[b]);
    const auto last = entries.begin() + static_cast<ptrdiff_t>(bucket_start[b + 1]);
    // Spelled out: std::array's == on the integers went to memcmp through the PLT (a quarter of the
    // time of a 16.8M-point write).
    auto same = [](const std::array<int64_t, 3>& u, const std::array<int64_t, 3>& v) {
      return u[0] == v[0] && u[1] == v[1] && u[2] == v[2];
    };
    std::sort(first, last, [](const Entry& x, const Entry& y) {
      for (size_t k = 0; k < 3; ++k)
        if (x.stored[k] != y.stored[k]) return x.stored[k] < y.stored[k];
      for (size_t k = 0; k < 3; ++k)
        if (x.exact[k] != y.exact[k]) return x.exact[k] < y.exact[k];
      return false;
    });
    uint64_t count = 0;
    for (auto e = first; e != last; ++e)
      if (e != first && same(e->stored, (e - 1)->stored) &&
          (e->exact[0] != (e - 1)->exact[0] || e->exact[1] != (e - 1)->exact[1] || e->exact[2] != (e - 1)->exact[2]))
        ++count;
    merged += count;
  });
  return merged;
}

// Whether axis k's extent fits the 32-bit integers at `scale` from the offset the writer would
// choose (lasOffsetFor rounds the minimum down by less than one unit).
bool extentFits(double min, double max, double scale) {
  for (double offset : {lasOffsetFor(min, scale), lasOffsetFor(min / 2 + max / 2, scale)})
    if (fitsInt32(quantize(min, offset, scale)) && fitsInt32(quantize(max, offset, scale))) return true;
  return false;
}

// True when every coordinate on axis k reads back within two units in the last place of itself
// (or of the offset, where that is larger): the decimal digits it has are all kept. Stops at the
// first that does not.
bool readsBackClosely(const PositionArray& positions, int k, double offset, double scale, unsigned threads) {
  std::atomic<bool> miss{false};
  const size_t n = positions.size();
  const double offset_ulp = std::nextafter(std::abs(offset), HUGE_VAL) - std::abs(offset);
  parallelFor((n + kWriteBlockPoints - 1) / kWriteBlockPoints, threads, [&](size_t b, unsigned) {
    const size_t last = std::min(n, (b + 1) * kWriteBlockPoints);
    for (size_t i = b * kWriteBlockPoints; i < last && !miss.load(std::memory_order_relaxed); ++i) {
      const double x = positions[i][k], back = quantize(x, offset, scale) * scale + offset;
      const double ulp = std::max(std::nextafter(std::abs(x), HUGE_VAL) - std::abs(x), offset_ulp);
      if (!(std::abs(back - x) <= 2.0 * ulp)) miss = true;
    }
  });
  return !miss;
}

// The decimal steps the writer chooses from, coarse to fine (literals: 1/10/10… drifts from them).
constexpr double kDecimalSteps[] = {1.0,  0.1,  0.01, 0.001, 1e-4,  1e-5, 1e-6,
                                    1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12};

// The scale of axis k of a set without a LAS source or an asked one (las.h): the coarsest decimal
// step at which every coordinate keeps its digits (the data's own step: 0.01 for centimetre
// data), else the finest at which the extent fits the 32-bit integers. `rounded`: set when that
// last is the case, and the coordinates lose digits to fit.
double chooseAxisScale(const PositionArray& positions, int k, double min, double max, unsigned threads, bool& rounded) {
  rounded = !positions.empty();
  double coarse = 1.0;
  while (!extentFits(min, max, coarse) && coarse < 1e300) coarse *= 10.0;
  if (coarse > 1.0 || positions.empty()) return coarse;  // a wider extent than 2^31 units: no finer step fits
  double finest = coarse;
  for (double step : kDecimalSteps) {
    if (!extentFits(min, max, step)) break;
    finest = step;
    if (readsBackClosely(positions, k, chooseOffset(positions, k, min, max, step, threads), step, threads)) {
      rounded = false;
      return step;
    }
  }
  return finest;
}

// What the writer puts in a file beside the records.
struct WriterLayout {
  int format = 0, version_minor = 2;
  uint32_t record_length = 0, base_length = 0;
  std::vector<LasExtraField> extra;  // dimensions kept as extra bytes, after the base record
  size_t described = 0;  // extra[0, described) have descriptors; the rest are undescribed bytes
  std::vector<LasVlr> vlrs, evlrs;
  uint16_t global_encoding = 0, file_source_id = 0;
  std::vector<std::string> renamed;  // "dimension 'höhe' written as 'h__he'": extra bytes named anew
  std::string crs_note;  // what became of the source's CRS records (lasWktCrs), empty when nothing
};

// The LAS 1.2 (227-byte) or 1.4 (375-byte) header. Creation day and year are 0 ("not given") so
// that the same points give the same bytes on any day.
std::string writerHeader(const WriterLayout& l, uint64_t count, const std::array<uint64_t, 15>& by_return,
                         const glm::dvec3& scale, const glm::dvec3& offset, const glm::dvec3& min,
                         const glm::dvec3& max, uint32_t point_offset, uint64_t evlr_start) {
  const bool v14 = l.version_minor >= 4;
  std::string h(v14 ? kHeaderSize14 : kHeaderSize12, '\0');
  std::memcpy(h.data(), "LASF", 4);
  storeUnaligned<uint16_t>(h.data() + 4, l.file_source_id);
  storeUnaligned<uint16_t>(h.data() + 6, l.global_encoding);
  h[kVersionMajorAt] = 1;
  h[kVersionMinorAt] = static_cast<char>(l.version_minor);
  std::memcpy(h.data() + kSystemIdAt, "OTHER", 5);
  std::memcpy(h.data() + kSoftwareAt, "dpoint", 6);
  storeUnaligned<uint16_t>(h.data() + kHeaderSizeAt, static_cast<uint16_t>(h.size()));
  storeUnaligned<uint32_t>(h.data() + kPointOffsetAt, point_offset);
  storeUnaligned<uint32_t>(h.data() + kVlrCountAt, static_cast<uint32_t>(l.vlrs.size()));
  h[kFormatAt] = static_cast<char>(l.format);
  storeUnaligned<uint16_t>(h.data() + kRecordLengthAt, static_cast<uint16_t>(l.record_length));
  // The legacy counts: 0 where they cannot hold the truth (formats 6-10, more than 2^32 - 1 points).
  const bool legacy = l.format < 6 && count <= UINT32_MAX;
  storeUnaligned<uint32_t>(h.data() + kLegacyCountAt, legacy ? static_cast<uint32_t>(count) : 0u);
  for (size_t r = 0; r < 5; ++r)
    storeUnaligned<uint32_t>(h.data() + kLegacyByReturnAt + 4 * r, legacy ? static_cast<uint32_t>(by_return[r]) : 0u);
  for (int k = 0; k < 3; ++k) {
    storeUnaligned<double>(h.data() + kScaleAt + 8 * k, scale[k]);
    storeUnaligned<double>(h.data() + kOffsetAt + 8 * k, offset[k]);
    storeUnaligned<double>(h.data() + kBoundsAt + 16 * k, max[k]);
    storeUnaligned<double>(h.data() + kBoundsAt + 16 * k + 8, min[k]);
  }
  if (v14) {
    storeUnaligned<uint64_t>(h.data() + kEvlrStartAt, l.evlrs.empty() ? 0 : evlr_start);
    storeUnaligned<uint32_t>(h.data() + kEvlrCountAt, static_cast<uint32_t>(l.evlrs.size()));
    storeUnaligned<uint64_t>(h.data() + kCountAt, count);
    for (size_t r = 0; r < 15; ++r) storeUnaligned<uint64_t>(h.data() + kCountAt + 8 + 8 * r, by_return[r]);
  }
  return h;
}

// A VLR (54-byte header) or EVLR (60) with its data.
std::string vlrBytes(const LasVlr& vlr, bool extended) {
  std::string out(extended ? kEvlrHeaderBytes : kVlrHeaderBytes, '\0');
  std::memcpy(out.data() + 2, vlr.user_id.data(), std::min<size_t>(vlr.user_id.size(), 16));
  storeUnaligned<uint16_t>(out.data() + 18, vlr.record_id);
  if (extended) storeUnaligned<uint64_t>(out.data() + 20, vlr.data.size());
  else storeUnaligned<uint16_t>(out.data() + 20, static_cast<uint16_t>(vlr.data.size()));
  std::memcpy(out.data() + (extended ? 28 : 22), vlr.description.data(), std::min<size_t>(vlr.description.size(), 32));
  return out + vlr.data;
}

// The value v stored as `type` at p: rounded and clamped into an integer type's range.
void storeValue(char* p, DimType type, double v) {
  auto whole = [&](double lo, double hi) { return std::isnan(v) ? 0.0 : std::clamp(std::round(v), lo, hi); };
  switch (type) {
    case DimType::kU8: storeUnaligned<uint8_t>(p, static_cast<uint8_t>(whole(0, 255))); break;
    case DimType::kI8: storeUnaligned<int8_t>(p, static_cast<int8_t>(whole(-128, 127))); break;
    case DimType::kU16: storeUnaligned<uint16_t>(p, static_cast<uint16_t>(whole(0, 65535))); break;
    case DimType::kI16: storeUnaligned<int16_t>(p, static_cast<int16_t>(whole(-32768, 32767))); break;
    case DimType::kU32: storeUnaligned<uint32_t>(p, static_cast<uint32_t>(whole(0, 4294967295.0))); break;
    case DimType::kI32: storeUnaligned<int32_t>(p, static_cast<int32_t>(whole(-2147483648.0, 2147483647.0))); break;
    case DimType::kU64: storeUnaligned<uint64_t>(p, static_cast<uint64_t>(whole(0, 18446744073709549568.0))); break;
    case DimType::kI64: storeUnaligned<int64_t>(p, static_cast<int64_t>(whole(-9223372036854775808.0, 9223372036854774784.0))); break;
    case DimType::kF32: storeUnaligned<float>(p, static_cast<float>(v)); break;
    case DimType::kF64: storeUnaligned<double>(p, v); break;
  }
}

// Which format, extra bytes, version and records the writer uses for `points` (las_fields.h).
Result<WriterLayout> writerLayout(const std::string& path, const PointSet& points, size_t n, bool compress,
                                  bool las14, const std::string& crs_wkt, bool source_crs_dropped, unsigned threads) {
  WriterLayout l;
  const LasSource* source = points.las ? &*points.las : nullptr;
  // LAZ and COPC hold no wave packets (their fields are extra bytes then); COPC holds formats 6-8
  // only: a legacy format becomes the 1.4 one with its fields (5 had become 6, without its colours).
  l.format = lasFormatFor(points, source ? source->point_format : -1, !compress && !las14);
  if (las14 && l.format < 6) l.format = l.format == 0 || l.format == 1 ? 6 : 7;
  l.base_length = lasBaseRecordLength(l.format);
  const std::vector<LasField>& fields = lasFields(l.format);
  const auto isField = [&](const std::string& name) {
    return std::any_of(fields.begin(), fields.end(), [&](const LasField& f) { return name == f.name; });
  };
  uint32_t at = 0;
  for (const Dimension& d : points.dimensions.all()) {
    if (isField(d.name)) continue;
    // The other family's scan angle fills this format's, unless the set has that one too.
    const char* counterpart = d.name == dim::kScanAngle ? dim::kScanAngleRank : d.name == dim::kScanAngleRank ? dim::kScanAngle : nullptr;
    if (counterpart && isField(counterpart) && !points.dimensions.find(counterpart)) continue;
    // The source's field where the dimension still fits it (its scale, no-data value, description).
    std::optional<LasExtraField> field;
    if (source)
      for (const auto& [name, descriptor] : source->extra_bytes)
        if (name == d.name) field = lasSourceExtraField(d, descriptor, threads);
    if (!field) field = LasExtraField{d.name, d.type, 0};
    field->offset = at;
    field->dimension = static_cast<size_t>(&d - points.dimensions.all().data());
    at += static_cast<uint32_t>(dimTypeSize(field->type));
    l.extra.push_back(std::move(*field));
  }
  // Names the reader gives back as they are (lasExtraFields): letters, digits and '_', at most 32
  // bytes ("extra" where none is left, as the reader names such a field), none a field's or the
  // position's and colours', none twice.
  std::unordered_set<std::string> taken = {"x", "y", "z", "red", "green", "blue"};
  for (const LasField& f : fields) taken.insert(f.name);
  std::vector<std::string> names;
  for (const LasExtraField& f : l.extra) names.push_back(f.name);
  names = writableNames(
      names, [](char c) { return !(std::isalnum(static_cast<unsigned char>(c)) || c == '_'); },
      [&](const std::string& name, size_t) { return taken.count(name) != 0; }, &l.renamed, 32, "extra");
  for (size_t k = 0; k < names.size(); ++k) l.extra[k].name = names[k];
  l.record_length = l.base_length + at;
  // Trailing bytes a LAS file left undescribed (the reader's u8 `extra_byte_N` at byte N) stay
  // undescribed: they read back as the same dimensions (65,515 of them had taken a descriptor each).
  l.described = l.extra.size();
  while (l.described > 0) {
    const LasExtraField& f = l.extra[l.described - 1];
    if (f.type != DimType::kU8 || f.scaled || !f.descriptor.empty() || f.name != "extra_byte_" + str(f.offset)) break;
    --l.described;
  }
  // Each other field is a 192-byte descriptor in one VLR, whose length is 16 bits: 342 of them
  // wrapped it, and no reader found the records after (a review finding).
  if (l.described * kExtraBytesDescriptorBytes > 65535)
    return Error{path + ": " + str(l.described) + " dimensions as LAS extra bytes, past the " +
                 str(65535 / kExtraBytesDescriptorBytes) + " whose descriptors one VLR holds (leave some out with --drop NAME)"};
  if (l.record_length > 65535)
    return Error{path + ": " + str(points.dimensions.count()) + " dimensions make a " + str(l.record_length) +
                 "-byte record, beyond LAS's 65535"};
  // A CRS given: GeoTIFF keys in a LAS 1.2 file where nothing else needs 1.4 and the keys can say it
  // (an EPSG code: what every LAS reader takes), else WKT, which needs 1.4.
  const bool needs14 = l.format >= 6 || (source && source->version_minor >= 4) || n > UINT32_MAX;
  const std::vector<LasVlr> given_keys = !crs_wkt.empty() && !needs14 ? lasGeoKeyRecords(crs_wkt) : std::vector<LasVlr>();
  const bool v14 = needs14 || (!crs_wkt.empty() && given_keys.empty());
  l.version_minor = v14 ? 4 : 2;
  // Bit 0: GPS time is adjusted standard time; bit 4 (1.4): the coordinate system is WKT.
  l.global_encoding = source ? static_cast<uint16_t>(source->global_encoding & (v14 ? 0x11 : 0x01)) : 0;
  // Point formats 6-10 take their coordinate system as WKT (LAS 1.4 R15: the bit must be set; PDAL
  // reports a file without it as an error), whatever the source said.
  if (l.format >= 6) l.global_encoding |= 0x10;
  l.file_source_id = source ? source->file_source_id : 0;
  // Formats 6-10 hold their CRS as WKT alone: GeoTIFF keys are made WKT (converters/las_crs.h).
  std::vector<LasVlr> crs = source && !source_crs_dropped ? source->vlrs : std::vector<LasVlr>();
  // The CRS given: as GeoTIFF keys in LAS 1.2, or as WKT in LAS 1.4. writePoints says what it
  // replaced, as for every format that keeps a CRS.
  if (!crs_wkt.empty()) {
    if (!given_keys.empty()) {
      crs = given_keys;
    } else {
      crs = {lasWktRecord(crs_wkt)};
      l.global_encoding |= 0x10;
    }
  } else if (l.format >= 6) {
    LasWktCrs wkt = lasWktCrs(crs, source && lasSaysWkt(*source));
    crs = std::move(wkt.records);
    l.crs_note = std::move(wkt.note);
  }
  for (const LasVlr& vlr : crs) {
    if (vlr.extended && v14) l.evlrs.push_back(vlr);
    else if (vlr.data.size() <= 65535) l.vlrs.push_back(vlr);
  }
  if (l.described > 0)
    l.vlrs.push_back(lasExtraBytesVlr({l.extra.begin(), l.extra.begin() + static_cast<ptrdiff_t>(l.described)}));
  return l;
}

// Whether the set's intensity is float 0..1 values (PTX's, or one normalised by another tool):
// every value from 0 to 1 and one between. LAS's intensity is a 16-bit integer normalised to the
// sensor's range (LAS 1.4 R15: multiplied by 65,536 over the sensor's dynamic range), so the
// writer takes such values as fractions of 65535. Whole numbers (0 and 1 alone too) are written as
// they are. `outside`: where some value lies between 0 and 1, the first point whose intensity is
// outside 0..1 (or NaN), which kept them from being fractions; else SIZE_MAX.
struct FractionIntensity {
  bool fractions = false;
  size_t outside = SIZE_MAX;
};
FractionIntensity intensityOfFractions(const PointSet& points, unsigned threads) {
  const Dimension* d = points.dimensions.find(dim::kIntensity);
  if (!d || !dimTypeIsFloat(d->type) || d->size() == 0) return {};
  constexpr size_t kBlock = size_t{1} << 16;
  std::vector<size_t> outside((d->size() + kBlock - 1) / kBlock, SIZE_MAX);
  std::vector<uint8_t> between(outside.size(), 0);
  parallelFor(outside.size(), threads, [&](size_t b, unsigned) {
    for (size_t i = b * kBlock, end = std::min(d->size(), i + kBlock); i < end; ++i) {
      const double v = d->value(i);
      if (!(v >= 0.0 && v <= 1.0)) {  // NaN too
        if (outside[b] == SIZE_MAX) outside[b] = i;
        continue;
      }
      between[b] |= v > 0.0 && v < 1.0 ? 1 : 0;
    }
  });
  if (std::find(between.begin(), between.end(), 1) == between.end()) return {};
  const size_t first = *std::min_element(outside.begin(), outside.end());
  return {first == SIZE_MAX, first};
}

// Encodes point i of a set into a record of the layout's format. `intensity`: whether the
// intensity is 0..1 values (intensityOfFractions), written as round(v · 65535).
class RecordEncoder {
 public:
  RecordEncoder(const PointSet& points, const WriterLayout& l, const glm::dvec3& offset, const glm::dvec3& scale,
                const FractionIntensity& intensity)
      : points_(points), offset_(offset), scale_(scale), format_(l.format), intensity_outside_(intensity.outside) {
    for (const LasField& f : lasFields(l.format)) {
      Slot slot{f.type, f.offset, f.shift, f.bits, points.dimensions.find(f.name), Convert::kNone};
      if (intensity.fractions && slot.source && std::strcmp(f.name, dim::kIntensity) == 0) {
        slot.convert = Convert::kFractionToWord;
      } else if (!slot.source && std::strcmp(f.name, dim::kScanAngleRank) == 0) {
        slot.source = points.dimensions.find(dim::kScanAngle);
        slot.convert = Convert::kAngleToRank;
      } else if (!slot.source && std::strcmp(f.name, dim::kScanAngle) == 0) {
        slot.source = points.dimensions.find(dim::kScanAngleRank);
        slot.convert = Convert::kRankToAngle;
      }
      // A set without returns was one return a pulse: 1 of 1, as LAS readers expect.
      slot.missing = std::strcmp(f.name, dim::kReturnNumber) == 0 || std::strcmp(f.name, dim::kNumberOfReturns) == 0 ? 1 : 0;
      slot.check = slot.source && slot.convert == Convert::kNone && !dimTypeIsFloat(f.type) &&
                   !widens(slot.source->type, f.type);
      slot.whole64 = slot.source && slot.convert == Convert::kNone && isWhole64(f.type) &&
                     isWhole64(slot.source->type) && slot.source->type != f.type;
      slots_.push_back(slot);
    }
    for (const LasExtraField& e : l.extra) {
      Slot slot{e.type, l.base_length + e.offset, 0, 0, &points.dimensions.all()[e.dimension],
                e.scaled ? Convert::kScaled : Convert::kNone};
      slot.field = &e;  // each value fits its scale (lasSourceExtraField)
      slots_.push_back(slot);
    }
    rgb_at_ = points.hasColors() ? lasRgbOffset(l.format) : 0;
    // 8-bit values where the colours came from a LAS file that had them (PLY or CSV 8-bit colours
    // are scaled to 16 bits, as the specification asks).
    color_scale_ = points.color_full_scale == 255 && points.las ? 255.0 : 65535.0;
    return_number_ = points.dimensions.find(dim::kReturnNumber);
    returns_ = l.format >= 6 ? 15 : 5;
  }

  // Encodes point i; false where one of its values does not fit its field (misfit(i) says which:
  // the record then holds it rounded and clamped, and is not to be written).
  bool encode(size_t i, char* r) const {
    const glm::dvec3& p = points_.positions[i];
    for (int k = 0; k < 3; ++k) storeUnaligned<int32_t>(r + 4 * k, static_cast<int32_t>(quantize(p[k], offset_[k], scale_[k])));
    bool fits = true;
    for (const Slot& s : slots_) {
      if (s.bits) {
        uint32_t v = s.missing;
        if (s.source) {  // fitsSlot without a call to floor: whole and in range where v is the value
          const double value = s.source->value(i);
          v = value >= 0.0 && value <= 255.0 ? static_cast<uint32_t>(value) : value > 255.0 ? 255u : 0u;
          fits &= static_cast<double>(v) == value && v < (1u << s.bits);
        }
        r[s.offset] = static_cast<char>(static_cast<uint8_t>(r[s.offset]) | ((v & ((1u << s.bits) - 1)) << s.shift));
      } else if (!s.source) {
        if (s.missing) storeValue(r + s.offset, s.type, s.missing);
      } else if (s.convert == Convert::kAngleToRank) {
        storeValue(r + s.offset, s.type, std::clamp(s.source->value(i) * 0.006, -90.0, 90.0));
      } else if (s.convert == Convert::kRankToAngle) {
        storeValue(r + s.offset, s.type, s.source->value(i) / 0.006);
      } else if (s.convert == Convert::kScaled) {
        storeValue(r + s.offset, s.type, lasStoredNumber(*s.field, s.source->value(i)));
      } else if (s.convert == Convert::kFractionToWord) {  // 0..1, so no clamping
        storeUnaligned<uint16_t>(r + s.offset, static_cast<uint16_t>(s.source->value(i) * 65535.0 + 0.5));
      } else if (s.source->type == s.type) {
        const size_t w = dimTypeSize(s.type);
        std::memcpy(r + s.offset, s.source->bytes.data() + i * w, w);
      } else if (s.whole64) {  // int64 into uint64 or back, as integers: a double rounds past 2^53
        uint64_t bits;
        std::memcpy(&bits, s.source->bytes.data() + i * 8, 8);
        fits &= bits <= static_cast<uint64_t>(std::numeric_limits<int64_t>::max());  // the sign bit clear both ways
        std::memcpy(r + s.offset, &bits, 8);
      } else {
        const double value = s.source->value(i);
        if (s.check) fits &= dimensionHolds(s.type, value);
        storeValue(r + s.offset, s.type, value);
      }
    }
    if (rgb_at_)
      for (int c = 0; c < 3; ++c) storeUnaligned<uint16_t>(r + rgb_at_ + 2 * c, colorInteger(points_.colors[i][c], color_scale_));
    return fits;
  }

  // Why point i's record would not hold its values: the first value that does not fit its field.
  std::string misfit(size_t i) const {
    for (const Slot& s : slots_) {
      if (!s.source || s.convert != Convert::kNone) continue;
      const double value = s.source->value(i);
      if (fitsSlot(s, value)) continue;
      const int bits = s.bits ? s.bits : static_cast<int>(8 * dimTypeSize(s.type));
      const bool sign = !s.bits && dimTypeIsSigned(s.type);
      const std::string lo = sign ? num(-std::ldexp(1.0, bits - 1)) : "0";
      const std::string hi = std::to_string(bits == 64 && !sign ? UINT64_MAX : (uint64_t{1} << (bits - sign)) - 1);
      const std::string what = s.bits ? std::to_string(bits) + (bits == 1 ? " bit" : " bits") : dimTypeName(s.type);
      std::string why = "point " + str(i) + ": " + s.source->name + " = " + num(value) + " does not fit LAS point format " +
                        std::to_string(format_) + "'s " + s.source->name + ", a whole number " + lo + ".." + hi + " (" +
                        what + "); leave it out with --drop " + s.source->name;
      if (intensity_outside_ != SIZE_MAX && std::strcmp(s.source->name.c_str(), dim::kIntensity) == 0)
        why += " (an intensity of 0..1 values is written as fractions of 65535, but point " + str(intensity_outside_) +
               "'s is " + num(s.source->value(intensity_outside_)) + ")";
      return why;
    }
    return "point " + str(i) + ": a value does not fit its field";
  }

  // Points by return number 1..15 (1..5 in formats 0-5), for the header.
  std::array<uint64_t, 15> countByReturn(unsigned threads) const {
    std::array<uint64_t, 15> counts{};
    const size_t n = points_.size();
    if (!return_number_) {
      counts[0] = n;
      return counts;
    }
    const size_t blocks = (n + kWriteBlockPoints - 1) / kWriteBlockPoints;
    std::vector<std::array<uint64_t, 16>> partial(blocks);
    parallelFor(blocks, threads, [&](size_t b, unsigned) {
      partial[b] = {};
      for (size_t i = b * kWriteBlockPoints, end = std::min(n, i + kWriteBlockPoints); i < end; ++i)
        ++partial[b][static_cast<size_t>(std::clamp(return_number_->value(i), 0.0, 15.0))];
    });
    for (const auto& part : partial)
      for (size_t r = 1; r <= returns_; ++r) counts[r - 1] += part[r];
    return counts;
  }

 private:
  enum class Convert { kNone, kAngleToRank, kRankToAngle, kScaled, kFractionToWord };
  struct Slot {
    DimType type;
    uint32_t offset;
    uint8_t shift, bits;
    const Dimension* source;
    Convert convert;
    uint32_t missing = 0;  // the value where the set lacks the dimension
    bool check = false;    // whether a value of the source may not fit this integer field
    bool whole64 = false;  // int64 into uint64 or back: copied as integers
    const LasExtraField* field = nullptr;  // kScaled: its scale and offset (lasStoredNumber)
  };

  static bool isWhole64(DimType type) { return type == DimType::kI64 || type == DimType::kU64; }

  // Whether every value of type `from` is one of integer type `to` (a widening: no check needed).
  static bool widens(DimType from, DimType to) {
    if (dimTypeIsFloat(from)) return false;
    const int bits = static_cast<int>(8 * dimTypeSize(from));
    const double lo = dimTypeIsSigned(from) ? -std::ldexp(1.0, bits - 1) : 0.0;
    const double hi = std::ldexp(1.0, dimTypeIsSigned(from) ? bits - 1 : bits) - 1.0;
    return dimensionHolds(to, lo) && dimensionHolds(to, hi);
  }

  // Whether the field holds the value as it is: a whole number in its bits' or its type's range
  // (any number for a float field). A conversion between the two scan-angle fields rounds by design.
  static bool fitsSlot(const Slot& s, double value) {
    if (s.convert != Convert::kNone) return true;
    if (s.bits) return value >= 0.0 && value <= double((1u << s.bits) - 1) && value == std::floor(value);
    return dimTypeIsFloat(s.type) || dimensionHolds(s.type, value);
  }

  const PointSet& points_;
  glm::dvec3 offset_, scale_;
  int format_;
  size_t intensity_outside_;  // intensityOfFractions' `outside`, for misfit's word
  std::vector<Slot> slots_;
  uint32_t rgb_at_ = 0;
  double color_scale_ = 65535.0;
  const Dimension* return_number_ = nullptr;
  size_t returns_ = 5;
};

}  // namespace

uint32_t lasBaseRecordLength(int point_format) {
  assert(point_format >= 0 && point_format <= 10);
  return kBaseLength[static_cast<size_t>(point_format)];
}

bool lasFormatHasRgb(int point_format) {
  assert(point_format >= 0 && point_format <= 10);
  return lasRgbOffset(point_format) != 0;
}

double lasOffsetFor(double min, double scale) {
  assert(std::isfinite(min) && scale > 0);
  return scale <= 1.0 ? std::floor(min) : std::floor(min / scale) * scale;
}

glm::vec3 lasClassColor(uint8_t classification) {
  const uint32_t c = asprsClassColor(classification);
  return glm::vec3(float(c & 0xffu), float((c >> 8) & 0xffu), float((c >> 16) & 0xffu)) / 255.0f;
}

bool lasBoundsContain(const LasHeader& header, const Box& points) {
  for (int k = 0; k < 3; ++k) {
    const double slack = std::fabs(header.scale[k]) / 2;
    if (points.min[k] < header.min[k] - slack || points.max[k] > header.max[k] + slack) return false;
  }
  return true;
}


Result<LasHeader> readLasHeader(const std::string& path) {
  Result<InputFile> file = InputFile::open(path);
  if (!file) return file.error();
  return parseHeader(*file);
}

Result<PointSet> readLas(const std::string& path, const LasReadOptions& options) {
  Result<InputFile> file = InputFile::open(path);
  if (!file) return file.error();
  return readLas(*file, options);
}

namespace {


// The VLRs between the header and the points, and a 1.4 file's EVLRs after them. A list that runs
// past its room ends the list (the points are still read, as before VLRs were kept).
std::vector<LasVlr> readVlrs(const InputFile& file, const LasHeader& h) {
  std::vector<LasVlr> out;
  uint64_t at = h.header_size;
  for (uint32_t k = 0; k < h.vlr_count && at + kVlrHeaderBytes <= h.point_offset; ++k) {
    char v[kVlrHeaderBytes];
    Result<size_t> got = file.readAt(at, v, sizeof v);
    if (!got || *got < sizeof v) break;
    LasVlr vlr{textField(v + 2, 16), loadUnaligned<uint16_t>(v + 18), textField(v + 22, 32), {}, false};
    const uint16_t length = loadUnaligned<uint16_t>(v + 20);
    if (at + kVlrHeaderBytes + length > h.point_offset) break;
    vlr.data.resize(length);
    got = file.readAt(at + kVlrHeaderBytes, vlr.data.data(), length);
    if (!got || *got < length) break;
    out.push_back(std::move(vlr));
    at += kVlrHeaderBytes + length;
  }
  if (h.version_minor < 4 || h.evlr_count == 0) return out;
  char start[8];
  Result<size_t> got = file.readAt(kEvlrStartAt, start, sizeof start);
  if (!got || *got < sizeof start) return out;
  at = loadUnaligned<uint64_t>(start);
  for (uint32_t k = 0; k < h.evlr_count && at >= h.point_offset && file.size() >= kEvlrHeaderBytes &&
                      at <= file.size() - kEvlrHeaderBytes;
       ++k) {
    char v[kEvlrHeaderBytes];
    got = file.readAt(at, v, sizeof v);
    if (!got || *got < sizeof v) break;
    LasVlr vlr{textField(v + 2, 16), loadUnaligned<uint16_t>(v + 18), textField(v + 28, 32), {}, true};
    const uint64_t length = loadUnaligned<uint64_t>(v + 20);
    if (length > file.size() - at - kEvlrHeaderBytes || length > (uint64_t{1} << 30)) break;
    vlr.data.resize(static_cast<size_t>(length));
    got = file.readAt(at + kEvlrHeaderBytes, vlr.data.data(), vlr.data.size());
    if (!got || *got < vlr.data.size()) break;
    out.push_back(std::move(vlr));
    at += kEvlrHeaderBytes + length;
  }
  return out;
}

bool isExtraBytesRecord(const LasVlr& vlr) { return vlr.user_id == "LASF_Spec" && vlr.record_id == 4; }

// The extra bytes of a record of `header`'s format, as the file's extra bytes record describes
// them; where that record cannot be followed, the bytes as they are, one field a byte, and a
// notice that says why (a reader that refused such files would refuse their points too).
std::vector<LasExtraField> extraFieldsOf(const std::string& path, const LasHeader& header,
                                         const std::vector<LasVlr>& vlrs, std::vector<std::string>* notices) {
  const LasVlr* extra_vlr = nullptr;
  for (const LasVlr& vlr : vlrs)
    if (isExtraBytesRecord(vlr)) extra_vlr = &vlr;
  const uint32_t extra_bytes = header.record_length - lasBaseRecordLength(header.point_format);
  const std::vector<LasField> base = lasFields(header.point_format);
  Result<std::vector<LasExtraField>> extra = lasExtraFields(extra_vlr, extra_bytes, base);
  if (extra) return std::move(*extra);
  if (notices)
    notices->push_back(path + ": " + extra.error().message + "; its " + str(uint64_t{extra_bytes}) +
                       " extra bytes a point are read as they are (extra_byte_0, ...)");
  return *lasExtraFields(nullptr, extra_bytes, base);  // without a record it cannot fail
}

}  // namespace

Result<std::vector<LasVlr>> readLasCrsRecords(const InputFile& file) {
  Result<LasHeader> header = parseHeader(file);
  if (!header) return header.error();
  std::vector<LasVlr> crs;
  for (LasVlr& vlr : readVlrs(file, *header))
    if (isLasCrsRecord(vlr)) crs.push_back(std::move(vlr));
  return crs;
}

Result<PointSet> readLas(const InputFile& file, const LasReadOptions& options) {
  const std::string& path = file.path();
  Result<LasHeader> header = parseHeader(file);
  if (!header) return header.error();
  const bool rgb = lasFormatHasRgb(header->point_format);
  LasColorSource source = options.color;
  if (source == LasColorSource::kAuto) source = rgb ? LasColorSource::kRgb : LasColorSource::kNone;
  if (source == LasColorSource::kRgb && !rgb)
    return Error{path + ": point format " + str(static_cast<uint64_t>(header->point_format)) +
                 " has no RGB colours (formats 2, 3, 5, 7, 8 and 10 have)"};
  // The records' fields and extra bytes become dimensions; the coordinate system's records are
  // kept for the LAS writer.
  const std::vector<LasVlr> vlrs = readVlrs(file, *header);
  const std::vector<LasExtraField> extra = extraFieldsOf(path, *header, vlrs, options.notices);
  // The count is bounded by the file size already; the point set must also fit --max-memory.
  uint64_t point_bytes = sizeof(glm::dvec3) + (source == LasColorSource::kNone ? 0 : sizeof(glm::vec3));
  for (const LasField& f : lasFields(header->point_format)) point_bytes += dimTypeSize(f.type);
  for (const LasExtraField& f : extra) point_bytes += dimTypeSize(f.dimensionType());
  if (Status fits = checkMemory(path + ": " + str(header->point_count) + " points", header->point_count * point_bytes,
                                options.max_memory);
      !fits)
    return fits.error();
  // LAZ: the records decoded (on all cores) into memory after the header and VLRs, and read from
  // there as from a LAS file.
  LazRecords decoded;
  std::optional<InputFile> records;
  LasHeader plain = *header;
  if (header->compressed) {
    Result<LazRecords> bytes = decodeLazRecords(file, options.threads, options.max_memory, header->point_offset);
    if (!bytes) return bytes.error();
    decoded = std::move(*bytes);
    Result<size_t> got = file.readAt(0, decoded.bytes.data(), header->point_offset);
    if (!got) return got.error();
    if (*got != header->point_offset) return Error{path + ": the file ends before its offset to point data"};
    records.emplace(InputFile::fromMemory(path, decoded.view()));
    plain.compressed = false;
  }
  LasReader reader(records ? *records : file, plain, source, options, extra);
  Result<PointSet> points = reader.run();
  if (!points) return points;
  LasSource las;
  las.version_minor = header->version_minor;
  las.point_format = header->point_format;
  las.scale = header->scale;
  las.offset = header->offset;
  las.global_encoding = header->global_encoding;
  las.file_source_id = header->file_source_id;
  for (const LasVlr& vlr : vlrs)
    if (isLasCrsRecord(vlr)) las.vlrs.push_back(vlr);
  for (const LasExtraField& f : extra)
    if (!f.descriptor.empty()) las.extra_bytes.push_back({f.name, f.descriptor});
  points->las = std::move(las);
  return points;
}

// --- The stream ------------------------------------------------------------------------------------

struct LasPointStream::State {
  InputFile file;
  LasHeader header;
  std::vector<LasField> fields;
  std::vector<LasExtraField> extra;
  Dimensions dimensions;  // fields then extra, empty
  std::vector<size_t> streamed;
  std::vector<std::string> notices;
  unsigned threads = 0;
  uint64_t max_memory = 0;  // for the decoded chunks (checkMemory's limit; 0: its default)
  float color_divisor = 0.0f;  // 0: no colours
  // LAZ: the chunks, and the last chunks decoded (their records) for the next block.
  std::optional<LazChunks> laz;
  size_t cached_first = 0, cached_last = 0;  // chunks [first, last) in `cache`
  std::string cache;

  explicit State(InputFile f) : file(std::move(f)) {}

  // Records [first, first + n) into `out` (n · record length bytes).
  Status records(uint64_t first, uint64_t n, char* out) {
    const uint64_t length = header.record_length;
    if (!laz) {
      Result<size_t> got = file.readAt(header.point_offset + first * length, out, static_cast<size_t>(n * length));
      if (!got) return got.error();
      if (*got != n * length) return Error{file.path() + ": truncated: the file ends in point " + str(first + *got / length)};
      return okStatus();
    }
    Result<const char*> at = lazRecords(first, n);
    if (!at) return at.error();
    std::memcpy(out, *at, static_cast<size_t>(n * length));
    return okStatus();
  }

  // A LAZ file's records [first, first + n) (n > 0), decoded into `cache` where the last read did
  // not leave them there: valid until the next call.
  Result<const char*> lazRecords(uint64_t first, uint64_t n) {
    const uint64_t length = header.record_length;
    const std::vector<uint64_t>& starts = laz->first_point;
    // The chunks holding the first and the last point.
    const auto chunkOf = [&](uint64_t point) {
      return static_cast<size_t>(std::upper_bound(starts.begin(), starts.end(), point) - starts.begin()) - 1;
    };
    const size_t from = chunkOf(first), to = chunkOf(first + n - 1) + 1;
    if (from < cached_first || to > cached_last) {
      const uint64_t begin = starts[from], end = to < starts.size() ? starts[to] : header.point_count;
      // The chunks' claimed points, checked before they are allocated: a damaged chunk size had a
      // 98 KB file take 3.7 GB past --max-memory for the colour sample (a review finding).
      if (Status s = checkMemory(file.path() + ": decoding LAZ chunks " + str(from) + " to " + str(to - 1) + " (" +
                                     str(end - begin) + " points)",
                                 (end - begin) * length, max_memory);
          !s)
        return s.error();
      cache.resize(static_cast<size_t>((end - begin) * length));
      if (Status s = decodeLazChunks(file, *laz, from, to, cache.data(), threads); !s) return s.error();
      cached_first = from;
      cached_last = to;
    }
    return static_cast<const char*>(cache.data() + (first - starts[cached_first]) * length);
  }
};

LasPointStream::LasPointStream() = default;
LasPointStream::~LasPointStream() = default;

Result<std::unique_ptr<LasPointStream>> LasPointStream::open(const std::string& path, unsigned threads,
                                                             uint64_t max_memory) {
  Result<InputFile> file = InputFile::open(path);
  if (!file) return file.error();
  std::unique_ptr<LasPointStream> stream(new LasPointStream());
  stream->state_ = std::make_unique<State>(std::move(*file));
  State& st = *stream->state_;
  Result<LasHeader> header = parseHeader(st.file);
  if (!header) return header.error();
  st.header = *header;
  st.threads = resolveThreads(threads);
  st.max_memory = max_memory;
  st.fields = lasFields(st.header.point_format);
  st.extra = extraFieldsOf(path, st.header, readVlrs(st.file, st.header), &st.notices);
  st.dimensions.reserve(st.fields.size() + st.extra.size());
  for (const LasField& f : st.fields) st.dimensions.append(f.name, f.type, 0);
  for (const LasExtraField& f : st.extra) st.dimensions.append(f.name, f.dimensionType(), 0);
  if (st.header.compressed) {
    Result<LazChunks> chunks = openLazChunks(st.file);
    if (!chunks) return chunks.error();
    st.laz = std::move(*chunks);
  }
  // The colour divisor from a sample (the class comment says which).
  if (lasFormatHasRgb(st.header.point_format) && st.header.point_count > 0) {
    const uint64_t count = st.header.point_count, length = st.header.record_length;
    std::vector<std::pair<uint64_t, uint64_t>> ranges;  // first, n
    if (st.laz) {
      const std::vector<uint64_t>& starts = st.laz->first_point;
      for (size_t c : {size_t{0}, starts.size() / 2, starts.size() - 1}) {
        const uint64_t end = c + 1 < starts.size() ? starts[c + 1] : count;
        ranges.emplace_back(starts[c], std::min<uint64_t>(end - starts[c], 4096));  // the chunk is decoded whole
      }
    } else {
      for (uint64_t k = 0; k < 64; ++k) {
        const uint64_t first = count * k / 64;
        ranges.emplace_back(first, std::min<uint64_t>(64, count - first));
      }
    }
    const size_t rgb_at = lasRgbOffset(st.header.point_format);
    uint16_t largest = 0;
    std::string buffer;
    for (const auto& [first, n] : ranges) {
      buffer.resize(static_cast<size_t>(n * length));
      if (Status s = st.records(first, n, buffer.data()); !s) return s.error();
      for (uint64_t i = 0; i < n; ++i)
        for (size_t c = 0; c < 3; ++c)
          largest = std::max(largest, loadUnaligned<uint16_t>(buffer.data() + i * length + rgb_at + 2 * c));
    }
    st.color_divisor = largest > 255 ? 65535.0f : 255.0f;
  } else if (lasFormatHasRgb(st.header.point_format)) {
    st.color_divisor = 65535.0f;
  }
  return stream;
}

const LasHeader& LasPointStream::header() const { return state_->header; }
uint64_t LasPointStream::count() const { return state_->header.point_count; }
bool LasPointStream::hasColors() const { return state_->color_divisor != 0.0f; }
const Dimensions& LasPointStream::dimensions() const { return state_->dimensions; }
const std::vector<std::string>& LasPointStream::notices() const { return state_->notices; }
void LasPointStream::streamDimensions(std::vector<size_t> which) { state_->streamed = std::move(which); }

Status LasPointStream::read(uint64_t first, uint64_t n, PointSet& block) {
  State& st = *state_;
  const LasHeader& h = st.header;
  assert(first <= h.point_count && n <= h.point_count - first);
  const size_t count = static_cast<size_t>(n), length = h.record_length;
  block.triangles.clear();
  block.z_axis = ZAxis::kPresent;
  block.z_up = true;
  block.positions.resize(count);
  block.colors.resize(st.color_divisor != 0.0f ? count : 0);
  std::vector<const Dimension*> like;
  for (size_t k : st.streamed) like.push_back(&st.dimensions.all()[k]);
  block.dimensions.shapeUnset(like, count);  // unset: every row's field is copied below
  if (n == 0) return okStatus();
  std::vector<Dimension*> columns;
  for (Dimension& d : block.dimensions.all()) columns.push_back(&d);
  const size_t rgb_at = lasRgbOffset(h.point_format), extra_at = lasBaseRecordLength(h.point_format);
  // Points [from, to) of the block from their records at `p`.
  const auto decode = [&](const char* p, size_t from, size_t to) {
    for (size_t i = from; i < to; ++i, p += length) {
      block.positions[i] = recordPosition(p, h.scale, h.offset);
      if (st.color_divisor != 0.0f)
        block.colors[i] = glm::vec3(loadUnaligned<uint16_t>(p + rgb_at), loadUnaligned<uint16_t>(p + rgb_at + 2),
                                    loadUnaligned<uint16_t>(p + rgb_at + 4)) / st.color_divisor;
      for (size_t k = 0; k < st.streamed.size(); ++k) {
        const size_t index = st.streamed[k];
        if (index < st.fields.size()) copyField(st.fields[index], p, *columns[k], i);
        else {
          const LasExtraField& f = st.extra[index - st.fields.size()];
          copyExtra(f, p + extra_at + f.offset, *columns[k], i);
        }
      }
    }
  };
  const size_t chunk = size_t{1} << 15, chunks = (count + chunk - 1) / chunk;
  if (st.laz) {  // decoded on all cores into the chunk cache, then read from there
    Result<const char*> records = st.lazRecords(first, n);
    if (!records) return records.error();
    parallelFor(chunks, st.threads, [&](size_t c, unsigned) {
      decode(*records + c * chunk * length, c * chunk, std::min(count, (c + 1) * chunk));
    });
    return okStatus();
  }
  // Each core reads its pieces into its own buffer, for the whole read (fresh pages once a read and
  // core, not for every piece). Freed after the read: a stream of many files holds none between
  // reads (a review finding: kept, they grew with files × cores, past --max-memory).
  std::vector<std::string> buffers(parallelWorkers(chunks, st.threads));
  std::mutex failed;
  std::optional<Error> error;
  size_t error_chunk = SIZE_MAX;
  parallelFor(chunks, st.threads, [&](size_t c, unsigned worker) {
    const size_t from = c * chunk, to = std::min(count, from + chunk);
    std::string& buffer = buffers[worker];
    buffer.resize((to - from) * length);
    if (Status s = st.records(first + from, to - from, buffer.data()); !s) {
      std::lock_guard<std::mutex> lock(failed);
      if (c < error_chunk) error_chunk = c, error = s.error();
      return;
    }
    decode(buffer.data(), from, to);
  });
  if (error) return *error;
  return okStatus();
}

Status writeLas(const std::string& path, const PointSet& points, const LasWriteOptions& options) {
  // The scale: as asked, else the source LAS file's per axis, else 0.001.
  if (options.scale != 0.0 && !(std::isfinite(options.scale) && options.scale > 0.0))
    return Error{path + ": LAS scale " + num(options.scale) + " is not a finite number > 0", ExitCode::kUsage};
  const bool keep_frame = options.scale == 0.0 && points.las;
  glm::dvec3 scale = options.scale > 0.0 ? glm::dvec3(options.scale)
                     : keep_frame       ? glm::abs(points.las->scale)
                                        : glm::dvec3(0.001);  // chosen from the data below
  const size_t n = points.size();
  assert(points.colors.empty() || points.colors.size() == n);
  const unsigned threads = resolveThreads(options.threads);
  const size_t blocks = (n + kWriteBlockPoints - 1) / kWriteBlockPoints;

  // The bounding box, and the first non-finite point (each block stops at its own first one).
  std::vector<Box> block_box(blocks);
  std::vector<size_t> block_bad(blocks, SIZE_MAX);
  parallelFor(blocks, threads, [&](size_t b, unsigned) {
    const size_t first = b * kWriteBlockPoints, last = std::min(n, first + kWriteBlockPoints);
    Box box{points.positions[first], points.positions[first]};
    for (size_t i = first; i < last; ++i) {
      const glm::dvec3& p = points.positions[i];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        block_bad[b] = i;
        return;
      }
      box.min = glm::min(box.min, p);
      box.max = glm::max(box.max, p);
    }
    block_box[b] = box;
  });
  size_t bad = SIZE_MAX;
  for (size_t first_bad : block_bad) bad = std::min(bad, first_bad);
  if (bad != SIZE_MAX) {
    const glm::dvec3& p = points.positions[bad];
    return Error{path + ": point " + str(bad) + " (" + num(p.x) + ", " + num(p.y) + ", " + num(p.z) +
                 ") is not finite; LAS stores finite coordinates only"};
  }
  Box box;
  for (size_t b = 0; b < blocks; ++b) {
    box.min = b == 0 ? block_box[b].min : glm::min(box.min, block_box[b].min);
    box.max = b == 0 ? block_box[b].max : glm::max(box.max, block_box[b].max);
  }

  // Quantization is monotonic (a subtraction, a division by a positive number and a rounding, each
  // correctly rounded), so the box's corners hold the extreme integers: when they fit, all do, and
  // their decoded values are the exact bounds a reader finds.
  glm::bvec3 rounded(false);
  if (options.scale == 0.0 && !keep_frame && n > 0)
    for (int k = 0; k < 3; ++k) scale[k] = chooseAxisScale(points.positions, k, box.min[k], box.max[k], threads, rounded[k]);
  // The source's offset where its integers still hold every point (LAS → LAS: the same records).
  glm::dvec3 offset(0.0), q_min(0.0), q_max(0.0);
  for (int k = 0; k < 3; ++k) {
    const double kept = keep_frame ? points.las->offset[k] : 0.0;
    const bool fits_kept = keep_frame && fitsInt32(quantize(box.min[k], kept, scale[k])) &&
                           fitsInt32(quantize(box.max[k], kept, scale[k]));
    offset[k] = fits_kept ? kept : chooseOffset(points.positions, k, box.min[k], box.max[k], scale[k], threads);
    q_min[k] = quantize(box.min[k], offset[k], scale[k]);
    q_max[k] = quantize(box.max[k], offset[k], scale[k]);
  }
  for (int k = 0; k < 3; ++k)
    if (!frameIsFinite(scale[k], offset[k]))
      return Error{path + ": " + kAxis[k] + " spans " + num(box.min[k]) + " .. " + num(box.max[k]) +
                   ": at the scale " + num(scale[k]) + " and offset " + num(offset[k]) +
                   " LAS's 32-bit integers reach beyond double's range, which no reader takes; a LAS file cannot "
                   "hold coordinates this large"};
  const bool fits = fitsInt32(q_min.x) && fitsInt32(q_min.y) && fitsInt32(q_min.z) && fitsInt32(q_max.x) &&
                    fitsInt32(q_max.y) && fitsInt32(q_max.z);
  for (size_t i = 0; !fits && i < n; ++i) {  // names the first point that does not fit
    for (int k = 0; k < 3; ++k) {
      const double q = quantize(points.positions[i][k], offset[k], scale[k]);
      if (!fitsInt32(q))
        return Error{path + ": point " + str(i) + ": " + kAxis[k] + " = " + num(points.positions[i][k]) + " is " +
                     num(q) + " steps of the scale " + num(scale[k]) + " from the offset " + num(offset[k]) +
                     ", beyond LAS's 32-bit integers (±2147483647); use a larger scale (--las-scale)"};
    }
  }
  assert(fits);
  glm::dvec3 bound_min(0.0), bound_max(0.0);
  for (int k = 0; k < 3; ++k) {  // what a reader computes for the extreme integers
    bound_min[k] = n == 0 ? 0.0 : q_min[k] * scale[k] + offset[k];
    bound_max[k] = n == 0 ? 0.0 : q_max[k] * scale[k] + offset[k];
  }

  if (options.report) {
    options.report->scale = scale;
    // Points that read back as themselves cannot merge: the count's two sorts only run otherwise.
    // With the source's scale, each axis: a coordinate off its grid (a review finding: positions
    // moved in Python by less than a step were rounded back without a word).
    bool exact = true;
    for (int k = 0; k < 3 && (exact || keep_frame); ++k) {
      const bool axis = readsBackExactly(points.positions, k, offset[k], scale[k], threads);
      if (keep_frame && !axis) rounded[k] = true;
      exact = exact && axis;
    }
    options.report->merged_points = exact ? 0 : mergedPoints(points.positions, scale, offset, threads);
    if (interrupted()) return interruptedError();
    options.report->rounded = rounded;
    options.report->source_scale = keep_frame;
  }
  Result<WriterLayout> layout = writerLayout(path, points, n, options.compress, options.las14, options.crs_wkt,
                                            options.source_crs_dropped, threads);
  if (!layout) return layout.error();
  WriterLayout& l = *layout;
  if (options.report) {
    options.report->renamed = l.renamed;
    options.report->crs = l.crs_note.empty() || !options.crs_wkt.empty()
                              ? l.crs_note
                              : "point format " + std::to_string(l.format) + " holds its CRS as WKT: " + l.crs_note;
  }
  std::optional<LazInfo> laz;
  if (options.compress) {
    Result<LazInfo> info = lazInfoForFormat(l.format, l.record_length);
    if (!info) return Error{path + ": " + info.error().message};
    laz = std::move(*info);
    l.vlrs.push_back(LasVlr{"laszip encoded", 22204, "dpoint LAZ (LASzip 3.4 format)", laszipVlrData(*laz), false});
  }
  const FractionIntensity intensity = intensityOfFractions(points, threads);
  if (options.report) options.report->intensity_scaled = intensity.fractions;
  const RecordEncoder encoder(points, l, offset, scale, intensity);
  std::string vlr_bytes;
  for (const LasVlr& vlr : l.vlrs) vlr_bytes += vlrBytes(vlr, false);
  const uint32_t point_offset = static_cast<uint32_t>((l.version_minor >= 4 ? kHeaderSize14 : kHeaderSize12) + vlr_bytes.size());
  // The bytes go to the file, or to options.memory (COPC reorganises a whole LAS 1.4 file).
  std::optional<AtomicFile> file;
  if (!options.memory) {
    Result<AtomicFile> created = AtomicFile::create(path);
    if (!created) return created.error();
    file.emplace(std::move(*created));
    // A LAS file's size; a LAZ file's is not known before its chunks are compressed.
    if (!laz)
      if (Status s = file->checkSpace(point_offset + uint64_t{n} * l.record_length); !s) return s;
  } else if (!laz) {
    // Its whole size at once: grown by appends, the string copied itself at each doubling (18% of a
    // COPC write of 8.4M points).
    size_t evlr_bytes = 0;
    for (const LasVlr& evlr : l.evlrs) evlr_bytes += kEvlrHeaderBytes + evlr.data.size();
    options.memory->reserve(options.memory->size() + point_offset + size_t{n} * l.record_length + evlr_bytes);
  }
  const auto write = [&](const void* data, size_t size) -> Status {
    if (!file) {
      if (interrupted()) return interruptedError();
      options.memory->append(static_cast<const char*>(data), size);
      return okStatus();
    }
    return file->write(data, size);
  };
  if (options.progress) options.progress->start((laz ? "compressing " : "writing ") + path, n);
  // Each block's first point whose values do not fit their fields (the blocks of a batch run at
  // once): the file is then refused, naming the first such point.
  const auto encodeRecords = [&](size_t first, size_t last, std::vector<char>& out) -> size_t {
    out.assign((last - first) * l.record_length, 0);
    char* r = out.data();
    size_t misfit = SIZE_MAX;
    for (size_t i = first; i < last; ++i, r += l.record_length)
      if (!encoder.encode(i, r) && misfit == SIZE_MAX) misfit = i;
    return misfit;
  };
  const auto refuse = [&](std::vector<size_t>& misfits) -> Status {
    const size_t first = *std::min_element(misfits.begin(), misfits.end());
    std::fill(misfits.begin(), misfits.end(), SIZE_MAX);
    if (first == SIZE_MAX) return okStatus();
    return Error{path + ": " + encoder.misfit(first)};
  };

  if (laz) {
    // Chunks compressed a batch at a time on all cores, kept until every size is known.
    const size_t chunk_count = (n + kLazChunkPoints - 1) / kLazChunkPoints;
    std::vector<std::vector<uint8_t>> coded(chunk_count);
    std::vector<std::vector<char>> records(threads);
    std::vector<size_t> misfits(2 * size_t{threads}, SIZE_MAX);
    for (size_t batch = 0; batch < chunk_count; batch += 2 * size_t{threads}) {
      const size_t batch_chunks = std::min<size_t>(2 * size_t{threads}, chunk_count - batch);
      parallelFor(batch_chunks, threads, [&](size_t j, unsigned worker) {
        const size_t c = batch + j, first = c * kLazChunkPoints, last = std::min(n, first + kLazChunkPoints);
        misfits[j] = encodeRecords(first, last, records[worker]);
        if (misfits[j] == SIZE_MAX) coded[c] = encodeLazChunk(*laz, records[worker].data(), last - first);
      });
      if (Status s = refuse(misfits); !s) return s;
      if (interrupted()) return interruptedError();
      if (options.progress) options.progress->advance(std::min(n, (batch + batch_chunks) * kLazChunkPoints) - batch * kLazChunkPoints);
    }
    std::vector<LazChunk> chunks(chunk_count);
    uint64_t at = uint64_t{point_offset} + 8;
    for (size_t c = 0; c < chunk_count; ++c) {
      if (coded[c].empty())
        return Error{path + ": point format " + std::to_string(l.format) + " is not written as LAZ yet"};
      chunks[c] = {at, coded[c].size(), std::min<uint64_t>(kLazChunkPoints, n - c * kLazChunkPoints)};
      at += coded[c].size();
    }
    const std::string table = encodeLazChunkTable(*laz, chunks);
    std::string header = writerHeader(l, n, encoder.countByReturn(threads), scale, offset, bound_min, bound_max,
                                      point_offset, at + table.size());
    header[kFormatAt] = static_cast<char>(l.format | 0x80);  // LASzip's mark of compressed records
    char table_at[8];
    storeUnaligned<int64_t>(table_at, static_cast<int64_t>(at));
    for (const std::string_view piece : {std::string_view(header), std::string_view(vlr_bytes), std::string_view(table_at, 8)})
      if (Status s = write(piece.data(), piece.size()); !s) return s;
    for (const std::vector<uint8_t>& c : coded)
      if (Status s = write(c.data(), c.size()); !s) return s;
    if (Status s = write(table.data(), table.size()); !s) return s;
  } else {
    const uint64_t evlr_start = point_offset + uint64_t{n} * l.record_length;
    const std::string header = writerHeader(l, n, encoder.countByReturn(threads), scale, offset, bound_min, bound_max,
                                            point_offset, evlr_start);
    if (Status s = write(header.data(), header.size()); !s) return s;
    if (Status s = write(vlr_bytes.data(), vlr_bytes.size()); !s) return s;
    // Blocks are encoded on all cores a batch at a time, then written in order.
    std::vector<std::vector<char>> encoded(static_cast<size_t>(threads) * 4);
    std::vector<size_t> misfits(encoded.size(), SIZE_MAX);
    for (size_t batch = 0; batch < blocks; batch += encoded.size()) {
      const size_t batch_blocks = std::min(encoded.size(), blocks - batch);
      parallelFor(batch_blocks, threads, [&](size_t j, unsigned) {
        const size_t first = (batch + j) * kWriteBlockPoints, last = std::min(n, first + kWriteBlockPoints);
        misfits[j] = encodeRecords(first, last, encoded[j]);
      });
      if (Status s = refuse(misfits); !s) return s;
      for (size_t j = 0; j < batch_blocks; ++j) {
        if (Status s = write(encoded[j].data(), encoded[j].size()); !s) return s;
        if (options.progress) options.progress->advance(encoded[j].size() / l.record_length);
      }
    }
  }
  for (const LasVlr& evlr : l.evlrs) {
    const std::string bytes = vlrBytes(evlr, true);
    if (Status s = write(bytes.data(), bytes.size()); !s) return s;
  }
  if (file)
    if (Status s = file->commit(); !s) return s;
  if (options.progress) options.progress->finish();
  return okStatus();
}

namespace {

// Digits after the point in v's shortest round-trip decimal form.
int shortestDecimals(double v) {
  char text[400];
  const std::to_chars_result r = std::to_chars(text, text + sizeof text, v, std::chars_format::fixed);
  assert(r.ec == std::errc());
  const char* point = std::find(text, r.ptr, '.');
  return point == r.ptr ? 0 : static_cast<int>(r.ptr - point - 1);
}

}  // namespace

int lasStepDecimals(const LasHeader& header) {
  int decimals = 0;
  for (int k = 0; k < 3; ++k)
    decimals = std::max({decimals, shortestDecimals(header.scale[k]), shortestDecimals(header.offset[k])});
  return decimals > 17 ? -1 : decimals;
}

}  // namespace dpoint
