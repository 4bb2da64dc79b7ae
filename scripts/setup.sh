#!/usr/bin/env bash
# Installs what shapecue needs on a Debian/Ubuntu machine that has Rust:
# the OpenCL ICD loader and headers, PoCL (an OpenCL device on the CPU, so
# everything runs without a GPU), and EGL + Mesa (headless OpenGL through
# llvmpipe for src/render; libEGL is loaded at run time), the X11 libraries
# and Xvfb of `shapecue view` (its window, and its tests without a screen),
# and Mesa's Vulkan on the CPU (lavapipe) with the Vulkan loader, for the
# external-memory route between OpenCL and GL (docs/edges.md).
# Used by the README, .ci/run and the Dockerfile.
# Idempotent: installs only what is missing.
set -euo pipefail

pkgs=(ocl-icd-libopencl1 ocl-icd-opencl-dev pocl-opencl-icd clinfo libegl1 libgl1-mesa-dri
    libgl1 libglx-mesa0 libx11-xcb1 libxkbcommon-x11-0 libxcursor1 libxi6 libxrandr2 xvfb xauth
    libvulkan1 mesa-vulkan-drivers)
missing=()
for p in "${pkgs[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
    SUDO=""
    [ "$(id -u)" -eq 0 ] || SUDO="sudo"
    echo "setup: installing ${missing[*]}"
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

if ! command -v cargo >/dev/null 2>&1; then
    echo "setup: cargo not found; install Rust from https://rustup.rs" >&2
    exit 1
fi
if command -v rustup >/dev/null 2>&1; then
    rustup component list --installed 2>/dev/null | grep -q '^rustfmt' || rustup component add rustfmt
    rustup component list --installed 2>/dev/null | grep -q '^clippy' || rustup component add clippy
fi
echo "setup: OpenCL devices:"
clinfo -l 2>/dev/null || true
