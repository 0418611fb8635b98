// bodies_reduce: force and torque of each body, summed over its particles in particle order.
#include <chrono>
#include <cstdint>

#include "openmp_device.h"
#include "shared/body_math.h"

namespace motes::openmp {

using shared::uint;
using shared::vec3;
using shared::vec4;

void OpenMPDevice::bodies_reduce(const shared::StepParams& p) {
  const auto start = std::chrono::steady_clock::now();
  const auto bodies = static_cast<std::int64_t>(p.body_count);
  const uint* first = buf<uint>(Buffer::BodyFirst);
  const vec4* body_pos = buf<vec4>(Buffer::BodyPos);
  const vec4* pos = buf<vec4>(Buffer::ParticlePos);
  const vec4* force = buf<vec4>(Buffer::ParticleForce);
  vec4* body_force = buf<vec4>(Buffer::BodyForce);
  vec4* body_torque = buf<vec4>(Buffer::BodyTorque);

#pragma omp parallel for num_threads(team_) schedule(static) if (parallel(bodies))
  for (std::int64_t b = 0; b < bodies; ++b) {
    const vec4 com = body_pos[b];
    vec3 f(0.0f);
    vec3 tau(0.0f);
    if (com.w != 0.0f) {
      for (uint i = first[b]; i < first[b + 1]; ++i) {
        f += shared::xyz(force[i]);
        tau += shared::particle_torque(pos[i], com, force[i]);
      }
    }
    body_force[b] = vec4(f, 0.0f);
    body_torque[b] = vec4(tau, 0.0f);
  }
  record(Kernel::BodiesReduce, start);
}

}  // namespace motes::openmp
