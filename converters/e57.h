// ASTM E57 (E2807), the exchange format of terrestrial laser scanners: read and written.
//
// The file is pages of 1020 bytes and a CRC-32C each (every page read is checked); a 48-byte
// header places an XML tree that names what the file holds. Each scan (a child of `data3D`) has a
// pose (a unit quaternion and a translation) and its points as a compressed vector: records whose
// fields the tree's prototype lists, each field a stream of bit-packed values (the bitpack codec,
// the only one E57 defines) spread over data packets of up to 64 KiB.
//
// Read: every scan's points, moved by its pose into the file's frame in double precision.
// Positions from cartesianX/Y/Z, else from sphericalRange/Azimuth/Elevation (x = r cos(el) cos(az),
// y = r cos(el) sin(az), z = r sin(el)); a point whose cartesian (or spherical) invalid state is
// not 0 (direction only, or no point) is left out with a note. Colours from colorRed/Green/Blue:
// integers 0..255 or 0..65535 keep that scale (PointSet::color_full_scale), other ranges are
// normalised by the scan's colorLimits (or the fields' own limits). Every other field is a
// dimension of its own type (an integer field the smallest type holding its limits, a float field
// float32 or float64, a scaled integer float64): intensity as `intensity` (read as 0..1 from the
// scan's intensityLimits, else the field's limits, where some scan's is no 0..65535 integer),
// returnIndex + 1 as `return_number` and returnCount as `number_of_returns` (LAS's), the LAS
// extension's fields (`las:classification`, …) by their LAS names, the normals extension's
// (`nor:normalX`, …) as nx, ny, nz, the others (rowIndex, timeStamp, …) by their own. Several
// scans: each point's scan number (from 1, in the file's order) in point_source_id, as a PTX
// file's scans are joined (converters/point_inputs.h), unless the file has its own ids; what the
// join fills in (white colours, 0) is a note. Images (images2D) are not read (a note).
//
// Errors name the file and what failed: a page's checksum, the XML's line, a scan and field. A
// non-finite coordinate is an error unless allow_nonfinite. The points are checked against
// max_memory before they are allocated; the fields' packed bytes are read a window of packets at a
// time and decoded as they come (a file whose packets give one field's values long before
// another's, which no writer does, holds more of them, up to what max_memory leaves).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/input_file.h"
#include "core/point_set.h"
#include "core/progress.h"
#include "core/result.h"

namespace dpoint {

struct E57ReadOptions {
  unsigned threads = 0;  // 0: all cores
  Progress* progress = nullptr;
  uint64_t max_memory = 0;  // 0: defaultMemoryLimit()
  bool allow_nonfinite = false;
  std::vector<std::string>* notices = nullptr;  // points left out, images not read
  // Logical bytes of packets read at a time (0: 32 MiB; at least 64 KiB, a packet's most): tests
  // make it small, so that small files take many windows.
  uint64_t packet_window = 0;
};

struct E57WriteOptions {
  unsigned threads = 0;  // 0: all cores; the bytes do not depend on it
  Progress* progress = nullptr;
  std::vector<std::string>* notices = nullptr;  // dimensions renamed, triangles not written
  // The file's coordinateMetadata: this where not empty (--crs, WKT), else the set's own `crs`,
  // else a LAS source's coordinate system where it is WKT or can be made WKT.
  std::string crs;
};

Result<PointSet> readE57(const std::string& path, const E57ReadOptions& options = {});
Result<PointSet> readE57(const InputFile& file, const E57ReadOptions& options = {});

// An E57 file read a block of points at a time (render's and info's --stream): the points readE57
// gives, in its order, positions and colours (white for a scan without beside scans with), and the
// dimensions asked for; none is held beyond a block. open() reads the tree and walks every scan's
// packets once (reading the file through, checking every page), keeping where each packet begins
// and, where a scan has an invalid state, how many of every 65,536 records are points; read() then
// starts at the packet before its first point, or goes on where the last read ended. The errors are
// readE57's, those of the packets at open, a non-finite coordinate (unless allow_nonfinite) when
// its block is read. read() may be called from one thread at a time.
class E57PointStream {
 public:
  static Result<std::unique_ptr<E57PointStream>> open(const std::string& path, const E57ReadOptions& options = {});
  static Result<std::unique_ptr<E57PointStream>> open(InputFile file, const E57ReadOptions& options = {});
  ~E57PointStream();
  uint64_t count() const;
  bool hasColors() const;
  // The scans' dimensions as readE57 joins them (a name's type float64 where the scans' differ;
  // point_source_id for the scan numbers where several scans hold points), as empty columns.
  const Dimensions& dimensions() const;
  // readE57's notes: points left out, intensities read as 0..1, images, what the join fills in.
  const std::vector<std::string>& notices() const;
  // The file's coordinate system (coordinateMetadata, as readE57's PointSet::crs); empty: none.
  const std::string& crs() const;
  // Host bytes the stream holds beside its blocks: the packets' places, the points' counts.
  uint64_t heldBytes() const;
  // From now on read() also fills these of dimensions() (by index) into the block; none by default.
  void streamDimensions(std::vector<size_t> which);
  Status read(uint64_t first, uint64_t n, PointSet& block);

 private:
  E57PointStream();
  struct State;
  std::unique_ptr<State> state_;
};

// The records the file's scans declare (points, and those marked invalid), from its tree alone.
Result<uint64_t> e57RecordCount(const std::string& path);

// A scan (data3D) for each point_source_id whose points lie together (pointSourceRuns: as an E57 or
// PTX file of several scans reads), else one, each with no pose: x, y and z as doubles (every coordinate as it is), colours as
// integers of their scale (0..255, or 0..65535 for 16-bit colours), each dimension a field:
// integers as Integer of their values' own limits (packed in as few bits as those need), floats as
// Float single or double; intensity as `intensity` with intensityLimits, return_number - 1 as
// `returnIndex` (where every value is 1 or more), number_of_returns as `returnCount`, nx/ny/nz as
// the normals extension's `nor:normalX/Y/Z`, the other LAS fields as the LAS extension's
// (`las:classification`, …), other names as XML names that no standard field has (renamed with a
// note). Triangles are not written. The same set makes the same bytes (the GUIDs are version 5
// UUIDs of every page's checksum).
Status writeE57(const std::string& path, const PointSet& points, const E57WriteOptions& options = {});

// CRC-32C (Castagnoli) of `size` bytes, as E57 checks each page (stored big-endian after it).
uint32_t crc32c(const uint8_t* data, size_t size);

}  // namespace dpoint
