#!/usr/bin/env bash
# Runs the conformance suite on every available device (MOTES_CONFORMANCE_BACKENDS restricts
# them) and writes its results table (device x case x error x verdict) as Markdown, for
# docs/conformance.md. Exits with the suite's status; the table is written either way.
# Usage: scripts/conformance-table.sh [BUILD_DIR] [OUT.md]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
out=${2:-$PWD/conformance-table.md}
exe=$build/tests/motes_conformance_tests
if [ ! -x "$exe" ]; then
  echo "no $exe: configure and build the tests first (cmake --build $build)" >&2
  exit 1
fi
# Threads that spin while waiting slow everything else down on a small machine.
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
export MOTES_VULKAN_VALIDATION=${MOTES_VULKAN_VALIDATION:-1}
MOTES_CONFORMANCE_TABLE="$out" "$exe" --gtest_brief=1
