// halo_pack and halo_unpack against the oracle (shared/halo.h), each kernel alone, then the two in
// a row. Every buffer a kernel neither reads nor writes is poisoned; HaloIndex holds junk words
// (valid particle indices) before p.halo_first and after the entries, so a kernel that ignores
// halo_first reads the wrong entries. Entries name particles and bodies in scrambled order and
// leave some unnamed. Velocities and body state hold NaNs with payloads (quiet and signalling),
// infinities, -0 and subnormals, positions -0 and subnormals: the kernels are copies, and every
// output is compared bitwise (integers and bits: no tolerance).
//
// halo_pack: HaloData is poisoned, and must come back as the oracle's (an entry whose index is out
// of range keeps the poison). halo_unpack: ParticlePos, ParticleVel and the five body buffers come
// back as the oracle's (unnamed particles and bodies untouched), and NeighbourState's rebuild word
// is set exactly when a particle it wrote is 0.45 skin or more from its NeighbourRefPos: the
// unnamed particles' references are 2 skin away, so a kernel that tests every particle fails the
// cases where no written particle moved; one case puts a written particle exactly at 0.45 skin,
// one a float below it. The round trip packs a state on the device, overwrites the particles and
// bodies, and unpacks the device's own HaloData: the named ones must come back bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <iterator>
#include <string>
#include <vector>

#include "conformance.h"
#include "motes/devices.h"
#include "reference/reference.h"
#include "shared/halo.h"
#include "shared/neighbours.h"
#include "test_data.h"

