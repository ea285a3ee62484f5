#include "generators/sierpinski.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
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
    return Error{"--level " + std::to_string(n) + " is out of range for sierpinski (0.." +
                     std::to_string(kSierpinskiMaxLevel) + ")",
                 ExitCode::kUsage};
  const uint64_t tetrahedra = uint64_t{1} << (2 * n);
  const uint64_t vertices = params.unwelded ? 4 * tetrahedra : 2 * tetrahedra + 2;
  const uint64_t bytes = vertices * sizeof(glm::dvec3) + tetrahedra * 12 * sizeof(uint32_t);
  if (Status s = checkMemory("sierpinski level " + std::to_string(n) + (params.unwelded ? " unwelded" : ""),
                             bytes, params.max_memory);
      !s)
    return s.error();

  PointSet out;
  out.positions.resize(vertices);
  out.triangles.resize(tetrahedra * 12);
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

}  // namespace dpoint
