#!/usr/bin/env bash
# What the GPU machine's output folder can take (issue #38 item 4's dd comparison): its filesystem,
# dd into the page cache (the comparison's figure) against dd with O_DIRECT, one stream and four
# at once (each a quarter of the file, seek= apart), for a file of SIZE_MB (default 5400, the
# res-2048 fast Mandelbulb's PLY). Results in $OUT/disk_probe.txt.
set -uo pipefail
out=${OUT:-/tmp/out}
data=${DATA:-/tmp/dpoint-generate-ab}
mb=${SIZE_MB:-5400}
mkdir -p "$data"
{
  echo "== filesystems"; df -hT "$data" "$PWD" /dev/shm 2>&1; findmnt -T "$data" 2>&1
  cat /sys/block/*/queue/rotational 2>/dev/null | tr '\n' ' '; echo; lsblk -o NAME,SIZE,MODEL,ROTA 2>&1 | head
  free -g
  t() { local s e; s=$(date +%s%N); "$@"; e=$(date +%s%N); awk -v n=$((e - s)) 'BEGIN { printf "%.2f s\n", n / 1e9 }'; }
  for round in 1 2 3; do
    echo "== round $round"
    rm -f "$data/dd.bin"; sync
    echo -n "dd page cache bs=1M: "; t dd if=/dev/zero of="$data/dd.bin" bs=1M count=$mb status=none
    rm -f "$data/dd.bin"; sync
    echo -n "dd O_DIRECT bs=64M: "; t dd if=/dev/zero of="$data/dd.bin" bs=64M count=$((mb / 64)) oflag=direct status=none
    rm -f "$data/dd.bin"; sync
    q=$((mb / 64 / 4))
    par() { for k in 0 1 2 3; do dd if=/dev/zero of="$data/dd.bin" bs=64M count=$q seek=$((k * q)) oflag=direct conv=notrunc status=none & done; wait; }
    echo -n "dd O_DIRECT bs=64M x4 streams: "; t par
    rm -f "$data/dd.bin"; sync
    fal() { fallocate -l $((mb * 1048576)) "$data/dd.bin" && par; }
    echo -n "fallocate + dd O_DIRECT x4: "; t fal
    rm -f "$data/dd.bin"; sync
    echo -n "sync after page-cache dd: "; t bash -c "dd if=/dev/zero of='$data/dd.bin' bs=1M count=$mb status=none; sync"
    rm -f "$data/dd.bin"; sync
  done
} 2>&1 | tee "$out/disk_probe.txt"
