// The canonical 27-cell walk of the hashed grid (docs/architecture.md): the sorted ranges a
// particle visits, in order. Used by neighbours_build and by contacts_compute's fallback for
// particles with more neighbours than their list holds, so both visit the same pairs in the same
// order.
#pragma once

#include "shared/grid_hash.h"
#include "shared/params.h"

namespace motes::openmp {

/// Up to 27 ranges [lo[r], hi[r]) of sorted slots (9 rows of 3 buckets; a row whose three buckets
/// are contiguous and unshared is one range).
struct GridRanges {
  shared::uint lo[27];
  shared::uint hi[27];
  int count = 0;
};

/// The ranges visited from the cell of `x`: rows (dz, dy) for dz = -1..1 and, inside, dy = -1..1;
/// in a row with centre bucket c the buckets c-1, c, c+1, each bucket only by the first row that
/// covers it.
inline GridRanges grid_walk(const shared::StepParams& p, shared::vec4 x,
                            const shared::uint* cell_start) {
  GridRanges out;
  const shared::uint mask = p.table_mask;
  const int cx = shared::grid_cell_coord(x.x, p.inv_cell_size);
  const int cy = shared::grid_cell_coord(x.y, p.inv_cell_size);
  const int cz = shared::grid_cell_coord(x.z, p.inv_cell_size);
  shared::uint centres[9] = {};
  int row = 0;
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy, ++row) {
      const shared::uint c = shared::grid_bucket(cx, cy + dy, cz + dz, mask);
      // Two rows' bucket triples overlap when their centres are within 2 of each other.
      bool clash = false;
      for (int r = 0; r < row; ++r) clash = clash || ((c - centres[r] + 2u) & mask) <= 4u;
      centres[row] = c;
      if (!clash && c >= 1u && c < mask) {  // buckets c-1, c, c+1 as one range
        out.lo[out.count] = cell_start[c - 1u];
        out.hi[out.count++] = cell_start[c + 2u];
        continue;
      }
      for (shared::uint k = 0; k < 3; ++k) {
        const shared::uint b = (c + k - 1u) & mask;
        bool seen = false;
        for (int r = 0; r < row; ++r) seen = seen || shared::grid_row_covers(centres[r], b, mask);
        if (seen) continue;
        out.lo[out.count] = cell_start[b];
        out.hi[out.count++] = cell_start[b + 1u];
      }
    }
  }
  return out;
}

}  // namespace motes::openmp
