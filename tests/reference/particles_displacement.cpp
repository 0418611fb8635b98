// The oracle of particles_displacement (reference.h has the contract): a plain loop over the
// particles; the displacement measure comes from shared/halo.h, as on every backend.
#include <cstddef>

#include "reference.h"
#include "shared/halo.h"

namespace motes_ref {

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
