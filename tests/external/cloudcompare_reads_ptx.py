"""dpoint reads Leica PTX files as CloudCompare (Debian's cloudcompare, headless) reads them, and
writes PTX files that CloudCompare reads.

Three files made here: one scan of 40 x 50 rows with a rotation and a survey-sized translation,
intensities and colours, a tenth of its points with no echo (0 0 0); a file of three scans, one
without colours and one transformed by the identity; and a scan of x y z and intensity rows
(CloudCompare refuses rows without an intensity, which dpoint reads). CloudCompare
opens each with a global shift (`-GLOBAL_SHIFT AUTO`: its coordinates are float32 about the
shift), merges the scans and writes ASCII; dpoint converts the same file to CSV. The two must
hold the same points in the same order: positions within CloudCompare's float32 rounding about
the shift (1e-4 of a unit here, against a translation of 5e6), colours equal, intensities equal
to float32's rounding, the points with no echo left out by both. Each set dpoint read is written
back to PTX by dpoint, and a deep zoom far from the origin without intensities; CloudCompare reads
those, and dpoint reads back the doubles it wrote."""
import math
import os
import random
import shutil
import subprocess
import sys

import numpy as np

from common import check, dpoint, scratch

exe = sys.argv[1]
check(shutil.which("CloudCompare") is not None, "CloudCompare is not installed (scripts/setup installs cloudcompare)")


def rotation(rng):
    """A random rotation as PTX's 3x3 part (rows of the row-vector form)."""
    a, b, c = (rng.uniform(-math.pi, math.pi) for _ in range(3))
    rz = np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]])
    ry = np.array([[math.cos(b), 0, math.sin(b)], [0, 1, 0], [-math.sin(b), 0, math.cos(b)]])
    rx = np.array([[1, 0, 0], [0, math.cos(c), -math.sin(c)], [0, math.sin(c), math.cos(c)]])
    return rz @ ry @ rx


def scan_text(rng, columns, rows, translation, rot, fields):
    """A scan's header and rows; returns the text and the expected registered points."""
    lines = [str(columns), str(rows), " ".join(f"{t:.6f}" for t in translation)]
    lines += [" ".join(f"{v:.6f}" for v in rot[k]) for k in range(3)]
    lines += [" ".join(f"{v:.9f}" for v in rot[k]) + " 0" for k in range(3)]
    lines.append(" ".join(f"{t:.6f}" for t in translation) + " 1")
    expected = []
    for i in range(columns * rows):
        if rng.random() < 0.1:
            lines.append("0 0 0" + (" 0.5" if fields >= 4 else "") + (" 0 0 0" if fields >= 6 else ""))
            continue
        p = [round(rng.uniform(-40, 40), 6) for _ in range(3)]
        row = [f"{v:.6f}" for v in p]
        intensity = round(rng.random(), 6)
        color = [rng.randrange(256) for _ in range(3)]
        if fields in (4, 7):
            row.append(f"{intensity:.6f}")
        if fields in (6, 7):
            row += [str(c) for c in color]
        lines.append(" ".join(row))
        rot_parsed = np.array([[float(f"{v:.9f}") for v in rot[k]] for k in range(3)])
        world = np.array(p) @ rot_parsed + np.array([float(f"{t:.6f}") for t in translation])
        expected.append((world, intensity if fields in (4, 7) else None, color if fields in (6, 7) else None))
    return "\n".join(lines) + "\n", expected


def cloudcompare(ptx, out):
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen")
    args = ["CloudCompare", "-SILENT", "-AUTO_SAVE", "OFF", "-O", "-GLOBAL_SHIFT", "AUTO", ptx, "-MERGE_CLOUDS",
            "-C_EXPORT_FMT", "ASC", "-PREC", "12", "-ADD_HEADER", "-SAVE_CLOUDS", "FILE", out]
    result = subprocess.run(args, capture_output=True, text=True, env=env, timeout=120)
    check(result.returncode == 0, f"CloudCompare failed on {ptx}: {result.stdout[-2000:]}{result.stderr[-2000:]}")
    # One cloud is saved as OUT, a merged set as OUT_0.
    path = out if os.path.exists(out) else out + "_0"
    check(os.path.exists(path), f"CloudCompare wrote no {out}: {result.stdout[-2000:]}")
    with open(path) as f:
        names = f.readline().lstrip("/").split()
    rows = np.loadtxt(path, skiprows=1, ndmin=2)
    return {name.lower(): rows[:, k] for k, name in enumerate(names)}


def read_csv(path):
    with open(path) as f:
        names = f.readline().strip().split(",")
    rows = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return {name: rows[:, k] for k, name in enumerate(names)}


