// The oracle of the families of runs over MPI ranks (halo_pack, halo_unpack,
// particles_displacement): reference.h has the contracts. Plain loops, entry after entry; the
// rebuild test and the displacement measure come from the shared headers, as on every backend.
#include <cstddef>

#include "reference.h"
#include "shared/halo.h"
#include "shared/neighbours.h"

namespace motes_ref {

namespace {

/// The body state of a halo body entry, in HaloData's order.
constexpr std::vector<vec4> Bodies::*kBodyState[MOTES_HALO_BODY_VEC4S] = {
    &Bodies::pos, &Bodies::quat, &Bodies::vel, &Bodies::angmom, &Bodies::angvel};

}  // namespace

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

uint particles_displacement(const std::vector<vec4>& pos, const std::vector<vec4>& ref,
                            const StepParams& p) {
  uint largest = 0;
  for (std::size_t i = 0; i < p.particle_count; ++i) {
    const uint d = motes::shared::displacement2_bits(pos[i], ref[i]);
    if (d > largest) largest = d;
  }
  return largest;
}

}  // namespace motes_ref
