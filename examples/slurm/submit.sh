#!/bin/bash
# Submits N tiles as an array job and the merge after them; prints the merge job's id.
#   examples/slurm/submit.sh N [sbatch options...]
# with KIND_ARGS (and DPOINT, PARTS, OUTPUT, DEVICE, MERGE_ARGS) in the environment.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
n=${1:?usage: submit.sh N [sbatch options...]}
shift
tiles=$(sbatch --parsable --array=0-$((n - 1)) "$@" "$here/tiles.sbatch")
sbatch --parsable --dependency=afterok:"${tiles%%;*}" --kill-on-invalid-dep=yes "$@" "$here/merge.sbatch"
