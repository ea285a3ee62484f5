#!/usr/bin/env bash
# The pair merge's A/B on the GPU machine (device tool; carry .gl and .gpu as gpu_bench.sh says):
# .gpu/dpoint-before (the build before it, with the subgroup merge) against .gpu/dpoint, alternating
# per dataset, through bench/scripts/gpu_adaptive.sh (compute backend, 1920x1080, Morton order,
# 50 frames after a 1 s warm-up). SETS as gpu_adaptive.sh's (random1g: 1e9 points streamed from a
# 24 GB PLY, made on the first run, and its 1% view); MODES as there. Rows in $OUT/adaptive.tsv.
set -euo pipefail
for set in ${SETS:-sierpinski mandelbulb}; do
  for build in before after; do
    bin=.gpu/dpoint
    [ "$build" = after ] || bin=.gpu/dpoint-before
    BIN=$bin LABEL=$build SETS=$set BACKENDS=compute MODES="${MODES:-adaptive batch fp32 native}" WARMUP=${WARMUP:-1s} \
      bash bench/scripts/gpu_adaptive.sh >/dev/null
  done
done
cut -f1,2,4,6,9,10 "${OUT:-/tmp/out}/adaptive.tsv"
