// LAS point clouds (ASPRS LAS 1.0–1.4, point data record formats 0–10): airborne and terrestrial
// laser scans, integers with a double scale and offset per axis. Written by hand from the ASPRS
// specifications (LAS 1.2 of 2008, LAS 1.4 R15 of 2019): Debian has no maintained LAS library.
//
// Reading: the public header block of any version 1.0–1.4 (227, 235 or 375 bytes, or more when a
// writer extended it), then `count` records of `record length` bytes from the offset to point data.
// VLRs, EVLRs, waveform packets and a record's extra bytes (record length beyond the format's base
// size) are skipped. The count is the 64-bit one of a 1.4 header (the legacy 32-bit field when the
// 64-bit one is 0), else the legacy one. Coordinates are X·scale + offset in double, rounded
// twice, as PDAL, laspy and loaders.gl compute them (on the corpus, loaders.gl's doubles and
// dpoint's are bit-identical).
// Before anything is allocated the header is checked: signature, version, point format, record
// length against the format's base size, finite non-zero scales, finite offsets and bounds, and
// count × record length against the bytes the file holds after the offset. Compressed records
// (LAZ: point format bit 7 or 6 set) are decoded first (converters/laz_decode.h: point formats
// 0–3; others refused by name) into memory after the header and VLRs, then read as a LAS file's.
// Records are decoded in blocks on all cores, each into its preassigned index, so the result does
// not depend on the thread count. Memory: the PointSet plus one block per thread.
//
// Colours (LasReadOptions::color):
// - RGB (formats 2, 3, 5, 7, 8, 10) as c / 65535, or as c / 255 when no channel of any point
//   exceeds 255: such a file holds 8-bit values in the 16-bit fields (as CloudCompare assumes; a
//   true 16-bit file that dark is shown 257 times brighter, the heuristic's known price). The
//   values are kept as they are, not decoded from sRGB: LAS RGB are display values (orthophoto
//   pixels), and dpoint treats PLY's uchar and CSV colours the same way; the
//   renderer writes a colour's value to the PNG unchanged, so a scan looks as in other viewers.
//   writeLas stores round(c · 65535), so LAS → LAS keeps every 16-bit value (c / 65535 is
//   correctly rounded to float, and float's 24 bits leave |c · 65535 − v| < 0.004).
// - Intensity as grey, divided by the file's largest intensity: the spec asks writers to scale
//   intensity to 16 bits, but many store the sensor's 8- or 12-bit values as they are, so a fixed
//   divisor would leave most files black; the file's maximum gives every file full contrast.
// - Classification through lasClassColor's fixed palette.
//
// Writing: every dimension a point format holds is written in its field (las_fields.h), the others
// as extra bytes with their names and types (the extra bytes VLR). The format is the source's
// (PointSet::las) when it holds everything the set carries, else the smallest that does: 0-3 in
// LAS 1.2, 6-8 in LAS 1.4 where a field or value needs them. A LAS source also gives its scale,
// offset, version and coordinate system records, so LAS → LAS writes the same point records.
// Otherwise a scale per axis: the coarsest of 1, 0.1, … 1e-12 at which every coordinate reads back
// within two units in its last place (the data's own decimal step: 0.01 for centimetres), else
// the finest at which the extent fits the 32-bit integers (coarser than 1 only where even 1 does
// not fit). Points that do not read back bit for bit are counted where they merge (the report).
// Per axis the first of these offsets under which every
// coordinate reads back as the same double: a whole number (lasOffsetFor), 0, the minimum rounded
// down to a multiple of the scale (none: the whole number). A set without returns is written as
// return 1 of 1. A point whose (coordinate − offset) / scale rounds outside the 32-bit integers is
// an error naming the point.
//
// Exactness: a coordinate reads back as itself when it is a value some LAS reader computes,
// X·scale + offset in double, for one of those offsets. That holds for data read from a LAS file
// at the same scale whose offset was 0 or a whole number (CSV → LAS → CSV of such data is
// byte-identical), and for decimal data with the scale's digits whose spread is small next to its
// magnitude (millimetre eastings and northings over a few km: with a whole-number offset o, the
// error of X·scale is below the distance from a 3-digit decimal to the nearest midpoint between
// doubles). Not for decimal values near 0: no integer X gives 418.191 back through X · 0.001 (it
// is 418.19100000000003), a property of the format's formula that every LAS writer shares.
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

// What becomes PointSet::colors. kAuto: the RGB of formats that have it, else no colours.
enum class LasColorSource { kAuto, kRgb, kIntensity, kClassification, kNone };

