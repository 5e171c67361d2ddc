#!/usr/bin/env bash
# What a slice view costs beside a 3D frame of the same size (issue 17, item 6), by GPU timestamps:
# `leapview render --stats` (3D DVR and MIP, default strategy and path) and
# `leapview slice --repeat 200` at 512x512 and 1920x1080 on the volumes named:
#   - a 1 x 1 slice: the floor of one timed pass on this GPU, whatever it does;
#   - thin axial and oblique slices as the window draws them (the texture unit's trilinear, grey
#     written into the texture on screen), and the axial one by the exact variant (--exact:
#     eight texel loads, values and grey to buffers);
#   - 20 mm coronal slabs, MIP and mean, leaping over the bricks and taking every sample
#     (--no-leap), the ratio the leaping gives;
#   - the axial slice coloured by the transfer function (--tf auto).
# Usage: scripts/slice-cost.sh LEAPVIEW_BINARY OUT_FOLDER VOLUME...
set -euo pipefail
bin=$1; out=$2; shift 2
mkdir -p "$out"
for volume in "$@"; do
  name=$(basename "$volume")
  echo "== $name 1x1 slice axial (the floor of a timed pass)"
  "$bin" slice "$volume" --size 1x1 --repeat 200 --out "$out/floor-$name.png" | grep 'GPU time'
  for size in 512x512 1920x1080; do
    for mode in dvr mip; do
      echo "== $name $size render $mode"
      "$bin" render "$volume" --size "$size" --mode "$mode" --stats --out "$out/render-$name-$size-$mode.png" \
        | grep -E 'adapter|gpu_ms'
    done
    for plane in axial 0,0.5,1; do
      echo "== $name $size slice $plane"
      "$bin" slice "$volume" --plane "$plane" --size "$size" --repeat 200 --out "$out/slice-$name-$size.png" \
        | grep 'GPU time'
    done
    echo "== $name $size slice axial --tf auto (coloured by the transfer function)"
    "$bin" slice "$volume" --plane axial --tf auto --size "$size" --repeat 200 --out "$out/tf-$name-$size.png" \
      | grep 'GPU time'
    echo "== $name $size slice axial --exact"
    "$bin" slice "$volume" --plane axial --exact --size "$size" --repeat 200 --out "$out/exact-$name-$size.png" \
      | grep 'GPU time'
    for slab in mip mean; do
      for leap in "" --no-leap; do
        echo "== $name $size slice coronal slab 20 mm $slab ${leap:-leaping}"
        "$bin" slice "$volume" --plane coronal --slab 20 --mode "$slab" $leap --size "$size" --repeat 200 \
          --out "$out/slab-$name-$size-$slab$leap.png" | grep 'GPU time'
      done
    done
  done
done
