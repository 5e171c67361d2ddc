#!/usr/bin/env bash
# The stream suite beside nvidia-smi (every 50 ms), for one build: bfr (2e541e3 + branch-free
# brick reads + the ranges worker on a pool of its own), mem2 (bfr + the budget keeping back the
# driver's context and an allocator block, Manual 4-16 MB blocks) or m3 (ebbf774: mem2 + the
# first frame sending bricks uncapped by page entries). Each was one device call:
#   .bench-data/run.sh BUILD     with the stripped build at .bench-data/BUILD.xz
# Writes /tmp/s/NAME/stream.{csv,md}, NAME.log and smi-NAME.log; the files here are those,
# renamed NAME-BUILD.
set -u
build=$1
start=$SECONDS
source scripts/gpu-env.sh
mkdir -p /tmp/s
xz -dc .bench-data/$build.xz > /tmp/$build; chmod +x /tmp/$build
pack() { tar czf $OUT/s.tgz --exclude='*.raw' -C /tmp s; }
stream() { local v=$1 budget=$2 tag=$3
  nvidia-smi --query-gpu=timestamp,memory.used --format=csv,noheader -lms 50 > /tmp/s/smi-$tag.log 2>&1 & smi=$!
  RUST_LOG=leapview=debug timeout 120 python3 .bench-data/rss.py /tmp/$build bench --stream $v --gpu-budget $budget --out /tmp/s/$tag > /tmp/s/$tag.log 2>&1
  kill $smi; echo "$tag done at $((SECONDS-start)) s" >> /tmp/s/gen.txt; pack
}
nvidia-smi > /tmp/s/smi.txt 2>&1
for n in 256 512 1024; do /tmp/$build generate vessels --size $n --out /tmp/v$n.nhdr > /dev/null 2>&1; done
python3 scripts/tile-volume.py /tmp/v1024.raw /tmp/big.raw 1024
sed -e 's/sizes: 1024 1024 1024/sizes: 2048 2048 1024/' -e 's/v1024.raw/big.raw/' /tmp/v1024.nhdr > /tmp/big.nhdr
echo "data at $((SECONDS-start)) s" >> /tmp/s/gen.txt
stream /tmp/big.nhdr 1GB big-1
stream /tmp/big.nhdr 1GB big-2
stream /tmp/v1024.nhdr 1GB v1024-1g
stream /tmp/v1024.nhdr 256MB v1024-256m
stream /tmp/v512.nhdr 1GB v512-1g
stream /tmp/v256.nhdr 1GB v256-1g
