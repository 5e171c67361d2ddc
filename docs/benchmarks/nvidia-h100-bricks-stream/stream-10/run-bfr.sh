#!/usr/bin/env bash
# bfr: branch-free brick reads + the ranges worker on a pool of its own; the stream suite beside nvidia-smi.
set -u
start=$SECONDS
source scripts/gpu-env.sh
mkdir -p /tmp/s
xz -dc .bench-data/bfr.xz > /tmp/bfr; chmod +x /tmp/bfr
pack() { tar czf $OUT/s.tgz --exclude='*.raw' -C /tmp s; }
stream() { local bin=$1 v=$2 budget=$3 tag=$4
  nvidia-smi --query-gpu=timestamp,memory.used --format=csv,noheader -lms 50 > /tmp/s/smi-$tag.log 2>&1 & smi=$!
  RUST_LOG=leapview=debug timeout 120 python3 .bench-data/rss.py /tmp/$bin bench --stream $v --gpu-budget $budget --out /tmp/s/$tag > /tmp/s/$tag.log 2>&1
  kill $smi; echo "$tag done at $((SECONDS-start)) s" >> /tmp/s/gen.txt; pack
}
nvidia-smi > /tmp/s/smi.txt 2>&1
for n in 256 512 1024; do /tmp/bfr generate vessels --size $n --out /tmp/v$n.nhdr > /dev/null 2>&1; done
python3 scripts/tile-volume.py /tmp/v1024.raw /tmp/big.raw 1024
sed -e 's/sizes: 1024 1024 1024/sizes: 2048 2048 1024/' -e 's/v1024.raw/big.raw/' /tmp/v1024.nhdr > /tmp/big.nhdr
echo "data at $((SECONDS-start)) s" >> /tmp/s/gen.txt
stream bfr /tmp/big.nhdr 1GB big-1
stream bfr /tmp/big.nhdr 1GB big-2
stream bfr /tmp/v1024.nhdr 1GB v1024-1g
stream bfr /tmp/v1024.nhdr 256MB v1024-256m
stream bfr /tmp/v512.nhdr 1GB v512-1g
stream bfr /tmp/v256.nhdr 1GB v256-1g
