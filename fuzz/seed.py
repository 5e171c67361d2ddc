"""Seeds the fuzz targets from files other software wrote (not committed: `seeds/` is ignored).

    ../.venv/bin/python seed.py

- codec_stream: every JPEG, JPEG-LS, JPEG 2000 and RLE frame among pydicom's test files, each
  behind the byte that picks its codec (0 JPEG, 1 JPEG-LS, 2 JPEG 2000, 3 RLE);
- dicom_file: pydicom's test files of at most 200 kB (every codec, byte order and oddity);
- nifti_file: nibabel's small NIfTI test files (3-D, 4-D, NIfTI-2).
"""

import glob
import os
import shutil

import nibabel
import pydicom
import pydicom.data
from pydicom.encaps import generate_frames

HERE = os.path.dirname(os.path.abspath(__file__))
CODECS = {
    "1.2.840.10008.1.2.4.50": 0,
    "1.2.840.10008.1.2.4.51": 0,
    "1.2.840.10008.1.2.4.57": 0,
    "1.2.840.10008.1.2.4.70": 0,
    "1.2.840.10008.1.2.4.80": 1,
    "1.2.840.10008.1.2.4.81": 1,
    "1.2.840.10008.1.2.4.90": 2,
    "1.2.840.10008.1.2.4.91": 2,
    "1.2.840.10008.1.2.5": 3,
}


def out(target):
    path = os.path.join(HERE, "seeds", target)
    os.makedirs(path, exist_ok=True)
    return path


def main():
    tests = os.path.join(os.path.dirname(pydicom.data.__file__), "test_files")
    streams = dicoms = 0
    for path in sorted(glob.glob(os.path.join(tests, "*.dcm"))):
        name = os.path.basename(path)
        if os.path.getsize(path) <= 200_000:
            shutil.copy(path, os.path.join(out("dicom_file"), name))
            dicoms += 1
        try:
            ds = pydicom.dcmread(path)
            codec = CODECS.get(str(ds.file_meta.TransferSyntaxUID))
            if codec is None or "PixelData" not in ds:
                continue
            frames = int(ds.get("NumberOfFrames", 1) or 1)
            for i, frame in enumerate(generate_frames(ds.PixelData, number_of_frames=frames)):
                if len(frame) <= 200_000:
                    with open(os.path.join(out("codec_stream"), f"{name}-{i}"), "wb") as f:
                        f.write(bytes([codec]) + frame)
                    streams += 1
        except Exception:  # noqa: BLE001: a file pydicom cannot read is no seed
            continue
    data = os.path.join(os.path.dirname(nibabel.__file__), "tests", "data")
    niftis = 0
    for path in sorted(glob.glob(os.path.join(data, "*.nii*"))):
        if os.path.getsize(path) <= 200_000:
            shutil.copy(path, os.path.join(out("nifti_file"), os.path.basename(path)))
            niftis += 1
    print(f"seeds: {streams} codestreams, {dicoms} DICOM files, {niftis} NIfTI files")


if __name__ == "__main__":
    main()
