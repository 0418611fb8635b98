// constraints_relax: every sweep over every colour of ConstraintColours in one call, each colour
// as constraints_solve projects it; on the team, one parallel region for the whole call (a colour
// per worksharing loop, whose end is the barrier between colours), or on this thread when the
// colours are too small to share. With MOTES_FLAG_SKIN_CHECK the last sweep asks for a rebuild
// when a particle it moved is too far from where the lists were built.
#include <algorithm>
#include <chrono>
#include <cstdint>

#include "openmp_device.h"
#include "shared/links.h"
#include "shared/neighbours.h"

namespace motes::openmp {

using shared::uint;
using shared::vec4;

void OpenMPDevice::constraints_relax(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  const float inv_dt = 1.0f / p.gravity_dt.w;
  const auto* constraints = buf<shared::Constraint>(Buffer::Constraints);
  const uint* colours = buf<uint>(Buffer::ConstraintColours);
  const vec4* ref = buf<vec4>(Buffer::NeighbourRefPos);
  vec4* pos = buf<vec4>(Buffer::ParticlePos);
  vec4* vel = buf<vec4>(Buffer::ParticleVel);
  const std::int64_t sweeps = p.constraint_sweeps;
  const std::int64_t count = p.constraint_count;
  std::int64_t widest = 0;
  for (std::int64_t c = 0; c < count; ++c) {
    widest = std::max<std::int64_t>(widest, colours[c + 1] - colours[c]);
  }
  const auto project = [&](std::int64_t k, bool check) {
    const shared::Constraint c = constraints[k];
    shared::constraint_project(pos[c.a], pos[c.b], vel[c.a], vel[c.b], c, inv_dt);
    return check && (shared::neighbour_moved_too_far(pos[c.a], ref[c.a], p.neighbour_skin) ||
                     shared::neighbour_moved_too_far(pos[c.b], ref[c.b], p.neighbour_skin));
  };
  const bool checked = (p.flags & MOTES_FLAG_SKIN_CHECK) != 0;
  uint moved = 0;
#pragma omp parallel num_threads(team_) if (parallel(widest)) reduction(| : moved)
  for (std::int64_t sweep = 0; sweep < sweeps; ++sweep) {
    const bool check = checked && sweep + 1 == sweeps;
    for (std::int64_t c = 0; c < count; ++c) {
      const std::int64_t end = colours[c + 1];
#pragma omp for schedule(static)
      for (std::int64_t k = colours[c]; k < end; ++k) moved |= project(k, check) ? 1u : 0u;
    }
  }
  if (moved != 0) buf<uint>(Buffer::NeighbourState)[MOTES_NEIGHBOUR_REBUILD] = 1;
  record(Kernel::ConstraintsRelax, start);
}

}  // namespace motes::openmp
