#!/usr/bin/env bash
# Installs what lucent needs to build and test on Debian/Ubuntu: the Vulkan loader and headers,
# Mesa's drivers (lavapipe, the CPU Vulkan driver the tests and benchmark run on), the validation
# layer, shaderc/glslang/SPIRV-Tools static libraries (linked by build.rs), vulkaninfo and Xvfb.
#
# On Debian 12 (bookworm), Mesa comes from bookworm-backports (25.0.x, built against the same
# LLVM 15 as bookworm's 22.3.6): its lavapipe has VK_KHR_acceleration_structure and
# VK_KHR_ray_query, which the ray-traced techniques need, and runs lucent's frames faster
# (docs/lavapipe-facts.md). The suite is added as a deb822 file signed by the Debian archive
# keyring, and only mesa-vulkan-drivers is installed from it, with what it needs from there
# (libdrm 2.4.123, and Mesa 25's libgallium with the installed Mesa packages that share it).
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

# Debian 12: Mesa's Vulkan drivers from bookworm-backports unless a Mesa 25 or later is there.
codename=$( (. /etc/os-release 2>/dev/null && echo "${VERSION_CODENAME:-}") || true)
backports=0
if [[ "$codename" == "bookworm" ]]; then
    mesa=$(dpkg-query -W -f='${db:Status-Status} ${Version}' mesa-vulkan-drivers 2>/dev/null || true)
    if [[ "$mesa" != installed\ * ]] || dpkg --compare-versions "${mesa#installed }" lt 25; then
        backports=1
        # Installed from the backports below, not from bookworm first.
        missing=($(printf '%s\n' "${missing[@]}" | grep -vx mesa-vulkan-drivers || true))
    fi
fi

if ((${#missing[@]} > 0 || backports)); then
    sudo=()
    if [[ $(id -u) -ne 0 ]]; then
        if command -v sudo >/dev/null 2>&1; then
            sudo=(sudo)
        else
            echo "setup.sh: not root and no sudo; as root run this script again (it installs ${missing[*]}$( ((backports)) && echo " and Mesa from bookworm-backports"))" >&2
            exit 1
        fi
    fi
    if ((backports)); then
        sources=/etc/apt/sources.list.d/lucent-bookworm-backports.sources
        # A source that names the suite outside a comment is enough.
        if ! grep -rqsE '^[^#]*bookworm-backports' /etc/apt/sources.list /etc/apt/sources.list.d/; then
            echo "setup.sh: adding bookworm-backports ($sources)"
            printf '%s\n' "Types: deb" "URIs: http://deb.debian.org/debian" \
                "Suites: bookworm-backports" "Components: main" \
                "Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg" |
                "${sudo[@]}" tee "$sources" >/dev/null
        fi
    fi
    "${sudo[@]}" apt-get update
    if ((${#missing[@]} > 0)); then
        echo "setup.sh: installing ${missing[*]}"
        "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}"
    fi
    if ((backports)); then
        echo "setup.sh: installing mesa-vulkan-drivers from bookworm-backports"
        "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends \
            -t bookworm-backports mesa-vulkan-drivers
    fi
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
installed="$installed; mesa-vulkan-drivers $(dpkg-query -W -f='${Version}' mesa-vulkan-drivers)"

echo "setup.sh: ok ($installed; $(cargo --version))"
