#!/usr/bin/env bash
# Runs on the GPU machine after scripts/gpu/prelude.sh: one workload with several motes binaries
# in turn, ROUNDS times over, so that every binary's runs share the GPU, its clocks and its
# temperature with the others' (a bisect, or a before and after finer than ab-bench.sh's pairs).
# Each run's `motes bench --json` (full-precision ms/step and per-kernel times) is kept.
# Usage: scripts/gpu/ab-rounds.sh BACKEND WORKLOAD ROUNDS NAME=MOTES...
#   WORKLOAD as scripts/gpu/ab-bench.sh (falling1m, falling16m: W1 falling at 1 M or 16 M alone)
# Output: ${OUT:-gpu-out}/ab-rounds.tar.gz holding BACKEND-WORKLOAD-NAME-ROUND.json, and a line
# per run on stdout.
set -uo pipefail
backend=$1 workload=$2 rounds=$3
shift 3
out=${OUT:-gpu-out}
dir=$(mktemp -d)
mkdir -p "$out" bench-cache
case $workload in
  falling) args="--workload settle --phase falling --sizes 1048576,16777216" ;;
  falling1m) args="--workload settle --phase falling --sizes 1048576" ;;
  falling16m) args="--workload settle --phase falling --sizes 16777216" ;;
  dominoes) args="--workload dominoes --dominoes 100000 --domino-rows 100" ;;
  cloth) args="--workload cloth --cloth-sides 256,1024" ;;
  soft) args="--workload soft --soft-counts 10000" ;;
  *) echo "ab-rounds.sh: unknown workload '$workload'" >&2; exit 2 ;;
esac
status=0
for ((r = 1; r <= rounds; ++r)); do
  for pair in "$@"; do
    name=${pair%%=*} exe=${pair#*=}
    json=$dir/$backend-$workload-$name-$r.json
    # shellcheck disable=SC2086
    if timeout "${LIMIT_AB:-240}" "$exe" bench --backend "$backend" $args --json "$json" \
      >"$dir/$name-$r.log" 2>&1; then
      echo "$backend $workload $name round $r: $(grep -o '"median_ms_per_step": *[0-9.e-]*' "$json" | tr '\n' ' ')"
    else
      echo "$backend $workload $name round $r: failed"; tail -n 5 "$dir/$name-$r.log"; status=1
    fi
  done
done
tar -czf "$out/ab-rounds-$backend-$workload.tar.gz" -C "$dir" .
exit $status
