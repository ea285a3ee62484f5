"""PCD both ways against Debian's pcl-tools (issue #37 item 2).

- PCL reads what dpoint writes: for each encoding (ascii, binary, binary_compressed), dpoint writes
  a PCD, `pcl_pcd2ply` turns it into a binary PLY, and that PLY's vertices (parsed here) are the
  source's values: positions bit for bit, 8-bit colours, intensity, normals, GPS time, scan angle.
- dpoint reads what PCL writes: `pcl_ply2pcd` writes the source as a binary PCD and
  `pcl_convert_pcd_ascii_binary` rewrites it in all three encodings (ASCII at 17 digits); dpoint
  reads each back to the same values.
A float-only set is also written with float fields (TYPE F SIZE 4) and read by PCL the same way."""
import os
import random
import shutil
import subprocess
import sys

import numpy as np

from common import check, dpoint, scratch

exe = sys.argv[1]
for tool in ("pcl_pcd2ply", "pcl_ply2pcd", "pcl_convert_pcd_ascii_binary"):
    check(shutil.which(tool) is not None, f"{tool} is not installed (scripts/setup installs pcl-tools)")

PLY_TYPES = {"char": "i1", "uchar": "u1", "short": "<i2", "ushort": "<u2", "int": "<i4", "uint": "<u4",
             "float": "<f4", "double": "<f8", "int8": "i1", "uint8": "u1", "int16": "<i2", "uint16": "<u2",
             "int32": "<i4", "uint32": "<u4", "float32": "<f4", "float64": "<f8"}


