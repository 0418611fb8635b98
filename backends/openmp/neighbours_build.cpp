// neighbours_build: every dynamic particle's list of the particles of other bodies closer than
// max(r_i + r_j, h) + skin (h: a fluid particle's support), in the canonical order of the 27-cell
// walk over the grid that grid_build has just made.
#include <algorithm>
#include <chrono>
#include <cstdint>

#include "openmp_device.h"
#include "shared/grid_walk.h"
#include "shared/impulse.h"
#include "shared/links.h"
#include "shared/neighbours.h"

namespace motes::openmp {

using shared::uint;
using shared::vec4;

void OpenMPDevice::neighbours_build(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  impulse_mirror_.clear();       // new lists: impulses_compute finds each slot's mirror again
  contact_pairs_ready_ = false;  // and contacts_compute its shared pairs
  plane_masks_ready_ = false;    // and the planes each particle may touch
  const auto n = static_cast<std::int64_t>(p.particle_count);
  const std::size_t stride = p.particle_count;
  const uint capacity = p.neighbour_capacity;
  const vec4* pos = buf<vec4>(Buffer::ParticlePos);
  const vec4* vel = buf<vec4>(Buffer::ParticleVel);
  const uint* body = buf<uint>(Buffer::ParticleBody);
  const uint* order = buf<uint>(Buffer::GridOrder);
  const uint* cell_start = buf<uint>(Buffer::GridCellStart);
  const vec4* spos = buf<vec4>(Buffer::SortedPos);
  const uint* sbody = buf<uint>(Buffer::SortedBody);
  const uint* exclusions = buf<uint>(Buffer::LinkExclusions);
  uint* list = buf<uint>(Buffer::NeighbourList);
  uint* count = buf<uint>(Buffer::NeighbourCount);
  vec4* ref = buf<vec4>(Buffer::NeighbourRefPos);
  uint over = 0;
  uint most = 0;
  // Impulse contacts: a rigid particle whose list comes out as it was keeps its contacts' memory
  // (shared/impulse.h: neighbour_keeps_slots): its stamp moves on to this build.
  const bool stamps = (p.flags & MOTES_FLAG_IMPULSE) != 0u && sizes_.impulse != 0;
  uint* stamp = stamps ? buf<uint>(Buffer::ImpulseStamp) : nullptr;
  uint* state = buf<uint>(Buffer::NeighbourState);
  const uint built = state[MOTES_NEIGHBOUR_BUILDS];  // the last build's count; this one's + 1

#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(n)) \
    reduction(+ : over) reduction(max : most)
  for (std::int64_t i = 0; i < n; ++i) {
    const vec4 pi = pos[i];
    ref[i] = pi;
    if (vel[i].w == 0.0f) {  // static: never moves, never gets a force
      count[i] = 0;
      continue;
    }
    const uint body_i = body[i];
    const float support_i =
        shared::neighbour_fluid_support(pi, uint(i), p.fluid_first, p.fluid_count);
    // Only a particle whose stamp may move on compares its new list with its old one.
    const bool tracked =
        stamps && static_cast<std::size_t>(i) < sizes_.rigid_particles && stamp[i] == built;
    const uint old_count = tracked ? count[i] : 0u;
    bool same = true;
    uint c = 0;
    shared::grid_walk(p, pi, cell_start, [&](uint lo, uint hi) {
      for (uint t = lo; t < hi; ++t) {
        const uint j = order[t];
        if (shared::contact_skipped(body_i, sbody[t], uint(i), j, exclusions, p.particle_count,
                                    p.linked_first) ||
            !shared::neighbour_within(
                pi, spos[t], p.neighbour_skin,
                shared::max(support_i, shared::neighbour_fluid_support(spos[t], j, p.fluid_first,
                                                                       p.fluid_count)))) {
          continue;
        }
        if (c < capacity) {
          uint& entry = list[std::size_t{c} * stride + static_cast<std::size_t>(i)];
          if (tracked && same) same = entry == j;
          entry = j;
        }
        ++c;
      }
    });
    count[i] = c;
    if (tracked && shared::neighbour_keeps_slots(old_count, c, same, capacity)) {
      stamp[i] = built + 1u;
    }
    over += c > capacity ? 1u : 0u;
    most = std::max(most, c);
  }
  state[MOTES_NEIGHBOUR_REBUILD] = 0;
  state[MOTES_NEIGHBOUR_BUILDS] += 1;
  state[MOTES_NEIGHBOUR_OVER_CAPACITY] = over;
  state[MOTES_NEIGHBOUR_MAX_COUNT] = most;
  record(Kernel::NeighboursBuild, start);
}

}  // namespace motes::openmp
