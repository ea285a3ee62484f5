#!/usr/bin/env python3
"""Writes the hand-made fuzz seeds in fuzz/seeds/{csv,pcd,ply,gltf,las}/ (committed; rerun to remake them;
`make_seeds.py pcd` writes only the PCD seeds, `make_seeds.py texture` stops after gltf/textured.glb, the seeds before it rewritten as they were).

Small files, each reaching a path of a reader the other seeds (samples/, ../shared/corpus/,
assimp-testmodels) may miss. The Draco and meshopt seeds are made from gltf/quantized.glb's
float twin by gltf-transform (.tools/, scripts/setup) and gltfpack when they are installed.
"""
import base64, json, os, struct, subprocess, sys

here = os.path.dirname(os.path.abspath(__file__))
top = os.path.dirname(os.path.dirname(here))


def write(sub, name, data):
    path = os.path.join(here, sub, name)
    with open(path, "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())
    return path


# ---- CSV: every layout, every accepted spelling, and the edge values ----
write("csv", "xyz.csv", "x,y,z\n1,2,3\n-4.5,6e10,-0\n")
write("csv", "xyzrgb_crlf_bom.csv", "\ufeffx,y,z,r,g,b\r\n1,2,3,0.5,0.25,1\r\n4,5,6,0,0,0\r\n")
write("csv", "xy_noheader.csv", "0.1,0.2\n  +3 , -4\t\n\n5,6")
write("csv", "xyrgb.csv", "x,y,r,g,b\n1,2,0.1,0.2,0.3\n")
write("csv", "extremes.csv", "x,y,z\n1.7976931348623157e308,4.9e-324,-2.2250738585072014e-308\n"
      "123456789012345678901234567890,0.000000000000000000001,1e-400\n")
write("csv", "nonfinite.csv", "x,y,z\nnan,inf,-inf\n")
# Two PTX scans (the csv target reads every input as .ptx too): a rotation with a translation and
# rows with intensity and colours, one with no echo; then an identity scan of x y z rows.
PTX_TWO_SCANS = ("2\n1\n10 20 30\n1 0 0\n0 1 0\n0 0 1\n0 -1 0 0\n1 0 0 0\n0 0 1 0\n10 20 30 1\n"
                 "1.5 2.5 -3 0.25 255 128 0\n0 0 0 0.5 0 0 0\n"
                 "1\n1\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n7 8 9\n")
write("csv", "two_scans.ptx", PTX_TWO_SCANS)

# ---- PCD: each encoding, PCL's header variants, an organized cloud with NaN points ----
def lzf_literals(data, repeat_at=None):
    """LZF as literal runs (a control byte < 32, then up to 32 bytes), with one back reference
    (length 3 from 1 byte back) after byte `repeat_at` when given: the decoder's two paths."""
    out = bytearray()
    i = 0
    while i < len(data):
        run = data[i:i + 32]
        out += bytes([len(run) - 1]) + run
        i += len(run)
    if repeat_at is not None:
        out += bytes([(1 << 5) | 0, 0])  # length 1 + 2 = 3, offset 0 + 1: the byte before, three times
    return bytes(out)

PCD_HEAD = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n"
write("pcd", "ascii_rgb.pcd", PCD_HEAD + "FIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
      "WIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n"
      "1 2 3 1.180104e-38\n-4.5 6e10 -0 4.2108e+06\nnan nan nan 0\n")
write("pcd", "ascii_v05_rgba.pcd", "VERSION .5\r\nCOLUMNS x y z rgba intensity\r\nSIZE 4 4 4 4 2\r\nTYPE F F F U U\r\n"
      "POINTS 2\r\nDATA ascii\r\n1 2 3 4294901760 7\r\n\r\n4\t5\t6\t0\t65535\r\n")
rows = b""
for i, (x, y, z) in enumerate([(0, 0, 1), (float("nan"),) * 3, (2, 0, 1), (0, 1, 5)]):
    rows += struct.pack("<fffB", x, y, z, 255) + b"\xee\xee" + struct.pack("<hhd", -i, i, i / 3.0)
write("pcd", "binary_organized.pcd", (PCD_HEAD + "FIELDS x y z label _ h gps\nSIZE 4 4 4 1 1 2 8\n"
      "TYPE F F F U U I F\nCOUNT 1 1 1 1 2 2 1\nWIDTH 2\nHEIGHT 2\nPOINTS 4\nDATA binary\n").encode() + rows)
columns = struct.pack("<3d", 1.5, -2.5, 6378137.0) + struct.pack("<3d", 0.1, 0.2, 0.3) + \
    struct.pack("<3d", 7, 8, 9) + struct.pack("<3I", 0x00ff0000, 0x0000ff00, 0)
packed = lzf_literals(columns[:-3], repeat_at=len(columns) - 3)  # its last 3 zero bytes by reference
write("pcd", "compressed.pcd", (PCD_HEAD + "FIELDS x y z rgb\nSIZE 8 8 8 4\nTYPE F F F U\nCOUNT 1 1 1 1\n"
      "WIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA binary_compressed\n").encode() +
      struct.pack("<II", len(packed), len(columns)) + packed)
if sys.argv[1:] == ["pcd"]:
    print("make_seeds: wrote the pcd seeds")
    sys.exit(0)

# ---- LAS: every header size, a point format of each record layout, VLRs, EVLRs, extra bytes ----
LAS_BASE = [20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67]
LAS_RGB_AT = [0, 0, 20, 28, 0, 28, 0, 30, 30, 0, 30]

def las(minor, fmt, points, extra=0, vlrs=0, evlrs=0, colours=None):
    """A LAS 1.minor file of point format fmt: `points` are integer (X, Y, Z), scale 0.01, offset
    (500000, 4000000, 100) (UTM-like); `extra` bytes after each record; `vlrs` VLRs of 8 bytes
    of payload before the points, `evlrs` EVLRs after them (1.4)."""
    header_size = {0: 227, 1: 227, 2: 227, 3: 235, 4: 375}[minor]
    vlr = b"".join(struct.pack("<H16sHH32s", 0, b"dpoint_seed", 1000 + i, 8, b"seed vlr") + b"\x01" * 8
                   for i in range(vlrs))
    length = LAS_BASE[fmt] + extra
    records = b""
    for k, (x, y, z) in enumerate(points):
        r = bytearray(length)
        struct.pack_into("<iiiH", r, 0, x, y, z, 1000 * (k + 1))
        if fmt >= 6:
            r[14] = 0x11           # return 1 of 1
            r[16] = 2 + k % 5      # classification
        else:
            r[14] = 0x09
            r[15] = 2 + k % 5
        if colours:
            struct.pack_into("<3H", r, LAS_RGB_AT[fmt], *colours[k % len(colours)])
        records += bytes(r)
    offset = header_size + len(vlr)
    h = bytearray(header_size)
    h[0:4] = b"LASF"
    h[24], h[25] = 1, minor
    h[26:58] = b"dpoint fuzz seed".ljust(32, b"\0")
    h[58:90] = b"make_seeds.py".ljust(32, b"\0")
    struct.pack_into("<HIIBHI", h, 94, header_size, offset, vlrs, fmt, length, len(points) if fmt < 6 else 0)
    scale, origin = (0.01, 0.01, 0.01), (500000.0, 4000000.0, 100.0)
    struct.pack_into("<3d3d", h, 131, *scale, *origin)
    xs = [[p[a] * scale[a] + origin[a] for p in points] for a in range(3)]
    for a in range(3):
        struct.pack_into("<2d", h, 179 + 16 * a, max(xs[a], default=0.0), min(xs[a], default=0.0))
    evlr = b"".join(struct.pack("<H16sHQ32s", 0, b"dpoint_seed", 2000 + i, 4, b"seed evlr") + b"\x02" * 4
                    for i in range(evlrs))
    if minor == 4:
        start = offset + len(records)
        struct.pack_into("<QQIQ", h, 227, 0, start if evlrs else 0, evlrs, len(points))
    return bytes(h) + vlr + records + evlr

grid = [(x * 100, y * 100, (x + y) * 10) for x in range(3) for y in range(3)]
write("las", "v1_0_format0.las", las(0, 0, grid[:4]))
write("las", "v1_2_format1_vlr.las", las(2, 1, grid, vlrs=2))
write("las", "v1_2_format2_8bit_colours.las", las(2, 2, grid, colours=[(255, 0, 0), (0, 128, 255)]))
write("las", "v1_3_format3_16bit_colours.las", las(3, 3, grid, colours=[(65535, 0, 30000)]))
write("las", "v1_3_format4_extra.las", las(3, 4, grid[:2], extra=3))
write("las", "v1_4_format6_evlr.las", las(4, 6, grid, vlrs=1, evlrs=1))
write("las", "v1_4_format7_extra.las", las(4, 7, grid, extra=5, colours=[(1, 2, 3), (300, 200, 100)]))
write("las", "v1_4_format10.las", las(4, 10, grid[:3], colours=[(40000, 20000, 0)]))
one = las(2, 0, grid[:1])
write("las", "laz_flag.las", one[:104] + bytes([0x80]) + one[105:])  # format 0 with LAZ's bit 7
write("las", "empty_v1_2.las", las(2, 0, []))

# ---- PLY: ASCII and binary, every property type, lists, faces, other elements ----
def ply_header(fmt, elements):
    lines = ["ply", "format %s 1.0" % fmt, "comment fuzz seed"]
    for name, count, props in elements:
        lines.append("element %s %d" % (name, count))
        lines += ["property " + p for p in props]
    return "\n".join(lines + ["end_header"]) + "\n"

tetra = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)]
faces = [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)]
write("ply", "ascii_faces.ply",
      ply_header("ascii", [("vertex", 4, ["float x", "float y", "float z", "uchar red", "uchar green", "uchar blue"]),
                           ("face", 4, ["list uchar int vertex_indices"])]) +
      "".join("%g %g %g %d 0 255\n" % (p + (i * 60,)) for i, p in enumerate(tetra)) +
      "".join("3 %d %d %d\n" % f for f in faces))
