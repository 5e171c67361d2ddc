#!/usr/bin/env bash
# One texture (`one`, --bricks off) against bricks with a page read per sample (`pg`, 5d4db34)
# and bricks held in place, their slot from the brick's index by f32 division (`ip2`).
set -u
scripts/gpu-ab.sh .bench-data/ab9.tar.xz $OUT 1 --config bench/config-targets.json --data-dir .bench-data --paths compute --strategies rc-t,rc-s-df --datasets ct_bonsai,vessels,dense_head
