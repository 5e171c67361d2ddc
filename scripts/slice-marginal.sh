#!/usr/bin/env bash
# What one more slice adds to a frame's GPU work (issue 17, item 6): `leapview slice --repeat`
# times each slice in a pass of its own between two timestamps, then 50 slices per timed pass
# (the pass's fixed cost spread over them); thin axial slices at 1x1, 512x512 and 1920x1080 and a
# 20 mm coronal MIP slab at 1920x1080, on the volumes named.
# Usage: scripts/slice-marginal.sh LEAPVIEW_BINARY VOLUME...
set -euo pipefail
bin=$1; shift
for volume in "$@"; do
  name=$(basename "$volume")
  for size in 1x1 512x512 1920x1080; do
    echo "== $name $size slice axial"
    "$bin" slice "$volume" --size "$size" --repeat 200 --out /tmp/slice-marginal.png | grep 'GPU time'
  done
  echo "== $name 1920x1080 slice coronal slab 20 mm mip"
  "$bin" slice "$volume" --plane coronal --slab 20 --size 1920x1080 --repeat 20 --out /tmp/slice-marginal.png \
    | grep 'GPU time'
done
