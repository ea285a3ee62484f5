#!/usr/bin/env bash
# Every mode of `render` on the GPU machine, builds alternated (device tool; carry .gl and .gpu as
# gpu_bench.sh says, the build before as .gpu/dpoint-$BASE, the current one as .gpu/dpoint; BUILDS,
# "BASE current", names more builds .gpu/dpoint-NAME): the 16.7M-point `sierpinski --level 11
# --unwelded` PLY at 1024x768, each mode one fresh process per round with FRAMES (10) frames: the
# median GPU frame, the whole process's wall time and the picture's SHA-256 (16). Rows in
# $OUT/modes.tsv; each build's median wall time and GPU frame per mode, and whether the pictures
# agree, in $OUT/modes-median.tsv. FRAMES=1 times what a host-side change (reading, encoding) costs
# every mode. SET=mb420 draws the res-420 Mandelbulb (its default 3-px points) instead.
#   BASE=A ROUNDS=2 MODES="fp32 split rte df64 native batch adaptive"
set -euo pipefail
source bench/scripts/gpu_env.sh
file=$(default_set "${SET:-s11u}")
rows=$out/modes.tsv
printf 'round\tmode\tbuild\tgpu_ms_median\tprocess_ms\tpng\n' >"$rows"
for round in $(seq "${ROUNDS:-2}"); do
  for mode in ${MODES:-fp32 split rte df64 native batch adaptive}; do
    for build in ${BUILDS:-${BASE:-A} current}; do
      bin=$(build_bin "$build")
      rm -f /tmp/r.json
      s=$(date +%s%N)
      "$bin" render "$file" --mode "$mode" --frames "${FRAMES:-10}" -q --json /tmp/r.json -o /tmp/m.png >/dev/null 2>&1 || true
      e=$(date +%s%N)
      png=$( [ -f /tmp/m.png ] && sha256sum </tmp/m.png | cut -c1-16 || echo -)
      rm -f /tmp/m.png
      /usr/bin/python3 - "$round" "$mode" "$build" "$(( (e - s) / 1000000 ))" "$png" <<'PY' | tee -a "$rows"
import json, os, sys
r, m, b, ms, png = sys.argv[1:6]
j = json.load(open("/tmp/r.json")) if os.path.exists("/tmp/r.json") else None
print("\t".join([r, m, b, str(j["gpu_ms"]["median"]) if j else "", ms, png]))
PY
    done
  done
done
/usr/bin/python3 - "$rows" <<'PY' | tee "$out/modes-median.tsv"
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter="\t"))
builds = list(dict.fromkeys(r["build"] for r in rows))
def med(m, b, key):
    v = [float(r[key]) for r in rows if r["mode"] == m and r["build"] == b and r[key]]
    return statistics.median(v) if v else float("nan")
print("mode\t" + "\t".join(f"{b}_ms" for b in builds) + "\t" + "\t".join(f"{b}_gpu_ms" for b in builds) + "\tsame_png")
for m in dict.fromkeys(r["mode"] for r in rows):
    same = len({r["png"] for r in rows if r["mode"] == m}) == 1
    print(m + "\t" + "\t".join(f"{med(m, b, 'process_ms'):.0f}" for b in builds) + "\t"
          + "\t".join(f"{med(m, b, 'gpu_ms_median'):.4f}" for b in builds) + "\t" + ("yes" if same else "NO"))
PY
