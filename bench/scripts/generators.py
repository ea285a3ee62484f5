#!/usr/bin/python3
"""Generator benchmark (issue #3): whole `dpoint generate` processes, median of N runs, peak RSS.
Usage: bench/scripts/generators.py build/dpoint [runs] [dir]. Prints JSON (bench/results/ keeps it)."""
import json
import os
import platform
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from timing import median_of, remover  # noqa: E402

exe = os.path.abspath(sys.argv[1])
runs = int(sys.argv[2]) if len(sys.argv) > 2 else 5
work = sys.argv[3] if len(sys.argv) > 3 else "/tmp/dpoint-bench-generators"
os.makedirs(work, exist_ok=True)

cases = [
    # name, arguments, output extension, target seconds, voxels (for voxels/s)
    ("mandelbulb res 200 seed", ["mandelbulb", "--resolution", "200", "--variant", "seed"], "csv", 2.0, 200**3),
    ("mandelbulb res 200 fast", ["mandelbulb", "--resolution", "200", "--variant", "fast"], "csv", 0.3, 200**3),
    ("mandelbulb res 1024 fast", ["mandelbulb", "--resolution", "1024", "--variant", "fast"], "ply", 60.0, 1024**3),
    ("julia res 500", ["julia", "--resolution", "500"], "csv", None, 500**3),
    ("sierpinski level 11 unwelded", ["sierpinski", "--level", "11", "--unwelded"], "csv", 10.0, None),
    ("menger exact level 5", ["menger", "--level", "5"], "ply", 5.0, None),
    ("mandelbrot2d 1024^2 width 1e-6", ["mandelbrot2d"], "csv", None, None),
    ("mandelbrot2d 1024^2 width 1e-12", ["mandelbrot2d", "--width", "1e-12"], "csv", None, None),
]
results = {"machine": f"{platform.node()} ({os.cpu_count()} cores)", "runs": runs, "cases": []}
for name, args, ext, target, voxels in cases:
    out = os.path.join(work, "out." + ext)
    row = {"name": name, "command": "dpoint generate " + " ".join(args) + " -o out." + ext}
    for threads in ("1", "2") if voxels and "1024" not in name else ("2",):
        s, rss, _ = median_of([exe, "generate", *args, "--threads", threads, "--quiet", "-o", out], runs, remover(out))
        row[f"s_{threads}t"] = round(s, 3)
        row[f"peak_rss_MB_{threads}t"] = round(rss / 1e6, 1)
        if voxels:
            row[f"voxels_per_s_{threads}t"] = round(voxels / s / 1e6, 2)
    row["bytes"] = os.path.getsize(out)
    if target:
        row["target_s"] = target
        row["meets_target"] = row["s_2t"] <= target
    if "s_1t" in row:
        row["scaling_1_to_2"] = round(row["s_1t"] / row["s_2t"], 2)
    results["cases"].append(row)
    print(json.dumps(row), flush=True)
print(json.dumps(results, indent=1))