write("ply", "ascii_quad_extra_element.ply",
      ply_header("ascii", [("vertex", 4, ["double x", "double y", "double z", "float nx"]),
                           ("face", 1, ["list uchar uint vertex_index"]),
                           ("edge", 1, ["int vertex1", "int vertex2"])]) +
      "0 0 0 1\n1 0 0 1\n1 1 0 1\n0 1 0 1\n4 0 1 2 3\n0 1\n")
body = b"".join(struct.pack("<3dBBB", *p, 10, 20, 30) for p in tetra)
body += b"".join(struct.pack("<B3I", 3, *f) for f in faces)
write("ply", "binary_double_uchar_faces.ply",
      ply_header("binary_little_endian", [("vertex", 4, ["double x", "double y", "double z", "uchar red",
                                                         "uchar green", "uchar blue"]),
                                          ("face", 4, ["list uchar uint vertex_indices"])]).encode() + body)
body = b"".join(struct.pack("<hhhfHHH", int(p[0]), int(p[1]), int(p[2]), 0.5, 1, 2, 65535) for p in tetra)
write("ply", "binary_short_ushort.ply",
      ply_header("binary_little_endian", [("vertex", 4, ["short x", "short y", "short z", "float confidence",
                                                         "ushort red", "ushort green", "ushort blue"])]).encode() + body)
