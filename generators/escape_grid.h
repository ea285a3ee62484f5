// Escape-time fractals on a grid, meshed at a level of the escape count (DESIGN §8): the part the
// Mandelbulb and the quaternion Julia share.
//
// Grid convention (shared/reference/README.md): axis value v[i] = lo + i·step with
// step = (hi − lo)/(res − 1) in double and v[res − 1] = hi exactly (numpy.linspace, which the
// seed used: its grids are reproduced byte for byte); layout [i][j][k], i along x, k fastest.
//
// Only what is needed: the surface at level L separates counts ≤ L from counts > L, so a first
// pass iterates every point only up to cap = ⌊L⌋ + 1 (min(count, cap) > L exactly when
// count > L), and the full count is finished only at the points above the level that end a
// crossed grid edge — the only values marching cubes interpolates. Points below the level already
// hold their exact count (it is < cap). Interior points far from the surface thus cost cap
// iterations instead of max_iter, and the mesh is the one the full grid gives, bit for bit.
//
// Slabs and streaming: the x-planes are cut into slabs of a few planes, meshed in parallel
// (parallelFor) by marching_cubes.h, two planes in memory per worker; a slab's result is appended
// in slab order as soon as its predecessors are done, so the whole grid is never held (a
// resolution-1024 run keeps a few 1024² planes per worker plus the mesh) and the output does not
// depend on the thread count. --grid-out needs every count, so it turns the lazy pass off and
// streams the planes to the file in the same order.
//
// Elsewhere: a plane function (a GPU, generators/gpu_generate.h) may compute the classification pass
// instead of the row function, a slab's planes at a time on a thread of its own, ahead of the
// workers that mesh earlier slabs (at most threads + 2 slabs of counts held, in the function's
// arena when it offers one: a GPU then writes them where the workers read them). Finishing the
// crossings, marching cubes and writing stay here. The function must return the row function's
// counts bit for bit, so the mesh is the same either way.
//
// Tiles (core/tile.h): the cell layers split into N contiguous shares; a tile meshes its own and
// copies the in-plane vertices of its last plane, which open the next tile's own vertices.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/point_set.h"
#include "core/progress.h"
#include "core/result.h"
#include "core/tile.h"
#include "generators/marching_cubes.h"