namespace motes_conf {
namespace {

using motes::Buffer;

constexpr Buffer kBodyState[MOTES_HALO_BODY_VEC4S] = {
    Buffer::BodyPos, Buffer::BodyQuat, Buffer::BodyVel, Buffer::BodyAngMom, Buffer::BodyAngVel};
constexpr std::vector<vec4> motes_ref::Bodies::*kOracleBodyState[MOTES_HALO_BODY_VEC4S] = {
    &motes_ref::Bodies::pos, &motes_ref::Bodies::quat, &motes_ref::Bodies::vel,
    &motes_ref::Bodies::angmom, &motes_ref::Bodies::angvel};

/// The bits poison_all_but writes: what an entry halo_pack skips keeps.
const vec4 kPoison(std::bit_cast<float>(0xFFFFFFFFu));

/// Bit patterns a copy must keep: NaNs with payloads (quiet, signalling), infinities, -0,
/// subnormals.
constexpr uint kSpecial[] = {0x7FC12345u, 0xFFA00001u, 0x7F800000u, 0xFF800000u,
                             0x80000000u, 0x00000001u, 0x807FFFFFu};
/// The finite ones, for positions (halo_unpack measures them against NeighbourRefPos).
constexpr uint kSpecialFinite[] = {0x80000000u, 0x00000001u, 0x807FFFFFu};

/// What a halo case runs on.
struct Halo {
  motes_ref::Particles particles;  ///< pos and vel only
  motes_ref::Bodies bodies;        ///< pos, quat, vel, angmom, angvel only
  std::vector<uint> index;  ///< HaloIndex: junk, the particle entries, the body entries, junk
  StepParams params{};
  motes::Sizes sizes;
  [[nodiscard]] std::size_t entries() const {
    return std::size_t{params.halo_particles} + params.halo_bodies;
  }
};

/// A component replaced by one of `patterns` now and then.
float maybe_special(Rng& rng, float x, const uint* patterns, std::size_t count) {
  if (!rng.chance(0.05f)) return x;
  return std::bit_cast<float>(patterns[rng.below(static_cast<std::uint32_t>(count))]);
}

vec4 random_state(Rng& rng, float scale, bool finite) {
  const uint* patterns = finite ? kSpecialFinite : kSpecial;
  const std::size_t count = finite ? std::size(kSpecialFinite) : std::size(kSpecial);
  vec4 v(rng.uniform(-scale, scale), rng.uniform(-scale, scale), rng.uniform(-scale, scale),
         rng.uniform(0.0f, scale));
  v.x = maybe_special(rng, v.x, patterns, count);
  v.y = maybe_special(rng, v.y, patterns, count);
  v.z = maybe_special(rng, v.z, patterns, count);
  v.w = maybe_special(rng, v.w, patterns, count);
  return v;
}

/// New particle and body states for every particle and body of h (positions finite).
void randomize_state(Rng& rng, Halo& h) {
  for (vec4& x : h.particles.pos) x = random_state(rng, 1.0f, true);
  for (vec4& v : h.particles.vel) v = random_state(rng, 3.0f, false);
  for (std::vector<vec4> motes_ref::Bodies::*state : kOracleBodyState) {
    for (vec4& v : h.bodies.*state) v = random_state(rng, 2.0f, false);
  }
}

/// The first `count` of a random permutation of [0, n).
std::vector<uint> scrambled(Rng& rng, std::size_t n, std::size_t count) {
  std::vector<uint> ids(n);
  for (std::size_t i = 0; i < n; ++i) ids[i] = static_cast<uint>(i);
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t j = i + rng.below(static_cast<std::uint32_t>(n - i));
    std::swap(ids[i], ids[j]);
  }
  ids.resize(count);
  return ids;
}

/// `np` particle entries and `nb` body entries over twice as many particles and bodies (plus a
/// few), in scrambled order after 1 to 7 junk words (none when there are no entries).
/// `out_of_range`: three entries name a particle or body that does not exist.
Halo make_halo(std::uint32_t seed, std::size_t np, std::size_t nb, bool out_of_range = false) {
  Rng rng(seed);
  Halo h;
  const std::size_t n = 2 * np + 3;
  const std::size_t b = 2 * nb + 2;
  h.particles.pos.resize(n);
  h.particles.vel.resize(n);
  for (std::vector<vec4> motes_ref::Bodies::*state : kOracleBodyState) (h.bodies.*state).resize(b);
  randomize_state(rng, h);

  const bool any = np + nb > 0;
  const std::size_t first = any ? 1 + rng.below(7) : 0;
  for (std::size_t k = 0; k < first; ++k) h.index.push_back(rng.below(static_cast<uint>(n)));
  for (const uint i : scrambled(rng, n, np)) h.index.push_back(i);
  for (const uint j : scrambled(rng, b, nb)) h.index.push_back(j);
  if (any) {
    for (int k = 0; k < 3; ++k) h.index.push_back(rng.below(static_cast<uint>(n)));
  }
  if (out_of_range && np > 2 && nb > 0) {
    h.index[first] = static_cast<uint>(n);  // the particle count itself
    h.index[first + np / 2] = 0xFFFFFFFFu;
    h.index[first + np + nb - 1] = static_cast<uint>(b);
  }

  h.sizes.particles = static_cast<std::uint32_t>(n);
  h.sizes.bodies = static_cast<std::uint32_t>(b);
  h.sizes.table = motes::grid_table_size(h.sizes.particles);
  h.sizes.halo_index = static_cast<std::uint32_t>(h.index.size());
  h.sizes.halo_data =
      static_cast<std::uint32_t>(MOTES_HALO_PARTICLE_VEC4S * np + MOTES_HALO_BODY_VEC4S * nb);
  StepParams& p = h.params;
  p.particle_count = h.sizes.particles;
  p.body_count = h.sizes.bodies;
  p.table_mask = h.sizes.table - 1;
  p.cell_size = 1.0f;
  p.inv_cell_size = 1.0f;
  p.neighbour_skin = kTestSkin;
  p.halo_first = static_cast<uint>(first);
  p.halo_particles = static_cast<uint>(np);
  p.halo_bodies = static_cast<uint>(nb);
  return h;
}

/// The particles an entry of h writes (in range), as a mask over particles.
std::vector<bool> named_particles(const Halo& h) {
  std::vector<bool> named(h.particles.size(), false);
  for (std::size_t k = 0; k < h.params.halo_particles; ++k) {
    const uint i = h.index[h.params.halo_first + k];
    if (i < h.particles.size()) named[i] = true;
  }
  return named;
}

class HaloTest : public DeviceTest {
 protected:
  /// Writes the particles' and bodies' state of h.
  void write_state(const Halo& h) {
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticlePos, h.particles.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleVel, h.particles.vel));
    for (std::size_t c = 0; c < MOTES_HALO_BODY_VEC4S; ++c) {
      ASSERT_NO_FATAL_FAILURE(write(kBodyState[c], h.bodies.*kOracleBodyState[c]));
    }
  }
  /// Compares the device's particles and bodies with h's, bitwise.
  void check_state(const Halo& want) {
    std::vector<vec4> got;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticlePos, got));
    check_identical("ParticlePos", got, want.particles.pos);
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticleVel, got));
    check_identical("ParticleVel", got, want.particles.vel);
    for (std::size_t c = 0; c < MOTES_HALO_BODY_VEC4S; ++c) {
      ASSERT_NO_FATAL_FAILURE(read(kBodyState[c], got));
      check_identical(motes::buffer_name(kBodyState[c]), got, want.bodies.*kOracleBodyState[c]);
    }
  }
};

