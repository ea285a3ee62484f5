"""Helpers for the glTF comparison tests: the node reference reader, CSV points, set comparisons."""
import json
import math
import os
import struct
import subprocess

import numpy
from scipy.spatial import cKDTree

from common import check

NODE_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "node")


def node_tools_dir(validator_dir):
    """The node_modules folder scripts/setup fills: the validator's path is .../node_modules/gltf-validator."""
    modules = os.path.dirname(os.path.abspath(validator_dir))
    for name in ("@gltf-transform/core", "@gltf-transform/cli", "draco3dgltf", "meshoptimizer"):
        check(os.path.isdir(os.path.join(modules, name)), f"npm module {name} missing under {modules} (run scripts/setup)")
    return modules


def run_tool(argv, env=None):
    """Runs a helper tool that must succeed; its failure is a broken test setup, not a skip."""
    result = subprocess.run(argv, capture_output=True, text=True, env=env)
    check(result.returncode == 0, f"{' '.join(argv)} failed ({result.returncode}): {result.stderr[-2000:]}")
    return result.stdout


def reference_points_of(modules, jobs):
    """The reference reader's points for each (model, out_csv) of `jobs`, read by one node process."""
    env = dict(os.environ, DPOINT_NODE_MODULES=modules)
    argv = ["node", os.path.join(NODE_DIR, "read_points.mjs")]
    for model, out_csv in jobs:
        argv += [model, "-o", out_csv]
    run_tool(argv, env)
    return [read_xyz(out_csv) for _, out_csv in jobs]


def read_xyz(csv_path):
    """The x,y,z columns (dpoint may add r,g,b) as an n×3 array of doubles. dpoint writes a point
    set whose z are all 0 as x,y; z is then 0."""
    with open(csv_path) as f:
        header = f.readline().strip().split(",")
    columns = 3 if header[:3] == ["x", "y", "z"] else 2
    check(header[:columns] == ["x", "y", "z"][:columns], f"{csv_path}: header {header}")
    data = numpy.loadtxt(csv_path, delimiter=",", skiprows=1, usecols=range(columns), ndmin=2)
    data = data.reshape(-1, columns)
    return data if columns == 3 else numpy.column_stack([data, numpy.zeros(len(data))])


def extent(points):
    """Largest side of the axis-aligned box: the scale tolerances are relative to."""
    return float(numpy.max(points.max(axis=0) - points.min(axis=0))) if len(points) else 0.0


def sorted_rows(points, grid):
    """Rows in lexicographic order of their coordinates snapped to `grid`. Snapping first keeps two
    readers' orders aligned where coordinates tie in one and differ by an ulp in the other."""
    keys = numpy.floor(points / grid)
    return points[numpy.lexsort((keys[:, 2], keys[:, 1], keys[:, 0]))]


def match_sorted(ours, theirs, rel):
    """Same multiset of points within `rel` relative, per coordinate: |a−b| ≤ rel·max(extent, |b|).
    Returns (ok, message). Duplicates count: the sorted arrays are compared row by row; rows left
    unpaired (a tie broken differently at a snapping boundary) are paired one-to-one by a k-d tree."""
    if ours.shape != theirs.shape:
        return False, f"{len(ours)} points, reference has {len(theirs)}"
    if not len(ours):
        return True, "0 points"
    scale = max(extent(theirs), 1e-300)
    a, b = sorted_rows(ours, scale * 1e-6), sorted_rows(theirs, scale * 1e-6)
    tol = rel * numpy.maximum(scale, numpy.abs(b))
    diff = numpy.abs(a - b)
    bad = ~numpy.all(diff <= tol, axis=1)
    if bad.any():
        left_a, left_b = a[bad], b[bad]
        tree = cKDTree(left_b)
        taken = numpy.zeros(len(left_b), bool)
        for p in left_a:
            limit = rel * max(scale, float(numpy.max(numpy.abs(p))))
            near = tree.query_ball_point(p, limit * (1 + 1e-12), p=math.inf)
            free = [i for i in near if not taken[i]]
            if not free:
                return False, f"point {p.tolist()} has no reference point within {limit:.3g}"
            taken[free[0]] = True
    worst = float(numpy.max(diff / numpy.maximum(scale, numpy.abs(b)))) if not bad.any() else rel
    return True, f"{len(ours)} points, worst relative difference {worst:.2g}"


def within(ours, theirs, tol):
    """Every point of each set has a point of the other within `tol` per coordinate (the symmetric
    Hausdorff distance in the max norm). Used where a variant legitimately changes how many times a
    point occurs (Draco splits vertices at attribute seams, join/weld merge), so counts can differ."""
    worst = 0.0
    for name, p, q in (("ours", ours, theirs), ("original", theirs, ours)):
        dist, _ = cKDTree(q).query(p, p=math.inf)
        worst = max(worst, float(numpy.max(dist)))
        if worst > tol:
            return False, f"a point of {name} is {worst:.3g} from the other set (allowed {tol:.3g})"
    return True, f"{len(ours)} vs {len(theirs)} points, {worst:.3g} apart (allowed {tol:.3g})"


def glb_json(path):
    """The JSON chunk of a GLB (for the extensions a variant requires)."""
    with open(path, "rb") as f:
        head = f.read(20)
        length = struct.unpack_from("<I", head, 12)[0]
        return json.loads(f.read(length))
