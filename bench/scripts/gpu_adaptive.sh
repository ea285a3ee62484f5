#!/usr/bin/env bash
# Issue #25's figures on the GPU machine (device tool; carry .gl and .gpu as bench/scripts/gpu_bench.sh
# describes). Makes the Morton-ordered datasets there, then one fresh `dpoint render` per dataset,
# backend and mode at 1920x1080: FRAMES (50) timed frames after WARMUP (5) untimed ones, the GPU
# median from timestamps. Adaptive's plan (bytes loaded per point, tier shares, culled batches) and
# every mode's predicted bound come from the render's JSON. The SM and memory clocks are sampled
# every 200 ms while it runs ($OUT/clocks.csv). SETS: sierpinski mandelbulb (16.7M), random1g (1e9,
# streamed from a 24 GB PLY; also its 1% view); MODES, BACKENDS as below. One line per run in
# $OUT/adaptive.tsv. BIN: another build, LABEL: its name in the table.
set -euo pipefail
source bench/scripts/gpu_env.sh
d=${BIN:-.gpu/dpoint}
data=/tmp/dpoint-speed
mkdir -p "$data"
[ -s "$out/copy.txt" ] || "$d" bench copy | tee "$out/copy.txt"
nvidia-smi --query-gpu=timestamp,clocks.sm,clocks.mem,power.draw,temperature.gpu --format=csv,noheader -lms 200 \
  >"$out/clocks.csv" &
clocks=$!
trap 'kill $clocks 2>/dev/null || true' EXIT

results=$out/adaptive.tsv
[ -s "$results" ] || printf 'dataset\tview\tbackend\tmode\tpoints\tgpu_ms_median\tgpu_ms_p95\tgpu_ms_min\tloaded_b_per_pt\ttier_share\tculled\tbatches\tbound_px\tmode_ms\tupload_ms\twall_s\n' >"$results"
row() {  # name view backend mode wall: fields of /tmp/r.json
  /usr/bin/python3 - "$@" <<'PY' | tee -a "$results"
import json, sys
name, view, backend, mode, wall = sys.argv[1:6]
label = sys.argv[6] if len(sys.argv) > 6 else ""
j = json.load(open("/tmp/r.json"))
g = j["gpu_ms"] or {}
p = j.get("batch_plan") or {}
share = ",".join(f"{s:.3f}" for s in p.get("tier_share", []))
print("\t".join(str(v) for v in [name + (f" ({label})" if label else ""), view, backend, mode, j["points"], g.get("median"), g.get("p95"), g.get("min"),
      p.get("loaded_bytes_per_point", j["bytes_per_point"] - 4), share, p.get("culled", ""), p.get("batches", ""),
      j["predicted_bound_px"], round(j["phases_ms"].get("mode", 0), 1), round(j["upload_ms"], 1), wall]))
PY
}
render() {  # name view file backend mode [render args...]
  local name=$1 view=$2 file=$3 backend=$4 mode=$5 start end
  shift 5
  start=$(date +%s.%N)
  "$d" render "$file" --backend "$backend" --mode "$mode" --width 1920 --height 1080 --frames "${FRAMES:-50}" \
    --warmup "${WARMUP:-5}" -q --stream "${STREAM:-auto}" --shade none --json /tmp/r.json -o /tmp/r.png "$@"
  end=$(date +%s.%N)
  row "$name" "$view" "$backend" "$mode" "$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.2f", b - a }')" "${LABEL:-}"
  cp /tmp/r.json "$out/last.json"
}

for set in ${SETS:-sierpinski mandelbulb}; do
  case $set in
    sierpinski) args=(sierpinski --level 11 --unwelded) ;;
    mandelbulb) args=(mandelbulb --resolution 1024 --variant fast) ;;
    random1g) args=(random2d --count 1000000000) ;;
    *) echo "unknown set $set" >&2; exit 1 ;;
  esac
  file=$data/$set-morton.ply
  [ -s "$file" ] || "$d" generate "${args[@]}" --order morton -q -o "$file"
  for backend in ${BACKENDS:-compute raster}; do
    for mode in ${MODES:-adaptive batch fp32 native rte df64}; do
      render "$set" default "$file" "$backend" "$mode"
      # The 1% view of the 2D set: 0.2667 x 0.15 of its 2 x 2 square.
      [ "$set" != random1g ] || render "$set" one-percent "$file" "$backend" "$mode" --view-center 0.3,0.2 --view-width 0.2667
    done
  done
done
cp /tmp/r.png "$out/last.png"
