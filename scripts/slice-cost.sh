#!/usr/bin/env bash
# What a slice view costs beside a 3D frame of the same size (issue 17, item 6), by GPU timestamps:
# `leapview render --stats` (3D DVR and MIP, default strategy and path) and
# `leapview slice --repeat 200` (axial, oblique, 20 mm MIP slab), at 512x512 and 1920x1080, on the
# volumes named. Usage: scripts/slice-cost.sh LEAPVIEW_BINARY OUT_FOLDER VOLUME...
set -euo pipefail
bin=$1; out=$2; shift 2
mkdir -p "$out"
for volume in "$@"; do
  name=$(basename "$volume")
  for size in 512x512 1920x1080; do
    for mode in dvr mip; do
      echo "== $name $size render $mode"
      "$bin" render "$volume" --size "$size" --mode "$mode" --stats --out "$out/render-$name-$size-$mode.png"
    done
    for plane in axial 0,0.5,1; do
      echo "== $name $size slice $plane"
      "$bin" slice "$volume" --plane "$plane" --size "$size" --repeat 200 --out "$out/slice-$name-$size.png"
    done
    echo "== $name $size slice coronal slab 20 mm mip"
    "$bin" slice "$volume" --plane coronal --slab 20 --mode mip --size "$size" --repeat 200 \
      --out "$out/slab-$name-$size.png"
  done
done
