#include "generators/menger.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/memory.h"
#include "core/parallel.h"
#include "core/text.h"

namespace dpoint {
namespace {

// Membership is decided a whole lattice row at a time. Along a row (x, y fixed, z varying) cell z
// is in the sponge iff x and y share no digit-1 position and z has no digit 1 at a position where
// x or y has one. So a row is one of 2^n bit patterns (indexed by the positions D where x or y has
// a 1), or empty, and exposed faces and used lattice points are bit operations on a few rows.
class Lattice {
 public:
  explicit Lattice(int level) {
    side_ = 1;
    for (int l = 0; l < level; ++l) side_ *= 3;
    words_ = (side_ + 1 + 63) / 64;  // rows hold side+1 lattice points, side cells
    ones_.resize(side_);
    for (uint32_t v = 0; v < side_; ++v) {
      uint32_t mask = 0;
      for (uint32_t rest = v, bit = 1; rest != 0; rest /= 3, bit <<= 1)
        if (rest % 3 == 1) mask |= bit;
      ones_[v] = mask;
    }
    const size_t patterns = size_t{1} << level;
    rows_.assign((patterns + 1) * words_, 0);  // pattern D at D·words; the last one stays empty
    for (size_t d = 0; d < patterns; ++d)
      for (uint32_t z = 0; z < side_; ++z)
        if ((ones_[z] & d) == 0) rows_[d * words_ + z / 64] |= uint64_t{1} << (z % 64);
    empty_ = rows_.data() + patterns * words_;
  }

  uint32_t side() const { return side_; }
  size_t words() const { return words_; }

  // Cells (x, y, 0 .. side−1) as bits; an empty row outside [0, side)².
  const uint64_t* row(int64_t x, int64_t y) const {
    if (x < 0 || y < 0 || x >= side_ || y >= side_) return empty_;
    const uint32_t mx = ones_[static_cast<size_t>(x)], my = ones_[static_cast<size_t>(y)];
    if ((mx & my) != 0) return empty_;
    return rows_.data() + size_t{mx | my} * words_;
  }

 private:
  uint32_t side_ = 1;
  size_t words_ = 1;
  std::vector<uint32_t> ones_;  // bit l set iff base-3 digit l of v is 1
  std::vector<uint64_t> rows_;
  const uint64_t* empty_ = nullptr;
};

// Bit k of the result is bit k−1 of `bits` (0 for k = 0).
uint64_t shiftedUp(const uint64_t* bits, size_t w) { return (bits[w] << 1) | (w > 0 ? bits[w - 1] >> 63 : 0); }
// Bit k of the result is bit k+1 of `bits`.
uint64_t shiftedDown(const uint64_t* bits, size_t w, size_t words) {
  return (bits[w] >> 1) | (w + 1 < words ? bits[w + 1] << 63 : 0);
}

// The used lattice points of plane x = i (corners of exposed faces) with their ranks. A point is
// used iff its 8 surrounding cells are neither all in nor all out of the sponge: the cells around
// a point are joined by the 12 faces through it, so a mixed set has an exposed face there, and an
// exposed face has cells of both kinds around each of its corners.
struct Plane {
  std::vector<uint64_t> used;   // row j at j·words
  std::vector<uint32_t> count;  // used bits in the plane before word (j, w)
  uint32_t total = 0;

  void build(const Lattice& lattice, int64_t i) {
    const size_t words = lattice.words();
    const uint32_t side = lattice.side();
    used.resize((side + 1) * words);
    count.resize((side + 1) * words);
    total = 0;
    for (int64_t j = 0; j <= side; ++j) {
      const uint64_t* r[4] = {lattice.row(i - 1, j - 1), lattice.row(i - 1, j), lattice.row(i, j - 1),
                              lattice.row(i, j)};
      uint64_t* out = used.data() + static_cast<size_t>(j) * words;
      for (size_t w = 0; w < words; ++w) {
        // any[k]/all[k]: some/every cell at z = k of the 4 rows is in the sponge.
        const uint64_t any = r[0][w] | r[1][w] | r[2][w] | r[3][w];
        const uint64_t all = r[0][w] & r[1][w] & r[2][w] & r[3][w];
        const uint64_t any_up = shiftedUp(r[0], w) | shiftedUp(r[1], w) | shiftedUp(r[2], w) | shiftedUp(r[3], w);
        const uint64_t all_up = shiftedUp(r[0], w) & shiftedUp(r[1], w) & shiftedUp(r[2], w) & shiftedUp(r[3], w);
        out[w] = (any | any_up) & ~(all & all_up);  // point k touches cells k−1 and k
        count[static_cast<size_t>(j) * words + w] = total;
        total += static_cast<uint32_t>(std::popcount(out[w]));
      }
    }
  }

