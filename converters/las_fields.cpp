#include "converters/las_fields.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <iterator>
#include <optional>
#include <string_view>
#include <unordered_set>

#include "core/bytes.h"
#include "core/parallel.h"

namespace dpoint {
namespace {

using T = DimType;

// Fields common to formats 0-5 (table 7), then each format's additions.
std::vector<LasField> legacyFields(bool gps, uint32_t wave_at) {
  std::vector<LasField> f = {
      {dim::kIntensity, T::kU16, 12},
      {dim::kReturnNumber, T::kU8, 14, 0, 3},
      {dim::kNumberOfReturns, T::kU8, 14, 3, 3},
      {dim::kScanDirection, T::kU8, 14, 6, 1},
      {dim::kEdgeOfFlightLine, T::kU8, 14, 7, 1},
      {dim::kClassification, T::kU8, 15, 0, 5},
      {dim::kSynthetic, T::kU8, 15, 5, 1},
      {dim::kKeyPoint, T::kU8, 15, 6, 1},
      {dim::kWithheld, T::kU8, 15, 7, 1},
      {dim::kScanAngleRank, T::kI8, 16},
      {dim::kUserData, T::kU8, 17},
      {dim::kPointSourceId, T::kU16, 18},
  };
  if (gps) f.push_back({dim::kGpsTime, T::kF64, 20});
  if (wave_at) {
    for (const LasField& w : std::initializer_list<LasField>{
             {dim::kWavePacketIndex, T::kU8, 0}, {dim::kWaveByteOffset, T::kU64, 1}, {dim::kWavePacketSize, T::kU32, 9},
             {dim::kWaveReturnLocation, T::kF32, 13}, {dim::kWaveXt, T::kF32, 17}, {dim::kWaveYt, T::kF32, 21},
             {dim::kWaveZt, T::kF32, 25}})
      f.push_back({w.name, w.type, wave_at + w.offset});
  }
  return f;
}

// Formats 6-10 (table 12), then NIR and the waveform fields where the format has them.
std::vector<LasField> modernFields(uint32_t nir_at, uint32_t wave_at) {
  std::vector<LasField> f = {
      {dim::kIntensity, T::kU16, 12},
      {dim::kReturnNumber, T::kU8, 14, 0, 4},
      {dim::kNumberOfReturns, T::kU8, 14, 4, 4},
      {dim::kSynthetic, T::kU8, 15, 0, 1},
      {dim::kKeyPoint, T::kU8, 15, 1, 1},
      {dim::kWithheld, T::kU8, 15, 2, 1},
      {dim::kOverlap, T::kU8, 15, 3, 1},
      {dim::kScannerChannel, T::kU8, 15, 4, 2},
      {dim::kScanDirection, T::kU8, 15, 6, 1},
      {dim::kEdgeOfFlightLine, T::kU8, 15, 7, 1},
      {dim::kClassification, T::kU8, 16},
      {dim::kUserData, T::kU8, 17},
      {dim::kScanAngle, T::kI16, 18},
      {dim::kPointSourceId, T::kU16, 20},
      {dim::kGpsTime, T::kF64, 22},
  };
  if (nir_at) f.push_back({dim::kNir, T::kU16, nir_at});
  if (wave_at) {
    std::vector<LasField> w = legacyFields(false, wave_at);
    f.insert(f.end(), w.end() - 7, w.end());
  }
  return f;
}

const std::array<std::vector<LasField>, 11>& allFields() {
  static const std::array<std::vector<LasField>, 11> fields = {
      legacyFields(false, 0), legacyFields(true, 0),  legacyFields(false, 0), legacyFields(true, 0),
      legacyFields(true, 28), legacyFields(true, 34), modernFields(0, 0),     modernFields(0, 0),
      modernFields(36, 0),    modernFields(0, 30),    modernFields(36, 38)};
  return fields;
}

constexpr std::array<uint32_t, 11> kRgbAt = {0, 0, 20, 28, 0, 28, 0, 30, 30, 0, 30};
// Where a descriptor's name, minimum, maximum, scale and offset start (LAS 1.4 R15 table 24).
constexpr size_t kNameAt = 4, kMinAt = 64, kMaxAt = 88, kScaleAt = 112, kOffsetAt = 136;

// The scale and offset of element e of the descriptor at d into `field`: options bit 3 (scale) and
// bit 4 (offset). A scale of 0 or one not finite (or such an offset) says nothing: the field is
// then read as stored, as where neither bit is set.
void takeScaling(const char* d, uint32_t e, LasExtraField& field) {
  const uint8_t options = static_cast<uint8_t>(d[3]);
  const double scale = options & 0x08 ? loadUnaligned<double>(d + kScaleAt + 8 * e) : 1.0;
  const double offset = options & 0x10 ? loadUnaligned<double>(d + kOffsetAt + 8 * e) : 0.0;
  if ((options & 0x18) && std::isfinite(scale) && scale != 0.0 && std::isfinite(offset)) {
    field.scaled = true;
    field.value_scale = scale, field.value_offset = offset;
  }
}

bool hasField(int format, const std::string& name) {
  const std::vector<LasField>& fields = lasFields(format);
  return std::any_of(fields.begin(), fields.end(), [&](const LasField& f) { return name == f.name; });
}

// The largest value of a dimension (0 when absent or empty).
double largest(const PointSet& points, const char* name) {
  const Dimension* d = points.dimensions.find(name);
  double m = 0.0;
  if (d)
    for (size_t i = 0; i < d->size(); ++i) m = std::max(m, d->value(i));
  return m;
}

// The largest class and return numbers of a set: what formats 0-5's narrower fields must hold.
struct Widest {
  double classification = 0.0, returns = 0.0;
};

// Whether format `f` holds every LAS field and value of the set.
bool holds(const PointSet& points, const Widest& widest, int f) {
  if (points.hasColors() && !kRgbAt[static_cast<size_t>(f)]) return false;
  for (const Dimension& d : points.dimensions.all()) {
    const KnownDimension* known = findKnownDimension(d.name);
    if (!known || !known->las_field) continue;  // extra bytes in any format
    // The angle in 0.006° steps only formats 6-10 hold as it is (a legacy format's whole degrees
    // of ±90 rounded and clamped it without a word: a review finding); either holds the rank.
    if (d.name == dim::kScanAngle && f < 6) return false;
    const bool scan_angle = d.name == dim::kScanAngle || d.name == dim::kScanAngleRank;
    if (!scan_angle && !hasField(f, d.name)) return false;
  }
  return f >= 6 || (widest.classification <= 31 && widest.returns <= 7);  // the narrower legacy fields
}

// Whether format `f` has a field the set lacks that a smaller format leaves out (colours, a legacy
// format's GPS time, NIR, the wave packets): the source's format is then not kept, so that
// --no-colors or --drop gps_time leave the field out instead of writing zeros (a review finding).
bool lacksFields(const PointSet& points, int f) {
  if (kRgbAt[static_cast<size_t>(f)] && !points.hasColors()) return true;
  for (const LasField& field : lasFields(f)) {
    const std::string_view name = field.name;
    const bool optional = (name == dim::kGpsTime && f < 6) || name == dim::kNir || name.rfind("wave_", 0) == 0;
    if (optional && !points.dimensions.find(field.name)) return true;
  }
  return false;
}

}  // namespace

const std::vector<LasField>& lasFields(int point_format) { return allFields().at(static_cast<size_t>(point_format)); }

uint32_t lasRgbOffset(int point_format) { return kRgbAt.at(static_cast<size_t>(point_format)); }

Result<std::vector<LasExtraField>> lasExtraFields(const LasVlr* vlr, uint32_t extra, const std::vector<LasField>& base) {
  std::vector<LasExtraField> out;
  std::vector<bool> described(extra, false);
  // Names in use, in a set: a record may carry 65,000 extra bytes (the fuzz target found one whose
  // pairwise name checks took seconds).
  std::unordered_set<std::string> taken = {"x", "y", "z", "red", "green", "blue"};
  for (const LasField& f : base) taken.insert(f.name);
  auto unique = [&](const std::string& name) -> std::string {
    std::string candidate = name;
    for (int n = 2; taken.count(candidate); ++n) {
      candidate = name;
      candidate += '_';
      candidate += std::to_string(n);
    }
    taken.insert(candidate);
    return candidate;
  };
  uint32_t at = 0;
  if (vlr) {
    if (vlr->data.size() % kExtraBytesDescriptorBytes != 0)
      return Error{"extra bytes VLR: " + std::to_string(vlr->data.size()) + " bytes are not whole 192-byte descriptors"};
    for (size_t k = 0; k * kExtraBytesDescriptorBytes < vlr->data.size(); ++k) {
      const char* d = vlr->data.data() + k * kExtraBytesDescriptorBytes;
      const uint8_t data_type = static_cast<uint8_t>(d[2]), options = static_cast<uint8_t>(d[3]);
      std::string name(d + 4, strnlen(d + 4, 32));
      // Types 1-10 are one value; 11-20 and 21-30 (deprecated) two and three of them, kept as
      // NAME_0, NAME_1, …; 0 is `options` undocumented bytes.
      uint32_t size = 0, elements = 0;
      std::optional<DimType> type;
      if (data_type == 0) {
        size = options;
      } else if (data_type <= 30) {
        type = static_cast<DimType>((data_type - 1) % 10);
        elements = data_type <= 10 ? 1 : data_type <= 20 ? 2 : 3;
        size = static_cast<uint32_t>(dimTypeSize(*type)) * elements;
      } else {
        return Error{"extra bytes descriptor " + std::to_string(k) + " ('" + name + "'): data type " +
                     std::to_string(data_type) + " is not one of LAS's 0 to 30"};
      }
      if (at + size > extra)
        return Error{"extra bytes descriptor " + std::to_string(k) + " ('" + name + "'): its " + std::to_string(size) +
                     " bytes at " + std::to_string(at) + " pass the record's " + std::to_string(extra) + " extra bytes"};
      for (char& c : name)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) c = '_';
      if (name.empty()) name = "extra";
      if (type) {
        const uint32_t width = static_cast<uint32_t>(dimTypeSize(*type));
        for (uint32_t e = 0; e < elements; ++e) {
          LasExtraField field{unique(elements == 1 ? name : name + "_" + std::to_string(e)), *type, at + e * width};
          takeScaling(d, e, field);
          if (elements == 1) field.descriptor.assign(d, kExtraBytesDescriptorBytes);
          out.push_back(std::move(field));
        }
        std::fill(described.begin() + at, described.begin() + at + size, true);
      }
      at += size;
    }
  }
  // The undescribed bytes, in offset order as the described fields are. A record of 65,000 of them
  // (the fuzz target's, 1.5 s under the sanitizers) is 65,000 fields: each name is made once, and
  // looked up only where a descriptor's name could be one of them (no field of LAS's is).
  const bool clash = std::any_of(taken.begin(), taken.end(), [](const std::string& name) {
    return name.rfind("extra_byte_", 0) == 0;
  });
  std::vector<LasExtraField> undescribed;
  undescribed.reserve(static_cast<size_t>(std::count(described.begin(), described.end(), false)));
  for (uint32_t b = 0; b < extra; ++b) {
    if (described[b]) continue;
    std::string name = "extra_byte_" + std::to_string(b);
    undescribed.emplace_back(clash ? unique(name) : std::move(name), DimType::kU8, b);
  }
  if (out.empty()) return undescribed;
  std::vector<LasExtraField> all;
  all.reserve(out.size() + undescribed.size());
  const auto by_offset = [](const LasExtraField& a, const LasExtraField& b) { return a.offset < b.offset; };
  std::merge(std::make_move_iterator(out.begin()), std::make_move_iterator(out.end()),
             std::make_move_iterator(undescribed.begin()), std::make_move_iterator(undescribed.end()),
             std::back_inserter(all), by_offset);
  return all;
}

