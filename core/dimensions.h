// Per-point attributes besides positions and colours (issue #34; PDAL calls them dimensions):
// intensity, classification, GPS time, a LAS file's extra bytes, a PLY property or CSV column no
// other field takes. Each is one column in its own numeric type, so a set pays only for the
// attributes it has, in their own width (a LAS class is a byte, not a double).
//
// The dimensions dpoint knows by name are one table (knownDimensions), as the precision modes are
// one table: its name, type, where LAS keeps it, and what PLY, CSV and glTF call it. Any other
// dimension keeps the name it came with.
#pragma once

#include <cassert>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/memory.h"

namespace dpoint {

// The numeric types a dimension may have: LAS extra bytes' types 1–10 in their order.
enum class DimType : uint8_t { kU8, kI8, kU16, kI16, kU32, kI32, kU64, kI64, kF32, kF64 };
inline constexpr size_t kDimTypeCount = 10;

size_t dimTypeSize(DimType type);
// "uint8", "int16", "float32", …; the names PLY uses are plyTypeName's.
const char* dimTypeName(DimType type);
bool dimTypeIsFloat(DimType type);
bool dimTypeIsSigned(DimType type);
// PLY's type names: uchar, char, ushort, short, uint, int, (none), (none), float, double; nullptr for
// the 64-bit integers, which PLY cannot store.
const char* plyTypeName(DimType type);
// Whether `v` is exactly a value of the type (a whole number in its range; for float32, a float;
// NaN for the float types only).
bool dimensionHolds(DimType type, double v);
// Whether every value of type `from` is one of type `to` (a join keeps a column of `to` then,
// else makes it float64: appendPoints).
bool dimTypeHolds(DimType to, DimType from);
// A value of the type stored at `bytes` (host order, unaligned), as a double (exact but for 64-bit
// integers beyond 2^53).
double loadDimValue(DimType type, const uint8_t* bytes);
// The type of a name as `dimTypeName` or PLY (uint8/uchar, int16/short, float64/double, …).
std::optional<DimType> parseDimType(std::string_view name);

// The names a writer gives dimensions `names` in a format that cannot hold every name as it is
// (PLY's and PCD's one-word names, a CSV header's columns, LAS's 32 bytes): each character `bad` is
// true of becomes '_', a name is cut to `most_bytes`, an empty one is `empty`, and a name
// `reserved` is true of (given its index), or one that repeats a name written before it, gets
// "_2" (or "_3", …) within those bytes. Each change is a line of `renamed`: "dimension 'my value'
// written as 'my_value'".
std::vector<std::string> writableNames(const std::vector<std::string>& names, const std::function<bool(char)>& bad,
                                       const std::function<bool(const std::string&, size_t)>& reserved,
                                       std::vector<std::string>* renamed, size_t most_bytes = std::string::npos,
                                       const std::string& empty = "unnamed");
// A control character or a space (PLY's and PCD's names are one word).
inline bool isSpaceOrControl(char c) { return static_cast<unsigned char>(c) <= 0x20 || c == 0x7f; }

// A column's bytes. Their allocator leaves bytes made without a value unset (core/memory.h), so
// that a reader which writes every value of a large column does not zero it on one thread first:
// Dimension's constructor and resize() still give zeros; Dimensions::appendUnset and resizeUnset do not.
using DimensionBytes = std::vector<uint8_t, DefaultInitAllocator<uint8_t>>;

// One named column: size() values of `type`, stored as their bytes in host order.
struct Dimension {
  std::string name;
  DimType type = DimType::kF64;
  DimensionBytes bytes;

  // Marks the constructor that leaves the values unset, for a caller that writes every one.
  struct Unset {};

  Dimension() = default;
  Dimension(std::string name_, DimType type_, size_t count = 0)
      : name(std::move(name_)), type(type_), bytes(count * dimTypeSize(type_), uint8_t{0}) {}
  Dimension(std::string name_, DimType type_, size_t count, Unset)
      : name(std::move(name_)), type(type_), bytes(count * dimTypeSize(type_)) {}

