#!/usr/bin/env bash
# Issue #27's Slurm run on a host of several GPUs (device tool kind nvidia-h100-x2 or larger): the
# single-node cluster of tests/external/slurm_tiles.sh, one tile per GPU (examples/slurm with
# DEVICE=task GPUS=G), then the merge job, and the merged file against one process's. Slurm and
# munge come as Debian 12's packages in .gpu/slurm/ (dpkg -x), with the libraries they link that
# the GPU machine's Ubuntu lacks (.gpu/slurm/lib: only those ldconfig does not know are used).
# KIND_ARGS: the set (default the issue's Mandelbulb at res 2048). Output: $OUT/slurm.txt.
# State (2026-11-25, nvidia-h100-x2): munged and slurmctld start there, slurmd exits at once (not
# diagnosed yet: the test's cleanup removes its log; keep $work to read it). The tiles were run there
# with GNU parallel instead (bench/scripts/gpu_tiles.sh); this Slurm path is tested on lavapipe
# (CTest external.slurm_tiles).
set -euo pipefail
source bench/scripts/gpu_env.sh
for f in .gpu/slurm/*.deb; do dpkg -x "$f" /; done
# The packages' scripts are not run by dpkg -x: make the links their update-alternatives makes.
shopt -s nullglob
for f in /usr/bin/*-wlm /usr/sbin/*-wlm; do [ -e "${f%-wlm}" ] || ln -s "$f" "${f%-wlm}"; done
mkdir -p /tmp/slurmlib
for lib in .gpu/slurm/lib/*; do
  ldconfig -p | grep -q "/$(basename "$lib")\$" || cp "$lib" /tmp/slurmlib/
done
export LD_LIBRARY_PATH=$LD_LIBRARY_PATH:/tmp/slurmlib
gpus=$(nvidia-smi -L | wc -l)
start=$(date +%s.%N)
TILES=$gpus GPUS=$gpus KIND_ARGS=${KIND_ARGS:-"mandelbulb --variant fast --resolution 2048"} \
  bash tests/external/slurm_tiles.sh "$PWD/.gpu/dpoint" "$PWD/examples/slurm" 2>&1 | tee "$out/slurm.txt"
echo "whole run (cluster start, $gpus tiles, merge, one process to compare): $(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.2f", b - a }') s" | tee -a "$out/slurm.txt"
