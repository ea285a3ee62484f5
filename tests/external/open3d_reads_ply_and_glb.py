"""Open3D reads dpoint's PLY (points and meshes, binary and ASCII), PTS and mesh GLB with the same
values, and dpoint reads the PTS Open3D writes and a big-endian PLY as Open3D reads it. (Open3D does not read POINTS primitives from glTF;
validator_accepts_glb.py checks those.)"""
import json
import os
import random
import struct
import sys

import numpy as np
import open3d as o3d

from common import check, dpoint, scratch, write_mesh_ply

exe = sys.argv[1]
o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
random.seed(8)
with scratch() as d:
    points = [(6378137.0 + random.randrange(100000) * 1e-3, random.uniform(-1, 1), random.uniform(-1e-3, 1e-3))
              for _ in range(5000)]
    colors = [tuple(random.randrange(256) for _ in range(3)) for _ in points]
    src = os.path.join(d, "cloud.csv")
    with open(src, "w") as f:
        f.write("x,y,z,r,g,b\n")
        for p, c in zip(points, colors):
            f.write(",".join(repr(v) for v in p) + "," + ",".join(repr(v / 255) for v in c) + "\n")
    want_points = np.array(points)
    want_colors = np.array(colors) / 255.0
    for args in ([], ["--ply-ascii"]):
        ply = os.path.join(d, "cloud.ply")
        dpoint(exe, "convert", src, "-o", ply, *args)
        cloud = o3d.io.read_point_cloud(ply)
        got = np.asarray(cloud.points)
        check(got.shape == want_points.shape, f"point cloud {args}: shape {got.shape}")
        check(np.array_equal(got, want_points), f"point cloud {args}: positions differ (max {np.abs(got - want_points).max()})")
        check(np.allclose(np.asarray(cloud.colors), want_colors, atol=1e-7), f"point cloud {args}: colours differ")

    # A PLY from a LAS file carries its frame and CRS records in header comments (autzen.las: GeoTIFF
    # keys and two 720-byte WKT records), in lines RPly, Open3D's PLY reader, takes (at most 1,024
    # bytes: a longer one aborted it).
    corpus_las = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "shared", "corpus", "las",
                              "autzen.las")
    las_ply = os.path.join(d, "autzen.ply")
    dpoint(exe, "convert", corpus_las, "-o", las_ply, "--ply-colors", "uchar")
    header = open(las_ply, "rb").read().split(b"end_header", 1)[0]
    check(b"comment dpoint: las crs" in header, "the PLY of a LAS file has no CRS comment")
    check(max(len(line) for line in header.split(b"\n")) <= 1000, "a PLY header line over 1,000 bytes")
    check(len(o3d.io.read_point_cloud(las_ply).points) == 106, "Open3D reads other than autzen.las's 106 points")

    # PTS both ways: dpoint's (count line, x y z r g b with 0-255 colours) read by Open3D, and
    # Open3D's (x y z intensity r g b, ten decimals) read by dpoint as the points Open3D reads back.
    pts = os.path.join(d, "cloud.pts")
    dpoint(exe, "convert", src, "-o", pts)
    cloud = o3d.io.read_point_cloud(pts)
    check(np.array_equal(np.asarray(cloud.points), want_points), "PTS: Open3D reads other positions")
    check(np.allclose(np.asarray(cloud.colors), want_colors, atol=1e-7), "PTS: Open3D reads other colours")
    theirs = os.path.join(d, "open3d.pts")
    check(o3d.io.write_point_cloud(theirs, cloud), "Open3D could not write PTS")
    back = o3d.io.read_point_cloud(theirs)
    ours = os.path.join(d, "open3d_pts.csv")
    dpoint(exe, "convert", theirs, "-o", ours)
    rows = np.loadtxt(ours, delimiter=",", skiprows=1)
    check(np.array_equal(rows[:, 0:3], np.asarray(back.points)), "PTS: dpoint reads Open3D's file to other positions")
    check(np.allclose(rows[:, 3:6] / 255.0, np.asarray(back.colors), atol=1e-7), "PTS: dpoint reads other colours")

    verts, faces = write_mesh_ply(os.path.join(d, "mesh_in.ply"))
    for args in ([], ["--ply-ascii"]):
        out = os.path.join(d, "mesh.ply")
        dpoint(exe, "convert", os.path.join(d, "mesh_in.ply"), "-o", out, *args)
        mesh = o3d.io.read_triangle_mesh(out)
        check(np.array_equal(np.asarray(mesh.vertices), np.array(verts)), f"mesh PLY {args}: vertices differ")
        check(np.array_equal(np.asarray(mesh.triangles), np.array(faces)), f"mesh PLY {args}: triangles differ")

    glb = os.path.join(d, "mesh.glb")
    dpoint(exe, "convert", os.path.join(d, "mesh_in.ply"), "-o", glb)
    mesh = o3d.io.read_triangle_mesh(glb)
    # Open3D 0.16 reads glTF meshes without their node transforms, so it returns the stored
    # float32 offsets; the double origin is the node's translation, read here from the JSON chunk.
    with open(glb, "rb") as f:
        data = f.read()
    json_length = struct.unpack_from("<I", data, 12)[0]
    gltf = json.loads(data[20:20 + json_length])
    origin = np.array(gltf["nodes"][0].get("translation", [0.0, 0.0, 0.0]))
    got = np.asarray(mesh.vertices) + origin
    check(got.shape == (len(verts), 3), f"mesh GLB: {got.shape[0]} vertices, expected {len(verts)}")
    # Positions are float32 offsets from a double origin in the node translation: the error is
    # float precision of the extent (2 m here: 1.2e-7 m steps), not of 6.4e6 m (0.5 m steps).
    err = np.abs(got - np.array(verts)).max()
    check(err <= 2e-7, f"mesh GLB: vertices off by {err}")
    check(np.array_equal(np.asarray(mesh.triangles), np.array(faces)), "mesh GLB: triangles differ")

    # A binary_big_endian PLY made by numpy (an older host's or tool's file): dpoint reads the
    # positions, colours and triangles Open3D reads (dpoint refused the format before 2026-12-01).
    n = 1000
    rows = np.zeros(n, dtype=[("x", ">f8"), ("y", ">f4"), ("z", ">f8"), ("red", "u1"), ("green", "u1"),
                              ("blue", "u1"), ("intensity", ">u2")])
    rng = np.random.default_rng(3)
    rows["x"] = 6378137.0 + rng.random(n)
    rows["y"] = rng.random(n).astype(np.float32)
    rows["z"] = -rng.random(n) * 1e-3
    for c in ("red", "green", "blue"):
        rows[c] = rng.integers(0, 256, n)
    rows["intensity"] = rng.integers(0, 65536, n)
    tris = np.zeros(n - 2, dtype=[("n", "u1"), ("i", ">i4", (3,))])
    tris["n"] = 3
    tris["i"] = np.stack([np.arange(n - 2), np.arange(1, n - 1), np.arange(2, n)], axis=1)
    big = os.path.join(d, "big_endian.ply")
    with open(big, "wb") as f:
        f.write(("ply\nformat binary_big_endian 1.0\nelement vertex %d\nproperty double x\nproperty float y\n"
                 "property double z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
                 "property ushort intensity\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
                 % (n, n - 2)).encode())
        f.write(rows.tobytes())
        f.write(tris.tobytes())
    theirs = o3d.io.read_triangle_mesh(big)
    check(len(theirs.vertices) == n, f"Open3D reads {len(theirs.vertices)} vertices of the big-endian PLY")
    ours = os.path.join(d, "big_endian.csv")
    dpoint(exe, "convert", big, "-o", ours)
    got = np.loadtxt(ours, delimiter=",", skiprows=1)
    check(np.array_equal(got[:, 0:3], np.asarray(theirs.vertices)), "big-endian PLY: dpoint reads other positions")
    check(np.allclose(got[:, 3:6], np.asarray(theirs.vertex_colors), atol=1e-7), "big-endian PLY: other colours")
    check(np.array_equal(got[:, 6], rows["intensity"].astype(np.float64)), "big-endian PLY: other intensities")
    back = os.path.join(d, "big_endian_le.ply")
    dpoint(exe, "convert", big, "-o", back)
    check(np.array_equal(np.asarray(o3d.io.read_triangle_mesh(back).triangles), np.asarray(theirs.triangles)),
          "big-endian PLY: dpoint reads other triangles")
print("Open3D", o3d.__version__, "read dpoint's PLY points, PLY meshes, PTS and mesh GLB with the same values; dpoint read "
      "Open3D's PTS and a big-endian PLY as Open3D reads it")
