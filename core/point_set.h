// The data model (DESIGN §2): only what a scene needs.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/dimensions.h"
#include "core/memory.h"

namespace dpoint {

// Whether a set has a z coordinate, as a fact of its source rather than of its values.
enum class ZAxis : uint8_t {
  kUnknown,  // made in memory (a generator, a tile): the values decide (isPlanar)
  kPresent,  // read from a format or file with z (LAS, glTF, a 3-column CSV, a PLY with z)
  kAbsent,   // read from genuinely 2D input (a 2-column CSV, a PLY without z): every z is 0
};

// A variable length record of a LAS file (VLR, or EVLR when `extended`), kept as its bytes.
struct LasVlr {
  std::string user_id;  // up to 16 bytes
  uint16_t record_id = 0;
  std::string description;  // up to 32 bytes
  std::string data;
  bool extended = false;
};

// What a LAS file said beside its points, so that LAS → LAS writes the same point records (the
// same format, scale and offset) and keeps the records the writer can vouch for (the CRS).
struct LasSource {
  int version_minor = 2;
  int point_format = 0;
  glm::dvec3 scale{0.001}, offset{0.0};
  uint16_t global_encoding = 0;  // bit 4: the CRS is WKT (LAS 1.4)
  uint16_t file_source_id = 0;
  std::vector<LasVlr> vlrs;  // the coordinate system's (LASF_Projection); extra bytes are described anew
  // The extra bytes descriptor (192 bytes) of each one-value field, by its dimension's name: its
  // type, scale and offset, no-data value and description, for the LAS writer.
  std::vector<std::pair<std::string, std::string>> extra_bytes;
};

// The arrays of positions and colours. Their `resize(n)` leaves the new elements unset (no pass
// zeroing them on one thread before the threads that fill them): write every one after it.
using PositionArray = std::vector<glm::dvec3, DefaultInitAllocator<glm::dvec3>>;
using ColorArray = std::vector<glm::vec3, DefaultInitAllocator<glm::vec3>>;

struct PointSet {
  PositionArray positions;  // always double
  ColorArray colors;        // empty, or one linear 0..1 colour per point
  std::vector<uint32_t> triangles;    // empty for point sets; 3 vertex indices per triangle
  // Per-point attributes (core/dimensions.h): each column has size() values or the set has none.
  Dimensions dimensions;
  // The integer full scale the colours were read from (255, 65535), 0 when they came as floats or
  // were made here: a writer of integer colours scales by it, so 8-bit colours stay 8-bit.
  uint16_t color_full_scale = 0;
  // The colours were read from a file as fractions (a PLY's float properties, a CSV's 0..1 columns,
  // a glTF's COLOR_0; color_full_scale 0): a writer of 8- or 16-bit colours says where it rounds
  // one. Colours made here (generate's, a sampled surface's blends) are rounded without a word.
  bool colors_read_as_fractions = false;
  // Set by the LAS reader, kept by the filters, used by the LAS writer.
  std::optional<LasSource> las;
  // The coordinate system a file other than LAS stated, as it gave it (an E57 file's
  // coordinateMetadata: WKT, an EPSG code or free text); empty when none. The E57 writer writes it
  // back, the LAS writer where PROJ makes it WKT (converters/point_io.cpp).
  std::string crs;

  // Facts of the source that the values cannot tell, set by the readers and kept by the filters.
  ZAxis z_axis = ZAxis::kUnknown;
  bool z_up = false;  // the source says z is up (LAS, or a PLY or CSV dpoint wrote from one)
  // A PCD source's VIEWPOINT (tx ty tz qw qx qy qz), the sensor's pose, where it is not the
  // identity: not applied to the points (as PCL's loaders do not), written back by the PCD writer.
  std::optional<std::array<double, 7>> viewpoint;

