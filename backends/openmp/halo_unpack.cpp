// halo_unpack: the copies' state scattered from HaloData to the particles and bodies HaloIndex
// names (shared/halo.h, docs/scale-out.md), with a neighbour-list rebuild asked for when a
// particle it wrote is too far from where the lists were built.
#include <chrono>
#include <cstdint>

#include "halo_buffers.h"
#include "openmp_device.h"
#include "shared/neighbours.h"

namespace motes::openmp {

using shared::uint;
using shared::vec4;

void OpenMPDevice::halo_unpack(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  const auto np = static_cast<std::int64_t>(p.halo_particles);
  const auto nb = static_cast<std::int64_t>(p.halo_bodies);
  const auto first = static_cast<std::int64_t>(p.halo_first);
  const uint* index = buf<uint>(Buffer::HaloIndex);
  const vec4* data = buf<vec4>(Buffer::HaloData);
  const vec4* ref = buf<vec4>(Buffer::NeighbourRefPos);
  vec4* pos = buf<vec4>(Buffer::ParticlePos);
  vec4* vel = buf<vec4>(Buffer::ParticleVel);
  uint moved = 0;
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(np)) reduction(| : moved)
  for (std::int64_t k = 0; k < np; ++k) {
    const uint i = index[first + k];
    if (i >= p.particle_count) continue;  // not a particle: nothing written
    pos[i] = data[MOTES_HALO_PARTICLE_VEC4S * k];
    vel[i] = data[MOTES_HALO_PARTICLE_VEC4S * k + 1];
    moved |= shared::neighbour_moved_too_far(pos[i], ref[i], p.neighbour_skin) ? 1u : 0u;
  }
  if (moved != 0) buf<uint>(Buffer::NeighbourState)[MOTES_NEIGHBOUR_REBUILD] = 1;
  const vec4* bodies = data + MOTES_HALO_PARTICLE_VEC4S * np;
  for (uint c = 0; c < MOTES_HALO_BODY_VEC4S; ++c) {
    vec4* state = buf<vec4>(kHaloBodyState[c]);
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(nb))
    for (std::int64_t j = 0; j < nb; ++j) {
      const uint b = index[first + np + j];
      if (b < p.body_count) state[b] = bodies[MOTES_HALO_BODY_VEC4S * j + c];
    }
  }
  record(Kernel::HaloUnpack, start);
}

}  // namespace motes::openmp