LasVlr lasExtraBytesVlr(const std::vector<LasExtraField>& fields) {
  LasVlr vlr;
  vlr.user_id = "LASF_Spec";
  vlr.record_id = 4;
  vlr.description = "dpoint dimensions";
  vlr.data.assign(fields.size() * kExtraBytesDescriptorBytes, '\0');
  for (size_t k = 0; k < fields.size(); ++k) {
    char* d = vlr.data.data() + k * kExtraBytesDescriptorBytes;
    if (fields[k].descriptor.size() == kExtraBytesDescriptorBytes) {
      std::memcpy(d, fields[k].descriptor.data(), kExtraBytesDescriptorBytes);
      std::memset(d + kNameAt, 0, 32);
    }
    d[2] = static_cast<char>(static_cast<uint8_t>(fields[k].type) + 1);
    std::memcpy(d + kNameAt, fields[k].name.data(), std::min<size_t>(fields[k].name.size(), 32));
  }
  return vlr;
}

std::optional<LasExtraField> lasSourceExtraField(const Dimension& d, const std::string& descriptor, unsigned threads) {
  if (descriptor.size() != kExtraBytesDescriptorBytes) return std::nullopt;
  const uint8_t data_type = static_cast<uint8_t>(descriptor[2]), options = static_cast<uint8_t>(descriptor[3]);
  if (data_type < 1 || data_type > 10) return std::nullopt;
  LasExtraField field{d.name.substr(0, 32), static_cast<DimType>(data_type - 1), 0};
  takeScaling(descriptor.data(), 0, field);  // as the reader takes it
  if (field.dimensionType() != d.type) return std::nullopt;
  // Every value as a stored number (the same, or back through the scale exactly), and the values'
  // range.
  const size_t n = d.size(), block = size_t{1} << 16, blocks = (n + block - 1) / block;
  struct Part {
    bool fits = true;
    double lo = HUGE_VAL, hi = -HUGE_VAL;
  };
  std::vector<Part> parts(blocks);
  parallelFor(blocks, threads, [&](size_t b, unsigned) {
    Part& part = parts[b];
    for (size_t i = b * block, end = std::min(n, i + block); i < end && part.fits; ++i) {
      const double v = d.value(i);
      if (field.scaled) {
        const double stored = lasStoredNumber(field, v);
        part.fits = dimensionHolds(field.type, stored) && stored * field.value_scale + field.value_offset == v;
      }
      part.lo = std::min(part.lo, v), part.hi = std::max(part.hi, v);
    }
  });
  Part all;
  for (const Part& part : parts) all.fits &= part.fits, all.lo = std::min(all.lo, part.lo), all.hi = std::max(all.hi, part.hi);
  if (!all.fits) return std::nullopt;
  field.descriptor = descriptor;
  // Bits 1 and 2: the minimum and maximum, doubles of the values, scale and offset applied
  // (R15: "fully transformed with any applicable scale or offset values").
  if (n > 0 && all.lo <= all.hi && (options & 0x02)) storeUnaligned<double>(field.descriptor.data() + kMinAt, all.lo);
  if (n > 0 && all.lo <= all.hi && (options & 0x04)) storeUnaligned<double>(field.descriptor.data() + kMaxAt, all.hi);
  return field;
}

