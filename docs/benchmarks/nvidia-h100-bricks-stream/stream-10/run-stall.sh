#!/usr/bin/env bash
# Streaming with bf (branch-free brick reads; 7eba639's atlas fit) beside nvidia-smi, then the
# fragment path: one texture, main (2e541e3) and bf bricked.
set -u
start=$SECONDS
source scripts/gpu-env.sh
mkdir -p /tmp/s /tmp/bins
tar xJf .bench-data/bins.tar.xz -C /tmp/bins
pack() { tar czf $OUT/s.tgz --exclude='*.raw' -C /tmp s; }
stream() { local bin=$1 v=$2 budget=$3 tag=$4
  nvidia-smi --query-gpu=timestamp,memory.used --format=csv,noheader -lms 50 > /tmp/s/smi-$tag.log 2>&1 & smi=$!
  RUST_LOG=leapview=debug timeout 120 python3 .bench-data/rss.py /tmp/bins/$bin bench --stream $v --gpu-budget $budget --out /tmp/s/$tag > /tmp/s/$tag.log 2>&1
  kill $smi; echo "$tag done at $((SECONDS-start)) s" >> /tmp/s/gen.txt; pack
}
/tmp/bins/bf generate vessels --size 1024 --out /tmp/v1024.nhdr > /dev/null 2>&1
python3 scripts/tile-volume.py /tmp/v1024.raw /tmp/big.raw 1024
sed -e 's/sizes: 1024 1024 1024/sizes: 2048 2048 1024/' -e 's/v1024.raw/big.raw/' /tmp/v1024.nhdr > /tmp/big.nhdr
echo "data at $((SECONDS-start)) s" >> /tmp/s/gen.txt
stream bf /tmp/v1024.nhdr 1GB v1024-1g
stream bf /tmp/big.nhdr 1GB big-1g
stream bf /tmp/v1024.nhdr 256MB v1024-256m
rm -f /tmp/big.raw
scripts/gpu-ab.sh .bench-data/bins.tar.xz $OUT 1 --config bench/config.json --data-dir .bench-data --paths fragment --strategies rc-t,rc-s-df --datasets ct_bonsai,vessels,dense_head 2>&1 | tail -5
echo "all done at $((SECONDS-start)) s" >> /tmp/s/gen.txt; pack
