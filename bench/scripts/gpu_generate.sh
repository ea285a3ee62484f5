#!/usr/bin/env bash
# Issue #14 on the GPU machine (device tool; carry .gl and .gpu as for bench/scripts/gpu_bench.sh: .gpu/
# holds build/dpoint, build/tests/generators_tests and the libraries dpoint links that the machine
# lacks). Five files in $OUT (gpu.txt from gpu_env.sh):
#   devices.txt   dpoint devices
#   equal.txt     the device's counts against the CPU's on the NVIDIA driver, whose fp64 sqrt and
#                 division need the exact correction: generators_tests' GpuGenerate suite (validation
#                 layer on), then --grid-out and output files of each kind, CPU path against
#                 --device 0 --validate, at small odd and even resolutions
#   generate.tsv  one line per case and path: wall time, peak RSS, output SHA-256; CPU (--device
#                 none, all cores) against the GPU (--device 0) at --counts capped and full
#                 (PATHS), REPEATS (1) runs each, median
#   tiles.tsv     TILES (8; 0: none) tiles of mandelbulb res TILE_RES (2048) spread over the GPUs
#                 (tile I on --device I mod GPUS, GPUS at a time) + dpoint merge, then the single
#                 GPU run (SINGLE=0: not): wall, peak RSS and SHA-256 of the merged file, its counts
#                 (MERGE=0: no merge); then info and render of the parts, streamed (tiles-info.txt,
#                 tiles-render.txt, tiles.png)
# Env: BIN (default .gpu/dpoint), CASES (a subset of the case names below), PATHS, REPEATS, TILES (0: none),
# TILE_RES, GPUS (default: nvidia-smi's count), DATA (scratch, default /tmp/dpoint-generate).
set -euo pipefail
source bench/scripts/gpu_env.sh
d=${BIN:-.gpu/dpoint}
data=${DATA:-/tmp/dpoint-generate}
repeats=${REPEATS:-1}
gpus=${GPUS:-$(nvidia-smi -L | wc -l)}
mkdir -p "$data"
"$d" devices | tee "$out/devices.txt"

# --- equality on the real driver (EQUAL=0 skips it) ---
[ "${EQUAL:-1}" = 0 ] || {
  if [ -x .gpu/generators_tests ]; then
    .gpu/generators_tests --gtest_filter='GpuGenerate*' 2>&1 | tail -12
  else
    echo "no .gpu/generators_tests carried: the GpuGenerate suite did not run"
  fi
  for kind in "mandelbulb --variant fast --max-iter 100" "julia" "mandelbrot2d --width 1e-9 --max-iter 3000"; do
    for res in 63 64 257; do
      # shellcheck disable=SC2086
      "$d" generate $kind --resolution $res -q --device none --grid-out "$data/cpu.grid" -o "$data/cpu.ply"
      # shellcheck disable=SC2086
      "$d" generate $kind --resolution $res -q --device 0 --validate --grid-out "$data/gpu.grid" -o "$data/gpu.ply"
      grid=$(cmp -s "$data/cpu.grid" "$data/gpu.grid" && echo equal || echo DIFFER)
      file=$(cmp -s "$data/cpu.ply" "$data/gpu.ply" && echo equal || echo DIFFER)
      echo "$kind --resolution $res: grid $grid, file $file"
    done
  done
} 2>&1 | tee "$out/equal.txt"

# timed LABEL ARGS...: one dpoint run; prints "wall_s<TAB>peak_mb<TAB>sha256<TAB>gpu_ms<TAB>gpu_points_per_s"
# of the output $data/out.ply (the last two from the device's own line: the classification alone,
# GPU timestamps around its dispatches; "-" on the CPU path).
timed() {
  /usr/bin/time -f "%e %M" -o "$data/time.txt" "$d" "$@" -o "$data/out.ply" 2>"$data/stderr.txt"
  printf '%s\t%s\t%s\n' "$(awk '{ printf "%s\t%.0f", $1, $2 / 1024 }' "$data/time.txt")" \
    "$(sha256sum <"$data/out.ply" | cut -c1-16)" \
    "$(sed -n 's/.* in \([0-9.]*\) ms of GPU time (\([0-9.e+]*\) points\/s).*/\1\t\2/p' "$data/stderr.txt" | grep . || printf -- '-\t-')"
  rm -f "$data/out.ply"
}
median() { printf '%s\n' "$@" | sort -n | awk '{ a[NR] = $0 } END { print a[int((NR + 1) / 2)] }'; }

