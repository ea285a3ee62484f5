#!/usr/bin/env bash
# Issue #38's targets on this machine (2 cores, lavapipe), two builds alternated:
#   generate  `generate mandelbulb --resolution 420` (the seed variant) as a whole process
#   mb420     the whole default `render mb420.ply -o r.png` (1.55M Mandelbulb points)
#   s11       the whole default `render s11u.ply -o r.png` (16.8M points: sierpinski --level 11
#             --unwelded, binary PLY)
# Usage: bench/scripts/local_targets.sh A_DPOINT B_DPOINT WORK [ROUNDS=3] > table.md
# The data are made once with B in WORK. Prints each run (stderr) and a Markdown table of medians.
set -euo pipefail
a=$1 b=$2 work=$3 rounds=${4:-3}
mkdir -p "$work"
[ -f "$work/mb420.ply" ] || "$b" generate mandelbulb --resolution 420 -q -o "$work/mb420.ply"
[ -f "$work/s11u.ply" ] || "$b" generate sierpinski --level 11 --unwelded -q -o "$work/s11u.ply"
declare -A times
run() {  # LABEL BUILD_NAME BINARY ARGS...
  local label=$1 name=$2 bin=$3; shift 3
  /usr/bin/time -f "%e" -o "$work/time.txt" "$bin" "$@" >/dev/null 2>&1
  local t; t=$(cat "$work/time.txt")
  times[$label,$name]+="$t "
  echo "$label $name $t" >&2
}
for ((r = 1; r <= rounds; ++r)); do
  for pair in "A $a" "B $b"; do
    set -- $pair
    name=$1 bin=$2
    run generate "$name" "$bin" generate mandelbulb --resolution 420 -q -o "$work/g.ply"
    run mb420 "$name" "$bin" render "$work/mb420.ply" -o "$work/r.png"
    run s11 "$name" "$bin" render "$work/s11u.ply" -o "$work/r.png"
  done
done
median() { tr ' ' '\n' <<<"$1" | grep . | sort -n | awk '{ a[NR] = $0 } END { print a[int((NR + 1) / 2)] }'; }
echo "| case | A ($a) s | B ($b) s | A/B |"
echo "| --- | --- | --- | --- |"
for label in generate mb420 s11; do
  ma=$(median "${times[$label,A]}") mb=$(median "${times[$label,B]}")
  printf '| %s | %s | %s | %.2f |\n' "$label" "$ma" "$mb" "$(awk -v x="$ma" -v y="$mb" 'BEGIN { print x / y }')"
done
