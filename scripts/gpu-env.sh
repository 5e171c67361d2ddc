# Sourced by the GPU machine's scripts (gpu-bench.sh, gpu-ab.sh) from the repository root: the
# Vulkan loader from the carried Debian packages where the machine has none, NVIDIA's driver file
# where the loader does not find it, and Vulkan as wgpu's backend. Returns 1 (with the reason on
# stderr) where there is no loader and nothing to unpack.

# The machine has NVIDIA's driver but no Vulkan loader: unpack the carried Debian packages.
if ! ldconfig -p | grep -q libvulkan.so.1; then
    if compgen -G ".gl/*.deb" >/dev/null; then
        for f in .gl/*.deb; do dpkg -x "$f" /; done
        ldconfig
    else
        echo "${0##*/}: no Vulkan loader and no .gl/*.deb to unpack (see docs/benchmarks/README.md)" >&2
        return 1
    fi
fi
if ! ls /usr/share/vulkan/icd.d/*nvidia* /etc/vulkan/icd.d/*nvidia* >/dev/null 2>&1 \
    && [[ -f /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json ]]; then
    export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
fi
# GL on these machines fails at device creation or renders only background (docs/benchmarks/README.md).
export LEAPVIEW_BACKEND="${LEAPVIEW_BACKEND:-vulkan}"
