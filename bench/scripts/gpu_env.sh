# Sourced by the bench/scripts/gpu_*.sh scripts on the GPU machine (device tool: NVIDIA H100/H200,
# Ubuntu 24.04, no package registry): unpacks the carried Vulkan loader and validation layer
# (.gl/, Debian packages: libvulkan1, libglvnd0, libglx0, libegl1 and friends, and
# vulkan-validationlayers for the gtest suites that turn the layer on; `apt-get download` each),
# points the loader at NVIDIA's driver and the dynamic linker at the carried libraries
# (.gpu/lib), and names the output folder.
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
export LD_LIBRARY_PATH=$PWD/.gpu/lib
out=${OUT:-/tmp/out}
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader | tee "$out/gpu.txt"

# The sets of the render A/Bs (gpu_modes_ab.sh, gpu_phases_ab.sh), made once with the current build
# in /tmp/dpoint-default: s11u (`sierpinski --level 11 --unwelded`, 16.8M points) or mb420 (the
# res-420 Mandelbulb, 1.55M). Prints the file's path.
default_set() {
  local data=/tmp/dpoint-default
  mkdir -p "$data"
  case $1 in
    s11u) [ -s "$data/s11u.ply" ] || .gpu/dpoint generate sierpinski --level 11 --unwelded -q -o "$data/s11u.ply" ;;
    mb420) [ -s "$data/mb420.ply" ] || .gpu/dpoint generate mandelbulb --resolution 420 -q -o "$data/mb420.ply" ;;
    *) echo "default_set: no set '$1' (s11u or mb420)" >&2; return 1 ;;
  esac
  echo "$data/$1.ply"
}

# The binary of a build the A/B scripts name in BUILDS: .gpu/dpoint for "current", else
# .gpu/dpoint-NAME.
build_bin() {
  if [ "$1" = current ]; then echo .gpu/dpoint; else echo ".gpu/dpoint-$1"; fi
}

# The medians of a rows file (TSV with a header; columns wall_s and peak_kb) for each pair of the
# two key columns named, in the order met: one line each, with every wall time.
median_summary() {
  /usr/bin/python3 - "$@" <<'PY'
import csv, statistics, sys
path, a, b = sys.argv[1:4]
rows = list(csv.DictReader(open(path), delimiter="\t"))
print(f"{a}\t{b}\tmedian_wall_s\tmedian_peak_mb\twalls")
for key in dict.fromkeys((r[a], r[b]) for r in rows):
    sel = [r for r in rows if (r[a], r[b]) == key]
    w = [float(r["wall_s"]) for r in sel]
    p = [float(r["peak_kb"]) / 1024 for r in sel]
    print(f"{key[0]}\t{key[1]}\t{statistics.median(w):.3f}\t{statistics.median(p):.0f}\t" + " ".join(f"{x:.3f}" for x in w))
PY
}