class HaloPack : public HaloTest {
 protected:
  void run_case(const std::string& layout, const Halo& h) {
    std::vector<vec4> want(h.sizes.halo_data, kPoison);
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

class HaloRoundTrip : public HaloTest {
 protected:
  void run_case(const std::string& layout, const Halo& h) {
    std::vector<vec4> packed(h.sizes.halo_data, kPoison);
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

TEST_P(HaloRoundTrip, One) { run_case("scrambled", make_halo(321, 1, 1)); }
TEST_P(HaloRoundTrip, Scrambled1234) { run_case("scrambled", make_halo(322, 1234, 1234)); }
TEST_P(HaloRoundTrip, Scrambled65536) { run_case("scrambled", make_halo(323, 65536, 65536)); }

INSTANTIATE_TEST_SUITE_P(Conformance, HaloRoundTrip, testing::ValuesIn(device_params()),
                         param_name);

/// A halo call beyond the buffers allocated for it is refused before it runs (the GPU backends'
/// launch guard, motes::halo_launch_error): synchronize() names it, and no guard word is touched.
/// The openmp device checks no launch parameters (it has no error to report them through).
class HaloLaunchGuard : public DeviceTest {
 protected:
  [[nodiscard]] bool wants_device() const override { return false; }  // it is left failed
  void run_case(const std::string& layout, motes::Kernel kernel, const Halo& h, StepParams p) {
    if (GetParam().backend == "openmp") GTEST_SKIP() << "openmp checks no launch parameters";
    auto opened = motes::open_device(GetParam().backend, GetParam().index);
    ASSERT_TRUE(opened) << opened.message();
    motes::Device& d = *opened.value();
    ASSERT_TRUE(d.allocate(h.sizes));
    ASSERT_TRUE(d.write(Buffer::HaloIndex, h.index.data(), h.index.size() * sizeof(uint)));
    d.enqueue(kernel, p);
    const motes::Status s = d.synchronize();
    begin_case(std::string(motes::kernel_name(kernel)) + "/" + layout, h.entries());
    check_that("the call is refused", !s);
    check_that("the refusal names the launch",
               s.message().find(motes::kernel_name(kernel)) != std::string::npos);
    end_case();
  }
};

TEST_P(HaloLaunchGuard, PackPastHaloIndex) {
  const Halo h = make_halo(331, 31, 31);
  StepParams p = h.params;
  p.halo_first = h.sizes.halo_index - p.halo_particles - p.halo_bodies + 1;
  run_case("refused_past_halo_index", motes::Kernel::HaloPack, h, p);
}

TEST_P(HaloLaunchGuard, UnpackPastHaloData) {
  const Halo h = make_halo(332, 31, 31);
  StepParams p = h.params;
  p.halo_first = 0;
  p.halo_particles += 2;  // still within HaloIndex (junk words), not within HaloData
  run_case("refused_past_halo_data", motes::Kernel::HaloUnpack, h, p);
}

TEST_P(HaloLaunchGuard, DisplacementWithoutPartition) {
  const Halo h = make_halo(333, 31, 31);  // Sizes::partition = 0
  run_case("refused_without_partition", motes::Kernel::ParticlesDisplacement, h, h.params);
}

INSTANTIATE_TEST_SUITE_P(Conformance, HaloLaunchGuard, testing::ValuesIn(device_params()),
                         param_name);

}  // namespace
}  // namespace motes_conf
