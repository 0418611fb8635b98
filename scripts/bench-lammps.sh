#!/usr/bin/env bash
# Runs LAMMPS (Debian package `lammps`) on W1 "settle" at N = 65,536, the same work as
# `motes bench --workload settle --sizes 65536` (docs/benchmarks.md), and prints particle-steps/s.
# Usage: scripts/bench-lammps.sh [falling|dense] [RANKS]   (dense needs settled.data: the first
# dense run makes it with in.make_settled, which takes 10 to 50 minutes on 2 cores).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
phase=${1:-falling}
ranks=${2:-2}
work=${LAMMPS_WORK:-$root/bench-cache/lammps}
command -v lmp >/dev/null || { echo "lmp not found: apt-get install lammps" >&2; exit 1; }
mkdir -p "$work"
cp "$root"/bench/lammps/in.* "$work"/
cd "$work"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
case "$phase" in
  falling) input=in.falling steps=2000 ;;
  dense)
    [ -f settled.data ] || mpirun --bind-to none -np "$ranks" lmp -in in.make_settled -log make_settled.log
    input=in.measure steps=5000 ;;
  *) echo "phase must be falling or dense" >&2; exit 2 ;;
esac
mpirun --bind-to none -np "$ranks" lmp -in "$input" -log "$phase.log" >/dev/null
loop=$(grep -m1 "^Loop time of" "$phase.log" | awk '{print $4}')
echo "lammps W1 $phase N=65536 ranks=$ranks: loop time $loop s for $steps steps," \
  "$(awk -v t="$loop" -v s="$steps" 'BEGIN{printf "%.3e", 65536*s/t}') particle-steps/s"
