#version 450
// grid_build, pass 5 of 5: the canonical order. A particle's place in its bucket is the number of
// particles of the bucket with a smaller id, which makes the result that of a stable sort by
// (bucket, id) whatever order the atomics ran in. The particle data is copied to its sorted slot.
// The work per bucket is quadratic in its occupancy, like the contact gather over the same cells.
#extension GL_GOOGLE_include_directive : require
#include "kernel_common.glsl"

void main() {
  uint i = thread_index();
  if (i >= p.particle_count) return;
  uint b = grid_bucket_of[i];
  uint lo = grid_cell_start[b];
  uint hi = grid_cell_start[b + 1u];
  uint s = lo;
  for (uint t = lo; t < hi; ++t) {
    if (grid_unsorted[t] < i) ++s;
  }
  grid_order[s] = i;
  sorted_pos[s] = particle_pos[i];
  sorted_body[s] = particle_body[i];
}
