// particles_displacement: the largest squared distance a particle has moved since the ranks last
// partitioned the scene (shared/halo.h: displacement2_bits), an integer max of float bits.
#include <chrono>
#include <cstdint>

#include "openmp_device.h"
#include "shared/halo.h"

namespace motes::openmp {

using shared::uint;
using shared::vec4;

void OpenMPDevice::particles_displacement(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  const auto n = static_cast<std::int64_t>(p.particle_count);
  const vec4* pos = buf<vec4>(Buffer::ParticlePos);
  const vec4* ref = buf<vec4>(Buffer::PartitionRefPos);
  uint largest = 0;
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(n)) reduction(max \
                                                                                        : largest)
  for (std::int64_t i = 0; i < n; ++i) {
    const uint d = shared::displacement2_bits(pos[i], ref[i]);
    largest = d > largest ? d : largest;
  }
  buf<uint>(Buffer::PartitionCheck)[MOTES_PARTITION_DISPLACEMENT2] = largest;
  record(Kernel::ParticlesDisplacement, start);
}

}  // namespace motes::openmp
