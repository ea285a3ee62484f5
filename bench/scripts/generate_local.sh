#!/usr/bin/env bash
# Issue #14's figures on the development machine (no GPU: Mesa lavapipe is the device).
#   bench/scripts/generate_local.sh [BIN] [OUT_DIR]
# 1. ratio.tsv: the escape counts on lavapipe (--device cpu) against the CPU path (--device none)
#    in the same run, alternating, REPEATS (3) times each, with the files compared.
# 2. tiles.tsv: mandelbulb res 1024 (fast) as one process against 8 tiles run by GNU parallel two
#    at a time plus dpoint merge, wall time and peak RSS, and both files' SHA-256.
# The load average at the start goes in load.txt: other builds on the machine skew the times.
# PARTS=ratio or PARTS=tiles runs one of the two (default both).
set -euo pipefail
bin=${1:-build/dpoint}
out=${2:-bench/results/$(date +%F)/generate-lavapipe}
work=${WORK:-/tmp/dpoint-generate-bench}
repeats=${REPEATS:-3}
mkdir -p "$out" "$work"
uptime | tee -a "$out/load.txt"

# run LABEL ARGS...: one timed dpoint run; prints "wall_s peak_mb".
run() {
  /usr/bin/time -f "%e %M" -o "$work/time.txt" "$bin" "$@" -q
  awk '{ printf "%s\t%.0f", $1, $2 / 1024 }' "$work/time.txt"
}

if [ "${PARTS:-all}" != tiles ]; then
printf 'kind\targs\tcpu_s\tlavapipe_s\tratio\tcpu_peak_mb\tlavapipe_peak_mb\tfiles_equal\n' >"$out/ratio.tsv"
cases=(
  "mandelbulb --variant fast --resolution 512"
  "julia --resolution 512"
  "mandelbrot2d --resolution 1024 --width 1e-9 --max-iter 2000"
)
for args in "${cases[@]}"; do
  cpu_runs=() gpu_runs=()
  for ((r = 0; r < repeats; ++r)); do
    # shellcheck disable=SC2086
    cpu_runs+=("$(run generate $args --device none -o "$work/cpu.ply")")
    # shellcheck disable=SC2086
    gpu_runs+=("$(run generate $args --device cpu -o "$work/gpu.ply")")
  done
  median() { printf '%s\n' "$@" | sort -n | awk '{ a[NR] = $0 } END { print a[int((NR + 1) / 2)] }'; }
  cpu=$(median "${cpu_runs[@]}")
  gpu=$(median "${gpu_runs[@]}")
  equal=$(cmp -s "$work/cpu.ply" "$work/gpu.ply" && echo yes || echo no)
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "${args%% *}" "$args" "${cpu%%	*}" "${gpu%%	*}" \
    "$(awk -v a="${gpu%%	*}" -v b="${cpu%%	*}" 'BEGIN { printf "%.2f", a / b }')" "${cpu##*	}" "${gpu##*	}" "$equal" |
    tee -a "$out/ratio.tsv"
done

fi

# Tiles through GNU parallel against the single process.
[ "${PARTS:-all}" = ratio ] && exit 0
args="mandelbulb --resolution 1024 --variant fast"
printf 'run\twall_s\tpeak_mb\tsha256\n' >"$out/tiles.tsv"
rm -f "$work"/part-*.ply
# shellcheck disable=SC2086
single=$(run generate $args -o "$work/single.ply")
printf 'single process\t%s\t%s\n' "$single" "$(sha256sum <"$work/single.ply" | cut -d' ' -f1)" | tee -a "$out/tiles.tsv"
start=$(date +%s.%N)
# shellcheck disable=SC2086
/usr/bin/time -f "%M" -o "$work/parallel-peak.txt" parallel --will-cite -j2 \
  /usr/bin/time -f "%M" -o "$work/peak-{}.txt" "$bin" generate $args -q --tile {}/8 -o "$work/part-{}.ply" ::: 0 1 2 3 4 5 6 7
tiles_end=$(date +%s.%N)
merge=$(run merge "$work"/part-*.ply -o "$work/merged.ply")
end=$(date +%s.%N)
tile_peak=$(cat "$work"/peak-*.txt | sort -n | tail -1)
printf '8 tiles, parallel -j2\t%s\t%.0f\t-\n' "$(awk -v a="$start" -v b="$tiles_end" 'BEGIN { printf "%.2f", b - a }')" \
  "$((tile_peak / 1024))" | tee -a "$out/tiles.tsv"
printf 'merge\t%s\t%s\n' "$merge" "$(sha256sum <"$work/merged.ply" | cut -d' ' -f1)" | tee -a "$out/tiles.tsv"
printf 'tiles + merge\t%s\t-\t-\n' "$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.2f", b - a }')" | tee -a "$out/tiles.tsv"
cmp "$work/single.ply" "$work/merged.ply" && echo "merged file == single process file" | tee -a "$out/tiles.tsv"
