#!/usr/bin/env bash
# The quick start's test command: the same set-up as demo.sh (warnings are errors here), a format
# check, then every test.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${MOTES_TEST_BUILD:-$root/build-test}
"$root/scripts/setup.sh" "$build" -DMOTES_WERROR=ON
"$root/scripts/check-format.sh"
cd "$build"
# Tests run side by side: OpenMP threads that spin while waiting would starve each other.
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
# Vulkan runs with the Khronos validation layer (synchronization validation included): any message
# it prints fails the test that caused it.
export MOTES_VULKAN_VALIDATION=${MOTES_VULKAN_VALIDATION:-1}
ctest --output-on-failure -j "${JOBS:-$(nproc)}" --timeout 900
