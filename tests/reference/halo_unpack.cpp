// The oracle of halo_unpack (reference.h has the contract): plain copies, entry after entry; the
// rebuild test comes from the shared header, as on every backend.
#include <cstddef>

#include "reference.h"
#include "reference_common.h"
#include "shared/halo.h"
#include "shared/neighbours.h"

namespace motes_ref {

bool halo_unpack(Particles& particles, Bodies& bodies, const std::vector<uint>& index,
                 const std::vector<vec4>& data, const StepParams& p, const std::vector<vec4>& ref) {
  bool moved = false;
  for (std::size_t k = 0; k < p.halo_particles; ++k) {
    const uint i = index[std::size_t{p.halo_first} + k];
    if (i >= p.particle_count) continue;
    particles.pos[i] = data[2 * k];
    particles.vel[i] = data[2 * k + 1];
    if (motes::shared::neighbour_moved_too_far(particles.pos[i], ref[i], p.neighbour_skin)) {
      moved = true;
    }
  }
  const std::size_t body_start = 2 * std::size_t{p.halo_particles};
  for (std::size_t j = 0; j < p.halo_bodies; ++j) {
    const uint b = index[std::size_t{p.halo_first} + p.halo_particles + j];
    if (b >= p.body_count) continue;
    for (std::size_t c = 0; c < MOTES_HALO_BODY_VEC4S; ++c) {
      (bodies.*kBodyState[c])[b] = data[body_start + 5 * j + c];
    }
  }
  return moved;
}

}  // namespace motes_ref
