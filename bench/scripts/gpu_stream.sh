#!/usr/bin/env bash
# Issue #38 item 2 on the GPU machine (device tool; carry .gl and .gpu as gpu_bench.sh says, each
# build to compare as .gpu/dpoint-LABEL, the current one as .gpu/dpoint): a 1e9-point random2d
# set in Morton order (24 GB binary PLY, made there once and read once before timing, so it sits
# in the page cache), then per round each build's whole default `dpoint render R1G.ply -o r.png`
# (wall time of the command; its --json phases and peak memory), builds alternated. With INFO=1
# also `dpoint info --stream on` of the file, per build. Rows in $OUT/stream.tsv, the medians over
# the rounds in $OUT/stream-summary.tsv.
#   BUILDS="a8d3c3e current" ROUNDS=3 COUNT=1000000000
set -euo pipefail
source bench/scripts/gpu_env.sh
data=${DATA:-/tmp/dpoint-stream}
mkdir -p "$data"
file=$data/R1G.ply
count=${COUNT:-1000000000}
if [ ! -s "$file" ]; then
  start=$(date +%s.%N)
  .gpu/dpoint generate random2d --count "$count" --order morton -q -o "$file"
  echo "generate: $(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }') s" | tee "$out/generate.txt"
fi
cat "$file" >/dev/null  # into the page cache
rows=$out/stream.tsv
printf 'round\tbuild\twhat\twall_s\tmode\tpoint_size\tread_again\tpeak_rss_mb\tphases\n' >"$rows"
for round in $(seq "${ROUNDS:-3}"); do
  for build in ${BUILDS:-current}; do
    bin=$(build_bin "$build")
    whats="render"
    [ "${INFO:-0}" = 1 ] && whats="render info"
    for what in $whats; do
      rm -f /tmp/r.json
      start=$(date +%s.%N)
      if [ "$what" = render ]; then
        "$bin" render "$file" -o /tmp/r.png -q --json /tmp/r.json >/dev/null 2>"$out/err.txt" || true
      else
        "$bin" info --stream on --json "$file" >/tmp/r.json 2>"$out/err.txt" || true
      fi
      wall=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.3f", b - a }')
      /usr/bin/python3 - "$round" "$build" "$what" "$wall" <<'PY' | tee -a "$rows"
import json, os, sys
r, b, w, wall = sys.argv[1:5]
try:
    j = json.load(open("/tmp/r.json"))
except Exception:
    j = {}
phases = j.get("phases_ms", {})
print("\t".join([r, b, w, wall, str(j.get("mode", "")), str(j.get("point_size", "")),
                 str(j.get("points_read_again", "")), str(j.get("peak_rss_mb", "")),
                 " ".join(f"{k}={v:.0f}" for k, v in phases.items())]))
PY
    done
  done
done
/usr/bin/python3 - "$rows" <<'PY' | tee "$out/stream-summary.tsv"
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter="\t"))
print("build\twhat\tmedian_wall_s\truns")
for key in dict.fromkeys((r["build"], r["what"]) for r in rows):
    v = [float(r["wall_s"]) for r in rows if (r["build"], r["what"]) == key]
    print(f"{key[0]}\t{key[1]}\t{statistics.median(v):.2f}\t" + " ".join(f"{x:.2f}" for x in v))
PY
