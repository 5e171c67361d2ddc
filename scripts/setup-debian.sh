#!/bin/sh
# Installs what LeapView needs on Debian 12 that is not there yet: cmake and a C++ compiler (the
# build compiles CharLS, the JPEG-LS codec DICOM files use), a Vulkan driver (Mesa's CPU
# driver lavapipe, only where no Vulkan driver is installed) and, with --tests, the virtual X
# server the window tests start and xdotool, with which they click in the window, and a Python
# environment `.venv` with pydicom, nibabel and zarr (scripts/python/requirements-tests.txt), whose
# readers the tests check LeapView's against. Uses sudo unless run as root. Installs nothing
# when all is there.
#
#   scripts/setup-debian.sh            for the app
#   scripts/setup-debian.sh --tests    for the app and the tests
#   scripts/setup-debian.sh --check    says what is missing, installs nothing (exit 1 if anything)
set -eu

tests=no
check=no
for arg in "$@"; do
  case "$arg" in
    --tests) tests=yes ;;
    --check) check=yes ;;
    *) echo "usage: $0 [--tests] [--check]" >&2; exit 2 ;;
  esac
done

missing=""
if ! command -v cmake >/dev/null 2>&1; then
  missing="$missing cmake"
fi
if ! command -v c++ >/dev/null 2>&1; then
  missing="$missing g++"
fi
if ! ls /usr/share/vulkan/icd.d/*.json >/dev/null 2>&1; then
  missing="$missing mesa-vulkan-drivers"
fi
if [ "$tests" = yes ] && ! command -v Xvfb >/dev/null 2>&1; then
  missing="$missing xvfb"
fi
if [ "$tests" = yes ] && ! command -v xdotool >/dev/null 2>&1; then
  missing="$missing xdotool"
fi
if [ "$tests" = yes ] && ! python3 -c "import venv, ensurepip" >/dev/null 2>&1; then
  missing="$missing python3-venv"
fi
if [ "$tests" = yes ] && ! command -v npm >/dev/null 2>&1; then
  missing="$missing nodejs npm"
fi

# The tests' Python references, in .venv beside this script's folder; remade when the
# requirements change.
here="$(cd "$(dirname "$0")/.." && pwd)"
requirements="$here/scripts/python/requirements-tests.txt"
venv_ready() {
  [ -x "$here/.venv/bin/python" ] && cmp -s "$requirements" "$here/.venv/requirements-tests.txt"
}
make_venv() {
  if venv_ready; then
    echo "setup: .venv is ready (pydicom, nibabel)"
    return 0
  fi
  echo "setup: making .venv from scripts/python/requirements-tests.txt"
  rm -rf "$here/.venv"
  python3 -m venv "$here/.venv"
  "$here/.venv/bin/pip" install --quiet --disable-pip-version-check -r "$requirements"
  cp "$requirements" "$here/.venv/requirements-tests.txt"
}

# The tests' Node packages (Azurite), in .node, from scripts/node's lock file; remade when it
# changes. Install scripts are not run: Azurite needs none.
lock="$here/scripts/node/package-lock.json"
node_ready() {
  [ -x "$here/.node/node_modules/.bin/azurite-blob" ] && cmp -s "$lock" "$here/.node/package-lock.json"
}
make_node() {
  if node_ready; then
    echo "setup: .node is ready (Azurite)"
    return 0
  fi
  echo "setup: making .node from scripts/node/package-lock.json"
  rm -rf "$here/.node"
  mkdir -p "$here/.node"
  cp "$here/scripts/node/package.json" "$lock" "$here/.node/"
  npm ci --prefix "$here/.node" --ignore-scripts --no-audit --no-fund --loglevel=error
}

if [ -z "$missing" ]; then
  echo "setup: nothing to install (cmake, C++ compiler, Vulkan driver$( [ "$tests" = yes ] && echo ', Xvfb, xdotool, python3-venv, npm') present)"
  if [ "$tests" = yes ]; then
    if [ "$check" = yes ]; then
      venv_ready || { echo "setup: missing: .venv (the tests' Python)" >&2; exit 1; }
      node_ready || { echo "setup: missing: .node (the tests' Azurite)" >&2; exit 1; }
    else
      make_venv
      make_node
    fi
  fi
  exit 0
fi
if [ "$check" = yes ]; then
  echo "setup: missing:$missing" >&2
  exit 1
fi

if [ "$(id -u)" -eq 0 ]; then
  run=""
elif command -v sudo >/dev/null 2>&1; then
  run="sudo"
else
  echo "setup: need root to install$missing (run as root, or install sudo)" >&2
  exit 1
fi
echo "setup: installing$missing"
$run env DEBIAN_FRONTEND=noninteractive apt-get update -qq
# shellcheck disable=SC2086
$run env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $missing
if [ "$tests" = yes ]; then
  make_venv
  make_node
fi
