// particles_update against the oracle, the kernel alone: ParticleBody, ParticleLocal, ParticlePos
// and ParticleVel (their w: radius and inverse mass), the body pose (BodyPos, BodyQuat, BodyVel,
// BodyAngVel), NeighbourRefPos and NeighbourState are written, every other buffer is poisoned;
// ParticlePos, ParticleVel and NeighbourState are read back. Only the rigid particles [0, Nr)
// move: the free ones must come back bitwise as written. Their xyz are compared by NMSE, their w
// (radius, inverse mass: other quantities, and kept by the kernel) bitwise; the rebuild word of
// NeighbourState must be set exactly when a particle ends 0.45 skin or more from its
// NeighbourRefPos (the refs sit at 0.3 or 0.6 skin from the new positions), and nothing else of
// NeighbourState may change.
//
// With MOTES_FLAG_ABSORB (cloth and ropes attached to rigid bodies) ParticleForce and
// ParticleMoment of the rigid particles are read back too: what their velocities as written (random
// here, so far from their bodies' point velocities) hand to their bodies, before the pose.
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
#include "shared/neighbours.h"
#include "test_data.h"

namespace motes_conf {
namespace {

using motes::Buffer;

constexpr double kParticlesUpdateTolerance = 1.0e-10;

class ParticlesUpdate : public DeviceTest {
 protected:
  /// `far`: one rigid particle's ref sits 0.6 skin away (a rebuild is due), the others 0.3.
  /// `reactions`: with MOTES_FLAG_PARTICLE_SHIFT too, the impulses are the reactions of position
  /// contacts given in ParticleForce (random here), their moments computed.
  void run_case(const std::string& layout, World w, bool far, bool absorb = false,
                bool reactions = false) {
    w.params.neighbour_skin = kTestSkin;
    std::vector<vec4> impulse_want, moment_want;
    std::vector<vec4> force_in;
    if (absorb) {
      w.params.flags |= MOTES_FLAG_ABSORB;
      w.sizes.absorb = 1;
      if (reactions) {
        w.params.flags |= MOTES_FLAG_POSITION | MOTES_FLAG_PARTICLE_SHIFT;
        force_in = random_forces(w.sizes.particles + 11u, w.particles.size(), 0.01f);
      }
      motes_ref::absorbed_impulses(w.bodies, w.particles, impulse_want, moment_want, force_in);
    }
    motes_ref::Particles want = w.particles;
    motes_ref::particles_update(w.bodies, want, w.params);
    Rng rng(static_cast<std::uint32_t>(w.sizes.particles) + 99u);
    std::vector<vec4> ref = moved_by(rng, want.pos, kTestSkin, 0.3f);
    if (far && w.particles.rigid > 0) {
      const std::size_t k = w.particles.rigid / 2;
      ref[k] = moved_by(rng, {want.pos[k]}, kTestSkin, 0.6f)[0];
    }
    motes_ref::Particles again = w.particles;
    const bool rebuild = motes_ref::particles_update(w.bodies, again, w.params, ref);
    ASSERT_EQ(rebuild, far && w.particles.rigid > 0) << "the case's own premise";
    const std::vector<uint> state_in = {0u, 7u, 3u, 5u};

    ASSERT_NO_FATAL_FAILURE(allocate(w.sizes));
    if (reactions) {  // ParticleForce is read: the reactions
      ASSERT_NO_FATAL_FAILURE(poison_all_but(
          {Buffer::ParticleBody, Buffer::ParticleLocal, Buffer::ParticlePos, Buffer::ParticleVel,
           Buffer::BodyPos, Buffer::BodyQuat, Buffer::BodyVel, Buffer::BodyAngVel,
           Buffer::NeighbourRefPos, Buffer::NeighbourState, Buffer::ParticleForce}));
      ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleForce, force_in));
    } else {
      ASSERT_NO_FATAL_FAILURE(
          poison_all_but({Buffer::ParticleBody, Buffer::ParticleLocal, Buffer::ParticlePos,
                          Buffer::ParticleVel, Buffer::BodyPos, Buffer::BodyQuat, Buffer::BodyVel,
                          Buffer::BodyAngVel, Buffer::NeighbourRefPos, Buffer::NeighbourState}));
    }
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleBody, w.particles.body));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleLocal, w.particles.local));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticlePos, w.particles.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleVel, w.particles.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyPos, w.bodies.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyQuat, w.bodies.quat));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyVel, w.bodies.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyAngVel, w.bodies.angvel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourRefPos, ref));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourState, state_in));
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::ParticlesUpdate, w.params));
    ASSERT_NO_FATAL_FAILURE(finish_kernel());
    std::vector<vec4> pos;
    std::vector<vec4> vel;
    std::vector<uint> state;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticlePos, pos));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticleVel, vel));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::NeighbourState, state));
    std::vector<vec4> impulse, moment;
    if (absorb) {
      ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticleForce, impulse));
      ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticleMoment, moment));
    }

    const std::size_t rigid = w.particles.rigid;
    std::vector<uint> state_want = state_in;
    if (rebuild) state_want[MOTES_NEIGHBOUR_REBUILD] = 1u;

    begin_case("particles_update/" + layout, w.sizes.particles);
    check_close("ParticlePos", slice(pos, 0, rigid), slice(want.pos, 0, rigid),
                kParticlesUpdateTolerance, Part::Xyz);
    check_close("ParticleVel", slice(vel, 0, rigid), slice(want.vel, 0, rigid),
                kParticlesUpdateTolerance, Part::Xyz);
    check_w_identical("ParticlePos.w (radius) kept", pos, w.particles.pos);
    check_w_identical("ParticleVel.w (inverse mass) kept", vel, w.particles.vel);
    check_identical("free particles' ParticlePos untouched", slice(pos, rigid, pos.size()),
                    slice(w.particles.pos, rigid, pos.size()));
    check_identical("free particles' ParticleVel untouched", slice(vel, rigid, vel.size()),
                    slice(w.particles.vel, rigid, vel.size()));
    check_identical("NeighbourState", state, state_want);
    if (absorb) {
      check_close("ParticleForce (absorbed impulse)", slice(impulse, 0, rigid), impulse_want,
                  kParticlesUpdateTolerance);
      check_close("ParticleMoment (absorbed)", moment, moment_want, kParticlesUpdateTolerance);
    }
    end_case();
  }
};

TEST_P(ParticlesUpdate, Empty) { run_case("random", random_world(61, 0), false); }
TEST_P(ParticlesUpdate, One) { run_case("random", random_world(62, 1), false); }
TEST_P(ParticlesUpdate, Random31) { run_case("random", random_world(63, 31), true); }
TEST_P(ParticlesUpdate, Random1234) { run_case("random", random_world(64, 1234), false); }
TEST_P(ParticlesUpdate, Random1234Moved) { run_case("moved_far", random_world(64, 1234), true); }
TEST_P(ParticlesUpdate, Random65536) { run_case("random", random_world(65, 65536), true); }
TEST_P(ParticlesUpdate, Random1234Absorb) {
  run_case("absorb", random_world(66, 1234), false, true);
}
TEST_P(ParticlesUpdate, Random31AbsorbMoved) {
  run_case("absorb", random_world(67, 31), true, true);
}
TEST_P(ParticlesUpdate, Random1234Reactions) {
  // Position contacts: each rigid particle hands its body the reaction in ParticleForce.
  run_case("reactions", random_world(68, 1234), false, true, true);
}

INSTANTIATE_TEST_SUITE_P(Conformance, ParticlesUpdate, testing::ValuesIn(device_params()),
                         param_name);

}  // namespace
}  // namespace motes_conf
