"""Reads a store LeapView wrote (`leapview convert`) with zarr-python and ome-zarr-py, as other
software would, and checks it against the volume LeapView wrote it from.

    python zarr_check.py STORE VALUES.f64

VALUES.f64: the volume's samples in data units, x fastest, little-endian float64. Checks that
ome-zarr-py finds one image with the levels' scale and translation, that level 0 times the
stored value mapping equals VALUES, and that each coarser level has the halved shape and is the
mean of 2 x 2 x 2 voxels of the one before (an odd axis's last voxel repeated), to within one
unit for integers. Prints one JSON line of what it found; exits 1 on a mismatch.
"""

import json
import sys

import numpy as np
import zarr
from ome_zarr.io import parse_url
from ome_zarr.reader import Reader


def fail(why):
    print(why, file=sys.stderr)
    sys.exit(1)


def halved(a):
    """LeapView's halving: pad an odd axis with its last voxel, then the mean of each 2x2x2."""
    pad = [(0, s % 2) for s in a.shape]
    a = np.pad(a.astype(np.float64), pad, mode="edge")
    z, y, x = a.shape
    return a.reshape(z // 2, 2, y // 2, 2, x // 2, 2).mean(axis=(1, 3, 5))


def main(store, values_path):
    group = zarr.open_group(store, mode="r")
    ome = group.attrs["ome"]
    if ome.get("version") != "0.5":
        fail(f"version {ome.get('version')}")
    facts = group.attrs.get("leapview", {})
    mapping = facts.get("value_mapping", {"slope": 1.0, "intercept": 0.0})
    nodes = list(Reader(parse_url(store))())
    if not nodes:
        fail("ome-zarr-py found no image")
    node = nodes[0]
    levels = [np.asarray(d) for d in node.data]
    datasets = node.metadata["coordinateTransformations"]
    values = np.fromfile(values_path, dtype="<f8").reshape(levels[0].shape)
    data = levels[0].astype(np.float64) * mapping["slope"] + mapping["intercept"]
    if not np.array_equal(data, values):
        fail(f"level 0 differs from the volume at {np.argwhere(data != values)[:3].tolist()}")
    scale0 = np.array(datasets[0][0]["scale"])
    for k in range(1, len(levels)):
        want = tuple(-(-s // 2) for s in levels[k - 1].shape)
        if levels[k].shape != want:
            fail(f"level {k} is {levels[k].shape}, not {want}")
        mean = halved(levels[k - 1])
        integer = np.issubdtype(levels[k].dtype, np.integer)
        error = np.abs(levels[k].astype(np.float64) - mean).max()
        if error > (1.0 if integer else 1e-4 * max(1.0, np.abs(mean).max())):
            fail(f"level {k} is not the mean of level {k - 1}: off by {error}")
        scale = np.array(datasets[k][0]["scale"])
        if not np.allclose(scale, scale0 * 2**k):
            fail(f"level {k}'s scale {scale.tolist()} is not 2^{k} x {scale0.tolist()}")
        shift = np.array(datasets[k][1]["translation"]) - np.array(datasets[0][1]["translation"])
        if not np.allclose(shift, scale0 * (2**k - 1) / 2):
            fail(f"level {k}'s translation is off by {shift.tolist()}")
    print(json.dumps({"levels": [list(l.shape) for l in levels], "dtype": str(levels[0].dtype),
                      "axes": [a["name"] for a in node.metadata["axes"]]}))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