double lasStoredNumber(const LasExtraField& field, double value) {
  const double stored = (value - field.value_offset) / field.value_scale;
  if (field.type == DimType::kF32) return static_cast<float>(stored);
  return dimTypeIsFloat(field.type) ? stored : std::nearbyint(stored);
}

int lasFormatFor(const PointSet& points, int preferred, bool waveforms) {
  const Widest widest{largest(points, dim::kClassification),
                      std::max(largest(points, dim::kReturnNumber), largest(points, dim::kNumberOfReturns))};
  if (!waveforms) {
    static constexpr int kBase[11] = {0, 1, 2, 3, 1, 3, 6, 7, 8, 6, 8};  // 10 is 8's fields and wave packets
    if (preferred >= 0 && preferred <= 10) preferred = kBase[preferred];
  }
  if (preferred >= 0 && preferred <= 10 && holds(points, widest, preferred) && !lacksFields(points, preferred))
    return preferred;
  for (int f : {0, 1, 2, 3, 6, 7, 8})
    if (holds(points, widest, f)) return f;
  if (!waveforms) return preferred >= 0 && preferred <= 10 ? preferred : 8;
  for (int f : {4, 5, 9, 10})
    if (holds(points, widest, f)) return f;
  return 10;
}

}  // namespace dpoint
