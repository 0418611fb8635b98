#version 450
// grid_build, pass 5 of 5: the canonical order, each particle at its slot of the stable sort by
// (bucket, id), with its data copied there (grid_build.glsl: grid_build_place).
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/grid_hash.h"
#include "grid_build.glsl"

void main() {
  uint i = thread_index();
  if (i < p.particle_count) grid_build_place(i);
}
