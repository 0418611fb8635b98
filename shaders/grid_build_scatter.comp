#version 450
// grid_build, pass 4 of 5: every particle id into its bucket's range, at its arrival rank.
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"

void main() {
  uint i = thread_index();
  if (i >= p.particle_count) return;
  grid_unsorted[grid_cell_start[grid_bucket_of[i]] + grid_arrival[i]] = i;
}
