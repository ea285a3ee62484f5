set -e
source bench/scripts/gpu_env.sh >/dev/null
data=/tmp/dpoint-speed; mkdir -p $data
[ -s $data/sierpinski-morton.ply ] || .gpu/dpoint generate sierpinski --level 11 --unwelded --order morton -q -o $data/sierpinski-morton.ply
[ "${SETS:-}" != random1g ] || [ -s $data/random1g-morton.ply ] || .gpu/dpoint generate random2d --count 1000000000 --order morton -q -o $data/random1g-morton.ply
[ -s $data/mandelbulb-morton.ply ] || .gpu/dpoint generate mandelbulb --resolution 1024 --variant fast --order morton -q -o $data/mandelbulb-morton.ply
one() { # label set mode envs...
  local label=$1 set=$2 mode=$3; shift 3
  env "$@" .gpu/dpoint-exp render $data/$set-morton.ply --backend compute --mode $mode --width 1920 --height 1080 --frames 50 --warmup 1s -q --shade none --json /tmp/r.json -o /tmp/$set-$mode-$label.png 2>/dev/null >/dev/null
  same=$(cmp -s /tmp/$set-$mode-$label.png /tmp/$set-$mode-main.png && echo same || echo DIFF)
  python3 -c "import json;j=json.load(open('/tmp/r.json'));print('$set\t$mode\t$label\t%.4f\t%.4f\t$same'%(j['gpu_ms']['median'],j['gpu_ms']['min']))"
}
for rep in 1 2; do
for set in ${SETS:-sierpinski mandelbulb}; do for mode in ${MODES:-adaptive batch}; do
  one main $set $mode
  one main-nomerge $set $mode DPOINT_SPLAT_MERGE=0
  for v in ${VARIANTS:-wrapped pair}; do
    one spv-$v $set $mode DPOINT_SPLAT_SPV=.gpu/spv/$mode-$v.spv
  done
done; done; done | tee -a $OUT/variants.tsv
