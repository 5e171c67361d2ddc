#!/bin/bash
# Label toggles with the surfaces' mask remade over the toggled label's box, and labels that
# travel in the volume's bricks (colour, inside, surfaces), at 1920x1080 on the GPU machine
# (compute path, --stats).
# Prepared here (ignored by git; 64 MiB carried at most):
#   cp ../shared/data/originals/VolumeRenderingData_seg3D_MR.nii.gz \
#      ../shared/data/labels/mr_head_t1_seg3d_parcels.nii.gz .bench-data/
#   .venv/bin/python docs/benchmarks/lavapipe-labels-3d/make-scene.py /tmp/p.nrrd, then that
#      file's gzip payload as a raw NRRD, xz -9: .bench-data/parcels512_raw.nrrd.xz
#   .venv/bin/python scripts/python/label_files.py --long 16400 .bench-data (long_*.nii.gz)
#   a stripped release build, xz -9e: .bench-data/leapview.xz
# Run: for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig; export LEAPVIEW_BACKEND=vulkan;
#      bash docs/benchmarks/gpu-label-toggle/run.sh   (carry .bench-data and .gl)
B=.bench-data
xz -dkf $B/leapview.xz; chmod +x $B/leapview; L=$B/leapview
$L generate dense-head --size 512 --out $B/head512.nrrd > /dev/null 2>&1
# The parcels upsampled onto that grid (../lavapipe-labels-3d/make-scene.py), carried as xz raw NRRD.
xz -dc $B/parcels512_raw.nrrd.xz > $B/parcels512.nrrd
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader >> $OUT/results.txt
run() { local name=$1; shift; { echo "## $name: $*"; $L render "$@" --size 1920x1080 --stats -o /tmp/o/$name.png 2>&1 | grep -v "^  "; } >> $OUT/results.txt; }
mkdir -p /tmp/o
MR=$B/VolumeRenderingData_seg3D_MR.nii.gz; P=$B/mr_head_t1_seg3d_parcels.nii.gz
for S in rc-t rc-s-df; do
  run mr-$S-surfaces $MR --strategy $S --labels $P --label-view surfaces
  run mr-$S-surfaces-half $MR --strategy $S --labels $P --label-view surfaces --label-opacity 0.5
  run head512-$S-surfaces-half $B/head512.nrrd --strategy $S --labels $B/parcels512.nrrd --label-view surfaces --label-opacity 0.5
  run head512-$S-colour $B/head512.nrrd --strategy $S --labels $B/parcels512.nrrd
done
# A bar of 16400 x 48 x 48: past the GPU's 3D textures (16384), so the image and its labels
# travel in bricks; seen from the side at its middle (labels 1 and 2 meet there) and from one end
# along it (every ray through all 16400 voxels).
BAR=$B/long_image.nii.gz; BL=$B/long_labels.nii.gz
side="--eye=8200,-150,60 --target 8200,24,24"; end="--eye=-60,24,24 --target 200,24,24"
for S in rc-t rc-s-df; do
  for V in side end; do
    run bar-$V-$S-plain $BAR ${!V} --strategy $S --tf ct-bone
    run bar-$V-$S-colour $BAR ${!V} --strategy $S --tf ct-bone --labels $BL
  done
  run bar-side-$S-inside $BAR $side --strategy $S --tf ct-bone --labels $BL --label-view inside --show-labels 2
  # Surfaces of labels in bricks: their mask on the labels' grid halved (8200 x 24 x 24).
  for V in side end; do
    run bar-$V-$S-surfaces $BAR ${!V} --strategy $S --tf ct-bone --labels $BL --label-view surfaces
  done
done
cd /tmp/o && tar czf $OUT/pngs.tgz mr-rc-t-surfaces-half.png head512-rc-t-surfaces-half.png bar-*-rc-t-*.png
