#!/usr/bin/env bash
# The splat of points larger than a pixel on the GPU machine (device tool; carry .gl and .gpu as
# gpu_bench.sh says, the build before as .gpu/dpoint-BASE, the current one as .gpu/dpoint): the
# default render (round points of at least 3 px, EDL) of the res-420 Mandelbulb (1.55M points) and
# of 16.8M Sierpinski points in input order, at 1024x768, in every mode (MODES), each build one fresh
# process per round, alternated: the point size and the median GPU frame of FRAMES (20) after the
# auto warm-up. Rows in $OUT/large_points.tsv, then each build's median over the rounds.
#   BASE=A ROUNDS=3 bash bench/scripts/gpu_large_points.sh
set -euo pipefail
source bench/scripts/gpu_env.sh
data=/tmp/dpoint-large
mkdir -p "$data"
[ -s "$data/mb420.ply" ] || .gpu/dpoint generate mandelbulb --resolution 420 -q -o "$data/mb420.ply"
[ -s "$data/s11.ply" ] || .gpu/dpoint generate sierpinski --level 11 --unwelded --order input -q -o "$data/s11.ply"
rows=$out/large_points.tsv
printf 'round\tdataset\tmode\tbuild\tpoint_size\tgpu_ms_median\n' >"$rows"
for round in $(seq "${ROUNDS:-3}"); do
  for set in mb420 s11; do
    for mode in ${MODES:-fp32 split rte df64 native batch adaptive}; do
      for build in "${BASE:-A}" current; do
        bin=.gpu/dpoint-$build
        [ "$build" = current ] && bin=.gpu/dpoint
        rm -f /tmp/r.json
        "$bin" render "$data/$set.ply" --mode "$mode" --frames "${FRAMES:-20}" -q --json /tmp/r.json -o /tmp/r.png >/dev/null 2>&1 || true
        /usr/bin/python3 - "$round" "$set" "$mode" "$build" <<'PY' | tee -a "$rows"
import json, os, sys
j = json.load(open("/tmp/r.json")) if os.path.exists("/tmp/r.json") else None
print("\t".join(sys.argv[1:5] + [str(j["point_size"]) if j else "", str(j["gpu_ms"]["median"]) if j else ""]))
PY
      done
    done
  done
done
/usr/bin/python3 - "$rows" <<'PY' | tee "$out/large_points-median.tsv"
import csv, statistics, sys
rows = [r for r in csv.DictReader(open(sys.argv[1]), delimiter="\t") if r["gpu_ms_median"]]
builds = sorted({r["build"] for r in rows}, key=lambda b: b == "current")
print("dataset\tmode\t" + "\t".join(f"{b}_ms" for b in builds) + "\tcurrent/base")
for key in sorted({(r["dataset"], r["mode"]) for r in rows}):
    med = [statistics.median(float(r["gpu_ms_median"]) for r in rows if (r["dataset"], r["mode"]) == key and r["build"] == b) for b in builds]
    print("\t".join(key) + "\t" + "\t".join(f"{m:.4f}" for m in med) + f"\t{med[-1] / med[0]:.3f}")
PY
