#!/usr/bin/env python3
"""Writes tests/data/dicom/: two-slice CT series of a known pattern in the codecs that
../shared/data/dicom has no file of (JPEG extended 12-bit, JPEG lossless, JPEG 2000 lossy), with
software other than LeapView: pydicom 3 (the files) and imagecodecs (libjpeg-turbo 3, OpenJPEG;
the codestreams). The tests decode them and compare with the pattern
    value(x, y, k) = 500 + 10 x + 7 y + 100 k   (stored, 12 bits; HU = value - 1024)
exactly for lossless codecs, within a tolerance for lossy ones. Run once; the files are committed.

    pip install pydicom imagecodecs && python3 scripts/make-dicom-fixtures.py
"""
import os

import imagecodecs
import numpy as np
import pydicom
from pydicom.dataset import FileDataset, FileMetaDataset
from pydicom.encaps import encapsulate
from pydicom.uid import generate_uid

OUT = os.path.join(os.path.dirname(__file__), "..", "tests", "data", "dicom")
SIZE = 64


def pattern(k):
    y, x = np.mgrid[0:SIZE, 0:SIZE]
    return (500 + 10 * x + 7 * y + 100 * k).astype(np.uint16)


CODECS = {
    # name: (transfer syntax, encoder)
    "jpeg-extended-12bit": (
        "1.2.840.10008.1.2.4.51",
        lambda a: imagecodecs.jpeg8_encode(a, level=95, bitspersample=12),
    ),
    "jpeg-lossless-sv1": (
        "1.2.840.10008.1.2.4.70",
        lambda a: imagecodecs.jpeg8_encode(a, lossless=True, predictor=1, bitspersample=12),
    ),
    "jpeg2000-lossy": (
        "1.2.840.10008.1.2.4.91",
        lambda a: imagecodecs.jpeg2k_encode(
            a, level=60, reversible=False, codecformat="J2K", bitspersample=12
        ),
    ),
}

for name, (ts, encode) in CODECS.items():
    folder = os.path.join(OUT, name)
    os.makedirs(folder, exist_ok=True)
    series, frame = generate_uid(), generate_uid()
    for k in range(2):
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = "1.2.840.10008.5.1.4.1.1.2"
        meta.MediaStorageSOPInstanceUID = generate_uid()
        meta.TransferSyntaxUID = ts
        ds = FileDataset(None, {}, file_meta=meta, preamble=b"\0" * 128)
        ds.SOPClassUID = meta.MediaStorageSOPClassUID
        ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
        ds.Modality = "CT"
        ds.SeriesInstanceUID = series
        ds.SeriesDescription = f"pattern, {name}"
        ds.FrameOfReferenceUID = frame
        ds.ImagePositionPatient = [0, 0, 3 * k]
        ds.ImageOrientationPatient = [1, 0, 0, 0, 1, 0]
        ds.PixelSpacing = [0.5, 0.5]
        ds.Rows = ds.Columns = SIZE
        ds.SamplesPerPixel = 1
        ds.PhotometricInterpretation = "MONOCHROME2"
        ds.BitsAllocated, ds.BitsStored, ds.HighBit = 16, 12, 11
        ds.PixelRepresentation = 0
        ds.RescaleIntercept, ds.RescaleSlope = -1024, 1
        ds.PixelData = encapsulate([encode(pattern(k))])
        ds["PixelData"].VR = "OB"
        ds.LossyImageCompression = "00" if "lossless" in name else "01"
        ds.save_as(os.path.join(folder, f"IM{k + 1}.dcm"), enforce_file_format=True)
print("wrote", OUT)
