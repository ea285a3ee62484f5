#!/usr/bin/env bash
# dpoint's LAZ decode on 1, 2, 4, 8 and 16 threads (build/laz_speed), each thread count alternated
# ROUNDS times, the median of REPEATS decodes each, the file in memory (issue #35: the scaling with
# cores, measured on an idle machine; the GPU machine's 16 cores when this 2-core one is busy).
#   bench/scripts/laz_threads.sh LAZ_SPEED FILE.laz...     (ROUNDS=3 REPEATS=3)
set -euo pipefail
speed=$1
shift
rounds=${ROUNDS:-3}
repeats=${REPEATS:-3}
echo "$(nproc) cores ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'))"
for laz in "$@"; do
  declare -A ms=()
  for ((r = 0; r < rounds; r++)); do
    for t in 1 2 4 8 16; do
      ms[$t]+="$("$speed" "$laz" --threads $t --repeats "$repeats" | sed -n 's/.*median_ms=\([0-9.]*\).*/\1/p') "
    done
  done
  for t in 1 2 4 8 16; do
    median=$(echo ${ms[$t]} | tr ' ' '\n' | sort -g | awk '{v[NR]=$1} END {print v[int((NR+1)/2)]}')
    echo "$(basename "$laz") threads=$t median_ms=$median"
  done
  unset ms
done