results=$out/generate.tsv
printf 'case\targs\tpath\twall_s\tpeak_mb\tsha256_16\tgpu_ms\tgpu_points_per_s\n' >"$results"
for name in ${CASES-bulb1024 bulb2048 julia1024 zoom4096}; do  # CASES= (empty): none
  case $name in
    bulb1024) args="mandelbulb --variant fast --resolution 1024" ;;
    bulb2048) args="mandelbulb --variant fast --resolution 2048" ;;
    julia1024) args="julia --resolution 1024" ;;
    julia2048) args="julia --resolution 2048" ;;
    zoom4096) args="mandelbrot2d --resolution 4096 --width 1e-12 --max-iter 5000" ;;
    *) echo "unknown case $name" >&2; exit 1 ;;
  esac
  # none: the CPU path; DEVICE:COUNTS: the GPU at that --counts (capped: the classification stops
  # past the level and the CPU finishes the points near the surface; full: every count on the GPU).
  for path in ${PATHS:-none 0:capped 0:full}; do
    device=${path%%:*} counts=${path#*:}
    extra=(--counts "$counts") label="gpu $counts"
    [ "$device" = none ] && extra=() label=cpu
    if [[ $args == mandelbrot2d* ]] && [ "$device" != none ]; then  # no --counts: one GPU run
      [ "$counts" = capped ] || continue
      extra=() label=gpu
    fi
    runs=()
    # shellcheck disable=SC2086
    for ((r = 0; r < repeats; ++r)); do runs+=("$(timed generate $args --device $device "${extra[@]}")"); done
    printf '%s\t%s\t%s\t%s\n' "$name" "$args" "$label" "$(median "${runs[@]}")" | tee -a "$results"
  done
done

# --- tiles over the GPUs of the host ---
[ "${TILES:-8}" = 0 ] && exit 0
tiles=${TILES:-8}
args="mandelbulb --variant fast --resolution ${TILE_RES:-2048}"
printf 'run\twall_s\tpeak_mb\tsha256_16\tgpu_ms\tgpu_points_per_s\n' >"$out/tiles.tsv"
rm -f "$data"/part-*.ply "$data"/peak-*.txt
start=$(date +%s.%N)
# shellcheck disable=SC2016,SC2086
seq 0 $((tiles - 1)) | xargs -P "$gpus" -I{} sh -c \
  '/usr/bin/time -f %M -o "$0/peak-$1.txt" "$2" generate '"$args"' -q --device $(($1 % $3)) --tile $1/$4 -o "$0/part-$1.ply"' \
  "$data" {} "$d" "$gpus" "$tiles"
tiles_end=$(date +%s.%N)
peak=$(cat "$data"/peak-*.txt | sort -n | tail -1)
printf '%s tiles on %s GPU(s)\t%.2f\t%.0f\t-\n' "$tiles" "$gpus" "$(awk -v a="$start" -v b="$tiles_end" 'BEGIN { print b - a }')" \
  "$((peak / 1024))" | tee -a "$out/tiles.tsv"
printf '# parts: %s bytes in all\n' "$(cat "$data"/part-*.ply | wc -c)" | tee -a "$out/tiles.tsv"
# MERGE=0: no merged file (at res 4096 the parts and the merged file do not both fit the 64 GB
# disk); the parts are described and drawn as the whole set instead, streamed.
if [ "${MERGE:-1}" != 0 ]; then
  /usr/bin/time -f "%e %M" -o "$data/time.txt" "$d" merge -q "$data"/part-*.ply -o "$data/merged.ply"
  end=$(date +%s.%N)
  printf 'merge\t%s\t%s\n' "$(awk '{ printf "%s\t%.0f", $1, $2 / 1024 }' "$data/time.txt")" \
    "$(sha256sum <"$data/merged.ply" | cut -c1-16)" | tee -a "$out/tiles.tsv"
  printf 'tiles + merge\t%.2f\t-\t-\n' "$(awk -v a="$start" -v b="$end" 'BEGIN { print b - a }')" | tee -a "$out/tiles.tsv"
  # The merged file's size and counts, from its header.
  printf '# merged: %s bytes; %s\n' "$(stat -c %s "$data/merged.ply")" \
    "$(head -c 1000 "$data/merged.ply" | grep -a '^element' | tr '\n' ' ')" | tee -a "$out/tiles.tsv"
fi
# The tiles as one set, streamed: dpoint info (counts, bounds) and a picture (compute, native).
timeout 300 /usr/bin/time -f "%e %M" -o "$data/time.txt" "$d" info --stream on "$data"/part-*.ply \
  >"$out/tiles-info.txt" || echo "info did not finish in 300 s" >"$data/time.txt"
printf 'info --stream on (the tiles)\t%s\n' "$(awk '{ printf "%s\t%.0f", $1, $2 / 1024 }' "$data/time.txt")" |
  tee -a "$out/tiles.tsv"
/usr/bin/time -f "%e %M" -o "$data/time.txt" "$d" render --stream on --backend compute --mode native --device 0 \
  --width 1920 --height 1080 "$data"/part-*.ply -o "$out/tiles.png" >"$out/tiles-render.txt"
printf 'render --stream on (the tiles)\t%s\n' "$(awk '{ printf "%s\t%.0f", $1, $2 / 1024 }' "$data/time.txt")" |
  tee -a "$out/tiles.tsv"
rm -f "$data"/part-*.ply "$data/merged.ply"
# The same grid in one process on one GPU, for the wall time and the checksum (SINGLE=0 skips it).
if [ "${SINGLE:-1}" != 0 ]; then
  # shellcheck disable=SC2086
  printf 'single process, --device 0\t%s\n' "$(timed generate $args --device 0)" | tee -a "$out/tiles.tsv"
fi
