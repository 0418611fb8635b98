#!/usr/bin/env bash
# Runs on the GPU machine, in the repository root, after scripts/gpu/bundle.sh built gpu-bundle/
# here and it travelled along: devices, the conformance suite (validation layer on), and the
# benchmarks, each part under its own time limit so that one slow part cannot lose the others'
# results. Results go to ${OUT:-gpu-out}/.
# Usage: scripts/gpu/run-suite.sh [conformance|bench|all]   (default all)
set -uo pipefail
what=${1:-all}
out=${OUT:-gpu-out}
mkdir -p "$out"
. "$(dirname "$0")/prelude.sh"
# At most 8 files come back from the GPU machine: the device list heads the conformance log.
{ nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader; motes devices; } \
  2>&1 | tee "$out/conformance.txt"
status=0
part() {  # part SECONDS NAME COMMAND...: runs COMMAND, its output to $out/NAME.txt
  local limit=$1 name=$2
  shift 2
  echo "== $name (at most ${limit} s)"
  timeout "$limit" "$@" >>"$out/$name.txt" 2>&1
  local rc=$?
  tail -n 25 "$out/$name.txt"
  echo "== $name: exit $rc"
  return $rc
}
if [ "$what" = all ] || [ "$what" = conformance ]; then
  MOTES_VULKAN_VALIDATION=1 MOTES_CONFORMANCE_TABLE="$out/conformance.md" \
    part "${LIMIT_CONFORMANCE:-180}" conformance motes_conformance_tests --gtest_brief=1 || status=1
  # Again with at most 3 workgroups per dimension (every shader through the 2D-dispatch path) and
  # the scan without subgroup arithmetic.
  MOTES_VULKAN_VALIDATION=1 MOTES_VULKAN_MAX_GROUPS_X=3 MOTES_VULKAN_NO_SUBGROUPS=1 \
    MOTES_CONFORMANCE_BACKENDS=vulkan \
    part 60 conformance motes_conformance_tests --gtest_brief=1 --gtest_filter=-*Scenes* ||
    status=1
  # The README's main job, on the GPU.
  MOTES_VULKAN_VALIDATION=1 part 60 conformance motes run examples/scenes/dominoes.json \
    --backend vulkan --out "${TMPDIR:-/tmp}/motes-dominoes" || status=1
fi
if [ "$what" = all ] || [ "$what" = bench ]; then
  mkdir -p bench-cache
  # The floors, in the same run: device-to-device copy and CUB's sort of N (key, value) pairs.
  part 60 bench-falling motes_gpu_floors \
    $(echo "${MOTES_GPU_SIZES:-16384,65536,262144,1048576,4194304,16777216}" | tr , ' ')
  part "${LIMIT_FALLING:-170}" bench-falling motes bench --backend vulkan --workload settle \
    --phase falling --sizes "${MOTES_GPU_SIZES:-16384,65536,262144,1048576,4194304,16777216}" \
    --json "$out/bench-falling.json"
  part "${LIMIT_DOMINOES:-60}" bench-dominoes motes bench --backend vulkan --workload dominoes \
    --dominoes 100000 --domino-rows 100 --json "$out/bench-dominoes.json"
  part "${LIMIT_DENSE:-150}" bench-dense motes bench --backend vulkan --workload settle \
    --phase dense --sizes "${MOTES_GPU_DENSE_SIZES:-16384,65536,262144,1048576}" \
    --json "$out/bench-dense.json"
fi
exit "$status"
