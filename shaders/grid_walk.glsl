// The canonical 27-cell walk of the hashed grid (docs/architecture.md): the sorted ranges a
// particle visits, in order, as shared/grid_walk.h (C++ and CUDA). Used by neighbours_build and by
// the fallback of contacts_compute and impulses_compute for particles with more neighbours than
// their list holds.
// Needs kernel_common.glsl and shared/grid_hash.h.
#ifndef MOTES_GRID_WALK_GLSL
#define MOTES_GRID_WALK_GLSL

// Fills lo/hi with the ranges visited from the cell of x; returns how many (at most 27).
int grid_walk(vec4 x, out uint lo[27], out uint hi[27]) {
  uint mask = p.table_mask;
  int cx = grid_cell_coord(x.x, p.inv_cell_size);
  int cy = grid_cell_coord(x.y, p.inv_cell_size);
  int cz = grid_cell_coord(x.z, p.inv_cell_size);
  uint centres[9];
  int row = 0;
  int count = 0;
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      uint c = grid_bucket(cx, cy + dy, cz + dz, mask);
      // Hashed rows can share buckets; every bucket is visited once, by its first row.
      bool clash = false;
      for (int r = 0; r < row; ++r) clash = clash || ((c - centres[r] + 2u) & mask) <= 4u;
      centres[row] = c;
      if (!clash && c >= 1u && c < mask) {  // buckets c-1, c, c+1 as one range
        lo[count] = grid_cell_start[c - 1u];
        hi[count] = grid_cell_start[c + 2u];
        ++count;
      } else {
        for (uint k = 0u; k < 3u; ++k) {
          uint b = (c + k - 1u) & mask;
          bool seen = false;
          for (int r = 0; r < row; ++r) seen = seen || grid_row_covers(centres[r], b, mask);
          if (!seen) {
            lo[count] = grid_cell_start[b];
            hi[count] = grid_cell_start[b + 1u];
            ++count;
          }
        }
      }
      ++row;
    }
  }
  return count;
}

#endif  // MOTES_GRID_WALK_GLSL