def read_binary_ply_vertices(path):
    """The vertex element of a binary little-endian PLY as a numpy structured array."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    lines = data[:end].decode().splitlines()
    check("format binary_little_endian 1.0" in lines, f"{path}: not a binary PLY")
    fields, count, in_vertex = [], 0, False
    for line in lines:
        words = line.split()
        if words[0] == "element":
            in_vertex = words[1] == "vertex"
            if in_vertex:
                count = int(words[2])
        elif words[0] == "property" and in_vertex:
            check(words[1] != "list", f"{path}: a list property in the vertices")
            fields.append((words[2], PLY_TYPES[words[1]]))
    return np.frombuffer(data, dtype=np.dtype(fields), count=count, offset=end)


def run(*args):
    result = subprocess.run(list(args), capture_output=True, text=True)
    check(result.returncode == 0, f"{' '.join(args)} failed ({result.returncode}): {result.stdout}{result.stderr}")


def read_csv(path):
    with open(path) as f:
        header = f.readline().strip().split(",")
    rows = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return {name: rows[:, k] for k, name in enumerate(header)}


random.seed(37)
n = 3000
src = {
    "x": np.array([6378137.0 + random.randrange(10**9) * 1e-6 for _ in range(n)]),
    "y": np.array([random.uniform(-1e4, 1e4) for _ in range(n)]),
    "z": np.array([random.uniform(-1, 1) * 1e-3 for _ in range(n)]),
    "red": np.array([random.randrange(256) for _ in range(n)]),
    "green": np.array([random.randrange(256) for _ in range(n)]),
    "blue": np.array([random.randrange(256) for _ in range(n)]),
    "intensity": np.array([random.randrange(65536) for _ in range(n)]),
    "nx": np.array([random.uniform(-1, 1) for _ in range(n)], dtype=np.float32),
    "ny": np.array([random.uniform(-1, 1) for _ in range(n)], dtype=np.float32),
    "nz": np.array([random.uniform(-1, 1) for _ in range(n)], dtype=np.float32),
    "gps_time": np.array([245370.0 + random.random() * 5000 for _ in range(n)]),
    "scan_angle_rank": np.array([random.randrange(-90, 91) for _ in range(n)]),
}
props = [("x", "double"), ("y", "double"), ("z", "double"), ("red", "uchar"), ("green", "uchar"),
         ("blue", "uchar"), ("intensity", "ushort"), ("nx", "float"), ("ny", "float"), ("nz", "float"),
         ("gps_time", "double"), ("scan_angle_rank", "char")]
# PCL names the normals normal_x/y/z in a PCD and nx/ny/nz in a PLY; dpoint calls them nx/ny/nz.
pcd_ply_names = {"nx": "nx", "ny": "ny", "nz": "nz"}


def same(got, name, what):
    want = src[name]
    check(len(got) == len(want), f"{what}: {len(got)} points, not {len(want)}")
    got = np.asarray(got, dtype=want.dtype)
    bad = np.nonzero(~((got == want) | (np.isnan(got) & np.isnan(want))))[0]
    check(len(bad) == 0, f"{what}: {name} differs at {len(bad)} points, first {bad[:1]}: {got[bad[:1]]} vs {want[bad[:1]]}")


with scratch() as d:
    src_ply = os.path.join(d, "source.ply")
    dtype = np.dtype([(name, PLY_TYPES[t]) for name, t in props])
    rows = np.zeros(n, dtype=dtype)
    for name, _ in props:
        rows[name] = src[name]
    with open(src_ply, "wb") as f:
        f.write(b"ply\nformat binary_little_endian 1.0\n")
        f.write(f"element vertex {n}\n".encode())
        for name, t in props:
            f.write(f"property {t} {name}\n".encode())
        f.write(b"end_header\n")
        f.write(rows.tobytes())

    # PCL reads dpoint's PCD in every encoding.
    for encoding in ("ascii", "binary", "binary_compressed"):
        pcd = os.path.join(d, f"dpoint_{encoding}.pcd")
        dpoint(exe, "convert", src_ply, "-o", pcd, "--pcd-encoding", encoding, "-q")
        with open(pcd, "rb") as f:
            head = f.read(600)
        check(f"DATA {encoding}\n".encode() in head, f"{pcd}: no DATA {encoding} line")
        check(b"FIELDS x y z rgb intensity normal_x normal_y normal_z gps_time scan_angle_rank\n" in head,
              f"{pcd}: fields {head!r}")
        ply = os.path.join(d, f"pcl_{encoding}.ply")
        run("pcl_pcd2ply", "-format", "1", pcd, ply)
        v = read_binary_ply_vertices(ply)
        for name, _ in props:
            same(v[pcd_ply_names.get(name, name)], name, f"pcl_pcd2ply of dpoint's {encoding} PCD")
        print(f"pcl_pcd2ply reads dpoint's {encoding} PCD: {n} points, every field the same")

    # dpoint reads PCL's PCD in every encoding.
    pcl_binary = os.path.join(d, "pcl.pcd")
    run("pcl_ply2pcd", "-format", "1", src_ply, pcl_binary)
    for mode, encoding in ((0, "ascii"), (1, "binary"), (2, "binary_compressed")):
        pcd = os.path.join(d, f"pcl_{encoding}.pcd")
        run("pcl_convert_pcd_ascii_binary", pcl_binary, pcd, str(mode), "17")
        with open(pcd, "rb") as f:
            check(f"DATA {encoding}\n".encode() in f.read(600), f"{pcd}: PCL did not write DATA {encoding}")
        csv = os.path.join(d, f"pcl_{encoding}.csv")
        dpoint(exe, "convert", pcd, "-o", csv, "-q")
        got = read_csv(csv)
        check(list(got)[:6] == ["x", "y", "z", "r", "g", "b"], f"{csv}: columns {list(got)}")
        for name, _ in props:
            same(got[{"red": "r", "green": "g", "blue": "b"}.get(name, name)], name, f"dpoint reading PCL's {encoding} PCD")
        print(f"dpoint reads PCL's {encoding} PCD: {n} points, every field the same")

    # Float coordinates are written as float fields, which PCL's typed loaders take.
    small = os.path.join(d, "float.csv")
    with open(small, "w") as f:
        f.write("x,y,z\n1.5,-2.25,0.125\n3,4,5\n")
    pcd = os.path.join(d, "float.pcd")
    dpoint(exe, "convert", small, "-o", pcd, "--pcd-encoding", "binary_compressed", "-q")
    with open(pcd, "rb") as f:
        check(b"SIZE 4 4 4\nTYPE F F F\n" in f.read(400), f"{pcd}: float coordinates not written as float fields")
    ply = os.path.join(d, "float.ply")
    run("pcl_pcd2ply", "-format", "1", pcd, ply)
    v = read_binary_ply_vertices(ply)
    check(v["x"].tolist() == [1.5, 3.0] and v["y"].tolist() == [-2.25, 4.0] and v["z"].tolist() == [0.125, 5.0],
          f"float PCD: PCL reads {v}")

    def pcl_ascii_rewrite(source, encoding):
        """The text of PCL's ASCII rewrite of the PCD dpoint writes from `source` in `encoding`."""
        stem = os.path.join(d, f"{os.path.splitext(os.path.basename(source))[0]}_{encoding}")
        dpoint(exe, "convert", source, "-o", stem + ".pcd", "--pcd-encoding", encoding, "-q")
        run("pcl_convert_pcd_ascii_binary", stem + ".pcd", stem + "_pcl.pcd", "0", "17")
        with open(stem + "_pcl.pcd") as f:
            return f.read()

    # A field of COUNT n (an FPFH's 33 values) is read as NAME_0 … NAME_n-1 and written back as the
    # one field NAME of COUNT n, each point's values together in binary_compressed: PCL rewrites
    # dpoint's file as ASCII with the same field and values.
    counted = os.path.join(d, "counted.csv")
    with open(counted, "w") as f:
        f.write("x,y,z,h_0,h_1,h_2\n1,2,3,10.5,11.5,12.5\n4,5,6,20.25,21.25,22.25\n7,8,9,30,31,32\n")
    for encoding in ("binary", "binary_compressed"):
        text = pcl_ascii_rewrite(counted, encoding)
        check("FIELDS x y z h\n" in text and "COUNT 1 1 1 3\n" in text, f"PCL's rewrite of {encoding}: {text[:400]!r}")
        rows = [[float(v) for v in line.split()] for line in text.split("DATA ascii\n", 1)[1].splitlines() if line.strip()]
        check(rows == [[1, 2, 3, 10.5, 11.5, 12.5], [4, 5, 6, 20.25, 21.25, 22.25], [7, 8, 9, 30, 31, 32]],
              f"PCL reads dpoint's {encoding} COUNT 3 field as {rows}")
    print("PCL reads a COUNT 3 field dpoint writes, binary and binary_compressed")

    # A VIEWPOINT (the sensor's pose) is carried through PCD → PCD: PCL reads the one dpoint writes.
    posed = os.path.join(d, "posed.pcd")
    with open(posed, "w") as f:
        f.write("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\nHEIGHT 1\n"
                "VIEWPOINT 1.5 -2 3.25 0.5 0.5 0.5 0.5\nPOINTS 1\nDATA ascii\n1 2 3\n")
    for encoding in ("ascii", "binary", "binary_compressed"):
        text = pcl_ascii_rewrite(posed, encoding)
        check("VIEWPOINT 1.5 -2 3.25 0.5 0.5 0.5 0.5\n" in text, f"PCL's rewrite of {encoding}: {text[:400]!r}")
    print("PCL reads the VIEWPOINT dpoint carries through, in every encoding")
print("PCD: pcl-tools and dpoint agree both ways")
