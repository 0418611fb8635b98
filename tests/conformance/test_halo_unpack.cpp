// halo_unpack against the oracle (shared/halo.h), the kernel alone, then after halo_pack.
// Every buffer a kernel neither reads nor writes is poisoned; HaloIndex holds junk words (valid
// particle indices) before p.halo_first and after the entries, so a kernel that ignores halo_first
// reads the wrong entries. Entries name particles and bodies in scrambled order and leave some
// unnamed. Velocities and body state hold NaNs with payloads (quiet and signalling), infinities,
// -0 and subnormals, positions -0 and subnormals (halo_support.h): the kernels are copies, and
// every output is compared bitwise (integers and bits: no tolerance).
//
// ParticlePos, ParticleVel and the five body buffers come back as the oracle's (unnamed particles
// and bodies untouched), and NeighbourState's rebuild word is set exactly when a particle it wrote
// is 0.45 skin or more from its NeighbourRefPos: the unnamed particles' references are 2 skin
// away, so a kernel that tests every particle fails the cases where no written particle moved;
// one case puts a written particle exactly at 0.45 skin, one a float below it.
//
// The round trip (HaloUnpackRoundTrip) packs a state on the device, overwrites the particles and
// bodies, and unpacks the device's own HaloData: the named ones must come back bit for bit.
//
// A call beyond the buffers allocated for it is refused before it runs (the GPU backends' launch
// guard; openmp, which checks no launch parameters, skips it): here an unpack past the end of
// HaloData.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "conformance.h"
#include "halo_support.h"
#include "reference/reference.h"
#include "shared/halo.h"
#include "shared/neighbours.h"
#include "test_data.h"

namespace motes_conf {
namespace {

using motes::Buffer;

/// Where the written particles' NeighbourRefPos lies: all within 0.3 skin, or one of them (the
/// last particle entry) 0.6 skin away, exactly 0.45 skin away, or a float closer than that.
enum class Moved { None, Far, AtLimit, JustInside };

class HaloUnpack : public HaloTest {
 protected:
  void run_case(const std::string& layout, Halo h, Moved moved) {
    Rng rng(h.sizes.particles + 11u);
    // HaloData: a new state for every entry (the skipped ones' too: they must not land).
    std::vector<vec4> data(h.sizes.halo_data);
    for (std::size_t k = 0; k < data.size(); ++k) {
      data[k] = random_state(rng, 1.0f,
                             k < MOTES_HALO_PARTICLE_VEC4S * h.params.halo_particles &&
                                 k % MOTES_HALO_PARTICLE_VEC4S == 0);
    }
    // NeighbourRefPos: 2 skin from an unnamed particle, 0.3 skin from a named one's new place.
    const std::vector<bool> named = named_particles(h);
    std::vector<vec4> ref = moved_by(rng, h.particles.pos, kTestSkin, 2.0f);
    const float limit = 0.45f * kTestSkin;
    for (std::size_t k = 0; k < h.params.halo_particles; ++k) {
      const uint i = h.index[h.params.halo_first + k];
      if (i >= h.particles.size()) continue;
      vec4& x = data[MOTES_HALO_PARTICLE_VEC4S * k];
      ref[i] = moved_by(rng, {x}, kTestSkin, 0.3f)[0];
      if (k + 1 < h.params.halo_particles || moved == Moved::None) continue;
      if (moved == Moved::Far) {
        ref[i] = moved_by(rng, {x}, kTestSkin, 0.6f)[0];
      } else {  // along x from 0: |dx|^2 is limit^2 (rounded as the kernel rounds it) or less
        x.x = 0.0f;
        ref[i] = x;
        ref[i].x = moved == Moved::AtLimit ? limit : std::nextafter(limit, 0.0f);
      }
    }
    motes_ref::Particles want_particles = h.particles;
    motes_ref::Bodies want_bodies = h.bodies;
    const bool rebuild =
        motes_ref::halo_unpack(want_particles, want_bodies, h.index, data, h.params, ref);
    const bool any_written = std::find(named.begin(), named.end(), true) != named.end();
    ASSERT_EQ(rebuild, moved != Moved::None && moved != Moved::JustInside && any_written)
        << "the case's own premise";
    const std::vector<uint> state_in = {0u, 2u, 0u, 9u};

    ASSERT_NO_FATAL_FAILURE(allocate(h.sizes));
    ASSERT_NO_FATAL_FAILURE(
        poison_all_but({Buffer::ParticlePos, Buffer::ParticleVel, Buffer::BodyPos, Buffer::BodyQuat,
                        Buffer::BodyVel, Buffer::BodyAngMom, Buffer::BodyAngVel, Buffer::HaloIndex,
                        Buffer::HaloData, Buffer::NeighbourRefPos, Buffer::NeighbourState}));
    ASSERT_NO_FATAL_FAILURE(write_state(h));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::HaloIndex, h.index));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::HaloData, data));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourRefPos, ref));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourState, state_in));
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::HaloUnpack, h.params));
    ASSERT_NO_FATAL_FAILURE(finish_kernel());
    std::vector<uint> state;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::NeighbourState, state));
    std::vector<uint> state_want = state_in;
    if (rebuild) state_want[MOTES_NEIGHBOUR_REBUILD] = 1u;

    begin_case("halo_unpack/" + layout, h.entries());
    h.particles = want_particles;
    h.bodies = want_bodies;
    ASSERT_NO_FATAL_FAILURE(check_state(h));
    check_identical("NeighbourState", state, state_want);
    end_case();
  }
};

