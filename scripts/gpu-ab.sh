#!/usr/bin/env bash
# Before against after on the GPU machine: runs `leapview bench` with each build of an archive in
# turn, alternating, so that every comparison comes from one device call (docs/benchmarks/README.md,
# "Before against after").
#
#   scripts/gpu-ab.sh ARCHIVE OUT ROUNDS [bench flags…]
#
# ARCHIVE is a tar.xz of stripped leapview builds made here (`strip -o /tmp/pk/main
# target/release/leapview`, one per build, then `tar cf - -C /tmp/pk main fix | xz -9e -T2 >
# .bench-data/bins.tar.xz`: builds share most bytes, so two or three fit the 64 MiB carry beside
# the scans); its members run in the archive's order, ROUNDS times (main-1, fix-1, main-2, …).
# Each run writes /tmp/r/NAME-I/ and NAME-I.log; before the runs every build's `leapview shaders`
# (and `--unlit`, `--bricked`) goes to /tmp/r/shaders-NAME*.md, where the driver reports
# statistics; the SM clock is logged every 500 ms to /tmp/r/clock.log. After every run /tmp/r is packed into
# OUT/r.tgz (the device tool brings back 8 files a call; a call cut short keeps what it ran).
# A member NAME.flags is not a build: its one line of flags is added to build NAME's runs (the
# same build twice under two names, e.g. `--bricks off` against `--bricks on`).
# Bench flags go to every run; give `--config` (a configuration in bench/: its transfer-function
# paths are relative to it) and `--data-dir .bench-data`. Carry [".gl", ".bench-data"].
set -euo pipefail
cd "$(dirname "$0")/.."

if [[ $# -lt 3 ]]; then
    echo "usage: scripts/gpu-ab.sh ARCHIVE OUT ROUNDS [bench flags…]" >&2
    exit 2
fi
archive=$1
out=$2
rounds=$3
shift 3
[[ -f "$archive" ]] || { echo "gpu-ab.sh: no archive $archive" >&2; exit 2; }
[[ "$rounds" =~ ^[1-9][0-9]?$ ]] || { echo "gpu-ab.sh: ROUNDS must be 1 to 99, not $rounds" >&2; exit 2; }

# The Vulkan loader and driver (scripts/gpu-env.sh).
source scripts/gpu-env.sh || exit 1

bins=$(mktemp -d)
mkdir -p /tmp/r "$out"
tar xJf "$archive" -C "$bins"
mapfile -t names < <(tar tJf "$archive" | grep -v '\.flags$')
# Flags of build $1 from its NAME.flags member, if any.
flags_of() { [[ -f "$bins/$1.flags" ]] && cat "$bins/$1.flags" || true; }
pack() { tar czf "$out/r.tgz" -C /tmp r; }

if command -v nvidia-smi >/dev/null; then
    nvidia-smi --query-gpu=name,driver_version,clocks.sm --format=csv,noheader | tee /tmp/r/gpu.txt
    nvidia-smi --query-gpu=timestamp,clocks.sm,utilization.gpu --format=csv,noheader -lms 500 \
        >/tmp/r/clock.log 2>&1 &
    clock=$!
    trap 'kill $clock 2>/dev/null || true' EXIT
fi
for name in "${names[@]}"; do
    "$bins/$name" shaders >"/tmp/r/shaders-$name.md" 2>&1 || true
    "$bins/$name" shaders --unlit >"/tmp/r/shaders-$name-unlit.md" 2>&1 || true
    "$bins/$name" shaders --bricked >"/tmp/r/shaders-$name-bricked.md" 2>&1 || true
done
pack
status=0
for round in $(seq 1 "$rounds"); do
    for name in "${names[@]}"; do
        run="$name-$round"
        # shellcheck disable=SC2046 # the flags are words
        if "$bins/$name" bench "$@" $(flags_of "$name") --out "/tmp/r/$run" >"/tmp/r/$run.log" 2>&1; then
            echo "$run: $(tail -n 1 "/tmp/r/$run.log")"
        else
            status=$?
            echo "$run FAILED (status $status): $(tail -n 1 "/tmp/r/$run.log")"
        fi
        pack
    done
done
exit $status
