#!/usr/bin/env bash
# One sitting of the CPU benchmarks recorded in docs/benchmarks.md: motes (OpenMP) on W1 and W2,
# then LAMMPS on the same W1 work at N = 65,536 (1 and 2 ranks), on the same machine, one after the
# other.
# Results go to bench-cache/cpu-DATE.{txt,json}. Usage: scripts/bench-cpu.sh [extra bench args]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
motes=${MOTES:-$root/build/bin/motes}
stamp=$(date -u +%Y%m%dT%H%MZ)
out=$root/bench-cache/cpu-$stamp
mkdir -p "$root/bench-cache"
{
  echo "== machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(nproc) cores"
  echo "== motes W1 falling + dense, W2 dominoes"
  "$motes" bench --sizes 16384,65536 --cache "$root/bench-cache" --json "$out.json" "$@"
  if command -v lmp >/dev/null; then
    # The goal compares motes with the better of LAMMPS on one and on two ranks, in each phase.
    echo "== LAMMPS W1 N=65536"
    "$root/scripts/bench-lammps.sh" falling 1
    "$root/scripts/bench-lammps.sh" falling 2
    "$root/scripts/bench-lammps.sh" dense 1
    "$root/scripts/bench-lammps.sh" dense 2
  else
    echo "== LAMMPS not run: lmp not found (apt-get install lammps)"
  fi
} 2>&1 | tee "$out.txt"
