#version 450
// A slab's mesh as a binary PLY's rows (issue #38 item 4; generators/gpu_mesh.h, EscapeSlab::
// ply_rows), from what mesh_slab.comp's passes 3 and 4 made, so that the host only writes them:
//   kPass 0  the vertex rows: x, y, z as doubles, then, with the colours, red, green, blue as bytes
//            (converters/ply_write.cpp's colorByte) or, for a tile's part file, as floats;
//   kPass 1  the face rows: the byte 3, then the three ids as uint, shifted by vertex_base.
// Row r lies at byte r · row size, packed little-endian; an invocation makes 4 rows, whole words,
// with the row size a constant (kColors) so that every byte's place is known when compiled (a
// per-invocation array indexed at run time cost about 130 ms of a res-2048 Mandelbulb on an H200).
// A shader of its own, on mesh_slab.comp's set layout and push constants: in mesh_slab.comp the
// buffers it reads could not be write-only, and lavapipe then took minutes to compile the noise.
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_EXT_control_flow_attributes : require

layout(local_size_x = 256) in;
layout(constant_id = 0) const uint kPass = 0;
// The vertex rows' colours (kPass 0): 0 none, 1 bytes, 2 floats.
layout(constant_id = 1) const uint kColors = 0u;
const uint kRowBytes = kPass == 1u ? 13u : kColors == 2u ? 36u : kColors == 1u ? 27u : 24u;

layout(std430, set = 0, binding = 10) readonly buffer Positions { double positions[]; };  // 3 a vertex
layout(std430, set = 0, binding = 11) readonly buffer Triangles { uint triangles[]; };     // 3 a triangle
layout(std430, set = 0, binding = 12) readonly buffer Colors { float colors[]; };          // 3 a vertex
layout(std430, set = 0, binding = 13) writeonly buffer VertexRows { uint vertex_rows[]; };
layout(std430, set = 0, binding = 14) writeonly buffer FaceRows { uint face_rows[]; };

// mesh_slab.comp's push constants; this shader reads the last five.
layout(push_constant) uniform Push {
  double step;
  uint n, plane, planes, first, word_offset, bits, above_at, stride, seed_frame;
  uint vertex_elements, triangle_elements, vertex_group_count, triangle_group_count;
  uint groups_x;     // groups along x of this dispatch (a group is y · groups_x + x)
  uint pad;
  uint rows;         // vertex rows
  uint row_bytes;    // 24, or 27 or 36 with the colours (kColors)
  uint faces;        // face rows
  uint vertex_base;  // added to the slab's vertex ids
} pc;

// converters/ply_write.cpp's colorByte: min(c, 1) · 255 + 0.5 in double, truncated; 0 unless c > 0.
uint colorByte(float c) {
  if (!(c > 0.0)) return 0u;
  precise double scaled = (c < 1.0 ? double(c) : 1.0lf) * 255.0lf;
  precise double rounded = scaled + 0.5lf;
  return uint(rounded);
}

// Each invocation's 4 rows as fields of 4 bytes, every index a constant once the loops are
// unrolled (the row size is one): vertex rows x, y, z as low and high words and the colours (the
// bytes in one word, or a float a word); face rows the three ids.
uint fields[4][9];
// Byte o of row r: vertex rows 24 bytes of coordinates, then the colours; face rows the byte 3,
// then the ids.
uint rowByte(uint r, uint o) {
  if (kPass == 1u) return o == 0u ? 3u : (fields[r][(o - 1u) / 4u] >> (8u * ((o - 1u) % 4u))) & 0xFFu;
  return (fields[r][o / 4u] >> (8u * (o % 4u))) & 0xFFu;
}

void main() {
  uint group = gl_WorkGroupID.y * pc.groups_x + gl_WorkGroupID.x;
  uint count = kPass == 0u ? pc.rows : pc.faces;
  uint first = 4u * (group * 256u + gl_LocalInvocationID.x);
  if (first >= count) return;
  // Past the last row (the last block) the last row again: its bytes fall in no copied word.
  [[unroll]] for (uint r = 0u; r < 4u; ++r) {
    uint id = min(first + r, count - 1u);
    if (kPass == 0u) {
      [[unroll]] for (uint d = 0u; d < 3u; ++d) {
        uvec2 halves = unpackDouble2x32(positions[3u * id + d]);
        fields[r][2u * d] = halves.x;
        fields[r][2u * d + 1u] = halves.y;
      }
      if (kColors == 2u) {
        [[unroll]] for (uint c = 0u; c < 3u; ++c) fields[r][6u + c] = floatBitsToUint(colors[3u * id + c]);
      } else {
        fields[r][6] = kColors == 1u ? colorByte(colors[3u * id]) | colorByte(colors[3u * id + 1u]) << 8 |
                                           colorByte(colors[3u * id + 2u]) << 16
                                     : 0u;
      }
    } else {
      [[unroll]] for (uint k = 0u; k < 3u; ++k) fields[r][k] = pc.vertex_base + triangles[3u * id + k];
    }
  }
  // 4 rows are kRowBytes words; the words with a byte of a row that exists.
  uint bytes = min(4u, count - first) * kRowBytes;
  uint at = (first / 4u) * kRowBytes;
  [[unroll]] for (uint w = 0u; w < kRowBytes; ++w) {
    if (4u * w >= bytes) break;
    uint word = 0u;
    [[unroll]] for (uint k = 0u; k < 4u; ++k) {
      uint b = 4u * w + k;
      word |= rowByte(b / kRowBytes, b % kRowBytes) << (8u * k);
    }
    if (kPass == 0u)
      vertex_rows[at + w] = word;
    else
      face_rows[at + w] = word;
  }
}
