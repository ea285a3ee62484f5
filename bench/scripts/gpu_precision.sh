#!/usr/bin/env bash
# Precision (issue #9) on the GPU machine (device tool: NVIDIA H100/H200, Ubuntu 24.04). Carry
# .gl/ and .gpu/ as bench/scripts/gpu_bench.sh describes. Runs the viewer tests there (validation layer
# on: the Precision suite's pixel-centre views, every DESIGN §7 case within its bound, --mode auto
# with the GPU's speed order), prints the precision table, and times --mode auto's choice and the
# fp32/native/batch compute frames on 16.7M points. Results go to $OUT.
set -euo pipefail
source bench/scripts/gpu_env.sh
.gpu/viewer_tests > "$out/viewer_tests.txt" 2>&1 || true
grep -E "^\[  (PASSED|FAILED|SKIPPED) " "$out/viewer_tests.txt" | head -20
grep "^precision: " "$out/viewer_tests.txt" > "$out/precision_table.txt" || true
work=/tmp/dpoint-precision
mkdir -p "$work"
.gpu/dpoint generate mandelbulb --resolution 200 --offset 6378137,0,0 --quiet -o "$work/earth.ply"
.gpu/dpoint generate sierpinski --level 11 --unwelded --quiet -o "$work/s16.ply"
for backend in raster compute; do
  .gpu/dpoint render "$work/earth.ply" -o "$work/e.png" --backend $backend --error --validate --frames 20 \
    --width 1920 --height 1080 --json "$out/auto_earth_$backend.json" | tee -a "$out/auto.txt"
done
TIMEFORMAT="wall %R s"
for mode in auto fp32 native batch; do
  time .gpu/dpoint render "$work/s16.ply" -o "$work/s.png" --backend compute --mode $mode \
    --frames 50 --warmup 3 --width 1920 --height 1080 --json "$out/s16_$mode.json" | tee -a "$out/auto.txt"
done 2>&1 | tee -a "$out/auto.txt"
