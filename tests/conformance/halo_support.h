// What the halo cases share (test_halo_pack.cpp, test_halo_unpack.cpp and the launch guard case of
// test_particles_displacement.cpp): halo layouts over particles and bodies whose state holds NaNs
// with payloads, infinities, -0 and subnormals, entries in scrambled order after junk words of
// HaloIndex, and the fixtures that write, compare and launch them.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "conformance.h"
#include "motes/devices.h"
#include "reference/reference.h"
#include "shared/halo.h"
#include "test_data.h"

namespace motes_conf {

/// The body buffers of a halo body entry, in HaloData's order, and the oracle's same states.
inline constexpr motes::Buffer kHaloBodyBuffers[MOTES_HALO_BODY_VEC4S] = {
    motes::Buffer::BodyPos, motes::Buffer::BodyQuat, motes::Buffer::BodyVel,
    motes::Buffer::BodyAngMom, motes::Buffer::BodyAngVel};
inline constexpr std::vector<vec4> motes_ref::Bodies::*kHaloOracleBodyState[MOTES_HALO_BODY_VEC4S] =
    {&motes_ref::Bodies::pos, &motes_ref::Bodies::quat, &motes_ref::Bodies::vel,
     &motes_ref::Bodies::angmom, &motes_ref::Bodies::angvel};

/// The bits poison_all_but writes: what an entry halo_pack skips keeps.
inline const vec4 kHaloPoison(std::bit_cast<float>(0xFFFFFFFFu));

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

/// A random state (components in [-scale, scale), w in [0, scale)), now and then a component
/// replaced by a special bit pattern: NaNs with payloads (quiet, signalling), infinities, -0,
/// subnormals, or with `finite` only the finite ones (for positions, which halo_unpack measures
/// against NeighbourRefPos).
vec4 random_state(Rng& rng, float scale, bool finite);

/// New particle and body states for every particle and body of h (positions finite).
void randomize_state(Rng& rng, Halo& h);

/// `np` particle entries and `nb` body entries over twice as many particles and bodies (plus a
/// few), in scrambled order after 1 to 7 junk words (none when there are no entries).
/// `out_of_range`: three entries name a particle or body that does not exist.
Halo make_halo(std::uint32_t seed, std::size_t np, std::size_t nb, bool out_of_range = false);

/// The particles an entry of h writes (in range), as a mask over particles.
std::vector<bool> named_particles(const Halo& h);

/// The fixture of the halo cases.
class HaloTest : public DeviceTest {
 protected:
  /// Writes the particles' and bodies' state of h.
  void write_state(const Halo& h) {
    ASSERT_NO_FATAL_FAILURE(write(motes::Buffer::ParticlePos, h.particles.pos));
    ASSERT_NO_FATAL_FAILURE(write(motes::Buffer::ParticleVel, h.particles.vel));
    for (std::size_t c = 0; c < MOTES_HALO_BODY_VEC4S; ++c) {
      ASSERT_NO_FATAL_FAILURE(write(kHaloBodyBuffers[c], h.bodies.*kHaloOracleBodyState[c]));
    }
  }
  /// Compares the device's particles and bodies with h's, bitwise.
  void check_state(const Halo& want) {
    std::vector<vec4> got;
    ASSERT_NO_FATAL_FAILURE(read(motes::Buffer::ParticlePos, got));
    check_identical("ParticlePos", got, want.particles.pos);
    ASSERT_NO_FATAL_FAILURE(read(motes::Buffer::ParticleVel, got));
    check_identical("ParticleVel", got, want.particles.vel);
    for (std::size_t c = 0; c < MOTES_HALO_BODY_VEC4S; ++c) {
      ASSERT_NO_FATAL_FAILURE(read(kHaloBodyBuffers[c], got));
      check_identical(motes::buffer_name(kHaloBodyBuffers[c]), got,
                      want.bodies.*kHaloOracleBodyState[c]);
    }
  }
};

/// A halo call beyond the buffers allocated for it is refused before it runs (the GPU backends'
/// launch guard, motes::halo_launch_error): synchronize() names it, and no guard word is touched.
/// The openmp device checks no launch parameters (it has no error to report them through).
class HaloLaunchGuardTest : public DeviceTest {
 protected:
  [[nodiscard]] bool wants_device() const override { return false; }  // it is left failed
  void run_case(const std::string& layout, motes::Kernel kernel, const Halo& h, StepParams p) {
    if (GetParam().backend == "openmp") GTEST_SKIP() << "openmp checks no launch parameters";
    auto opened = motes::open_device(GetParam().backend, GetParam().index);
    ASSERT_TRUE(opened) << opened.message();
    motes::Device& d = *opened.value();
    ASSERT_TRUE(d.allocate(h.sizes));
    ASSERT_TRUE(d.write(motes::Buffer::HaloIndex, h.index.data(), h.index.size() * sizeof(uint)));
    d.enqueue(kernel, p);
    const motes::Status s = d.synchronize();
    begin_case(std::string(motes::kernel_name(kernel)) + "/" + layout, h.entries());
    check_that("the call is refused", !s);
    check_that("the refusal names the launch",
               s.message().find(motes::kernel_name(kernel)) != std::string::npos);
    end_case();
  }
};

}  // namespace motes_conf
