#!/usr/bin/env bash
# Issue #27 on a host of several GPUs (device tool kind nvidia-h100-x2 or larger; carry .gl and .gpu
# as for bench/scripts/gpu_bench.sh, with GNU parallel's Debian package in .gpu/debs/, a Perl script
# that runs on the GPU machine's Ubuntu). For each KIND (default: the issue's two sets), one file made
# three ways, each timed as the wall time of its commands:
#   single: one process, `--device 0` (one GPU);
#   tiles:  G tiles `--tile I/G --device I`, one per GPU, at the same time (GNU parallel -j G), then
#           `dpoint merge` (the two timed apart and together);
#   cpu:    one process, `--device none` (CPU=1 to run it; minutes at res 2048).
# The merged file's SHA-256 against the single process's (and the CPU's). Also: `dpoint devices`,
# `--device auto`'s pick, and a device index past the last (exit 3). Lines in $OUT/tiles.tsv.
set -euo pipefail
source bench/scripts/gpu_env.sh
for f in .gpu/debs/*.deb; do dpkg -x "$f" /; done
d=${BIN:-$PWD/.gpu/dpoint}
data=/tmp/dpoint-tiles
mkdir -p "$data"
gpus=$(nvidia-smi -L | wc -l)
"$d" devices | tee "$out/devices.txt"
results=$out/tiles.tsv
[ -s "$results" ] || printf 'set\thow\tgpus\tseconds\tsha256\n' >"$results"
now() { date +%s.%N; }
since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.2f", b - a }'; }
row() { printf '%s\t%s\t%s\t%s\t%s\n' "$@" | tee -a "$results"; }

# --device auto picks one device; an index past the last is refused with exit 3 naming it.
"$d" generate julia --resolution 64 --device auto -o "$data/auto.ply" 2>&1 | tail -2 | tee "$out/auto.txt"
set +e
"$d" generate julia --resolution 64 --device "$gpus" -o "$data/bad.ply" >"$out/bad_device.txt" 2>&1
echo "exit $?" >>"$out/bad_device.txt"
set -e
cat "$out/bad_device.txt"

for set in ${SETS:-mandelbulb julia}; do
  case $set in
    mandelbulb) args=(mandelbulb --variant fast --resolution "${RES:-2048}") ;;
    julia) args=(julia --resolution "${RES:-2048}") ;;
    *) echo "unknown set $set" >&2; exit 1 ;;
  esac
  start=$(now)
  "$d" generate "${args[@]}" --device 0 -q -o "$data/$set-single.ply"
  row "$set" single 1 "$(since "$start")" "$(sha256sum <"$data/$set-single.ply" | cut -c1-64)"
  rm -f "$data"/$set-part-*.ply
  start=$(now)
  seq 0 $((gpus - 1)) | parallel -j "$gpus" "$d" generate "${args[@]}" --tile "{}/$gpus" --device "{}" -q \
    -o "$data/$set-part-{}.ply"
  tiles=$(since "$start")
  start=$(now)
  "$d" merge "$data"/$set-part-*.ply -o "$data/$set-merged.ply"
  merge=$(since "$start")
  row "$set" "tiles ($tiles s) + merge ($merge s)" "$gpus" "$(awk -v a="$tiles" -v b="$merge" 'BEGIN { printf "%.2f", a + b }')" \
    "$(sha256sum <"$data/$set-merged.ply" | cut -c1-64)"
  rm -f "$data"/$set-part-*.ply "$data/$set-merged.ply"
  if [ -n "${CPU:-}" ]; then
    start=$(now)
    "$d" generate "${args[@]}" --device none -q -o "$data/$set-cpu.ply"
    row "$set" cpu 0 "$(since "$start")" "$(sha256sum <"$data/$set-cpu.ply" | cut -c1-64)"
    rm -f "$data/$set-cpu.ply"
  fi
  rm -f "$data/$set-single.ply"
done