  // Rank of used point (j, k) within the plane.
  uint32_t rank(size_t words, uint32_t j, uint32_t k) const {
    const size_t at = j * words + k / 64;
    assert((used[at] >> (k % 64)) & 1);
    return count[at] + static_cast<uint32_t>(std::popcount(used[at] & ((uint64_t{1} << (k % 64)) - 1)));
  }
};

// Exposed faces of one cell row (i, j), by direction −x, +x, −y, +y, −z, +z: word w of each.
void exposedWords(const Lattice& lattice, int64_t i, int64_t j, size_t w, uint64_t faces[6]) {
  const size_t words = lattice.words();
  const uint64_t* cells = lattice.row(i, j);
  const uint64_t c = cells[w];
  faces[0] = c & ~lattice.row(i - 1, j)[w];
  faces[1] = c & ~lattice.row(i + 1, j)[w];
  faces[2] = c & ~lattice.row(i, j - 1)[w];
  faces[3] = c & ~lattice.row(i, j + 1)[w];
  faces[4] = c & ~shiftedUp(cells, w);
  faces[5] = c & ~shiftedDown(cells, w, words);
}

// Corners of the unit face of cell (0,0,0) in each direction, counter-clockwise seen from outside
// (the cross product of the first two edges points along the direction).
constexpr int kQuads[6][4][3] = {
    {{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {0, 1, 0}},  // −x
    {{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}},  // +x
    {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}},  // −y
    {{0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0}},  // +y
    {{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}},  // −z
    {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}},  // +z
};

uint64_t power(uint64_t base, int exponent) {
  uint64_t p = 1;
  for (int e = 0; e < exponent; ++e) p *= base;
  return p;
}

}  // namespace

uint64_t mengerFaceCount(int level) { return 2 * power(20, level) + 4 * power(8, level); }

uint64_t mengerVertexCount(int level) {
  return (224 * power(20, level) + 456 * power(8, level) + 384) / 133;
}

bool mengerCellInSponge(uint64_t x, uint64_t y, uint64_t z) {
  for (; x != 0 || y != 0 || z != 0; x /= 3, y /= 3, z /= 3) {
    const int ones = (x % 3 == 1) + (y % 3 == 1) + (z % 3 == 1);
    if (ones >= 2) return false;
  }
  return true;
}

