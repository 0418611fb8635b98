// The canonical 27-cell walk of the hashed grid (docs/architecture.md), as
// backends/openmp/grid_walk.h: visit(lo, hi) is called for each range of sorted slots in order.
// Used by neighbours_build and by contacts_compute's fallback for particles with more neighbours
// than their list holds, so both visit the same pairs in the same order.
#pragma once

#include "shared/grid_hash.h"
#include "shared/params.h"

namespace motes::cuda {

template <typename Visit>
__device__ void grid_walk(const shared::StepParams& p, shared::vec4 x,
                          const shared::uint* __restrict__ cell_start, Visit&& visit) {
  const shared::uint mask = p.table_mask;
  const int cx = shared::grid_cell_coord(x.x, p.inv_cell_size);
  const int cy = shared::grid_cell_coord(x.y, p.inv_cell_size);
  const int cz = shared::grid_cell_coord(x.z, p.inv_cell_size);
  shared::uint centres[9];
  int row = 0;
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy, ++row) {
      const shared::uint c = shared::grid_bucket(cx, cy + dy, cz + dz, mask);
      // Hashed rows can share buckets; every bucket is visited once, by its first row.
      bool clash = false;
      for (int r = 0; r < row; ++r) clash = clash || ((c - centres[r] + 2u) & mask) <= 4u;
      centres[row] = c;
      if (!clash && c >= 1u && c < mask) {  // buckets c-1, c, c+1 as one range
        visit(cell_start[c - 1u], cell_start[c + 2u]);
        continue;
      }
      for (shared::uint k = 0; k < 3u; ++k) {
        const shared::uint b = (c + k - 1u) & mask;
        bool seen = false;
        for (int r = 0; r < row; ++r) seen = seen || shared::grid_row_covers(centres[r], b, mask);
        if (!seen) visit(cell_start[b], cell_start[b + 1u]);
      }
    }
  }
}

}  // namespace motes::cuda
