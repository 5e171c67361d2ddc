"""A Siemens mosaic for LeapView's tests: nibabel's own test file (a diffusion-weighted MR
mosaic, 48 slices of 128 x 128 in a 896 x 896 image, its pixels zeroed by its publishers), its
pixels replaced by a pattern that names each tile and pixel, and nibabel's unpacking of it.

    python nibabel_mosaic.py OUT

Writes OUT/mosaic.dcm, OUT/mosaic.f64 (nibabel's volume, column fastest, then row, then slice,
little-endian float64) and OUT/mosaic.json (its shape and its affine from (column, row, slice)
to DICOM's LPS millimetres).
"""

import gzip
import json
import os
import sys

import nibabel.nicom
import nibabel.nicom.dicomwrappers as wrappers
import numpy as np
import pydicom


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    source = os.path.join(
        os.path.dirname(nibabel.nicom.__file__), "tests", "data", "siemens_dwi_1000.dcm.gz"
    )
    with gzip.open(source) as f:
        ds = pydicom.dcmread(f)
    rows, columns = int(ds.Rows), int(ds.Columns)
    y, x = np.mgrid[0:rows, 0:columns]
    tile = (y // 128) * 7 + x // 128
    # BitsStored is 12: every value below 4096, each tile's and each quarter's its own.
    pattern = (tile * 80 + (x % 128) // 4 + 32 * ((y % 128) // 64)).astype(np.uint16)
    ds.PixelData = pattern.tobytes()
    path = os.path.join(out, "mosaic.dcm")
    ds.save_as(path)
    wrapper = wrappers.wrapper_from_data(pydicom.dcmread(path))
    # nibabel indexes (row, column, slice); LeapView (column, row, slice).
    data = wrapper.get_data().astype(np.float64).transpose(1, 0, 2)
    affine = wrapper.affine[:, [1, 0, 2, 3]]
    data.ravel(order="F").astype("<f8").tofile(os.path.join(out, "mosaic.f64"))
    with open(os.path.join(out, "mosaic.json"), "w") as f:
        json.dump({"shape": list(data.shape), "affine": affine.tolist()}, f)


if __name__ == "__main__":
    main()
