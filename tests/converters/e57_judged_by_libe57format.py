#!/usr/bin/env python3
"""dpoint's E57 reader against libE57Format's verdicts (tests/data/e57/README.md).

For each tests/data/e57/NAME.e57 with a NAME.libe57format.txt (what libE57Format, the E57
reference implementation's heir, read from it: each scan's fields, its pose, every record of a
small scan or every k-th of a large one, and each field's sum), `dpoint convert NAME.e57 -o
NAME.csv` must give, with numpy computing what the E57 standard says from libE57Format's values:
- each scan's valid points (invalid state 0), in order, the scans one after another (the dump
  gives each record's place among its scan's valid ones);
- positions: cartesian, or x = r cos(el) cos(az), y = r cos(el) sin(az), z = r sin(el), then
  moved by the pose (the unit quaternion's rotation, then the translation): equal where there is no
  pose and no spherical coordinates, else within a few units in the last place of the extent;
- colours: the integers as the file has them (0..255 or 0..65535: CSV writes them at that scale);
- the other fields as dimensions of their values (returnIndex + 1 as return_number, returnCount as
  number_of_returns, las:pointSourceId as point_source_id, las:classification as classification;
  an intensity that is no 0..65535 integer, and where one scan has such every scan's, from its
  field's limits to 0..1),
  and with several scans each point's scan number in point_source_id;
- the sums of the valid points' coordinates, to 1e-12 of their size (every row, not the samples).
bad-crc.e57 must be refused, as libE57Format refuses it, naming the damaged page.

Written: for each written/NAME.e57 (dpoint's E57 of tests/data/NAME's source, WRITTEN below, which
libE57Format read into written/NAME.libe57format.txt), `dpoint convert SOURCE -o X.e57` must make
those bytes again, and libE57Format's reading must be dpoint's reading of the source: positions
equal, colours the same integers, each dimension its field (return_number - 1 as returnIndex,
number_of_returns as returnCount, the other LAS fields as las:camelCase).
"""
import math
import os
import subprocess
import sys
import tempfile

import numpy as np
import pandas as pd

DPOINT = sys.argv[1]
DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "e57")
failures = []


def fail(name, what):
    failures.append(f"{name}: {what}")


def parse_judge(path):
    scans = []
    with open(path) as f:
        for line in f:
            words = line.split()
            if words[0] == "scan":
                scans.append({"records": int(words[3]), "fields": words[5:], "rows": {}, "pose": None, "limits": {},
                              "precision": {}})
            elif words[0] == "field" and words[2] == "Integer":
                scans[-1]["limits"][words[1]] = ("Integer", int(words[3]), int(words[4]))
            elif words[0] == "field" and words[2] == "Float":
                scans[-1]["precision"][words[1]] = words[3]
            elif words[0] == "field" and words[2] == "ScaledInteger":
                ends = [int(words[3]) * float(words[5]) + float(words[6]), int(words[4]) * float(words[5]) + float(words[6])]
                scans[-1]["limits"][words[1]] = ("ScaledInteger", min(ends), max(ends))
            elif words[0] == "pose":
                scans[-1]["pose"] = None if words[1] == "none" else [float(w) for w in words[1:]]
            elif words[0] == "r":  # the record, its place among the scan's valid ones, its values
                scans[-1]["rows"][int(words[1])] = (int(words[2]), [float(w) for w in words[3:]])
            elif words[0] == "sum":
                scans[-1]["sums"] = [float(w) for w in words[1:]]
    return scans


def rotation(q):
    w, x, y, z = np.array(q) / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def expected_position(scan, values):
    f = scan["fields"]
    v = dict(zip(f, values))
    if "cartesianX" in v:
        p = np.array([v["cartesianX"], v["cartesianY"], v["cartesianZ"]])
    else:
        r, az, el = v["sphericalRange"], v["sphericalAzimuth"], v["sphericalElevation"]
        p = np.array([r * math.cos(el) * math.cos(az), r * math.cos(el) * math.sin(az), r * math.sin(el)])
    if scan["pose"] is not None:
        p = rotation(scan["pose"][:4]) @ p + np.array(scan["pose"][4:])
    return p


def invalid(scan, values):
    v = dict(zip(scan["fields"], values))
    key = "cartesianInvalidState" if "cartesianX" in v else "sphericalInvalidState"
    return v.get(key, 0) != 0


DIMENSIONS = {"returnIndex": ("return_number", 1), "returnCount": ("number_of_returns", 0),
              "las:pointSourceId": ("point_source_id", 0), "las:classification": ("classification", 0)}
USED = {"cartesianX", "cartesianY", "cartesianZ", "cartesianInvalidState", "sphericalRange", "sphericalAzimuth",
        "sphericalElevation", "sphericalInvalidState", "colorRed", "colorGreen", "colorBlue"}


