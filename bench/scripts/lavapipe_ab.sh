#!/usr/bin/env bash
# An A/B of the compute frame on lavapipe (issue #38): two builds alternated on this machine, so a
# change of the machine's state hits both. 16.7M Sierpinski points in input order (made once with
# the new build), 1920x1080, 1-px points, no shading; per round, per mode, each build one fresh
# `dpoint render --json` (FRAMES frames after WARMUP, the GPU median from timestamps). Rows go to
# OUT (default bench/results/DATE/lavapipe/ab-DATE.tsv); the last lines give each build's median
# over the rounds.
#   bench/scripts/lavapipe_ab.sh OLD_BIN NEW_BIN   (MODES, ROUNDS, FRAMES, BACKENDS to narrow;
#   POINT_SIZE, 1 by default, for the splat of larger points: round ones, as a 3D set's default;
#   FILE, another set than the Sierpinski one, e.g. a Mandelbulb in its marching-cubes order)
set -euo pipefail
old=$1 new=$2
data=${DATA:-/tmp/dpoint-lavapipe}
out=${OUT:-bench/results/$(date +%F)/lavapipe/ab-$(date +%F).tsv}
mkdir -p "$data" "$(dirname "$out")"
file=${FILE:-$data/sierpinski-input.ply}
[ -s "$file" ] || "$new" generate sierpinski --level 11 --unwelded --order input -q -o "$file"
printf 'round\tbuild\tmode\tbackend\tpoints\tgpu_ms_median\n' >"$out"
for round in $(seq "${ROUNDS:-3}"); do
  for mode in ${MODES:-fp32 batch native}; do
    for backend in ${BACKENDS:-compute}; do
      for build in old new; do
        bin=$old
        [ $build = new ] && bin=$new
        "$bin" render "$file" --backend "$backend" --mode "$mode" --shade none --point-size "${POINT_SIZE:-1}" --width 1920 \
          --height 1080 --frames "${FRAMES:-5}" --warmup "${WARMUP:-1}" -q --json "$data/r.json" -o "$data/r.png" >/dev/null
        python3 -c "import json; d=json.load(open('$data/r.json')); print('$round\t$build\t$mode\t$backend', d['points'], d['gpu_ms']['median'], sep='\t')" | tee -a "$out"
      done
    done
  done
done
python3 - "$out" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter='\t'))
for key in sorted({(r['mode'], r['backend']) for r in rows}):
    med = {b: statistics.median(float(r['gpu_ms_median']) for r in rows if (r['mode'], r['backend']) == key and r['build'] == b) for b in ('old', 'new')}
    print(f"{key[0]}\t{key[1]}\told {med['old']:.1f} ms\tnew {med['new']:.1f} ms\tnew/old {med['new'] / med['old']:.2f}")
PY
