#!/usr/bin/env bash
# An A/B of one generate on the GPU machine (device tool; carry .gl and .gpu as for
# gpu_generate.sh: .gpu/dpoint-A the build before, .gpu/dpoint the current one). First the
# current build's device counts against its CPU path at res 63, 64 and 257 ($OUT/equal.txt). For ROUNDS
# (3) rounds, each build of BUILDS ("A current"; a build .gpu/dpoint-NAME may be a script that runs
# .gpu/dpoint with other options, e.g. `--mesh host`) in turn: `generate CASE --device 0` (CASE default
# "mandelbulb --variant fast --resolution 2048"), then dd of a file of its size into the same
# folder. One line per run in $OUT/generate_ab.tsv: round, build, wall s, the classification's GPU
# ms (the device line), SHA-256 (16) of the output, and the phases generate prints (generate,
# colours and offset, write, s); the medians in $OUT/generate_ab-median.tsv; each build's stderr of
# the last round in $OUT/stderr-BUILD.txt.
set -euo pipefail
source bench/scripts/gpu_env.sh
data=${DATA:-/tmp/dpoint-generate-ab}
mkdir -p "$data"
case=${CASE:-mandelbulb --variant fast --resolution 2048}
# The current build's device counts against its CPU path (grid and file) at small odd and even
# resolutions of CASE's kind.
kind=${case%--resolution*}
for res in 63 64 257; do
  # shellcheck disable=SC2086
  .gpu/dpoint generate $kind --resolution $res -q --device none --grid-out "$data/cpu.grid" -o "$data/cpu.ply"
  # shellcheck disable=SC2086
  .gpu/dpoint generate $kind --resolution $res -q --device 0 --grid-out "$data/gpu.grid" -o "$data/gpu.ply"
  # Without --grid-out: marching cubes where --mesh auto puts it (the device, on a GPU).
  # shellcheck disable=SC2086
  .gpu/dpoint generate $kind --resolution $res -q --device 0 -o "$data/mesh.ply"
  echo "$kind--resolution $res: grid $(cmp -s "$data/cpu.grid" "$data/gpu.grid" && echo equal || echo DIFFER)," \
    "file $(cmp -s "$data/cpu.ply" "$data/gpu.ply" && echo equal || echo DIFFER)," \
    "file meshed by --mesh auto $(cmp -s "$data/cpu.ply" "$data/mesh.ply" && echo equal || echo DIFFER)"
done | tee "$out/equal.txt"
rows=$out/generate_ab.tsv
printf 'round\tbuild\twall_s\tgpu_ms\tsha256\tgenerate_s\tcolours_s\twrite_s\n' >"$rows"
for round in $(seq "${ROUNDS:-3}"); do
  for build in ${BUILDS:-A current}; do
    bin=$(build_bin "$build")
    # shellcheck disable=SC2086
    /usr/bin/time -f "%e" -o "$data/time.txt" "$bin" generate $case --device 0 -o "$data/out.ply" 2>"$data/stderr.txt"
    gpu=$(sed -n 's/.* in \([0-9.]*\) ms of GPU time.*/\1/p' "$data/stderr.txt" | head -1)
    phases=$(sed -n 's/^time (s): generate \([0-9.]*\), colours and offset \([0-9.]*\), .*write \([0-9.]*\);.*/\1\t\2\t\3/p' \
      "$data/stderr.txt" | head -1)
    printf '%s\t%s\t%s\t%s\t%s\t%s\n' "$round" "$build" "$(cat "$data/time.txt")" "${gpu:--}" \
      "$(sha256sum <"$data/out.ply" | cut -c1-16)" "${phases:--}" | tee -a "$rows"
    cp "$data/stderr.txt" "$out/stderr-$build.txt"  # the last round's: the device and phase lines
    size=$(stat -c %s "$data/out.ply")
    rm -f "$data/out.ply"
    sync
  done
  s=$(date +%s%N)
  dd if=/dev/zero of="$data/dd.bin" bs=1M count=$(( (size + 1048575) / 1048576 )) status=none
  e=$(date +%s%N)
  printf '%s\tdd\t%s\t-\t-\t-\t-\t-\n' "$round" "$(awk -v n=$(( e - s )) 'BEGIN { printf "%.2f", n / 1e9 }')" | tee -a "$rows"
  rm -f "$data/dd.bin"
done
/usr/bin/python3 - "$rows" <<'PY' | tee "$out/generate_ab-median.tsv"
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter="\t"))
for b in dict.fromkeys(r["build"] for r in rows):
    w = [float(r["wall_s"]) for r in rows if r["build"] == b]
    g = [float(r["gpu_ms"]) for r in rows if r["build"] == b and r["gpu_ms"] not in ("-", "")]
    line = f"{b}\twall {statistics.median(w):.2f} s"
    if g:
        line += f"\tgpu {statistics.median(g):.1f} ms"
    for phase in ("generate_s", "colours_s", "write_s"):
        v = [float(r[phase]) for r in rows if r["build"] == b and r.get(phase) not in (None, "-", "")]
        if v:
            line += f"\t{phase[:-2]} {statistics.median(v):.2f} s"
    print(line)
PY