  size_t size() const { return bytes.size() / dimTypeSize(type); }
  // New values are 0.
  void resize(size_t count) { bytes.resize(count * dimTypeSize(type), uint8_t{0}); }
  // New values unset: for a caller that writes every one before any is read.
  void resizeUnset(size_t count) { bytes.resize(count * dimTypeSize(type)); }
  // The value of point i as a double (exact for every type but 64-bit integers beyond 2^53).
  double value(size_t i) const;
  // Sets point i from a double: rounded toward zero and clamped to an integer type's range (NaN as
  // 0), rounded to nearest for float32. Exact when dimensionHolds(type, v).
  void setValue(size_t i, double v);
  // Typed access; T must be the type's C++ type.
  template <typename T>
  T get(size_t i) const {
    assert(sizeof(T) == dimTypeSize(type) && i < size());
    T v;
    std::memcpy(&v, bytes.data() + i * sizeof(T), sizeof(T));
    return v;
  }
  template <typename T>
  void set(size_t i, T v) {
    assert(sizeof(T) == dimTypeSize(type) && i < size());
    std::memcpy(bytes.data() + i * sizeof(T), &v, sizeof(T));
  }
  // Copies point `from` of `source` (the same type) to point `to` of this.
  void copyFrom(size_t to, const Dimension& source, size_t from) {
    const size_t w = dimTypeSize(type);
    assert(source.type == type);
    std::memcpy(bytes.data() + to * w, source.bytes.data() + from * w, w);
  }
};

// A dimension dpoint knows: its one name (lower case, as PLY and CSV write it), type, LAS field
// (nullptr: only as extra bytes) and glTF attribute (application-specific, `_NAME`).
struct KnownDimension {
  const char* name;
  DimType type;
  const char* las_field;  // the field of the LAS 1.4 point record, or nullptr
  const char* gltf_attribute;
  const char* description;
};
std::span<const KnownDimension> knownDimensions();
const KnownDimension* findKnownDimension(std::string_view name);

// The names of the LAS fields, as knownDimensions names them.
namespace dim {
inline constexpr const char* kIntensity = "intensity";
inline constexpr const char* kReturnNumber = "return_number";
inline constexpr const char* kNumberOfReturns = "number_of_returns";
inline constexpr const char* kScanDirection = "scan_direction";
inline constexpr const char* kEdgeOfFlightLine = "edge_of_flight_line";
inline constexpr const char* kClassification = "classification";
inline constexpr const char* kSynthetic = "synthetic";
inline constexpr const char* kKeyPoint = "key_point";
inline constexpr const char* kWithheld = "withheld";
inline constexpr const char* kOverlap = "overlap";
inline constexpr const char* kScannerChannel = "scanner_channel";
inline constexpr const char* kScanAngleRank = "scan_angle_rank";
inline constexpr const char* kScanAngle = "scan_angle";
inline constexpr const char* kUserData = "user_data";
inline constexpr const char* kPointSourceId = "point_source_id";
inline constexpr const char* kGpsTime = "gps_time";
inline constexpr const char* kNir = "nir";
inline constexpr const char* kWavePacketIndex = "wave_packet_index";
inline constexpr const char* kWaveByteOffset = "wave_byte_offset";
inline constexpr const char* kWavePacketSize = "wave_packet_size";
inline constexpr const char* kWaveReturnLocation = "wave_return_location";
inline constexpr const char* kWaveXt = "wave_xt";
inline constexpr const char* kWaveYt = "wave_yt";
inline constexpr const char* kWaveZt = "wave_zt";
inline constexpr const char* kNormalX = "nx";
inline constexpr const char* kNormalY = "ny";
inline constexpr const char* kNormalZ = "nz";
}  // namespace dim

// The dimensions of a set, in the order they were read or added.
class Dimensions {
 public:
  bool empty() const { return columns_.empty(); }
  size_t count() const { return columns_.size(); }
  const std::vector<Dimension>& all() const { return columns_; }
  std::vector<Dimension>& all() { return columns_; }
  const Dimension* find(std::string_view name) const;
  Dimension* find(std::string_view name);
  // The column `name`, added with `points` zero values when missing (its type must then match).
  Dimension& add(const std::string& name, DimType type, size_t points);
  // A new column whose name the caller knows is not taken (no search: readers adding many).
  Dimension& append(const std::string& name, DimType type, size_t points) {
    return columns_.emplace_back(name, type, points);
  }
  // The same with the `points` values unset: for a reader that writes every one before any is read
  // (a large column is then not zeroed on one thread first).
  Dimension& appendUnset(const std::string& name, DimType type, size_t points) {
    return columns_.emplace_back(name, type, points, Dimension::Unset{});
  }
  // The columns of `like` (names and types, in order), each of `points` values unset. Where the
  // columns in place are those, they keep their memory: a stream's block read again and again is
  // not given fresh pages each time (which the kernel zeroes on one thread).
  void shapeUnset(const std::vector<const Dimension*>& like, size_t points);
  bool remove(std::string_view name);
  // Room for `columns` in all (a reader adding thousands: a LAS record's extra bytes).
  void reserve(size_t columns) { columns_.reserve(columns); }
  // Every column resized to `points` (new values 0).
  void resize(size_t points);
  // The same with the new values unset (Dimension::resizeUnset).
  void resizeUnset(size_t points) {
    for (Dimension& d : columns_) d.resizeUnset(points);
  }
  // Bytes per point of all columns.
  size_t bytesPerPoint() const;

 private:
  std::vector<Dimension> columns_;
};

}  // namespace dpoint
