#!/usr/bin/env bash
# A store larger than memory on the GPU machine (issue 40, item 7): generates the dense head of
# 2048 × 2048 × 4096 uint16 (32 GiB of samples) as an OME-Zarr store slab by slab, then opens it
# with `info` and streams it with `bench --stream` under --ram-budget 8GiB --gpu-budget 4GiB at
# 1920 × 1080. The store is generated in the background and kept in /tmp, so that a second call
# on the still-warm machine (the tool's 10-minute limit a call) goes on where the first stopped.
#
#   scripts/gpu-ooc.sh ARCHIVE OUT
#
# ARCHIVE: a tar.xz holding one stripped build named `leapview` (in .bench-data; carry it and .gl).
# Writes OUT/ooc.tgz: generate.log, info.txt, stream/ (stream.md, stream.csv), time logs.
set -euo pipefail
cd "$(dirname "$0")/.."
archive=$1
out=$2
source scripts/gpu-env.sh || exit 1
mkdir -p /tmp/ooc "$out"
if [[ ! -x /tmp/ooc/leapview ]]; then
    tar xJf "$archive" -C /tmp/ooc
fi
bin=/tmp/ooc/leapview
store=/tmp/ooc/head-2048x2048x4096.ome.zarr
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader >/tmp/ooc/gpu.txt || true
nproc >/tmp/ooc/cores.txt
if [[ ! -d $store ]] && ! pgrep -f "leapview generate" >/dev/null; then
    nohup /usr/bin/time -v "$bin" generate dense-head --dims 2048,2048,4096 --type uint16 \
        --out "$store" >/tmp/ooc/generate.log 2>&1 &
fi
# Wait for the store (at most 8.5 minutes in this call).
for _ in $(seq 1020); do
    [[ -d $store ]] && break
    sleep 0.5
done
pack() { tar czf "$out/ooc.tgz" -C /tmp/ooc --exclude=leapview --exclude='*.zarr' --exclude='.*.partial-*' . ; }
if [[ ! -d $store ]]; then
    du -sh /tmp/ooc/.head* >>/tmp/ooc/generate.log 2>&1 || true
    pack
    echo "the store is not written yet: call again"
    exit 0
fi
du -sb "$store" >/tmp/ooc/store-bytes.txt
/usr/bin/time -v "$bin" info "$store" --ram-budget 8GiB >/tmp/ooc/info.txt 2>/tmp/ooc/info.time
/usr/bin/time -v "$bin" bench --stream "$store" --out /tmp/ooc/stream --ram-budget 8GiB \
    --gpu-budget 4GiB --stream-size 1920x1080 >/tmp/ooc/stream.log 2>/tmp/ooc/stream.time
pack
cat /tmp/ooc/stream/stream.md
