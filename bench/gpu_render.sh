#!/usr/bin/env bash
# The renderer on the GPU machine (device tool: NVIDIA H100/H200, Ubuntu 24.04, no package
# registry). Built here, carried there:
#   .gl/   libvulkan1 and vulkan-validationlayers .debs from Debian (see bench/results/README.md)
#   .gpu/  build/dpoint, build/tests/viewer_tests and the shared libraries dpoint links that the
#          machine lacks (libtinygltf, libmeshoptimizer, libdraco, libstb)
# Runs the viewer tests there (validation layer on; covers native's R64G64B64 vertex-input path,
# which lavapipe lacks), `dpoint devices`, then bench/render.py. Results go to $OUT.
set -euo pipefail
source bench/gpu_env.sh
.gpu/dpoint devices | tee "$out/devices.txt"
.gpu/viewer_tests --gtest_brief=1 2>&1 | tee "$out/viewer_tests.txt" | tail -5
python3 bench/render.py .gpu/dpoint "$out/render-gpu" --frames "${FRAMES:-50}" --work /tmp/dpoint-bench 2>&1 | tail -40
