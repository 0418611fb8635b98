// The per-particle steps of the grid build, shared by its passes (grid_build_count.comp,
// grid_build_scatter.comp, grid_build.comp) and by neighbours_update_small.glsl, which runs them
// all in one workgroup. Needs kernel_common.glsl and shared/grid_hash.h.
#ifndef MOTES_GRID_BUILD_GLSL
#define MOTES_GRID_BUILD_GLSL

// The bucket of a particle at x.
uint grid_build_bucket(vec4 x) {
  return grid_bucket(grid_cell_coord(x.x, p.inv_cell_size), grid_cell_coord(x.y, p.inv_cell_size),
                     grid_cell_coord(x.z, p.inv_cell_size), p.table_mask);
}

// Particle i's bucket, and its arrival rank in the bucket. The rank comes from an integer atomic,
// so it is in no particular order; grid_build_place restores the canonical (bucket, particle id)
// order. GridCellStart holds the counts until the scan.
void grid_build_count(uint i) {
  uint b = grid_build_bucket(particle_pos[i]);
  grid_bucket_of[i] = b;
  grid_arrival[i] = atomicAdd(grid_cell_start[b], 1u);
}

// Particle id i into its bucket's range (GridCellStart scanned), at its arrival rank.
void grid_build_scatter(uint i) {
  grid_unsorted[grid_cell_start[grid_bucket_of[i]] + grid_arrival[i]] = i;
}

// The canonical order: particle i's slot in its bucket's range [lo, hi) of GridUnsorted is lo plus
// the number of particles of the bucket with a smaller id, which makes the result that of a stable
// sort by (bucket, id) whatever order the atomics ran in. The range holds i itself, so it is never
// empty; its first entry, first, is passed in already loaded (so that a caller can have several
// particles' loads in flight). The work per bucket is quadratic in its occupancy, like the contact
// gather over the same cells.
uint grid_build_slot(uint i, uint lo, uint hi, uint first) {
  uint s = first < i ? lo + 1u : lo;
  for (uint t = lo + 1u; t < hi; ++t) {
    if (grid_unsorted[t] < i) ++s;
  }
  return s;
}

// Particle i at its canonical slot s, with its data copied there.
void grid_build_copy(uint i, uint s, vec4 x, uint body) {
  grid_order[s] = i;
  sorted_pos[s] = x;
  sorted_body[s] = body;
}

void grid_build_place(uint i) {
  uint b = grid_bucket_of[i];
  uint lo = grid_cell_start[b];
  uint hi = grid_cell_start[b + 1u];
  grid_build_copy(i, grid_build_slot(i, lo, hi, grid_unsorted[lo]), particle_pos[i],
                  particle_body[i]);
}

#endif  // MOTES_GRID_BUILD_GLSL
