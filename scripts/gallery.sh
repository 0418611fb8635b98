#!/usr/bin/env bash
# Renders every example scene (examples/scenes/*.json) into docs/gallery/: for SCENE, a still
# (SCENE.png, 640 px wide), a short animated GIF (SCENE.gif, 480 px wide, about 3 s, under ~2 MB)
# and the full video (SCENE.mp4, 960x540 H.264). Needs a built motes and ffmpeg.
# Usage: scripts/gallery.sh [MOTES_BINARY]   (default: build/bin/motes)
# Environment: GALLERY_SIZE (render size, default 960x540), GALLERY_SCENES (names to render,
# default all), GALLERY_WORK (scratch directory, default a temporary one), GALLERY_BACKEND
# (default auto; openmp is much faster than Vulkan on lavapipe on a machine without a GPU).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
motes=${1:-$root/build/bin/motes}
size=${GALLERY_SIZE:-960x540}
out=$root/docs/gallery
if [ ! -x "$motes" ]; then
  echo "gallery: $motes not found; build first (scripts/setup.sh) or pass the motes binary" >&2
  exit 1
fi
if ! command -v ffmpeg >/dev/null; then
  echo "gallery: ffmpeg is needed for the GIFs and videos (Debian: apt-get install ffmpeg)" >&2
  exit 1
fi
work=${GALLERY_WORK:-$(mktemp -d)}
[ -n "${GALLERY_WORK:-}" ] || trap 'rm -rf "$work"' EXIT
mkdir -p "$out"

for scene in "$root"/examples/scenes/*.json; do
  name=$(basename "$scene" .json)
  if [ -n "${GALLERY_SCENES:-}" ] && [[ " $GALLERY_SCENES " != *" $name "* ]]; then continue; fi
  echo "== $name"
  frames=$work/$name
  rm -rf "$frames"
  "$motes" run "$scene" --backend "${GALLERY_BACKEND:-auto}" --format none --render "$frames" \
    --size "$size" 2>/dev/null |
    grep -E "^motes: (video|rendering)|pictures"
  count=$(ls "$frames"/frame_*.png | wc -l)
  # The still: the frame 40% of the way through (the motion under way), 640 px wide.
  still=$(printf '%s/frame_%06d.png' "$frames" $((count * 2 / 5)))
  ffmpeg -v error -y -i "$still" -vf scale=640:-2:flags=lanczos "$out/$name.png"
  # The GIF: about 3 s of the run at 20 fps, 480 px wide, one palette made for the clip.
  step=$(( count / 60 > 0 ? count / 60 : 1 ))
  gif_filter="select='not(mod(n\,$step))',setpts=N/20/TB,scale=480:-2:flags=lanczos"
  ffmpeg -v error -y -framerate 20 -i "$frames/frame_%06d.png" \
    -vf "$gif_filter,split[a][b];[a]palettegen=max_colors=128:stats_mode=diff[p];[b][p]paletteuse=dither=bayer:bayer_scale=4:diff_mode=rectangle" \
    -r 20 "$out/$name.gif"
  cp "$frames/video.mp4" "$out/$name.mp4"
  ls -l "$out/$name.png" "$out/$name.gif" "$out/$name.mp4" | awk '{print "   " $5 " bytes  " $9}'
done
echo "gallery: $out"
