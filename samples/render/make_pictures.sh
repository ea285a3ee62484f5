#!/usr/bin/env bash
# Remakes the README's pictures: the Mandelbulb (res 200) moved to the Earth's radius, framed
# by --fit, in fp32 (float's 0.5 m spacing at 6.4e6 m shows as a lattice) and native fp64.
# Usage: samples/render/make_pictures.sh build/dpoint
set -euo pipefail
dpoint=${1:-build/dpoint}
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$dpoint" generate mandelbulb --resolution 200 --offset 6378137,0,0 --quiet -o "$work/mandelbulb_earth.ply"
for mode in fp32 native; do
  "$dpoint" render "$work/mandelbulb_earth.ply" -o "$here/mandelbulb_earth_$mode.png" --mode $mode --error \
    --width 480 --height 480 --point-size 2
done
