"""OME-Zarr stores written by zarr-python and ome-zarr-py, for LeapView's tests.

    python zarr_stores.py OUT

Writes into OUT, for each case, a store `<case>.zarr` and `<case>.f64`: the samples LeapView is to
read (the time point and channel the case names, level 0), x fastest, little-endian float64; and
`cases.json` listing the cases with the store, the time point and channel to open (counted from
0), the dimensions (x, y, z), the spacing (mm, x y z), the first voxel's centre (LPS, mm: the
store's axes taken as RAS), a note LeapView must give where it must give one, and the time points
the store holds. `errors` lists stores LeapView must refuse, each with words its message holds.
"""

import json
import os
import shutil
import sys

import numcodecs
import numpy as np
import zarr
from zarr.codecs import BloscCodec, GzipCodec, ZstdCodec


def ngff(axes, levels, version, name="image"):
    """The multiscales entry: `axes` as (name, type, unit) and `levels` as (path, scale,
    translation) with one value per axis."""
    entry = {
        "name": name,
        "axes": [
            {k: v for k, v in (("name", n), ("type", t), ("unit", u)) if v is not None}
            for n, t, u in axes
        ],
        "datasets": [
            {
                "path": path,
                "coordinateTransformations": [{"type": "scale", "scale": list(scale)}]
                + ([{"type": "translation", "translation": list(t)}] if t is not None else []),
            }
            for path, scale, t in levels
        ],
    }
    if version == "0.4":
        entry["version"] = "0.4"
        return {"multiscales": [entry]}
    return {"ome": {"version": "0.5", "multiscales": [entry]}}


def halve(a):
    """Every second voxel along the last three axes (the stores' coarser levels: their values
    are not compared, only that they open)."""
    return a[..., ::2, ::2, ::2]


def volume(shape, dtype, seed):
    rng = np.random.default_rng(seed)
    if np.issubdtype(dtype, np.floating):
        return rng.normal(100.0, 40.0, shape).astype(dtype)
    info = np.iinfo(dtype)
    lo, hi = max(info.min, -3000), min(info.max, 60000)
    return rng.integers(lo, hi, shape, dtype=dtype, endpoint=True)


