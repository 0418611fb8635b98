// halo_pack against the oracle (shared/halo.h), the kernel alone. Every buffer it neither reads
// nor writes is poisoned; HaloIndex holds junk words (valid particle indices) before p.halo_first
// and after the entries, so a kernel that ignores halo_first reads the wrong entries. Entries name
// particles and bodies in scrambled order and leave some unnamed. Velocities and body state hold
// NaNs with payloads (quiet and signalling), infinities, -0 and subnormals, positions -0 and
// subnormals (halo_support.h): the kernel is a copy, and every output is compared bitwise.
//
// HaloData is poisoned, and must come back as the oracle's (an entry whose index is out of range
// keeps the poison); the particles and bodies it reads come back as written.
//
// A call beyond the buffers allocated for it is refused before it runs (the GPU backends' launch
// guard; openmp, which checks no launch parameters, skips it): here a pack past the end of
// HaloIndex.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "conformance.h"
#include "halo_support.h"
#include "reference/reference.h"
#include "test_data.h"

namespace motes_conf {
namespace {

using motes::Buffer;

class HaloPack : public HaloTest {
 protected:
  void run_case(const std::string& layout, const Halo& h) {
    std::vector<vec4> want(h.sizes.halo_data, kHaloPoison);
    motes_ref::halo_pack(h.particles, h.bodies, h.index, h.params, want);
    ASSERT_NO_FATAL_FAILURE(allocate(h.sizes));
    ASSERT_NO_FATAL_FAILURE(poison_all_but(
        {Buffer::ParticlePos, Buffer::ParticleVel, Buffer::BodyPos, Buffer::BodyQuat,
         Buffer::BodyVel, Buffer::BodyAngMom, Buffer::BodyAngVel, Buffer::HaloIndex}));
    ASSERT_NO_FATAL_FAILURE(write_state(h));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::HaloIndex, h.index));
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::HaloPack, h.params));
    ASSERT_NO_FATAL_FAILURE(finish_kernel());
    std::vector<vec4> got;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::HaloData, got));

    begin_case("halo_pack/" + layout, h.entries());
    check_identical("HaloData", got, want);
    ASSERT_NO_FATAL_FAILURE(check_state(h));  // its inputs, untouched
    end_case();
  }
};

TEST_P(HaloPack, Empty) { run_case("empty", make_halo(301, 0, 0)); }
TEST_P(HaloPack, One) { run_case("scrambled", make_halo(302, 1, 1)); }
TEST_P(HaloPack, Scrambled31) { run_case("scrambled", make_halo(303, 31, 31)); }
TEST_P(HaloPack, Scrambled1234) { run_case("scrambled", make_halo(304, 1234, 1234)); }
TEST_P(HaloPack, ParticlesOnly1234) { run_case("particles_only", make_halo(305, 1234, 0)); }
TEST_P(HaloPack, BodiesOnly1234) { run_case("bodies_only", make_halo(306, 0, 1234)); }
TEST_P(HaloPack, OutOfRange1234) { run_case("out_of_range", make_halo(307, 1234, 1234, true)); }
TEST_P(HaloPack, Scrambled65536) { run_case("scrambled", make_halo(308, 65536, 65536)); }

INSTANTIATE_TEST_SUITE_P(Conformance, HaloPack, testing::ValuesIn(device_params()), param_name);

class HaloPackLaunchGuard : public HaloLaunchGuardTest {};

TEST_P(HaloPackLaunchGuard, PastHaloIndex) {
  const Halo h = make_halo(331, 31, 31);
  StepParams p = h.params;
  p.halo_first = h.sizes.halo_index - p.halo_particles - p.halo_bodies + 1;
  run_case("refused_past_halo_index", motes::Kernel::HaloPack, h, p);
}

INSTANTIATE_TEST_SUITE_P(Conformance, HaloPackLaunchGuard, testing::ValuesIn(device_params()),
                         param_name);

}  // namespace
}  // namespace motes_conf
