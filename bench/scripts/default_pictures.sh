#!/bin/bash
# The default pictures of issue #36 item 5, two builds side by side: for each set and picture size
# the point size, gaps and artefacts (the measures of tests/viewer/picture_metrics.h, recomputed in
# numpy by picture_measures.py), then the whole `dpoint render` process at 1024x768, the two builds
# alternated, ROUNDS runs each (median reported).
#   bench/scripts/default_pictures.sh BASE_DPOINT NEW_DPOINT WORK [ROUNDS]
# SETS: other sets (paths, or names made in WORK beforehand), e.g. SETS="s11u.ply mb420.ply";
# SIZES: other picture sizes, e.g. SIZES="1024x768 3840x2160"
set -euo pipefail
base=$1 new=$2 work=$3 rounds=${4:-5}
here=$(cd "$(dirname "$0")" && pwd)
corpus=${DPOINT_CORPUS:-$here/../../../shared/corpus}
mkdir -p "$work"
[ -f "$work/mb200.ply" ] || "$new" generate mandelbulb --resolution 200 -o "$work/mb200.ply" -q
[ -f "$work/mb420.ply" ] || "$new" generate mandelbulb --resolution 420 -o "$work/mb420.ply" -q
[ -f "$work/menger.ply" ] || "$new" generate menger -o "$work/menger.ply" -q
[ -f "$work/sier7.ply" ] || "$new" generate sierpinski --level 7 -o "$work/sier7.ply" -q
[ -f "$work/sier9.ply" ] || "$new" generate sierpinski -o "$work/sier9.ply" -q
sets=${SETS:-"mb200.ply mb420.ply menger.ply sier7.ply sier9.ply $corpus/las/simple.las $corpus/laz/autzen_trim.las"}
echo "| set | size | build | point size | gaps | artefacts |"
echo "| --- | --- | --- | --- | --- | --- |"
for f in $sets; do
  path=$f; [ -f "$path" ] || path=$work/$f
  name=$(basename "$f")
  for size in ${SIZES:-640x480 1024x768 1920x1080}; do
    for build in base new; do
      bin=$base; [ $build = new ] && bin=$new
      png=$work/$name-$size-$build.png
      px=$("$bin" render "$path" -o "$png" --width "${size%x*}" --height "${size#*x}" 2>&1 | grep -o '[0-9.]* px points' | head -1)
      echo "| $name | $size | $build | ${px% points} | $(/usr/bin/python3 "$here/picture_measures.py" "$png") |"
    done
  done
done
echo
echo "Whole process, default render at 1024x768, ms (median of $rounds, builds alternated):"
echo "| set | base | new | new/base |"
echo "| --- | --- | --- | --- |"
for f in $sets; do
  path=$f; [ -f "$path" ] || path=$work/$f
  b=(); n=()
  for r in $(seq "$rounds"); do
    for build in base new; do
      bin=$base; [ $build = new ] && bin=$new
      s=$(date +%s%N); "$bin" render "$path" -o "$work/timing.png" -q; e=$(date +%s%N)
      ms=$(( (e - s) / 1000000 ))
      if [ $build = base ]; then b+=("$ms"); else n+=("$ms"); fi
    done
  done
  mb=$(printf '%s\n' "${b[@]}" | sort -n | sed -n "$(( (rounds + 1) / 2 ))p")
  mn=$(printf '%s\n' "${n[@]}" | sort -n | sed -n "$(( (rounds + 1) / 2 ))p")
  echo "| $(basename "$f") | $mb | $mn | $(awk -v a="$mn" -v b="$mb" 'BEGIN { printf "%.2f", a / b }') |"
done
