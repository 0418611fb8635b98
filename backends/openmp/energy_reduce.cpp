// energy_reduce: the energy guard's reduction (shared/energy.h). Each block of 256 items is one
// loop iteration: its items' energies into a local array of 256 slots, then the tree the GPUs run
// in shared memory, in the same order, so every block's sums are the GPUs' (and do not depend on
// the thread count).
#include <chrono>
#include <cstdint>

#include "openmp_device.h"
#include "shared/energy.h"

namespace motes::openmp {

using shared::uint;
using shared::vec3;
using shared::vec4;

void OpenMPDevice::energy_reduce(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  // More items than EnergyPartials has blocks for: nothing is written (the GPU backends refuse
  // the call with this error; this backend has no error to report it through).
  if (!energy_launch_error(Kernel::EnergyReduce, p, sizes_).empty()) return;
  const uint bodies = p.body_count;
  const uint items = shared::energy_items(bodies, p.particle_count, p.rigid_particle_count);
  const auto blocks = static_cast<std::int64_t>(shared::energy_blocks(items));
  const vec4* ppos = buf<vec4>(Buffer::ParticlePos);
  const vec4* pvel = buf<vec4>(Buffer::ParticleVel);
  const vec4* bpos = buf<vec4>(Buffer::BodyPos);
  const vec4* bvel = buf<vec4>(Buffer::BodyVel);
  const vec4* bangvel = buf<vec4>(Buffer::BodyAngVel);
  const vec4* bangmom = buf<vec4>(Buffer::BodyAngMom);
  uint* out = buf<uint>(Buffer::EnergyPartials);
  const vec3 ref(shared::bits_float(out[0]), shared::bits_float(out[1]),
                 shared::bits_float(out[2]));
  const vec4 gravity = p.gravity_dt;

#pragma omp parallel for num_threads(team_) \
    schedule(static) if (parallel(blocks * MOTES_ENERGY_BLOCK))
  for (std::int64_t k = 0; k < blocks; ++k) {
    float kinetic[MOTES_ENERGY_BLOCK];
    float potential[MOTES_ENERGY_BLOCK];
    float largest[MOTES_ENERGY_BLOCK];
    uint item[MOTES_ENERGY_BLOCK];
    for (uint t = 0; t < MOTES_ENERGY_BLOCK; ++t) {
      const uint j = static_cast<uint>(k) * MOTES_ENERGY_BLOCK + t;
      vec3 e(0.0f);
      if (j < bodies) {
        e = shared::item_energy(bpos[j], bvel[j], bpos[j].w, true, bangvel[j], bangmom[j], gravity,
                                ref);
      } else if (j < items) {
        const uint i = p.rigid_particle_count + (j - bodies);
        e = shared::item_energy(ppos[i], pvel[i], pvel[i].w, false, vec4(0.0f), vec4(0.0f), gravity,
                                ref);
      }
      const bool counts = e.z != 0.0f;
      kinetic[t] = e.x;
      potential[t] = e.y;
      largest[t] = counts ? e.x : MOTES_ENERGY_NO_KINETIC;
      item[t] = counts ? j : MOTES_ENERGY_NONE;
    }
    for (uint s = MOTES_ENERGY_BLOCK / 2; s > 0; s >>= 1) {
      for (uint t = 0; t < s; ++t) {
        kinetic[t] = kinetic[t] + kinetic[t + s];
        potential[t] = potential[t] + potential[t + s];
        if (shared::energy_larger(largest[t + s], item[t + s], largest[t], item[t])) {
          largest[t] = largest[t + s];
          item[t] = item[t + s];
        }
      }
    }
    uint* block = out + MOTES_ENERGY_HEADER + MOTES_ENERGY_WORDS * static_cast<std::size_t>(k);
    block[MOTES_ENERGY_KINETIC] = shared::float_bits(kinetic[0]);
    block[MOTES_ENERGY_POTENTIAL] = shared::float_bits(potential[0]);
    block[MOTES_ENERGY_MAX_KINETIC] = shared::float_bits(largest[0]);
    block[MOTES_ENERGY_MAX_ITEM] = item[0];
  }
  record(Kernel::EnergyReduce, start);
}

}  // namespace motes::openmp
