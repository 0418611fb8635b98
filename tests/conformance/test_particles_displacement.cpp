// particles_displacement against the oracle, the kernel alone: ParticlePos and PartitionRefPos are
// written, every other buffer is poisoned (PartitionCheck too: the kernel must reset it);
// PartitionCheck is read back and compared bitwise: the largest squared distance's float bits
// (shared/halo.h: displacement2_bits, products rounded on their own, so the same bits on every
// backend). The cases: random displacements of up to 2 skin, every particle where it was
// partitioned (0), one particle moved, the last (the kernel must reach the end of a partial
// workgroup), a NaN or infinity in a position or a reference (0x7F800000, an infinity's bits), a
// square beyond the float range (the same), and no particle at all. A call without the partition's
// buffers (Sizes::partition = 0) is refused before it runs by the GPU backends' launch guard
// (ParticlesDisplacementLaunchGuard; openmp, which checks no launch parameters, skips it).
#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

#include "conformance.h"
#include "halo_support.h"
#include "reference/reference.h"
#include "shared/halo.h"
#include "test_data.h"

namespace motes_conf {
namespace {

using motes::Buffer;

/// The positions of random_world(seed, n) (a cloud over rigid and free particles), sized for
/// particles_displacement (Sizes::partition).
World partition_world(std::uint32_t seed, std::size_t n) {
  World w = random_world(seed, n);
  w.sizes.partition = 1;
  return w;
}

class ParticlesDisplacement : public DeviceTest {
 protected:
  void run_case(const std::string& layout, const World& w, const std::vector<vec4>& ref) {
    const uint want = motes_ref::particles_displacement(w.particles.pos, ref, w.params);
    ASSERT_NO_FATAL_FAILURE(allocate(w.sizes));
    ASSERT_NO_FATAL_FAILURE(poison_all_but({Buffer::ParticlePos, Buffer::PartitionRefPos}));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticlePos, w.particles.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::PartitionRefPos, ref));
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::ParticlesDisplacement, w.params));
    ASSERT_NO_FATAL_FAILURE(finish_kernel());
    std::vector<uint> got;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::PartitionCheck, got));
    ASSERT_EQ(got.size(), std::size_t{MOTES_PARTITION_WORDS});

    begin_case("particles_displacement/" + layout, w.sizes.particles);
    check_identical("PartitionCheck largest |x - ref|^2 (float bits)", got,
                    std::vector<uint>{want});
    end_case();
  }
  /// Every particle moved by a random fraction of up to 2 skin from its reference.
  void run_random(const std::string& layout, const World& w) {
    Rng rng(w.sizes.particles + 41u);
    std::vector<vec4> ref = w.particles.pos;
    for (std::size_t i = 0; i < ref.size(); ++i) {
      ref[i] = moved_by(rng, {w.particles.pos[i]}, kTestSkin, rng.uniform(0.0f, 2.0f))[0];
    }
    run_case(layout, w, ref);
  }
};

TEST_P(ParticlesDisplacement, Empty) { run_random("empty", partition_world(401, 0)); }
TEST_P(ParticlesDisplacement, Random1) { run_random("random", partition_world(402, 1)); }
TEST_P(ParticlesDisplacement, Random31) { run_random("random", partition_world(403, 31)); }
TEST_P(ParticlesDisplacement, Random1234) { run_random("random", partition_world(404, 1234)); }
TEST_P(ParticlesDisplacement, Random65536) { run_random("random", partition_world(405, 65536)); }

TEST_P(ParticlesDisplacement, NoneMoved) {
  const World w = partition_world(406, 1234);
  run_case("none_moved", w, w.particles.pos);
  EXPECT_EQ(motes_ref::particles_displacement(w.particles.pos, w.particles.pos, w.params), 0u);
}

TEST_P(ParticlesDisplacement, LastMoved) {
  // 65,537 particles: the last is alone in the last workgroup.
  const World w = partition_world(407, 65537);
  std::vector<vec4> ref = w.particles.pos;
  Rng rng(407);
  ref.back() = moved_by(rng, {ref.back()}, kTestSkin, 0.7f)[0];
  run_case("last_moved", w, ref);
  EXPECT_NE(motes_ref::particles_displacement(w.particles.pos, ref, w.params), 0u);
}

TEST_P(ParticlesDisplacement, NonFinite) {
  World w = partition_world(408, 1234);
  std::vector<vec4> ref = w.particles.pos;
  w.particles.pos[500].y = std::numeric_limits<float>::quiet_NaN();
  ref[900].z = -std::numeric_limits<float>::infinity();
  run_case("non_finite", w, ref);
  EXPECT_EQ(motes_ref::particles_displacement(w.particles.pos, ref, w.params),
            MOTES_PARTITION_NOT_FINITE);
}

TEST_P(ParticlesDisplacement, NonFiniteLast) {
  World w = partition_world(409, 65537);
  std::vector<vec4> ref = w.particles.pos;
  w.particles.pos.back().x = std::numeric_limits<float>::infinity();
  run_case("non_finite_last", w, ref);
}

TEST_P(ParticlesDisplacement, Overflow) {
  // Finite positions whose squared distance is beyond the float range: an infinity's bits.
  World w = partition_world(410, 1234);
  std::vector<vec4> ref = w.particles.pos;
  w.particles.pos[700].x = 3.0e19f;
  ref[700].x = -3.0e19f;
  run_case("overflow", w, ref);
  EXPECT_EQ(motes_ref::particles_displacement(w.particles.pos, ref, w.params),
            MOTES_PARTITION_NOT_FINITE);
}

INSTANTIATE_TEST_SUITE_P(Conformance, ParticlesDisplacement, testing::ValuesIn(device_params()),
                         param_name);

class ParticlesDisplacementLaunchGuard : public HaloLaunchGuardTest {};

TEST_P(ParticlesDisplacementLaunchGuard, WithoutPartition) {
  const Halo h = make_halo(333, 31, 31);  // Sizes::partition = 0
  run_case("refused_without_partition", motes::Kernel::ParticlesDisplacement, h, h.params);
}

INSTANTIATE_TEST_SUITE_P(Conformance, ParticlesDisplacementLaunchGuard,
                         testing::ValuesIn(device_params()), param_name);

}  // namespace
}  // namespace motes_conf
