// The canonical 27-cell walk of the hashed grid (docs/architecture.md), for C++ and CUDA: the
// sorted ranges a particle visits, in order. Used by neighbours_build and by the grid fallback of
// contacts_compute and impulses_compute for particles with more neighbours than their list holds,
// so all visit the same pairs in the same order. GLSL has the same walk in shaders/grid_walk.glsl
// (it reads the grid's buffer by name and hands out one range at a time: GLSL has no callbacks).
#ifndef MOTES_SHARED_GRID_WALK_H
#define MOTES_SHARED_GRID_WALK_H

#include "grid_hash.h"
#include "params.h"

#ifdef __cplusplus
MOTES_SHARED_BEGIN

/// Calls visit(lo, hi) for each range [lo, hi) of sorted slots visited from the cell of `x`, in
/// order: rows (dz, dy) for dz = -1..1 and, inside, dy = -1..1; in a row with centre bucket c the
/// buckets c-1, c, c+1, each bucket only by the first row that covers it (up to 27 ranges; a row
/// whose three buckets are contiguous and unshared is one range).
template <typename Visit>
MOTES_FN void grid_walk(MOTES_IN(StepParams) p, vec4 x, const uint* __restrict__ cell_start,
                        Visit&& visit) {
  const uint mask = p.table_mask;
  const int cx = grid_cell_coord(x.x, p.inv_cell_size);
  const int cy = grid_cell_coord(x.y, p.inv_cell_size);
  const int cz = grid_cell_coord(x.z, p.inv_cell_size);
  uint centres[9];
  int row = 0;
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy, ++row) {
      const uint c = grid_bucket(cx, cy + dy, cz + dz, mask);
      // Two rows' bucket triples overlap when their centres are within 2 of each other.
      bool clash = false;
      for (int r = 0; r < row; ++r) clash = clash || ((c - centres[r] + 2u) & mask) <= 4u;
      centres[row] = c;
      if (!clash && c >= 1u && c < mask) {  // buckets c-1, c, c+1 as one range
        visit(cell_start[c - 1u], cell_start[c + 2u]);
        continue;
      }
      for (uint k = 0; k < 3u; ++k) {
        const uint b = (c + k - 1u) & mask;
        bool seen = false;
        for (int r = 0; r < row; ++r) seen = seen || grid_row_covers(centres[r], b, mask);
        if (!seen) visit(cell_start[b], cell_start[b + 1u]);
      }
    }
  }
}

#ifndef __CUDACC__
/// The ranges grid_walk visits, gathered, for a CPU loop that walks them itself: the OpenMP
/// contact loop keeps the callback out of its body this way (with the callback inlined, W1's
/// contacts_compute ran 5% more instructions).
struct GridRanges {
  uint lo[27];
  uint hi[27];
  int count = 0;
};
inline GridRanges grid_ranges(const StepParams& p, vec4 x, const uint* cell_start) {
  GridRanges out;
  grid_walk(p, x, cell_start, [&out](uint lo, uint hi) {
    out.lo[out.count] = lo;
    out.hi[out.count++] = hi;
  });
  return out;
}
#endif

MOTES_SHARED_END
#endif  // __cplusplus

#endif  // MOTES_SHARED_GRID_WALK_H
