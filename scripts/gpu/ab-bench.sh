#!/usr/bin/env bash
# Runs on the GPU machine after scripts/gpu/prelude.sh: the same benchmarks with two motes binaries
# in one sitting, A then B for each workload, so that a change's before and after share the GPU,
# its clocks and its temperature (docs/benchmarks.md: compare only numbers from one sitting).
# Usage: scripts/gpu/ab-bench.sh A_MOTES B_MOTES BACKEND WORKLOAD...
#   WORKLOAD: falling (W1 at 1 M and 16 M), dominoes (W2, 100 k), cloth (W3, 256 and 1024),
#   soft (W4, 10,000 cubes), impulse-dominoes (W2 with impulse contacts, 100 k)
# Output: each run's table, headed "== A|B BACKEND WORKLOAD", in ${OUT:-gpu-out}/ab-BACKEND.txt.
set -uo pipefail
a=$1 b=$2 backend=$3
shift 3
out=${OUT:-gpu-out}
log=$out/ab-$backend.txt
mkdir -p "$out" bench-cache
args_for() {
  case $1 in
    falling) echo "--workload settle --phase falling --sizes 1048576,16777216" ;;
    dominoes) echo "--workload dominoes --dominoes 100000 --domino-rows 100" ;;
    cloth) echo "--workload cloth --cloth-sides 256,1024" ;;
    soft) echo "--workload soft --soft-counts 10000" ;;
    impulse-dominoes)
      echo "--workload impulse-dominoes --dominoes 100000 --domino-rows 100 --domino-steps 500" ;;
    *) echo "ab-bench.sh: unknown workload '$1'" >&2; return 1 ;;
  esac
}
status=0
for what in "$@"; do
  args=$(args_for "$what") || exit 2
  for side in A B; do
    exe=$a
    [[ $side == B ]] && exe=$b
    echo "== $side $backend $what: $exe bench --backend $backend $args" >>"$log"
    # shellcheck disable=SC2086
    timeout "${LIMIT_AB:-240}" "$exe" bench --backend "$backend" $args >>"$log" 2>&1 || status=1
  done
done
grep -vE "^motes bench|^workload" "$log" | tail -n 60
exit $status
