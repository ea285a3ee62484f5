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

# The first picture (issue #24): `dpoint render FILE -o OUT.png` with every default but the size
# (640x480), beside Open3D's default capture of the same file where Open3D is there
# (bench/scripts/open3d_capture.py: python3-open3d for /usr/bin/python3 and Xvfb): the Mandelbulb
# (res 200) and the default Menger sponge (level 4, exact); a LAS survey (the corpus's simple.las,
# 1,065 returns over 3.4 x 4.6 km, when ../shared sits beside the checkout); a deep zoom 1e-12 wide
# (mandelbrot2d's --max-iter auto and equalized colours, at a centre on the set's boundary: at the
# default centre a view this deep holds no boundary, only a smooth ramp of escape counts).
first=$here/first
mkdir -p "$first"
"$dpoint" generate mandelbulb --resolution 200 --quiet -o "$work/mandelbulb.ply"
"$dpoint" generate menger --quiet -o "$work/menger_exact.ply"
"$dpoint" generate mandelbrot2d --width 1e-12 --center=-0.7436450004729,0.131825899748 --quiet -o "$work/deep.ply"
survey=$here/../../../shared/corpus/las/simple.las
for set in mandelbulb menger_exact deep; do
  "$dpoint" render "$work/$set.ply" -o "$first/$set.png" --width 640 --height 480 --quiet
done
if [ -f "$survey" ]; then "$dpoint" render "$survey" -o "$first/survey.png" --width 640 --height 480 --quiet; fi
# A LAZ survey (issue #35): laz-perf's autzen_trim.laz (110,000 returns, LASzip-compressed) by
# classification, with the ASPRS colours and their legend.
laz=$here/../../../shared/corpus/laz/autzen_trim.laz
if [ -f "$laz" ]; then
  "$dpoint" render "$laz" --color classification -o "$first/survey_laz_classes.png" --width 640 --height 480 --quiet
fi
if /usr/bin/python3 -c "import open3d" 2>/dev/null && command -v Xvfb >/dev/null; then
  for set in mandelbulb menger_exact; do
    /usr/bin/python3 "$here/../../bench/scripts/open3d_capture.py" "$work/$set.ply" "$first/$set.open3d.png" \
      --width 640 --height 480 >/dev/null
  done
fi
