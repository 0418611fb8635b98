#version 450
// grid_build, pass 1 of 5: the bucket of every particle, and its arrival rank in the bucket
// (grid_build.glsl: grid_build_count).
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/grid_hash.h"
#include "grid_build.glsl"

void main() {
  uint i = thread_index();
  if (i < p.particle_count) grid_build_count(i);
}
