// The fluid families' walk over a particle's neighbours on the OpenMP device: its list in list
// order, or over capacity the 27 cells of the last build (contact_skipped's pairs left out; the
// extra particles beyond h add zeros), as every backend walks them (docs/fluids.md).
#pragma once

#include <cstddef>

#include "shared/grid_walk.h"
#include "shared/links.h"
#include "shared/params.h"

namespace motes::openmp {

struct NeighbourWalk {
  const shared::uint* list;
  const shared::uint* count;
  const shared::vec4* ref;
  const shared::uint* order;
  const shared::uint* cell_start;
  const shared::uint* sbody;
  const shared::uint* body;
  const shared::uint* exclusions;
};

/// add(j) for every neighbour j of particle i, in the order every backend and the oracle sum.
template <typename Add>
void for_each_neighbour(const shared::StepParams& p, const NeighbourWalk& w, std::size_t i,
                        Add&& add) {
  const shared::uint c = w.count[i];
  if (c <= p.neighbour_capacity) {
    const std::size_t stride = p.particle_count;
    for (shared::uint s = 0; s < c; ++s) add(w.list[std::size_t{s} * stride + i]);
    return;
  }
  const shared::GridRanges ranges = shared::grid_ranges(p, w.ref[i], w.cell_start);
  for (int r = 0; r < ranges.count; ++r) {
    for (shared::uint t = ranges.lo[r]; t < ranges.hi[r]; ++t) {
      if (!shared::contact_skipped(w.body[i], w.sbody[t], shared::uint(i), w.order[t], w.exclusions,
                                   p.particle_count, p.linked_first)) {
        add(w.order[t]);
      }
    }
  }
}

}  // namespace motes::openmp
