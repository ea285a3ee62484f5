#!/usr/bin/env bash
# The rates `--mode auto` predicts a picture's time from (viewer/modes.cpp, ModeInfo::host_core_ns
# and frame_ns; issue #38 item 3): for every mode and both backends, one `dpoint render` of the
# 16.7M-point Sierpinski set (level 11, unwelded, input order) at 1920x1080 with 1-px points and no
# shading, FRAMES (5) frames after one warm-up: the host's encoding and upload (upload_ms, as core
# nanoseconds a point: ms x threads / points) and the frame (gpu_ms median, ns a point).
# One row per mode and backend in $OUT/mode_rates.tsv. BIN: the dpoint to run (build/dpoint).
#   OUT=/tmp/rates bench/scripts/mode_rates.sh
set -euo pipefail
bin=${BIN:-build/dpoint}
out=${OUT:-/tmp/out}
data=${DATA:-/tmp/dpoint-rates}
mkdir -p "$out" "$data"
[ -s "$data/s11u.ply" ] || "$bin" generate sierpinski --level 11 --unwelded -q -o "$data/s11u.ply"
threads=$(nproc)
rows=$out/mode_rates.tsv
printf 'mode\tbackend\tpoints\tthreads\tupload_ms\tgpu_ms_median\thost_core_ns\tframe_ns\tdevice\n' >"$rows"
for backend in compute raster; do
  for mode in fp32 split rte df64 native batch adaptive; do
    rm -f /tmp/rates.json
    "$bin" render "$data/s11u.ply" -o /tmp/rates.png -q --mode "$mode" --backend "$backend" --width 1920 --height 1080 \
      --point-size 1 --shade none --frames "${FRAMES:-5}" --warmup 1 --json /tmp/rates.json >/dev/null 2>&1 || true
    /usr/bin/python3 - "$mode" "$backend" "$threads" <<'PY' | tee -a "$rows"
import json, os, sys
mode, backend, threads = sys.argv[1], sys.argv[2], int(sys.argv[3])
if not os.path.exists("/tmp/rates.json"):
    print(f"{mode}\t{backend}\t\t{threads}\t\t\t\t\tnot run")
    sys.exit()
j = json.load(open("/tmp/rates.json"))
n = j["points"]
gpu = j["gpu_ms"]["median"] if j["gpu_ms"] else j["frame_ms"]["median"]
print(f"{mode}\t{backend}\t{n}\t{threads}\t{j['upload_ms']:.1f}\t{gpu:.4f}\t{j['upload_ms'] * 1e6 * threads / n:.2f}\t"
      f"{gpu * 1e6 / n:.4f}\t{j['device']}")
PY
  done
done
