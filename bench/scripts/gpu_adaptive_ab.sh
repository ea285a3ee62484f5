#!/usr/bin/env bash
# Issue #25 before/after on one warm GPU machine: gpu_adaptive.sh's renders with this build
# (.gpu/dpoint) and the build before the issue (.gpu/dpoint-old, 98a768b, which has no adaptive
# mode), alternating, so both see the same card and clocks. ROUNDS (2) alternations; SETS as
# gpu_adaptive.sh. Results in $OUT/adaptive.tsv, the dataset column naming the build.
set -euo pipefail
for round in $(seq "${ROUNDS:-2}"); do
  BIN=.gpu/dpoint-old LABEL=old MODES="${OLD_MODES:-batch fp32}" bash bench/scripts/gpu_adaptive.sh
  BIN=.gpu/dpoint LABEL=new MODES="${NEW_MODES:-adaptive batch fp32}" bash bench/scripts/gpu_adaptive.sh
done