def check_written(ptx, source, tmp):
    """A PTX file dpoint wrote from `source` (read_csv's columns): CloudCompare reads its points
    within float32 about its global shift, its colours equal and its intensities (0 where the source
    has none) to float32's rounding; dpoint reads back every double as it was."""
    name = os.path.basename(ptx)
    n = len(source["x"])
    theirs = cloudcompare(ptx, ptx + ".asc")
    check(len(theirs["x"]) == n, f"{name}: CloudCompare read {len(theirs['x'])} points of {n}")
    for axis in "xyz":
        gap = np.abs(source[axis] - theirs[axis]).max()
        check(gap < 1e-4, f"{name}: {axis} and CloudCompare's differ by up to {gap}")
    intensity = source.get("intensity", np.zeros(n))
    check(np.all(np.abs(intensity - theirs["intensity"]) <= 1e-7 * np.maximum(1.0, np.abs(intensity))),
          f"{name}: intensities differ from CloudCompare's")
    if "r" in source:
        for c in "rgb":
            check(np.array_equal(source[c], theirs[c]), f"{name}: {c} differs from CloudCompare's")
    back = os.path.join(tmp, name + ".csv")
    dpoint(exe, "convert", ptx, "-o", back)
    again = read_csv(back)
    for column in ("x", "y", "z", "r", "g", "b", "intensity", "point_source_id"):  # the scans too
        if column in source:
            check(np.array_equal(again[column], source[column]), f"{name}: {column} read back differs")
    print(f"{name}: {n} points written, read by CloudCompare and read back")


rng = random.Random(20261201)
cases = {
    "survey": [(40, 50, (558312.218127, 5240857.469093, 76.298415), rotation(rng), 7)],
    "three_scans": [(20, 10, (1000.5, -2000.25, 12.0), rotation(rng), 7),
                    (15, 10, (980.0, -1990.0, 11.5), rotation(rng), 4),
                    (10, 10, (0.0, 0.0, 0.0), np.eye(3), 7)],
    "no_colours": [(30, 30, (-120.0, 35.0, 2.0), rotation(rng), 4)],
}
with scratch() as tmp:
    for name, scans in cases.items():
        text, expected = "", []
        for columns, rows, translation, rot, fields in scans:
            t, e = scan_text(rng, columns, rows, translation, rot, fields)
            text += t
            expected += e
        ptx = os.path.join(tmp, name + ".ptx")
        with open(ptx, "w") as f:
            f.write(text)
        csv = os.path.join(tmp, name + ".csv")
        dpoint(exe, "convert", ptx, "-o", csv)
        ours = read_csv(csv)
        theirs = cloudcompare(ptx, os.path.join(tmp, name + ".asc"))
        n = len(expected)
        check(len(ours["x"]) == n, f"{name}: dpoint read {len(ours['x'])} points, {n} have an echo")
        check(len(theirs["x"]) == n, f"{name}: CloudCompare read {len(theirs['x'])} points, {n} have an echo")
        for k, axis in enumerate("xyz"):
            ref = np.array([e[0][k] for e in expected])
            check(np.abs(ours[axis] - ref).max() <= 8 * np.spacing(max(1.0, np.abs(ref).max())),
                  f"{name}: dpoint's {axis} differs from the registered values by {np.abs(ours[axis] - ref).max()}")
            gap = np.abs(ours[axis] - theirs[axis]).max()
            check(gap < 1e-4, f"{name}: dpoint's {axis} and CloudCompare's differ by up to {gap}")
        has_intensity = any(e[1] is not None for e in expected)
        check(("intensity" in ours) == has_intensity, f"{name}: dpoint's intensity column: {list(ours)}")
        if has_intensity:
            for s, (col, cc) in enumerate(zip(ours["intensity"], theirs["intensity"])):
                if expected[s][1] is not None:
                    check(abs(col - cc) <= 1e-7 * max(1.0, abs(col)), f"{name}: point {s}: intensity {col} against {cc}")
        has_color = any(e[2] is not None for e in expected)
        check(("r" in ours) == has_color, f"{name}: dpoint's colour columns: {list(ours)}")
        if has_color:
            for s in range(n):
                if expected[s][2] is None:  # a scan without colours: white in dpoint's set
                    check([ours[c][s] for c in "rgb"] == [255, 255, 255], f"{name}: point {s} should be white")
                    continue
                mine = [int(ours[c][s]) for c in "rgb"]
                check(mine == expected[s][2] and mine == [int(theirs[c][s]) for c in "rgb"],
                      f"{name}: point {s}: colour {mine}, CloudCompare {[theirs[c][s] for c in 'rgb']}, "
                      f"file {expected[s][2]}")
        print(f"{name}: {n} points agree with CloudCompare's reading ({len(scans)} scan(s))")

        # Written back by dpoint, a scan for each of the set's (its point_source_id): CloudCompare
        # reads the same points, intensities and colours, and dpoint reads back the very doubles it
        # wrote (shortest round trip about each scan's whole-unit translation) and the scans.
        written = os.path.join(tmp, name + "_written.ptx")
        dpoint(exe, "convert", csv, "-o", written)
        check_written(written, ours, tmp)

    # A set with no intensity (each row's is 0), far from the origin: a deep zoom at 6.4e6 with a
    # 1e-6 extent.
    far = os.path.join(tmp, "far.csv")
    with open(far, "w") as f:
        f.write("x,y,z,r,g,b\n")
        for i in range(500):
            f.write(f"{6.4e6 + rng.random() * 1e-6!r},{-3.2e6 + rng.random() * 1e-6!r},{rng.random() * 1e-6!r},"
                    f"{rng.randrange(256)},{rng.randrange(256)},{rng.randrange(256)}\n")
    written = os.path.join(tmp, "far.ptx")
    dpoint(exe, "convert", far, "-o", written)
    check_written(written, read_csv(far), tmp)
print("ok")