body = b"".join(struct.pack("<B", 2) + struct.pack("<2f", 0.5, 0.5) + struct.pack("<3f", *p) for p in tetra)
write("ply", "binary_vertex_with_list.ply",
      ply_header("binary_little_endian", [("vertex", 4, ["list uchar float uv", "float x", "float y",
                                                         "float z"])]).encode() + body)
write("ply", "empty_vertices.ply", ply_header("ascii", [("vertex", 0, ["float x", "float y", "float z"])]))

# ---- glTF: each accessor form and extension the walker decodes ----
def data_uri(b):
    return "data:application/octet-stream;base64," + base64.b64encode(b).decode()

def glb(doc, binary):
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * ((4 - len(js) % 4) % 4)
    binary += b"\0" * ((4 - len(binary) % 4) % 4)
    chunks = struct.pack("<II", len(js), 0x4E4F534A) + js
    if binary:
        chunks += struct.pack("<II", len(binary), 0x004E4942) + binary
    return struct.pack("<III", 0x46546C67, 2, 12 + len(chunks)) + chunks

def png(width, height, rgb):
    """An 8-bit RGB PNG of the rows in `rgb` (bytes, 3 per pixel)."""
    import zlib
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff)
    rows = b"".join(b"\0" + rgb[y * width * 3:(y + 1) * width * 3] for y in range(height))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))

