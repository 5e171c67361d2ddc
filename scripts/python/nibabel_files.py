"""NIfTI files written by nibabel, the reference NIfTI implementation, for LeapView's tests.

    python nibabel_files.py OUT

Writes into OUT, for each case, `<case>.nii` or `.nii.gz` (or names one of nibabel's own test
files) and `<case>.f64`: the data nibabel holds for the volume LeapView is to open, in data units
(scl_slope and scl_inter applied), x fastest, little-endian float64; and `cases.json` listing the
cases with the file, the volume to open (counted from 0), the dimensions and nibabel's affine
(RAS).
"""

import json
import os
import sys

import nibabel as nib
import numpy as np


def cases():
    rng = np.random.default_rng(7)
    affine = np.diag([0.9, 1.1, 2.5, 1.0])
    affine[:3, 3] = [-10.0, 20.0, 5.5]
    base = np.arange(5 * 4 * 3, dtype=np.float32).reshape(5, 4, 3)
    # A time series: volume t holds base * (t + 1) + noise, so that each volume differs.
    series = np.stack([base * (t + 1) + rng.normal(0, 0.25, base.shape) for t in range(6)], axis=-1)
    yield "fmri_4d", nib.Nifti1Image(series.astype(np.float32), affine), ".nii.gz", 3
    yield "fmri_4d_first", nib.Nifti1Image(series.astype(np.float32), affine), ".nii", 0
    yield "nifti2_int16", nib.Nifti2Image((base * 7 - 100).astype(np.int16), affine), ".nii", 0
    yield "nifti2_4d", nib.Nifti2Image(series.astype(np.float64), affine), ".nii.gz", 5
    big = nib.Nifti1Image((base * 3).astype(">u2"), affine)
    yield "big_endian", big, ".nii", 0
    scaled = nib.Nifti1Image((base).astype(np.int16), affine)
    scaled.header.set_slope_inter(0.5, -3.0)
    yield "scaled", scaled, ".nii", 0
    # An MR-like volume with negative values and no modality (a bias-corrected or filtered MR,
    # a statistics map): values from −800 to 1200, no air peak at −1000, no tissue peak at 40.
    mr = (np.sin(np.arange(24 * 20 * 16) / 37.0).reshape(24, 20, 16) * 1000.0 + 200.0).astype(np.float32)
    yield "mr_negative", nib.Nifti1Image(mr, affine), ".nii.gz", 0


# NIfTI files from nibabel's own test data (written by SPM, FSL, AFNI and nibabel over the
# years): opened as they are, compared with nibabel's reading.
SHIPPED = [
    ("example4d.nii.gz", 2),
    ("example_nifti2.nii.gz", 1),
    ("anatomical.nii", 0),
    ("functional.nii", 5),
    ("standard.nii.gz", 0),
    ("reoriented_anat_moved.nii", 0),
]


def shipped():
    data = os.path.join(os.path.dirname(nib.__file__), "tests", "data")
    for name, volume in SHIPPED:
        path = os.path.join(data, name)
        if os.path.exists(path):
            yield name.split(".")[0], path, volume


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    listing = []
    for name, source, volume in shipped():
        image = nib.load(source)
        data = np.asanyarray(image.dataobj).astype(np.float64)
        if data.ndim == 4:
            volume = min(volume, data.shape[3] - 1)
            data = data[..., volume]
        else:
            volume = 0
        data.ravel(order="F").astype("<f8").tofile(os.path.join(out, name + ".f64"))
        listing.append(
            {
                "name": name,
                "file": source,
                "volume": volume,
                "volumes": int(np.prod(image.shape[3:])) if len(image.shape) > 3 else 1,
                "dims": [int(d) for d in image.shape[:3]],
                "affine": image.affine.tolist(),
                "shipped": True,
            }
        )
    for name, image, suffix, volume in cases():
        path = os.path.join(out, name + suffix)
        nib.save(image, path)
        data = np.asanyarray(nib.load(path).dataobj).astype(np.float64)
        if data.ndim == 4:
            data = data[..., volume]
        # NIfTI stores x fastest: Fortran order.
        data.ravel(order="F").astype("<f8").tofile(os.path.join(out, name + ".f64"))
        listing.append(
            {
                "name": name,
                "file": os.path.basename(path),
                "volume": volume,
                "volumes": int(np.prod(image.shape[3:])) if len(image.shape) > 3 else 1,
                "dims": [int(d) for d in image.shape[:3]],
                "affine": image.affine.tolist(),
                "shipped": False,
            }
        )
    with open(os.path.join(out, "cases.json"), "w") as f:
        json.dump(listing, f, indent=1)


if __name__ == "__main__":
    main()