namespace dpoint {

// Coordinates of the output vertices.
enum class GridFrame {
  kNative,  // the fractal's own: v = lo + index·step ([-1.5, 1.5]³ by default)
  kSeed,    // the seed's (skimage with spacing = step): index·step, grid corner at the origin
};

constexpr int kMaxGridResolution = 65536;
constexpr int kMaxEscapeIterations = 65535;  // counts fit the uint16 grid file

// Samples of one axis: v[i] = lo + i·step, the last exactly hi (numpy.linspace).
struct GridAxis {
  int resolution = 200;
  double lo = -1.5, hi = 1.5;
  double step() const { return (hi - lo) / (resolution - 1); }
  double value(int i) const { return i == resolution - 1 ? hi : lo + i * step(); }
};

// Escape counts of the points (x, y, zs[0..n)), each iterated at most `limit` times: counts[k] =
// min(count, limit). Must be a pure function of its arguments (called from several threads).
using EscapeRowFunction =
    std::function<void(double x, double y, const double* zs, size_t n, int limit, uint32_t* counts)>;

// Escape counts of whole x-planes: count (p − first)·res² + j·res + k = min(count, limit) for planes
// first ≤ p < first + planes, equal to the row function's, each in escapeGridBytesPerCount(limit)
// little-endian bytes (the grid file's encoding: one byte at the usual limits, a quarter of what
// uint32 counts would copy out of a GPU and through the mesher). Called from one thread at a time.
using EscapePlaneFunction = std::function<Status(int first, int planes, int limit, uint8_t* counts)>;

// Memory that the plane function fills fastest, `bytes` of it, valid until the next call (a GPU's
// mapped buffer, which its dispatches write in place: no copy out of a staging buffer); nullptr
// when there is none. The blocks of counts are then carved from it.
using EscapeArena = std::function<uint8_t*(uint64_t bytes)>;

// A slab of the grid for a mesher elsewhere (EscapeSlabMesher), which makes its counts (the plane
// function's, every count to max_iter) where it meshes them.
struct EscapeSlab {
  int res = 0;
  int first = 0, last = 0;       // planes first..last (last > first): cell layers first..last − 1
  bool owns_last_plane = false;  // as marchingCubesSlab's arguments
  bool seam_positions = false;
  int limit = 0;                 // the counts' limit: max_iter
  double level = 0.0;
  GridFrame frame = GridFrame::kNative;
  const std::vector<double>* values = nullptr;  // the axis: GridAxis::value(i), i < res
  double step = 0.0;                            // GridAxis::step()
  bool noise_colors = false;                    // the vertices' seedColor too (generators/perlin.h)
  // The mesh as a binary PLY's rows (McSlabView::vertex_rows, face_rows): x, y, z as doubles, and
  // with noise_colors red, green, blue as bytes (float_colors: as floats, a tile's part file's
  // rows); faces as the byte 3 and three uint ids, each the slab's own plus vertex_base. With
  // seam_positions the vertex rows go on with the seam plane's vertices (a tile's copies).
  bool ply_rows = false;
  bool float_colors = false;
  uint32_t vertex_base = 0;
  size_t rowBytes() const { return noise_colors ? (float_colors ? 36 : 27) : 24; }
};

// Marching cubes elsewhere (a GPU, generators/gpu_mesh.h): the counts and the mesh of a slab
// there, the mesh marchingCubesSlab makes with this file's vertices, bit for bit. Used, in place of
// the plane function, when `takes` the run's largest slab (planes of res² counts up to limit).
// `mesh` is called for the slabs in order, from one thread; its view stays valid until the second
// call after it returns (the caller copies one slab out while the next is made). `next`, where not
// null, is the slab the following call will mesh: its counts may be made meanwhile.
struct EscapeSlabMesher {
  std::function<bool(int res, int planes, int limit)> takes;
  std::function<Result<McSlabView>(const EscapeSlab& slab, const EscapeSlab* next)> mesh;
  // Optional: memory for slabs of up to `vertices` vertices and `triangles` triangles made at once,
  // with colours and as rows as EscapeSlab says (else it grows as the slabs do, which on a GPU
  // costs a host-visible allocation on the way from one slab's passes to the next).
  // row_bytes: EscapeSlab::rowBytes() where the slabs are made as rows, else 0.
  std::function<Status(uint64_t vertices, uint64_t triangles, bool colors, size_t row_bytes)> reserve;
};

// Where a surface meshed elsewhere goes as a binary PLY's rows as they are made, in place of the
// mesh (a PlyRowStream, converters/ply.h, written while the device makes the next slab): the whole
// surface, or a tile's part (its owned vertices, then the copies of the seam's, as
// converters/tile_file.h lays them out). Taken only where the mesher meshes every slab, and with
// `colors` makes the noise colours too; then the set returned is empty, and `start` has been called.
struct EscapeRowSink {
  bool colors = false;        // the vertex rows carry the seed noise colours (EscapeSlab::noise_colors)
  bool float_colors = false;  // as floats (EscapeSlab::float_colors)
  // Once, before any slab: the whole mesh's vertices and triangles, estimated from a sample of its
  // cell layers (within a few percent; exact when every layer is sampled).
  std::function<Status(uint64_t vertices, uint64_t triangles)> start;
  // Each slab's rows, in slab order, from one thread (not the mesher's); the face rows' ids are
  // the whole mesh's.
  std::function<Status(std::span<const uint8_t> vertex_rows, std::span<const uint8_t> face_rows)> slab;
};

struct EscapeSurfaceParams {
  std::string name = "fractal";  // for messages and progress
  GridAxis axis;
  int max_iter = 100;
  double level = 25.0;           // resolved: inside (0, max_iter)
  GridFrame frame = GridFrame::kNative;
  bool lazy = true;              // false: every count to max_iter (tests; implied by grid_out)
  std::string grid_out;          // non-empty: also write the raw count grid there
  unsigned threads = 0;          // 0: all cores
  uint64_t max_memory = 0;       // bytes; 0: half of physical memory
  Progress* progress = nullptr;
  EscapePlaneFunction planes;    // empty: the row function classifies too
  EscapeArena arena;             // where the plane function's blocks go; empty: the heap
  // With the plane function, final counts (not lazy) and no grid_out: counts and meshes the slabs.
  EscapeSlabMesher mesher;
  // Where the mesher meshes and every coordinate lies in the noise's fast range: it makes the
  // vertices' seed noise colours too (generators/perlin.h seedColor, bit for bit), and the mesh has
  // them; otherwise the mesh has no colours, as without it.
  bool noise_colors = false;
  EscapeRowSink rows;  // empty: the mesh is returned
};

// The surface parameters of a fractal whose Params have the shared grid fields (resolution,
// max_iter, lo, hi, level, frame, grid_out, threads, max_memory, progress, planes, arena, mesher,
// noise_colors, rows).
template <typename FractalParams>
EscapeSurfaceParams escapeSurfaceParams(std::string name, const FractalParams& params);

// Checks the user-facing parameters; errors name the flag and the limit (kUsage).
// `level` < 0 means "the default", max_iter/4.
Status validateEscapeParams(int resolution, int max_iter, double lo, double hi, double level);
double resolveLevel(int max_iter, double level);

template <typename FractalParams>
EscapeSurfaceParams escapeSurfaceParams(std::string name, const FractalParams& params) {
  EscapeSurfaceParams surface;
  surface.name = std::move(name);
  surface.axis = {params.resolution, params.lo, params.hi};
  surface.max_iter = params.max_iter;
  surface.level = resolveLevel(params.max_iter, params.level);
  surface.frame = params.frame;
  surface.lazy = params.grid_out.empty() && !params.full_counts;
  surface.grid_out = params.grid_out;
  surface.threads = params.threads;
  surface.max_memory = params.max_memory;
  surface.progress = params.progress;
  surface.planes = params.planes;
  surface.arena = params.arena;
  surface.mesher = params.mesher;
  surface.noise_colors = params.noise_colors;
  surface.rows = params.rows;
  return surface;
}

// Bytes the run is expected to hold at its peak: per-worker planes, the streamed grid slabs and a
// mesh of 0.5·res^2.5 vertices (the Mandelbulb has 13,112 at res 64, 226,382 at res 200 and
// 16.6 million at res 1024: a fractal surface grows faster than res²).
uint64_t estimateEscapeSurfaceMemory(const EscapeSurfaceParams& params);

// Welded marching-cubes mesh of {count > level} on the grid (marching_cubes.h), outward normals
// (counter-clockwise seen from the lower counts). Vertices in the canonical order of
// marching_cubes.h, independent of the thread count. Writes params.grid_out (whole or not at all)
// when set. Errors: over the memory limit (kResourceLimit), grid file errors.
Result<PointSet> generateEscapeSurface(const EscapeSurfaceParams& params, const EscapeRowFunction& row);

// Tile `tile` of the same mesh (core/tile.h): the vertices and triangles of its share of the cell
// layers; concatenated in tile order they are generateEscapeSurface's. Where params.rows took them
// as rows (owned vertices, then the copies), the tile's points are empty, its owned count and
// foreign references set. With grid_out, the tile's
// planes of the grid file (its layers' first planes, and the last plane in the last tile), so the
// pieces concatenated are the whole grid file. Same errors.
Result<PointTile> generateEscapeSurfaceTile(const EscapeSurfaceParams& params, const EscapeRowFunction& row,
                                            TileSpec tile);

// The full count grid of x-planes [first_plane, first_plane + planes), layout [i][j][k]; for tests
// and measurements (holds planes·res² counts).
Result<std::vector<uint32_t>> computeEscapeGrid(const GridAxis& axis, int max_iter, const EscapeRowFunction& row,
                                                unsigned threads, int first_plane, int planes);

// The grid file format: uint8 per count when max_iter ≤ 255, else little-endian uint16.
int escapeGridBytesPerCount(int max_iter);
Status writeEscapeGrid(const std::string& path, const std::vector<uint32_t>& counts, int max_iter);

}  // namespace dpoint
