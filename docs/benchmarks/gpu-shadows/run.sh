#!/bin/bash
# Shadows in lit DVR (issue 42): frame time with shadow rays against Phong DVR without them, at
# 1920x1080 on the GPU machine (compute path, `render --stats`: the median of 5 frames' GPU time).
# Prepared here (ignored by git; 64 MiB carried at most): a stripped release build, xz -9e, as
# .bench-data/leapview.xz; the shared scans
# mra_head_200x256x120_uint8.nrrd and originals/VolumeRenderingData_seg3D_MR.nii.gz copied into
# .bench-data; the 512^3 dense head and vessels generated there.
# Run: for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig; export LEAPVIEW_BACKEND=vulkan;
#      bash docs/benchmarks/gpu-shadows/run.sh   (carry .bench-data and .gl)
B=.bench-data
xz -dkf $B/leapview.xz; chmod +x $B/leapview; L=$B/leapview
[ -f $B/head512.nrrd ] || $L generate dense-head --size 512 --out $B/head512.nrrd > /dev/null 2>&1
[ -f $B/vessels512.nrrd ] || $L generate vessels --size 512 --out $B/vessels512.nrrd > /dev/null 2>&1
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader >> $OUT/shadows.txt
mkdir -p /tmp/s
run() { local name=$1; shift; { echo "## $name: $*"; $L render "$@" --size 1920x1080 --stats -o /tmp/s/$name.png 2>&1 | grep -E "gpu_ms|strategy|error|shadow rays"; } >> $OUT/shadows.txt; }
LIGHT="--light=0.5,0.6,0.62"
for D in $B/mra_head_200x256x120_uint8.nrrd $B/VolumeRenderingData_seg3D_MR.nii.gz $B/head512.nrrd $B/vessels512.nrrd; do
  n=$(basename $D | cut -d_ -f1-2 | cut -d. -f1)
  for S in rc-s-df rc-t; do
    run $n-$S-phong $D --strategy $S $LIGHT
    run $n-$S-shadows $D --strategy $S $LIGHT --shadows on
    [ $S = rc-t ] && continue
    run $n-$S-shadows-step2 $D --strategy $S $LIGHT --shadows on --shadow-step 2
    run $n-$S-shadows-reach025 $D --strategy $S $LIGHT --shadows on --shadow-reach 0.25
    run $n-$S-shadows-weight003 $D --strategy $S $LIGHT --shadows on --light-min-weight 0.003
    run $n-$S-shadows-headlight $D --strategy $S --shadows on
  done
done
cd /tmp/s && tar czf $OUT/shadow-pngs.tgz *-rc-s-df-phong.png *-rc-s-df-shadows.png
