#version 450
// Marching cubes of one slab of escape counts on the device (issue #38 item 4;
// generators/gpu_mesh.h): the mesh generators/marching_cubes.cpp's marchingCubesSlab makes with
// generators/escape_grid.cpp's vertices, bit for bit, for planes first..first + planes − 1 of the
// final counts (8 or 32 bits each, packed little-endian as escape.comp writes them).
//
// Canonical order as a scan. The slab's vertices are numbered section by section: the in-plane
// edges of plane 0 (point by point in (j, k) order, the y edge before the z edge), the x edges to
// plane 1, the in-plane edges of plane 1, …, the in-plane edges of the last plane. Element
// e = section · n² + point has 0–2 vertices; an exclusive prefix sum over the elements in that
// order is each element's first vertex id, which is marchingCubesSlab's next_id. Triangles: cells
// in (layer, j, k) order, each cell's in table order; element e = layer · n² + point. Five passes
// (kPass), each a workgroup of 256 invocations of kRun consecutive elements:
//   0, 1  each element's crossed edges (0) or cell case (1), kept a byte each, and each group's
//         vertex or triangle count;
//   2     the exclusive scan of those group counts (workgroup 0 the vertices, 1 the triangles),
//         and the totals;
//   3     the vertices: each element's ids (a shared-memory scan inside the group) into the id
//         planes, and its positions, from the crossed edges pass 0 kept;
//   4     the triangles: the ids of each cell's edges' vertices, from the case pass 1 kept.
// Positions: t = (level − v1)/(v2 − v1) comes from a table the host made with the CPU's own
// division (the counts are small integers, so the pairs are few); the rest is fp64 add, sub and
// mul, which round correctly in Vulkan, and nothing is fused (`precise`), as the CPU is built
// (-ffp-contract=off).
#extension GL_ARB_gpu_shader_int64 : require

layout(local_size_x = 256) in;
layout(constant_id = 0) const uint kPass = 0;
// Bits a count, 8 or 32 (the push constant `bits` before): a constant, so that a count's word and
// shift are shifts and masks, not the integer divisions by a value known only at run time that
// every count read cost.
layout(constant_id = 1) const uint kBits = 8;
const uint kRun = 16u;                // elements an invocation: kGroupElements in generators/gpu_mesh.cpp
const uint kGroupElements = 256u * kRun;

layout(std430, set = 0, binding = 0) readonly buffer Counts { uint counts[]; };
layout(std430, set = 0, binding = 1) readonly buffer Axis { double values[]; };    // the grid axis
layout(std430, set = 0, binding = 2) readonly buffer Fractions { double fractions[]; };  // t by (v1, v2)
// Case m: bytes 4m..4m+15 as words: the triangle count, then 15 cube edges (marching_cubes.h)
// (then mesh_colors.comp's noise tables).
layout(std430, set = 0, binding = 3) readonly buffer Cases { uint cases[]; };
layout(std430, set = 0, binding = 4) buffer VertexGroups { uint vertex_groups[]; };
layout(std430, set = 0, binding = 5) buffer TriangleGroups { uint triangle_groups[]; };
// 0: vertices, 1: triangles, 2: the first id of section 1 (plane 0's in-plane vertices),
// 3: the first id of the last section (the last plane's in-plane vertices).
layout(std430, set = 0, binding = 6) buffer Totals { uint totals[]; };
layout(std430, set = 0, binding = 7) buffer IdsY { uint ids_y[]; };  // by plane · n² + point
layout(std430, set = 0, binding = 8) buffer IdsZ { uint ids_z[]; };
layout(std430, set = 0, binding = 9) buffer IdsX { uint ids_x[]; };  // by layer · n² + point
layout(std430, set = 0, binding = 10) writeonly buffer Positions { double positions[]; };  // 3 a vertex
layout(std430, set = 0, binding = 11) writeonly buffer Triangles { uint triangles[]; };     // 3 a triangle
// What passes 0 and 1 found, a byte an element (4 a word), for passes 3 and 4 to read instead of
// reading the counts again: an element's crossed edges (bit 0 its y edge, or its x edge in an x
// section; bit 1 its z edge), and a cell's case.
layout(std430, set = 0, binding = 15) buffer ElementEdges { uint element_edges[]; };
layout(std430, set = 0, binding = 16) buffer CellCases { uint cell_cases[]; };

layout(push_constant) uniform Push {
  double step;            // the seed frame's grid step
  uint n;                 // points along y and z
  uint plane;             // n²
  uint planes;            // the slab's planes
  uint first;             // the grid index of its plane 0
  uint word_offset;       // of its counts in `counts`
  uint bits;              // 8 or 32 bits a count (kBits)
  uint above_at;          // a point is above the level when its count is greater
  uint stride;            // fractions[v1 · stride + v2]
  uint seed_frame;        // 1: (index + t) · step; 0: the axis values
  uint vertex_elements;   // (2 · planes − 1) · n²
  uint triangle_elements; // (planes − 1) · n²
  uint vertex_group_count;
  uint triangle_group_count;
  uint groups_x;          // groups along x of this dispatch (a group is y · groups_x + x)
  uint pad;
} pc;