namespace {

Status validate(const MengerParams& params) {
  const int n = params.level;
  if (n < 0 || n > kMengerMaxLevel)
    return Error{"--level " + std::to_string(n) + ": must be 0.." + std::to_string(kMengerMaxLevel) + " for menger",
                 ExitCode::kUsage};
  if (!(params.size > 0.0) || !std::isfinite(params.size))
    return Error{"--size " + formatNumber(params.size) + ": must be a finite number above 0", ExitCode::kUsage};
  // The lattice's k · size (k up to 3^level) must stay finite: 1e308 made infinite coordinates.
  if (!std::isfinite(params.size * std::pow(3.0, n)))
    return Error{"--size " + formatNumber(params.size) + ": too large for level " + std::to_string(n) +
                     " (the lattice's coordinates reach size · 3^level, beyond double's range; at most " +
                     formatNumber(std::numeric_limits<double>::max() / std::pow(3.0, n)) + ")",
                 ExitCode::kUsage};
  return okStatus();
}

// The cell slabs x ∈ [first, last) of the exact mesh: the used points of planes first ..
// last − 1 (and of plane `last` when it is the sponge's last, side), then the faces of the slabs.
// A face corner on plane `last` that the range does not own is index (points owned) + its rank in
// the plane, and `seam` holds those points' positions (the whole plane, in rank order).
struct RangeMesh {
  PointSet mesh;
  PositionArray seam;
};

Result<RangeMesh> meshRange(const MengerParams& params, const Lattice& lattice, uint32_t first, uint32_t last,
                            const std::string& what) {
  const uint32_t side = lattice.side();
  const size_t words = lattice.words();
  assert(first < last && last <= side);
  const bool owns_last = last == side;
  const size_t planes = last - first + 1;

  // Pass 1: used points per plane x = first + item and exposed faces per cell slab.
  std::vector<uint64_t> vertex_base(planes + 1, 0), face_base(planes + 1, 0);
  parallelFor(planes, params.threads, [&](size_t item, unsigned) {
    const int64_t i = static_cast<int64_t>(first + item);
    Plane plane;
    plane.build(lattice, i);
    vertex_base[item + 1] = plane.total;
    uint64_t count = 0;
    if (item + 1 < planes) {
      for (int64_t j = 0; j < side; ++j)
        for (size_t w = 0; w < words; ++w) {
          uint64_t exposed[6];
          exposedWords(lattice, i, j, w, exposed);
          for (uint64_t e : exposed) count += static_cast<uint64_t>(std::popcount(e));
        }
    }
    face_base[item + 1] = count;
  });
  for (size_t i = 0; i < planes; ++i) {
    vertex_base[i + 1] += vertex_base[i];
    face_base[i + 1] += face_base[i];
  }
  const uint64_t owned = owns_last ? vertex_base[planes] : vertex_base[planes - 1];
  const uint64_t faces = face_base[planes];
  if (Status s = checkMemory(what, vertex_base[planes] * sizeof(glm::dvec3) + faces * 6 * sizeof(uint32_t),
                             params.max_memory);
      !s)
    return s.error();
  if (vertex_base[planes] > UINT32_MAX)
    return Error{what + " has " + std::to_string(vertex_base[planes]) +
                     " vertices, more than 32-bit triangle indices can address",
                 ExitCode::kResourceLimit};

  // One coordinate per lattice integer, shared by every point on that plane, so faces are exactly
  // flat and welding needs no double comparison. k·size is exact when size is 1 (or a power of
  // two, or an integer below 2^40), leaving one correctly rounded division by 3^n; otherwise it is
  // two roundings of at most half an ulp each.
  std::vector<double> coordinate(side + 1);
  for (uint32_t k = 0; k <= side; ++k) coordinate[k] = (static_cast<double>(k) * params.size) / side;

  RangeMesh out;
  out.mesh.positions.resize(owned);
  out.seam.resize(vertex_base[planes] - owned);
  out.mesh.triangles.resize(faces * 6);
  if (params.progress) params.progress->start("menger", faces);

  // Pass 2: item i writes the points of plane first + i and the faces of the cell slab there
  // (whose corners lie on that plane and the next). Each worker keeps its own two planes.
  const unsigned workers = resolveThreads(params.threads);
  std::vector<Plane> lower(workers), upper(workers);
  parallelFor(planes, params.threads, [&](size_t item, unsigned worker) {
    const int64_t i = static_cast<int64_t>(first + item);
    Plane& here = lower[worker];
    Plane& next = upper[worker];
    here.build(lattice, i);
    assert(vertex_base[item] + here.total == vertex_base[item + 1]);
    const bool seam = item + 1 == planes && !owns_last;
    glm::dvec3* v = seam ? out.seam.data() : out.mesh.positions.data() + vertex_base[item];
    for (uint32_t j = 0; j <= side; ++j)
      for (size_t w = 0; w < words; ++w)
        for (uint64_t bits = here.used[j * words + w]; bits != 0; bits &= bits - 1) {
          const size_t k = w * 64 + static_cast<size_t>(std::countr_zero(bits));
          *v++ = glm::dvec3(coordinate[static_cast<size_t>(i)], coordinate[j], coordinate[k]);
        }
    if (item + 1 == planes) return;

    next.build(lattice, i + 1);
    const Plane* pair[2] = {&here, &next};
    const uint32_t base[2] = {static_cast<uint32_t>(vertex_base[item]), static_cast<uint32_t>(vertex_base[item + 1])};
    uint32_t* tri = out.mesh.triangles.data() + face_base[item] * 6;
    std::vector<uint64_t> exposed(6 * words);  // direction d, word w at d·words + w
    for (uint32_t j = 0; j < side; ++j) {
      for (size_t w = 0; w < words; ++w) {
        uint64_t row_faces[6];
        exposedWords(lattice, i, j, w, row_faces);
        for (size_t d = 0; d < 6; ++d) exposed[d * words + w] = row_faces[d];
      }
      for (int dir = 0; dir < 6; ++dir)
        for (size_t w = 0; w < words; ++w) {
          for (uint64_t bits = exposed[static_cast<size_t>(dir) * words + w]; bits != 0; bits &= bits - 1) {
            const uint32_t k = static_cast<uint32_t>(w * 64) + static_cast<uint32_t>(std::countr_zero(bits));
            uint32_t corner[4];
            for (int c = 0; c < 4; ++c) {
              const int* d = kQuads[dir][c];
              corner[c] = base[d[0]] + pair[d[0]]->rank(words, j + uint32_t(d[1]), k + uint32_t(d[2]));
            }
            *tri++ = corner[0], *tri++ = corner[1], *tri++ = corner[2];
            *tri++ = corner[0], *tri++ = corner[2], *tri++ = corner[3];
          }
        }
    }
    assert(tri == out.mesh.triangles.data() + face_base[item + 1] * 6);
    if (params.progress) params.progress->advance(face_base[item + 1] - face_base[item]);
  });
  if (params.progress) params.progress->finish();
  return out;
}

}  // namespace