// The public header block as the reader uses it (fields it skips are not kept).
struct LasHeader {
  int version_major = 1, version_minor = 2;
  int point_format = 0;         // 0..10
  uint32_t record_length = 0;   // bytes per point record, the format's base size and any extra bytes
  uint32_t header_size = 0;
  uint32_t point_offset = 0;    // offset to point data
  uint32_t vlr_count = 0;
  uint32_t evlr_count = 0;      // 1.4 only
  uint64_t point_count = 0;     // the count the reader uses (see the top comment)
  glm::dvec3 scale{1.0}, offset{0.0};
  glm::dvec3 min{0.0}, max{0.0};  // the header's bounds as written: finite, not checked against the points
  std::string generating_software;
  uint16_t file_source_id = 0, global_encoding = 0;
  bool compressed = false;  // LAZ: the records are LASzip-compressed (converters/laz_decode.h)
};

struct LasReadOptions {
  unsigned threads = 0;  // 0: all cores
  Progress* progress = nullptr;
  LasColorSource color = LasColorSource::kAuto;
  uint64_t max_memory = 0;  // bytes for the point set (--max-memory); 0: defaultMemoryLimit()
  // When not null, gets a line for what the reader read past: an extra bytes record it cannot
  // follow, whose bytes are then read as they are (extra_byte_N, one byte each).
  std::vector<std::string>* notices = nullptr;
};

// What writeLas chose and what the file cannot hold as given.
struct LasWriteReport {
  glm::dvec3 scale{0.0};
  // Axes whose scale the writer chose coarser than the coordinates' digits, the finest at which the
  // extent fits the 32-bit integers: their coordinates move by up to half a step.
  glm::bvec3 rounded{false};
  // The scale is the source LAS file's (a set read from LAS): `rounded` then marks axes whose
  // coordinates left its grid since (changed in Python) and moved back onto it.
  bool source_scale = false;
  // Extra bytes named anew, one line each ("dimension 'höhe' written as 'h__he'"): LAS names are up
  // to 32 letters, digits or '_'.
  std::vector<std::string> renamed;
  // What became of the source's CRS records in a point format 6–10 file, which holds WKT alone
  // (converters/las_crs.h): made WKT, or left out and why, or replaced by crs_wkt; empty when they
  // were kept as they were.
  std::string crs;
  // Distinct positions that share their integers at that scale with another: they read back as one.
  uint64_t merged_points = 0;
  // The intensity was float 0..1 values (PTX's, a normalised one), written as round(v · 65535).
  bool intensity_scaled = false;
};

struct LasWriteOptions {
  // The coordinate step for x, y and z, finite and > 0; 0: the source LAS file's (PointSet::las)
  // per axis, with its offset where every point fits it, else chosen from the data (above).
  double scale = 0.0;
  unsigned threads = 0;
  Progress* progress = nullptr;
  LasWriteReport* report = nullptr;  // filled when not null
  // LAZ: the records compressed as LASzip does (converters/laz_encode.h), in chunks of 50,000
  // points compressed on all cores and held compressed until the header (which needs the EVLRs'
  // offset) is written. Point formats 0–3 and 6–8.
  bool compress = false;
  // Point formats 6–8 (LAS 1.4) whatever the set needs: 0 and 1 become 6, 2 and 3 become 7
  // (COPC's formats; a format 4/5 source with compress is written as 6 or 7 too).
  bool las14 = false;
  // When not empty, the file's CRS (one line of OGC WKT 1, crsAsWkt's) in place of the source's CRS
  // records: as GeoTIFF keys in a LAS 1.2 file where the point format, the count and the source's
  // version allow 1.2 and the CRS is an EPSG one the keys hold (lasGeoKeyRecords), else a LAS 1.4
  // file with the WKT bit set, whatever its point format (LAS 1.4 R15 allows WKT for every format;
  // LAS 1.2 has GeoTIFF keys only).
  std::string crs_wkt;
  // Set where the set's own CRS text (PointSet::crs) is its CRS over the source's records (the text
  // wins: converters/las_crs.h): the records are not written, crs_wkt (the text made WKT; empty
  // where PROJ made none, and then no CRS) is.
  bool source_crs_dropped = false;
  // When set, the file's bytes are appended here and nothing is written at `path` (which names the
  // output in messages).
  std::string* memory = nullptr;
};

// Reads and checks the header only (everything the top comment lists, the file size included).
Result<LasHeader> readLasHeader(const std::string& path);
Result<PointSet> readLas(const std::string& path, const LasReadOptions& options = {});
// The same from an open file (the fuzz target reads bytes as a file, InputFile::fromMemory).
Result<PointSet> readLas(const InputFile& file, const LasReadOptions& options = {});
// The coordinate system's records of a LAS or LAZ file, VLRs and EVLRs (isLasCrsRecord's), as
// readLas keeps them in PointSet::las.
Result<std::vector<LasVlr>> readLasCrsRecords(const InputFile& file);

