#!/usr/bin/env bash
# Issue #24's GPU figures (device tool; carry .gl and .gpu as for bench/scripts/gpu_bench.sh):
# 1. the whole default render (`dpoint render FILE -o OUT.png`, wall time of the command, RUNS
#    runs, 5 by default) of the 1.55M-point Mandelbulb (res 420) and of a 16.7M-point one (res
#    1024, fast variant);
# 2. the compute backend at point sizes 1, 2, 4 and 8 on the 16.7M set at 1920x1080: GPU frame
#    (timestamps: the splat and resolve) and host frame (the submission, shading included) as the
#    median of 20 frames after 2 warm-up, with the default shading and with --shade none.
# One line per run in $OUT/first_picture.tsv.
set -euo pipefail
source bench/scripts/gpu_env.sh
d=${BIN:-.gpu/dpoint}
data=/tmp/dpoint-first
mkdir -p "$data"
[ -s "$data/mb420.ply" ] || "$d" generate mandelbulb --resolution 420 -q -o "$data/mb420.ply"
[ -s "$data/mb1024.ply" ] || "$d" generate mandelbulb --resolution 1024 --variant fast -q -o "$data/mb1024.ply"

results=$out/first_picture.tsv
printf 'set\twhat\tpoint_size\tshade\tpoints\tgpu_ms_median\tframe_ms_median\twall_s\n' >"$results"
value() { sed -n "s/.*\"$1\": \([^,}]*\).*/\1/p" /tmp/r.json | head -1 | tr -d '"'; }
median() { sed -n "s/.*\"$1\": {\"median\": \([^,]*\),.*/\1/p" /tmp/r.json | head -1; }
for set in mb420 mb1024; do
  "$d" render "$data/$set.ply" -o /tmp/r.png -q >/dev/null  # the file in the page cache, the shader cache filled
  for run in $(seq "${RUNS:-5}"); do
    start=$(date +%s.%N)
    "$d" render "$data/$set.ply" -o /tmp/r.png -q --json /tmp/r.json >/dev/null
    end=$(date +%s.%N)
    printf '%s\tdefault render\t%s\t%s\t%s\t%s\t%s\t%s\n' "$set" "$(value point_size)" "$(value shading)" "$(value points)" \
      "$(median gpu_ms)" "$(median frame_ms)" "$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.3f", b - a }')" | tee -a "$results"
  done
done
for size in 1 2 4 8; do
  for shade in auto none; do
    "$d" render "$data/mb1024.ply" -o /tmp/r.png -q --backend compute --width 1920 --height 1080 --point-size "$size" \
      --shade "$shade" --frames 20 --warmup 2 --json /tmp/r.json >/dev/null
    printf 'mb1024\tcompute 1920x1080\t%s\t%s\t%s\t%s\t%s\t\n' "$size" "$shade" "$(value points)" "$(median gpu_ms)" \
      "$(median frame_ms)" | tee -a "$results"
  done
done
