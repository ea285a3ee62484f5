#!/usr/bin/env bash
# Every mode of `render` on the GPU machine, two builds alternated (device tool; carry .gl and .gpu
# as gpu_bench.sh says, the build before as .gpu/dpoint-$BASE, the current one as .gpu/dpoint):
# the 16.7M-point `sierpinski --level 11 --unwelded` PLY at 1024x768, each mode one fresh process
# per round with FRAMES (10) frames: the median GPU frame and the whole process's wall time.
# Rows in $OUT/modes.tsv.   BASE=A ROUNDS=2 MODES="fp32 rte df64 native batch adaptive"
set -euo pipefail
source bench/scripts/gpu_env.sh
data=/tmp/dpoint-default
mkdir -p "$data"
[ -s "$data/s11u.ply" ] || .gpu/dpoint generate sierpinski --level 11 --unwelded -q -o "$data/s11u.ply"
rows=$out/modes.tsv
printf 'round\tmode\tbuild\tgpu_ms_median\tprocess_ms\n' >"$rows"
for round in $(seq "${ROUNDS:-2}"); do
  for mode in ${MODES:-fp32 rte df64 native batch adaptive}; do
    for build in "${BASE:-A}" current; do
      bin=.gpu/dpoint-$build
      [ "$build" = current ] && bin=.gpu/dpoint
      rm -f /tmp/r.json
      s=$(date +%s%N)
      "$bin" render "$data/s11u.ply" --mode "$mode" --frames "${FRAMES:-10}" -q --json /tmp/r.json -o /tmp/m.png >/dev/null 2>&1 || true
      e=$(date +%s%N)
      /usr/bin/python3 - "$round" "$mode" "$build" "$(( (e - s) / 1000000 ))" <<'PY' | tee -a "$rows"
import json, os, sys
r, m, b, ms = sys.argv[1:5]
j = json.load(open("/tmp/r.json")) if os.path.exists("/tmp/r.json") else None
print("\t".join([r, m, b, str(j["gpu_ms"]["median"]) if j else "", ms]))
PY
    done
  done
done
