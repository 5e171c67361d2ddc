#!/usr/bin/env bash
# m5 (stream-12's) against m6 (+ the pyramid's level 0 built brick by brick, each texel once;
# the ranges' arrival over two frames: one decides, the next writes the page tables whole),
# an orbit of 2000 frames; m6 alone from 256³ up for the scaling plot.
set -u
start=$SECONDS
source scripts/gpu-env.sh || exit 1
mkdir -p /tmp/s /tmp/bins
tar xJf .bench-data/m56.tar.xz -C /tmp/bins
pack() { tar czf $OUT/s.tgz --exclude='*.raw' -C /tmp s; }
stream() { local bin=$1 v=$2 budget=$3 tag=$4
  nvidia-smi --query-gpu=timestamp,memory.used --format=csv,noheader -lms 50 > /tmp/s/smi-$tag.log 2>&1 & smi=$!
  RUST_LOG=leapview=debug timeout 120 python3 .bench-data/rss.py /tmp/bins/$bin bench --stream $v --gpu-budget $budget --stream-frames 2000 --out /tmp/s/$tag > /tmp/s/$tag.log 2>&1
  kill $smi; echo "$tag done at $((SECONDS-start)) s" >> /tmp/s/gen.txt; pack
}
for n in 256 512 1024; do
  [[ -f /tmp/v$n.raw ]] || /tmp/bins/m6 generate vessels --size $n --out /tmp/v$n.nhdr > /dev/null 2>&1
done
[[ -f /tmp/big.raw ]] || python3 scripts/tile-volume.py /tmp/v1024.raw /tmp/big.raw 1024
sed -e 's/sizes: 1024 1024 1024/sizes: 2048 2048 1024/' -e 's/v1024.raw/big.raw/' /tmp/v1024.nhdr > /tmp/big.nhdr
echo "data at $((SECONDS-start)) s" >> /tmp/s/gen.txt
stream m6 /tmp/big.nhdr 1GB big-m6
stream m5 /tmp/big.nhdr 1GB big-m5
stream m6 /tmp/v1024.nhdr 1GB v1024-1g-m6
stream m5 /tmp/v1024.nhdr 1GB v1024-1g-m5
stream m6 /tmp/v512.nhdr 1GB v512-1g-m6
stream m6 /tmp/v256.nhdr 1GB v256-1g-m6
stream m6 /tmp/v1024.nhdr 256MB v1024-256m-m6
stream m6 /tmp/big.nhdr 1GB big-m6-again
