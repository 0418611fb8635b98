// bodies_reduce against the oracle, the kernel alone: ParticleForce, ParticlePos, BodyPos and
// BodyFirst are written (random forces), every other buffer is poisoned, BodyForce and BodyTorque
// (w = 0; static bodies 0) are read back.
//
// Tolerance: NMSE 1e-10. The oracle sums in float in particle order with the shared
// particle_torque, exactly as the contract says, so openmp must match bitwise (it measures 0). A
// GPU may sum a body's particles as a tree in another fixed order and fuse the cross product's
// multiply-adds: with K terms of similar size that changes each sum by about sqrt(K) u relative
// (u = 2^-24), NMSE ~ K u^2 <= 1.5e-11 for these bodies of up to 4096 particles. Faults measured
// by breaking the oracle: each body's last particle left out gives 2.6e-4 (bodies of 4096) to
// 0.3, the torque about the origin 0.5 to 1, static bodies summed 0.1.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "conformance.h"
#include "reference/reference.h"
#include "test_data.h"

namespace motes_conf {
namespace {

using motes::Buffer;

constexpr double kBodiesReduceTolerance = 1.0e-10;

/// Random forces (up to 1 N per component), w = 0.
class BodiesReduce : public DeviceTest {
 protected:
  void run_case(const std::string& layout, World w) {
    const std::vector<vec4> force = random_forces(w.sizes.particles + 7, w.particles.size(), 1.0f);
    motes_ref::bodies_reduce(w.particles.pos, force, w.bodies);
    ASSERT_NO_FATAL_FAILURE(allocate(w.sizes));
    ASSERT_NO_FATAL_FAILURE(poison_all_but(
        {Buffer::ParticleForce, Buffer::ParticlePos, Buffer::BodyPos, Buffer::BodyFirst}));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleForce, force));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticlePos, w.particles.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyPos, w.bodies.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyFirst, w.bodies.first));
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::BodiesReduce, w.params));
    ASSERT_NO_FATAL_FAILURE(finish_kernel());
    std::vector<vec4> got_force;
    std::vector<vec4> got_torque;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyForce, got_force));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyTorque, got_torque));

    begin_case("bodies_reduce/" + layout, w.sizes.particles);
    check_close("BodyForce", got_force, w.bodies.force, kBodiesReduceTolerance);
    check_close("BodyTorque", got_torque, w.bodies.torque, kBodiesReduceTolerance);
    end_case();
  }
};

TEST_P(BodiesReduce, Empty) { run_case("random", random_world(41, 0)); }
TEST_P(BodiesReduce, One) { run_case("random", random_world(42, 1)); }
TEST_P(BodiesReduce, Random31) { run_case("random", random_world(43, 31)); }
TEST_P(BodiesReduce, Random1234) { run_case("random", random_world(44, 1234)); }
TEST_P(BodiesReduce, Random65536) { run_case("random", random_world(45, 65536)); }

TEST_P(BodiesReduce, LargeBodies) {
  // 16 bodies of 4096 particles (like a voxelized mesh), 1e5 m from the origin.
  Rng rng(46);
  const float rmax = 0.05f;
  World w =
      make_world(rng, random_cloud(rng, 65536, rmax, 4.0f, vec3(1e5f, 2.0f, -1e5f)), 0, false);
  const std::size_t bodies = 16;
  const std::size_t per_body = w.particles.size() / bodies;
  w.bodies.pos.resize(bodies);
  w.bodies.first.resize(bodies + 1);
  for (std::size_t b = 0; b <= bodies; ++b) w.bodies.first[b] = static_cast<uint>(b * per_body);
  for (std::size_t i = 0; i < w.particles.size(); ++i) {
    w.particles.body[i] = static_cast<uint>(i / per_body);
  }
  w.bodies.pos[3].w = 0.0f;  // one of them static
  w.sizes.bodies = static_cast<std::uint32_t>(bodies);
  w.params.body_count = w.sizes.bodies;
  run_case("large_bodies_far", w);
}

INSTANTIATE_TEST_SUITE_P(Conformance, BodiesReduce, testing::ValuesIn(device_params()), param_name);

}  // namespace
}  // namespace motes_conf