def las_intensity(scan):
    kind, lo, hi = scan["limits"].get("intensity", ("Float", 0, 1))
    return kind == "Integer" and lo >= 0 and hi <= 65535


def check(name, work):
    scans = parse_judge(os.path.join(DATA, name + ".libe57format.txt"))
    out = os.path.join(work, name + ".csv")
    run = subprocess.run([DPOINT, "convert", os.path.join(DATA, name + ".e57"), "-o", out, "-q"],
                         capture_output=True, text=True)
    if run.returncode != 0:
        fail(name, f"dpoint convert exit {run.returncode}: {run.stderr.strip()}")
        return
    table = pd.read_csv(out, dtype=np.float64, float_precision="round_trip") if os.path.getsize(out) > 0 else pd.DataFrame()
    total_valid = 0
    first_row = 0
    # An intensity that is no 0..65535 integer in one scan makes every scan's 0..1.
    fractions = any(s["records"] > 0 and "intensity" in s["fields"] and not las_intensity(s) for s in scans)
    several = sum(1 for s in scans if s["records"] > 0) > 1
    for number, scan in enumerate(scans, start=1):
        if scan["records"] == 0:
            continue
        for index, (place, values) in sorted(scan["rows"].items()):
            if invalid(scan, values):
                continue
            row = first_row + place
            got = table.iloc[row]
            want = expected_position(scan, values)
            exact = scan["pose"] is None and "cartesianX" in scan["fields"]
            tolerance = 0.0 if exact else 8 * np.finfo(float).eps * max(1.0, float(np.max(np.abs(want))))
            for k, axis in enumerate("xyz"):
                if abs(got[axis] - want[k]) > tolerance:
                    fail(name, f"scan {number} record {index} (row {row}): {axis} {got[axis]!r}, libE57Format "
                               f"and the pose give {want[k]!r}")
            v = dict(zip(scan["fields"], values))
            if "colorRed" in v:
                # 0..255 or 0..65535 integers in these files: CSV writes them as they are.
                for channel, field in zip("rgb", ("colorRed", "colorGreen", "colorBlue")):
                    if got[channel] != v[field]:
                        fail(name, f"scan {number} record {index}: {channel} {got[channel]!r}, libE57Format {v[field]!r}")
            for field in scan["fields"]:
                if field in USED:
                    continue
                column, add = DIMENSIONS.get(field, (field, 0))
                if column not in table.columns:
                    fail(name, f"no column {column} for the field {field} (columns: {list(table.columns)})")
                    return
                want_value = v[field] + add
                kind, lo, hi = scan["limits"].get(field, ("Float", 0, 1))  # these files' float intensities are 0..1
                if field == "intensity" and (fractions or not las_intensity(scan)) and (lo, hi) != (0, 1):
                    want_value = (v[field] - lo) / (hi - lo)  # read as 0..1 (float32) from the field's limits
                if abs(got[column] - want_value) > 1e-7 * max(1.0, abs(want_value)):
                    fail(name, f"scan {number} record {index}: {column} {got[column]!r}, libE57Format {want_value!r}")
            if several and "las:pointSourceId" not in scan["fields"] and got["point_source_id"] != number:
                fail(name, f"scan {number} record {index}: point_source_id {got['point_source_id']!r}")
        last = max(scan["rows"])  # the valid records: those before the last printed one, and it
        valid = scan["rows"][last][0] + (0 if invalid(scan, scan["rows"][last][1]) else 1)
        if last != scan["records"] - 1:
            fail(name, f"scan {number}: the judge's dump ends at record {last} of {scan['records']}")
        # Sums over every valid point (without a pose: equal to rounding; sums of positions with
        # a pose or spherical coordinates are not what libE57Format summed).
        if scan["pose"] is None and "cartesianX" in scan["fields"] and valid == scan["records"]:
            part = table.iloc[first_row:first_row + valid]
            for k, axis in enumerate("xyz"):
                want = scan["sums"][scan["fields"].index("cartesian" + axis.upper())]
                got_sum = math.fsum(part[axis])
                if abs(got_sum - want) > 1e-12 * max(1.0, float(np.sum(np.abs(part[axis])))):
                    fail(name, f"scan {number}: the sum of {axis} is {got_sum!r}, libE57Format's {want!r}")
        first_row += valid
        total_valid += valid
    if len(table) != total_valid:
        fail(name, f"{len(table)} rows, libE57Format's valid records {total_valid}")
    print(f"{name}: {total_valid} points, {sum(len(s['rows']) for s in scans)} records compared", file=sys.stderr)


WRITTEN = {"1.2-with-color": os.path.join(DATA, "..", "laz", "1.2-with-color.las"),
           # More fields than one 64-record group of fits in a packet: each group over two packets.
           "130-doubles": os.path.join(DATA, "written", "130-doubles.ply"),
           # Two scans read as one set (each point's scan in point_source_id): written as two.
           "two_scans": os.path.join(DATA, "two_scans.e57")}
