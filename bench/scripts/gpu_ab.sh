#!/usr/bin/env bash
# An A/B of the compute frame on the GPU machine (device tool; carry .gl and .gpu as gpu_bench.sh
# says, each build to compare as .gpu/dpoint-LABEL, the current one as .gpu/dpoint): the Morton
# 16.7M sets made there once, then per round, dataset and mode, each build one fresh `dpoint render`
# (compute backend, 1920x1080, 1-px points, no shading, FRAMES (50) timed frames after WARMUP (5)),
# the builds alternated so a change of clocks hits all. A build without a mode (adaptive before
# #25) gets an empty cell. Rows in $OUT/ab.tsv, the medians over the rounds in $OUT/ab-summary.tsv.
# CAMERA: render options that fix the view (builds may fit it differently), e.g. "--eye 0,0,3.5 --target 0,0,0".
# RENDER: the render options instead of the 1-px ones above; RENDER="" FRAMES=20 times the default
# render (round points of at least 3 px, EDL, 1024x768, the auto warm-up), as with SETS="mb420 s11":
# the res-420 Mandelbulb (1.55M points) and 16.8M Sierpinski points, both in input order.
#   BUILDS="34402e9 3d7d229 current" SETS="sierpinski mandelbulb" MODES="batch adaptive fp32 native" ROUNDS=3
set -euo pipefail
source bench/scripts/gpu_env.sh
data=/tmp/dpoint-ab
mkdir -p "$data"
rows=$out/ab.tsv
printf 'round\tdataset\tmode\tbuild\tpoints\tgpu_ms_median\tpoint_size\n' >"$rows"
for set in ${SETS:-sierpinski mandelbulb}; do
  case $set in
    sierpinski) args=(sierpinski --level 11 --unwelded --order morton) ;;
    mandelbulb) args=(mandelbulb --resolution 1024 --variant fast --order morton) ;;
    mb420) args=(mandelbulb --resolution 420) ;;
    s11) args=(sierpinski --level 11 --unwelded --order input) ;;
    *) echo "unknown set $set" >&2; exit 1 ;;
  esac
  [ -s "$data/$set.ply" ] || .gpu/dpoint generate "${args[@]}" -q -o "$data/$set.ply"
done
render=${RENDER---backend compute --width 1920 --height 1080 --point-size 1 --shade none --warmup ${WARMUP:-5}}
for round in $(seq "${ROUNDS:-3}"); do
  for set in ${SETS:-sierpinski mandelbulb}; do
    for mode in ${MODES:-batch adaptive fp32 native}; do
      for build in ${BUILDS:-current}; do
        bin=$(build_bin "$build")
        rm -f /tmp/r.json
        # shellcheck disable=SC2086
        "$bin" render "$data/$set.ply" --mode "$mode" $render --frames "${FRAMES:-50}" -q --json /tmp/r.json \
          -o /tmp/r.png ${CAMERA:-} >/dev/null 2>&1 || true
        /usr/bin/python3 - "$round" "$set" "$mode" "$build" <<'PY' | tee -a "$rows"
import json, os, sys
r, s, m, b = sys.argv[1:5]
j = json.load(open("/tmp/r.json")) if os.path.exists("/tmp/r.json") else None
print("\t".join([r, s, m, b, str(j["points"]) if j else "", str(j["gpu_ms"]["median"]) if j else "",
                 str(j["point_size"]) if j else ""]))
PY
      done
    done
  done
done
/usr/bin/python3 - "$rows" <<'PY' | tee "$out/ab-summary.tsv"
import csv, statistics, sys
rows = [r for r in csv.DictReader(open(sys.argv[1]), delimiter="\t") if r["gpu_ms_median"]]
builds = list(dict.fromkeys(r["build"] for r in rows))
print("dataset\tmode\t" + "\t".join(builds))
for key in dict.fromkeys((r["dataset"], r["mode"]) for r in rows):
    cells = []
    for b in builds:
        v = [float(r["gpu_ms_median"]) for r in rows if (r["dataset"], r["mode"], r["build"]) == (*key, b)]
        cells.append(f"{statistics.median(v):.4f}" if v else "")
    print("\t".join([*key, *cells]))
PY
