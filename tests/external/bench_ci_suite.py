"""`dpoint bench --suite ci` (issue #10) on the machine's Vulkan device with the validation layer on:
every row and picture is produced, every measured error is within its predicted bound, and the modes'
errors are ordered as DESIGN §4 predicts. Checked here from results.json, independently of the
report's own checks. The SVGs must parse, carry axes with tick labels and one series per mode, and
render through rsvg-convert (librsvg). Never timings."""
import json
import math
import os
import struct
import subprocess
import sys
import xml.etree.ElementTree as ET

from common import check, dpoint, scratch

exe = sys.argv[1]
MODES = ["fp32", "split", "rte", "df64", "native", "batch", "adaptive"]
FIELDS = ["suite", "dataset", "points", "mode", "backend", "device", "driver", "resolution", "gpu_ms", "e2e_ms",
          "points_per_s", "bytes_per_point", "splat_bytes_per_point", "bytes_per_frame", "bandwidth_bound_ms",
          "bandwidth_fraction", "predicted_bound_px", "error_px", "share_off_half_px", "points_lost",
          "pixels_differing"]
SVG = "{http://www.w3.org/2000/svg}"


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    check(head[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG")
    return struct.unpack(">II", head[16:24])


def groups(root, cls):
    return [g for g in root.iter(SVG + "g") if cls in (g.get("class") or "").split()]


def check_svg(path, series_per_panel, panels):
    root = ET.parse(path).getroot()  # raises on malformed XML
    check(root.tag == SVG + "svg", f"{path}: root is {root.tag}")
    found = groups(root, "panel")
    check(len(found) == panels, f"{path}: {len(found)} panels, expected {panels}")
    for panel in found:
        for axis in ("x-axis", "y-axis"):
            ax = groups(panel, axis)
            check(len(ax) == 1, f"{path}: a panel has {len(ax)} {axis} groups")
            labels = [t for t in ax[0].iter(SVG + "text") if "tick-label" in (t.get("class") or "")]
            check(len(labels) >= 2, f"{path}: {axis} has {len(labels)} tick labels")
        names = [g.get("data-series") for g in groups(panel, "series")]
        for mode in MODES:
            mine = [n for n in names if n.split()[0] == mode]
            check(len(mine) == series_per_panel, f"{path}: {len(mine)} series for {mode} in a panel: {names}")
    check(len(groups(root, "legend")) == 1, f"{path}: no legend")
    png = path + ".png"
    result = subprocess.run(["rsvg-convert", "-o", png, path], capture_output=True, text=True)
    check(result.returncode == 0, f"rsvg-convert {path}: {result.stderr}")
    w, h = png_size(png)
    check(w >= 600 and h >= 300, f"{png} is {w}x{h}")


with scratch() as d:
    out, cache = os.path.join(d, "out"), os.path.join(d, "cache")
    dpoint(exe, "bench", "--suite", "ci", "--out", out, "--cache", cache, "--frames", "3", "--warmup", "1", "--validate",
           "--copy-bytes", "64M", "--copy-repeats", "5", "--quiet")
    for name in ["report.md", "results.json", "speed_vs_error.svg", "breakdown.svg", "montage.png"]:
        check(os.path.getsize(os.path.join(out, name)) > 0, f"{name} missing or empty")
    with open(os.path.join(out, "results.json")) as f:
        results = json.load(f)
    rows = results["rows"]
    cases = sorted({r["case"] for r in rows})
    check(len(rows) == len(cases) * 2 * len(MODES), f"{len(rows)} rows for {len(cases)} cases")
    check(results["check_failures"] == [], f"the report's own checks failed: {results['check_failures']}")
    # The copy bandwidth: measured once, as asked, and positive both ways (read+write is twice the copy rate).
    copy = results["copy_bandwidth"]
    check(copy is not None, "no copy_bandwidth in results.json")
    check(copy["copy_bytes"] == 64 << 20 and copy["copies"] == 5, f"copy_bandwidth {copy}")
    check(copy["copy_gb_per_s"] > 0 and math.isclose(copy["read_write_gb_per_s"], 2 * copy["copy_gb_per_s"]),
          f"copy_bandwidth {copy}")
    check(copy["bound_uses"] == "read_write_gb_per_s", f"copy_bandwidth {copy}")
    # Splat bytes per point are the mode's position bytes: the two fixed layouts here, and batch's
    # (its encoding may change) the same in every row and 4 B under its bytes_per_point (colour).
    # adaptive: its three 4-byte tier planes, as the bench counts a frame's bytes (positionBytes).
    splat_bytes = {"fp32": 12, "split": 24, "rte": 24, "df64": 24, "native": 24, "adaptive": 12}
    batch_bytes = {r["splat_bytes_per_point"] for r in rows if r["mode"] == "batch"}
    check(len(batch_bytes) == 1, f"batch splat bytes differ between rows: {batch_bytes}")
    splat_bytes["batch"] = batch_bytes.pop()
    for r in rows:
        name = f"{r['case']} {r['backend']} {r['mode']}"
        check(r["splat_bytes_per_point"] == splat_bytes[r["mode"]],
              f"{name}: splat_bytes_per_point {r['splat_bytes_per_point']}, expected {splat_bytes[r['mode']]}")
        check(r["bytes_per_point"] == r["splat_bytes_per_point"] + 4, f"{name}: bytes_per_point {r['bytes_per_point']}")
        if r["backend"] == "compute":
            w, h = map(int, r["resolution"].split("x"))
            pixels = w * h
            frame = r["points"] * r["splat_bytes_per_point"] + pixels * 20 + min(r["points"], pixels) * 4
            check(r["bytes_per_frame"] == frame, f"{name}: bytes_per_frame {r['bytes_per_frame']}, expected {frame}")
            bound = frame / (copy["read_write_gb_per_s"] * 1e6)
            check(math.isclose(r["bandwidth_bound_ms"], bound, rel_tol=1e-9), f"{name}: bound {r['bandwidth_bound_ms']} ms")
            check(r["bandwidth_fraction"] is not None and r["bandwidth_fraction"] > 0,
                  f"{name}: bandwidth_fraction {r['bandwidth_fraction']}")
            if r["gpu_ms"] is not None:
                check(math.isclose(r["bandwidth_fraction"], bound / r["gpu_ms"]["median"], rel_tol=1e-9),
                      f"{name}: bandwidth_fraction {r['bandwidth_fraction']} is not bound / GPU median")
        else:
            check(r["bytes_per_frame"] is None and r["bandwidth_fraction"] is None, f"{name}: raster has a bound")
    groups_by = {}
    for r in rows:
        for field in FIELDS:
            check(field in r, f"row {r['case']} {r['mode']} lacks {field}")
        check(r["skipped"] is None, f"{r['case']} {r['backend']} {r['mode']} did not run: {r['skipped']}")
        check(r["gpu_ms"] is None or r["gpu_ms"]["min"] <= r["gpu_ms"]["median"] <= r["gpu_ms"]["p95"],
              f"{r['case']}: gpu_ms {r['gpu_ms']}")
        bound, err = r["predicted_bound_px"], r["error_px"]
        if bound is not None and err is not None:
            check(err["max"] <= bound, f"{r['case']} {r['backend']} {r['mode']}: max error {err['max']} > bound {bound}")
        if err is not None:
            check(err["rms"] <= err["max"] and err["p99"] <= err["max"], f"{r['case']} {r['mode']}: {err}")
        groups_by.setdefault((r["case"], r["backend"]), {})[r["mode"]] = r

    def max_err(row):  # every point lost: infinitely wrong
        return math.inf if row["error_px"] is None else row["error_px"]["max"]

    for (case, backend), by_mode in groups_by.items():
        check(max_err(by_mode["split"]) == max_err(by_mode["fp32"]), f"{case} {backend}: split != fp32")
        floor = by_mode["native"]["float_floor_px"]
        best = min(max_err(by_mode[m]) for m in MODES)
        check(max_err(by_mode["native"]) <= best + floor, f"{case} {backend}: native {max_err(by_mode['native'])} > {best}")
        if max_err(by_mode["fp32"]) > 1.0:
            for m in ["rte", "df64", "native", "batch"]:
                check(max_err(by_mode[m]) <= max_err(by_mode["fp32"]), f"{case} {backend}: {m} no better than fp32")
    # The sweeps the breakdown draws are all there, each step in every mode.
    zoom = {r["sweep"]["x"] for r in rows if r["sweep"] and r["sweep"]["kind"].startswith("deep zoom")}
    offset = {r["sweep"]["x"] for r in rows if r["sweep"] and r["sweep"]["kind"] == "offset"}
    check(zoom == {10.0 ** -e for e in range(1, 16)}, f"deep-zoom sweep {sorted(zoom)}")
    check(offset == {10.0 ** e for e in range(0, 9)}, f"offset sweep {sorted(offset)}")

    families = len({r["family"] for r in rows})
    check_svg(os.path.join(out, "speed_vs_error.svg"), 2, families)  # a series per mode and backend
    check_svg(os.path.join(out, "breakdown.svg"), 2, 2)              # measured and bound per mode
    w, h = png_size(os.path.join(out, "montage.png"))
    check(w >= 6 * 128 and h >= 2 * 128, f"montage is {w}x{h}")
    with open(os.path.join(out, "report.md")) as f:
        report = f.read()
    for case in cases:
        check(f"| {case} |" in report, f"report.md has no row for {case}")
    check("## Checks" in report and "All passed" in report, "report.md lacks its checks")
    for outside in ("DESIGN", "../", "shared/"):
        check(outside not in report, f"report.md names {outside!r}, outside the repository")
    check("- Copy bandwidth: **" in report and "% of bound" in report, "report.md lacks the copy bandwidth or % of bound")
print(f"bench ci suite: {len(rows)} rows checked")