LAS_FIELDS = {"scan_direction", "edge_of_flight_line", "classification", "synthetic", "key_point", "withheld",
              "scan_angle_rank", "scan_angle", "user_data", "point_source_id", "gps_time", "overlap",
              "scanner_channel", "nir"}  # the LAS fields the writer puts in the LAS extension (las:camelCase)


def camel(snake):
    head, *rest = snake.split("_")
    return head + "".join(w[:1].upper() + w[1:] for w in rest)


def check_written(name, source, work):
    out = os.path.join(work, name + ".e57")
    run = subprocess.run([DPOINT, "convert", source, "-o", out, "-q"], capture_output=True, text=True)
    if run.returncode != 0:
        fail("written/" + name, f"dpoint convert exit {run.returncode}: {run.stderr.strip()}")
        return
    golden = os.path.join(DATA, "written", name + ".e57")
    with open(out, "rb") as a, open(golden, "rb") as b:
        if a.read() != b.read():
            fail("written/" + name, "dpoint's E57 is not the bytes libE57Format read (tests/data/e57/written)")
    csv = os.path.join(work, name + ".csv")
    # 17 fixed decimals: every coordinate's double (a LAS source's CSV has its step's digits alone).
    subprocess.run([DPOINT, "convert", source, "-o", csv, "-q", "--decimals", "17"], check=True)
    table = pd.read_csv(csv, dtype=np.float64, float_precision="round_trip")
    # A scan for each of the source's scans (point_source_id's runs), the source's points in order.
    scans = parse_judge(os.path.join(DATA, "written", name + ".libe57format.txt"))
    ids = table["point_source_id"].to_numpy() if "point_source_id" in table.columns else np.zeros(len(table))
    runs = 1 + int(np.count_nonzero(ids[1:] != ids[:-1])) if len(ids) else 1
    expected_scans = runs if runs == len(np.unique(ids)) else 1
    if sum(scan["records"] for scan in scans) != len(table) or len(scans) != expected_scans or any(
            scan["pose"] is not None for scan in scans):
        fail("written/" + name, f"{[scan['records'] for scan in scans]} records in {len(scans)} scans (poses "
             f"{[scan['pose'] for scan in scans]}), the source has {len(table)} points in {expected_scans}")
        return
    column_of = {"cartesianX": "x", "cartesianY": "y", "cartesianZ": "z", "colorRed": "r", "colorGreen": "g",
                 "colorBlue": "b", "intensity": "intensity", "returnIndex": "return_number",
                 "returnCount": "number_of_returns"}
    for column in table.columns:
        if column not in column_of.values():
            column_of[("las:" + camel(column)) if column in LAS_FIELDS else column] = column
    fractions = "r" in table.columns and table[["r", "g", "b"]].to_numpy().max() <= 1.0
    first, compared = 0, 0
    for scan in scans:
        if sorted(column_of[f] for f in scan["fields"]) != sorted(table.columns):
            fail("written/" + name, f"fields {scan['fields']} for the columns {list(table.columns)}")
            return
        for index, (_, values) in scan["rows"].items():
            for field, value in zip(scan["fields"], values):
                want = table.iloc[first + index][column_of[field]] - (1 if field == "returnIndex" else 0)
                if field.startswith("color") and fractions:  # the CSV's 0..1 as the integers of the colour's scale
                    want = round(want * scan["limits"][field][2])
                if scan["precision"].get(field) == "single":  # the CSV's shortest float32 form
                    value, want = np.float32(value), np.float32(want)
                if value != want:
                    fail("written/" + name, f"record {first + index}: {field} {value!r}, the source's "
                         f"{column_of[field]} {want!r}")
        first += scan["records"]
        compared += len(scan["rows"])
    print(f"written/{name}: {len(table)} points in {len(scans)} scan(s), {compared} records compared", file=sys.stderr)


with tempfile.TemporaryDirectory() as work:
    for name, source in WRITTEN.items():
        check_written(name, source, work)
    names = sorted(f[:-len(".libe57format.txt")] for f in os.listdir(DATA) if f.endswith(".libe57format.txt"))
    if len(names) < 6:
        fail("tests/data/e57", f"only {len(names)} files with libE57Format's verdict")
    for name in names:
        check(name, work)
    bad = subprocess.run([DPOINT, "convert", os.path.join(DATA, "bad-crc.e57"), "-o", os.path.join(work, "bad.csv")],
                         capture_output=True, text=True)
    if bad.returncode != 2 or "page 0" not in bad.stderr or "CRC-32C" not in bad.stderr or os.path.exists(
            os.path.join(work, "bad.csv")):
        fail("bad-crc", f"exit {bad.returncode}, {bad.stderr.strip()!r} (libE57Format: checksum mismatch, page 0)")

for f in failures:
    print("FAIL " + f, file=sys.stderr)
sys.exit(1 if failures else 0)
