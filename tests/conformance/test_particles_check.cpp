// particles_check against the oracle, the kernel alone: ParticlePos and ParticleVel are written,
// every other buffer is poisoned (MotionCheck too: the kernel must reset it); MotionCheck is read
// back. Its indices (the first fastest particle, the first non-finite one) must be identical; the
// rate and speed words are float bits, compared as floats: relative 1e-6 (openmp and cuda:
// bitwise, the same correctly rounded products and division; Vulkan's division may be off by
// 2.5 ulp). The cases: random velocities over rigid and free particles, one particle faster than
// a float rate can say (saturated), NaN and infinity at several places (the first must be named),
// every particle at rest (rate 0: the first particle is the "fastest", the host reads it as
// nothing moving), and no particle at all.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "conformance.h"
#include "reference/reference.h"
#include "shared/motion_check.h"
#include "test_data.h"

namespace motes_conf {
namespace {

using motes::Buffer;

constexpr double kParticlesCheckTolerance = 1.0e-6;

double relative(uint device, uint oracle) {
  const auto a = static_cast<double>(std::bit_cast<float>(device));
  const auto b = static_cast<double>(std::bit_cast<float>(oracle));
  if (a == b) return 0.0;
  return std::abs(a - b) / std::max(std::abs(b), 1e-30);
}

class ParticlesCheck : public DeviceTest {
 protected:
  void run_case(const std::string& layout, const World& w) {
    const std::vector<uint> want = motes_ref::particles_check(w.particles);
    ASSERT_NO_FATAL_FAILURE(allocate(w.sizes));
    ASSERT_NO_FATAL_FAILURE(poison_all_but({Buffer::ParticlePos, Buffer::ParticleVel}));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticlePos, w.particles.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleVel, w.particles.vel));
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::ParticlesCheck, w.params));
    ASSERT_NO_FATAL_FAILURE(finish_kernel());
    std::vector<uint> got;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::MotionCheck, got));
    ASSERT_EQ(got.size(), std::size_t{MOTES_MOTION_WORDS});

    begin_case("particles_check/" + layout, w.sizes.particles);
    check_identical("MotionCheck fastest and non-finite particle",
                    std::vector<uint>{got[MOTES_MOTION_FASTEST], got[MOTES_MOTION_NON_FINITE]},
                    std::vector<uint>{want[MOTES_MOTION_FASTEST], want[MOTES_MOTION_NON_FINITE]});
    check_at_most("MotionCheck largest (|v| / d)^2", "relative",
                  relative(got[MOTES_MOTION_RATE2], want[MOTES_MOTION_RATE2]),
                  kParticlesCheckTolerance);
    check_at_most("MotionCheck |v|^2 of the fastest", "relative",
                  relative(got[MOTES_MOTION_SPEED2], want[MOTES_MOTION_SPEED2]),
                  kParticlesCheckTolerance);
    end_case();
  }
};

/// Random velocities of up to 3 m/s in every particle (random_world's are zero for some).
World moving_world(std::uint32_t seed, std::size_t n) {
  World w = random_world(seed, n);
  Rng rng(seed + 1000u);
  for (vec4& v : w.particles.vel) {
    v.x = rng.uniform(-3.0f, 3.0f);
    v.y = rng.uniform(-3.0f, 3.0f);
    v.z = rng.uniform(-3.0f, 3.0f);
  }
  return w;
}

TEST_P(ParticlesCheck, Empty) { run_case("empty", random_world(181, 0)); }

TEST_P(ParticlesCheck, Random1234) { run_case("random", moving_world(182, 1234)); }

TEST_P(ParticlesCheck, Random65536) { run_case("random", moving_world(183, 65536)); }

TEST_P(ParticlesCheck, Saturated) {
  // |v|^2 overflows a float at particle 700: its rate saturates, and it is the fastest.
  World w = moving_world(184, 1234);
  w.particles.vel[700].x = 3.0e25f;
  run_case("saturated", w);
  EXPECT_EQ(motes_ref::particles_check(w.particles)[MOTES_MOTION_RATE2], MOTES_MOTION_SATURATED);
}

TEST_P(ParticlesCheck, NonFinite) {
  // NaN and infinity in positions and velocities at several places, the first at particle 300.
  World w = moving_world(185, 65536);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  w.particles.vel[40000].y = nan;
  w.particles.pos[300].z = -inf;
  w.particles.vel[1000].x = inf;
  w.particles.pos[65535].x = nan;
  run_case("non_finite", w);
  EXPECT_EQ(motes_ref::particles_check(w.particles)[MOTES_MOTION_NON_FINITE], 300u);
}

TEST_P(ParticlesCheck, AtRest) {
  World w = random_world(186, 1234);
  for (vec4& v : w.particles.vel) v = vec4(0.0f, 0.0f, 0.0f, v.w);
  run_case("at_rest", w);
}

INSTANTIATE_TEST_SUITE_P(Conformance, ParticlesCheck, testing::ValuesIn(device_params()),
                         param_name);

}  // namespace
}  // namespace motes_conf