  size_t size() const { return positions.size(); }
  bool hasColors() const { return !colors.empty(); }
  bool isMesh() const { return !triangles.empty(); }
  // True when every z is +0.0 (bit pattern zero). The renderer draws such a set as 2D.
  bool isPlanar() const;
  // Whether writers write z: as z_axis says, or (kUnknown) when not isPlanar(). A LAS file whose
  // z are all 0 still has z; a 2-column CSV has none.
  bool hasZ() const { return z_axis == ZAxis::kUnknown ? !isPlanar() : z_axis == ZAxis::kPresent; }
  // The position in `triangles` of the first index that names no point, or triangles.size() when
  // every one does; checked on `threads` cores (0: all), as a big mesh has hundreds of millions.
  size_t firstBadTriangleIndex(unsigned threads = 0) const;
};

// The bytes the set's arrays hold (their capacities): positions, colours, triangles and dimensions.
uint64_t heldBytes(const PointSet& points);

// Points that are not held but made on demand, `count` of them: make(begin, end, out) writes the
// positions of points [begin, end) to out[0 .. end - begin). For a generator whose points are a
// function of their index (random2d), so that a writer formats its rows straight from them and
// no array of positions is ever held. Called from several threads at once.
struct MadePositions {
  size_t count = 0;
  std::function<void(size_t begin, size_t end, glm::dvec3* out)> make;
  explicit operator bool() const { return static_cast<bool>(make); }
};

// A colour channel as an integer of `full` (255, 65535): round(clamp(c, 0, 1) · full), NaN as 0.
// c · full is exact in double (24 + 16 significant bits), so adding 0.5 and truncating rounds half
// up without a libm call.
inline uint16_t colorInteger(float c, double full) {
  if (!(c > 0.0f)) return 0;
  return static_cast<uint16_t>((c < 1.0f ? static_cast<double>(c) : 1.0) * full + 0.5);
}

// Whether colour channel `c` is a whole number from 0 to `full` (NaN is not): a float colour read
// as an integer of that scale.
inline bool isWholeChannel(float c, float full) { return c >= 0.0f && c <= full && c == std::floor(c); }

// The colours a writer of integers of `full` (255, 65535) changes (colorInteger): `clamped`, those
// with a channel outside 0..1 or NaN; `rounded`, the others with a channel between two steps. Both
// 0 for colours read as k / full in float or double (within full · 2^-24 of k at that scale).
struct ColorsOffGrid {
  uint64_t rounded = 0, clamped = 0;
};
ColorsOffGrid colorsOffGrid(const ColorArray& colors, double full, unsigned threads);

// The integer scale of float colours written as 0..255 or 0..65535 values (as some tools write a
// PLY's float red, green, blue). `full`: 255 where the largest channel is above 1 and at most 255,
// 65535 where it is above 255 and at most 65535, and every channel is an integer from 0 to it;
// else 0 (0..1 fractions, or values no integer scale explains, such as 1.2 among fractions). `odd`:
// where some channels are whole numbers above 1 and at most 1% of the colours are not whole, the
// first of those (a channel of 0.5, 127.5, negative, NaN or past 65535), which kept `full` 0; else
// UINT64_MAX (HDR values, 1.5 beside 2 and 0.5, are not 0..255 values with a few odd ones).
struct WholeColorScale {
  uint16_t full = 0;
  uint64_t odd = UINT64_MAX;
};
WholeColorScale wholeColorScale(const ColorArray& colors, unsigned threads);
// What a reader says of WholeColorScale::odd (`color`, of vertex `vertex`): why colours of whole
// numbers above 1 stay 0..1 values, clamped.
std::string oddColorNote(const glm::vec3& color, uint64_t vertex);
// Colours read as integers of `full` (255, 65535) taken as 0..1 values: each channel divided by
// it, and PointSet::color_full_scale set, so that a writer of integers writes them back as they were.
void takeColorsAsIntegers(PointSet& points, uint16_t full, unsigned threads);

// `part`'s points after `out`'s: positions; colours, white for the points of either set without
// where the other has them; dimensions, the union of both, 0 where a set lacks one (a name of two
// types keeps out's type where it holds every value of part's, else both become float64);
// triangles offset by out's size (the caller keeps the total within 2^32). colors_read_as_fractions is kept where either has it; the other fields
// (color_full_scale, las, z_axis) are the caller's.
void appendPoints(PointSet& out, const PointSet& part);

// A set's scans as E57 and PTX write them: the runs of its point_source_id, [first, end) each with
// its value, where it has several values (every NaN one value), each value's points lie together
// (as an E57 or PTX file of several scans reads: each point's scan) and they are at most 65,535
// (what the readers number); else one run of every point (`id` 0).
struct SourceRun {
  size_t first = 0, end = 0;
  double id = 0.0;
};
std::vector<SourceRun> pointSourceRuns(const PointSet& points);

// Whether every coordinate is finite (no nan, no inf).
inline bool isFinite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Smallest and largest coordinates of positions [first, last); asserts first < last.
struct Box {
  glm::dvec3 min{0.0}, max{0.0};
};
Box boundingBox(const PositionArray& positions, size_t first, size_t last);
inline Box boundingBox(const PositionArray& positions) { return boundingBox(positions, 0, positions.size()); }

// The box of the finite coordinates of positions [first, last), axis by axis (an axis with none
// has min +inf and max -inf), on `threads` cores (0: all); `nonfinite` (if given) is whether some
// coordinate was nan or inf. For sets that --allow-nonfinite let in.
Box finiteBox(const PositionArray& positions, size_t first, size_t last, unsigned threads, bool* nonfinite = nullptr);

}  // namespace dpoint
