#!/usr/bin/env bash
# Runs `leapview bench` on the GPU machine (see docs/benchmarks/README.md, "Rerunning").
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

# The Vulkan loader and driver (scripts/gpu-env.sh).
source scripts/gpu-env.sh || exit 1

mkdir -p "$out"
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader >"$out/bench.log" 2>&1 || true
set -o pipefail
"$bin" bench --config bench/config.json --data-dir "$data" --out "$out" "$@" 2>&1 | tee -a "$out/bench.log"