def textured_seed():
    """A quad whose material's base-colour texture is a 2x2 PNG in a bufferView, its TEXCOORD_0
    normalized unsigned bytes moved by KHR_texture_transform, sampled NEAREST with MIRRORED_REPEAT:
    the texture path of the reader (converters/gltf_texture.h) that the fuzz target runs."""
    qpos = struct.pack("<12f", 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0)
    quv = bytes([0, 255, 255, 255, 255, 0, 0, 0])
    qidx = struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    image = png(2, 2, bytes([255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255]))
    parts = [qpos, quv, qidx, image]
    offsets, binary = [], b""
    for part in parts:
        binary += b"\0" * ((4 - len(binary) % 4) % 4)
        offsets.append(len(binary))
        binary += part
    doc = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "extensionsUsed": ["KHR_texture_transform"],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1, 0.5, 0.5, 1], "baseColorTexture": {
            "index": 0, "extensions": {"KHR_texture_transform": {"offset": [0.5, 0], "rotation": 0.3, "scale": [3, 2]}}}}}],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9728, "wrapS": 33648, "wrapT": 33071}],
        "images": [{"bufferView": 3, "mimeType": "image/png"}],
        "buffers": [{"byteLength": len(binary)}],
        "bufferViews": [{"buffer": 0, "byteOffset": offsets[i], "byteLength": len(part)} for i, part in enumerate(parts)],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                      {"bufferView": 1, "componentType": 5121, "normalized": True, "count": 4, "type": "VEC2"},
                      {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
    }
    write("gltf", "textured.glb", glb(doc, binary))

textured_seed()
if sys.argv[1:] == ["texture"]:
    print("make_seeds: wrote the textured gltf seed")
    sys.exit(0)

# Points with unorm8 colours in a data: URI, under a node with T, R, S.
pos = b"".join(struct.pack("<3f", *p) for p in tetra)
col = bytes([255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 9, 9, 9, 255])
points = {
    "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
    "nodes": [{"mesh": 0, "translation": [6378137.0, 0, 0], "rotation": [0, 0.7071068, 0, 0.7071068], "scale": [2, 2, 2]}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "COLOR_0": 1}, "mode": 0}]}],
    "buffers": [{"byteLength": len(pos) + len(col), "uri": data_uri(pos + col)}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(pos)},
                    {"buffer": 0, "byteOffset": len(pos), "byteLength": len(col)}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
                  {"bufferView": 1, "componentType": 5121, "normalized": True, "count": 4, "type": "VEC4"}],
}
write("gltf", "points_unorm8_colors.gltf", json.dumps(points, indent=1))

# Sparse accessor over no bufferView, substituted by a second one over zeros, strip and fan modes.
idx = struct.pack("<2H", 1, 3)
vals = struct.pack("<6f", 5, 5, 5, -1, -2, -3)
strip = struct.pack("<6B", 0, 1, 2, 3, 0, 1)
buf = idx + vals + strip
sparse = {
    "asset": {"version": "2.0"}, "scenes": [{"nodes": [0, 1]}],
    "nodes": [{"mesh": 0, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 10, 20, 30, 1]},
              {"mesh": 1, "children": [2]}, {"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": 5, "material": 0}]},
               {"primitives": [{"attributes": {"POSITION": 0}, "mode": 6}, {"attributes": {"POSITION": 0}, "mode": 1}]}],
    "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.4, 0.6, 1]}}],
    "buffers": [{"byteLength": len(buf), "uri": data_uri(buf)}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(idx)},
                    {"buffer": 0, "byteOffset": len(idx), "byteLength": len(vals)},
                    {"buffer": 0, "byteOffset": len(idx) + len(vals), "byteLength": len(strip)}],
    "accessors": [{"componentType": 5126, "count": 4, "type": "VEC3",
                   "sparse": {"count": 2, "indices": {"bufferView": 0, "componentType": 5123},
                              "values": {"bufferView": 1}}},
                  {"bufferView": 2, "componentType": 5121, "count": 6, "type": "SCALAR"}],
}
write("gltf", "sparse_strip_fan_lines.gltf", json.dumps(sparse, indent=1))

