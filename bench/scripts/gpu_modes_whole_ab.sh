#!/usr/bin/env bash
# Whole `dpoint render` processes in every precision mode, two builds alternated, on the GPU
# machine (device tool; carry .gl and .gpu: .gpu/dpoint-BASE the build before, .gpu/dpoint the
# current one): for a change on the host side of a render (reading, encoding) that every mode
# pays. SET (s11u: `sierpinski --level 11 --unwelded`, 16.8M points) is made once with the current
# build. One line per run in $OUT/modes.tsv (round, mode, build, ms, PNG SHA-256 16); the medians
# in $OUT/modes-median.tsv.   BASE=B ROUNDS=3 MODES="fp32 split rte df64 native batch adaptive"
set -euo pipefail
source bench/scripts/gpu_env.sh
data=/tmp/dpoint-modes
mkdir -p "$data"
[ -s "$data/s11u.ply" ] || .gpu/dpoint generate sierpinski --level 11 --unwelded -q -o "$data/s11u.ply"
rows=$out/modes.tsv
printf 'round\tmode\tbuild\tms\tpng\n' >"$rows"
for round in $(seq "${ROUNDS:-3}"); do
  for mode in ${MODES:-fp32 split rte df64 native batch adaptive}; do
    for build in "${BASE:-B}" current; do
      bin=.gpu/dpoint-$build
      [ "$build" = current ] && bin=.gpu/dpoint
      s=$(date +%s%N); "$bin" render "$data/s11u.ply" --mode "$mode" -q -o "$data/r.png"; e=$(date +%s%N)
      printf '%s\t%s\t%s\t%s\t%s\n' "$round" "$mode" "$build" "$(( (e - s) / 1000000 ))" \
        "$(sha256sum <"$data/r.png" | cut -c1-16)" >>"$rows"
    done
  done
done
/usr/bin/python3 - "$rows" <<'PY' | tee "$out/modes-median.tsv"
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter="\t"))
builds = list(dict.fromkeys(r["build"] for r in rows))
print("mode\t" + "\t".join(f"{b}_ms" for b in builds) + "\tsame_png")
for m in dict.fromkeys(r["mode"] for r in rows):
    ms = [statistics.median(float(r["ms"]) for r in rows if r["mode"] == m and r["build"] == b) for b in builds]
    same = len({r["png"] for r in rows if r["mode"] == m}) == 1
    print(m + "\t" + "\t".join(f"{x:.0f}" for x in ms) + "\t" + ("yes" if same else "NO"))
PY
