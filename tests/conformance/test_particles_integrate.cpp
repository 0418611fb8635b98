// particles_integrate against the oracle, the kernel alone: ParticlePos, ParticleVel,
// ParticleForce, NeighbourRefPos and NeighbourState are written, every other buffer is poisoned;
// ParticlePos, ParticleVel and NeighbourState are read back. Only the free particles [Nr, N)
// move: the rigid ones must come back bitwise as written. xyz compared by NMSE, w (radius,
// inverse mass) bitwise; the rebuild word of NeighbourState must be set exactly when a free
// particle ends 0.45 skin or more from its NeighbourRefPos, nothing else of it may change.
//
// Tolerance: NMSE 1e-10, as particles_update: the shared particle_integrate on the same floats
// (openmp: bitwise), a GPU's fused multiply-adds moving a component by an ulp or two.
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

constexpr double kParticlesIntegrateTolerance = 1.0e-10;

class ParticlesIntegrate : public DeviceTest {
 protected:
  /// `far`: one free particle's ref sits 0.6 skin from where it ends (a rebuild is due), the
  /// others 0.3 skin.
  /// `flags`: MOTES_FLAG_POSITION (predict: the force not used) or with MOTES_FLAG_PARTICLE_SHIFT
  /// (each particle moved by the mean of the shifts in ParticleForce: their number 0 to 3 in w).
  void run_case(const std::string& layout, World w, bool far, uint flags = 0u) {
    w.params.neighbour_skin = kTestSkin;
    w.params.flags |= flags;
    std::vector<vec4> force = random_forces(w.sizes.particles + 5u, w.particles.size(), 2.0f);
    if ((flags & MOTES_FLAG_PARTICLE_SHIFT) != 0u) {
      for (std::size_t i = 0; i < force.size(); ++i) {
        force[i] = vec4(force[i].x * 1e-4f, force[i].y * 1e-4f, force[i].z * 1e-4f,
                        static_cast<float>(i % 4));
      }
    }
    motes_ref::Particles want = w.particles;
    motes_ref::particles_integrate(want, force, w.params);
    Rng rng(static_cast<std::uint32_t>(w.sizes.particles) + 77u);
    std::vector<vec4> ref = moved_by(rng, want.pos, kTestSkin, 0.3f);
    const std::size_t rigid = w.particles.rigid;
    const bool any_free = w.particles.size() > rigid;
    if (far && any_free) {
      const std::size_t k = rigid + (w.particles.size() - rigid) / 2;
      ref[k] = moved_by(rng, {want.pos[k]}, kTestSkin, 0.6f)[0];
    }
    motes_ref::Particles again = w.particles;
    const bool rebuild = motes_ref::particles_integrate(again, force, w.params, ref);
    ASSERT_EQ(rebuild, far && any_free) << "the case's own premise";
    const std::vector<uint> state_in = {0u, 2u, 0u, 9u};

    ASSERT_NO_FATAL_FAILURE(allocate(w.sizes));
    ASSERT_NO_FATAL_FAILURE(
        poison_all_but({Buffer::ParticlePos, Buffer::ParticleVel, Buffer::ParticleForce,
                        Buffer::NeighbourRefPos, Buffer::NeighbourState}));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticlePos, w.particles.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleVel, w.particles.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleForce, force));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourRefPos, ref));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourState, state_in));
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::ParticlesIntegrate, w.params));
    ASSERT_NO_FATAL_FAILURE(finish_kernel());
    std::vector<vec4> pos;
    std::vector<vec4> vel;
    std::vector<uint> state;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticlePos, pos));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticleVel, vel));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::NeighbourState, state));

    std::vector<uint> state_want = state_in;
    if (rebuild) state_want[MOTES_NEIGHBOUR_REBUILD] = 1u;

    begin_case("particles_integrate/" + layout, w.sizes.particles - rigid);
    check_close("ParticlePos", slice(pos, rigid, pos.size()), slice(want.pos, rigid, pos.size()),
                kParticlesIntegrateTolerance, Part::Xyz);
    check_close("ParticleVel", slice(vel, rigid, vel.size()), slice(want.vel, rigid, vel.size()),
                kParticlesIntegrateTolerance, Part::Xyz);
    check_w_identical("ParticlePos.w (radius) kept", pos, w.particles.pos);
    check_w_identical("ParticleVel.w (inverse mass) kept", vel, w.particles.vel);
    check_identical("rigid particles' ParticlePos untouched", slice(pos, 0, rigid),
                    slice(w.particles.pos, 0, rigid));
    check_identical("rigid particles' ParticleVel untouched", slice(vel, 0, rigid),
                    slice(w.particles.vel, 0, rigid));
    check_identical("NeighbourState", state, state_want);
    end_case();
  }
};

TEST_P(ParticlesIntegrate, Empty) { run_case("random", random_world(161, 0), false); }
TEST_P(ParticlesIntegrate, Random31) { run_case("random", random_world(163, 31), true); }
TEST_P(ParticlesIntegrate, Random1234) { run_case("random", random_world(164, 1234), false); }
TEST_P(ParticlesIntegrate, Random1234Moved) {
  run_case("moved_far", random_world(164, 1234), true);
}
TEST_P(ParticlesIntegrate, Linked1234) {
  // The free particles are cloth and rope particles: damped before they are integrated.
  run_case("linked", with_linked(random_world(166, 1234), 166), true);
}
TEST_P(ParticlesIntegrate, Predict1234) {
  // Position contacts: gravity alone predicts, the force is not used.
  run_case("predict", with_linked(random_world(167, 1234), 167), true, MOTES_FLAG_POSITION);
}
TEST_P(ParticlesIntegrate, Shift1234) {
  // Position contacts: the mean of each particle's shifts; no damping, no gravity.
  run_case("shift", with_linked(random_world(168, 1234), 168), true,
           MOTES_FLAG_POSITION | MOTES_FLAG_PARTICLE_SHIFT);
}
TEST_P(ParticlesIntegrate, Random65536) { run_case("random", random_world(165, 65536), true); }

INSTANTIATE_TEST_SUITE_P(Conformance, ParticlesIntegrate, testing::ValuesIn(device_params()),
                         param_name);

}  // namespace
}  // namespace motes_conf
