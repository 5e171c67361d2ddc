#!/bin/bash
# Label surfaces with walls between touching labels drawn from class channels (a channel of the
# mask per class of shown labels), opaque and at half opacity, against plain DVR at 1920x1080.
B=.bench-data
xz -dkf $B/leapview.xz; chmod +x $B/leapview; L=$B/leapview
$L generate dense-head --size 512 --out $B/head512.nrrd > /dev/null 2>&1
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader >> $OUT/results.txt
run() { local name=$1; shift; { echo "## $name: $*"; $L render "$@" --size 1920x1080 --stats -o /tmp/o/$name.png 2>&1 | grep -v "^  "; } >> $OUT/results.txt; }
mkdir -p /tmp/o
MR=$B/VolumeRenderingData_seg3D_MR.nii.gz; P=$B/mr_head_t1_seg3d_parcels.nii.gz
for S in rc-t rc-s-df; do
  run mr-$S-plain $MR --strategy $S
  run mr-$S-surfaces $MR --strategy $S --labels $P --label-view surfaces
  run mr-$S-surfaces-half $MR --strategy $S --labels $P --label-view surfaces --label-opacity 0.5
  run mr-$S-surfaces-third $MR --strategy $S --labels $P --label-view surfaces --label-opacity 0.3
  run head512-$S-plain $B/head512.nrrd --strategy $S
  run head512-$S-surfaces-half $B/head512.nrrd --strategy $S --labels $B/parcels512.nrrd --label-view surfaces --label-opacity 0.5
done
for S in rc-t rc-s; do
  run mr-$S-mip-plain $MR --strategy $S --mode mip
  run mr-$S-mip-surfaces-half $MR --strategy $S --mode mip --labels $P --label-view surfaces --label-opacity 0.5
done
cd /tmp/o && tar czf $OUT/pngs.tgz mr-rc-t-surfaces-half.png mr-rc-t-surfaces.png head512-rc-t-surfaces-half.png
