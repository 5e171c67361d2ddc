#!/usr/bin/env bash
# m3 (ebbf774) against m4 (+ the RC-s-df variant compiled in the stream's first frame), an orbit
# of 2000 frames: every frame until complete is an orbit frame.
set -u
start=$SECONDS
source scripts/gpu-env.sh
mkdir -p /tmp/s /tmp/bins
tar xJf .bench-data/m34.tar.xz -C /tmp/bins
pack() { tar czf $OUT/s.tgz --exclude='*.raw' -C /tmp s; }
stream() { local bin=$1 v=$2 budget=$3 tag=$4
  nvidia-smi --query-gpu=timestamp,memory.used --format=csv,noheader -lms 50 > /tmp/s/smi-$tag.log 2>&1 & smi=$!
  RUST_LOG=leapview=debug timeout 120 python3 .bench-data/rss.py /tmp/bins/$bin bench --stream $v --gpu-budget $budget --stream-frames 2000 --out /tmp/s/$tag > /tmp/s/$tag.log 2>&1
  kill $smi; echo "$tag done at $((SECONDS-start)) s" >> /tmp/s/gen.txt; pack
}
/tmp/bins/m4 generate vessels --size 1024 --out /tmp/v1024.nhdr > /dev/null 2>&1
python3 scripts/tile-volume.py /tmp/v1024.raw /tmp/big.raw 1024
sed -e 's/sizes: 1024 1024 1024/sizes: 2048 2048 1024/' -e 's/v1024.raw/big.raw/' /tmp/v1024.nhdr > /tmp/big.nhdr
echo "data at $((SECONDS-start)) s" >> /tmp/s/gen.txt
stream m4 /tmp/big.nhdr 1GB big-m4
stream m3 /tmp/big.nhdr 1GB big-m3
stream m4 /tmp/v1024.nhdr 1GB v1024-1g-m4
stream m3 /tmp/v1024.nhdr 1GB v1024-1g-m3
