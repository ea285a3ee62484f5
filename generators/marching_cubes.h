// Marching cubes (Lorensen & Cline, "Marching cubes: a high resolution 3D surface construction
// algorithm", SIGGRAPH 1987), streamed over x-planes with welded vertices.
//
// The 256-case table is derived here, not copied: for each corner mask, every cube face
// contributes segments from each crossed face edge where the walk (counter-clockwise seen from
// outside the cube) enters the above-level corners to the next edge where it leaves them; each
// crossed cube edge is entered on one of its two faces and left on the other, so the segments
// chain into closed loops, which are fanned into triangles. On an ambiguous face (two diagonal
// corners above the level) the above-level corners are kept apart; both cells sharing the face
// see the same four corners and make the same choice, so the surface has no cracks. The fan root
// is chosen so that no diagonal lies in a cube face (where the neighbouring cell could draw the
// same edge), so every directed edge of the mesh is used at most once. Orientation: the loop runs
// clockwise around the above-level corners seen from them, so triangle normals (right-hand rule)
// point toward lower values.
//
// Welding: one vertex per crossed grid edge, shared by the up to four cells around it. Vertex
// order (canonical, independent of how the planes are cut into slabs): for plane 0, 1, ...: the
// crossed in-plane edges of the plane (points in (j, k) order, the y edge before the z edge),
// then the crossed x edges to the next plane (points in (j, k) order). Triangles: cells in
// (i, j, k) order, each cell's triangles in table order.
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <functional>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "core/point_set.h"
#include "core/result.h"

namespace dpoint {

// Corner c of a cell sits at offset (c & 1, (c >> 1) & 1, (c >> 2) & 1) from the cell's first
// point. Edge e runs along axis e / 4 from corner mcEdgeStart(e).
constexpr int kMcMaxTriangles = 5;  // as in Lorensen & Cline's table
struct McCase {
  uint8_t triangle_count = 0;
  std::array<uint8_t, 3 * kMcMaxTriangles> edges{};  // 3 cube edges per triangle
};
// mask bit c is set when corner c is above the level.
const McCase& marchingCubesCase(unsigned mask);

// Eight consecutive above-level flags (0 or 1, McSlabCallbacks::load_plane's) as one word, for
// passing over eight points at once where a run of the grid is on one side of the level: all 0
// (kMcNoneAbove) or all 1 (kMcAllAbove), or equal to its neighbours' words.
inline uint64_t mcFlagWord(const uint8_t* p) {
  uint64_t w;
  std::memcpy(&w, p, sizeof w);
  return w;
}
inline constexpr uint64_t kMcNoneAbove = 0, kMcAllAbove = 0x0101010101010101ull;
int mcEdgeAxis(int edge);
int mcEdgeStart(int edge);

// One slab: planes first..last (last > first) of a grid of ny·nz points per x-plane (index
// j·nz + k). The slab owns the vertices on the in-plane edges of planes first..last−1, on the x
// edges between them, and, when owns_last_plane, those of plane `last`; otherwise plane `last`
// belongs to the next slab, whose vertices start with them (a slab that ends a tile may still want
// their positions, as copies: seam_positions).
struct McSlabCallbacks {
  // Sets above[j·nz + k] to 1 when the value at (p, j, k) is above the level, else 0.
  // Called for p = first, first + 1, ..., last in order.
  std::function<void(int p, uint8_t* above)> load_plane;
  // Position of the vertex on the crossed edge from (p, j, k) to its neighbour along `axis`
  // (0: x, 1: y, 2: z). Only for planes among the last two loaded, in canonical vertex order.
  std::function<glm::dvec3(int p, int j, int k, int axis)> edge_vertex;
  // Called after each plane is done with (for progress and cancellation); false stops the slab.
  std::function<bool(int p)> plane_done;
};

struct McSlabMesh {
  PositionArray positions;  // the vertices the slab owns, in canonical order
  // 3 per triangle. An index n ≥ positions.size() is the next slab's vertex n − positions.size().
  std::vector<uint32_t> triangles;
  uint32_t first_plane_vertices = 0;  // crossed in-plane edges of plane `first`
  uint32_t last_plane_vertices = 0;   // crossed in-plane edges of plane `last`
  // With seam_positions and !owns_last_plane: the positions of those last_plane_vertices, in order.
  PositionArray seam_positions;
  bool complete = false;              // false when plane_done stopped it
};

// A slab's mesh in memory someone else owns (a GPU's mesher: generators/gpu_mesh.h): McSlabMesh's
// arrays and counts.
struct McSlabView {
  std::span<const glm::dvec3> positions;
  std::span<const uint32_t> triangles;
  uint32_t first_plane_vertices = 0;
  uint32_t last_plane_vertices = 0;
  std::span<const glm::dvec3> seam_positions;
  std::span<const glm::vec3> colors;  // empty, or one a position (the mesher's noise colours)
  // Made as a binary PLY's rows instead (generators/escape_grid.h EscapeSlab::ply_rows; positions,
  // triangles and colours then empty): the rows of the row_vertices vertices the slab owns (with
  // EscapeSlab::seam_positions followed by the last_plane_vertices copies of the seam's), and its
  // triangles' face rows.
  uint64_t row_vertices = 0;
  std::span<const uint8_t> vertex_rows, face_rows;
  // Where set, the rows are still being copied into that memory (a GPU's transfer queue): the
  // reader calls it first, once, from any one thread; it waits for the copy.
  std::function<Status()> ready;
};

McSlabMesh marchingCubesSlab(int ny, int nz, int first, int last, bool owns_last_plane,
                             const McSlabCallbacks& callbacks, bool seam_positions = false);

// Whole-field convenience: values[(i·ny + j)·nz + k] on an nx·ny·nz grid, surface of
// {value > level}, vertex = origin + (index + t along the edge)·spacing with
// t = (level − v1)/(v2 − v1) from the lower-index end (skimage's formula).
PointSet marchingCubes(const std::vector<double>& values, int nx, int ny, int nz, double level,
                       const glm::dvec3& origin, const glm::dvec3& spacing);

}  // namespace dpoint
