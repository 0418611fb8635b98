#!/usr/bin/env bash
# Source this on the GPU machine, in the repository root, before running the bundle:
#   . scripts/gpu/prelude.sh
# Unpacks the Vulkan loader and glvnd, points the loader at NVIDIA's driver, puts the bundled
# libraries on the search path, and makes the tests' compiled-in source path exist.
for f in gpu-bundle/debs/*.deb; do dpkg -x "$f" /; done
ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
[ -f "$VK_DRIVER_FILES" ] || export VK_DRIVER_FILES=/usr/share/vulkan/icd.d/nvidia_icd.json
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
export LD_LIBRARY_PATH=$PWD/gpu-bundle/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export PATH=$PWD/gpu-bundle/bin:$PATH
# The tests were built in /work/main and look for examples/ there.
if [ ! -e /work/main ]; then mkdir -p /work && ln -s "$PWD" /work/main; fi
# The unit tests run the command line from the build directory it was built in (bundle.sh's
# default build-gpu, or the quick start's build).
for dir in build-gpu build; do
  if [ ! -e $dir/bin/motes ]; then mkdir -p $dir/bin && ln -s "$PWD/gpu-bundle/bin/motes" $dir/bin/motes; fi
done
