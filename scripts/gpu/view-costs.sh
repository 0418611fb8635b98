#!/usr/bin/env bash
# What a frame of `motes view` costs on the GPU machine, zero copy against staged (docs/viewer.md,
# "What a frame costs"): boxes of 4 x 4 x 4 particles on a floor with position contacts in 4
# substeps, 160, 16,000 and 160,000 of them (10,240, 1,024,000 and 10,240,000 particles), drawn
# offscreen at 1280 x 720 for FRAMES frames (default 20) on Vulkan, zero copy and --staged, and on
# CUDA, by the CUDA copy and --staged. Each run prints its summary line: step, copy to the host and
# draw (which holds the CUDA copy), ms a frame. Run from the repository root after `. scripts/gpu/prelude.sh`:
#   scripts/gpu/view-costs.sh [FRAMES] [SIZES...]      e.g. scripts/gpu/view-costs.sh 20 160 16000
# RUNS (a |-separated list of backend options, default all four) and VIEW_ARGS (added to every
# run, e.g. --no-shadows) choose what runs.
set -euo pipefail
frames=${1:-20}
shift || true
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(160 16000 160000)
motes=${MOTES:-$(command -v motes || echo build/bin/motes)}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT

scene() {  # scene BOXES FILE: rows of boxes 5 cm apart on a floor, as square as the count allows
  local boxes=$1 file=$2 rows cols r bodies=""
  rows=$(awk -v n="$boxes" 'BEGIN { r = int(sqrt(n)); while (n % r) r--; print r }')
  cols=$((boxes / rows))
  for ((r = 0; r < rows; ++r)); do
    bodies+="${bodies:+,}{\"name\": \"row$r\", \"material\": \"plastic\", \"shape\": {\"type\": \"box\", \"particles\": [4, 4, 4]}, \"position\": [0.0, 0.02, $(awk -v r="$r" 'BEGIN { print 0.05 * r }')], \"repeat\": {\"count\": $cols, \"offset\": [0.05, 0.0, 0.0]}}"
  done
  cat >"$file" <<JSON
{ "settings": { "dt": 0.016666666666666666, "substeps": 4, "contact_model": "position",
                "gravity": [0.0, -9.81, 0.0], "particle_diameter": 0.01 },
  "materials": { "plastic": { "density": 1200.0, "friction": 0.4, "restitution": 0.3 } },
  "planes": [ { "name": "floor", "normal": [0.0, 1.0, 0.0], "point": [0.0, 0.0, 0.0] } ],
  "bodies": [ $bodies ] }
JSON
}

for boxes in "${sizes[@]}"; do
  file=$dir/boxes-$boxes.json
  scene "$boxes" "$file"
  IFS='|' read -r -a runs <<<"${RUNS:-vulkan|vulkan --staged|cuda|cuda --staged}"
  for run in "${runs[@]}"; do
    echo "== $((64 * boxes)) particles, --backend $run ${VIEW_ARGS:-}"
    # shellcheck disable=SC2086
    "$motes" view "$file" --offscreen --frames "$frames" --size 1280x720 --backend $run ${VIEW_ARGS:-} |
      grep -e '^motes view: drawing' -e 'frames shown' || echo "(failed)"
  done
done
