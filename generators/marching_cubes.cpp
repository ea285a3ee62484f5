#include "generators/marching_cubes.h"

#include <cassert>
#include <cstdint>

namespace dpoint {
namespace {

// The six cube faces, corners counter-clockwise seen from outside the cube. For the face normal
// +a the corners (0,0), (1,0), (1,1), (0,1) in the axes u = a+1, v = a+2 (mod 3) turn
// counter-clockwise seen from +a because u × v = a; the −a face takes them in reverse.
struct Face {
  std::array<int, 4> corners;
  std::array<int, 4> edges;  // edges[i] joins corners[i] and corners[(i + 1) % 4]
};

int edgeBetween(int c0, int c1) {
  const int diff = c0 ^ c1;
  assert(diff == 1 || diff == 2 || diff == 4);
  const int axis = diff == 1 ? 0 : diff == 2 ? 1 : 2;
  const int base = c0 & c1;
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  return 4 * axis + ((base >> u) & 1) + 2 * ((base >> v) & 1);
}

std::array<Face, 6> cubeFaces() {
  std::array<Face, 6> faces{};
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      const int base = side << axis;
      std::array<int, 4> q = {base, base | (1 << u), base | (1 << u) | (1 << v), base | (1 << v)};
      if (side == 0) q = {q[3], q[2], q[1], q[0]};
      Face& f = faces[static_cast<size_t>(2 * axis + side)];
      f.corners = q;
      for (size_t i = 0; i < 4; ++i) f.edges[i] = edgeBetween(q[i], q[(i + 1) % 4]);
    }
  }
  return faces;
}

struct CaseTable {
  std::array<McCase, 256> cases{};
};

CaseTable buildCaseTable() {
  const std::array<Face, 6> faces = cubeFaces();
  // The two faces of each edge: diagonals between edges of one face would lie in that face.
  std::array<uint8_t, 12> face_bits{};
  for (size_t f = 0; f < faces.size(); ++f)
    for (int e : faces[f].edges) face_bits[static_cast<size_t>(e)] |= static_cast<uint8_t>(1u << f);
  auto shareFace = [&](int a, int b) {
    return (face_bits[static_cast<size_t>(a)] & face_bits[static_cast<size_t>(b)]) != 0;
  };

  CaseTable table;
  for (unsigned mask = 0; mask < 256; ++mask) {
    auto above = [mask](int corner) { return ((mask >> corner) & 1u) != 0; };
    // next[e]: the crossed edge where the loop goes after entering the face at e.
    std::array<int, 12> next;
    next.fill(-1);
    for (const Face& f : faces) {
      for (int i = 0; i < 4; ++i) {
        const bool from = above(f.corners[static_cast<size_t>(i)]);
        const bool to = above(f.corners[static_cast<size_t>((i + 1) % 4)]);
        if (from || !to) continue;  // not an entry into the above-level corners
        for (int d = 1; d < 4; ++d) {  // the next exit in counter-clockwise order
          const int n = (i + d) % 4;
          if (above(f.corners[static_cast<size_t>(n)]) && !above(f.corners[static_cast<size_t>((n + 1) % 4)])) {
            const size_t entry = static_cast<size_t>(f.edges[static_cast<size_t>(i)]);
            assert(next[entry] == -1);  // each crossed edge is entered on exactly one of its faces
            next[entry] = f.edges[static_cast<size_t>(n)];
            break;
          }
        }
      }
    }
    McCase& out = table.cases[mask];
    std::array<bool, 12> used{};
    for (int start = 0; start < 12; ++start) {
      if (next[static_cast<size_t>(start)] < 0 || used[static_cast<size_t>(start)]) continue;
      std::vector<int> loop;
      for (int e = start; !used[static_cast<size_t>(e)]; e = next[static_cast<size_t>(e)]) {
        used[static_cast<size_t>(e)] = true;
        loop.push_back(e);
      }
      const int n = static_cast<int>(loop.size());
      assert(n >= 3);
      // A fan root whose diagonals all cross the cube's inside (one exists for every case).
      int root = -1;
      for (int r = 0; r < n && root < 0; ++r) {
        bool interior = true;
        for (int d = 2; d <= n - 2; ++d)
          interior = interior && !shareFace(loop[static_cast<size_t>(r)], loop[static_cast<size_t>((r + d) % n)]);
        if (interior) root = r;
      }
      assert(root >= 0);
      for (int d = 1; d + 1 < n; ++d) {
        assert(out.triangle_count < kMcMaxTriangles);
        uint8_t* tri = &out.edges[3u * out.triangle_count++];
        tri[0] = static_cast<uint8_t>(loop[static_cast<size_t>(root)]);
        tri[1] = static_cast<uint8_t>(loop[static_cast<size_t>((root + d) % n)]);
        tri[2] = static_cast<uint8_t>(loop[static_cast<size_t>((root + d + 1) % n)]);
      }
    }
  }
  return table;
}

}  // namespace

