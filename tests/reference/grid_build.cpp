// The oracle of grid_build (reference.h has the contract): one bucket per particle, then
// std::stable_sort of the ids by bucket, a linear scan for the bucket starts and the sorted copies.
#include <algorithm>
#include <cstddef>
#include <numeric>

#include "reference.h"
#include "shared/grid_hash.h"

namespace motes_ref {

Grid grid_build(const Particles& particles, const StepParams& p) {
  const std::size_t n = particles.size();
  const std::size_t table = std::size_t{p.table_mask} + 1;
  Grid g;
  g.bucket.assign(n, 0u);
  for (std::size_t i = 0; i < n; ++i) {
    const vec4 x = particles.pos[i];
    g.bucket[i] = motes::shared::grid_bucket(motes::shared::grid_cell_coord(x.x, p.inv_cell_size),
                                             motes::shared::grid_cell_coord(x.y, p.inv_cell_size),
                                             motes::shared::grid_cell_coord(x.z, p.inv_cell_size),
                                             p.table_mask);
  }
  g.order.assign(n, 0u);
  std::iota(g.order.begin(), g.order.end(), uint{0});
  std::stable_sort(g.order.begin(), g.order.end(),
                   [&](uint a, uint b) { return g.bucket[a] < g.bucket[b]; });

  // cell_start[b] = first sorted position whose bucket is >= b (a linear scan, one bucket at a
  // time); cell_start[T] = N.
  g.cell_start.assign(table + 1, 0u);
  std::size_t s = 0;
  for (std::size_t b = 0; b <= table; ++b) {
    while (s < n && g.bucket[g.order[s]] < b) ++s;
    g.cell_start[b] = static_cast<uint>(s);
  }

  g.sorted_pos.assign(n, vec4(0.0f));
  g.sorted_body.assign(n, 0u);
  for (std::size_t k = 0; k < n; ++k) {
    const uint i = g.order[k];
    g.sorted_pos[k] = particles.pos[i];
    g.sorted_body[k] = particles.body[i];
  }
  return g;
}

}  // namespace motes_ref
