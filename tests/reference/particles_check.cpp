// The oracle of particles_check (reference.h has the contract): the MotionCheck words by their
// definitions, particle after particle.
#include <algorithm>
#include <cstddef>

#include "reference.h"
#include "shared/motion_check.h"

namespace motes_ref {

std::vector<uint> particles_check(const Particles& particles) {
  using namespace motes::shared;  // NOLINT: the MotionCheck helpers
  std::vector<uint> words = {0u, MOTES_MOTION_NONE, MOTES_MOTION_NONE, 0u};
  for (std::size_t i = 0; i < particles.size(); ++i) {
    if (!motion_finite(particles.pos[i], particles.vel[i])) {
      if (words[MOTES_MOTION_NON_FINITE] == MOTES_MOTION_NONE) {
        words[MOTES_MOTION_NON_FINITE] = static_cast<uint>(i);
      }
    } else {
      words[MOTES_MOTION_RATE2] = std::max(words[MOTES_MOTION_RATE2],
                                           motion_rate2_bits(particles.pos[i], particles.vel[i]));
    }
  }
  for (std::size_t i = 0; i < particles.size(); ++i) {
    if (motion_finite(particles.pos[i], particles.vel[i]) &&
        motion_rate2_bits(particles.pos[i], particles.vel[i]) == words[MOTES_MOTION_RATE2]) {
      words[MOTES_MOTION_FASTEST] = static_cast<uint>(i);
      words[MOTES_MOTION_SPEED2] = float_bits(motion_speed2(particles.vel[i]));
      break;
    }
  }
  return words;
}

}  // namespace motes_ref
