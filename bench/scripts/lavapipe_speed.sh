#!/usr/bin/env bash
# Issue #11 on lavapipe (this machine's CPU): the 16.7M-point sets drawn at 1920x1080 in both
# backends and every mode in one run, so compute and raster compare as ratios of the same machine
# state. One fresh `dpoint render` per set, mode and backend: compute FRAMES (20) frames after 3
# warm-up, raster RFRAMES (5) after 1 (a raster frame takes about a second here); the GPU median
# from timestamps. Rows go to OUT (default bench/results/DATE/lavapipe/speed-DATE.tsv).
#   bench/scripts/lavapipe_speed.sh [BIN]      (BIN: default build/dpoint; SETS, MODES, ORDERS to narrow)
set -euo pipefail
bin=${1:-build/dpoint}
data=${DATA:-/tmp/dpoint-lavapipe}
out=${OUT:-bench/results/$(date +%F)/lavapipe/speed-$(date +%F).tsv}
mkdir -p "$data" "$(dirname "$out")"
# First the regression check (issue #38): the paper suite's 1M sets against the recorded lavapipe
# baseline; rows more than 5% slower are warned of and marked in its report.md.
"$bin" bench --suite paper --sizes 1M --frames 10 --baseline bench/results/baselines/lavapipe.json \
  --out "$(dirname "$out")/bench-vs-baseline" --cache "$data/bench-cache" -q
[ -s "$out" ] || printf 'dataset\torder\tmode\tbackend\tpoints\tgpu_ms_median\tgpu_ms_p95\tframes\n' >"$out"
value() { python3 -c "import json,sys; d=json.load(open('$data/r.json')); print(d['points'], d['gpu_ms']['median'], d['gpu_ms']['p95'], sep='\t')"; }
for set in ${SETS:-sierpinski mandelbulb}; do
  case $set in
    sierpinski) args=(sierpinski --level 11 --unwelded) ;;
    mandelbulb) args=(mandelbulb --resolution 1024 --variant fast) ;;
    *) echo "unknown set $set" >&2; exit 1 ;;
  esac
  for order in ${ORDERS:-input}; do
    file=$data/$set-$order.ply
    [ -s "$file" ] || "$bin" generate "${args[@]}" --order "$order" -q -o "$file"
    for mode in ${MODES:-fp32 native batch df64}; do
      for backend in compute raster; do
        frames=${FRAMES:-20} warmup=3
        [ "$backend" = raster ] && frames=${RFRAMES:-5} warmup=1
        "$bin" render "$file" --backend "$backend" --mode "$mode" --shade none --width 1920 --height 1080 \
          --frames "$frames" --warmup "$warmup" -q --json "$data/r.json" -o "$data/r.png" >/dev/null
        printf '%s\t%s\t%s\t%s\t%s\t%s\n' "$set" "$order" "$mode" "$backend" "$(value)" "$frames" | tee -a "$out"
      done
    done
  done
done