Result<PointSet> generateMenger(const MengerParams& params) {
  if (Status s = validate(params); !s) return s.error();
  if (params.method == MengerMethod::kVoxel) return generateMengerVoxel(params);

  const int n = params.level;
  const uint64_t faces = mengerFaceCount(n);
  const uint64_t vertices = mengerVertexCount(n);
  const std::string what = "menger level " + std::to_string(n);
  // Checked before the lattice is built, from the closed forms.
  if (Status s = checkMemory(what, vertices * sizeof(glm::dvec3) + faces * 6 * sizeof(uint32_t), params.max_memory); !s)
    return s.error();
  if (vertices > UINT32_MAX)
    return Error{what + " has " + std::to_string(vertices) + " vertices, more than 32-bit triangle indices can address",
                 ExitCode::kResourceLimit};
  const Lattice lattice(n);
  Result<RangeMesh> whole = meshRange(params, lattice, 0, lattice.side(), what);
  if (!whole) return whole.error();
  assert(whole->mesh.triangles.size() == faces * 6 && whole->mesh.size() == vertices);
  return std::move(whole->mesh);
}

Result<PointTile> generateMengerTile(const MengerParams& params, TileSpec tile) {
  if (Status s = validate(params); !s) return s.error();
  if (params.method == MengerMethod::kVoxel)
    return Error{"--tile: menger --method voxel has no split; use --method exact (the default)", ExitCode::kUsage};
  const Lattice lattice(params.level);
  const TileRange range = tileRange(lattice.side(), tile);
  PointTile out;
  out.tile = tile;
  if (range.empty()) return out;
  const std::string what = "menger level " + std::to_string(params.level) + " tile " + std::to_string(tile.index) +
                           "/" + std::to_string(tile.count);
  Result<RangeMesh> part =
      meshRange(params, lattice, static_cast<uint32_t>(range.begin), static_cast<uint32_t>(range.end), what);
  if (!part) return part.error();
  out.points = std::move(part->mesh);
  out.owned = static_cast<uint32_t>(out.points.size());
  // The seam plane's points open the next non-empty tile's own, in the same (rank) order.
  const uint32_t next = nextNonEmptyTile(lattice.side(), tile);
  for (size_t i = 0; i < part->seam.size(); ++i) {
    out.points.positions.push_back(part->seam[i]);
    out.foreign.push_back({next, static_cast<uint32_t>(i)});
  }
  return out;
}

}  // namespace dpoint
