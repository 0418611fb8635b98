#!/usr/bin/env bash
# Runs on the GPU machine, in the repository root, after scripts/gpu/bundle.sh built gpu-bundle/
# here and it travelled along: devices, the conformance suite (validation layer on), and the
# benchmarks. Results go to ${OUT:-gpu-out}/.
# Usage: scripts/gpu/run-suite.sh [conformance|bench|all]   (default all)
set -uo pipefail
what=${1:-all}
out=${OUT:-gpu-out}
mkdir -p "$out"
. "$(dirname "$0")/prelude.sh"
{ nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader; motes devices; } \
  2>&1 | tee "$out/devices.txt"
status=0
if [ "$what" = all ] || [ "$what" = conformance ]; then
  MOTES_VULKAN_VALIDATION=1 MOTES_CONFORMANCE_TABLE="$out/conformance.md" \
    motes_conformance_tests --gtest_brief=1 2>&1 | tee "$out/conformance.log" | tail -60
  status=${PIPESTATUS[0]}
fi
if [ "$what" = all ] || [ "$what" = bench ]; then
  mkdir -p bench-cache
  motes bench --backend vulkan --workload settle --phase falling \
    --sizes ${MOTES_GPU_SIZES:-16384,65536,262144,1048576,4194304,16777216} \
    --json "$out/bench-falling.json" 2>&1 | tee "$out/bench-falling.txt"
  motes bench --backend vulkan --workload settle --phase dense \
    --sizes ${MOTES_GPU_DENSE_SIZES:-16384,65536,262144,1048576} \
    --json "$out/bench-dense.json" 2>&1 | tee "$out/bench-dense.txt"
  motes bench --backend vulkan --workload dominoes --dominoes 100000 --domino-rows 100 \
    --json "$out/bench-dominoes.json" 2>&1 | tee "$out/bench-dominoes.txt"
fi
exit "$status"
