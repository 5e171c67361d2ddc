"""A ball of label 1 and an empty image beside it, written by nibabel: LeapView's label surfaces
are checked against the analytic sphere's normals (tests/integration/label_surfaces.rs).

    python sphere_labels.py OUT

Writes `OUT/sphere_image.nii.gz` (uint8 zeros, 40³, 1 mm, identity affine) and
`OUT/sphere_labels.nii.gz` (uint8: 1 within 13.3 voxels of the grid's centre, else 0).
"""

import os
import sys

import nibabel as nib
import numpy as np


def main(out):
    n = 40
    c = (n - 1) / 2.0
    i, j, k = np.meshgrid(*[np.arange(n)] * 3, indexing="ij")
    ball = ((i - c) ** 2 + (j - c) ** 2 + (k - c) ** 2) <= 13.3**2
    affine = np.eye(4)
    image = np.zeros((n, n, n), dtype=np.uint8)
    # One voxel of value 1 far from the ball: the image is not wholly uniform.
    image[0, 0, 0] = 1
    nib.save(nib.Nifti1Image(image, affine), os.path.join(out, "sphere_image.nii.gz"))
    nib.save(
        nib.Nifti1Image(ball.astype(np.uint8), affine),
        os.path.join(out, "sphere_labels.nii.gz"),
    )


if __name__ == "__main__":
    main(sys.argv[1])
