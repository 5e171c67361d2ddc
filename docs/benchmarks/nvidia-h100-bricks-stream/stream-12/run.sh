#!/usr/bin/env bash
# m4 (3d82f4e) against m5 (a4d7cac's coarse bricks in the first frame, 05809bf's faster ranges,
# and the ranges' arrival: no uploads in that frame, page tables on all cores, the pyramid's
# nodes over constant bricks built without reading texels), an orbit of 2000 frames.
set -u
start=$SECONDS
source scripts/gpu-env.sh
mkdir -p /tmp/s /tmp/bins
tar xJf .bench-data/m45.tar.xz -C /tmp/bins
pack() { tar czf $OUT/s.tgz --exclude='*.raw' -C /tmp s; }
stream() { local bin=$1 v=$2 budget=$3 tag=$4
  nvidia-smi --query-gpu=timestamp,memory.used --format=csv,noheader -lms 50 > /tmp/s/smi-$tag.log 2>&1 & smi=$!
  RUST_LOG=leapview=debug timeout 120 python3 .bench-data/rss.py /tmp/bins/$bin bench --stream $v --gpu-budget $budget --stream-frames 2000 --out /tmp/s/$tag > /tmp/s/$tag.log 2>&1
  kill $smi; echo "$tag done at $((SECONDS-start)) s" >> /tmp/s/gen.txt; pack
}
/tmp/bins/m5 generate vessels --size 1024 --out /tmp/v1024.nhdr > /dev/null 2>&1
python3 scripts/tile-volume.py /tmp/v1024.raw /tmp/big.raw 1024
sed -e 's/sizes: 1024 1024 1024/sizes: 2048 2048 1024/' -e 's/v1024.raw/big.raw/' /tmp/v1024.nhdr > /tmp/big.nhdr
echo "data at $((SECONDS-start)) s" >> /tmp/s/gen.txt
stream m5 /tmp/big.nhdr 1GB big-m5
stream m4 /tmp/big.nhdr 1GB big-m4
stream m5 /tmp/v1024.nhdr 1GB v1024-1g-m5
stream m4 /tmp/v1024.nhdr 1GB v1024-1g-m4
stream m5 /tmp/big.nhdr 1GB big-m5-again
