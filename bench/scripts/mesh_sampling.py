#!/usr/bin/python3
"""Mesh sampling against Open3D and PCL (issue #37 item 3).

Usage: /usr/bin/python3 bench/scripts/mesh_sampling.py build/dpoint [N_POISSON] > bench/results/DATE/mesh_sampling.md

1. Poisson: for BoxTextured, the 2CylinderEngine and a generated Mandelbulb mesh, the mean
   nearest-neighbour spacing of `dpoint convert MESH --sample N --sample-method poisson` against
   Open3D's `sample_points_poisson_disk(N)` (Debian's python3-open3d), spacing by scipy's k-d tree.
2. Time: `dpoint convert 2CylinderEngine.glb --sample 10000000` against `pcl_mesh_sampling` of the
   same mesh (as PLY) with 1,000,000 samples (one run each, wall time of the whole command).
"""
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
import open3d as o3d
from scipy.spatial import cKDTree

exe = os.path.abspath(sys.argv[1])
n = int(sys.argv[2]) if len(sys.argv) > 2 else 20000
models = "/usr/share/assimp/models/glTF2/"
o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)


def run(*args):
    start = time.perf_counter()
    subprocess.run([str(a) for a in args], check=True, capture_output=True)
    return time.perf_counter() - start


def mean_spacing(points):
    distances, _ = cKDTree(points).query(points, k=2)
    return float(distances[:, 1].mean())


def read_ply_points(path):
    return np.asarray(o3d.io.read_point_cloud(str(path)).points)


with tempfile.TemporaryDirectory(prefix="dpoint-sampling-") as d:
    bulb = os.path.join(d, "bulb.ply")
    run(exe, "generate", "mandelbulb", "--resolution", "120", "-o", bulb, "-q")
    meshes = [("BoxTextured", models + "BoxTextured-glTF-Binary/BoxTextured.glb"),
              ("2CylinderEngine", models + "2CylinderEngine-glTF-Binary/2CylinderEngine.glb"),
              ("Mandelbulb (res 120)", bulb)]
    print(f"# Mesh sampling: dpoint against Open3D and PCL\n")
    print(f"Command: `/usr/bin/python3 bench/scripts/mesh_sampling.py build/dpoint {n}` on this machine "
          f"({os.cpu_count()} cores).\n")
    print(f"## Poisson-disk samples of {n} points: mean nearest-neighbour spacing\n")
    print("| mesh | triangles | dpoint | Open3D | dpoint / Open3D | dpoint s | Open3D s | uniform (dpoint) |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    worst = 0.0
    for name, path in meshes:
        # Open3D reads the same file (glTF through its own reader, PLY too); dpoint's mesh as PLY for both
        # would do as well, but each reading its own keeps the comparison independent.
        mesh_ply = os.path.join(d, "mesh.ply")
        run(exe, "convert", path, "-o", mesh_ply, "-q")
        mesh = o3d.io.read_triangle_mesh(mesh_ply)
        ours = os.path.join(d, "ours.ply")
        ours_s = run(exe, "convert", path, "-o", ours, "--sample", n, "--sample-method", "poisson", "-q")
        uniform = os.path.join(d, "uniform.ply")
        run(exe, "convert", path, "-o", uniform, "--sample", n, "-q")
        start = time.perf_counter()
        theirs = o3d.geometry.TriangleMesh.sample_points_poisson_disk(mesh, n, init_factor=5)
        theirs_s = time.perf_counter() - start
        a = mean_spacing(read_ply_points(ours))
        b = mean_spacing(np.asarray(theirs.points))
        u = mean_spacing(read_ply_points(uniform))
        worst = max(worst, abs(a / b - 1))
        print(f"| {name} | {len(mesh.triangles)} | {a:.6g} | {b:.6g} | {a / b:.3f} | {ours_s:.2f} | {theirs_s:.2f} | {u:.6g} |")
    print(f"\nLargest difference from Open3D's spacing: {100 * worst:.1f}% (the issue asks for at most 20%).\n")

    engine = models + "2CylinderEngine-glTF-Binary/2CylinderEngine.glb"
    engine_ply = os.path.join(d, "engine.ply")
    run(exe, "convert", engine, "-o", engine_ply, "-q")
    ours_s = run(exe, "convert", engine, "-o", os.path.join(d, "engine_10m.ply"), "--sample", 10000000, "-q")
    pcl_s = run("pcl_mesh_sampling", engine_ply, os.path.join(d, "engine_pcl.pcd"), "-n_samples", 1000000,
                "-no_vis_result")
    print("## Time: uniform samples of the 2CylinderEngine (one run each, whole command)\n")
    print("| command | samples | seconds |")
    print("| --- | ---: | ---: |")
    print(f"| `dpoint convert 2CylinderEngine.glb -o out.ply --sample 10000000` | 10,000,000 | {ours_s:.2f} |")
    print(f"| `pcl_mesh_sampling engine.ply out.pcd -n_samples 1000000 -no_vis_result` | 1,000,000 | {pcl_s:.2f} |")
    print(f"\ndpoint's 10M take {ours_s / pcl_s:.2f}× the time of PCL's 1M (the issue asks for at most 1×).")
