#!/usr/bin/env bash
# Host-visible buffers imported from the process's memory (VK_EXT_external_memory_host) on the
# GPU machine: every mode on both backends at 1920x1080 (an 8 MB picture readback, imported) with
# the validation layer, the current build (.gpu/dpoint) against the build before
# (.gpu/dpoint-$BASE): exit code, validation messages and the picture's SHA-256 (16) in
# $OUT/import_check.tsv.   BASE=B MODES="fp32 split rte df64 native batch adaptive"
set -euo pipefail
source bench/scripts/gpu_env.sh
data=/tmp/dpoint-import
mkdir -p "$data"
[ -s "$data/mb.ply" ] || .gpu/dpoint generate mandelbulb --resolution 200 -q -o "$data/mb.ply"
rows=$out/import_check.tsv
printf 'backend\tmode\tbuild\texit\tmessages\tpng\n' >"$rows"
for backend in compute raster; do
  for mode in ${MODES:-fp32 split rte df64 native batch adaptive}; do
    for build in "${BASE:-B}" current; do
      bin=$(build_bin "$build")
      rm -f "$data/m.png"
      rc=0
      "$bin" render "$data/mb.ply" --backend "$backend" --mode "$mode" --width 1920 --height 1080 --validate \
        -o "$data/m.png" >"$data/log.txt" 2>&1 || rc=$?
      png=$( [ -f "$data/m.png" ] && sha256sum <"$data/m.png" | cut -c1-16 || echo -)
      printf '%s\t%s\t%s\t%s\t%s\t%s\n' "$backend" "$mode" "$build" "$rc" "$(grep -c -i validation "$data/log.txt" || true)" \
        "$png" | tee -a "$rows"
    done
  done
done
# --error: the raster backend's probe (the projected points written to a host-visible buffer).
for build in "${BASE:-B}" current; do
  bin=$(build_bin "$build")
  rc=0
  "$bin" render "$data/mb.ply" --backend raster --mode fp32 --error --validate -o "$data/m.png" 2>&1 | grep -E "^error:|validation" |
    sed "s/^/$build: /" | tee -a "$out/import_check_error.txt" || rc=$?
done
