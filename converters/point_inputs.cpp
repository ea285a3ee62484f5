#include "converters/point_inputs.h"

#include <sys/stat.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <tuple>

#include "converters/e57.h"
#include "converters/las.h"
#include "converters/las_crs.h"
#include "converters/ply.h"
#include "converters/tile_file.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "core/text.h"

namespace dpoint {

PointSet joinScans(std::vector<NumberedScan> scans) {
  size_t total = 0;
  for (const NumberedScan& scan : scans) total += scan.points.size();
  PointSet out;
  out.z_axis = ZAxis::kPresent;
  // No copies as the set grows (pages are touched as the scans arrive and leave).
  out.positions.reserve(total);
  uint16_t full = 0;
  for (const NumberedScan& scan : scans) {
    if (!scan.points.hasColors()) continue;
    if (out.colors.capacity() == 0) {
      out.colors.reserve(total);
      full = scan.points.color_full_scale;
    } else if (scan.points.color_full_scale != full) {
      full = 65535;
    }
  }
  for (NumberedScan& each : scans) {
    PointSet& scan = each.points;
    if (each.number != 0) {
      Dimension& source = scan.dimensions.append(dim::kPointSourceId, DimType::kU16, scan.size());
      for (size_t i = 0; i < scan.size(); ++i) source.set<uint16_t>(i, static_cast<uint16_t>(each.number));
    }
    appendPoints(out, scan);
    for (Dimension& d : out.dimensions.all()) d.bytes.reserve(total * dimTypeSize(d.type));
    scan = PointSet();  // its memory back before the next is appended
  }
  out.color_full_scale = full;
  return out;
}

Result<InputSet> checkInputSet(const std::vector<std::string>& paths) {
  InputSet set;
  set.tiles = static_cast<size_t>(std::count_if(paths.begin(), paths.end(), isTileFile));
  if (paths.size() < 2) return set;
  // Each file once by (device, inode), sorted: not every pair compared (3000 inputs took 10.7 s).
  struct Seen {
    dev_t device;
    ino_t inode;
    size_t index;
  };
  std::vector<Seen> seen;
  for (size_t i = 0; i < paths.size(); ++i) {
    struct stat st {};
    if (::stat(paths[i].c_str(), &st) == 0) seen.push_back({st.st_dev, st.st_ino, i});  // else: its reader names it
  }
  std::sort(seen.begin(), seen.end(), [](const Seen& a, const Seen& b) {
    return std::tie(a.device, a.inode, a.index) < std::tie(b.device, b.inode, b.index);
  });
  for (size_t k = 1; k < seen.size(); ++k)
    if (seen[k].device == seen[k - 1].device && seen[k].inode == seen[k - 1].inode)
      return Error{paths[seen[k].index] + ": given twice as an input (also " + paths[seen[k - 1].index] + ")",
                   ExitCode::kUsage};
  if (set.tiles != paths.size()) return set;
  std::vector<std::pair<std::string, uint64_t>> given;  // by index, of the first file's count
  uint32_t count = 0;
  std::string signature;
  for (size_t i = 0; i < paths.size(); ++i) {
    Result<TileHeader> h = readTileHeader(paths[i]);
    if (!h) return h.error();
    if (i == 0) count = h->tile.count, given.assign(count, {}), signature = h->signature;
    // Tiles of several runs (another count, or other options: a tile 0 of each was "tile 0 again"):
    // file by file.
    if (h->tile.count != count || h->signature != signature) return set;
    if (!given[h->tile.index].first.empty())
      return Error{paths[i] + ": tile " + std::to_string(h->tile.index) + " again (also " +
                   given[h->tile.index].first + ")"};
    given[h->tile.index] = {paths[i], h->owned};
  }
  set.whole = paths.size() == count;  // each index once: all of them
  if (set.whole) set.in_tile_order = std::move(given);
  return set;
}

namespace {

// Rows of a float-colour PLY streamed whose colours decide whether they are 0..255 values.
constexpr uint64_t kColorSampleRows = uint64_t{1} << 16;

// A note where tiles are read file by file (one alone, a set with tiles left out, tiles of several
// runs, or tiles beside other files): each brings its copies of the seam vertices, which the
// whole set holds once; the count of points is then not the merged set's. None for a whole set or
// no tile.
std::optional<std::string> tilesFileByFile(const std::vector<std::string>& paths, const InputSet& set) {
  if (set.whole || set.tiles == 0) return std::nullopt;
  return describeInputs(paths) + ": " + (set.tiles == 1 ? std::string("a tile") : std::to_string(set.tiles) + " tiles") +
         " of `generate --tile` read file by file, each with its copies of the seam vertices (a run's N tiles "
         "given together are read as the merged set)";
}

// The coordinate system of several files read as one set: the first file's that states one (empty
// files pass: they add no point). A later file that states another is said and left out, for a
// whole read and a stream alike (a review finding: a stream took an empty file's, a whole read
// the text of a later file over an earlier LAS file's records).
class CrsChoice {
 public:
  void offer(const std::string& path, StatedCrs stated, std::vector<std::string>* notices) {
    if (!stated.any()) return;
    if (from_.empty()) {
      from_ = path, chosen_ = std::move(stated);
    } else if (!stated.sameAs(chosen_) && notices) {
      notices->push_back(path + ": its coordinate system left out: the set takes " + from_ +
                         "'s, the first file's that states one");
    }
  }
  const StatedCrs& chosen() const { return chosen_; }

