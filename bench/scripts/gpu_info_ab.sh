#!/usr/bin/env bash
# `dpoint info` of hard sets on the GPU machine's 16 cores, two builds alternated (device tool;
# carry .gl and .gpu as gpu_bench.sh says, the build before as .gpu/dpoint-BASE, the current one as
# .gpu/dpoint). info runs on the CPU; this shows what its parallel parts give on many cores. The
# sets, made there once as binary PLY (x, y, z doubles) with the standard library's Python:
#   plain  5M uniform in a 100-unit cube
#   zeros  the same with 20% of the points at (0, 0, 0) (a scanner's no-return points)
#   one    2M copies of (0, 0, 0) and one point (1, 1, 1)
#   zoom   10M points in a 0.01-unit cube at (6.4e6, -2.1e6, 3.3e5): all merge in float32
# Per round, per set, each build's whole `dpoint info SET -q` (wall time, peak memory; the reports
# compared across the builds). Rows in $OUT/info.tsv, medians in $OUT/info-summary.tsv.
#   BASE=d43301b ROUNDS=3 SETS="plain zeros one zoom"
set -euo pipefail
source bench/scripts/gpu_env.sh
data=/tmp/dpoint-info
mkdir -p "$data"
/usr/bin/python3 - "$data" <<'PY'
import array, os, random, sys
data = sys.argv[1]

def write(name, n, point):
    path = os.path.join(data, name + ".ply")
    if os.path.exists(path) and os.path.getsize(path) > 24 * n:
        return
    header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {n}\n"
              "property double x\nproperty double y\nproperty double z\nend_header\n").encode()
    with open(path + ".part", "wb") as f:
        f.write(header)
        for start in range(0, n, 1 << 20):
            a = array.array("d")
            for i in range(start, min(n, start + (1 << 20))):
                a.extend(point(i))
            a.tofile(f)
    os.replace(path + ".part", path)

r = random.Random(2)
write("plain", 5_000_000, lambda i: (r.random() * 100, r.random() * 100, r.random() * 100))
write("zeros", 5_000_000, lambda i: (0.0, 0.0, 0.0) if r.random() < 0.2 else (r.random() * 100, r.random() * 100, r.random() * 100))
write("one", 2_000_000, lambda i: (1.0, 1.0, 1.0) if i == 0 else (0.0, 0.0, 0.0))
write("zoom", 10_000_000, lambda i: (6.4e6 + r.random() * 1e-2, -2.1e6 + r.random() * 1e-2, 3.3e5 + r.random() * 1e-2))
PY
ls -l "$data" | tee "$out/sizes.txt"
cat "$data"/*.ply >/dev/null
nproc | tee "$out/cores.txt"
base=${BASE:-d43301b}
rows=$out/info.tsv
printf 'round\tset\tbuild\twall_s\tpeak_kb\n' >"$rows"
for round in $(seq "${ROUNDS:-3}"); do
  for set in ${SETS:-plain zeros one zoom}; do
    for build in "$base" current; do
      bin=$(build_bin "$build")
      /usr/bin/time -f "%e %M" -o /tmp/t.txt timeout 300 "$bin" info "$data/$set.ply" -q >"/tmp/info-$set-$build.txt" 2>>"$out/errors.txt" ||
        echo "info $set $build failed" >>"$out/errors.txt"
      read -r wall peak <<<"$(tail -1 /tmp/t.txt)"
      printf '%s\t%s\t%s\t%s\t%s\n' "$round" "$set" "$build" "$wall" "$peak" | tee -a "$rows"
    done
    cmp -s "/tmp/info-$set-$base.txt" "/tmp/info-$set-current.txt" || echo "$set: the reports differ" | tee -a "$out/reports.txt"
    cp "/tmp/info-$set-current.txt" "$out/info-$set.txt"
  done
done
median_summary "$rows" set build | tee "$out/info-summary.tsv"
