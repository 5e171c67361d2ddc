"""What pydicom makes of DICOM images: the reference LeapView's reader is tested against.

    python pydicom_reference.py OUT [FILE ...]

Every file of pydicom's own test files (shipped with the pydicom wheel), then each FILE. For each
file, OUT/manifest.json gets an entry: whether pydicom decodes its pixels (and if not, why), the
array's shape, and whether the samples are colour (RGB: `pixel_array` converts YBR to RGB, and a
palette is applied here); the samples themselves go to OUT/<n>.f64 as little-endian float64, frames first, then
rows, columns and samples: the stored values (no rescale), as `Dataset.pixel_array` gives them.
"""

import json
import os
import sys

import numpy as np
import pydicom
import pydicom.data
from pydicom.pixels import apply_color_lut


def test_files():
    folder = os.path.join(os.path.dirname(pydicom.data.__file__), "test_files")
    for root, _, names in os.walk(folder):
        for name in sorted(names):
            if name.endswith(".dcm") or "." not in name:
                yield os.path.join(root, name)


def reference(path):
    entry = {"file": path}
    try:
        ds = pydicom.dcmread(path)
    except Exception as e:  # noqa: BLE001: any failure is the reference's answer
        entry.update(dicom=False, error=f"{type(e).__name__}: {e}")
        return entry, None
    entry["dicom"] = True
    if "PixelData" not in ds:
        entry.update(image=False)
        return entry, None
    entry["image"] = True
    entry["photometric"] = str(ds.get("PhotometricInterpretation", ""))
    entry["transfer_syntax"] = str(ds.file_meta.get("TransferSyntaxUID", ""))
    try:
        frames = int(ds.get("NumberOfFrames", 1) or 1)
        array = ds.pixel_array
        photometric = entry["photometric"]
        if photometric == "PALETTE COLOR":
            array = apply_color_lut(array, ds)
    except Exception as e:  # noqa: BLE001
        entry.update(decoded=False, error=f"{type(e).__name__}: {e}")
        return entry, None
    colour = array.ndim >= 3 and array.shape[-1] == 3 and int(ds.get("SamplesPerPixel", 1)) == 3 or (
        entry["photometric"] == "PALETTE COLOR"
    )
    if frames == 1:
        array = array[np.newaxis, ...]
    entry.update(
        decoded=True,
        frames=frames,
        rows=int(array.shape[1]),
        columns=int(array.shape[2]),
        colour=bool(colour),
        lossy=entry["transfer_syntax"]
        in (
            "1.2.840.10008.1.2.4.50",
            "1.2.840.10008.1.2.4.51",
            "1.2.840.10008.1.2.4.81",
            "1.2.840.10008.1.2.4.91",
            "1.2.840.10008.1.2.4.93",
        )
        or str(ds.get("LossyImageCompression", "00")) == "01",
    )
    return entry, array.astype("<f8")


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    paths = list(test_files()) + sys.argv[2:]
    manifest = []
    for n, path in enumerate(paths):
        entry, array = reference(path)
        if array is not None:
            entry["samples"] = f"{n}.f64"
            array.tofile(os.path.join(out, entry["samples"]))
        manifest.append(entry)
    with open(os.path.join(out, "manifest.json"), "w") as f:
        json.dump(manifest, f, indent=1)


if __name__ == "__main__":
    main()
