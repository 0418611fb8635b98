// The oracle of halo_pack (reference.h has the contract): plain copies, entry after entry.
#include <cstddef>

#include "reference.h"
#include "reference_common.h"
#include "shared/halo.h"

namespace motes_ref {

void halo_pack(const Particles& particles, const Bodies& bodies, const std::vector<uint>& index,
               const StepParams& p, std::vector<vec4>& data) {
  for (std::size_t k = 0; k < p.halo_particles; ++k) {
    const uint i = index[std::size_t{p.halo_first} + k];
    if (i >= p.particle_count) continue;
    data[2 * k] = particles.pos[i];
    data[2 * k + 1] = particles.vel[i];
  }
  const std::size_t body_start = 2 * std::size_t{p.halo_particles};
  for (std::size_t j = 0; j < p.halo_bodies; ++j) {
    const uint b = index[std::size_t{p.halo_first} + p.halo_particles + j];
    if (b >= p.body_count) continue;
    for (std::size_t c = 0; c < MOTES_HALO_BODY_VEC4S; ++c) {
      data[body_start + 5 * j + c] = (bodies.*kBodyState[c])[b];
    }
  }
}

}  // namespace motes_ref
