#!/usr/bin/env bash
# Runs `leapview bench` on the GPU machine (see ../shared/GPU.md and docs/benchmarks/README.md).
#
#   scripts/gpu-bench.sh BIN OUT_DIR [bench flags…]
#
# BIN is a release build of leapview made on an x86-64 machine and carried (e.g. .bench-bin/leapview);
# OUT_DIR receives frames.csv, frames.json, summary.json, tables.md, the PNG plots and bench.log
# (8 files: what the device tool can bring back from one folder). The eight scans are read from
# $LEAPVIEW_DATA_DIR (default .bench-data, a carried copy of ../shared/data). Extra flags go to
# `leapview bench`, e.g. `--paths compute` or `--datasets ct_head,mra_head` to split the full run
# into calls that each fit the device tool's 10-minute limit; merge the parts afterwards with
# `leapview bench --merge DIR1,DIR2,… --out docs/benchmarks/<gpu>`.
set -euo pipefail
cd "$(dirname "$0")/.."

if [[ $# -lt 2 ]]; then
    echo "usage: scripts/gpu-bench.sh BIN OUT_DIR [bench flags…]" >&2
    exit 2
fi
bin=$1
out=$2
shift 2
data=${LEAPVIEW_DATA_DIR:-.bench-data}

[[ -x "$bin" ]] || { echo "gpu-bench.sh: $bin is not an executable leapview build" >&2; exit 2; }
[[ -d "$data" ]] || { echo "gpu-bench.sh: no datasets in $data (copy ../shared/data/*.nrrd there and carry it)" >&2; exit 2; }

# The machine has NVIDIA's driver but no Vulkan loader: unpack the carried Debian packages.
if ! ldconfig -p | grep -q libvulkan.so.1; then
    if compgen -G ".gl/*.deb" >/dev/null; then
        for f in .gl/*.deb; do dpkg -x "$f" /; done
        ldconfig
    else
        echo "gpu-bench.sh: no Vulkan loader and no .gl/*.deb to unpack (see docs/benchmarks/README.md)" >&2
        exit 1
    fi
fi
if ! ls /usr/share/vulkan/icd.d/*nvidia* /etc/vulkan/icd.d/*nvidia* >/dev/null 2>&1 \
    && [[ -f /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json ]]; then
    export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
fi
# GL on these machines fails at device creation or renders only background (GPU.md).
export LEAPVIEW_BACKEND=vulkan

mkdir -p "$out"
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader >"$out/bench.log" 2>&1 || true
set -o pipefail
"$bin" bench --config bench/config.json --data-dir "$data" --out "$out" "$@" 2>&1 | tee -a "$out/bench.log"
