#!/usr/bin/env bash
# A LAS file streamed on the GPU machine, two builds alternated (device tool; carry .gl and .gpu
# as gpu_bench.sh says, the build before as .gpu/dpoint-BASE, the current one as .gpu/dpoint):
# `random2d --count COUNT` made there once as a LAS file (format 0 records, 12 dimensions) and
# read into the page cache, then per round, per mode, each build's whole
# `dpoint render FILE --stream on --mode MODE` (wall time, peak memory; the PNGs compared across
# the builds), and each build's `dpoint info --stream on FILE`. Rows in $OUT/las-stream.tsv,
# medians in $OUT/las-stream-summary.tsv.
#   BASE=e2b3981 ROUNDS=3 COUNT=50000000 MODES="fp32 split rte df64 native batch adaptive auto"
set -euo pipefail
source bench/scripts/gpu_env.sh
data=/tmp/dpoint-las-stream
mkdir -p "$data"
file=$data/r.las
if [ ! -s "$file" ]; then
  .gpu/dpoint generate random2d --count "${COUNT:-50000000}" -q -o "$data/r.ply"
  .gpu/dpoint convert "$data/r.ply" -q -o "$file" 2>/dev/null
  rm -f "$data/r.ply"
fi
ls -l "$file" | tee "$out/size.txt"
cat "$file" >/dev/null
base=${BASE:-e2b3981}
rows=$out/las-stream.tsv
printf 'round\twhat\tbuild\twall_s\tpeak_kb\n' >"$rows"
for round in $(seq "${ROUNDS:-3}"); do
  for what in ${MODES:-fp32 split rte df64 native batch adaptive auto} info; do
    for build in "$base" current; do
      bin=$(build_bin "$build")
      if [ "$what" = info ]; then
        /usr/bin/time -f "%e %M" -o /tmp/t.txt "$bin" info --stream on "$file" >"$out/info-$build.txt" 2>/dev/null || echo "info failed" >>"$out/errors.txt"
      else
        /usr/bin/time -f "%e %M" -o /tmp/t.txt "$bin" render "$file" --stream on --mode "$what" -q -o "/tmp/$what-$build.png" \
          >/dev/null 2>>"$out/errors.txt" || echo "render $what $build failed" >>"$out/errors.txt"
      fi
      read -r wall peak <<<"$(tail -1 /tmp/t.txt)"
      printf '%s\t%s\t%s\t%s\t%s\n' "$round" "$what" "$build" "$wall" "$peak" | tee -a "$rows"
    done
    [ "$what" = info ] || cmp -s "/tmp/$what-$base.png" "/tmp/$what-current.png" || echo "$what: the PNGs differ" | tee -a "$out/pngs.txt"
  done
done
median_summary "$rows" what build | tee "$out/las-stream-summary.tsv"
