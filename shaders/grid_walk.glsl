// The canonical 27-cell walk of the hashed grid (docs/architecture.md): the sorted ranges a
// particle visits, in order, as shared/grid_walk.h (C++ and CUDA). Used by neighbours_build, the
// fluid passes and the fallback of contacts_compute and impulses_compute for particles with more
// neighbours than their list holds.
//
// GLSL has no callbacks, so the walk is an iterator that hands out one range at a time:
//   GridWalk w = grid_walk_begin(x);
//   uint lo, hi;
//   while (grid_walk_next(w, lo, hi)) { for (uint t = lo; t < hi; ++t) ... }
// It keeps no arrays: the earlier rows' centre buckets are hashed again where a row checks what
// they cover. Filling 27-entry range arrays (as it did until 2026-12) held contacts_compute at 64
// registers and 432 B of local memory on an H200 although its list path never walks; the iterator
// holds it at 40 and none (docs/benchmarks.md).
// Needs kernel_common.glsl and shared/grid_hash.h.
#ifndef MOTES_GRID_WALK_GLSL
#define MOTES_GRID_WALK_GLSL

struct GridWalk {
  int cx, cy, cz;  // the cell of the walk's position
  int row;         // the row (dz, dy) being walked: row = 3 (dz + 1) + dy + 1
  uint centre;     // its centre bucket, while its buckets are visited one by one
  uint next;       // the next of its buckets (0..2, as centre - 1 + next); 3: the row is done
};

GridWalk grid_walk_begin(vec4 x) {
  GridWalk w;
  w.cx = grid_cell_coord(x.x, p.inv_cell_size);
  w.cy = grid_cell_coord(x.y, p.inv_cell_size);
  w.cz = grid_cell_coord(x.z, p.inv_cell_size);
  w.row = -1;
  w.centre = 0u;
  w.next = 3u;
  return w;
}

// The centre bucket of row r of the walk.
uint grid_walk_centre(GridWalk w, int r) {
  return grid_bucket(w.cx, w.cy + r % 3 - 1, w.cz + r / 3 - 1, p.table_mask);
}

// The next range [lo, hi) of sorted slots, in the order of shared/grid_walk.h: rows (dz, dy) for
// dz = -1..1 and, inside, dy = -1..1; in a row with centre bucket c the buckets c-1, c, c+1, each
// bucket only by the first row that covers it; a row whose three buckets are contiguous and
// unshared is one range. Returns false when the walk is done.
bool grid_walk_next(inout GridWalk w, out uint lo, out uint hi) {
  uint mask = p.table_mask;
  for (;;) {
    if (w.next >= 3u) {
      if (++w.row >= 9) {
        lo = 0u;
        hi = 0u;
        return false;
      }
      uint c = grid_walk_centre(w, w.row);
      // Two rows' bucket triples overlap when their centres are within 2 of each other.
      bool clash = false;
      for (int r = 0; r < w.row; ++r) {
        clash = clash || ((c - grid_walk_centre(w, r) + 2u) & mask) <= 4u;
      }
      if (!clash && c >= 1u && c < mask) {  // buckets c-1, c, c+1 as one range
        lo = grid_cell_start[c - 1u];
        hi = grid_cell_start[c + 2u];
        return true;
      }
      w.centre = c;
      w.next = 0u;
    }
    uint b = (w.centre + w.next - 1u) & mask;
    ++w.next;
    bool seen = false;
    for (int r = 0; r < w.row; ++r) seen = seen || grid_row_covers(grid_walk_centre(w, r), b, mask);
    if (!seen) {
      lo = grid_cell_start[b];
      hi = grid_cell_start[b + 1u];
      return true;
    }
  }
  return false;  // not reached
}

#endif  // MOTES_GRID_WALK_GLSL