uint countAt(uint q, uint point) {
  uint i = q * pc.plane + point;
  if (kBits == 32u) return counts[pc.word_offset + i];
  const uint per = 32u / kBits;
  return (counts[pc.word_offset + i / per] >> ((i % per) * kBits)) & ((1u << kBits) - 1u);
}
uint aboveAt(uint q, uint point) { return countAt(q, point) > pc.above_at ? 1u : 0u; }

// An element's place: its section (vertex passes) or layer (triangle passes), its point in the
// plane, and the point's row j and column k. An invocation's elements are consecutive, so only the
// first is divided out; the others step from it (k fastest).
struct Place {
  uint section, point, j, k;
};
Place placeOf(uint e) {
  Place p;
  p.section = e / pc.plane;
  p.point = e - p.section * pc.plane;
  p.j = p.point / pc.n;
  p.k = p.point - p.j * pc.n;
  return p;
}
void stepPlace(inout Place p) {
  ++p.point;
  if (++p.k < pc.n) return;
  p.k = 0u;
  if (++p.j < pc.n) return;
  p.j = 0u;
  p.point = 0u;
  ++p.section;
}

// An element's crossed edges, its vertices: bit 0 the y edge and bit 1 the z edge of an in-plane
// point, or bit 0 the x edge.
uint crossedEdges(Place p) {
  uint section = p.section, point = p.point, j = p.j, k = p.k;
  uint q = section >> 1;
  uint a = aboveAt(q, point);
  if ((section & 1u) == 1u) return a != aboveAt(q + 1u, point) ? 1u : 0u;
  uint edges = 0u;
  if (j + 1u < pc.n && a != aboveAt(q, point + pc.n)) edges |= 1u;
  if (k + 1u < pc.n && a != aboveAt(q, point + 1u)) edges |= 2u;
  return edges;
}

// The case of the cell at a place (layer, j, k); 0 for the points without a cell (j or k last).
uint cellMask(Place p) {
  uint q = p.section, point = p.point, j = p.j, k = p.k;
  if (j + 1u >= pc.n || k + 1u >= pc.n) return 0u;
  uint row = pc.n;
  return aboveAt(q, point) | aboveAt(q + 1u, point) << 1 | aboveAt(q, point + row) << 2 |
         aboveAt(q + 1u, point + row) << 3 | aboveAt(q, point + 1u) << 4 | aboveAt(q + 1u, point + 1u) << 5 |
         aboveAt(q, point + row + 1u) << 6 | aboveAt(q + 1u, point + row + 1u) << 7;
}
uint caseByte(uint mask, uint b) { return (cases[4u * mask + (b >> 2)] >> ((b & 3u) * 8u)) & 0xFFu; }

shared uint scanned[256];
// The exclusive prefix sum of v over the group (every invocation calls it); total: the group's sum.
uint exclusiveScan(uint v, out uint total) {
  uint i = gl_LocalInvocationID.x;
  scanned[i] = v;
  barrier();
  for (uint offset = 1u; offset < 256u; offset <<= 1) {
    uint add = i >= offset ? scanned[i - offset] : 0u;
    barrier();
    scanned[i] += add;
    barrier();
  }
  total = scanned[255];
  return scanned[i] - v;
}

// generators/escape_grid.cpp's SlabField::vertex: the vertex on the edge from (first + q, j, k)
// along `axis`.
void writeVertex(uint id, uint q, uint point, uint j, uint k, uint axis) {
  uint q2 = axis == 0u ? q + 1u : q;
  uint point2 = axis == 1u ? point + pc.n : axis == 2u ? point + 1u : point;
  uint v1 = countAt(q, point), v2 = countAt(q2, point2);
  double t = fractions[v1 * pc.stride + v2];
  uint index[3] = uint[3](pc.first + q, j, k);
  for (uint d = 0u; d < 3u; ++d) {
    uint i = index[d];
    precise double out_value;
    if (pc.seed_frame == 1u) {
      precise double along = double(i) + (d == axis ? t : 0.0lf);
      out_value = along * pc.step;
    } else if (d == axis) {
      precise double span = values[i + 1u] - values[i];
      out_value = values[i] + t * span;
    } else {
      out_value = values[i];
    }
    positions[3u * id + d] = out_value;
  }
}

// The id of the vertex on cube edge `edge` of cell (q, point) (marching_cubes.h's mcEdgeStart).
uint edgeId(uint edge, uint q, uint point) {
  uint axis = edge / 4u, r = edge % 4u;
  uint corner = ((r & 1u) << ((axis + 1u) % 3u)) | ((r >> 1) << ((axis + 2u) % 3u));
  uint dx = corner & 1u, dy = (corner >> 1) & 1u, dz = (corner >> 2) & 1u;
  uint at = point + dy * pc.n + dz;
  if (axis == 0u) return ids_x[q * pc.plane + at];
  if (axis == 1u) return ids_y[(q + dx) * pc.plane + at];
  return ids_z[(q + dx) * pc.plane + at];
}

