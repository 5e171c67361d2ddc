import pydicom, glob, os, sys
from pydicom.encaps import generate_frames
out = "/tmp/j2k/streams"
n = 0
for d in ["ct_head_cthead", "mr_head_t1_seg3d"]:
    for f in sorted(glob.glob(f"/work/shared/data/dicom/{d}/*")):
        ds = pydicom.dcmread(f)
        for i, fr in enumerate(generate_frames(ds.PixelData, number_of_frames=int(getattr(ds, "NumberOfFrames", 1)))):
            open(f"{out}/{d}_{os.path.basename(f)}_{i}.j2k", "wb").write(fr)
            arr = ds.pixel_array
            arr.astype(arr.dtype.newbyteorder("<")).tofile(f"{out}/{d}_{os.path.basename(f)}_{i}.raw")
            n += 1
print(n, ds.BitsStored, ds.PixelRepresentation, ds.pixel_array.dtype)
