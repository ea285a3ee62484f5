#!/usr/bin/env bash
# Reading a large LAS on the GPU machine's cores (device tool; carry .gl and .gpu as gpu_bench.sh
# says, the build before as .gpu/dpoint-BASE, the current one as .gpu/dpoint): the 16.8M-point
# `sierpinski --level 11 --unwelded` set converted once to a format-2 LAS (12 record fields as
# dimensions), then `dpoint bench io` of it per build, builds alternated, ROUNDS rounds, and with
# WRITE=1 also `dpoint convert s11u.ply -o w.las` (the LAS writer: scale, offset, the merged-point
# count, the records) timed whole. Rows in $OUT/las_read.tsv, medians in $OUT/las_read-summary.tsv.
#   BASE=a968b90 ROUNDS=7 WRITE=1
set -euo pipefail
source bench/scripts/gpu_env.sh
data=/tmp/dpoint-default
mkdir -p "$data"
[ -s "$data/s11u.ply" ] || .gpu/dpoint generate sierpinski --level 11 --unwelded -q -o "$data/s11u.ply"
[ -s "$data/s11u.las" ] || .gpu/dpoint convert "$data/s11u.ply" -q -o "$data/s11u.las"
cat "$data/s11u.las" >/dev/null
rows=$out/las_read.tsv
printf 'round\tbuild\tread_s\tprocess_s\tpeak_kb\twrite_process_s\n' >"$rows"
for round in $(seq "${ROUNDS:-7}"); do
  for build in "${BASE:-a968b90}" current; do
    bin=.gpu/dpoint-$build
    [ "$build" = current ] && bin=.gpu/dpoint
    /usr/bin/time -f "%e %M" -o /tmp/las_time.txt "$bin" bench io "$data/s11u.las" -q >/tmp/las_io.json 2>/dev/null || true
    echo "" >/tmp/las_write.txt
    if [ "${WRITE:-0}" = 1 ]; then
      /usr/bin/time -f "%e" -o /tmp/las_write.txt "$bin" convert "$data/s11u.ply" -o "$data/w.las" -q >/dev/null 2>&1 || true
      rm -f "$data/w.las"
    fi
    /usr/bin/python3 - "$round" "$build" <<'PY' | tee -a "$rows"
import json, sys
r, b = sys.argv[1:3]
line = [l for l in open("/tmp/las_io.json") if l.startswith("{")][-1]
wall, peak = open("/tmp/las_time.txt").read().split()[-2:]
write = open("/tmp/las_write.txt").read().split()
print("\t".join([r, b, str(json.loads(line)["read_s"]), wall, peak, write[-1] if write else ""]))
PY
  done
done
/usr/bin/python3 - "$rows" <<'PY' | tee "$out/las_read-summary.tsv"
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter="\t"))
print("build\tmedian_read_s\tmedian_process_s\tmedian_write_process_s\treads")
for b in dict.fromkeys(r["build"] for r in rows):
    v = [float(r["read_s"]) for r in rows if r["build"] == b]
    w = [float(r["process_s"]) for r in rows if r["build"] == b]
    x = [float(r["write_process_s"]) for r in rows if r["build"] == b and r["write_process_s"]]
    print(f"{b}\t{statistics.median(v):.4f}\t{statistics.median(w):.3f}\t" + (f"{statistics.median(x):.3f}" if x else "") +
          "\t" + " ".join(f"{y:.3f}" for y in v))
PY
