// halo_pack: the state a neighbour rank holds copies of, gathered into HaloData (shared/halo.h,
// docs/scale-out.md).
#include <chrono>
#include <cstdint>

#include "halo_buffers.h"
#include "openmp_device.h"

namespace motes::openmp {

using shared::uint;
using shared::vec4;

void OpenMPDevice::halo_pack(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  const auto np = static_cast<std::int64_t>(p.halo_particles);
  const auto nb = static_cast<std::int64_t>(p.halo_bodies);
  const auto first = static_cast<std::int64_t>(p.halo_first);
  const uint* index = buf<uint>(Buffer::HaloIndex);
  const vec4* pos = buf<vec4>(Buffer::ParticlePos);
  const vec4* vel = buf<vec4>(Buffer::ParticleVel);
  vec4* data = buf<vec4>(Buffer::HaloData);
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(np))
  for (std::int64_t k = 0; k < np; ++k) {
    const uint i = index[first + k];
    if (i >= p.particle_count) continue;  // not a particle: the entry is left as it is
    data[MOTES_HALO_PARTICLE_VEC4S * k] = pos[i];
    data[MOTES_HALO_PARTICLE_VEC4S * k + 1] = vel[i];
  }
  vec4* bodies = data + MOTES_HALO_PARTICLE_VEC4S * np;
  for (uint c = 0; c < MOTES_HALO_BODY_VEC4S; ++c) {
    const vec4* state = buf<vec4>(kHaloBodyState[c]);
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(nb))
    for (std::int64_t j = 0; j < nb; ++j) {
      const uint b = index[first + np + j];
      if (b < p.body_count) bodies[MOTES_HALO_BODY_VEC4S * j + c] = state[b];
    }
  }
  record(Kernel::HaloPack, start);
}

}  // namespace motes::openmp
