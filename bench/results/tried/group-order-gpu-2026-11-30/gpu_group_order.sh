#!/usr/bin/env bash
# Measurement (issue #38): would the compute splat gain on a GPU from its 1024-point workgroups
# taken nearest first? Each set is rewritten by .gpu/tools/group_depth_order (group_depth_order.cpp
# here, built with g++ -O2 -std=c++20) as vertices only, in its order (o) and with its groups
# sorted nearest first for the default view (s); each rendered in MODES with FRAMES frames, ROUNDS
# rounds alternated. Run from the repository root: bash bench/results/tried/group-order-gpu-2026-11-30/gpu_group_order.sh.
# Rows in $OUT/group_order.tsv.
set -euo pipefail
source bench/scripts/gpu_env.sh
data=/tmp/dpoint-group-order
mkdir -p "$data"
[ -s "$data/s11u.ply" ] || .gpu/dpoint generate sierpinski --level 11 --unwelded -q -o "$data/s11u.ply"
[ -s "$data/s11m.ply" ] || .gpu/dpoint convert "$data/s11u.ply" --order morton -q -o "$data/s11m.ply"
[ -s "$data/mb420.ply" ] || .gpu/dpoint generate mandelbulb --resolution 420 -q -o "$data/mb420.ply"
for set in ${SETS:-s11u s11m mb420}; do
  [ -s "$data/$set-s.ply" ] || .gpu/tools/group_depth_order "$data/$set.ply" "$data/$set-o.ply" "$data/$set-s.ply"
done
rows=$out/group_order.tsv
printf 'round\tset\tmode\torder\tgpu_ms_median\tsplat_order\n' >"$rows"
for round in $(seq "${ROUNDS:-3}"); do
  for set in ${SETS:-s11u s11m mb420}; do
    for mode in ${MODES:-fp32 native batch}; do
      for order in o s; do
        rm -f /tmp/r.json
        .gpu/dpoint render "$data/$set-$order.ply" --mode "$mode" --frames "${FRAMES:-10}" -q --json /tmp/r.json -o /tmp/g.png >/dev/null 2>&1 || true
        /usr/bin/python3 - "$round" "$set" "$mode" "$order" <<'PY' | tee -a "$rows"
import json, os, sys
j = json.load(open("/tmp/r.json")) if os.path.exists("/tmp/r.json") else None
print("\t".join(sys.argv[1:5] + ([str(j["gpu_ms"]["median"]), str(j["splat_order"])] if j else ["", ""])))
PY
      done
    done
  done
done