const McCase& marchingCubesCase(unsigned mask) {
  static const CaseTable table = buildCaseTable();
  assert(mask < 256);
  return table.cases[mask];
}

int mcEdgeAxis(int edge) { return edge / 4; }

int mcEdgeStart(int edge) {
  const int axis = edge / 4, r = edge % 4;
  return ((r & 1) << ((axis + 1) % 3)) | ((r >> 1) << ((axis + 2) % 3));
}

McSlabMesh marchingCubesSlab(int ny, int nz, int first, int last, bool owns_last_plane,
                             const McSlabCallbacks& callbacks, bool seam_positions) {
  assert(ny >= 2 && nz >= 2 && last > first);
  const size_t plane = static_cast<size_t>(ny) * static_cast<size_t>(nz);
  const size_t row = static_cast<size_t>(nz);
  // Two planes in flight, addressed by plane parity. The planes are kept by the thread from slab
  // to slab: every value is written before it is read, and fresh ones would cost a page fault per
  // 4 KiB (at res 2048, 90 MB per slab, most of the meshing's time went to the kernel).
  struct Scratch {
    std::vector<uint8_t> above[2];
    std::vector<uint32_t> ids_y[2], ids_z[2], ids_x;
  };
  thread_local Scratch scratch;
  for (int s = 0; s < 2; ++s) {
    scratch.above[s].resize(plane);
    scratch.ids_y[s].resize(plane);
    scratch.ids_z[s].resize(plane);
  }
  scratch.ids_x.resize(plane);
  std::vector<uint8_t>(&above)[2] = scratch.above;
  std::vector<uint32_t>(&ids_y)[2] = scratch.ids_y;
  std::vector<uint32_t>(&ids_z)[2] = scratch.ids_z;
  std::vector<uint32_t>& ids_x = scratch.ids_x;
  McSlabMesh out;
  uint32_t next_id = 0;

  // Cube-corner offsets and, per edge, where its vertex id lives relative to the cell.
  struct EdgeSlot {
    int axis;
    int dx;
    size_t offset;  // dy·nz + dz
  };
  std::array<EdgeSlot, 12> slots{};
  for (int e = 0; e < 12; ++e) {
    const int c = mcEdgeStart(e);
    slots[static_cast<size_t>(e)] = {mcEdgeAxis(e), c & 1,
                                     static_cast<size_t>((c >> 1) & 1) * row + static_cast<size_t>((c >> 2) & 1)};
  }

  // owned: the positions go to out.positions; seam: to out.seam_positions; neither: ids only.
  auto numberPlane = [&](int p, bool owned, bool seam) {
    PositionArray* positions = owned ? &out.positions : seam ? &out.seam_positions : nullptr;
    const size_t s = static_cast<size_t>(p & 1);
    const uint8_t* a = above[s].data();
    uint32_t count = 0;
    for (int j = 0; j < ny; ++j) {
      const bool has_y = j + 1 < ny;
      for (int k = 0; k < nz; ++k) {
        const size_t pt = static_cast<size_t>(j) * row + static_cast<size_t>(k);
        // Eight points at once where no y or z edge from them is crossed (most of the grid).
        if (k + 8 < nz && mcFlagWord(a + pt) == mcFlagWord(a + pt + 1) && (!has_y || mcFlagWord(a + pt) == mcFlagWord(a + pt + row))) {
          k += 7;
          continue;
        }
        if (has_y && a[pt] != a[pt + row]) {
          ids_y[s][pt] = next_id++;
          ++count;
          if (positions) positions->push_back(callbacks.edge_vertex(p, j, k, 1));
        }
        if (k + 1 < nz && a[pt] != a[pt + 1]) {
          ids_z[s][pt] = next_id++;
          ++count;
          if (positions) positions->push_back(callbacks.edge_vertex(p, j, k, 2));
        }
      }
    }
    return count;
  };

  callbacks.load_plane(first, above[first & 1].data());
  out.first_plane_vertices = numberPlane(first, true, false);
  if (callbacks.plane_done && !callbacks.plane_done(first)) return out;

  for (int l = first; l < last; ++l) {
    const size_t s0 = static_cast<size_t>(l & 1), s1 = s0 ^ 1;
    callbacks.load_plane(l + 1, above[s1].data());
    const uint8_t* a0 = above[s0].data();
    const uint8_t* a1 = above[s1].data();
    for (int j = 0; j < ny; ++j) {
      for (int k = 0; k < nz; ++k) {
        const size_t pt = static_cast<size_t>(j) * row + static_cast<size_t>(k);
        if (k + 8 <= nz && mcFlagWord(a0 + pt) == mcFlagWord(a1 + pt)) {  // no x edge crossed at these eight
          k += 7;
          continue;
        }
        if (a0[pt] != a1[pt]) {
          ids_x[pt] = next_id++;
          out.positions.push_back(callbacks.edge_vertex(l, j, k, 0));
        }
      }
    }
    const bool owned = l + 1 < last || owns_last_plane;
    const uint32_t plane_vertices = numberPlane(l + 1, owned, !owned && seam_positions && l + 1 == last);
    if (l + 1 == last) out.last_plane_vertices = plane_vertices;

    const uint32_t* id_planes[2][3] = {{ids_x.data(), ids_y[s0].data(), ids_z[s0].data()},
                                       {ids_x.data(), ids_y[s1].data(), ids_z[s1].data()}};
    for (int j = 0; j + 1 < ny; ++j) {
      for (int k = 0; k + 1 < nz; ++k) {
        const size_t pt = static_cast<size_t>(j) * row + static_cast<size_t>(k);
        // Eight cubes at once when their 18 corners are all on one side: the words at pt and
        // pt + 1 of the four rows equal one another only when all their bytes are equal.
        if (k + 9 <= nz) {
          const uint64_t w = mcFlagWord(a0 + pt);
          if (w == mcFlagWord(a0 + pt + 1) && w == mcFlagWord(a1 + pt) && w == mcFlagWord(a1 + pt + 1) && w == mcFlagWord(a0 + pt + row) &&
              w == mcFlagWord(a0 + pt + row + 1) && w == mcFlagWord(a1 + pt + row) && w == mcFlagWord(a1 + pt + row + 1)) {
            k += 7;
            continue;
          }
        }
        const unsigned mask = static_cast<unsigned>(a0[pt]) | static_cast<unsigned>(a1[pt]) << 1 |
                              static_cast<unsigned>(a0[pt + row]) << 2 | static_cast<unsigned>(a1[pt + row]) << 3 |
                              static_cast<unsigned>(a0[pt + 1]) << 4 | static_cast<unsigned>(a1[pt + 1]) << 5 |
                              static_cast<unsigned>(a0[pt + row + 1]) << 6 |
                              static_cast<unsigned>(a1[pt + row + 1]) << 7;
        if (mask == 0 || mask == 255) continue;
        const McCase& c = marchingCubesCase(mask);
        for (int t = 0; t < 3 * c.triangle_count; ++t) {
          const EdgeSlot& slot = slots[c.edges[static_cast<size_t>(t)]];
          out.triangles.push_back(id_planes[slot.dx][slot.axis][pt + slot.offset]);
        }
      }
    }
    if (callbacks.plane_done && !callbacks.plane_done(l + 1)) return out;
  }
  out.complete = true;
  return out;
}