// Writes atomically (AtomicFile). Triangles are not stored. Fails (exit 2) on a non-finite
// position and on a point that does not fit the 32-bit integers at the scale; with exit 1 on a
// scale that is not finite and positive. More than 2^32 − 1 points are written as LAS 1.4.
Status writeLas(const std::string& path, const PointSet& points, const LasWriteOptions& options = {});

// A LAS or LAZ file read a block at a time (`render`/`info --stream`, converters/point_inputs.h):
// positions, colours and the dimensions asked for, in bounded memory (LAZ: the chunks a block
// covers are decoded, on all cores, and the last ones kept for the next block). Colours: the RGB
// of formats that have it, divided by 255 when no channel of a sample exceeds 255 (an uncompressed
// file: 4096 records spread over it; LAZ: the first 4096 of its first, middle and last chunk), else
// by 65535: the whole-file read's rule (readLas), decided before the first block, so a file whose
// only 16-bit values lie outside the sample streams 257 times brighter than it reads whole.
class LasPointStream {
 public:
  // The LAZ chunks a block needs are decoded only where their claimed points' records fit
  // `max_memory` (checkMemory; 0: its default), else exit 4.
  static Result<std::unique_ptr<LasPointStream>> open(const std::string& path, unsigned threads = 0,
                                                      uint64_t max_memory = 0);
  ~LasPointStream();
  const LasHeader& header() const;
  uint64_t count() const;
  bool hasColors() const;
  // The record's fields and extra bytes as dimensions, as empty columns (names and types).
  const Dimensions& dimensions() const;
  // What the reader read past, one line each (LasReadOptions::notices).
  const std::vector<std::string>& notices() const;
  // From now on read() also fills these of dimensions() (by index) into the block; none by default.
  void streamDimensions(std::vector<size_t> which);
  Status read(uint64_t first, uint64_t n, PointSet& block);

 private:
  LasPointStream();
  struct State;
  std::unique_ptr<State> state_;
};

// True when the header's bounds contain `points` (the box of the points read), each side within
// half a scale step (writers round the bounds they store). Not a reason to refuse a file: the
// corpus's simple1_3.las, a real file PDAL, laspy and loaders.gl all read, stores its raw integers
// (x · 1000) as bounds. `dpoint info` reports the disagreement.
bool lasBoundsContain(const LasHeader& header, const Box& points);

// The digits after the point that the file's coordinates have: the most any axis's scale or offset
// needs in its shortest decimal form (0.01 and 638000 → 2; 0.001 and 0.5 → 3), or −1 when one needs
// more than 17 (a scale like 1/3, not a decimal step). X·scale + offset is an exact decimal with
// that many digits; the double a reader computes is within a few ulps of it, so printing with
// these digits gives the decimal back (849087.70 at scale 0.01, where the double's shortest form
// is 849087.7000000001) as long as an ulp of the value stays below half a step (|v| < 2^52 ·
// step, 4.5e13 at 0.01). `convert` writes LAS → CSV this way unless --decimals asks otherwise.
int lasStepDecimals(const LasHeader& header);

// Bytes of a record of point format 0..10 without extra bytes (20, 28, 26, 34, 57, 63, 30, 36, 38,
// 59, 67); formats 2, 3, 5, 7, 8 and 10 carry RGB.
uint32_t lasBaseRecordLength(int point_format);
bool lasFormatHasRgb(int point_format);

// The writer's first choice of offset for one axis: floor(min) for scales up to 1, floor(min /
// scale) · scale above. A whole number is exact in double, and for the decimal scales people use
// (0.01, 0.001) it is also a multiple of the scale; floor(min / scale) · scale itself is not a
// double for them (0.01 · 63561985 is not), and its rounding error lands in every coordinate read
// back: of 20000 3-digit points at UTM eastings, 765 came back one ulp off with it, none with
// floor(min).
double lasOffsetFor(double min, double scale);

// The ASPRS standard classes (LAS 1.4 R15, table 17) as colours, for LasColorSource::kClassification:
// 0 never classified and 1 unclassified grey, 2 ground brown, 3/4/5 low/medium/high vegetation
// from light to dark green, 6 building brick red, 7 low point (noise) and 18 high noise magenta,
// 9 water blue, 10 rail dark purple, 11 road surface dark grey, 13/14 wires yellow, 15 transmission
// tower orange, 16 wire-structure connector light orange, 17 bridge deck tan, 19 overhead
// structure cyan, 20 ignored ground pale brown, 21 snow white, 22 temporal exclusion pink;
// reserved (8, 12, 23–63) and user-defined (64–255) classes a light grey apart from 0 and 1.
glm::vec3 lasClassColor(uint8_t classification);

}  // namespace dpoint
