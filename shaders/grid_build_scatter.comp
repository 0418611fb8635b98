#version 450
// grid_build, pass 4 of 5: every particle id into its bucket's range, at its arrival rank
// (grid_build.glsl: grid_build_scatter).
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/grid_hash.h"
#include "grid_build.glsl"

void main() {
  uint i = thread_index();
  if (i < p.particle_count) grid_build_scatter(i);
}
