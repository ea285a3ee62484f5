#!/usr/bin/env bash
# A/B of two laz_speed builds on 1 and 2 threads (issue #35: 2 cores ≥ 1.8× one core's speed).
# The threads are pinned with taskset to two CPUs of different physical cores (on a machine with
# hyperthreads, two siblings would share one core and measure something else); the builds and the
# thread counts alternate ROUNDS times, each cell the median of the rounds' medians of REPEATS
# decodes, the file in memory.
#   bench/scripts/laz_scaling_ab.sh BASE_LAZ_SPEED NEW_LAZ_SPEED FILE.laz...   (ROUNDS=5 REPEATS=3)
set -euo pipefail
base=$1 new=$2
shift 2
rounds=${ROUNDS:-5}
repeats=${REPEATS:-3}
# Two CPUs on distinct (package, core) pairs.
declare -A seen=()
cpus=()
for c in /sys/devices/system/cpu/cpu[0-9]*; do
  id="$(cat "$c/topology/physical_package_id" 2>/dev/null)-$(cat "$c/topology/core_id" 2>/dev/null)"
  [[ -n ${seen[$id]:-} ]] && continue
  seen[$id]=1
  cpus+=("${c##*cpu}")
  ((${#cpus[@]} == 2)) && break
done
echo "$(nproc) CPUs ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')); pinned to CPUs ${cpus[*]}"
median() { tr ' ' '\n' | grep . | sort -g | awk '{v[NR]=$1} END {print v[int((NR+1)/2)]}'; }
for laz in "$@"; do
  declare -A ms=()
  for ((r = 0; r < rounds; r++)); do
    for build in base new; do
      bin=$base
      [[ $build == new ]] && bin=$new
      ms[$build-1]+="$(taskset -c "${cpus[0]}" "$bin" "$laz" --threads 1 --repeats "$repeats" | sed -n 's/.*median_ms=\([0-9.]*\).*/\1/p') "
      ms[$build-2]+="$(taskset -c "${cpus[0]},${cpus[1]}" "$bin" "$laz" --threads 2 --repeats "$repeats" | sed -n 's/.*median_ms=\([0-9.]*\).*/\1/p') "
    done
  done
  for build in base new; do
    one=$(echo ${ms[$build-1]} | median) two=$(echo ${ms[$build-2]} | median)
    echo "$(basename "$laz") build=$build threads1_ms=$one threads2_ms=$two scaling=$(awk -v a="$one" -v b="$two" 'BEGIN {printf "%.2f", a / b}')"
  done
  unset ms
done
