#version 450
// grid_build, pass 1 of 5: the bucket of every particle, and its arrival rank in the bucket. The
// rank comes from an integer atomic, so it is in no particular order; grid_build.comp (the last pass)
// restores the canonical (bucket, particle id) order. GridCellStart holds the counts until the scan.
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"
#include "shared/grid_hash.h"

void main() {
  uint i = thread_index();
  if (i >= p.particle_count) return;
  vec4 x = particle_pos[i];
  uint b = grid_bucket(grid_cell_coord(x.x, p.inv_cell_size), grid_cell_coord(x.y, p.inv_cell_size),
                       grid_cell_coord(x.z, p.inv_cell_size), p.table_mask);
  grid_bucket_of[i] = b;
  grid_arrival[i] = atomicAdd(grid_cell_start[b], 1u);
}