 private:
  std::string from_;
  StatedCrs chosen_;
};

}  // namespace

Result<PointSet> readPointInputs(const std::vector<std::string>& paths, const ReadOptions& options) {
  if (paths.size() == 1) {
    if (options.notices)
      if (std::optional<std::string> note = tilesFileByFile(paths, InputSet{false, isTileFile(paths[0]) ? 1u : 0u, {}}))
        options.notices->push_back(*note);
    return readPoints(paths[0], options);
  }
  if (options.texture) {  // a texture is one file's: several are read without
    *options.texture = MeshTexture{};
    ReadOptions each = options;
    each.texture = nullptr;
    return readPointInputs(paths, each);
  }
  Result<InputSet> set = checkInputSet(paths);
  if (!set) return set.error();
  if (set->whole) {
    return mergeTiles(paths, options.max_memory, options.progress, options.threads,
                      !options.points_only && !options.faces_unkept);
  }
  if (options.notices)
    if (std::optional<std::string> note = tilesFileByFile(paths, *set)) options.notices->push_back(*note);
  PointSet out;
  CrsChoice crs;
  for (const std::string& path : paths) {
    Result<PointSet> part = readPoints(path, options);
    if (!part) return part.error();
    if (part->size() == 0) continue;
    crs.offer(path, statedCrs(*part), options.notices);
    if (out.size() + part->size() > UINT32_MAX && !part->triangles.empty())
      return Error{path + ": the inputs hold more than 2^32 points, past what triangle indices address",
                   ExitCode::kResourceLimit};
    // Colours white for the files without; dimensions the union, 0 where a file lacks one.
    appendPoints(out, *part);
    if (!out.las) out.las = part->las;  // the first LAS part's frame
  }
  // The chosen coordinate system, as text or as the frame's records (text: none beside it).
  out.crs = crs.chosen().text;
  if (out.las) {
    std::erase_if(out.las->vlrs, [](const LasVlr& vlr) { return isLasCrsRecord(vlr); });
    out.las->vlrs.insert(out.las->vlrs.end(), crs.chosen().records.begin(), crs.chosen().records.end());
  }
  return out;
}

// One file of the stream: a binary PLY, a LAS/LAZ or an E57 file.
struct PointInputStream::Part {
  std::unique_ptr<PlyVertexStream> ply;  // one of the three
  std::unique_ptr<LasPointStream> las;
  std::unique_ptr<E57PointStream> e57;
  uint64_t first = 0;  // the part's first point in the stream
  uint64_t count = 0;  // points it streams (a tile: its owned vertices)

