#!/usr/bin/env bash
# The default render at three picture sizes on the GPU machine (device tool; carry .gl and .gpu as
# gpu_bench.sh says): the res-420 Mandelbulb and the 16.7M-point `sierpinski --level 11
# --unwelded` at 1024x768, 1920x1080 and 3840x2160, ROUNDS (5) rounds, each one fresh process: the
# whole process's wall time, the mode and point size auto chose, the median GPU splat and whole
# frame, and the phases --json reports. Rows in $OUT/render_sizes.tsv, medians in
# $OUT/render_sizes-median.tsv, the last 4K picture of each set as $OUT/SET-4k.png (SET-4k-BUILD.png).
# BUILDS ("current") names builds .gpu/dpoint-NAME to alternate in each round (current: .gpu/dpoint).
set -euo pipefail
source bench/scripts/gpu_env.sh
data=/tmp/dpoint-default
mkdir -p "$data"
[ -s "$data/mb420.ply" ] || .gpu/dpoint generate mandelbulb --resolution 420 -q -o "$data/mb420.ply"
[ -s "$data/s11u.ply" ] || .gpu/dpoint generate sierpinski --level 11 --unwelded -q -o "$data/s11u.ply"
rows=$out/render_sizes.tsv
printf 'round\tbuild\tset\tsize\twall_ms\tmode\tpoint_size\tgpu_ms\tframe_ms\tphases_ms\n' >"$rows"
for round in $(seq "${ROUNDS:-5}"); do
  for set in ${SETS:-mb420 s11u}; do
    for size in 1024x768 1920x1080 3840x2160; do
      for build in ${BUILDS:-current}; do
        bin=$(build_bin "$build") picture=$out/$set-4k-$build.png
        [ "${BUILDS:-current}" = current ] && picture=$out/$set-4k.png
        rm -f /tmp/k.json
        s=$(date +%s%N)
        "$bin" render "$data/$set.ply" --width "${size%x*}" --height "${size#*x}" -q --json /tmp/k.json -o /tmp/k.png
        e=$(date +%s%N)
        [ "$size" = 3840x2160 ] && cp /tmp/k.png "$picture"
        /usr/bin/python3 - "$round" "$build" "$set" "$size" "$(( (e - s) / 1000000 ))" <<'PY' >>"$rows"
import json, sys
j = json.load(open("/tmp/k.json"))
print("\t".join(sys.argv[1:6] + [j["mode"], str(j["point_size"]), f'{j["gpu_ms"]["median"]:.3f}',
      f'{j["frame_ms"]["median"]:.3f}', " ".join(f"{k}={v:.0f}" for k, v in j["phases_ms"].items())]))
PY
      done
    done
  done
done
/usr/bin/python3 - "$rows" <<'PY' | tee "$out/render_sizes-median.tsv"
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter="\t"))
print("build\tset\tsize\tmode\tpoint_size\twall_ms\tgpu_ms\tframe_ms\tphases_ms (median each)")
for key in dict.fromkeys((r["build"], r["set"], r["size"]) for r in rows):
    rs = [r for r in rows if (r["build"], r["set"], r["size"]) == key]
    med = lambda f: statistics.median(float(r[f]) for r in rs)
    phases = {}
    for r in rs:
        for kv in r["phases_ms"].split():
            k, v = kv.split("=")
            phases.setdefault(k, []).append(float(v))
    print("\t".join([*key, rs[0]["mode"], rs[0]["point_size"], f"{med('wall_ms'):.0f}", f"{med('gpu_ms'):.3f}",
                     f"{med('frame_ms'):.3f}", " ".join(f"{k}={statistics.median(v):.0f}" for k, v in phases.items())]))
PY
