// particles_check: the motion guard's reduction over every particle (shared/motion_check.h): the
// largest (|v| / d)^2, the first particle with it and its |v|^2, and the first non-finite particle.
#include <chrono>
#include <cstdint>

#include "openmp_device.h"
#include "shared/motion_check.h"

namespace motes::openmp {

using shared::uint;
using shared::vec4;

void OpenMPDevice::particles_check(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  const auto n = static_cast<std::int64_t>(p.particle_count);
  const vec4* pos = buf<vec4>(Buffer::ParticlePos);
  const vec4* vel = buf<vec4>(Buffer::ParticleVel);
  uint rate2 = 0;
  uint non_finite = MOTES_MOTION_NONE;
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(n)) reduction(max      \
                                                                                        : rate2) \
    reduction(min                                                                                \
              : non_finite)
  for (std::int64_t i = 0; i < n; ++i) {
    if (shared::motion_finite(pos[i], vel[i])) {
      const uint r = shared::motion_rate2_bits(pos[i], vel[i]);
      rate2 = r > rate2 ? r : rate2;
    } else {
      non_finite = static_cast<uint>(i) < non_finite ? static_cast<uint>(i) : non_finite;
    }
  }
  uint fastest = MOTES_MOTION_NONE;
#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(n)) reduction(min \
                                                                                        : fastest)
  for (std::int64_t i = 0; i < n; ++i) {
    if (static_cast<uint>(i) < fastest && shared::motion_finite(pos[i], vel[i]) &&
        shared::motion_rate2_bits(pos[i], vel[i]) == rate2) {
      fastest = static_cast<uint>(i);
    }
  }
  uint* out = buf<uint>(Buffer::MotionCheck);
  out[MOTES_MOTION_RATE2] = rate2;
  out[MOTES_MOTION_FASTEST] = fastest;
  out[MOTES_MOTION_NON_FINITE] = non_finite;
  out[MOTES_MOTION_SPEED2] =
      fastest == MOTES_MOTION_NONE ? 0u : shared::float_bits(shared::motion_speed2(vel[fastest]));
  record(Kernel::ParticlesCheck, start);
}

}  // namespace motes::openmp
