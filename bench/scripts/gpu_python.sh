#!/usr/bin/env bash
# Issue #26 on the GPU machine: the Python module in one long-lived process
# (bench/scripts/python_session.py: a Renderer over RENDERS renders of a 16.7M-point set, fresh
# devices, then renders after a probed draw), beside fresh `dpoint render` processes of the same set.
# Carry .gl and .gpu as bench/scripts/gpu_bench.sh says, and in .gpu also python/dpoint (the built
# package: cp -r build/python/dpoint .gpu/python/) and py311.tar.xz: Debian 12's python3.11 with its
# standard library and NumPy (the module's ABI; Ubuntu 24.04 has 3.12): /usr/bin/python3.11,
# /usr/lib/python3.11 less its tests, /usr/lib/python3/dist-packages/numpy and the BLAS, LAPACK and
# gfortran libraries NumPy links, as bin/, lib/python3.11/, site/ and lib/. SM and memory clocks are
# sampled every 200 ms ($OUT/clocks.csv).
set -euo pipefail
source bench/scripts/gpu_env.sh
py=/tmp/py311
mkdir -p "$py"
tar -C "$py" -xJf .gpu/py311.tar.xz
nvidia-smi --query-gpu=timestamp,clocks.sm,clocks.mem,power.draw,temperature.gpu,memory.used --format=csv,noheader -lms 200 \
  >"$out/clocks.csv" &
clocks=$!
trap 'kill $clocks 2>/dev/null || true' EXIT
RENDERS=${RENDERS:-10} FRAMES=${FRAMES:-50}
PYTHONHOME=$py PYTHONPATH=$PWD/.gpu/python:$py/site LD_LIBRARY_PATH=$LD_LIBRARY_PATH:$py/lib \
  DPOINT_EXECUTABLE=$PWD/.gpu/dpoint "$py/bin/python3.11" bench/scripts/python_session.py \
  --renders "$RENDERS" --frames "$FRAMES" "$@" | tee "$out/python_session.jsonl"
# The same set and options in fresh processes, as every figure before this issue was taken.
.gpu/dpoint generate sierpinski --level 11 --unwelded --order morton -o /tmp/s11.ply --quiet
for i in 1 2 3; do
  .gpu/dpoint render /tmp/s11.ply -o /tmp/s11.png --mode fp32 --backend compute --width 1920 --height 1080 \
    --frames "$FRAMES" --warmup 300ms --json /tmp/r.json --quiet
  /usr/bin/python3 -c "import json; j = json.load(open('/tmp/r.json')); g = j['gpu_ms']; \
print(json.dumps(dict(phase='cli_process', index=$i, points=j['points'], gpu_ms_median=g['median'], gpu_ms_min=g['min'], gpu_ms_p95=g['p95'])))" \
    | tee -a "$out/python_session.jsonl"
done
