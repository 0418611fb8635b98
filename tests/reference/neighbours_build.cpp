// The oracle of neighbours_build (reference.h has the contract): brute force over every pair,
// each list sorted into the canonical order of the 27-cell walk (walk_buckets), and what a build
// does to the impulse contacts' stamps (impulse_stamps_after_build).
#include <algorithm>
#include <cstddef>
#include <utility>

#include "reference.h"
#include "shared/grid_hash.h"
#include "shared/impulse.h"
#include "shared/neighbours.h"

namespace motes_ref {

std::vector<uint> walk_buckets(vec4 x, const StepParams& p) {
  using motes::shared::grid_cell_coord;
  const int cx = grid_cell_coord(x.x, p.inv_cell_size);
  const int cy = grid_cell_coord(x.y, p.inv_cell_size);
  const int cz = grid_cell_coord(x.z, p.inv_cell_size);
  std::vector<uint> seq;
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const uint b = motes::shared::grid_bucket(cx + dx, cy + dy, cz + dz, p.table_mask);
        if (std::find(seq.begin(), seq.end(), b) == seq.end()) seq.push_back(b);
      }
    }
  }
  return seq;
}

Neighbours neighbours_build(const Particles& particles, const Grid& grid, const StepParams& p) {
  const std::size_t n = particles.size();
  std::vector<uint> slot(n, 0u);
  for (std::size_t s = 0; s < n; ++s) slot[grid.order[s]] = static_cast<uint>(s);
  Neighbours out;
  out.lists.resize(n);
  out.count.assign(n, 0u);
  out.ref = particles.pos;
  for (std::size_t i = 0; i < n; ++i) {
    if (particles.vel[i].w == 0.0f) continue;  // static: no list
    const std::vector<uint> walk = walk_buckets(particles.pos[i], p);
    std::vector<std::pair<std::size_t, uint>> found;  // (place on the walk, slot) of each j
    const vec4 xi = particles.pos[i];
    const float support_i =
        motes::shared::neighbour_fluid_support(xi, uint(i), p.fluid_first, p.fluid_count);
    for (std::size_t j = 0; j < n; ++j) {
      // Every test must pass, so the cheapest (the distance) goes first: at 20,000 particles the
      // walk's search and the set lookup for every pair were most of the conformance suite's time.
      // Apart along x by the cutoff or more: neighbour_within says no (dx * dx alone reaches it).
      const vec4 xj = particles.pos[j];
      const float dx = xj.x - xi.x;
      const float h = std::max(support_i, motes::shared::neighbour_fluid_support(
                                              xj, uint(j), p.fluid_first, p.fluid_count));
      const float cutoff = std::max(xi.w + xj.w, h) + p.neighbour_skin;
      if (dx >= cutoff || -dx >= cutoff) continue;
      if (!motes::shared::neighbour_within(xi, xj, p.neighbour_skin, h)) continue;
      if (motes::shared::contact_excluded(particles.body[j], particles.body[i]) ||
          particles.never_touch.count({uint(i), uint(j)}) != 0) {
        continue;  // j == i, or j never touches i
      }
      const auto on_walk = std::find(walk.begin(), walk.end(), grid.bucket[j]);
      if (on_walk == walk.end()) continue;
      found.emplace_back(static_cast<std::size_t>(on_walk - walk.begin()), slot[j]);
    }
    std::sort(found.begin(), found.end());
    for (const auto& [place, s] : found) out.lists[i].push_back(grid.order[s]);
    const auto c = static_cast<uint>(found.size());
    out.count[i] = c;
    out.over_capacity += c > p.neighbour_capacity ? 1u : 0u;
    out.max_count = std::max(out.max_count, c);
  }
  return out;
}

void impulse_stamps_after_build(const Particles& particles, const std::vector<uint>& old_list,
                                const std::vector<uint>& old_count, const Neighbours& now,
                                const StepParams& p, uint built, std::vector<uint>& stamp) {
  const std::size_t n = now.count.size();
  for (std::size_t i = 0; i < stamp.size() && i < n; ++i) {
    if (stamp[i] != built || particles.vel[i].w == 0.0f) continue;
    const std::vector<uint>& list = now.lists[i];
    bool same = true;
    for (std::size_t k = 0; k < list.size() && k < p.neighbour_capacity; ++k) {
      same = same && old_list[k * n + i] == list[k];
    }
    if (motes::shared::neighbour_keeps_slots(old_count[i], now.count[i], same,
                                             p.neighbour_capacity)) {
      stamp[i] = built + 1u;
    }
  }
}

}  // namespace motes_ref
