// The oracle of energy_reduce (the energy guard): reference.h has the contract. Plain loops, item
// after item, each block's terms summed in double in item order and rounded once; the energy of
// one item comes from the shared header, as on every backend.
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "reference.h"
#include "shared/energy.h"

namespace motes_ref {

EnergyBlocks energy_reduce(const Particles& particles, const Bodies& bodies, const StepParams& p,
                           const std::vector<uint>& header) {
  using motes::shared::vec3;
  const vec3 ref(motes::shared::bits_float(header[0]), motes::shared::bits_float(header[1]),
                 motes::shared::bits_float(header[2]));
  const uint items =
      motes::shared::energy_items(p.body_count, p.particle_count, p.rigid_particle_count);
  const uint blocks = motes::shared::energy_blocks(items);
  EnergyBlocks out;
  out.words.assign(header.begin(), header.begin() + MOTES_ENERGY_HEADER);
  for (uint k = 0; k < blocks; ++k) {
    double kinetic = 0.0, potential = 0.0, kinetic_abs = 0.0, potential_abs = 0.0;
    float largest = MOTES_ENERGY_NO_KINETIC;
    uint largest_item = MOTES_ENERGY_NONE;
    for (uint j = k * MOTES_ENERGY_BLOCK; j < std::min(items, (k + 1) * MOTES_ENERGY_BLOCK); ++j) {
      vec3 e(0.0f);
      if (j < p.body_count) {
        e = motes::shared::item_energy(bodies.pos[j], bodies.vel[j], bodies.pos[j].w, true,
                                       bodies.angvel[j], bodies.angmom[j], p.gravity_dt, ref);
      } else {
        const std::size_t i = p.rigid_particle_count + (j - p.body_count);
        e = motes::shared::item_energy(particles.pos[i], particles.vel[i], particles.vel[i].w,
                                       false, vec4(0.0f), vec4(0.0f), p.gravity_dt, ref);
      }
      if (e.z == 0.0f) continue;  // an item that does not count
      kinetic += static_cast<double>(e.x);
      potential += static_cast<double>(e.y);
      kinetic_abs += std::abs(static_cast<double>(e.x));
      potential_abs += std::abs(static_cast<double>(e.y));
      if (e.x > largest) {  // the first of equal ones: items in ascending order
        largest = e.x;
        largest_item = j;
      }
    }
    out.words.push_back(motes::shared::float_bits(static_cast<float>(kinetic)));
    out.words.push_back(motes::shared::float_bits(static_cast<float>(potential)));
    out.words.push_back(motes::shared::float_bits(largest));
    out.words.push_back(largest_item);
    out.kinetic_abs.push_back(kinetic_abs);
    out.potential_abs.push_back(potential_abs);
  }
  return out;
}

}  // namespace motes_ref