TEST_P(HaloUnpack, Empty) { run_case("empty", make_halo(311, 0, 0), Moved::None); }
TEST_P(HaloUnpack, OneMoved) { run_case("moved_far", make_halo(312, 1, 1), Moved::Far); }
TEST_P(HaloUnpack, Scrambled31) { run_case("scrambled", make_halo(313, 31, 31), Moved::None); }
TEST_P(HaloUnpack, Scrambled1234) {
  run_case("scrambled", make_halo(314, 1234, 1234), Moved::None);
}
TEST_P(HaloUnpack, Scrambled1234Moved) {
  run_case("moved_far", make_halo(314, 1234, 1234), Moved::Far);
}
TEST_P(HaloUnpack, AtLimit1234) {
  run_case("at_limit", make_halo(315, 1234, 1234), Moved::AtLimit);
}
TEST_P(HaloUnpack, JustInside1234) {
  run_case("just_inside", make_halo(315, 1234, 1234), Moved::JustInside);
}
TEST_P(HaloUnpack, ParticlesOnly1234) {
  run_case("particles_only", make_halo(316, 1234, 0), Moved::None);
}
TEST_P(HaloUnpack, BodiesOnly1234) {
  run_case("bodies_only", make_halo(317, 0, 1234), Moved::None);
}
TEST_P(HaloUnpack, OutOfRange1234) {
  run_case("out_of_range", make_halo(318, 1234, 1234, true), Moved::Far);
}
TEST_P(HaloUnpack, Scrambled65536Moved) {
  run_case("moved_far", make_halo(319, 65536, 65536), Moved::Far);
}

INSTANTIATE_TEST_SUITE_P(Conformance, HaloUnpack, testing::ValuesIn(device_params()), param_name);

class HaloUnpackRoundTrip : public HaloTest {
 protected:
  void run_case(const std::string& layout, const Halo& h) {
    std::vector<vec4> packed(h.sizes.halo_data, kHaloPoison);
    motes_ref::halo_pack(h.particles, h.bodies, h.index, h.params, packed);
    // Another state everywhere before the unpack; the lists built where the packed particles
    // are, so that their return asks for no rebuild.
    Halo overwritten = h;
    Rng rng(h.sizes.particles + 23u);
    randomize_state(rng, overwritten);
    Halo want = overwritten;
    const std::vector<vec4> ref = h.particles.pos;
    const bool rebuild =
        motes_ref::halo_unpack(want.particles, want.bodies, h.index, packed, h.params, ref);
    ASSERT_FALSE(rebuild) << "the case's own premise";
    const std::vector<uint> state_in = {0u, 5u, 1u, 17u};

    ASSERT_NO_FATAL_FAILURE(allocate(h.sizes));
    ASSERT_NO_FATAL_FAILURE(poison_all_but({}));
    ASSERT_NO_FATAL_FAILURE(write_state(h));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::HaloIndex, h.index));
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::HaloPack, h.params));
    ASSERT_NO_FATAL_FAILURE(finish_kernel());
    std::vector<vec4> got;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::HaloData, got));
    ASSERT_NO_FATAL_FAILURE(write_state(overwritten));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourRefPos, ref));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourState, state_in));
    ASSERT_NO_FATAL_FAILURE(
        run(motes::Kernel::HaloUnpack, h.params));  // from the HaloData the device packed
    ASSERT_NO_FATAL_FAILURE(finish_kernel());
    std::vector<uint> state;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::NeighbourState, state));

    begin_case("halo_pack+unpack/" + layout, h.entries());
    check_identical("HaloData", got, packed);
    ASSERT_NO_FATAL_FAILURE(check_state(want));  // the named ones back to h's bits
    check_identical("NeighbourState", state, state_in);
    end_case();
  }
};

TEST_P(HaloUnpackRoundTrip, One) { run_case("scrambled", make_halo(321, 1, 1)); }
TEST_P(HaloUnpackRoundTrip, Scrambled1234) { run_case("scrambled", make_halo(322, 1234, 1234)); }
TEST_P(HaloUnpackRoundTrip, Scrambled65536) { run_case("scrambled", make_halo(323, 65536, 65536)); }

INSTANTIATE_TEST_SUITE_P(Conformance, HaloUnpackRoundTrip, testing::ValuesIn(device_params()),
                         param_name);

class HaloUnpackLaunchGuard : public HaloLaunchGuardTest {};

TEST_P(HaloUnpackLaunchGuard, PastHaloData) {
  const Halo h = make_halo(332, 31, 31);
  StepParams p = h.params;
  p.halo_first = 0;
  p.halo_particles += 2;  // still within HaloIndex (junk words), not within HaloData
  run_case("refused_past_halo_data", motes::Kernel::HaloUnpack, h, p);
}

INSTANTIATE_TEST_SUITE_P(Conformance, HaloUnpackLaunchGuard, testing::ValuesIn(device_params()),
                         param_name);

}  // namespace
}  // namespace motes_conf
