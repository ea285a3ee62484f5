"""pandas reads dpoint's CSV with the same values: shortest form bit for bit, --decimals 15 as
Python's '%.15f' text would give."""
import math
import os
import random
import struct
import sys

import pandas

from common import check, dpoint, scratch

exe = sys.argv[1]
random.seed(4)
values = [0.0, -0.0, 5e-324, -5e-324, 2.2250738585072014e-308, 1.7976931348623157e308, -1.7976931348623157e308,
          1e-300, 0.1, 1 / 3, 6378137.000000001, 1.2345678901234567]
while len(values) < 30000:
    d = struct.unpack("<d", struct.pack("<Q", random.getrandbits(64)))[0]
    if math.isfinite(d):
        values.append(d)
rows = [values[i:i + 3] for i in range(0, len(values), 3)]
colors = [[random.randrange(256) / 255 for _ in range(3)] for _ in rows]

with scratch() as d:
    src = os.path.join(d, "in.csv")
    with open(src, "w") as f:
        f.write("x,y,z,r,g,b\n")
        for r, c in zip(rows, colors):
            f.write(",".join(repr(v) for v in r + c) + "\n")
    out = os.path.join(d, "out.csv")
    dpoint(exe, "convert", src, "-o", out)
    frame = pandas.read_csv(out, float_precision="round_trip")
    check(list(frame.columns) == ["x", "y", "z", "r", "g", "b"], f"columns {list(frame.columns)}")
    check(len(frame) == len(rows), f"{len(frame)} rows, expected {len(rows)}")
    for i, r in enumerate(rows):
        got = [frame.x[i], frame.y[i], frame.z[i]]
        same = all(struct.pack("<d", a) == struct.pack("<d", b) for a, b in zip(got, r))
        check(same, f"row {i}: pandas read {got}, wrote {r}")
    # Colours are float32 in dpoint: pandas reads the shortest float text, which rounds to the same float.
    for i, c in enumerate(colors):
        got = [frame.r[i], frame.g[i], frame.b[i]]
        check(all(struct.pack("<f", a) == struct.pack("<f", b) for a, b in zip(got, c)), f"row {i} colour {got} vs {c}")

    fixed = os.path.join(d, "fixed.csv")
    dpoint(exe, "convert", src, "-o", fixed, "--decimals", "15")
    frame = pandas.read_csv(fixed, float_precision="round_trip")
    for i, r in enumerate(rows[:2000]):
        want = [float("%.15f" % v) for v in r]
        got = [frame.x[i], frame.y[i], frame.z[i]]
        check(got == want, f"row {i}: --decimals 15 gave {got}, '%.15f' gives {want}")
    # A survey's fields after x,y,z,r,g,b (issue #34): pandas reads them as numbers, integers as integers.
    las = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "shared", "corpus", "las",
                       "simple.las")
    fields = os.path.join(d, "fields.csv")
    dpoint(exe, "convert", las, "-o", fields)
    frame = pandas.read_csv(fields, float_precision="round_trip")
    want = ["x", "y", "z", "r", "g", "b", "intensity", "return_number", "number_of_returns", "scan_direction",
            "edge_of_flight_line", "classification", "synthetic", "key_point", "withheld", "scan_angle_rank",
            "user_data", "point_source_id", "gps_time"]
    check(list(frame.columns) == want, f"LAS fields: columns {list(frame.columns)}")
    check(len(frame) == 1065, f"LAS fields: {len(frame)} rows")
    first = frame.iloc[0]
    check((first.intensity, first.classification, first.scan_angle_rank, first.point_source_id) == (143, 1, -9, 7326),
          f"LAS fields: first row {first.to_dict()}")
    check(str(frame.classification.dtype).startswith("int"), f"classification read as {frame.classification.dtype}")
    check(first.gps_time == 245380.78254962614, f"gps time {first.gps_time!r}")
    check(sorted(frame.classification.unique().tolist()) == [1, 2], f"classes {frame.classification.unique()}")
print(f"pandas {pandas.__version__} read {len(rows)} rows with the same values")
