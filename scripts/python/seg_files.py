"""DICOM segmentations written by highdicom over a CT series written by pydicom, for LeapView's
DICOM SEG reader (tests/integration/labels.rs).

    python seg_files.py OUT

Writes OUT/series/ (12 axial CT slices of 32 x 32 pixels, 0.7 x 0.9 mm, 2.5 mm apart),
OUT/other/ (the same slices as another series in the same frame of reference) and:
- binary.dcm: three BINARY segments, the first two overlapping (two spheres), the third apart
  (a box); highdicom leaves out the frames a segment does not touch;
- fractional.dcm: one FRACTIONAL segment of values 0, 0.3, 0.7 and 1 (shown where above half);
- binary_j2k.dcm: binary.dcm's segments compressed as JPEG 2000 lossless (the only codec
  highdicom writes BINARY frames with); fractional_rle.dcm, fractional_jls.dcm and
  fractional_j2k.dcm: fractional.dcm's segment as RLE, JPEG-LS and JPEG 2000 lossless;
- other.dcm: a BINARY segment of the other series;
bad_*.dcm: binary.dcm altered with pydicom to lie (more frames than functional groups,
pixel data cut short, a frame of a segment not described, a type its bits do not fit, a frame
moved 10 m away), fractional_rle.dcm with a frame's fragment left out, binary_j2k.dcm with
Columns two fewer than its JPEG 2000 frames hold; and, for each segment of binary.dcm and fractional.dcm, `<file>_<segment>.u8`: 1 where the voxel
is in the segment, 0 elsewhere, index = column + columns * (row + rows * slice), slices in
order of z. cases.json gives the geometry (first voxel's centre, spacing: x, y, z in mm,
LPS) and the segments' numbers, labels and colours as highdicom converts their CIELab values to
sRGB.
"""

import json
import os
import sys

import highdicom as hd
import numpy as np
import pydicom
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.sr.codedict import codes
from pydicom.uid import (
    CTImageStorage,
    ExplicitVRLittleEndian,
    JPEG2000Lossless,
    JPEGLSLossless,
    RLELossless,
    generate_uid,
)

# 32 x 32: highdicom encodes no smaller frame as JPEG 2000.
ROWS, COLS, SLICES = 32, 32, 12
DX, DY, DZ = 0.7, 0.9, 2.5
ORIGIN = (-8.05, -9.1, 30.0)


def ct_series(folder, study, frame_of_reference, series):
    """The CT slices, written with pydicom; returns their data sets."""
    os.makedirs(folder, exist_ok=True)
    rng = np.random.default_rng(3)
    slices = []
    for k in range(SLICES):
        ds = Dataset()
        ds.file_meta = FileMetaDataset()
        ds.file_meta.MediaStorageSOPClassUID = CTImageStorage
        ds.file_meta.TransferSyntaxUID = ExplicitVRLittleEndian
        ds.SOPClassUID = CTImageStorage
        ds.SOPInstanceUID = generate_uid()
        ds.file_meta.MediaStorageSOPInstanceUID = ds.SOPInstanceUID
        ds.StudyInstanceUID = study
        ds.SeriesInstanceUID = series
        ds.FrameOfReferenceUID = frame_of_reference
        ds.Modality = "CT"
        ds.PatientName = "Seg^Test"
        ds.PatientID = "seg-test"
        ds.PatientBirthDate = ""
        ds.PatientSex = "O"
        ds.StudyDate = "20261206"
        ds.StudyTime = "120000"
        ds.AccessionNumber = ""
        ds.ReferringPhysicianName = ""
        ds.StudyID = "1"
        ds.SeriesNumber = 1
        ds.InstanceNumber = k + 1
        ds.Manufacturer = "LeapView tests"
        ds.ImagePositionPatient = [ORIGIN[0], ORIGIN[1], ORIGIN[2] + k * DZ]
        ds.ImageOrientationPatient = [1, 0, 0, 0, 1, 0]
        ds.PixelSpacing = [DY, DX]
        ds.SliceThickness = DZ
        ds.Rows, ds.Columns = ROWS, COLS
        ds.SamplesPerPixel = 1
        ds.PhotometricInterpretation = "MONOCHROME2"
        ds.BitsAllocated = 16
        ds.BitsStored = 16
        ds.HighBit = 15
        ds.PixelRepresentation = 1
        ds.RescaleIntercept = -1024
        ds.RescaleSlope = 1
        pixels = rng.integers(900, 1200, (ROWS, COLS)).astype(np.int16)
        ds.PixelData = pixels.tobytes()
        ds.save_as(os.path.join(folder, f"slice{k:03d}.dcm"), enforce_file_format=True)
        slices.append(ds)
    return slices


