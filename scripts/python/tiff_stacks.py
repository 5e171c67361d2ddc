"""TIFF stacks written by tifffile, as microscopy and micro-CT software write them, for
LeapView's tests.

    python tiff_stacks.py OUT

Writes into OUT, for each case, a TIFF file or a folder of slices and `<case>.f64`: the samples
LeapView is to read (the channel and time point the case names), x fastest, little-endian
float64; and `cases.json` listing the cases with the path, the channel and time point to open
(counted from 0), the dimensions (x, y, z), the spacing (mm), and a note LeapView must give.
`errors` lists files LeapView must refuse, each with words its message holds.
"""

import json
import os
import sys

import numpy as np
import tifffile


def volume(shape, dtype, seed):
    rng = np.random.default_rng(seed)
    if np.issubdtype(dtype, np.floating):
        return rng.normal(100.0, 40.0, shape).astype(dtype)
    info = np.iinfo(dtype)
    return rng.integers(max(info.min, -3000), min(info.max, 60000), shape, dtype=dtype,
                        endpoint=True)


def main(out):
    cases, errors = [], []

    def case(name, path, data, spacing, channel=0, time=0, note=None):
        np.ascontiguousarray(data, dtype="<f8").tofile(os.path.join(out, name + ".f64"))
        z, y, x = data.shape
        cases.append({"name": name, "path": path, "channel": channel, "time": time,
                      "dims": [x, y, z], "spacing": list(spacing), "note": note})

    # 1. A multi-page uint16 stack (tifffile's own JSON description), deflate, 0.05 cm pixels
    # (ResolutionUnit centimetre), no slice spacing.
    data = volume((7, 18, 22), np.uint16, 1)
    tifffile.imwrite(os.path.join(out, "multipage.tif"), data, photometric="minisblack",
                     compression="zlib", resolution=(20.0, 20.0), resolutionunit="CENTIMETER")
    case("multipage", "multipage.tif", data, (0.5, 0.5, 0.5), note="no slice spacing")

    # 2. OME-TIFF, int16, two channels (the second read), micrometre pixels, 2 µm slices.
    data = volume((2, 5, 16, 20), np.int16, 2)
    tifffile.imwrite(os.path.join(out, "ome.ome.tif"), data, photometric="minisblack", ome=True,
                     metadata={"axes": "CZYX", "PhysicalSizeX": 0.5, "PhysicalSizeXUnit": "µm",
                               "PhysicalSizeY": 0.25, "PhysicalSizeYUnit": "µm",
                               "PhysicalSizeZ": 2.0, "PhysicalSizeZUnit": "µm"})
    case("ome", "ome.ome.tif", data[1], (0.5e-3, 0.25e-3, 2e-3), channel=1)

    # 3. An ImageJ hyperstack, float32, slices of two channels (the first read), 0.2 µm pixels
    # and 1.5 µm slices; tiled.
    data = volume((6, 2, 32, 48), np.float32, 3)
    tifffile.imwrite(os.path.join(out, "imagej.tif"), data, imagej=True,
                     resolution=(1 / 0.2, 1 / 0.2), tile=(16, 16),
                     metadata={"spacing": 1.5, "unit": "um", "axes": "ZCYX"})
    case("imagej", "imagej.tif", data[:, 0], (0.2e-3, 0.2e-3, 1.5e-3))

    # 4. A folder of 2-D uint8 slices, named so that only a natural sort orders them.
    folder = os.path.join(out, "slices")
    os.makedirs(folder)
    data = volume((12, 10, 14), np.uint8, 4)
    for z in range(12):
        tifffile.imwrite(os.path.join(folder, f"slice_{z + 1}.tif"), data[z],
                         photometric="minisblack")
    case("slices", "slices", data, (1.0, 1.0, 1.0), note="natural order")

    # 5. BigTIFF, float64, uncompressed.
    data = volume((4, 9, 11), np.float64, 5)
    tifffile.imwrite(os.path.join(out, "big.tif"), data, bigtiff=True, photometric="minisblack")
    case("big", "big.tif", data, (1.0, 1.0, 1.0), note="no pixel size")

    # 6. Strips of 5 rows, deflate, on pages of odd sizes: strips, and the halvings of the
    # stack, end part way.
    data = volume((19, 33, 41), np.uint16, 7)
    tifffile.imwrite(os.path.join(out, "strips.tif"), data, photometric="minisblack",
                     compression="zlib", rowsperstrip=5)
    case("strips", "strips.tif", data, (1.0, 1.0, 1.0), note="no pixel size")

    # 7. Tiles of 16 x 16 on 41 x 33 pages: the edge tiles padded.
    data = volume((9, 33, 41), np.int16, 8)
    tifffile.imwrite(os.path.join(out, "tiles.tif"), data, photometric="minisblack",
                     tile=(16, 16))
    case("tiles", "tiles.tif", data, (1.0, 1.0, 1.0), note="no pixel size")

    def error(path, said, channel=0):
        errors.append({"path": path, "said": said, "channel": channel})

    rgb = volume((3, 8, 8, 3), np.uint8, 6)
    tifffile.imwrite(os.path.join(out, "rgb.tif"), rgb, photometric="rgb")
    error("rgb.tif", "colour TIFF pages")
    error("ome.ome.tif", "no channel 3", channel=2)
    with open(os.path.join(out, "broken.tif"), "wb") as f:
        f.write(b"II*\x00" + b"\xff" * 12)
    error("broken.tif", "ends before")

    with open(os.path.join(out, "cases.json"), "w") as f:
        json.dump({"cases": cases, "errors": errors}, f, indent=1)


if __name__ == "__main__":
    os.makedirs(sys.argv[1], exist_ok=True)
    main(sys.argv[1])
