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

from common import check, scratch

exe = sys.argv[1]
MODES = ["fp32", "split", "rte", "df64", "native", "batch", "adaptive"]
FIELDS = ["suite", "dataset", "points", "mode", "backend", "device", "driver", "resolution", "gpu_ms", "e2e_ms",
          "points_per_s", "warmup", "bytes_per_point", "splat_bytes_per_point", "loaded_bytes_per_point",
          "culled_share", "tier_share", "bytes_per_frame", "bandwidth_bound_ms",
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
    # A child run that fails: the bench stops with its error, the child's own stderr quoted in it,
    # and writes no report.
    fake = os.path.join(d, "fake-dpoint")
    with open(fake, "w") as f:
        f.write("#!/bin/sh\necho \"dpoint: error: the child's own message ($1)\" >&2\nexit 2\n")
    os.chmod(fake, 0o755)
    failed = subprocess.run([exe, "bench", "--suite", "ci", "--out", os.path.join(d, "failed"), "--cache",
                             os.path.join(d, "failed-cache"), "--quiet"], capture_output=True, text=True,
                            env={**os.environ, "DPOINT_EXECUTABLE": fake})
    check(failed.returncode == 2, f"a failing child: bench exited {failed.returncode}")
    check("failed (exit 2)" in failed.stderr and "\n  dpoint: error: the child's own message (generate)" in failed.stderr,
          f"a failing child: the bench's error lacks the child's message: {failed.stderr!r}")
    check(not os.path.exists(os.path.join(d, "failed", "report.md")), "a failing child: report.md written")

with scratch() as d:
    out, cache = os.path.join(d, "out"), os.path.join(d, "cache")
    ran = subprocess.run([exe, "bench", "--suite", "ci", "--out", out, "--cache", cache, "--frames", "3", "--warmup", "1ms",
                          "--validate", "--copy-bytes", "64M", "--copy-repeats", "5", "--quiet"], capture_output=True, text=True)
    check(ran.returncode == 0, f"dpoint bench failed ({ran.returncode}): {ran.stderr}")
    # Quiet and every check passed: nothing on stderr, the runs' own warnings (fp32 unbounded on the
    # hard cases, sets that cover little of the picture) included.
    check(ran.stderr == "", f"dpoint bench --quiet wrote to stderr:\n{ran.stderr[:2000]}")
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
    # Splat bytes per point are the mode's layout: the fixed layouts here, and the per-batch modes'
    # (their encodings may change) the same in every row and 4 B under bytes_per_point (colour).
    splat_bytes = {"fp32": 12, "split": 24, "rte": 24, "df64": 24, "native": 24}
    for mode in ("batch", "adaptive"):
        found = {r["splat_bytes_per_point"] for r in rows if r["mode"] == mode}
        check(len(found) == 1, f"{mode} splat bytes differ between rows: {found}")
        splat_bytes[mode] = found.pop()
    check(splat_bytes["batch"] <= 8, f"batch stores {splat_bytes['batch']} B a point")
    check(splat_bytes["adaptive"] == 12, f"adaptive stores {splat_bytes['adaptive']} B a point, not 3 tiers of 4")
    for r in rows:
        name = f"{r['case']} {r['backend']} {r['mode']}"
        check(r["splat_bytes_per_point"] == splat_bytes[r["mode"]],
              f"{name}: splat_bytes_per_point {r['splat_bytes_per_point']}, expected {splat_bytes[r['mode']]}")
        check(r["bytes_per_point"] == r["splat_bytes_per_point"] + 4, f"{name}: bytes_per_point {r['bytes_per_point']}")
        # The warm-up each timed draw ran (--warmup 1ms: by time, at least one frame).
        check(r["warmup"] is not None and r["warmup"]["frames"] >= 1 and r["warmup"]["ms"] >= 0,
              f"{name}: warmup {r['warmup']}")
        # Loaded bytes: the layout's for a fixed mode; a per-batch mode's plan for the view (culled
        # batches load nothing; adaptive 4 B a tier), batch's raster path every point's 8 B.
        loaded, culled, tiers = r["loaded_bytes_per_point"], r["culled_share"], r["tier_share"]
        if r["mode"] not in ("batch", "adaptive"):
            check(loaded == r["splat_bytes_per_point"] and culled is None and tiers is None,
                  f"{name}: loaded {loaded}, culled {culled}, tiers {tiers}")
        else:
            check(loaded is not None and 0 <= loaded <= r["splat_bytes_per_point"], f"{name}: loaded {loaded} B/pt")
            check(culled is not None and 0 <= culled <= 1, f"{name}: culled share {culled}")
            if culled == 0 or (r["mode"] == "batch" and r["backend"] == "raster"):
                low = 4 if r["mode"] == "adaptive" else r["splat_bytes_per_point"]
                check(low <= loaded, f"{name}: {loaded} B/pt loaded with no batch culled")
            if r["mode"] == "batch":
                check(tiers is None, f"{name}: batch has tier shares {tiers}")
                if culled == 0 or r["backend"] == "raster":
                    check(loaded == r["splat_bytes_per_point"], f"{name}: batch loaded {loaded} B/pt, culling none")
            else:
                check(tiers is not None and len(tiers) == 3 and all(0 <= t <= 1 for t in tiers), f"{name}: tiers {tiers}")
                check(math.isclose(sum(tiers) + culled, 1, abs_tol=1e-12), f"{name}: tiers {tiers} + culled {culled}")
                if culled == 0:  # every point loads 4 B per tier of its batch: between the fewest and the most tiers
                    used = [4 * (t + 1) for t in range(3) if tiers[t] > 0]
                    check(min(used) <= loaded <= max(used), f"{name}: {loaded} B/pt from tiers {tiers}")
        if r["backend"] == "compute":
            w, h = map(int, r["resolution"].split("x"))
            pixels = w * h
            frame = round(r["points"] * loaded) + pixels * 20 + min(r["points"], pixels) * 4
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
    # The plan is the view's: both backends of a case load the same (batch's raster path aside).
    for r in rows:
        if r["mode"] == "adaptive" and r["backend"] == "raster":
            twin = [c for c in rows if c["case"] == r["case"] and c["mode"] == "adaptive" and c["backend"] == "compute"]
            check(len(twin) == 1 and twin[0]["loaded_bytes_per_point"] == r["loaded_bytes_per_point"]
                  and twin[0]["tier_share"] == r["tier_share"], f"{r['case']}: adaptive's plan differs by backend")
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
            for m in ["rte", "df64", "native", "batch", "adaptive"]:
                check(max_err(by_mode[m]) <= max_err(by_mode["fp32"]), f"{case} {backend}: {m} no better than fp32")
    # The sweeps the breakdown draws are all there, each step in every mode.
    zoom = {r["sweep"]["x"] for r in rows if r["sweep"] and r["sweep"]["kind"].startswith("deep zoom")}
    offset = {r["sweep"]["x"] for r in rows if r["sweep"] and r["sweep"]["kind"] == "offset"}
    # The ci suite's sweeps take every other decade (bench/suites.cpp).
    check(zoom == {10.0 ** -e for e in range(1, 16, 2)}, f"deep-zoom sweep {sorted(zoom)}")
    check(offset == {10.0 ** e for e in range(0, 9, 2)}, f"offset sweep {sorted(offset)}")

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
    check("B/pt loaded, tiers " in report and "--warmup 1ms" in report,
          "report.md lacks adaptive's loaded bytes and tiers, or the warm-up asked")
print(f"bench ci suite: {len(rows)} rows checked")
