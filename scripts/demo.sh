#!/usr/bin/env bash
# The quick start's main job: set up (install what is missing, build), then run the default scene
# (a domino chain) on the best available backend, writing frames to out/ (open out/*.pvd in
# ParaView, or read out/ with any VTU reader).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh" "$root/build"
cd "$root"
"$root/build/bin/motes" devices
"$root/build/bin/motes" run --out "$root/out" "$@"
