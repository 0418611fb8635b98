// particles_integrate: semi-implicit Euler on the free particles [Nr, N) (particle_integrate; cloth
// and rope particles damped first; with MOTES_FLAG_POSITION gravity alone predicts), or with
// MOTES_FLAG_PARTICLE_SHIFT the mean of their contacts' shifts (particle_shift_apply), and a
// neighbour-list rebuild asked for when one has moved too far since the last build.
#include <chrono>
#include <cstdint>

#include "openmp_device.h"
#include "shared/body_math.h"
#include "shared/links.h"
#include "shared/neighbours.h"
#include "shared/particle_shift.h"

namespace motes::openmp {

using shared::uint;
using shared::vec4;

void OpenMPDevice::particles_integrate(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  const auto first = static_cast<std::int64_t>(p.rigid_particle_count);
  const auto n = static_cast<std::int64_t>(p.particle_count);
  const vec4* force = buf<vec4>(Buffer::ParticleForce);
  const vec4* ref = buf<vec4>(Buffer::NeighbourRefPos);
  vec4* pos = buf<vec4>(Buffer::ParticlePos);
  vec4* vel = buf<vec4>(Buffer::ParticleVel);
  uint moved = 0;

#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(n - first)) \
    reduction(|                                                                       \
              : moved)
  for (std::int64_t i = first; i < n; ++i) {
    if ((p.flags & MOTES_FLAG_PARTICLE_SHIFT) != 0u) {
      shared::particle_shift_apply(pos[i], vel[i], force[i], p.gravity_dt.w);
    } else {
      vel[i] =
          shared::linked_damped(vel[i], static_cast<uint>(i), p.linked_first, p.linked_damping);
      shared::particle_integrate(pos[i], vel[i], force[i], p.gravity_dt, p.flags);
    }
    moved |= shared::neighbour_moved_too_far(pos[i], ref[i], p.neighbour_skin) ? 1u : 0u;
  }
  if (moved != 0) buf<uint>(Buffer::NeighbourState)[MOTES_NEIGHBOUR_REBUILD] = 1;
  record(Kernel::ParticlesIntegrate, start);
}

}  // namespace motes::openmp
