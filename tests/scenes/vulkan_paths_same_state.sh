#!/bin/sh
# Vulkan's ways of running the same steps give the same run: each scene's first steps with the
# conditional rebuild's indirect passes dispatched empty, one step a command buffer (the settings
# of a device without conditional rendering: MOTES_VULKAN_NO_CONDITIONAL=1, MOTES_VULKAN_CYCLES=1),
# with the indirect passes in conditional rendering and 16 steps a command buffer (lavapipe's
# default), and with neighbours_update_small.glsl's one workgroup (a table of up to 1,048,576
# buckets) must end in the same state hash, with no guard warning.
# Usage: vulkan_paths_same_state.sh MOTES_CLI SCENES_DIR OUT_DIR
set -u
cli=$1 scenes=$2 out=$3
status=0
for run in fluid_mixed:30 position_mixed:30 impulse_dominoes:1000; do
  scene=${run%%:*} steps=${run#*:}
  hashes=""
  for way in empty default small; do
    case $way in
      empty) settings="MOTES_VULKAN_SMALL_REBUILD=0 MOTES_VULKAN_NO_CONDITIONAL=1 MOTES_VULKAN_CYCLES=1" ;;
      default) settings="MOTES_VULKAN_SMALL_REBUILD=0" ;;
      small) settings="MOTES_VULKAN_SMALL_REBUILD=1048576" ;;
    esac
    log=$(env $settings "$cli" run "$scenes/$scene.json" --backend vulkan \
      --steps "$steps" --out "$out/vulkan-paths-$scene-$way" 2>&1)
    rc=$?
    hash=$(echo "$log" | sed -n 's/^ *state hash *//p')
    echo "$scene, $way ($settings): exit $rc, state hash ${hash:-none}"
    if [ $rc -ne 0 ] || [ -z "$hash" ] || echo "$log" | grep -qiE "warning:|validation (error|warning)"; then
      echo "$log" | tail -n 20
      status=1
    fi
    hashes="$hashes $hash"
  done
  set -- $hashes
  if [ "${1:-a}" != "${2:-b}" ] || [ "${1:-a}" != "${3:-c}" ]; then
    echo "$scene: the state hashes differ ($hashes )"
    status=1
  fi
done
exit $status
