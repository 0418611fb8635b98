#!/usr/bin/env bash
# Builds motes for the GPU machine and bundles what has to travel there (it has no network and
# lacks assimp, the Vulkan loader and the glvnd libraries NVIDIA's Vulkan driver needs):
#   gpu-bundle/bin/   motes, motes_conformance_tests, motes_unit_tests (their CUDA cases: run
#                     with --gtest_filter='*cuda*:*Cuda*'), motes_property_tests (CUDA for
#                     sm_90, Vulkan, OpenMP),
#                     motes_mpi_tests and motes_mpi_bench (over MPI ranks), motes_gpu_floors
#                     (bench/gpu)
#   gpu-bundle/lib/   their shared libraries, except those the GPU machine has (libc, libstdc++...)
#   gpu-bundle/debs/  Debian packages of the Vulkan loader and glvnd (unpacked there by run.sh)
# Usage: scripts/gpu/bundle.sh [BUILD_DIR]   (gpu-bundle/ is ignored by git; carry it along)
# Then, with the device tool: run `scripts/gpu/run-suite.sh` there, carrying gpu-bundle.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build-gpu}
bundle=$root/gpu-bundle
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DMOTES_WITH_VULKAN=ON \
  -DMOTES_WITH_CUDA=ON >/dev/null
cmake --build "$build" -j "${JOBS:-$(nproc)}" --target motes_cli motes_conformance_tests \
  motes_unit_tests motes_property_tests motes_mpi_tests motes_mpi_bench
rm -rf "$bundle/bin" "$bundle/lib"
mkdir -p "$bundle/bin" "$bundle/lib" "$bundle/debs"
cp "$build/bin/motes" "$build/tests/motes_conformance_tests" "$build/tests/motes_unit_tests" \
  "$build/tests/motes_property_tests" \
  "$build/tests/motes_mpi_tests" "$build/bin/motes_mpi_bench" "$bundle/bin/"
# The floors every GPU number is compared with (copy bandwidth, CUB sort), for sm_90 plus PTX.
nvcc=${NVCC:-$(command -v nvcc || echo /usr/local/cuda/bin/nvcc)}
if [ -x "$nvcc" ]; then
  "$nvcc" -O3 -std=c++17 -gencode arch=compute_90,code=sm_90 -gencode arch=compute_90,code=compute_90 \
    -cudart static -o "$bundle/bin/motes_gpu_floors" "$root/bench/gpu/gpu_floors.cu"
else
  echo "no nvcc: gpu-bundle/bin/motes_gpu_floors not built" >&2
fi
# Libraries the GPU machine has itself (or must take from its own driver) stay behind; so does
# the MPI stack: the machine's OpenMPI (libmpi.so.40, as Debian's) goes with its own mpirun.
skip='^(linux-vdso|ld-linux|libc\.|libm\.|libstdc\+\+|libgcc_s|libgomp|libdl\.|libpthread|librt|libcuda|libvulkan|libmpi|libopen-rte|libopen-pal|libhwloc|libevent|libudev)'
for exe in "$bundle"/bin/*; do
  ldd "$exe" | awk '$3 ~ /^\// {print $1, $3}' | while read -r name path; do
    if ! [[ $name =~ $skip ]]; then cp -L "$path" "$bundle/lib/$name"; fi
  done
done
if [ -z "$(ls "$bundle"/debs/*.deb 2>/dev/null)" ]; then
  o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/motes-amd64-lists'
  mkdir -p /tmp/motes-amd64-lists/partial
  # shellcheck disable=SC2086
  apt-get $o update -qq
  # shellcheck disable=SC2086
  (cd "$bundle/debs" && apt-get $o download -qq libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 \
    libglx0 libgles2 libx11-6 libxext6 libxcb1 libxau6 libxdmcp6 libbsd0 libmd0 vulkan-validationlayers 2>&1 |
    grep -v unsandboxed || true)
fi
du -sh "$bundle"
