#!/usr/bin/env bash
# Installs what motes needs from Debian 12 packages (only what is missing), then configures and
# builds it. Usage: scripts/setup.sh [BUILD_DIR] [extra cmake arguments...]
# Environment: MOTES_SKIP_INSTALL=1 skips the package step; JOBS sets build parallelism.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
shift || true

packages=(build-essential cmake ninja-build pkg-config git
  libeigen3-dev libassimp-dev nlohmann-json3-dev libcli11-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev python3 python3-meshio clang-format
  clang libclang-rt-14-dev libomp-dev
  glslang-tools spirv-tools libvulkan-dev libvulkan-volk-dev libvulkan1 mesa-vulkan-drivers
  vulkan-validationlayers libstb-dev ffmpeg python3-dev python3-pybind11 python3-numpy python3-scipy
  libglfw3-dev xvfb xdotool
  python3-pytest libopenmpi-dev openmpi-bin ccache)

if [ "${MOTES_SKIP_INSTALL:-0}" != 1 ]; then
  missing=()
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "== installing: ${missing[*]}"
    if [ "$(id -u)" -ne 0 ]; then
      echo "motes setup: these Debian packages are missing and installing them needs root:" >&2
      echo "  apt-get install ${missing[*]}" >&2
      exit 1
    fi
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  fi
fi

echo "== configuring $build"
# MOTES_COMPILER_LAUNCHER (scripts/test.sh sets ccache): what runs each C++ compile.
launcher=()
if [ -n "${MOTES_COMPILER_LAUNCHER:-}" ]; then
  if command -v "$MOTES_COMPILER_LAUNCHER" >/dev/null; then
    launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER="$MOTES_COMPILER_LAUNCHER")
  else
    echo "motes setup: $MOTES_COMPILER_LAUNCHER not found; compiling without it" >&2
  fi
fi
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" "$@" >/dev/null
echo "== building"
cmake --build "$build" -j "${JOBS:-$(nproc)}"
