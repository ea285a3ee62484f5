#!/usr/bin/env bash
# LAZ codec speed against laz-perf (issue #35): decode of each FILE.laz by dpoint's codec on 1 and
# 2 threads (build/laz_speed: the records from the file's bytes in memory) and by laz-perf (npm,
# LASzip's codec in WASM, Node, one thread: tests/external/node/lazperf_records.mjs --time), the
# three alternated ROUNDS times, each the median of REPEATS decodes; then each tool's median over
# the rounds. Encode: dpoint's compression of FILE.las (if it sits beside FILE.laz) on 1 and 2
# threads, and the sizes of dpoint's LAZ against FILE.laz's.
#
#   bench/scripts/laz_speed.sh OUT.md FILE.laz...      (ROUNDS=5 REPEATS=5 by default)
set -euo pipefail
top=$(cd "$(dirname "$0")/../.." && pwd)
out=$1
shift
rounds=${ROUNDS:-5}
repeats=${REPEATS:-5}
speed=$top/build/laz_speed
node_script=$top/tests/external/node/lazperf_records.mjs
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
median() { sort -g | awk '{v[NR]=$1} END {print v[int((NR+1)/2)]}'; }
field() { sed -n "s/.*$1=\([0-9.]*\).*/\1/p"; }
{
  echo "# LAZ decode and encode, dpoint against laz-perf"
  echo
  echo "$(date -u +%Y-%m-%d), $(nproc) cores ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')),"
  echo "commit $(git -C "$top" rev-parse --short HEAD), laz-perf $(node -p "require('$top/.tools/node_modules/laz-perf/package.json').version")."
  echo "Command: \`bench/scripts/laz_speed.sh $out $*\` (ROUNDS=$rounds REPEATS=$repeats): each cell the median over"
  echo "$rounds alternated rounds of the median of $repeats decodes, the file in memory, records out."
  echo
  echo "| file | points | laz-perf 1 thread (ms) | dpoint 1 thread (ms) | dpoint 2 threads (ms) | dpoint vs laz-perf | 2 threads vs 1 | dpoint encode 1 / 2 threads (ms) | size dpoint / LASzip |"
  echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
} > "$out"
for laz in "$@"; do
  name=$(basename "$laz")
  : > "$tmp/lp"; : > "$tmp/d1"; : > "$tmp/d2"
  for ((r = 0; r < rounds; r++)); do
    node "$node_script" "$laz" "$tmp/records.bin" --time "$repeats" | field median_ms >> "$tmp/lp"
    "$speed" "$laz" --threads 1 --repeats "$repeats" | field median_ms >> "$tmp/d1"
    "$speed" "$laz" --threads 2 --repeats "$repeats" | field median_ms >> "$tmp/d2"
  done
  points=$(node "$node_script" "$laz" "$tmp/records.bin" | sed -n 's/.*count=\([0-9]*\).*/\1/p')
  lp=$(median < "$tmp/lp"); d1=$(median < "$tmp/d1"); d2=$(median < "$tmp/d2")
  las=${laz%.laz}.las
  [ -f "$las" ] || las=${laz%.las.laz}.las
  enc="–"; size="–"
  if [ -f "$las" ]; then
    e1=$("$speed" "$las" --encode --threads 1 --repeats "$repeats" | field median_ms)
    e2=$("$speed" "$las" --encode --threads 2 --repeats "$repeats" | field median_ms)
    ours=$("$speed" "$las" --encode --repeats 1 | field bytes_out)
    enc="$e1 / $e2"
    size=$(awk -v a="$ours" -v b="$(stat -c %s "$laz")" 'BEGIN {printf "%.4f", a / b}')
  fi
  awk -v n="$name" -v p="$points" -v lp="$lp" -v d1="$d1" -v d2="$d2" -v enc="$enc" -v size="$size" \
    'BEGIN {printf "| %s | %s | %.1f | %.1f | %.1f | %.2f× | %.2f× | %s | %s |\n", n, p, lp, d1, d2, lp / d1, d1 / d2, enc, size}' >> "$out"
done
cat "$out"
