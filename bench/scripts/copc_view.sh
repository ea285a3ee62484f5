#!/usr/bin/env bash
# COPC by view (issue #35): a large set written as .copc.laz, walked whole by the npm `copc`
# package (copc.js, viewer.copc.io's reader; tests/external/node/copc_walk.mjs), then what render
# reads for the default 640x480 picture, for an orthographic window 1% of the extent wide at its
# centre, and (3D sets) for two perspective views, from the box's face into the set and from 20
# widths above; each line the render report's copc block (--json).
#   bench/scripts/copc_view.sh DPOINT WORK_DIR [KIND_ARGS...]
#   (default KIND_ARGS: random2d --count 16777216 --seed 7: 16.7M points)
set -euo pipefail
dpoint=$(realpath "$1")
work=$2
shift 2
args=("$@")
[ ${#args[@]} -gt 0 ] || args=(random2d --count 16777216 --seed 7)
top=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$work"
copc="$work/set.copc.laz"
start=$(date +%s.%N)
"$dpoint" generate "${args[@]}" -q -o "$copc"
echo "generate ${args[*]} -o set.copc.laz: $(echo "$(date +%s.%N) - $start" | bc) s, $(stat -c %s "$copc") bytes"
node "$top/tests/external/node/copc_walk.mjs" "$copc" | sed "s|$work/||"
read -r cx cy cz w xmax dz <<<"$("$dpoint" info "$copc" --json --sample 10 --stream on |
  /usr/bin/python3 -c 'import json, sys; d = json.load(sys.stdin); lo, hi = d["min"], d["max"]
print(*[(lo[a] + hi[a]) / 2 for a in range(3)], d["extent"][0], hi[0], d["extent"][2])')"
view() {
  local name=$1
  shift
  "$dpoint" render "$copc" -o "$work/$name.png" --width 640 --height 480 --json "$work/$name.json" -q "$@"
  /usr/bin/python3 -c 'import json, sys; c = json.load(open(sys.argv[1]))["copc"]
share = 100 * c["bytes_read"] / c["file_bytes"]
print("%s: read %d of %d points, %d of %d bytes (%.1f%%), %d nodes" % (sys.argv[2], c["points_read"],
      c["file_points"], c["bytes_read"], c["file_bytes"], share, c["nodes_read"]))' "$work/$name.json" "$name $*"
}
view default
view window --ortho --view-center "$cx,$cy" --view-width "$(echo "$w / 100" | bc -l)"
# A perspective view from the box's +x face into the set (3D sets only: a 2D set renders ortho).
if [ "$(echo "$dz > 0" | bc -l)" = 1 ]; then
  view inside --eye "$xmax,$cy,$cz" --target "$cx,$cy,$cz" --up 0,0,1
  view far --eye "$cx,$cy,$(echo "$cz + 20 * $w" | bc -l)" --target "$cx,$cy,$cz" --up 0,1,0
fi
