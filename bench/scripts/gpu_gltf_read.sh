#!/usr/bin/env bash
# Reading a large GLB mesh on the GPU machine's cores (device tool; carry .gl and .gpu as
# gpu_bench.sh says, the build before as .gpu/dpoint-BASE, the current one as .gpu/dpoint): the
# res-RES fast Mandelbulb made once with --device 0 and converted to .glb by the current build
# (res 1024: 27M vertices, 52M triangles), then `dpoint bench io` of the GLB per build,
# alternated, ROUNDS rounds. Rows in $OUT/gltf_read.tsv.   BASE=a968b90 ROUNDS=3 RES=1024
set -euo pipefail
source bench/scripts/gpu_env.sh
data=/tmp/dpoint-gltf
mkdir -p "$data"
[ -s "$data/mb.ply" ] || .gpu/dpoint generate mandelbulb --variant fast --resolution "${RES:-1024}" --device 0 -q -o "$data/mb.ply"
[ -s "$data/mb.glb" ] || .gpu/dpoint convert "$data/mb.ply" -q -o "$data/mb.glb"
ls -l "$data/mb.glb" | tee "$out/size.txt"
cat "$data/mb.glb" >/dev/null
rows=$out/gltf_read.tsv
printf 'round\tbuild\tread_s\tprocess_s\tpeak_kb\n' >"$rows"
for round in $(seq "${ROUNDS:-3}"); do
  for build in "${BASE:-a968b90}" current; do
    bin=.gpu/dpoint-$build
    [ "$build" = current ] && bin=.gpu/dpoint
    /usr/bin/time -f "%e %M" -o /tmp/gltf_time.txt "$bin" bench io "$data/mb.glb" -q >/tmp/gltf_io.json 2>/dev/null || true
    /usr/bin/python3 - "$round" "$build" <<'PY' | tee -a "$rows"
import json, sys
r, b = sys.argv[1:3]
line = [l for l in open("/tmp/gltf_io.json") if l.startswith("{")][-1]
wall, peak = open("/tmp/gltf_time.txt").read().split()[-2:]
print("\t".join([r, b, str(json.loads(line)["read_s"]), wall, peak]))
PY
  done
done
