#!/usr/bin/env bash
# The installed motes, consumed as another project would (examples/embed): `find_package(motes)`
# and motes.pc, static and shared. Run by scripts/test.sh after the tests.
#   static: installed from BUILD (the test build: every backend that was built)
#   shared: a second, lean build (BUILD_SHARED_LIBS=ON, no CUDA, no tests) in BUILD-shared
# Each install goes to a temporary prefix; the example is built against it and run on a scene,
# the installed command runs, and the installed package must not point into the build or source
# tree. Usage: scripts/check-package.sh BUILD
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:?usage: check-package.sh BUILD}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
scene=$root/tests/data/cli/small.json

check() {  # check NAME PREFIX
  local name=$1 prefix=$2
  echo "== package ($name): installed in $prefix"
  if grep -rl -e "$root" -e "$build" "$prefix/lib/cmake" "$prefix/lib/pkgconfig"; then
    echo "check-package: FAILED: the installed package ($name) points into the build or source tree" >&2
    return 1
  fi
  "$prefix/bin/motes" devices >/dev/null
  cmake -S "$root/examples/embed" -B "$work/embed-$name" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
  cmake --build "$work/embed-$name" >/dev/null
  "$work/embed-$name/motes_embed" "$scene" openmp 50 >"$work/out-$name.txt"
  grep -q "^body 3 box\[3\]: position" "$work/out-$name.txt" || {
    echo "check-package: FAILED: examples/embed ($name) printed:" >&2
    cat "$work/out-$name.txt" >&2
    return 1
  }
  # pkg-config: the same program from the command line.
  local flags
  flags=$(PKG_CONFIG_PATH="$prefix/lib/pkgconfig" pkg-config --cflags --libs \
    $([ "$name" = static ] && echo --static) motes)
  # shellcheck disable=SC2086
  c++ -std=c++20 "$root/examples/embed/main.cpp" -o "$work/pc-$name" $flags \
    -Wl,-rpath,"$prefix/lib"
  "$work/pc-$name" "$scene" openmp 10 | grep -q "^body 0 box\[0\]" || {
    echo "check-package: FAILED: the pkg-config build ($name) did not run" >&2
    return 1
  }
  echo "== package ($name): examples/embed built with find_package(motes) and with pkg-config, ran"
  check_vulkan "$name" "$prefix"
}

# examples/embed_vulkan: a program with its own Vulkan device that runs motes on it and draws
# motes' buffers itself, under the validation layer (synchronization validation on) when it is
# installed: any message fails, and the picture must show the particles (not the clear colour in
# a plausible share of its 640 x 480 pixels).
check_vulkan() {  # check_vulkan NAME PREFIX
  local name=$1 prefix=$2
  if ! grep -q 'motes_WITH_VULKAN ON' "$prefix/lib/cmake/motes/motesConfig.cmake"; then
    echo "== package ($name): built without Vulkan, examples/embed_vulkan skipped"
    return 0
  fi
  cmake -S "$root/examples/embed_vulkan" -B "$work/embed-vulkan-$name" -G Ninja \
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
  cmake --build "$work/embed-vulkan-$name" >/dev/null
  local layers=()
  if ls /usr/share/vulkan/explicit_layer.d/*khronos_validation* >/dev/null 2>&1; then
    layers=(VK_INSTANCE_LAYERS=VK_LAYER_KHRONOS_validation
      VK_LAYER_ENABLES=VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT)
  fi
  local out=$work/vulkan-$name.txt
  env "${layers[@]}" "$work/embed-vulkan-$name/motes_embed_vulkan" \
    "$root/examples/scenes/position_dice.json" "$work/vulkan-$name.ppm" 5 >"$out" 2>&1 || {
    echo "check-package: FAILED: examples/embed_vulkan ($name) printed:" >&2
    cat "$out" >&2
    return 1
  }
  local drawn
  drawn=$(sed -n 's/.*: \([0-9]*\) of 307200 pixels drawn.*/\1/p' "$out")
  if grep -q -e 'Validation Error' -e 'SYNC-HAZARD' "$out" || [ -z "$drawn" ] ||
    [ "$drawn" -lt 5000 ] || [ "$drawn" -gt 200000 ]; then
    echo "check-package: FAILED: examples/embed_vulkan ($name): validation messages or an" \
      "implausible picture ($drawn pixels drawn):" >&2
    cat "$out" >&2
    return 1
  fi
  echo "== package ($name): examples/embed_vulkan drew $drawn pixels of particles" \
    "${layers:+under the validation layer}"
}

cmake --install "$build" --prefix "$work/static" >/dev/null
check static "$work/static"

"$root/scripts/setup.sh" "$build-shared" -DBUILD_SHARED_LIBS=ON -DMOTES_BUILD_TESTS=OFF \
  -DMOTES_WITH_CUDA=OFF -DMOTES_WERROR=ON >/dev/null
cmake --install "$build-shared" --prefix "$work/shared" >/dev/null
soname=$(objdump -p "$work/shared/lib/libmotes.so" | awk '/SONAME/ {print $2}')
expected=libmotes.so.$(sed -n 's/^project(motes VERSION \([0-9]*\.[0-9]*\).*/\1/p' "$root/CMakeLists.txt")
if [ "$soname" != "$expected" ]; then
  echo "check-package: FAILED: libmotes.so has SONAME '$soname', expected '$expected'" >&2
  exit 1
fi
check shared "$work/shared"
echo "check-package: static and shared packages work"
