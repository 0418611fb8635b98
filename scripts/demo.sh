#!/usr/bin/env bash
# The quick start's main job: set up (install what is missing, build), then run the default scene
# (a domino chain) on the best available backend, writing frames to out/ (open out/*.pvd in
# ParaView, or read out/ with any VTU reader) and pictures to out/frames/ (a PNG per frame and
# out/frames/video.mp4; docs/rendering.md).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh" "$root/build"
cd "$root"
"$root/build/bin/motes" devices
"$root/build/bin/motes" run --out "$root/out" --render "$root/out/frames" "$@"
echo "demo: pictures in $root/out/frames/ (frame_*.png)"
if [ -f "$root/out/frames/video.mp4" ]; then
  echo "demo: video $root/out/frames/video.mp4"
fi
if [ -f "$root/out/particles.pvd" ]; then
  echo "demo: simulation frames in $root/out/particles.pvd (ParaView)"
fi