def description(number, label, colour):
    return hd.seg.SegmentDescription(
        segment_number=number,
        segment_label=label,
        segmented_property_category=codes.SCT.Tissue,
        segmented_property_type=codes.SCT.Tissue,
        algorithm_type=hd.seg.SegmentAlgorithmTypeValues.MANUAL,
        display_color=hd.color.CIELabColor(*colour),
    )


def write_seg(path, sources, pixels, kind, descriptions, **extra):
    seg = hd.seg.Segmentation(
        source_images=sources,
        pixel_array=pixels,
        segmentation_type=kind,
        segment_descriptions=descriptions,
        series_instance_uid=generate_uid(),
        series_number=100,
        sop_instance_uid=generate_uid(),
        instance_number=1,
        manufacturer="LeapView tests",
        manufacturer_model_name="seg_files.py",
        software_versions="1",
        device_serial_number="1",
        **extra,
    )
    seg.save_as(path)


def lying(out):
    """binary.dcm altered to lie in one way each; returns [{file, said}]: what LeapView must
    say of each."""
    cases = []

    def alter(name, said, change, source="binary.dcm"):
        ds = pydicom.dcmread(os.path.join(out, source))
        change(ds)
        ds.save_as(os.path.join(out, name))
        cases.append({"file": name, "said": said})

    def more_frames(ds):
        ds.NumberOfFrames = int(ds.NumberOfFrames) + 5

    def cut_pixels(ds):
        ds.PixelData = ds.PixelData[: len(ds.PixelData) // 2]

    def unknown_segment(ds):
        item = ds.PerFrameFunctionalGroupsSequence[0].SegmentIdentificationSequence[0]
        item.ReferencedSegmentNumber = 9

    def wrong_type(ds):
        ds.SegmentationType = "FRACTIONAL"

    def far_frame(ds):
        position = ds.PerFrameFunctionalGroupsSequence[-1].PlanePositionSequence[0]
        x, y, z = (float(v) for v in position.ImagePositionPatient)
        position.ImagePositionPatient = [x, y, z + 10000.0]

    def drop_fragment(ds):
        frames = list(pydicom.encaps.generate_frames(ds.PixelData, number_of_frames=int(ds.NumberOfFrames)))
        ds.PixelData = pydicom.encaps.encapsulate(frames[:-1])

    def narrower(ds):
        ds.Columns = int(ds.Columns) - 2

    alter("bad_frames.dcm", "functional groups", more_frames)
    alter("bad_rle_fragments.dcm", "fragments", drop_fragment, "fractional_rle.dcm")
    alter("bad_j2k_size.dcm", "the header says 30", narrower, "binary_j2k.dcm")
    alter("bad_pixels.dcm", "pixel data holds", cut_pixels)
    alter("bad_segment.dcm", "does not describe", unknown_segment)
    alter("bad_type.dcm", "BitsAllocated 1", wrong_type)
    alter("bad_far.dcm", "far more than the image", far_frame)
    return cases


def rgb(lab):
    return list(hd.color.CIELabColor(*lab).to_rgb(clip=True))


def main(out):
    study, frame = generate_uid(), generate_uid()
    series = ct_series(os.path.join(out, "series"), study, frame, generate_uid())
    other = ct_series(os.path.join(out, "other"), study, frame, generate_uid())
    k, r, c = np.meshgrid(np.arange(SLICES), np.arange(ROWS), np.arange(COLS), indexing="ij")
    z, y, x = k * DZ, r * DY, c * DX
    a = (x - 6) ** 2 + (y - 8) ** 2 + ((z - 14) / 1.5) ** 2 < 25
    b = (x - 10) ** 2 + (y - 9) ** 2 + ((z - 15) / 1.5) ** 2 < 20
    box = (c >= 18) & (c < 22) & (r >= 2) & (r < 6) & (k >= 2) & (k < 4)
    binary = np.stack([a, b, box], axis=-1).astype(np.uint8)
    assert (a & b).any() and not (box & (a | b)).any()
    colours = [(60.0, 40.0, 20.0), (80.0, -50.0, 30.0), (50.0, 10.0, -60.0)]
    labels = ["sphere a", "sphere b", "box"]
    write_seg(
        os.path.join(out, "binary.dcm"),
        series,
        binary,
        hd.seg.SegmentationTypeValues.BINARY,
        [description(i + 1, labels[i], colours[i]) for i in range(3)],
    )
    # Fractions in four levels: 0 outside, 0.3 and 0.7 in two shells, 1 at the core.
    d = np.sqrt((x - 8) ** 2 + (y - 9) ** 2 + ((z - 15) / 2) ** 2)
    fraction = np.select([d < 2, d < 4, d < 6], [1.0, 0.7, 0.3], 0.0).astype(np.float32)
    write_seg(
        os.path.join(out, "binary_j2k.dcm"),
        series,
        binary,
        hd.seg.SegmentationTypeValues.BINARY,
        [description(i + 1, labels[i], colours[i]) for i in range(3)],
        transfer_syntax_uid=JPEG2000Lossless,
    )
    for name, syntax in [
        ("fractional", ExplicitVRLittleEndian),
        ("fractional_rle", RLELossless),
        ("fractional_jls", JPEGLSLossless),
        ("fractional_j2k", JPEG2000Lossless),
    ]:
        write_seg(
            os.path.join(out, f"{name}.dcm"),
            series,
            fraction,
            hd.seg.SegmentationTypeValues.FRACTIONAL,
            [description(1, "fraction", colours[0])],
            max_fractional_value=255,
            transfer_syntax_uid=syntax,
        )
    write_seg(
        os.path.join(out, "other.dcm"),
        other,
        binary[..., :1],
        hd.seg.SegmentationTypeValues.BINARY,
        [description(1, "elsewhere", colours[0])],
    )
    refused = lying(out)
    for i in range(3):
        for name in ["binary", "binary_j2k"]:
            binary[..., i].astype(np.uint8).tofile(os.path.join(out, f"{name}_{i + 1}.u8"))
    for name in ["fractional", "fractional_rle", "fractional_jls", "fractional_j2k"]:
        (fraction > 0.5).astype(np.uint8).tofile(os.path.join(out, f"{name}_1.u8"))
    cases = {
        "origin": ORIGIN,
        "spacing": [DX, DY, DZ],
        "dims": [COLS, ROWS, SLICES],
        # highdicom's own conversion of each CIELab colour to sRGB (clipped into the gamut).
        "binary": [
            {"number": i + 1, "label": labels[i], "rgb": rgb(colours[i])} for i in range(3)
        ],
        "fractional": [{"number": 1, "label": "fraction", "rgb": rgb(colours[0])}],
        "refused": refused,
    }
    cases["binary_j2k"] = cases["binary"]
    for name in ["fractional_rle", "fractional_jls", "fractional_j2k"]:
        cases[name] = cases["fractional"]
    with open(os.path.join(out, "cases.json"), "w") as f:
        json.dump(cases, f, indent=1)


if __name__ == "__main__":
    main(sys.argv[1])
