// constraints_solve: one colour of distance constraints (no two share a particle), each projected
// once (shared/links.h), and a neighbour-list rebuild asked for when a particle it moved is too far
// from where the lists were built.
#include <chrono>
#include <cstdint>

#include "openmp_device.h"
#include "shared/links.h"
#include "shared/neighbours.h"

namespace motes::openmp {

using shared::uint;
using shared::vec4;

void OpenMPDevice::constraints_solve(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  const auto first = static_cast<std::int64_t>(p.constraint_first);
  const auto end = first + static_cast<std::int64_t>(p.constraint_count);
  const float inv_dt = 1.0f / p.gravity_dt.w;
  const auto* constraints = buf<shared::Constraint>(Buffer::Constraints);
  const vec4* ref = buf<vec4>(Buffer::NeighbourRefPos);
  vec4* pos = buf<vec4>(Buffer::ParticlePos);
  vec4* vel = buf<vec4>(Buffer::ParticleVel);
  uint moved = 0;
  const bool check = (p.flags & MOTES_FLAG_SKIN_CHECK) != 0;

#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(end - first)) \
    reduction(|                                                                         \
              : moved)
  for (std::int64_t k = first; k < end; ++k) {
    const shared::Constraint c = constraints[k];
    shared::constraint_project(pos[c.a], pos[c.b], vel[c.a], vel[c.b], c, inv_dt);
    moved |= (check && (shared::neighbour_moved_too_far(pos[c.a], ref[c.a], p.neighbour_skin) ||
                        shared::neighbour_moved_too_far(pos[c.b], ref[c.b], p.neighbour_skin)))
                 ? 1u
                 : 0u;
  }
  if (moved != 0) buf<uint>(Buffer::NeighbourState)[MOTES_NEIGHBOUR_REBUILD] = 1;
  record(Kernel::ConstraintsSolve, start);
}

}  // namespace motes::openmp
