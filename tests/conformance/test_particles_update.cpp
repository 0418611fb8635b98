// particles_update against the oracle, the kernel alone: ParticleBody, ParticleLocal, ParticlePos
// and ParticleVel (their w: radius and inverse mass) and the body pose (BodyPos, BodyQuat,
// BodyVel, BodyAngVel) are written, every other buffer is poisoned; ParticlePos and ParticleVel
// are read back. Their xyz are compared by NMSE, their w (radius, inverse mass: other quantities,
// and kept by the kernel) bitwise.
//
// Tolerance: NMSE 1e-10. The same shared particle_position and particle_velocity run on the same
// floats, so openmp matches bitwise (measures 0); a GPU's fused multiply-adds change each
// component by a few ulps (NMSE ~1e-14). Faults measured by breaking the oracle: the velocity
// without the w x r term gives 0.3 to 0.65, the rotation by the conjugate 0.06 to 5.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "conformance.h"
#include "reference/reference.h"
#include "test_data.h"

namespace motes_conf {
namespace {

using motes::Buffer;

constexpr double kTolerance = 1.0e-10;

class ParticlesUpdate : public DeviceTest {
 protected:
  void run_case(const std::string& layout, const World& w) {
    motes_ref::Particles want = w.particles;
    motes_ref::particles_update(w.bodies, want);
    ASSERT_NO_FATAL_FAILURE(allocate(w.sizes));
    ASSERT_NO_FATAL_FAILURE(poison_all_but(
        {Buffer::ParticleBody, Buffer::ParticleLocal, Buffer::ParticlePos, Buffer::ParticleVel,
         Buffer::BodyPos, Buffer::BodyQuat, Buffer::BodyVel, Buffer::BodyAngVel}));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleBody, w.particles.body));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleLocal, w.particles.local));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticlePos, w.particles.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleVel, w.particles.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyPos, w.bodies.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyQuat, w.bodies.quat));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyVel, w.bodies.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyAngVel, w.bodies.angvel));
    device().particles_update(w.params);
    ASSERT_NO_FATAL_FAILURE(finish_kernel());
    std::vector<vec4> pos;
    std::vector<vec4> vel;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticlePos, pos));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticleVel, vel));

    begin_case("particles_update/" + layout, w.sizes.particles);
    check_close("ParticlePos", pos, want.pos, kTolerance, Part::Xyz);
    check_close("ParticleVel", vel, want.vel, kTolerance, Part::Xyz);
    check_w_identical("ParticlePos.w (radius) kept", pos, w.particles.pos);
    check_w_identical("ParticleVel.w (inverse mass) kept", vel, w.particles.vel);
    end_case();
  }
};

TEST_P(ParticlesUpdate, Empty) { run_case("random", random_world(61, 0)); }
TEST_P(ParticlesUpdate, One) { run_case("random", random_world(62, 1)); }
TEST_P(ParticlesUpdate, Random31) { run_case("random", random_world(63, 31)); }
TEST_P(ParticlesUpdate, Random1234) { run_case("random", random_world(64, 1234)); }
TEST_P(ParticlesUpdate, Random65536) { run_case("random", random_world(65, 65536)); }

INSTANTIATE_TEST_SUITE_P(Conformance, ParticlesUpdate, testing::ValuesIn(device_params()),
                         param_name);

}  // namespace
}  // namespace motes_conf
