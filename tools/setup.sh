#!/usr/bin/env bash
# Installs what lucent needs to build and test on Debian/Ubuntu: the Vulkan loader and headers,
# Mesa's drivers (lavapipe, the CPU Vulkan driver the tests and benchmark run on), the validation
# layer, shaderc/glslang/SPIRV-Tools static libraries (linked by build.rs), vulkaninfo and Xvfb.
# Idempotent: when everything is installed it only checks (well under a second).
set -euo pipefail

packages=(
    mesa-vulkan-drivers
    vulkan-validationlayers
    libshaderc-dev
    glslang-dev
    spirv-tools
    libvulkan-dev
    xvfb
    vulkan-tools
    fonts-dejavu-core
)

if ! command -v dpkg-query >/dev/null 2>&1; then
    echo "setup.sh: dpkg-query not found; this script knows Debian/Ubuntu only. Install the equivalents of: ${packages[*]}" >&2
    exit 1
fi

missing=()
for pkg in "${packages[@]}"; do
    status=$(dpkg-query -W -f='${db:Status-Status}' "$pkg" 2>/dev/null || true)
    if [[ "$status" != "installed" ]]; then
        missing+=("$pkg")
    fi
done

if ((${#missing[@]} > 0)); then
    echo "setup.sh: installing ${missing[*]}"
    sudo=()
    if [[ $(id -u) -ne 0 ]]; then
        if command -v sudo >/dev/null 2>&1; then
            sudo=(sudo)
        else
            echo "setup.sh: not root and no sudo; as root run: apt-get install -y --no-install-recommends ${missing[*]}" >&2
            exit 1
        fi
    fi
    "${sudo[@]}" apt-get update
    "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}"
fi

if ! command -v cargo >/dev/null 2>&1; then
    echo "setup.sh: cargo not found; install Rust from https://rustup.rs (then open a new shell)" >&2
    exit 1
fi

if ((${#missing[@]} > 0)); then
    installed="installed ${#missing[@]} package(s)"
else
    installed="all ${#packages[@]} packages already present"
fi
echo "setup.sh: ok ($installed; $(cargo --version))"
