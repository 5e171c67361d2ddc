#!/usr/bin/env bash
# One texture (`one`, --bricks off) against bricks with a page read per sample (`pg`, 5d4db34)
# and bricks held in place, found with no page read (`ip`), compute then fragment, one call.
set -u
scripts/gpu-ab.sh .bench-data/ab8.tar.xz $OUT/c 1 --config bench/config-targets.json --data-dir .bench-data --paths compute --strategies rc-t,rc-s-df --datasets ct_bonsai,vessels,dense_head
mv /tmp/r /tmp/rc
scripts/gpu-ab.sh .bench-data/ab8.tar.xz $OUT/f 1 --config bench/config.json --data-dir .bench-data --paths fragment
