#!/usr/bin/env bash
# `dpoint merge` alone, two builds alternated on one GPU machine (carry .gl and .gpu as for
# gpu_generate.sh): the two tiles of `generate mandelbulb --variant fast --resolution RES` are made
# once with the current build (tile 0 then tile 1, --device 0), then for each of ROUNDS rounds each
# build of BUILDS ("A current": .gpu/dpoint-A and .gpu/dpoint) merges them. One line per merge in
# $OUT/merge_ab.tsv (build, round, wall s, peak MB, SHA-256 (16) of the output); medians in
# $OUT/merge_ab-median.tsv. Each merge starts after the last one's output is removed, synced and SETTLE s (3).
set -euo pipefail
source bench/scripts/gpu_env.sh
res=${RES:-2048}
rounds=${ROUNDS:-5}
builds=${BUILDS:-current}
data=${DATA:-/tmp/dpoint-merge-ab}
mkdir -p "$data"
bin() { [ "$1" = current ] && echo .gpu/dpoint || echo ".gpu/dpoint-$1"; }
for i in 0 1; do
  .gpu/dpoint generate mandelbulb --variant fast --resolution "$res" -q --device 0 --tile "$i/2" -o "$data/part-$i.ply"
done
ls -l "$data" | tee "$out/parts.txt"
tsv=$out/merge_ab.tsv
printf 'build\tround\twall_s\tpeak_mb\tsha256_16\n' >"$tsv"
for ((r = 1; r <= rounds; ++r)); do
  for b in $builds; do
    rm -f "$data/merged.ply"; sync; sleep "${SETTLE:-3}"
    /usr/bin/time -f "%e %M" -o "$data/time.txt" "$(bin "$b")" merge -q "$data/part-0.ply" "$data/part-1.ply" \
      -o "$data/merged.ply"
    read -r wall peak <"$data/time.txt"
    printf '%s\t%s\t%s\t%.0f\t%s\n' "$b" "$r" "$wall" "$((peak / 1024))" "$(sha256sum <"$data/merged.ply" | cut -c1-16)" |
      tee -a "$tsv"
  done
done
{
  printf 'build\tmedian_s\truns\n'
  for b in $builds; do
    times=$(awk -F'\t' -v b="$b" '$1 == b { print $3 }' "$tsv" | sort -n)
    n=$(wc -l <<<"$times")
    printf '%s\t%s\t%s\n' "$b" "$(sed -n "$(((n + 1) / 2))p" <<<"$times")" "$n"
  done
} | tee "$out/merge_ab-median.tsv"
