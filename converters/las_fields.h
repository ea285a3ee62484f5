// Where each field of a LAS point record sits (LAS 1.4 R15, tables 7-16 and 27-35), for the
// reader that turns records into dimensions (core/dimensions.h) and the writer that turns them back:
// one table, so the two cannot disagree. Formats 0-5 pack return numbers, flags and a 5-bit class
// into bytes 14-15 and keep an 8-bit scan angle rank; formats 6-10 have 4-bit returns, an 8-bit
// class and a 16-bit scan angle. The extra bytes VLR (LASF_Spec, record 4) names and types the
// bytes a record holds beyond its format's base.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/dimensions.h"
#include "core/point_set.h"
#include "core/result.h"

namespace dpoint {

// One field of a record: the dimension it fills, at byte `offset`; a bit field when `bits` > 0
// (bits [shift, shift + bits) of the byte at offset, into a uint8 dimension).
struct LasField {
  const char* name;
  DimType type;
  uint32_t offset;
  uint8_t shift = 0, bits = 0;
};

// The fields of point format 0..10 besides X, Y, Z (bytes 0-11) and RGB (colours, not dimensions).
const std::vector<LasField>& lasFields(int point_format);
// Where RGB starts in a record of the format, 0 when it has none; NIR is a field (format 8, 10).
uint32_t lasRgbOffset(int point_format);

// A dimension kept in a record's extra bytes: its name, type and byte offset after the base record.
struct LasExtraField {
  LasExtraField() = default;
  LasExtraField(std::string name_, DimType type_, uint32_t offset_)
      : name(std::move(name_)), type(type_), offset(offset_) {}

  std::string name;
  DimType type = DimType::kU8;  // as stored in the record
  uint32_t offset = 0;
  size_t dimension = 0;  // the writer's: its index in the set's dimensions
  // Options bit 3 or 4 of its descriptor (LAS 1.4 R15 table 24): the value is the stored number ·
  // value_scale + value_offset, a float64 dimension (as X is X·scale + offset).
  bool scaled = false;
  double value_scale = 1.0, value_offset = 0.0;
  // The 192 bytes of the descriptor of a one-value field (its no-data value, minimum, maximum and
  // description with its scale): kept in LasSource, and written again where the field is.
  std::string descriptor;

  DimType dimensionType() const { return scaled ? DimType::kF64 : type; }
};

// The extra bytes of a record of `extra` bytes as the VLR `vlr` (null: none) describes them. Bytes
// it leaves undescribed (or the whole of them without a VLR) become uint8 dimensions named
// extra_byte_N (N: the byte's offset after the base record). A name that is already taken (a LAS
// field, a repeated name) gets the suffix _2, _3, …. Errors name the descriptor.
Result<std::vector<LasExtraField>> lasExtraFields(const LasVlr* vlr, uint32_t extra, const std::vector<LasField>& base);
inline constexpr size_t kExtraBytesDescriptorBytes = 192;

// The extra bytes VLR describing `fields` (LAS 1.4 R15 table 24: 192 bytes a field): each field's
// own descriptor where it has one, with its name, else its type and name.
LasVlr lasExtraBytesVlr(const std::vector<LasExtraField>& fields);
// A field of the source's (LasSource::extra_bytes) that dimension `d` fits as it is: its stored
// type (the same as d's), or its scaled one (d float64, every value a stored number · scale +
// offset exactly); the descriptor's minimum and maximum made the set's (doubles of the values).
// Nothing where it does not fit: the dimension is then written as its own type.
std::optional<LasExtraField> lasSourceExtraField(const Dimension& d, const std::string& descriptor, unsigned threads);
// The number a scaled field stores for `value`: (value − offset) / scale, rounded to a whole number
// for an integer type, to a float for float32.
double lasStoredNumber(const LasExtraField& field, double value);

// The point format that holds what `points` carries: `preferred` (the source's) when it holds every
// LAS field the set has, its colours and the values of its fields, and the set has its colours,
// GPS time (0-5), NIR and wave packets (else they would be zeros); else the smallest of formats
// 0-3 or, where a field or value needs LAS 1.4's (`scan_angle`, classes past 31, returns past 7),
// 6-8 (waveform fields: 4, 5, 9 or 10). Without `waveforms` (LAZ and COPC, whose waveform items
// dpoint does not code) the formats 4, 5, 9 and 10 are never chosen: a waveform source's format
// becomes its base (1, 3, 6, 8), the others as above, and the wave packet fields are left to the
// extra bytes.
int lasFormatFor(const PointSet& points, int preferred, bool waveforms = true);

}  // namespace dpoint
