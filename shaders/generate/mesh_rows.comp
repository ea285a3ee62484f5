#version 450
// A slab's mesh as a binary PLY's rows (issue #38 item 4; generators/gpu_mesh.h, EscapeSlab::
// ply_rows), from what mesh_slab.comp's passes 3 and 4 made, so that the host only writes them:
//   kPass 0  the vertex rows: x, y, z as doubles, then, with the colours, red, green, blue as bytes
//            (converters/ply_write.cpp's colorByte);
//   kPass 1  the face rows: the byte 3, then the three ids as uint, shifted by vertex_base.
// Row r lies at byte r · row size, packed little-endian; an invocation makes 4 rows, whole words.
// A shader of its own, on mesh_slab.comp's set layout and push constants: in mesh_slab.comp the
// buffers it reads could not be write-only, and lavapipe then took minutes to compile the noise.
#extension GL_ARB_gpu_shader_int64 : require

layout(local_size_x = 256) in;
layout(constant_id = 0) const uint kPass = 0;

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
  uint row_bytes;    // 24, or 27 with the colours
  uint faces;        // face rows
  uint vertex_base;  // added to the slab's vertex ids
} pc;

uint block[27];  // 4 rows as words
void putByte(uint at, uint value) { block[at >> 2] |= (value & 0xFFu) << ((at & 3u) * 8u); }
void putWord(uint at, uint value) {
  uint shift = (at & 3u) * 8u;
  block[at >> 2] |= value << shift;
  if (shift != 0u) block[(at >> 2) + 1u] |= value >> (32u - shift);
}
// converters/ply_write.cpp's colorByte: min(c, 1) · 255 + 0.5 in double, truncated; 0 unless c > 0.
uint colorByte(float c) {
  if (!(c > 0.0)) return 0u;
  precise double scaled = (c < 1.0 ? double(c) : 1.0lf) * 255.0lf;
  precise double rounded = scaled + 0.5lf;
  return uint(rounded);
}

void main() {
  uint group = gl_WorkGroupID.y * pc.groups_x + gl_WorkGroupID.x;
  bool vertices = kPass == 0u;
  uint row_bytes = vertices ? pc.row_bytes : 13u;
  uint count = vertices ? pc.rows : pc.faces;
  uint first = 4u * (group * 256u + gl_LocalInvocationID.x);
  if (first >= count) return;
  for (uint w = 0u; w < 27u; ++w) block[w] = 0u;
  uint rows = min(4u, count - first);
  for (uint r = 0u; r < rows; ++r) {
    uint at = r * row_bytes, id = first + r;
    if (vertices) {
      for (uint d = 0u; d < 3u; ++d) {
        uvec2 halves = unpackDouble2x32(positions[3u * id + d]);
        putWord(at, halves.x);
        putWord(at + 4u, halves.y);
        at += 8u;
      }
      if (row_bytes == 27u)
        for (uint c = 0u; c < 3u; ++c) putByte(at + c, colorByte(colors[3u * id + c]));
    } else {
      putByte(at, 3u);
      for (uint k = 0u; k < 3u; ++k) putWord(at + 1u + 4u * k, pc.vertex_base + triangles[3u * id + k]);
    }
  }
  // 4 rows are row_bytes words; the last block's partial word is padded with 0.
  uint word = (first / 4u) * row_bytes;
  for (uint w = 0u; w < (rows * row_bytes + 3u) / 4u; ++w) {
    if (vertices)
      vertex_rows[word + w] = block[w];
    else
      face_rows[word + w] = block[w];
  }
}
