#!/usr/bin/env bash
# Issue #11's speed figures on the GPU machine (device tool; carry .gl and .gpu as for
# bench/scripts/gpu_bench.sh). Makes the datasets there (input and Morton order), then runs one fresh
# `dpoint render --backend compute` per dataset, order and mode at 1920x1080: FRAMES (50) timed
# frames after 5 warm-up, the GPU median from timestamps, e2e_ms (encode + upload + one frame +
# readback) and the whole command's wall time. Also `dpoint bench copy` (the copy bandwidth).
# One line per run in $OUT/speed.tsv. SETS picks the datasets (default: sierpinski mandelbulb
# random300m; also menger, random1g), STREAM passes --stream (auto: sets above 2^26 points are streamed from the file), EXTRA more
# render arguments (e.g. a camera that sees nothing: the frame's floor).
set -euo pipefail
source bench/scripts/gpu_env.sh
d=${BIN:-.gpu/dpoint}  # BIN: another build to compare, LABEL: its name in the table
data=/tmp/dpoint-speed
mkdir -p "$data"
[ -s "$out/copy.txt" ] || "$d" bench copy | tee "$out/copy.txt"

# gen NAME ARGS...: the dataset, made once per machine.
gen() {
  local file=$data/$1
  shift
  [ -s "$file" ] || "$d" generate "$@" -q -o "$file"
}

results=$out/speed.tsv
[ -s "$results" ] || printf 'dataset\torder\tmode\tpoints\tgpu_ms_median\tgpu_ms_p95\tupload_ms\te2e_ms\twall_s\tpeak_rss_mb\tgpu_ms_min\n' >"$results"
field() { sed -n "s/.*\"$1\": {\"median\": \([^,]*\), \"p95\": \([^,]*\),.*/\1\t\2/p" /tmp/r.json; }
minimum() { sed -n "s/.*\"$1\": {.*\"min\": \([^,}]*\).*/\1/p" /tmp/r.json; }
value() { sed -n "s/.*\"$1\": \([^,}]*\).*/\1/p" /tmp/r.json | head -1; }
render() {
  local name=$1 order=$2 file=$3 mode=$4 start end
  start=$(date +%s.%N)
  "$d" render "$file" --backend compute --mode "$mode" --width 1920 --height 1080 --frames "${FRAMES:-50}" \
    --warmup 5 -q --stream "${STREAM:-auto}" --json /tmp/r.json -o /tmp/r.png ${EXTRA:-}
  end=$(date +%s.%N)
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$name${LABEL:+ ($LABEL)}" "$order" "$mode" "$(value points)" "$(field gpu_ms)" \
    "$(value upload_ms)" "$(value e2e_ms)" "$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.2f", b - a }')" \
    "$(value peak_rss_mb)" "$(minimum gpu_ms)" | tee -a "$results"
}

for set in ${SETS:-sierpinski mandelbulb random300m}; do
  case $set in
    sierpinski) args=(sierpinski --level 11 --unwelded) ;;
    mandelbulb) args=(mandelbulb --resolution 1024 --variant fast) ;;
    random300m) args=(random2d --count 300000000) ;;
    random1g) args=(random2d --count 1000000000) ;;  # 24 GB of binary PLY
    menger) args=(menger --method voxel --level 4 --resolution 482) ;;  # 11.9M, the bench's largest Menger
    *) echo "unknown set $set" >&2; exit 1 ;;
  esac
  for order in ${ORDERS:-input morton}; do
    gen "$set-$order.ply" "${args[@]}" --order "$order"
    for mode in ${MODES:-fp32 native batch df64}; do
      render "$set" "$order" "$data/$set-$order.ply" "$mode"
    done
  done
done
cp /tmp/r.png "$out/last.png"
