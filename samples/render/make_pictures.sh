#!/usr/bin/env bash
# Remakes the pictures of README.md and docs/rendering.md: the Mandelbulb (res 200) moved to the Earth's radius, framed
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

# Readable previews (issue #13): the same Mandelbulb and a level-4 Menger sponge as plain 1-px
# points and as `dpoint render` draws them by default (eye-dome lighting, --point-size auto),
# and the Mandelbulb's four-view contact sheet. The sponge is the voxel method's surface (res 243,
# one voxel per smallest cube): the exact method's vertices sit only on the lattice, where a
# hole's back wall lines up with its front face and the holes do not show.
"$dpoint" generate menger --level 4 --method voxel --resolution 243 --quiet -o "$work/menger.ply"
for set in mandelbulb_earth menger; do
  "$dpoint" render "$work/$set.ply" -o "$here/${set}_plain.png" --shade none --point-size 1 --width 480 --height 480
  "$dpoint" render "$work/$set.ply" -o "$here/${set}_edl.png" --width 480 --height 480
done
"$dpoint" render "$work/mandelbulb_earth.ply" -o "$here/mandelbulb_earth_views.png" --views 4 --width 960 --height 720

# A real survey (issue #13): the corpus's simple.las (TerraScan, UTM-like coordinates at 0.01 m)
# when ../shared sits beside the checkout: plain and with eye-dome lighting and elevation colours,
# and the hard case: one return seen 1 m wide (3.9 mm a pixel: 1 m over 256 px) from straight
# above, off centre, in fp32 (float's 6 cm spacing at 853 km moves it) and native (on its pixel).
las=$here/../../../shared/corpus/las/simple.las
if [ -f "$las" ]; then
  "$dpoint" render "$las" -o "$here/simple_las_plain.png" --shade none --width 480 --height 480
  "$dpoint" render "$las" -o "$here/simple_las_elevation.png" --color elevation --width 480 --height 480
  for mode in fp32 native; do
    "$dpoint" render "$las" -o "$here/simple_las_$mode.png" --mode $mode --error --ortho \
      --view-center 638435.2,853170.1 --view-width 1 --width 256 --height 256 --point-size 15 --background 255,255,255
  done
fi
