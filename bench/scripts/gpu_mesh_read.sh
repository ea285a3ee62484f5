#!/usr/bin/env bash
# Reading a large mesh PLY on the GPU machine's cores (device tool; carry .gl and .gpu as
# gpu_bench.sh says, the build before as .gpu/dpoint-BASE, the current one as .gpu/dpoint): the
# res-RES fast Mandelbulb made once with --device 0 (res 2048: 108M vertices, 207M triangles,
# 5.6 GB), then `dpoint bench io` of it per build, alternated, ROUNDS rounds. Rows in
# $OUT/mesh_read.tsv.   BASE=a968b90 ROUNDS=3 RES=2048
set -euo pipefail
source bench/scripts/gpu_env.sh
data=/tmp/dpoint-write
mkdir -p "$data"
file=$data/mb.ply
[ -s "$file" ] || .gpu/dpoint generate mandelbulb --variant fast --resolution "${RES:-2048}" --device 0 -q -o "$file"
cat "$file" >/dev/null
rows=$out/mesh_read.tsv
printf 'round\tbuild\tread_s\tprocess_s\tpeak_kb\n' >"$rows"
for round in $(seq "${ROUNDS:-3}"); do
  for build in "${BASE:-a968b90}" current; do
    bin=.gpu/dpoint-$build
    [ "$build" = current ] && bin=.gpu/dpoint
    /usr/bin/time -f "%e %M" -o /tmp/mesh_time.txt "$bin" bench io "$file" -q >/tmp/mesh_io.json 2>/dev/null || true
    /usr/bin/python3 - "$round" "$build" <<'PY' | tee -a "$rows"
import json, sys
r, b = sys.argv[1:3]
line = [l for l in open("/tmp/mesh_io.json") if l.startswith("{")][-1]
wall, peak = open("/tmp/mesh_time.txt").read().split()[-2:]
print("\t".join([r, b, str(json.loads(line)["read_s"]), wall, peak]))
PY
  done
done
