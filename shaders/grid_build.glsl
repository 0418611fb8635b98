// The per-particle steps of the grid build, shared by its passes (grid_build_count.comp,
// grid_build_scatter.comp, grid_build.comp) and by neighbours_update_small.comp, which runs them
// all in one workgroup. Needs kernel_common.glsl and shared/grid_hash.h.
#ifndef MOTES_GRID_BUILD_GLSL
#define MOTES_GRID_BUILD_GLSL

// Particle i's bucket, and its arrival rank in the bucket. The rank comes from an integer atomic,
// so it is in no particular order; grid_build_place restores the canonical (bucket, particle id)
// order. GridCellStart holds the counts until the scan.
void grid_build_count(uint i) {
  vec4 x = particle_pos[i];
  uint b = grid_bucket(grid_cell_coord(x.x, p.inv_cell_size), grid_cell_coord(x.y, p.inv_cell_size),
                       grid_cell_coord(x.z, p.inv_cell_size), p.table_mask);
  grid_bucket_of[i] = b;
  grid_arrival[i] = atomicAdd(grid_cell_start[b], 1u);
}

// Particle id i into its bucket's range (GridCellStart scanned), at its arrival rank.
void grid_build_scatter(uint i) {
  grid_unsorted[grid_cell_start[grid_bucket_of[i]] + grid_arrival[i]] = i;
}

// The canonical order: particle i's place in its bucket is the number of particles of the bucket
// with a smaller id, which makes the result that of a stable sort by (bucket, id) whatever order
// the atomics ran in. Its data is copied to its sorted slot. The work per bucket is quadratic in
// its occupancy, like the contact gather over the same cells.
void grid_build_place(uint i) {
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

#endif  // MOTES_GRID_BUILD_GLSL
