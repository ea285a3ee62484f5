#!/usr/bin/env bash
# Issue #38 item 5 (a merge that is not the bottleneck) and the writing side of item 4, on the
# device tool's two-GPU kind (carry .gl and .gpu as for gpu_generate.sh). For each of ROUNDS
# rounds, each build of BUILDS in turn ("A current": .gpu/dpoint-A and .gpu/dpoint):
#   single  generate mandelbulb --variant fast --resolution RES --device 0 (one process, one GPU)
#   tiles   the same as two tiles at once, tile i on --device i
#   merge   dpoint merge of that build's two parts
# then dd of a file of the merged file's size into the same folder (bs 1M, from /dev/zero).
# One line per run in $OUT/merge.tsv: build, round, step, wall s, peak MB, SHA-256 (16) of the
# output; the medians in $OUT/merge-median.tsv. EXTRA="julia --resolution 2048" adds a whole
# generate --device 0 of that case per build and round (step "extra"), with its own dd.
set -euo pipefail
source bench/scripts/gpu_env.sh
res=${RES:-2048}
rounds=${ROUNDS:-3}
builds=${BUILDS:-current}
data=${DATA:-/tmp/dpoint-merge}
mkdir -p "$data"
bin() { [ "$1" = current ] && echo .gpu/dpoint || echo ".gpu/dpoint-$1"; }
.gpu/dpoint devices | tee "$out/devices.txt"
args="mandelbulb --variant fast --resolution $res"
tsv=$out/merge.tsv
printf 'build\tround\tstep\twall_s\tpeak_mb\tsha256_16\n' >"$tsv"
# row BUILD ROUND STEP WALL PEAK_KB FILE
row() {
  printf '%s\t%s\t%s\t%s\t%.0f\t%s\n' "$1" "$2" "$3" "$4" "$(($5 / 1024))" \
    "$( [ -f "$6" ] && sha256sum <"$6" | cut -c1-16 || echo -)" | tee -a "$tsv"
}
timed() {  # FILE CMD...: runs CMD, sets wall and peak
  local file=$1; shift
  /usr/bin/time -f "%e %M" -o "$data/time.txt" "$@" >/dev/null 2>"$data/stderr.txt" || { cat "$data/stderr.txt"; exit 1; }
  read -r wall peak <"$data/time.txt"
}
dd_row() {  # ROUND LABEL BYTES
  sync; sleep 1
  local mb=$((($3 + 1048575) / 1048576))
  /usr/bin/time -f "%e %M" -o "$data/time.txt" dd if=/dev/zero of="$data/dd.bin" bs=1M count="$mb" 2>/dev/null
  read -r wall peak <"$data/time.txt"
  printf 'dd\t%s\t%s\t%s\t-\t%s MiB\n' "$1" "$2" "$wall" "$mb" | tee -a "$tsv"
  rm -f "$data/dd.bin"
}
for ((r = 1; r <= rounds; ++r)); do
  for b in $builds; do
    d=$(bin "$b")
    rm -f "$data"/*.ply; sync; sleep 1
    # shellcheck disable=SC2086
    timed "$data/single.ply" "$d" generate $args -q --device 0 -o "$data/single.ply"
    row "$b" "$r" single "$wall" "$peak" "$data/single.ply"
    single_bytes=$(stat -c %s "$data/single.ply")
    rm -f "$data/single.ply"; sync; sleep 1
    start=$(date +%s.%N)
    # shellcheck disable=SC2086
    for i in 0 1; do
      /usr/bin/time -f "%M" -o "$data/peak-$i.txt" "$d" generate $args -q --device $i --tile $i/2 -o "$data/part-$i.ply" &
    done
    wait
    wall=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.2f", b - a }')
    row "$b" "$r" tiles "$wall" "$(cat "$data"/peak-*.txt | sort -n | tail -1)" /nonexistent
    timed "$data/merged.ply" "$d" merge -q "$data/part-0.ply" "$data/part-1.ply" -o "$data/merged.ply"
    row "$b" "$r" merge "$wall" "$peak" "$data/merged.ply"
    if [ -n "${EXTRA:-}" ]; then
      rm -f "$data"/*.ply; sync; sleep 1
      # shellcheck disable=SC2086
      timed "$data/extra.ply" "$d" generate $EXTRA -q --device 0 -o "$data/extra.ply"
      row "$b" "$r" extra "$wall" "$peak" "$data/extra.ply"
      extra_bytes=$(stat -c %s "$data/extra.ply")
    fi
  done
  rm -f "$data"/*.ply
  dd_row "$r" "$res mandelbulb" "$single_bytes"
  [ -z "${EXTRA:-}" ] || dd_row "$r" "$EXTRA" "$extra_bytes"
done
# Medians per build and step (and of dd); mawk has no asort, so each key's times go through sort.
{
  printf 'build\tstep\tmedian_s\truns\n'
  tail -n +2 "$tsv" | cut -f1,3 | sort -u | while IFS=$'\t' read -r b step; do
    times=$(awk -F'\t' -v b="$b" -v s="$step" '$1 == b && $3 == s { print $4 }' "$tsv" | sort -n)
    n=$(wc -l <<<"$times")
    printf '%s\t%s\t%s\t%s\n' "$b" "$step" "$(sed -n "$(((n + 1) / 2))p" <<<"$times")" "$n"
  done
} | tee "$out/merge-median.tsv"
