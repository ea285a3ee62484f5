#include "generators/sierpinski.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "core/memory.h"
#include "core/parallel.h"

namespace dpoint {
namespace {

// Faces of a tetrahedron by corner slot, the face opposite corner k k-th. The seed's tetrahedron
// is negatively oriented (det[v1−v0, v2−v0, v3−v0] < 0) and every child is a positively scaled
// copy of it, so one winding fits all: (1,3,2) etc. are counter-clockwise seen from outside
// (checked by a test).
constexpr int kFaces[4][3] = {{1, 3, 2}, {0, 2, 3}, {0, 3, 1}, {0, 1, 2}};

// For welding: the first place in a tetrahedron's 12 triangle entries where slot j appears.
constexpr std::array<int, 4> primaryEntries() {
  std::array<int, 4> first{-1, -1, -1, -1};
  for (int e = 11; e >= 0; --e) first[static_cast<size_t>(kFaces[e / 3][e % 3])] = e;
  return first;
}
constexpr std::array<int, 4> kPrimaryEntry = primaryEntries();

// Lattice coordinates of the corners of one tetrahedron: tetrahedron t has corner j at
// (base + e_j)/2^n, where base[i] = Σ 2^L over the base-4 digit positions L of t (L = 0 the last
// subdivision) whose digit is i. (Choosing child k at depth m moves the corners by 2^-m·e_k
// toward corner k and halves the tetrahedron; summing the moves gives base.)
struct Corners {
  uint32_t base[4] = {0, 0, 0, 0};
};

Corners cornersOf(uint64_t t, int level) {
  Corners c;
  for (int l = 0; l < level; ++l) c.base[(t >> (2 * l)) & 3] += uint32_t{1} << l;
  return c;
}

struct Frame {
  double s29, s23;  // √(2/9), √(2/3)
  double inv_n;     // 2^-n
  double three_n;   // 3·2^n
  uint32_t n;       // 2^n
};

Frame makeFrame(int level) {
  Frame f;
  f.s29 = std::sqrt(2.0 / 9.0);
  f.s23 = std::sqrt(2.0 / 3.0);
  f.inv_n = std::ldexp(1.0, -level);
  f.n = uint32_t{1} << level;
  f.three_n = 3.0 * f.n;
  return f;
}

// The point with integer barycentric weights w (Σw = 2^n) on the seed's corners, one rounding per
// coordinate. With v1.x = √(8/9) = 2·√(2/9) (also true of the rounded values: 8/9 = 4·(2/9) and a
// correctly rounded sqrt commutes with scaling by 4) the exact coordinates are
//   x = (2b − c − d)·√(2/9) / 2^n,  y = (c − d)·√(2/3) / 2^n,  z = (4a − 2^n) / (3·2^n).
// The integer factors are exact in double, the product with the constant rounds once, and
// dividing by 2^n is exact; z is one correctly rounded division of exact integers. So each
// coordinate is a function of the lattice point alone, and the corners equal the seed's constants.
glm::dvec3 latticePosition(const Frame& f, const int64_t w[4]) {
  const double x = static_cast<double>(2 * w[1] - w[2] - w[3]) * f.s29 * f.inv_n;
  const double y = static_cast<double>(w[2] - w[3]) * f.s23 * f.inv_n;
  const double z = static_cast<double>(4 * w[0] - int64_t{f.n}) / f.three_n;
  return {x, y, z};
}

glm::dvec3 cornerPosition(const Frame& f, const Corners& c, int j) {
  int64_t w[4] = {c.base[0], c.base[1], c.base[2], c.base[3]};
  ++w[j];
  return latticePosition(f, w);
}

// Slot j of tetrahedron t is also corner `other_slot` of exactly one other tetrahedron, unless it
// is one of the 4 outer corners. With L the number of t's lowest base-4 digits equal to j and
// i = t's digit L, the other tetrahedron is t with digit L set to j and digits 0..L−1 set to i
// (both give the lattice point base + e_j). The occurrence listed first "owns" the welded vertex:
// t's own occurrence when i < j, or when t is all j's (an outer corner).
struct Occurrence {
  bool owned;
  uint64_t other_t;  // valid when !owned
  int other_slot;
};

Occurrence occurrence(uint64_t t, int j, int level) {
  int l = 0;
  while (l < level && static_cast<int>((t >> (2 * l)) & 3) == j) ++l;
  if (l == level) return {true, 0, 0};
  const int i = static_cast<int>((t >> (2 * l)) & 3);
  if (i < j) return {true, 0, 0};
  uint64_t other = t & ~((uint64_t{4} << (2 * l)) - 1);  // clear digits 0..l
  other |= uint64_t(j) << (2 * l);
  for (int m = 0; m < l; ++m) other |= uint64_t(i) << (2 * m);
  return {false, other, i};
}

// Owned occurrences (welded vertices) among the tetrahedra [0, t). [0, t) is a union of whole
// subtrees: for each digit position L (most significant first) and each digit v below t's digit
// there, the 4^L tetrahedra with t's digits above L, v at L and any digits below. In such a
// subtree, occurrence (t', j) is decided by t''s digits below L unless they are all j: per j, the
// lowest digit l < L that differs from j is below j for j·4^(L−1−l) of the patterns, so
// Σ_j Σ_l j·4^(L−1−l) = 2·(4^L − 1) occurrences are owned that way (the whole tree, L = n, then
// has 2·4^n − 2, plus its 4 outer corners: 2·4^n + 2); the 4 tetrahedra whose low digits are all
// j are asked directly.
uint64_t ownedBefore(uint64_t t, int level) {
  if (t >= uint64_t{1} << (2 * level)) return 2 * (uint64_t{1} << (2 * level)) + 2;  // all of them
  uint64_t owned = 0;
  for (int l = level - 1; l >= 0; --l) {
    const uint64_t digit = (t >> (2 * l)) & 3;
    const uint64_t high = (t >> (2 * l + 2)) << (2 * l + 2);
    for (uint64_t v = 0; v < digit; ++v) {
      const uint64_t base = high | (v << (2 * l));
      owned += 2 * ((uint64_t{1} << (2 * l)) - 1);
      for (int j = 0; j < 4; ++j) {
        uint64_t all_j = 0;
        for (int m = 0; m < l; ++m) all_j |= uint64_t(j) << (2 * m);
        owned += occurrence(base | all_j, j, level).owned ? 1 : 0;
      }
    }
  }
  return owned;
}

// Index, in the welded order, of the vertex that occurrence (t, j) owns.
uint64_t ownedIndex(uint64_t t, int j, int level) {
  uint64_t index = ownedBefore(t, level);
  for (int k = 0; k < j; ++k) index += occurrence(t, k, level).owned ? 1 : 0;
  return index;
}

}  // namespace

glm::dvec3 sierpinskiCorner(int k) {
  assert(k >= 0 && k < 4);
  const Frame f = makeFrame(0);
  int64_t w[4] = {0, 0, 0, 0};
  w[k] = 1;
  return latticePosition(f, w);
}

Result<PointSet> generateSierpinski(const SierpinskiParams& params) {
  const int n = params.level;
  if (n < 0 || n > kSierpinskiMaxLevel)
    return Error{"--level " + std::to_string(n) + ": must be 0.." + std::to_string(kSierpinskiMaxLevel) +
                     " for sierpinski",
                 ExitCode::kUsage};
  const uint64_t tetrahedra = uint64_t{1} << (2 * n);
  const uint64_t vertices = params.unwelded ? 4 * tetrahedra : 2 * tetrahedra + 2;
  const uint64_t bytes = vertices * sizeof(glm::dvec3) + tetrahedra * 12 * sizeof(uint32_t);
  if (Status s = checkMemory("sierpinski level " + std::to_string(n) + (params.unwelded ? " unwelded" : ""),
                             bytes, params.max_memory);
      !s)
    return s.error();

  PointSet out;
  resizePrefaulted(out.positions, vertices, params.threads);
  resizePrefaulted(out.triangles, tetrahedra * 12, params.threads);
  const Frame frame = makeFrame(n);
  // Work items are whole subtrees (up to 256 of them), each a contiguous range of tetrahedra.
  const int chunk_depth = std::min(n, 4);
  const uint64_t chunks = uint64_t{1} << (2 * chunk_depth);
  const uint64_t per_chunk = tetrahedra / chunks;
  if (params.progress) params.progress->start("sierpinski", tetrahedra);

  if (params.unwelded) {
    parallelFor(chunks, params.threads, [&](size_t chunk, unsigned) {
      for (uint64_t t = chunk * per_chunk; t < (chunk + 1) * per_chunk; ++t) {
        const Corners c = cornersOf(t, n);
        for (int j = 0; j < 4; ++j) out.positions[4 * t + static_cast<uint64_t>(j)] = cornerPosition(frame, c, j);
        for (int e = 0; e < 12; ++e)
          out.triangles[12 * t + static_cast<uint64_t>(e)] = static_cast<uint32_t>(4 * t) + uint32_t(kFaces[e / 3][e % 3]);
      }
      if (params.progress) params.progress->advance(per_chunk);
    });
    if (params.progress) params.progress->finish();
    return out;
  }

  // Welded, in three passes over the same chunks: count the owned occurrences per chunk; number
  // them in order and write their positions, parking each index at its slot's first triangle
  // entry; then fill every other entry, reading the owners' parked indices (an owner's entry is
  // never written in the last pass, so the reads do not race with the writes).
  std::vector<uint64_t> chunk_base(chunks + 1, 0);
  parallelFor(chunks, params.threads, [&](size_t chunk, unsigned) {
    uint64_t owned = 0;
    for (uint64_t t = chunk * per_chunk; t < (chunk + 1) * per_chunk; ++t)
      for (int j = 0; j < 4; ++j) owned += occurrence(t, j, n).owned ? 1 : 0;
    chunk_base[chunk + 1] = owned;
  });
  for (uint64_t c = 0; c < chunks; ++c) chunk_base[c + 1] += chunk_base[c];
  assert(chunk_base[chunks] == vertices);

  parallelFor(chunks, params.threads, [&](size_t chunk, unsigned) {
    uint64_t next = chunk_base[chunk];
    for (uint64_t t = chunk * per_chunk; t < (chunk + 1) * per_chunk; ++t) {
      const Corners c = cornersOf(t, n);
      for (int j = 0; j < 4; ++j) {
        if (!occurrence(t, j, n).owned) continue;
        out.positions[next] = cornerPosition(frame, c, j);
        out.triangles[12 * t + static_cast<uint64_t>(kPrimaryEntry[static_cast<size_t>(j)])] = static_cast<uint32_t>(next);
        ++next;
      }
    }
    assert(next == chunk_base[chunk + 1]);
  });

  parallelFor(chunks, params.threads, [&](size_t chunk, unsigned) {
    for (uint64_t t = chunk * per_chunk; t < (chunk + 1) * per_chunk; ++t) {
      uint32_t index[4];
      for (int j = 0; j < 4; ++j) {
        const uint64_t entry = 12 * t + static_cast<uint64_t>(kPrimaryEntry[static_cast<size_t>(j)]);
        const Occurrence o = occurrence(t, j, n);
        if (o.owned) {
          index[j] = out.triangles[entry];
        } else {
          index[j] = out.triangles[12 * o.other_t + static_cast<uint64_t>(kPrimaryEntry[static_cast<size_t>(o.other_slot)])];
          out.triangles[entry] = index[j];
        }
      }
      for (int e = 0; e < 12; ++e) {
        const int slot = kFaces[e / 3][e % 3];
        if (kPrimaryEntry[static_cast<size_t>(slot)] != e) out.triangles[12 * t + static_cast<uint64_t>(e)] = index[slot];
      }
    }
    if (params.progress) params.progress->advance(per_chunk);
  });
  if (params.progress) params.progress->finish();
  return out;
}


Result<PointTile> generateSierpinskiTile(const SierpinskiParams& params, TileSpec tile) {
  const int n = params.level;
  if (n < 0 || n > kSierpinskiMaxLevel)
    return Error{"--level " + std::to_string(n) + ": must be 0.." + std::to_string(kSierpinskiMaxLevel) +
                     " for sierpinski",
                 ExitCode::kUsage};
  const uint64_t tetrahedra = uint64_t{1} << (2 * n);
  const TileRange range = tileRange(tetrahedra, tile);
  const uint64_t first = range.begin, count = range.end - range.begin;
  const uint64_t most_vertices = params.unwelded ? 4 * count : ownedBefore(range.end, n) - ownedBefore(first, n);
  const uint64_t bytes = most_vertices * sizeof(glm::dvec3) + count * 12 * sizeof(uint32_t);
  if (Status s = checkMemory("sierpinski level " + std::to_string(n) + " tile " + std::to_string(tile.index) + "/" +
                                 std::to_string(tile.count),
                             bytes, params.max_memory);
      !s)
    return s.error();

  PointTile out;
  out.tile = tile;
  PointSet& points = out.points;
  points.triangles.resize(count * 12);
  const Frame frame = makeFrame(n);
  constexpr uint64_t kChunk = 4096;  // tetrahedra per work item
  const uint64_t chunks = (count + kChunk - 1) / kChunk;
  auto chunkEnd = [&](uint64_t c) { return std::min(first + (c + 1) * kChunk, range.end); };
  if (params.progress) params.progress->start("sierpinski", count);

  if (params.unwelded) {  // rows 4t + j, nothing shared
    points.positions.resize(4 * count);
    parallelFor(chunks, params.threads, [&](size_t c, unsigned) {
      for (uint64_t t = first + c * kChunk; t < chunkEnd(c); ++t) {
        const uint64_t local = t - first;
        const Corners corners = cornersOf(t, n);
        for (int j = 0; j < 4; ++j) points.positions[4 * local + uint64_t(j)] = cornerPosition(frame, corners, j);
        for (int e = 0; e < 12; ++e)
          points.triangles[12 * local + uint64_t(e)] = static_cast<uint32_t>(4 * local) + uint32_t(kFaces[e / 3][e % 3]);
      }
      if (params.progress) params.progress->advance(chunkEnd(c) - first - c * kChunk);
    });
    out.owned = static_cast<uint32_t>(points.size());
    if (params.progress) params.progress->finish();
    return out;
  }

  // Welded, as generateSierpinski but over the tile's tetrahedra: owned occurrences numbered in
  // order, each parked at its slot's first triangle entry; every other entry reads its owner's
  // parked index when the owner is in this tile, else names a foreign vertex (resolved after).
  std::vector<uint64_t> chunk_base(chunks + 1, 0);
  parallelFor(chunks, params.threads, [&](size_t c, unsigned) {
    uint64_t owned = 0;
    for (uint64_t t = first + c * kChunk; t < chunkEnd(c); ++t)
      for (int j = 0; j < 4; ++j) owned += occurrence(t, j, n).owned ? 1 : 0;
    chunk_base[c + 1] = owned;
  });
  for (uint64_t c = 0; c < chunks; ++c) chunk_base[c + 1] += chunk_base[c];
  assert(chunk_base[chunks] == most_vertices);
  points.positions.resize(most_vertices);
  out.owned = static_cast<uint32_t>(most_vertices);
  parallelFor(chunks, params.threads, [&](size_t c, unsigned) {
    uint64_t next = chunk_base[c];
    for (uint64_t t = first + c * kChunk; t < chunkEnd(c); ++t) {
      const Corners corners = cornersOf(t, n);
      for (int j = 0; j < 4; ++j) {
        if (!occurrence(t, j, n).owned) continue;
        points.positions[next] = cornerPosition(frame, corners, j);
        points.triangles[12 * (t - first) + uint64_t(kPrimaryEntry[size_t(j)])] = static_cast<uint32_t>(next);
        ++next;
      }
    }
  });
  struct Outside {
    uint64_t entry;  // triangle entry to fill
    uint64_t t;      // the owning occurrence
    int slot;
  };
  std::vector<std::vector<Outside>> outside(chunks);
  parallelFor(chunks, params.threads, [&](size_t c, unsigned) {
    for (uint64_t t = first + c * kChunk; t < chunkEnd(c); ++t) {
      const uint64_t local = t - first;
      uint64_t index[4];  // the local index, or UINT64_MAX for a foreign vertex
      for (int j = 0; j < 4; ++j) {
        const uint64_t entry = 12 * local + uint64_t(kPrimaryEntry[size_t(j)]);
        const Occurrence o = occurrence(t, j, n);
        if (o.owned) {
          index[j] = points.triangles[entry];
        } else if (o.other_t >= first) {
          index[j] = points.triangles[12 * (o.other_t - first) + uint64_t(kPrimaryEntry[size_t(o.other_slot)])];
          points.triangles[entry] = static_cast<uint32_t>(index[j]);
        } else {
          index[j] = UINT64_MAX;
          outside[c].push_back({entry, o.other_t, o.other_slot});
        }
      }
      for (int e = 0; e < 12; ++e) {
        const int slot = kFaces[e / 3][e % 3];
        if (kPrimaryEntry[size_t(slot)] == e) continue;
        if (index[slot] != UINT64_MAX) points.triangles[12 * local + uint64_t(e)] = static_cast<uint32_t>(index[slot]);
        else outside[c].push_back({12 * local + uint64_t(e), 0, -1 - slot});  // same vertex as the slot's primary entry
      }
    }
    if (params.progress) params.progress->advance(chunkEnd(c) - first - c * kChunk);
  });
  // Foreign vertices: a corner shared with a tetrahedron of an earlier tile (a few per tile
  // boundary), copied once each in the order first met.
  std::map<uint64_t, uint32_t> copies;  // owner's index in the whole set → local index
  for (std::vector<Outside>& list : outside) {
    for (const Outside& o : list) {
      if (o.slot < 0) continue;
      const uint64_t global = ownedIndex(o.t, o.slot, n);
      auto [it, added] = copies.emplace(global, static_cast<uint32_t>(points.positions.size()));
      if (added) {
        const uint32_t owner = tileOfItem(tetrahedra, tile.count, o.t);
        const uint64_t owner_first = ownedBefore(tileRange(tetrahedra, {owner, tile.count}).begin, n);
        points.positions.push_back(cornerPosition(frame, cornersOf(o.t, n), o.slot));
        out.foreign.push_back({owner, static_cast<uint32_t>(global - owner_first)});
      }
      points.triangles[o.entry] = it->second;
    }
    for (const Outside& o : list) {  // the other entries of the same slot, from the primary one
      if (o.slot >= 0) continue;
      const uint64_t local = o.entry / 12;
      points.triangles[o.entry] = points.triangles[12 * local + uint64_t(kPrimaryEntry[size_t(-1 - o.slot)])];
    }
  }
  if (params.progress) params.progress->finish();
  return out;
}

}  // namespace dpoint