PointSet marchingCubes(const std::vector<double>& values, int nx, int ny, int nz, double level,
                       const glm::dvec3& origin, const glm::dvec3& spacing) {
  const size_t sy = static_cast<size_t>(ny), sz = static_cast<size_t>(nz);
  assert(nx >= 2 && values.size() == static_cast<size_t>(nx) * sy * sz);
  auto at = [&](int i, int j, int k) {
    return values[(static_cast<size_t>(i) * sy + static_cast<size_t>(j)) * sz + static_cast<size_t>(k)];
  };
  McSlabCallbacks callbacks;
  callbacks.load_plane = [&](int p, uint8_t* above) {
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) above[static_cast<size_t>(j) * sz + static_cast<size_t>(k)] = at(p, j, k) > level;
  };
  callbacks.edge_vertex = [&](int p, int j, int k, int axis) {
    glm::dvec3 index(p, j, k);
    glm::ivec3 next(p, j, k);
    next[axis] += 1;
    const double v1 = at(p, j, k), v2 = at(next.x, next.y, next.z);
    index[axis] += (level - v1) / (v2 - v1);
    return origin + index * spacing;
  };
  McSlabMesh slab = marchingCubesSlab(ny, nz, 0, nx - 1, true, callbacks);
  PointSet mesh;
  mesh.positions = std::move(slab.positions);
  mesh.triangles = std::move(slab.triangles);
  return mesh;
}

}  // namespace dpoint
