// Hashed uniform grid. Cell edge = largest particle diameter; cells are hashed into T = 2^k buckets
// so the world is unbounded. The hash adds the x cell index to a hash of (y, z), so the three
// x-neighbours of a cell are three consecutive buckets (one contiguous range after the sort).
#ifndef MOTES_SHARED_GRID_HASH_H
#define MOTES_SHARED_GRID_HASH_H

#include "common.h"

MOTES_SHARED_BEGIN

/// Integer cell coordinate of x; clamped so that far-away or huge values never overflow.
MOTES_FN int grid_cell_coord(float x, float inv_cell_size) {
  float c = floor(x * inv_cell_size);
  c = clamp(c, -1073741824.0f, 1073741823.0f);
  return int(c);
}

/// Base bucket of the row of cells (., cy, cz), before the x index is added.
MOTES_FN uint grid_row_hash(int cy, int cz) {
  // Two odd multipliers, then a xor-shift-multiply finalizer so that nearby rows land far apart.
  uint h = uint(cy) * 0x9E3779B1u + uint(cz) * 0x85EBCA77u;
  h = h ^ (h >> 15u);
  h = h * 0x2C1B3C6Du;
  h = h ^ (h >> 12u);
  return h;
}

MOTES_FN uint grid_bucket(int cx, int cy, int cz, uint table_mask) {
  return (grid_row_hash(cy, cz) + uint(cx)) & table_mask;
}

/// True when bucket b is one of the three buckets of a row whose centre bucket is c.
MOTES_FN bool grid_row_covers(uint c, uint b, uint table_mask) {
  return ((b - c + 1u) & table_mask) <= 2u;
}

MOTES_SHARED_END

#endif  // MOTES_SHARED_GRID_HASH_H
