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
.gpu/dpoint bench --suite "${SUITE:-all}" --frames "${FRAMES:-20}" --warmup "${WARMUP:-300ms}" --out "$out/bench" \
  --cache /tmp/dpoint-bench-cache
