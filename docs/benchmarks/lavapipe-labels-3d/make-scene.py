"""The 512^3 labelled scene of gpu-run.sh: the MR head's 120 parcels (nibabel's file in
../shared/data/labels/) nearest-upsampled onto the grid of `leapview generate dense-head --size 512`
(512^3, 0.390625 mm, no origin), written as a gzip NRRD of uint16 labels: a timing scene, not
anatomy. Run from the repository root with the tests' .venv:
    .venv/bin/python docs/benchmarks/lavapipe-labels-3d/make-scene.py .bench-data/parcels512.nrrd
"""
import gzip
import sys

import nibabel as nib
import numpy as np

src = nib.load("../shared/data/labels/mr_head_t1_seg3d_parcels.nii.gz")
a = np.asarray(src.dataobj).astype(np.uint16)
n = 512
idx = [np.minimum((np.arange(n) * s) // n, s - 1) for s in a.shape]
out = a[np.ix_(idx[0], idx[1], idx[2])]
header = (
    "NRRD0004\n# the MR head's 120 parcels, nearest-upsampled onto the dense head's 512^3 grid\n"
    "type: uint16\ndimension: 3\nsizes: 512 512 512\nspacings: 0.390625 0.390625 0.390625\n"
    "kinds: domain domain domain\nendian: little\nencoding: gzip\n\n"
)
with open(sys.argv[1], "wb") as f:
    f.write(header.encode())
    # NRRD stores x fastest: the array's Fortran order.
    f.write(gzip.compress(out.astype("<u2").tobytes(order="F"), 6))
