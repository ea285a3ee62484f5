#!/usr/bin/env bash
# Issue #38 item 4's random2d target on the device tool's machine (carry .gl and .gpu as for gpu_merge.sh):
# `generate random2d --count COUNT (1e9) --order morton` as a whole process, for each of ROUNDS
# rounds each build of BUILDS in turn ("A current": .gpu/dpoint-A and .gpu/dpoint), on CORES cores
# (taskset; default all), then dd of a file of the output's size into the same folder. One line per
# run in $OUT/random2d.tsv: build, round, wall s, peak MB, SHA-256 (16) of the first 64 MiB (of the
# whole file with FULL_SHA=1), and the process's own phase line (generate, colours, order, write).
set -euo pipefail
source bench/scripts/gpu_env.sh  # dpoint links the Vulkan loader, even where it uses no device
count=${COUNT:-1000000000}
rounds=${ROUNDS:-3}
builds=${BUILDS:-current}
data=${DATA:-/tmp/dpoint-random2d}
cores=${CORES:-0-$(($(nproc) - 1))}
mkdir -p "$data"
bin() { [ "$1" = current ] && echo .gpu/dpoint || echo ".gpu/dpoint-$1"; }
tsv=$out/random2d.tsv
printf 'build\tround\twall_s\tpeak_mb\tsha256_16\tphases\n' >"$tsv"
for ((r = 1; r <= rounds; ++r)); do
  for b in $builds; do
    rm -f "$data"/*.ply; sync; sleep 1
    /usr/bin/time -f "%e %M" -o "$data/time.txt" taskset -c "$cores" "$(bin "$b")" generate random2d \
      --count "$count" --order morton -o "$data/r.ply" 2>"$data/stderr.txt" >/dev/null
    read -r wall peak <"$data/time.txt"
    bytes=$(stat -c %s "$data/r.ply")
    printf '%s\t%s\t%s\t%.0f\t%s\t%s\n' "$b" "$r" "$wall" "$((peak / 1024))" "$(if [ "${FULL_SHA:-0}" = 1 ]; then sha256sum <"$data/r.ply"; else head -c 67108864 "$data/r.ply" | sha256sum; fi | cut -c1-16)" \
      "$(grep -a '^time (s)' "$data/stderr.txt" | tr -d '\r' | tail -1)" | tee -a "$tsv"
  done
  rm -f "$data"/*.ply; sync; sleep 1
  mb=$(((bytes + 1048575) / 1048576))
  /usr/bin/time -f "%e" -o "$data/time.txt" dd if=/dev/zero of="$data/dd.bin" bs=1M count="$mb" 2>/dev/null
  printf 'dd\t%s\t%s\t-\t%s MiB\t-\n' "$r" "$(cat "$data/time.txt")" "$mb" | tee -a "$tsv"
  rm -f "$data/dd.bin"
done
