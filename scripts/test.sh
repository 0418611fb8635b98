#!/usr/bin/env bash
# The quick start's test command: the same set-up as demo.sh (warnings are errors here), a format
# check, then every test.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${MOTES_TEST_BUILD:-$root/build-test}
# Each stage says when it starts (seconds since the start), so a slow CI run shows where it went.
stage() { echo "== test.sh: $1 (at ${SECONDS} s)"; }
stage "set-up and build"
# The build and the installed package's lean build (scripts/check-package.sh) compile most of the
# library's files with the same commands: ccache compiles them once (its cache beside the build,
# paths taken relative to the repository, each file's headers from the compiler's own list; the
# core's precompiled header cached too, which needs the two sloppinesses: no file uses __DATE__ or
# __TIME__). The sanitizer build shares no command with them and runs without it.
export MOTES_COMPILER_LAUNCHER=ccache CCACHE_DIR=${CCACHE_DIR:-$build-ccache} CCACHE_BASEDIR=$root \
  CCACHE_DEPEND=1 CCACHE_NOHASHDIR=1 CCACHE_SLOPPINESS=pch_defines,time_macros
# lavapipe, the Vulkan driver the tests run on without a GPU: Mesa 25 from bookworm-backports on
# Debian 12, about three times faster than Debian 12's own (scripts/lavapipe-backport.sh says why).
if [ "${MOTES_LAVAPIPE_BACKPORT:-1}" = 1 ]; then
  "$root/scripts/lavapipe-backport.sh"
fi
"$root/scripts/setup.sh" "$build" -DMOTES_WERROR=ON
stage "format check"
"$root/scripts/check-format.sh"
stage "tests"
cd "$build"
# Tests run side by side: OpenMP threads that spin while waiting would starve each other.
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
# Each would also see the others as load and run on one thread (backends/openmp/cpu_share.h): keep
# the thread counts the tests ask for (tests/unit/test_cpu_share.cpp checks the adapting itself).
export MOTES_CPU_ADAPT=${MOTES_CPU_ADAPT:-0}
# The seeded property scenes (tests/properties) run their OpenMP simulations on one thread: small
# scenes of many short kernels cost less CPU time so than on two threads that wait for each other
# while another test has the second core (tests/properties/random_scenes.h, device_options).
export MOTES_PROPERTY_THREADS=${MOTES_PROPERTY_THREADS:-1}
# Vulkan runs with the Khronos validation layer (synchronization validation included): any message
# it prints fails the test that caused it.
export MOTES_VULKAN_VALIDATION=${MOTES_VULKAN_VALIDATION:-1}
# lavapipe hands every dispatch to worker threads (one per core). The tests already run side by
# side on every core, and at test sizes the hand-offs cost more than they give (the 2-core machine,
# Mesa 22.3: cloth.json on Vulkan 63 steps/s with two workers, 139 with none; four example scenes
# on Vulkan under ctest -j2 took 109 s against 83 s): LP_NUM_THREADS=0 runs each dispatch in the
# thread that submits it. The conformance suite's kernel and scene cases keep two workers
# (tests/CMakeLists.txt), so that on lavapipe too the workgroups of a dispatch run side by side, as
# on a GPU; its extra passes (Conformance.VulkanTwoDimensionalDispatch and .PoisonUnreadBuffers)
# run with none, like the rest.
export LP_NUM_THREADS=${LP_NUM_THREADS:-0}
# --no-tests=error: a build that lists no test fails rather than passing empty.
ctest --output-on-failure -j "${JOBS:-$(nproc)}" --timeout 900 --no-tests=error \
  --output-junit "$build/ctest-results.xml"

# The installed package as another project uses it (examples/embed, find_package and
# pkg-config): static from this build, shared from a lean second build (no CUDA, no tests).
stage "installed package"
MOTES_SKIP_INSTALL=1 "$root/scripts/check-package.sh" "$build"

# The sanitizer stage: every test again, built with AddressSanitizer and UndefinedBehaviorSanitizer
# (MOTES_SANITIZER_STAGE=0 skips it). The Vulkan tests run without the validation layer here (it
# ran above); the Vulkan loader's and lavapipe's process-lifetime allocations are suppressed by
# library name, which works because sanitized executables keep libraries loaded until exit
# (tests/sanitizers/keep_libraries_loaded.cpp); Sanitizers.LeakCanary proves a leak in motes's
# code is still reported. Afterwards every test that passed above must have passed here too.
# CUDA is left out of this build: its kernels run only on a GPU, where compute-sanitizer's
# memcheck and racecheck check them (scripts/gpu/run-suite.sh sanitize).
# It is built with clang (its OpenMP from libomp-dev), the release build above with GCC: two
# compilers' warnings, and clang builds it in about half the time (this 2-core VM: 273 to 306 s,
# 839 CPU-s, against GCC's 568 s and 1,151).
if [ "${MOTES_SANITIZER_STAGE:-1}" = 1 ]; then
  stage "sanitizer build"
  MOTES_COMPILER_LAUNCHER= MOTES_SKIP_INSTALL=1 "$root/scripts/setup.sh" "$build-sanitize" \
    -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DMOTES_WITH_OPENMP=ON \
    -DMOTES_WERROR=ON -DMOTES_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DMOTES_TEST_VULKAN_VALIDATION=OFF -DMOTES_WITH_CUDA=OFF
  cd "$build-sanitize"
  stage "sanitizer tests"
  MOTES_VULKAN_VALIDATION=0 \
    LSAN_OPTIONS=suppressions=$root/tests/sanitizers/lsan.supp:print_suppressions=0 \
    UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --output-on-failure -j "${JOBS:-$(nproc)}" --timeout 1800 --no-tests=error \
    --output-junit "$build-sanitize/ctest-results.xml"
  /usr/bin/python3 "$root/scripts/check-test-counts.py" "$build/ctest-results.xml" \
    "$build-sanitize/ctest-results.xml"
fi

# The fuzzing stage (docs/fuzzing.md): every libFuzzer target for 60 s from seeds made from the
# repository's scenes, meshes and test data, in a clang build of its own (MOTES_FUZZ=ON, ASan +
# UBSan); any crash, leak, timeout or sanitizer report fails it and names the reproducer.
# MOTES_FUZZ_STAGE=0 skips it.
if [ "${MOTES_FUZZ_STAGE:-1}" = 1 ]; then
  stage "fuzzing"
  MOTES_FUZZ_BUILD="$build-fuzz" "$root/scripts/fuzz.sh" all 60
fi
stage "done"
