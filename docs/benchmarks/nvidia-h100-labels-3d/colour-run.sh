#!/bin/bash
# Colouring by 120 labels against plain DVR at 1920x1080, after the review's shader change.
B=.bench-data
xz -dkf $B/leapview.xz; chmod +x $B/leapview; L=$B/leapview
$L generate dense-head --size 512 --out $B/head512.nrrd > /dev/null 2>&1
run() { local name=$1; shift; { echo "## $name: $*"; $L render "$@" --size 1920x1080 --stats -o /tmp/$name.png 2>&1; } >> $OUT/results.txt; }
for S in rc-t rc-s-df; do
  run mr-$S-plain $B/VolumeRenderingData_seg3D_MR.nii.gz --strategy $S
  run mr-$S-colour $B/VolumeRenderingData_seg3D_MR.nii.gz --strategy $S --labels $B/mr_head_t1_seg3d_parcels.nii.gz
  run head512-$S-plain $B/head512.nrrd --strategy $S
  run head512-$S-colour $B/head512.nrrd --strategy $S --labels $B/parcels512.nrrd
done
