"""Shared helpers for the external-reader checks: run dpoint, make scratch folders, report."""
import os
import subprocess
import sys
import tempfile


def dpoint(exe, *args):
    result = subprocess.run([exe, *args], capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit(f"dpoint {' '.join(args)} failed ({result.returncode}): {result.stderr}")
    return result.stdout


def scratch():
    return tempfile.TemporaryDirectory(prefix="dpoint-external-")


def write_mesh_ply(path):
    """A small closed mesh (an octahedron far from the origin, one quad-free fan) as ASCII PLY."""
    c = (6378137.25, -1234.5, 10.125)
    verts = [(c[0] + dx, c[1] + dy, c[2] + dz) for dx, dy, dz in
             [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]]
    faces = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
    with open(path, "w") as f:
        f.write("ply\nformat ascii 1.0\n")
        f.write(f"element vertex {len(verts)}\nproperty double x\nproperty double y\nproperty double z\n")
        f.write("property uchar red\nproperty uchar green\nproperty uchar blue\n")
        f.write(f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
        for i, v in enumerate(verts):
            f.write(f"{v[0]!r} {v[1]!r} {v[2]!r} {40 * i} {255 - 40 * i} 7\n")
        for face in faces:
            f.write("3 " + " ".join(map(str, face)) + "\n")
    return verts, faces


def check(condition, message):
    if not condition:
        sys.exit("FAILED: " + message)
