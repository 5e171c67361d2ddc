#!/usr/bin/env python3
"""Tiles a raw uint8 volume 2 x 2 in x and y: from `leapview generate vessels --size 1024`'s
1024^3 .raw, the issue's 2048 x 2048 x 1024 (4 GiB) case for `leapview bench --stream`.

    scripts/tile-volume.py v.raw big.raw 1024
    sed -e 's/sizes: 1024 1024 1024/sizes: 2048 2048 1024/' -e 's/v.raw/big.raw/' v.nhdr > big.nhdr
"""
import sys

src, dst, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
with open(src, "rb") as f, open(dst, "wb") as out:
    for _ in range(n):
        plane = f.read(n * n)
        if len(plane) != n * n:
            sys.exit(f"{src}: shorter than {n}^3 bytes")
        rows = b"".join(plane[y * n:(y + 1) * n] * 2 for y in range(n))
        out.write(rows)
        out.write(rows)
