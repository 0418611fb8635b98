#!/bin/sh
# Vulkan's two conditional rebuilds give the same run: each scene's first steps with the indirect
# passes (MOTES_VULKAN_SMALL_REBUILD=0) and with neighbours_update_small.glsl's one workgroup
# (a table of up to 1,048,576 buckets) must end in the same state hash, with no guard warning.
# Usage: small_rebuild_same_state.sh MOTES_CLI SCENES_DIR OUT_DIR
set -u
cli=$1 scenes=$2 out=$3
status=0
for run in fluid_mixed:30 position_mixed:30 impulse_dominoes:1000; do
  scene=${run%%:*} steps=${run#*:}
  hashes=""
  for table in 0 1048576; do
    log=$(MOTES_VULKAN_SMALL_REBUILD=$table "$cli" run "$scenes/$scene.json" --backend vulkan \
      --steps "$steps" --out "$out/small-rebuild-$scene-$table" 2>&1)
    rc=$?
    hash=$(echo "$log" | sed -n 's/^ *state hash *//p')
    echo "$scene, table $table: exit $rc, state hash ${hash:-none}"
    if [ $rc -ne 0 ] || [ -z "$hash" ] || echo "$log" | grep -qiE "warning:|validation (error|warning)"; then
      echo "$log" | tail -n 20
      status=1
    fi
    hashes="$hashes $hash"
  done
  set -- $hashes
  if [ "${1:-a}" != "${2:-b}" ]; then
    echo "$scene: the state hashes differ ($hashes )"
    status=1
  fi
done
exit $status
