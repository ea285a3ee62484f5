#!/usr/bin/env bash
# `dpoint bench` on the GPU machine (device tool: NVIDIA H100/H200, Ubuntu 24.04, no package
# registry). Built here, carried there:
#   .gl/   libvulkan1 and vulkan-validationlayers .debs from Debian (unpacked by gpu_env.sh)
#   .gpu/  build/dpoint, build/tests/viewer_tests and the shared libraries dpoint links that the
#          machine lacks (libtinygltf, libmeshoptimizer, libdraco, libstb)
# Runs `dpoint devices`, then `dpoint bench --suite ${SUITE:-all}` (datasets made there, on all its
# cores). The report lands in $OUT/bench/ (report.md, results.json, the SVGs, montage.png); copy it
# to bench/results/DATE/h100/ (or h200/).
set -euo pipefail
source bench/scripts/gpu_env.sh
.gpu/dpoint devices | tee "$out/devices.txt"
mkdir -p "$out/bench"
# BASELINE (h100 or h200): compare with bench/results/baselines/$BASELINE.json where it exists
# (issue #38: rows more than 5% slower are marked); a run without one can become it.
baseline=()
[ -f "bench/results/baselines/${BASELINE:-h100}.json" ] && baseline=(--baseline "bench/results/baselines/${BASELINE:-h100}.json")
.gpu/dpoint bench --suite "${SUITE:-all}" --frames "${FRAMES:-20}" --warmup "${WARMUP:-300ms}" --out "$out/bench" \
  --cache /tmp/dpoint-bench-cache "${baseline[@]}"
