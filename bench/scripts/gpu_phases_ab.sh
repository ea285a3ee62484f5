#!/usr/bin/env bash
# The phases of the render (`time to picture` in --json: read, spacing, camera, device, mode,
# render, png) and the whole process, builds alternated, on the GPU machine (device tool; carry
# .gl and .gpu: .gpu/dpoint-A the build before, .gpu/dpoint the current one): where a whole-process
# difference of gpu_modes_ab.sh comes from. SET (s11u) as gpu_modes_ab.sh makes it, MODES ("rte
# fp32"), ROUNDS (6), FRAMES (1). Rows in $OUT/phases.tsv, each build's medians per mode in
# $OUT/phases-median.tsv.
set -euo pipefail
source bench/scripts/gpu_env.sh
file=$(default_set "${SET:-s11u}")
rows=$out/phases.tsv
printf 'round\tmode\tbuild\tprocess_ms\tread\tspacing\tcamera\tdevice\tmode_ms\trender\tpng\tupload\n' >"$rows"
for round in $(seq "${ROUNDS:-6}"); do
  for mode in ${MODES:-rte fp32}; do
    for build in ${BUILDS:-A current}; do
      bin=$(build_bin "$build")
      s=$(date +%s%N)
      "$bin" render "$file" --mode "$mode" --frames "${FRAMES:-1}" -q --json /tmp/r.json -o /tmp/m.png >/dev/null 2>&1
      e=$(date +%s%N)
      /usr/bin/python3 - "$round" "$mode" "$build" "$(( (e - s) / 1000000 ))" <<'PY' | tee -a "$rows"
import json, sys
j = json.load(open("/tmp/r.json"))
p = j["phases_ms"]
print("\t".join(sys.argv[1:5] + [f"{p[k]:.1f}" for k in ("read", "spacing", "camera", "device", "mode", "render", "png")]
                + [f"{j['upload_ms']:.1f}"]))
PY
    done
  done
done
/usr/bin/python3 - "$rows" <<'PY' | tee "$out/phases-median.tsv"
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter="\t"))
keys = ["process_ms", "read", "spacing", "camera", "device", "mode_ms", "render", "png", "upload"]
print("mode\tbuild\t" + "\t".join(keys))
for m in dict.fromkeys(r["mode"] for r in rows):
    for b in dict.fromkeys(r["build"] for r in rows):
        sel = [r for r in rows if r["mode"] == m and r["build"] == b]
        print(m + "\t" + b + "\t" + "\t".join(f"{statistics.median(float(r[k]) for r in sel):.1f}" for k in keys))
PY