void main() {
  uint group = gl_WorkGroupID.y * pc.groups_x + gl_WorkGroupID.x;
  if (kPass == 2u) {
    // One workgroup a domain: thread t scans a run of the group counts, then the runs' sums.
    bool vertices = gl_WorkGroupID.x == 0u;
    uint n = vertices ? pc.vertex_group_count : pc.triangle_group_count;
    uint run = (n + 255u) / 256u;
    uint begin = min(n, gl_LocalInvocationID.x * run), end = min(n, begin + run);
    uint sum = 0u;
    for (uint g = begin; g < end; ++g) sum += vertices ? vertex_groups[g] : triangle_groups[g];
    uint total;
    uint offset = exclusiveScan(sum, total);
    for (uint g = begin; g < end; ++g) {
      uint c = vertices ? vertex_groups[g] : triangle_groups[g];
      if (vertices)
        vertex_groups[g] = offset;
      else
        triangle_groups[g] = offset;
      offset += c;
    }
    if (gl_LocalInvocationID.x == 0u) totals[vertices ? 0 : 1] = total;
    return;
  }
  bool vertex_pass = kPass == 0u || kPass == 3u;
  if (group >= (vertex_pass ? pc.vertex_group_count : pc.triangle_group_count)) return;  // the whole group
  uint elements = vertex_pass ? pc.vertex_elements : pc.triangle_elements;
  uint first_e = group * kGroupElements + gl_LocalInvocationID.x * kRun;
  // Each element's byte (crossed edges, or the cell's case) and its count: found in passes 0 and 1
  // and kept, read back in passes 3 and 4. An invocation's 16 bytes are 4 whole words.
  uint found[kRun];
  uint c[kRun];
  uint sum = 0u;
  if (kPass <= 1u) {
    Place place = placeOf(first_e);
    for (uint r = 0u; r < kRun; ++r) {
      uint e = first_e + r;
      found[r] = e >= elements ? 0u : vertex_pass ? crossedEdges(place) : cellMask(place);
      stepPlace(place);
    }
    for (uint w = 0u; w < kRun / 4u; ++w) {
      uint word = found[4u * w] | found[4u * w + 1u] << 8 | found[4u * w + 2u] << 16 | found[4u * w + 3u] << 24;
      if (vertex_pass)
        element_edges[first_e / 4u + w] = word;
      else
        cell_cases[first_e / 4u + w] = word;
    }
  } else {
    for (uint w = 0u; w < kRun / 4u; ++w) {
      uint word = vertex_pass ? element_edges[first_e / 4u + w] : cell_cases[first_e / 4u + w];
      for (uint b = 0u; b < 4u; ++b) found[4u * w + b] = (word >> (8u * b)) & 0xFFu;
    }
  }
  for (uint r = 0u; r < kRun; ++r) {
    c[r] = vertex_pass ? bitCount(found[r]) : caseByte(found[r], 0u);
    sum += c[r];
  }
  uint total;
  uint before = exclusiveScan(sum, total);
  if (kPass == 0u || kPass == 1u) {
    if (gl_LocalInvocationID.x == 0u) {
      if (kPass == 0u)
        vertex_groups[group] = total;
      else
        triangle_groups[group] = total;
    }
    return;
  }
  Place place = placeOf(first_e);
  if (kPass == 3u) {
    uint id = vertex_groups[group] + before;
    for (uint r = 0u; r < kRun; ++r, stepPlace(place)) {
      uint e = first_e + r;
      if (e >= elements) return;
      if (e == pc.plane) totals[2] = id;
      if (e == (2u * pc.planes - 2u) * pc.plane) totals[3] = id;
      if (c[r] == 0u) continue;
      uint point = place.point, j = place.j, k = place.k;
      uint q = place.section >> 1;
      if ((place.section & 1u) == 1u) {
        ids_x[q * pc.plane + point] = id;
        writeVertex(id, q, point, j, k, 0u);
        ++id;
        continue;
      }
      if ((found[r] & 1u) != 0u) {
        ids_y[q * pc.plane + point] = id;
        writeVertex(id, q, point, j, k, 1u);
        ++id;
      }
      if ((found[r] & 2u) != 0u) {
        ids_z[q * pc.plane + point] = id;
        writeVertex(id, q, point, j, k, 2u);
        ++id;
      }
    }
    return;
  }
  // kPass == 4: the triangles.
  uint first_triangle = triangle_groups[group] + before;
  for (uint r = 0u; r < kRun; ++r, stepPlace(place)) {
    if (c[r] == 0u) continue;
    uint mask = found[r];
    uint q = place.section, point = place.point;
    for (uint t = 0u; t < 3u * c[r]; ++t) triangles[3u * first_triangle + t] = edgeId(caseByte(mask, 1u + t), q, point);
    first_triangle += c[r];
  }
}
