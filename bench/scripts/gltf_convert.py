#!/usr/bin/python3
"""glTF → CSV benchmark (issue #4): a 16.7M-vertex GLB (`generate sierpinski --level 11
--unwelded`) converted by dpoint, by glTF-Transform + tests/external/node/read_points.mjs, and by
`assimp export` to PLY; whole processes, median wall time of N runs, largest peak RSS.
Usage: bench/scripts/gltf_convert.py build/dpoint [runs] [dir]. Prints JSON (bench/results/ keeps it).
The npm modules come from .tools/node_modules (scripts/setup installs them)."""
import json
import os
import platform
import shutil
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from timing import median_of, remover  # noqa: E402

top = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
exe = os.path.abspath(sys.argv[1])
runs = int(sys.argv[2]) if len(sys.argv) > 2 else 3
work = sys.argv[3] if len(sys.argv) > 3 else "/tmp/dpoint-bench-gltf"
os.makedirs(work, exist_ok=True)
reader = os.path.join(top, "tests", "external", "node", "read_points.mjs")
modules = os.path.join(top, ".tools", "node_modules")
for needed in (os.path.join(modules, "@gltf-transform", "core"), shutil.which("assimp"), shutil.which("node")):
    if not needed or not os.path.exists(needed):
        sys.exit(f"missing {needed!r}: run scripts/setup")

glb = os.path.join(work, "sierpinski11.glb")
if not os.path.exists(glb):  # the input is the same every time; make it once
    median_of([exe, "generate", "sierpinski", "--level", "11", "--unwelded", "--quiet", "-o", glb], 1)

results = {"machine": f"{platform.node()} ({os.cpu_count()} cores)", "runs": runs,
           "input": "sierpinski --level 11 --unwelded (GLB)", "input_bytes": os.path.getsize(glb),
           # Other work on the machine skews whole-process timings: the 1-minute load average
           # before the first and after the last case is kept with the numbers.
           "load_average_before": round(os.getloadavg()[0], 2), "cases": []}
cases = [
    # name, argv, output written
    # dpoint adds r,g,b (the material's base colour) since the model has a material; the node
    # reader writes x,y,z only, so --no-colors is the like-for-like comparison.
    ("dpoint convert", [exe, "convert", glb, "-o", os.path.join(work, "dpoint.csv"), "--quiet"], "dpoint.csv"),
    ("dpoint convert --no-colors",
     [exe, "convert", glb, "-o", os.path.join(work, "dpoint.csv"), "--quiet", "--no-colors"], "dpoint.csv"),
    ("gltf-transform + node CSV writer", ["node", reader, glb, "-o", os.path.join(work, "node.csv")], "node.csv"),
    ("assimp export (PLY)", ["assimp", "export", glb, os.path.join(work, "assimp.ply")], "assimp.ply"),
]
for name, argv, output in cases:
    path = os.path.join(work, output)
    seconds, rss, _ = median_of(argv, runs, remover(path))
    size = os.path.getsize(path)
    results["cases"].append({"name": name, "command": " ".join(os.path.basename(a) for a in argv),
                             "s": round(seconds, 2), "peak_rss_MB": round(rss / 1e6, 1),
                             "peak_rss_per_input_byte": round(rss / results["input_bytes"], 2),
                             "output_bytes": size, "output_MB_per_s": round(size / seconds / 1e6, 1)})
    os.remove(path)  # several GB of text; keep the disk free for the next case
results["load_average_after"] = round(os.getloadavg()[0], 2)
print(json.dumps(results, indent=2))