  uint64_t fileCount() const { return ply ? ply->count() : las ? las->count() : e57->count(); }
  bool hasColors() const { return ply ? ply->hasColors() : las ? las->hasColors() : e57->hasColors(); }
  uint64_t faceCount() const { return ply ? ply->faceCount() : 0; }
  const Dimensions& dimensions() const { return ply ? ply->dimensions() : las ? las->dimensions() : e57->dimensions(); }
  void streamDimensions(std::vector<size_t> which) {
    if (ply) ply->streamDimensions(std::move(which));
    else if (las) las->streamDimensions(std::move(which));
    else e57->streamDimensions(std::move(which));
  }
  Status read(uint64_t from, uint64_t n, PointSet& block) {
    return ply ? ply->read(from, n, block) : las ? las->read(from, n, block) : e57->read(from, n, block);
  }
  std::string path;
  bool watch_colors = false;  // a float-colour PLY whose colours above 1 are not yet said
  // A float-colour PLY whose first `sampled` rows' colours are whole numbers above 1: streamed as
  // 0..color_scale values (255, 65535), as readPoints takes such a file's colours.
  uint16_t color_scale = 0;
  uint64_t sampled = 0;
  bool scale_doubted = false;  // a later row's colour no such value: said
};

// A copy of a seam vertex: its owner's index among the owning part's points, and where the copy is.
struct PointInputStream::TileCopies {
  struct Copy {
    uint64_t index;  // the owner, in its part
    uint32_t part;   // the part (tile) holding the copy
    uint32_t f;      // the copy's number there: rows[part] point f
  };
  std::vector<std::vector<Copy>> of;  // of[p]: the copies of part p's points, by index
  std::vector<PointSet> rows;         // rows[p]: part p's copies as read, positions and colours
};

PointInputStream::~PointInputStream() = default;

Status PointInputStream::checkCopies(size_t part, uint64_t first, const PointSet& rows) const {
  if (!copies_) return okStatus();
  const std::vector<TileCopies::Copy>& copies = copies_->of[part];
  auto copy = std::lower_bound(copies.begin(), copies.end(), first,
                               [](const TileCopies::Copy& c, uint64_t index) { return c.index < index; });
  for (; copy != copies.end() && copy->index < first + rows.size(); ++copy) {
    const PointSet& mine = copies_->rows[copy->part];
    const size_t at = static_cast<size_t>(copy->index - first);
    const bool same_position = std::memcmp(&rows.positions[at], &mine.positions[copy->f], sizeof(glm::dvec3)) == 0;
    const bool same_color = !mine.hasColors() || !rows.hasColors() ||
                            std::memcmp(&rows.colors[at], &mine.colors[copy->f], sizeof(glm::vec3)) == 0;
    if (!same_position || !same_color)
      return tileCopyDiffers(parts_[copy->part].path, parts_[part].first + copy->index, same_position);
  }
  return okStatus();
}

Result<std::unique_ptr<PointInputStream>> PointInputStream::open(const std::vector<std::string>& paths,
                                                                 unsigned threads, uint64_t max_memory,
                                                                 bool allow_nonfinite, uint64_t chunk_memory) {
  Result<InputSet> set = checkInputSet(paths);
  if (!set) return set.error();
  std::unique_ptr<PointInputStream> stream(new PointInputStream());
  stream->threads_ = threads;
  std::vector<std::pair<std::string, uint64_t>> files;  // path, points to stream (all: UINT64_MAX)
  // A tile set's copies' references, read before the parts are opened: reading them opens every
  // file once more, and a set of hundreds of tiles must not take twice its files at once (a
  // review finding: 700 tiles under `ulimit -n 1024`).
  std::vector<std::vector<TileVertexRef>> refs;
  if (set->whole) {
    Result<std::vector<std::vector<TileVertexRef>>> read = readTileCopyRefs(paths, threads);
    if (!read) return read.error();
    refs = std::move(*read);
    // What the copies hold for the whole stream: each one's row (position and colour), its place
    // among its owner's copies and, while they are read, its reference (a seam's worth of rows:
    // 89,880 for 40 tiles of 1.36M points).
    uint64_t copies = 0;
    for (const std::vector<TileVertexRef>& mine : refs) copies += mine.size();
    stream->held_bytes_ = copies * (sizeof(glm::dvec3) + sizeof(glm::vec3) + sizeof(TileCopies::Copy) +
                                    sizeof(TileVertexRef));
    if (Status s = checkMemory(describeInputs(paths) + ": holding the " + std::to_string(copies) + " seam copies of " +
                                   std::to_string(paths.size()) + " tiles while they stream",
                               stream->held_bytes_, max_memory);
        !s)
      return s.error();
    files = set->in_tile_order;
  } else {
    for (const std::string& path : paths) files.emplace_back(path, UINT64_MAX);
    if (std::optional<std::string> note = tilesFileByFile(paths, *set)) stream->notices_.push_back(*note);
  }
  CrsChoice crs;
  for (const auto& [path, owned] : files) {
    Part part;
    part.path = path;
    Result<FileFormat> format = formatOf(path);
    if (format && (*format == FileFormat::kLas || *format == FileFormat::kLaz)) {
      Result<std::unique_ptr<LasPointStream>> las = LasPointStream::open(path, threads, chunk_memory);
      if (!las) return las.error();
      part.las = std::move(*las);
      stream->notices_.insert(stream->notices_.end(), part.las->notices().begin(), part.las->notices().end());
    } else if (format && *format == FileFormat::kE57) {
      E57ReadOptions options;
      options.threads = threads;
      options.max_memory = max_memory;
      options.allow_nonfinite = allow_nonfinite;
      Result<std::unique_ptr<E57PointStream>> e57 = E57PointStream::open(path, options);
      if (!e57) return e57.error();
      part.e57 = std::move(*e57);
      stream->held_bytes_ += part.e57->heldBytes();
      stream->e57_index_ = true;
      stream->notices_.insert(stream->notices_.end(), part.e57->notices().begin(), part.e57->notices().end());
    } else {
      PlyReadOptions read{allow_nonfinite, nullptr, threads, true};
      read.notices = &stream->notices_;  // a CRS left out, as the whole read says (a review finding)
      Result<std::unique_ptr<PlyVertexStream>> ply = PlyVertexStream::open(path, read);
      if (!ply) return ply.error();
      part.ply = std::move(*ply);
      part.watch_colors = part.ply->floatColors();
    }
    part.count = std::min(owned, part.fileCount());
    if (part.watch_colors && part.count > 0) {
      // A stream cannot scale colours it has drawn, so the scale is judged from the first rows.
      PointSet sample;
      part.sampled = std::min<uint64_t>(part.count, kColorSampleRows);
      if (Status s = part.read(0, part.sampled, sample); !s) return s.error();
      const WholeColorScale whole = wholeColorScale(sample.colors, 1);
      const std::string first = part.sampled == part.count ? "" : " in its first " + std::to_string(part.sampled) + " rows";
      if (whole.full != 0) {
        part.color_scale = whole.full;
        part.watch_colors = false;
        stream->notices_.push_back(path + ": its float colours are whole numbers above 1" + first +
                                   " (PLY's are 0..1): read as 0.." + std::to_string(whole.full) + " values");
      } else if (whole.odd != UINT64_MAX) {
        part.watch_colors = false;
        stream->notices_.push_back(path + ": " + oddColorNote(sample.colors[whole.odd], whole.odd));
      }
    }
    part.first = stream->count_;
    stream->count_ += part.count;
    if (part.count > 0) stream->has_colors_ = stream->has_colors_ || part.hasColors();
    stream->faces_ += part.faceCount();
    if (part.count > 0) {  // the coordinate system as readPointInputs chooses it
      StatedCrs stated;
      if (part.ply) {
        stated = statedCrs(part.ply->las());  // its CRS records only, as readPointInputs (a review finding)
        stated.text = part.ply->crs();
      } else if (part.e57) {
        stated.text = part.e57->crs();
      } else {
        Result<InputFile> file = InputFile::open(path);
        if (!file) return file.error();
        Result<std::vector<LasVlr>> records = readLasCrsRecords(*file);
        if (!records) return records.error();
        LasSource frame;
        frame.point_format = part.las->header().point_format;
        frame.global_encoding = part.las->header().global_encoding;
        frame.vlrs = std::move(*records);
        stated = statedCrs(std::optional<LasSource>(std::move(frame)));
      }
      crs.offer(path, std::move(stated), &stream->notices_);
    }
    stream->parts_.push_back(std::move(part));
  }
  stream->crs_ = crs.chosen();
  if (set->whole) {
    // Every tile's copies, read once (a seam's worth of rows), to be checked as their owners pass.
    auto copies = std::make_unique<TileCopies>();
    copies->of.resize(stream->parts_.size());
    copies->rows.resize(stream->parts_.size());
    for (size_t t = 0; t < refs.size(); ++t) {
      const std::vector<TileVertexRef>& mine = refs[t];
      if (mine.empty()) continue;
      Part& part = stream->parts_[t];
      if (Status s = part.read(part.count, mine.size(), copies->rows[t]); !s) return s.error();
      for (size_t f = 0; f < mine.size(); ++f)
        copies->of[mine[f].tile].push_back({mine[f].index, static_cast<uint32_t>(t), static_cast<uint32_t>(f)});
    }
    for (std::vector<TileCopies::Copy>& of : copies->of)
      std::sort(of.begin(), of.end(), [](const TileCopies::Copy& a, const TileCopies::Copy& b) {
        return std::tie(a.index, a.part, a.f) < std::tie(b.index, b.part, b.f);
      });
    stream->copies_ = std::move(copies);
  }
  return stream;
}

const Dimensions& PointInputStream::dimensions() const { return parts_.front().dimensions(); }

Dimensions PointInputStream::commonDimensions() const {
  Dimensions common;
  for (const Dimension& d : dimensions().all()) {
    DimType type = d.type;
    bool everywhere = true;
    for (const Part& part : parts_) {
      const Dimension* other = part.dimensions().find(d.name);
      everywhere = everywhere && other != nullptr;
      if (other && !dimTypeHolds(type, other->type)) type = DimType::kF64;  // appendPoints's rule
    }
    if (everywhere) common.append(d.name, type, 0);
  }
  return common;
}

Status PointInputStream::streamDimensions(const std::vector<std::string>& names) {
  const Dimensions common = commonDimensions();  // their types: as readPointInputs joins them
  std::vector<Dimension> streamed;
  for (const std::string& name : names) {
    const Dimension* d = common.find(name);
    if (!d) return Error{"dimension '" + name + "' is not in every file streamed", ExitCode::kUsage};
    streamed.emplace_back(name, d->type);
  }
  for (Part& part : parts_) {
    const std::vector<Dimension>& all = part.dimensions().all();
    std::vector<size_t> which;
    for (const std::string& name : names)
      which.push_back(static_cast<size_t>(
          std::find_if(all.begin(), all.end(), [&](const Dimension& d) { return d.name == name; }) - all.begin()));
    part.streamDimensions(std::move(which));
  }
  streamed_ = std::move(streamed);
  return okStatus();
}

void PointInputStream::noteColorsAboveOne(Part& part, const glm::vec3* colors, size_t n) {
  if (!part.watch_colors || colors == nullptr) return;
  for (size_t i = 0; i < n; ++i)
    if (colors[i].r > 1.0f || colors[i].g > 1.0f || colors[i].b > 1.0f) {
      part.watch_colors = false;
      notices_.push_back(part.path + ": float colours above 1 (0..255 values?) streamed as PLY's 0..1 and clamped; "
                                     "where every colour is a whole number, --stream off reads them as 0..255 values");
      return;
    }
}

void PointInputStream::takeStreamedColors(Part& part, glm::vec3* colors, size_t n, uint64_t first) {
  if (part.color_scale == 0 || colors == nullptr) return;
  constexpr size_t kBlock = size_t{1} << 16;
  const float full = part.color_scale;
  std::vector<std::pair<size_t, glm::vec3>> odd((n + kBlock - 1) / kBlock, {SIZE_MAX, glm::vec3(0.0f)});
  parallelFor(odd.size(), threads_, [&](size_t b, unsigned) {
    for (size_t i = b * kBlock, end = std::min(n, i + kBlock); i < end; ++i) {
      for (int k = 0; k < 3; ++k) {
        const float c = colors[i][k];
        if (!isWholeChannel(c, full) && odd[b].first == SIZE_MAX) odd[b] = {i, colors[i]};
      }
      colors[i] /= full;  // as takeColorsAsIntegers divides a whole read's
    }
  });
  const auto first_odd = std::find_if(odd.begin(), odd.end(), [](const auto& o) { return o.first != SIZE_MAX; });
  if (first_odd == odd.end() || part.scale_doubted) return;
  part.scale_doubted = true;
  const size_t at = first_odd->first;
  const glm::vec3 c = first_odd->second;
  // A whole value past 255 makes the whole read take 0..65535 values; anything else, 0..1 ones.
  bool words = true;
  for (int k = 0; k < 3; ++k) words = words && isWholeChannel(c[k], 65535.0f);
  notices_.push_back(part.path + ": vertex " + std::to_string(first + at) + "'s colour (" + formatNumber(c.r) + ", " +
                     formatNumber(c.g) + ", " + formatNumber(c.b) + ") is not a whole number of 0 to " +
                     std::to_string(part.color_scale) + " a channel, though the first " + std::to_string(part.sampled) +
                     " rows' are: streamed as 0.." + std::to_string(part.color_scale) +
                     " values, clamped (--stream off judges every row first, and then reads the colours as " +
                     (words ? "0..65535" : "0..1") + " values)");
}

Status PointInputStream::read(uint64_t first, uint64_t n, PointSet& block) {
  assert(first <= count_ && n <= count_ - first);
  if (parts_.size() == 1) {  // straight into the block
    if (Status s = parts_[0].read(first, n, block); !s) return s;
    if (Status s = checkCopies(0, first, block); !s) return s;
    takeStreamedColors(parts_[0], block.hasColors() ? block.colors.data() : nullptr, block.size(), first);
    noteColorsAboveOne(parts_[0], block.hasColors() ? block.colors.data() : nullptr, block.size());
    if (has_colors_ && !block.hasColors()) block.colors.assign(block.size(), glm::vec3(1.0f));
    return okStatus();
  }
  block.triangles.clear();
  block.positions.resize(static_cast<size_t>(n));
  block.colors.resize(has_colors_ ? static_cast<size_t>(n) : 0);
  std::vector<const Dimension*> like;
  for (const Dimension& d : streamed_) like.push_back(&d);
  block.dimensions.shapeUnset(like, n);
  const uint64_t end = first + n;
  for (Part& part : parts_) {
    const uint64_t from = std::max(first, part.first), to = std::min(end, part.first + part.count);
    if (from >= to) continue;
    if (Status s = part.read(from - part.first, to - from, scratch_); !s) return s;
    if (Status s = checkCopies(static_cast<size_t>(&part - parts_.data()), from - part.first, scratch_); !s) return s;
    takeStreamedColors(part, scratch_.hasColors() ? scratch_.colors.data() : nullptr, scratch_.size(), from - part.first);
    noteColorsAboveOne(part, scratch_.hasColors() ? scratch_.colors.data() : nullptr, scratch_.size());
    const auto at = static_cast<ptrdiff_t>(from - first);
    std::copy(scratch_.positions.begin(), scratch_.positions.end(), block.positions.begin() + at);
    for (size_t k = 0; k < streamed_.size(); ++k) {
      const Dimension& from_part = scratch_.dimensions.all()[k];
      Dimension& into = block.dimensions.all()[k];
      if (from_part.type == into.type)
        std::copy(from_part.bytes.begin(), from_part.bytes.end(), into.bytes.begin() + at * ptrdiff_t(dimTypeSize(into.type)));
      else  // float64: holds every other type's values (but 64-bit integers past 2^53, as everywhere)
        for (size_t i = 0; i < scratch_.size(); ++i) into.setValue(static_cast<size_t>(at) + i, from_part.value(i));
    }
    if (!has_colors_) continue;
    if (scratch_.hasColors()) std::copy(scratch_.colors.begin(), scratch_.colors.end(), block.colors.begin() + at);
    else std::fill_n(block.colors.begin() + at, scratch_.size(), glm::vec3(1.0f));
  }
  return okStatus();
}

Result<std::unique_ptr<PointInputStream>> openPointStream(const std::vector<std::string>& paths,
                                                          const std::string& stream, unsigned threads,
                                                          uint64_t max_memory, bool allow_nonfinite) {
  const bool streamable = std::all_of(paths.begin(), paths.end(), [](const std::string& path) {
    Result<FileFormat> format = formatOf(path);
    return format && (*format == FileFormat::kPly || *format == FileFormat::kLas || *format == FileFormat::kLaz ||
                      *format == FileFormat::kE57);
  });
  if (stream == "off") return std::unique_ptr<PointInputStream>();
  if (!streamable) {
    if (stream == "on")
      return Error{describeInputs(paths) + ": --stream on reads binary PLY, LAS, LAZ and E57 files", ExitCode::kUsage};
    return std::unique_ptr<PointInputStream>();
  }
  // An E57 stream reads its whole file as it opens (E57PointStream): under auto, E57 files whose
  // scans declare no more records than a stream is for are read whole without that pass.
  if (stream == "auto") {
    uint64_t declared = 0;
    bool all_e57 = true;
    for (const std::string& path : paths) {
      Result<FileFormat> format = formatOf(path);
      if (!format || *format != FileFormat::kE57) {
        all_e57 = false;
        continue;
      }
      Result<uint64_t> records = e57RecordCount(path);
      if (!records) return std::unique_ptr<PointInputStream>();  // read whole: the reader reports what is wrong
      declared = declared > UINT64_MAX - *records ? UINT64_MAX : declared + *records;
    }
    if (all_e57 && declared <= kStreamAbovePoints) return std::unique_ptr<PointInputStream>();
  }
  // Under auto the set may yet be read whole: the copies are held to the default limit only, and
  // --max-memory applies once the stream is chosen (checkStreamMemory with heldBytes). A stream
  // that cannot open (an ASCII file, too many files for the open-file limit) is read whole.
  Result<std::unique_ptr<PointInputStream>> opened =
      PointInputStream::open(paths, threads, stream == "on" ? max_memory : 0, allow_nonfinite, max_memory);
  if (!opened) {
    // A LAZ chunk past --max-memory is past it read whole too: said now, not after a whole read.
    if (stream == "on" || opened.error().code == ExitCode::kResourceLimit) return opened.error();
    return std::unique_ptr<PointInputStream>();  // read whole: the reader reports what is wrong
  }
  if (stream == "on" || (*opened)->count() > kStreamAbovePoints) return opened;
  return std::unique_ptr<PointInputStream>();
}

}  // namespace dpoint