def main(out):
    cases = []
    errors = []

    def case(name, data, spacing, origin_ras, *, channel=0, time=0, note=None, times=1):
        """`data` is what LeapView must read, indexed [z, y, x]."""
        np.ascontiguousarray(data, dtype="<f8").tofile(os.path.join(out, name + ".f64"))
        z, y, x = data.shape
        cases.append(
            {
                "name": name,
                "store": name + ".zarr",
                "channel": channel,
                "time": time,
                "times": times,
                "dims": [x, y, z],
                "spacing": list(spacing),
                "origin_lps": [-origin_ras[0], -origin_ras[1], origin_ras[2]],
                "note": note,
            }
        )

    # 1. NGFF 0.5 on Zarr v3, sharded (inner chunks 8 x 16 x 16 in shards of 16 x 32 x 32), zstd,
    # uint16, sizes that are no multiple of the chunks, micrometres, a translation.
    path = os.path.join(out, "v05_sharded.zarr")
    data = volume((21, 35, 47), np.uint16, 1)
    g = zarr.open_group(path, mode="w", zarr_format=3)
    for level, d in enumerate([data, halve(data)]):
        a = g.create_array(
            f"s{level}", shape=d.shape, dtype=d.dtype, chunks=(8, 16, 16), shards=(16, 32, 32),
            compressors=ZstdCodec(level=3), dimension_names=["z", "y", "x"], fill_value=0,
        )
        a[:] = d
    g.attrs.update(ngff(
        [("z", "space", "micrometer"), ("y", "space", "micrometer"), ("x", "space", "micrometer")],
        [("s0", (2.0, 0.5, 0.25), (10.0, -4.0, 3.0)), ("s1", (4.0, 1.0, 0.5), (11.0, -3.75, 3.125))],
        "0.5",
    ))
    case("v05_sharded", data, (0.25e-3, 0.5e-3, 2e-3), (3e-3, -4e-3, 10e-3))

    # 2. NGFF 0.4 on Zarr v2, blosc (zstd, byte shuffle), int16 with negative values, two
    # channels (the second read), millimetres, "/" chunk keys.
    path = os.path.join(out, "v04_blosc_channels.zarr")
    data = volume((2, 12, 17, 19), np.int16, 2)
    g = zarr.open_group(path, mode="w", zarr_format=2)
    a = g.create_array(
        "0", shape=data.shape, dtype=data.dtype, chunks=(1, 5, 8, 8),
        compressors=numcodecs.Blosc(cname="zstd", clevel=5, shuffle=numcodecs.Blosc.SHUFFLE),
        chunk_key_encoding={"name": "v2", "separator": "/"}, fill_value=0,
    )
    a[:] = data
    g.attrs.update(ngff(
        [("c", "channel", None), ("z", "space", "millimeter"), ("y", "space", "millimeter"),
         ("x", "space", "millimeter")],
        [("0", (1.0, 1.5, 0.7, 0.7), None)],
        "0.4",
    ))
    case("v04_blosc_channels", data[1], (0.7, 0.7, 1.5), (0.0, 0.0, 0.0), channel=1)

    # 3. NGFF 0.4 on Zarr v2, gzip, uint8 with whole chunks at the fill value (zarr-python does
    # not write them: they are absent from the store) and a fill value of 7.
    path = os.path.join(out, "v04_gzip_missing.zarr")
    data = np.full((16, 16, 16), 7, dtype=np.uint8)
    data[8:, :8, 8:] = volume((8, 8, 8), np.uint8, 3)
    g = zarr.open_group(path, mode="w", zarr_format=2)
    a = g.create_array("0", shape=data.shape, dtype=data.dtype, chunks=(8, 8, 8),
                       compressors=numcodecs.GZip(level=5), fill_value=7)
    a[:] = data
    g.attrs.update(ngff(
        [("z", "space", "millimeter"), ("y", "space", "millimeter"), ("x", "space", "millimeter")],
        [("0", (1.0, 1.0, 1.0), None)], "0.4",
    ))
    chunks = sorted(f for f in os.listdir(os.path.join(path, "0")) if not f.startswith("."))
    assert len(chunks) == 1, chunks  # seven of the eight chunks are absent
    case("v04_gzip_missing", data, (1.0, 1.0, 1.0), (0.0, 0.0, 0.0))

    # 4. NGFF 0.5, float32 (NaN and infinities among the values), a time axis of three points
    # (the third read), gzip on Zarr v3, nanometres.
    path = os.path.join(out, "v05_time_float.zarr")
    data = volume((3, 6, 9, 10), np.float32, 4)
    data[2, 0, 0, 0] = np.nan
    data[2, 1, 2, 3] = np.inf
    g = zarr.open_group(path, mode="w", zarr_format=3)
    a = g.create_array("0", shape=data.shape, dtype=data.dtype, chunks=(1, 4, 4, 4),
                       compressors=GzipCodec(level=5), dimension_names=["t", "z", "y", "x"])
    a[:] = data
    g.attrs.update(ngff(
        [("t", "time", "second"), ("z", "space", "nanometer"), ("y", "space", "nanometer"),
         ("x", "space", "nanometer")],
        [("0", (1.0, 300.0, 100.0, 100.0), None)], "0.5",
    ))
    case("v05_time_float", data[2], (1e-4, 1e-4, 3e-4), (0.0, 0.0, 0.0), time=2, times=3)

    # 5. A plain Zarr v3 array, no NGFF metadata: one level, 1 mm voxels, blosc.
    path = os.path.join(out, "plain_array.zarr")
    data = volume((5, 6, 7), np.uint16, 5)
    a = zarr.create_array(path, shape=data.shape, dtype=data.dtype, chunks=(4, 4, 4),
                          compressors=BloscCodec(cname="lz4", clevel=5, shuffle="bitshuffle"),
                          zarr_format=3)
    a[:] = data
    case("plain_array", data, (1.0, 1.0, 1.0), (0.0, 0.0, 0.0),
         note="no unit for its space axes")

    # 6. ome-zarr-py's own writer with its defaults (NGFF 0.5): a pyramid halving every axis.
    from ome_zarr.io import parse_url
    from ome_zarr.writer import write_image

    path = os.path.join(out, "ome_zarr_py.zarr")
    data = volume((24, 32, 40), np.uint16, 6)
    root = zarr.open_group(parse_url(path, mode="w").store, mode="w")
    write_image(
        image=data, group=root, axes=[
            {"name": "z", "type": "space", "unit": "micrometer"},
            {"name": "y", "type": "space", "unit": "micrometer"},
            {"name": "x", "type": "space", "unit": "micrometer"},
        ],
        scale_factors=[{"z": 2, "y": 2, "x": 2}],
        storage_options={"chunks": (8, 16, 16)},
    )
    # (0.18 writes the axes without their units: LeapView takes millimetres and says so.)
    case("ome_zarr_py", data, (1.0, 1.0, 1.0), (0.0, 0.0, 0.0), note="no unit for its space axes")

    # 7. A chunk that fails to decode (its bytes overwritten): the rest reads, the note says so.
    path = os.path.join(out, "corrupt_chunk.zarr")
    data = volume((8, 8, 16), np.uint16, 7)
    g = zarr.open_group(path, mode="w", zarr_format=3)
    a = g.create_array("0", shape=data.shape, dtype=data.dtype, chunks=(8, 8, 8),
                       compressors=ZstdCodec(level=3), fill_value=0, dimension_names=["z", "y", "x"])
    a[:] = data
    g.attrs.update(ngff(
        [("z", "space", "millimeter"), ("y", "space", "millimeter"), ("x", "space", "millimeter")],
        [("0", (1.0, 1.0, 1.0), None)], "0.5",
    ))
    with open(os.path.join(path, "0", "c", "0", "0", "1"), "wb") as f:
        f.write(b"not zstd at all")
    expected = data.copy()
    expected[:, :, 8:] = 0
    case("corrupt_chunk", expected, (1.0, 1.0, 1.0), (0.0, 0.0, 0.0),
         note="1 of 2 chunks could not be read")

    # Stores LeapView must refuse, with words its message holds.
    def error(name, said, **open_with):
        errors.append({"store": name + ".zarr", "said": said, **open_with})

    # A codec LeapView does not build (bz2).
    path = os.path.join(out, "bz2_codec.zarr")
    g = zarr.open_group(path, mode="w", zarr_format=2)
    a = g.create_array("0", shape=(4, 4, 4), dtype="u1", chunks=(4, 4, 4),
                       compressors=numcodecs.BZ2(level=1))
    a[:] = 1
    g.attrs.update(ngff([("z", "space", None), ("y", "space", None), ("x", "space", None)],
                        [("0", (1, 1, 1), None)], "0.4"))
    error("bz2_codec", "bz2")
    # 64-bit integers.
    path = os.path.join(out, "int64.zarr")
    zarr.create_array(path, shape=(4, 4, 4), dtype="i8", chunks=(4, 4, 4), zarr_format=3)[:] = 1
    error("int64", "int64")
    # A channel past the last, and a time point past the last.
    error("v04_blosc_channels", "no channel 3", channel=2)
    error("v05_time_float", "no time point 4", time=3)
    # A group with no image.
    path = os.path.join(out, "no_image.zarr")
    zarr.open_group(path, mode="w", zarr_format=3).attrs["something"] = 1
    error("no_image", "no 'multiscales'")
    # A dataset path that leaves the group.
    path = os.path.join(out, "escape.zarr")
    g = zarr.open_group(path, mode="w", zarr_format=3)
    g.attrs.update(ngff([("z", "space", None), ("y", "space", None), ("x", "space", None)],
                        [("../v05_sharded.zarr/s0", (1, 1, 1), None)], "0.5"))
    error("escape", "inside the group")
    # A level whose array is missing.
    path = os.path.join(out, "missing_level.zarr")
    g = zarr.open_group(path, mode="w", zarr_format=3)
    g.attrs.update(ngff([("z", "space", None), ("y", "space", None), ("x", "space", None)],
                        [("0", (1, 1, 1), None)], "0.5"))
    error("missing_level", "'/0' cannot be opened")
    # Chunks of absurd size (2^60 samples each).
    path = os.path.join(out, "huge_chunks.zarr")
    os.makedirs(path)
    with open(os.path.join(path, "zarr.json"), "w") as f:
        json.dump({"zarr_format": 3, "node_type": "array", "shape": [4, 4, 4],
                   "data_type": "uint8", "chunk_grid": {"name": "regular", "configuration":
                   {"chunk_shape": [1 << 20, 1 << 20, 1 << 20]}},
                   "chunk_key_encoding": {"name": "default"}, "fill_value": 0,
                   "codecs": [{"name": "bytes"}]}, f)
    error("huge_chunks", "larger than")

    with open(os.path.join(out, "cases.json"), "w") as f:
        json.dump({"cases": cases, "errors": errors}, f, indent=1)


if __name__ == "__main__":
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    main(out)
