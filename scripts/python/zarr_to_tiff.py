"""Writes level 0 of an OME-Zarr store as a TIFF stack, a few slices in memory at a time, for
the out-of-core TIFF measurement (docs/benchmarks/out-of-core).

    python zarr_to_tiff.py STORE OUT [--folder] [--zlib]

OUT is a multi-page BigTIFF (one page a slice, strips of tifffile's choosing), or with --folder
a folder of one TIFF file per slice; --zlib compresses with deflate.
"""

import argparse
import os

import tifffile
import zarr


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("store")
    ap.add_argument("out")
    ap.add_argument("--folder", action="store_true")
    ap.add_argument("--zlib", action="store_true")
    a = ap.parse_args()
    level = zarr.open_group(a.store, mode="r")["0"]
    depth = level.shape[0]
    compression = "zlib" if a.zlib else None
    # A row of chunks at a time: a slice alone would decode each chunk it cuts once per slice.
    step = level.chunks[0]
    if a.folder:
        os.makedirs(a.out)
        for z0 in range(0, depth, step):
            slab = level[z0:z0 + step]
            for i, page in enumerate(slab):
                tifffile.imwrite(os.path.join(a.out, f"slice_{z0 + i:05d}.tif"), page,
                                 photometric="minisblack", compression=compression)
    else:
        with tifffile.TiffWriter(a.out, bigtiff=True) as tiff:
            for z0 in range(0, depth, step):
                for page in level[z0:z0 + step]:
                    tiff.write(page, photometric="minisblack", compression=compression)


if __name__ == "__main__":
    main()
