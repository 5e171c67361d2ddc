#!/usr/bin/env bash
# A TIFF stack larger than the memory budget (docs/benchmarks/out-of-core/README.md, "TIFF
# stacks"): a generated 1024³ uint16 head written by tifffile as a multi-page BigTIFF and as a
# folder of slices, opened, rendered and converted under --ram-budget 512MiB.
# Run from the repository root with the release build and the tests' .venv.
set -euo pipefail
L=target/release/leapview
PY=.venv/bin/python
W=${1:-/tmp/tiff-ooc}
mkdir -p "$W"
drop() { sync; echo 3 > /proc/sys/vm/drop_caches 2>/dev/null || true; }
t() { /usr/bin/time -f "$1: %e s, peak resident %M KB" "${@:2}"; }
t generate $L generate dense-head --dims 1024,1024,1024 --type uint16 --out "$W/head.ome.zarr"
t multi-page $PY scripts/python/zarr_to_tiff.py "$W/head.ome.zarr" "$W/head.tif"
t folder $PY scripts/python/zarr_to_tiff.py "$W/head.ome.zarr" "$W/slices" --folder
drop; t "info stack" $L info "$W/head.tif" --ram-budget 512MiB
drop; t "info folder" $L info "$W/slices" --ram-budget 512MiB
t "info store" $L info "$W/head.ome.zarr" --ram-budget 512MiB
t "info stack whole" $L info "$W/head.tif"
t "render stack" $L render "$W/head.tif" --ram-budget 512MiB --size 640x480 --out "$W/stack.png"
t "render store" $L render "$W/head.ome.zarr" --ram-budget 512MiB --size 640x480 --out "$W/store.png"
t convert $L convert "$W/head.tif" "$W/from-tiff.ome.zarr" --ram-budget 512MiB
$PY - "$W" <<'PY'
import sys
import numpy as np
import zarr
from PIL import Image
w = sys.argv[1]
a = zarr.open_group(f"{w}/from-tiff.ome.zarr", mode="r")
b = zarr.open_group(f"{w}/head.ome.zarr", mode="r")
same = all(np.array_equal(a["0"][z:z + 64], b["0"][z:z + 64]) for z in range(0, 1024, 64))
same = same and all(np.array_equal(a[str(k)][:], b[str(k)][:]) for k in range(1, 6))
print("converted store equals the generated one, every level (zarr-python):", same)
p = np.asarray(Image.open(f"{w}/stack.png")).astype(int)
q = np.asarray(Image.open(f"{w}/store.png")).astype(int)
d = np.abs(p - q).max(axis=2)
print(f"stack vs store picture: {(d > 0).sum()} of {d.size} pixels differ, by {d.max()}/255 at most")
PY
