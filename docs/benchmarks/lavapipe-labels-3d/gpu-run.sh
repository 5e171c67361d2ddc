#!/bin/bash
# Segmentations in 3D on the GPU machine: plain DVR against the labels' views at 1920x1080.
B=.bench-data
xz -dkf $B/leapview.xz; chmod +x $B/leapview; L=$B/leapview
nvidia-smi --query-gpu=name,memory.total --format=csv > $OUT/gpu.txt 2>&1
$L generate dense-head --size 512 --out $B/head512.nrrd > $OUT/generate.txt 2>&1
run() { # name, file, args...
  local name=$1; shift
  { echo "## $name: $*"; $L render "$@" --size 1920x1080 --stats -o $OUT/$name.png 2>&1; } >> $OUT/results.txt
}
for S in rc-t rc-s-df; do
  for V in "mr $B/VolumeRenderingData_seg3D_MR.nii.gz $B/mr_head_t1_seg3d_parcels.nii.gz" "head512 $B/head512.nrrd $B/parcels512.nrrd"; do
    set -- $V; name=$1; img=$2; lab=$3
    run $name-$S-plain $img --strategy $S
    run $name-$S-colour $img --strategy $S --labels $lab
    run $name-$S-inside $img --strategy $S --labels $lab --label-view inside
    run $name-$S-inside-3 $img --strategy $S --labels $lab --label-view inside --show-labels 1,2,3
    M=$S; [ $S = rc-s-df ] && M=rc-s
    run $name-$M-mip-inside-3 $img --mode mip --strategy $M --labels $lab --label-view colour-inside --show-labels 1,2,3
  done
done
# Only the 1080p PNGs of the MR come back (the rest stay).
mkdir -p $OUT/keep; mv $OUT/mr-rc-s-df-*.png $OUT/keep/ 2>/dev/null; rm -f $OUT/*.png
