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
