#!/usr/bin/env bash
# Reading large files on the GPU machine's cores, two builds alternated (device tool; carry .gl and
# .gpu as gpu_bench.sh says, the build before as .gpu/dpoint-BASE, the current one as
# .gpu/dpoint). Each set is made once by the current build, read into the page cache, then
# `dpoint bench io` of it per build, ROUNDS rounds:
#   las   `sierpinski --level 11 --unwelded` (16.8M points) as a format-2 LAS (12 record fields);
#         with WRITE=1 also the whole `dpoint convert s11u.ply -o w.las` (scale, offset, the
#         merged-point count, the records)
#   mesh  `mandelbulb --variant fast --resolution MESH_RES --device 0` (2048: 108M vertices, 207M
#         triangles, 5.6 GB PLY)
#   gltf  the same at GLTF_RES (1024: 27M vertices, a 1.18 GB GLB with COLOR_0 and uint32 indices);
#         with WRITE=1 also the whole `dpoint convert mb1024.glb -o w.csv` (the streamed glTF → CSV)
#   pcd   the las set's 16.8M points as an ASCII PCD (x y z rgb); with WRITE=1 also the whole
#         `dpoint convert s11u.ply --pcd-encoding ascii -o w.pcd`
#   plyascii  the gltf set's mesh as an ASCII PLY (1024: 16.6M vertices, 33M faces, 2 GB)
# Rows in $OUT/read.tsv, medians in $OUT/read-summary.tsv.
#   SETS="las mesh gltf pcd" BASE=a968b90 ROUNDS=3 WRITE=1 MESH_RES=2048 GLTF_RES=1024
set -euo pipefail
source bench/scripts/gpu_env.sh
data=/tmp/dpoint-read
mkdir -p "$data"
rows=$out/read.tsv
printf 'round\tset\tbuild\tread_s\tprocess_s\tpeak_kb\twrite_process_s\n' >"$rows"
for set in ${SETS:-las mesh gltf pcd}; do
  case $set in
    las)
      [ -s "$data/s11u.ply" ] || .gpu/dpoint generate sierpinski --level 11 --unwelded -q -o "$data/s11u.ply"
      [ -s "$data/s11u.las" ] || .gpu/dpoint convert "$data/s11u.ply" -q -o "$data/s11u.las"
      file=$data/s11u.las ;;
    mesh)
      file=$data/mb${MESH_RES:-2048}.ply
      [ -s "$file" ] || .gpu/dpoint generate mandelbulb --variant fast --resolution "${MESH_RES:-2048}" --device 0 -q -o "$file" ;;
    gltf)
      file=$data/mb${GLTF_RES:-1024}.glb
      [ -s "$data/mb${GLTF_RES:-1024}.ply" ] ||
        .gpu/dpoint generate mandelbulb --variant fast --resolution "${GLTF_RES:-1024}" --device 0 -q -o "$data/mb${GLTF_RES:-1024}.ply"
      [ -s "$file" ] || .gpu/dpoint convert "$data/mb${GLTF_RES:-1024}.ply" -q -o "$file" ;;
    pcd)
      [ -s "$data/s11u.ply" ] || .gpu/dpoint generate sierpinski --level 11 --unwelded -q -o "$data/s11u.ply"
      file=$data/s11u-ascii.pcd
      [ -s "$file" ] || .gpu/dpoint convert "$data/s11u.ply" --pcd-encoding ascii -q -o "$file" ;;
    plyascii)
      file=$data/mb${GLTF_RES:-1024}-ascii.ply
      [ -s "$data/mb${GLTF_RES:-1024}.ply" ] ||
        .gpu/dpoint generate mandelbulb --variant fast --resolution "${GLTF_RES:-1024}" --device 0 -q -o "$data/mb${GLTF_RES:-1024}.ply"
      [ -s "$file" ] || .gpu/dpoint convert "$data/mb${GLTF_RES:-1024}.ply" --ply-ascii -q -o "$file" ;;
    *) echo "unknown set $set" >&2; exit 2 ;;
  esac
  ls -l "$file" | tee -a "$out/sizes.txt"
  cat "$file" >/dev/null
  for round in $(seq "${ROUNDS:-3}"); do
    for build in "${BASE:-a968b90}" current; do
      bin=$(build_bin "$build")
      /usr/bin/time -f "%e %M" -o /tmp/read_time.txt "$bin" bench io "$file" -q >/tmp/read_io.json 2>/dev/null || true
      echo "" >/tmp/read_write.txt
      if [ "${WRITE:-0}" = 1 ]; then
        case $set in
          las) /usr/bin/time -f "%e" -o /tmp/read_write.txt "$bin" convert "$data/s11u.ply" -o "$data/w.las" -q >/dev/null 2>&1 || true ;;
          pcd) /usr/bin/time -f "%e" -o /tmp/read_write.txt "$bin" convert "$data/s11u.ply" --pcd-encoding ascii -o "$data/w.pcd" -q >/dev/null 2>&1 || true ;;
          gltf) /usr/bin/time -f "%e" -o /tmp/read_write.txt "$bin" convert "$file" -o "$data/w.csv" -q >/dev/null 2>&1 || true ;;
        esac
        rm -f "$data/w.las" "$data/w.pcd" "$data/w.csv"
      fi
      /usr/bin/python3 - "$round" "$set" "$build" <<'PY' | tee -a "$rows"
import json, sys
r, s, b = sys.argv[1:4]
line = [l for l in open("/tmp/read_io.json") if l.startswith("{")][-1]
wall, peak = open("/tmp/read_time.txt").read().split()[-2:]
write = open("/tmp/read_write.txt").read().split()
print("\t".join([r, s, b, str(json.loads(line)["read_s"]), wall, peak, write[-1] if write else ""]))
PY
    done
  done
done
/usr/bin/python3 - "$rows" <<'PY' | tee "$out/read-summary.tsv"
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter="\t"))
print("set\tbuild\tmedian_read_s\tmedian_process_s\tmedian_write_process_s\treads")
for key in dict.fromkeys((r["set"], r["build"]) for r in rows):
    sel = [r for r in rows if (r["set"], r["build"]) == key]
    v = [float(r["read_s"]) for r in sel]
    w = [float(r["process_s"]) for r in sel]
    x = [float(r["write_process_s"]) for r in sel if r["write_process_s"]]
    print(f"{key[0]}\t{key[1]}\t{statistics.median(v):.4f}\t{statistics.median(w):.3f}\t" +
          (f"{statistics.median(x):.3f}" if x else "") + "\t" + " ".join(f"{y:.3f}" for y in v))
PY
