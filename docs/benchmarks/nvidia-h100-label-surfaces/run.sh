#!/bin/bash
# Colour (the d539c81 shader) and surfaces against plain DVR at 1920x1080, 120 labels.
B=.bench-data
xz -dkf $B/leapview.xz; chmod +x $B/leapview; L=$B/leapview
$L generate dense-head --size 512 --out $B/head512.nrrd > /dev/null 2>&1
nvidia-smi --query-gpu=name --format=csv,noheader >> $OUT/results.txt
run() { local name=$1; shift; { echo "## $name: $*"; $L render "$@" --size 1920x1080 --stats -o $OUT/$name.png 2>&1 | grep -v "^  "; } >> $OUT/results.txt; }
for S in rc-t rc-s-df; do
  run mr-$S-plain $B/VolumeRenderingData_seg3D_MR.nii.gz --strategy $S
  run mr-$S-colour $B/VolumeRenderingData_seg3D_MR.nii.gz --strategy $S --labels $B/mr_head_t1_seg3d_parcels.nii.gz
  run mr-$S-surfaces $B/VolumeRenderingData_seg3D_MR.nii.gz --strategy $S --labels $B/mr_head_t1_seg3d_parcels.nii.gz --label-view surfaces
  run head512-$S-plain $B/head512.nrrd --strategy $S
  run head512-$S-colour $B/head512.nrrd --strategy $S --labels $B/parcels512.nrrd
  run head512-$S-surfaces $B/head512.nrrd --strategy $S --labels $B/parcels512.nrrd --label-view surfaces
done
for S in rc-t rc-s; do
  run head512-$S-mip-plain $B/head512.nrrd --strategy $S --mode mip
  run head512-$S-mip-surfaces $B/head512.nrrd --strategy $S --mode mip --labels $B/parcels512.nrrd --label-view surfaces
done
