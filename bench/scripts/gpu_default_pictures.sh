#!/usr/bin/env bash
# Issue #36 item 5 on the GPU machine (device tool; carry .gl and .gpu as gpu_bench.sh says, the
# build before as .gpu/dpoint-BASE, the current one as .gpu/dpoint): the default render (every
# default: round points, EDL) of the res-200 and res-420 Mandelbulbs and the Menger sponge at
# 1024x768, each build one fresh process per round, alternated: the point size, the median GPU
# frame of FRAMES (20) after the auto warm-up, and the whole process's wall time for one picture.
# Rows in $OUT/default.tsv. BUILDS ("BASE current") names more builds .gpu/dpoint-NAME to alternate.
#   BASE=19318e9 ROUNDS=3 SETS="mb200 mb420 menger" (s11u: the 16.7M-point
# `sierpinski --level 11 --unwelded`, as bench/scripts/local_targets.sh draws on lavapipe)
set -euo pipefail
source bench/scripts/gpu_env.sh
data=/tmp/dpoint-default
mkdir -p "$data"
[ -s "$data/mb200.ply" ] || .gpu/dpoint generate mandelbulb --resolution 200 -q -o "$data/mb200.ply"
[ -s "$data/mb420.ply" ] || .gpu/dpoint generate mandelbulb --resolution 420 -q -o "$data/mb420.ply"
[ -s "$data/menger.ply" ] || .gpu/dpoint generate menger -q -o "$data/menger.ply"
case " ${SETS:-} " in *" s11u "*) [ -s "$data/s11u.ply" ] || .gpu/dpoint generate sierpinski --level 11 --unwelded -q -o "$data/s11u.ply" ;; esac
rows=$out/default.tsv
printf 'round\tdataset\tbuild\tpoint_size\tgpu_ms_median\tprocess_ms\n' >"$rows"
for round in $(seq "${ROUNDS:-3}"); do
  for set in ${SETS:-mb200 mb420 menger}; do
    for build in ${BUILDS:-${BASE:-19318e9} current}; do
      bin=$(build_bin "$build")
      rm -f /tmp/r.json
      "$bin" render "$data/$set.ply" --frames "${FRAMES:-20}" -q --json /tmp/r.json -o "$out/$set-$build.png" >/dev/null 2>&1 || true
      s=$(date +%s%N); "$bin" render "$data/$set.ply" -q -o /tmp/one.png >/dev/null 2>&1 || true; e=$(date +%s%N)
      /usr/bin/python3 - "$round" "$set" "$build" "$(( (e - s) / 1000000 ))" <<'PY' | tee -a "$rows"
import json, os, sys
r, s, b, ms = sys.argv[1:5]
j = json.load(open("/tmp/r.json")) if os.path.exists("/tmp/r.json") else None
print("\t".join([r, s, b, str(j["point_size"]) if j else "", str(j["gpu_ms"]["median"]) if j else "", ms]))
PY
    done
  done
done
