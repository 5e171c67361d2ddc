#!/usr/bin/env bash
# One texture (`one`, 61fd9c6 with --bricks off) against the same build whose every volume read
# also does the address arithmetic bricks held in place would need, multiplied by a uniform zero
# (`alu`, alu-probe.patch, --bricks off), and bricks with a page read per sample (`pg`, 61fd9c6
# with --bricks on). ab-11 is the same command in a second call on the same machine.
set -u
scripts/gpu-ab.sh .bench-data/ab10.tar.xz $OUT 1 --config bench/config-targets.json --data-dir .bench-data --paths compute --strategies rc-t,rc-s-df --datasets ct_bonsai,vessels,dense_head