# KHR_mesh_quantization: normalized short positions (stride 8), unorm16 colours, uint16 indices,
# placed twice by EXT_mesh_gpu_instancing (float translation, normalized-short rotation).
qpos = b"".join(struct.pack("<3hh", int(p[0] * 32767), int(p[1] * 32767), int(p[2] * 32767), 0) for p in tetra)
qcol = b"".join(struct.pack("<3H", 65535, i * 20000, 0) for i in range(4))
qidx = b"".join(struct.pack("<3H", *f) for f in faces)
inst_t = struct.pack("<6f", 0, 0, 0, 100, 0, 0)
inst_r = struct.pack("<8h", 0, 0, 0, 32767, 0, 23170, 0, 23170)
binary = qpos + qcol + qidx + inst_t + inst_r
offsets = [0]
for part in (qpos, qcol, qidx, inst_t):
    offsets.append(offsets[-1] + len(part))
quant = {
    "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
    "extensionsUsed": ["KHR_mesh_quantization", "EXT_mesh_gpu_instancing"],
    "extensionsRequired": ["KHR_mesh_quantization"],
    "nodes": [{"mesh": 0, "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 3, "ROTATION": 4}}}}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "COLOR_0": 1}, "indices": 2}]}],
    "buffers": [{"byteLength": len(binary)}],
    "bufferViews": [{"buffer": 0, "byteOffset": offsets[0], "byteLength": len(qpos), "byteStride": 8},
                    {"buffer": 0, "byteOffset": offsets[1], "byteLength": len(qcol)},
                    {"buffer": 0, "byteOffset": offsets[2], "byteLength": len(qidx)},
                    {"buffer": 0, "byteOffset": offsets[3], "byteLength": len(inst_t)},
                    {"buffer": 0, "byteOffset": offsets[4], "byteLength": len(inst_r)}],
    "accessors": [{"bufferView": 0, "componentType": 5122, "normalized": True, "count": 4, "type": "VEC3"},
                  {"bufferView": 1, "componentType": 5123, "normalized": True, "count": 4, "type": "VEC3"},
                  {"bufferView": 2, "componentType": 5123, "count": 12, "type": "SCALAR"},
                  {"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"},
                  {"bufferView": 4, "componentType": 5122, "normalized": True, "count": 2, "type": "VEC4"}],
}
write("gltf", "quantized_instanced.glb", glb(quant, binary))

# A float triangle mesh, the source of the compressed seeds (not a seed itself).
fpos = b"".join(struct.pack("<3f", *p) for p in tetra)
fidx = b"".join(struct.pack("<3I", *f) for f in faces)
mesh = {
    "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "COLOR_0": 1}, "indices": 2}]}],
    "buffers": [{"byteLength": len(fpos) * 2 + len(fidx)}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(fpos)},
                    {"buffer": 0, "byteOffset": len(fpos), "byteLength": len(fpos)},
                    {"buffer": 0, "byteOffset": 2 * len(fpos), "byteLength": len(fidx)}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
                  {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
                  {"bufferView": 2, "componentType": 5125, "count": 12, "type": "SCALAR"}],
}
source = os.path.join(os.environ.get("TMPDIR", "/tmp"), "dpoint-fuzz-seed-mesh.glb")
with open(source, "wb") as f:
    f.write(glb(mesh, fpos + fpos + fidx))

tool = os.path.join(top, ".tools", "node_modules", ".bin", "gltf-transform")
made = []
def run(command, name, options=()):
    """command + [output] + options; a missing tool leaves the seed out, with a note."""
    out = os.path.join(here, "gltf", name)
    try:
        subprocess.run(list(command) + [out] + list(options), check=True, capture_output=True)
        made.append(name)
    except (OSError, subprocess.CalledProcessError) as e:
        print("make_seeds: could not make %s: %s" % (name, e), file=sys.stderr)
if os.path.exists(tool):
    run([tool, "draco", source], "draco_edgebreaker.glb")
    run([tool, "draco", source], "draco_sequential.glb", ["--method", "sequential", "--quantize-position", "0"])
run(["gltfpack", "-c", "-i", source, "-o"], "meshopt.glb")
run(["gltfpack", "-cc", "-noq", "-i", source, "-o"], "meshopt_filters_fallback.glb")
os.remove(source)
print("make_seeds: wrote the csv, pcd, ply, gltf and las seeds (compressed: %s)" % (", ".join(made) or "none"))
