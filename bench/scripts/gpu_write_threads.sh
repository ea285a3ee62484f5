#!/usr/bin/env bash
# How fast the PLY writer streams a large mesh against dd, by worker count (device tool; carry .gl
# and .gpu as gpu_bench.sh says): the res-2048 fast Mandelbulb made once with --device 0 (5.6 GB),
# then per round dd of its size into the same folder and `dpoint bench io` of it with --write at
# each of THREADS (the read is timed apart). Rows in $OUT/write_threads.tsv.
#   ROUNDS=2 THREADS="16 15 12 8" RES=2048
set -euo pipefail
source bench/scripts/gpu_env.sh
data=/tmp/dpoint-write
mkdir -p "$data"
file=$data/mb.ply
[ -s "$file" ] || .gpu/dpoint generate mandelbulb --variant fast --resolution "${RES:-2048}" --device 0 -q -o "$file"
size=$(stat -c %s "$file")
rows=$out/write_threads.tsv
printf 'round\twhat\tthreads\tread_s\twrite_s\n' >"$rows"
for round in $(seq "${ROUNDS:-2}"); do
  rm -f "$data/dd.bin"
  s=$(date +%s.%N)
  dd if=/dev/zero of="$data/dd.bin" bs=1M count=$(( (size + 1048575) / 1048576 )) status=none
  printf '%s\tdd\t1\t\t%s\n' "$round" "$(awk -v a="$s" -v b="$(date +%s.%N)" 'BEGIN { printf "%.3f", b - a }')" | tee -a "$rows"
  rm -f "$data/dd.bin"
  for t in ${THREADS:-16 15 12 8}; do
    rm -f "$data/x.ply"
    .gpu/dpoint bench io "$file" --write "$data/x.ply" --threads "$t" -q >/tmp/io.json
    /usr/bin/python3 - "$round" "$t" <<'PY' | tee -a "$rows"
import json, sys
j = json.loads([l for l in open("/tmp/io.json") if l.startswith("{")][-1])
print(f"{sys.argv[1]}\twrite\t{sys.argv[2]}\t{j['read_s']:.3f}\t{j['write_s']:.3f}")
PY
    rm -f "$data/x.ply"
  done
done
