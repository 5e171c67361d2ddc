#!/usr/bin/env bash
# Takes docs/screenshot.png: the viewer window on the generated Shepp–Logan phantom with the
# defaults (its transfer function picked from the data: ct-brain; strategy auto), drawn by Mesa's
# Vulkan CPU driver (lavapipe) on a virtual X server (Xvfb), so it looks the same on every machine.
#
#   scripts/screenshot.sh [--release] [OUT.png]
#
# Needs Xvfb (`apt-get install xvfb`) and lavapipe (`apt-get install mesa-vulkan-drivers`).
# The app saves the window once the first frame and its GPU time are on screen, logs how the view
# in the screenshot compares with the renderer's own image (it must not differ), then exits.
set -euo pipefail
cd "$(dirname "$0")/.."

profile=debug
cargo_flags=()
if [[ "${1:-}" == "--release" ]]; then
    profile=release
    cargo_flags=(--release)
    shift
fi
out=${1:-docs/screenshot.png}

command -v Xvfb >/dev/null || { echo "screenshot.sh: Xvfb is missing (apt-get install xvfb)" >&2; exit 1; }
icd=$(ls /usr/share/vulkan/icd.d/lvp_icd*.json 2>/dev/null | head -n 1 || true)
[[ -n "$icd" ]] || { echo "screenshot.sh: lavapipe is missing (apt-get install mesa-vulkan-drivers)" >&2; exit 1; }

cargo build "${cargo_flags[@]}" --bin leapview
bin=target/$profile/leapview

# A free display number.
display=99
while [[ -e /tmp/.X$display-lock ]]; do display=$((display + 1)); done

runtime=$(mktemp -d)
chmod 700 "$runtime"
Xvfb ":$display" -screen 0 1280x800x24 -nolisten tcp >"$runtime/xvfb.log" 2>&1 &
xvfb=$!
cleanup() {
    kill "$xvfb" 2>/dev/null || true
    wait "$xvfb" 2>/dev/null || true
    rm -rf "$runtime"
}
trap cleanup EXIT
for _ in $(seq 50); do [[ -e /tmp/.X11-unix/X$display ]] && break; sleep 0.1; done

mkdir -p "$(dirname "$out")"
rm -f "$out"
# XDG_RUNTIME_DIR silences Mesa's warnings; the log line about the comparison is at info level.
DISPLAY=":$display" WAYLAND_DISPLAY='' XDG_RUNTIME_DIR="$runtime" \
    VK_ICD_FILENAMES="$icd" LEAPVIEW_BACKEND=vulkan \
    RUST_LOG="${RUST_LOG:-warn,leapview=info}" \
    LEAPVIEW_SCREENSHOT="$out" LEAPVIEW_EXIT_AFTER_FRAMES=1 \
    timeout 300 "$bin"

[[ -s "$out" ]] || { echo "screenshot.sh: no screenshot was written" >&2; exit 1; }
echo "wrote $out"
