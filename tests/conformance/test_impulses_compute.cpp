// impulses_compute against the oracle, alone and with impulses_apply (test_impulses_apply.cpp has
// impulses_apply alone).
//
// ImpulsesCompute: one call, the counting pass, from the inputs and the contacts' memory described
// below (BodyVelStart and BodyAngVelStart poisoned: the counting pass takes the stage's start from
// the bodies). Read back: every ContactImpulse slot, ImpulseStamp (unchanged) and the rigid
// particles' ParticleForce and ParticleMoment. A sweep is no call of its own: the openmp device's
// sweeps visit only the particles its last counting pass found touching (the others keep the
// zeros that pass wrote), so the sweeps are tested after the counting pass, below. The oracle
// made to ignore the stamps (warm-starting void slots) fails every case of 31 particles or more
// but one (31 with K = 2): NMSE 2.3e-3 to 4.0e-2.
//
// ImpulsesComputeThenApply: impulses_compute and impulses_apply as the core runs them: the counting
// pass (compute, apply: each body's contacts counted, the stage's start kept and the warm start
// applied), then three sweeps with position correction (compute, apply; the last apply with
// MOTES_FLAG_IMPULSE_PUSH: BodyVelPush and BodyAngMomPush kept), then two relaxing sweeps
// (MOTES_FLAG_IMPULSE_RELAX). Written: the particles, the bodies' state and
// mass properties, the lists and grid of the oracle (built at the particles' positions, with
// skin 1 mm: every pair within the impulse margin is listed), ContactLaws (frictionless, capped
// and uncapped friction, restitution 0 to 0.9) and Planes, NeighbourState (builds = 7), and the
// contacts' memory of the last substep: random accumulated impulses in every ContactImpulse slot
// (the same in the two slots of a contact listed on both sides, as the kernels keep them: the
// OpenMP sweeps evaluate such a contact once for both) and ImpulseStamp = 7 for most particles
// (their slots are warm-started) and 6 for the others (their slots are void: lists rebuilt). Every
// other buffer is poisoned. Read back: the bodies' velocities, angular momenta and angular
// velocities, BodyVelStart and BodyAngVelStart, BodyVelPush and BodyAngMomPush, every
// ContactImpulse slot, ImpulseStamp, and the last iteration's ParticleForce and ParticleMoment of
// the rigid particles. Each case runs with K = 16 and again with K = 2, where most particles walk
// the grid and their contacts keep no memory. PositionsComputeThenApply runs the same worlds
// through a substep of position contacts (shared/position.h): two sweeps of a counting pass and
// a projection (which moves the bodies: BodyPos and BodyQuat read back too; the first flagged
// MOTES_FLAG_POSITION_FIRST, the second count MOTES_FLAG_POSITION_GRAM: each body's Gram bound,
// which the velocity pass steps by) and the velocity pass, each a compute and an apply.
//
// Tolerance: NMSE 1e-7. The terms come from the same shared functions and floats, summed in float
// in the contract's order (list order, then particle order per body), so openmp matches bitwise
// (it measures 0). A GPU may fuse multiply-adds in each term; through four passes that feed the
// bodies' velocities back into the next pass's contacts, each value moves by a few float
// roundings relative, NMSE ~ 1e-13, with contacts at a clamp (zero normal impulse, friction at
// its cap) switching sides only for near-zero impulses. Faults it catches: a slot read at the
// wrong index, a stamp ignored or a warm start applied twice change ContactImpulse and the
// velocities by O(1) relative.
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

constexpr double kImpulsesTolerance = 1.0e-7;
constexpr uint kBuilds = 7;
constexpr int kIterations = 3;
constexpr int kRelaxing = 2;

/// The contacts' memory of the last substep for lists of capacity K (Sizes::impulse = 1): random
/// accumulated impulses in every ContactImpulse slot, the same in the two slots of a contact
/// listed on both sides, ImpulseStamp kBuilds for most particles (their slots are warm-started)
/// and 6 for the others (void: lists rebuilt); builds = kBuilds, BodyVelStart and
/// BodyAngVelStart 0.
motes_ref::ImpulseState contact_memory(const World& w, const motes_ref::Neighbours& nb,
                                       uint capacity, std::uint32_t seed) {
  const std::size_t nr = w.particles.rigid;
  const std::size_t slots = motes::buffer_layout(Buffer::ContactImpulse, w.sizes).count;
  Rng rng(seed);
  motes_ref::ImpulseState s;
  s.builds = kBuilds;
  s.vel0.assign(w.bodies.size(), vec4(0.0f));
  s.angvel0.assign(w.bodies.size(), vec4(0.0f));
  for (std::size_t k = 0; k < slots; ++k) {
    s.acc.emplace_back(rng.uniform(-1e-3f, 1e-3f), rng.uniform(-1e-3f, 1e-3f),
                       rng.uniform(-1e-3f, 1e-3f), rng.uniform(0.0f, 1e-3f));
  }
  // A contact's two slots hold the same bits (both particles evaluate it in one order and write
  // the same total): the higher id's slot takes the lower id's.
  for (std::size_t i = 0; i < nr; ++i) {
    if (nb.count[i] > capacity) continue;
    for (std::size_t k = 0; k < nb.count[i]; ++k) {
      const uint j = nb.lists[i][k];
      if (j >= nr || j < i || nb.count[j] > capacity) continue;
      for (std::size_t m = 0; m < nb.count[j]; ++m) {
        if (nb.lists[j][m] == i) s.acc[m * nr + j] = s.acc[k * nr + i];
      }
    }
  }
  for (std::size_t i = 0; i < nr; ++i) s.stamp.push_back(rng.chance(0.8f) ? kBuilds : 6u);
  return s;
}

class ImpulsesComputeThenApply : public DeviceTest {
 protected:
  /// Set: a substep of position contacts (shared/position.h) instead of the impulse stage.
  bool position_ = false;

  /// The counting pass and kIterations iterations on the device and the oracle, lists of
  /// capacity K; `acc` and `stamp` are the contacts' memory at the start.
  void run_capacity(const std::string& name, World w, const motes_ref::Grid& g,
                    const motes_ref::Neighbours& nb, uint capacity, std::uint32_t seed) {
    w.sizes.neighbour_capacity = capacity;
    w.params.neighbour_capacity = capacity;
    w.sizes.impulse = 1;
    const std::size_t nr = w.particles.rigid;
    motes_ref::ImpulseState s = contact_memory(w, nb, capacity, seed);
    const std::vector<vec4> acc0 = s.acc;
    const std::vector<uint> stamp0 = s.stamp;

    // The passes, each a compute and an apply with the same flags.
    std::vector<StepParams> passes;
    const auto pass = [&](uint flags) {
      passes.push_back(w.params);
      passes.back().flags |= flags;
    };
    if (position_) {
      // A substep of position contacts: the first sweep's count and projection, a second's
      // (the contacts the first projected are kept, overlapping or not), the velocity pass.
      pass(MOTES_FLAG_POSITION | MOTES_FLAG_POSITION_FIRST | MOTES_FLAG_IMPULSE_COUNT);
      pass(MOTES_FLAG_POSITION | MOTES_FLAG_POSITION_FIRST);
      pass(MOTES_FLAG_POSITION | MOTES_FLAG_IMPULSE_COUNT | MOTES_FLAG_POSITION_GRAM);
      pass(MOTES_FLAG_POSITION);
      pass(MOTES_FLAG_POSITION | MOTES_FLAG_POSITION_VELOCITY);
    } else {
      // The impulse stage's substep with split impulses: the counting pass, the relaxing sweeps
      // (the last keeps its velocities and copies its accumulated impulses), the correcting
      // sweeps on the copies.
      pass(MOTES_FLAG_IMPULSE_COUNT);
      for (int it = 0; it < kRelaxing; ++it) {
        pass(MOTES_FLAG_IMPULSE_RELAX | (it + 1 == kRelaxing ? MOTES_FLAG_IMPULSE_PUSH : 0u));
      }
      for (int it = 0; it < kIterations; ++it) pass(MOTES_FLAG_IMPULSE_SPLIT);
    }
    motes_ref::Bodies want = w.bodies;
    for (const StepParams& q : passes) {
      motes_ref::impulses_compute(w.particles, want, nb, w.laws, w.planes, q, s);
      motes_ref::impulses_apply(want, q, s, w.particles.pos);
    }

    ASSERT_NO_FATAL_FAILURE(allocate(w.sizes));
    ASSERT_NO_FATAL_FAILURE(
        poison_all_but({Buffer::ParticlePos,      Buffer::ParticleVel,    Buffer::ParticleBody,
                        Buffer::ParticleMaterial, Buffer::NeighbourList,  Buffer::NeighbourCount,
                        Buffer::NeighbourRefPos,  Buffer::GridOrder,      Buffer::GridCellStart,
                        Buffer::SortedBody,       Buffer::ContactLaws,    Buffer::Planes,
                        Buffer::BodyPos,          Buffer::BodyQuat,       Buffer::BodyInvInertia,
                        Buffer::BodyVel,          Buffer::BodyAngMom,     Buffer::BodyAngVel,
                        Buffer::BodyFirst,        Buffer::NeighbourState, Buffer::ContactImpulse,
                        Buffer::ImpulseStamp,     Buffer::ParticleLocal}));
    const std::vector<uint> state = {0u, kBuilds, 0u, 0u};
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticlePos, w.particles.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleVel, w.particles.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleLocal, w.particles.local));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleBody, w.particles.body));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleMaterial, w.particles.material));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourList, list_buffer(nb, capacity)));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourCount, nb.count));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourRefPos, nb.ref));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::GridOrder, g.order));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::GridCellStart, g.cell_start));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::SortedBody, g.sorted_body));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ContactLaws, w.laws));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::Planes, w.planes));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyPos, w.bodies.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyQuat, w.bodies.quat));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyInvInertia, w.bodies.inv_inertia));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyVel, w.bodies.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyAngMom, w.bodies.angmom));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyAngVel, w.bodies.angvel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyFirst, w.bodies.first));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourState, state));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ContactImpulse, acc0));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ImpulseStamp, stamp0));
    for (const StepParams& q : passes) {
      ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::ImpulsesCompute, q));
      ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::ImpulsesApply, q));
    }
    ASSERT_NO_FATAL_FAILURE(finish_kernel());
    std::vector<vec4> pos, quat, vel, angmom, angvel, vel0, angvel0, vel_push, angmom_push, acc,
        force, moment;
    std::vector<uint> stamp;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyPos, pos));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyQuat, quat));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyVel, vel));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyAngMom, angmom));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyAngVel, angvel));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyVelStart, vel0));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyAngVelStart, angvel0));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyVelPush, vel_push));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyAngMomPush, angmom_push));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ContactImpulse, acc));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ImpulseStamp, stamp));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticleForce, force));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticleMoment, moment));

    // The case must make contacts and change velocities, or it proves little.
    std::size_t touching = 0;
    for (const vec4& j : s.impulse) touching += j.w > 0.0f ? 1 : 0;
    std::size_t changed = 0;
    for (std::size_t b = 0; b < want.size(); ++b) {
      const vec4 a = want.vel[b], o = w.bodies.vel[b];
      changed += a.x != o.x || a.y != o.y || a.z != o.z ? 1 : 0;
    }
    // Static particles: exactly zero impulse and moment.
    std::vector<uint> static_nonzero;
    for (std::size_t i = 0; i < nr && i < force.size() && i < moment.size(); ++i) {
      if (w.particles.vel[i].w != 0.0f) continue;
      const vec4 f = force[i], m = moment[i];
      static_nonzero.push_back(f.x != 0.0f || f.y != 0.0f || f.z != 0.0f || f.w != 0.0f ||
                                       m.x != 0.0f || m.y != 0.0f || m.z != 0.0f
                                   ? 1
                                   : 0);
    }
    begin_case((position_ ? "positions/" : "impulses/") + name, w.particles.size());
    check_close("BodyPos", pos, want.pos, kImpulsesTolerance);
    check_close("BodyQuat", quat, want.quat, kImpulsesTolerance);
    check_close("BodyVel", vel, want.vel, kImpulsesTolerance);
    check_close("BodyAngMom", angmom, want.angmom, kImpulsesTolerance);
    check_close("BodyAngVel", angvel, want.angvel, kImpulsesTolerance);
    check_close("BodyVelStart", vel0, s.vel0, kImpulsesTolerance);
    check_close("BodyAngVelStart", angvel0, s.angvel0, kImpulsesTolerance);
    if (!position_) {  // position contacts keep no pushed velocities
      check_close("BodyVelPush", vel_push, s.vel_push, kImpulsesTolerance);
      check_close("BodyAngMomPush", angmom_push, s.angmom_push, kImpulsesTolerance);
    }
    check_close("ContactImpulse", acc, s.acc, kImpulsesTolerance);
    check_identical("ImpulseStamp", stamp, s.stamp);
    check_close("ParticleForce (impulses)", slice(force, 0, nr), s.impulse, kImpulsesTolerance);
    check_close("ParticleMoment", slice(moment, 0, nr), s.moment, kImpulsesTolerance);
    check_identical("impulse and moment of static particles are 0", static_nonzero,
                    std::vector<uint>(static_nonzero.size(), 0u));
    check_that("a quarter of the rigid particles touch something", nr < 31 || touching >= nr / 4);
    check_that("the impulses change most bodies' velocities",
               want.size() < 3 || changed >= want.size() / 2);
    end_case();
  }

  void run_case(const std::string& layout, const World& w) {
    const motes_ref::Grid g = motes_ref::grid_build(w.particles, w.params);
    const motes_ref::Neighbours nb = motes_ref::neighbours_build(w.particles, g, w.params);
    const auto seed = static_cast<std::uint32_t>(w.particles.size()) + 11u;
    run_capacity(layout, w, g, nb, 16, seed);
    ASSERT_FALSE(HasFatalFailure());
    run_capacity(layout + " (K = 2: walks)", w, g, nb, 2, seed);
  }
};

World impulse_world(std::uint32_t seed, std::size_t n) {
  return random_world(seed, n, MOTES_FLAG_IMPULSE, kTestSkin);
}

TEST_P(ImpulsesComputeThenApply, Empty) { run_case("random", impulse_world(61, 0)); }
TEST_P(ImpulsesComputeThenApply, One) { run_case("random", impulse_world(62, 1)); }
TEST_P(ImpulsesComputeThenApply, Random31) { run_case("random", impulse_world(63, 31)); }
TEST_P(ImpulsesComputeThenApply, Random1234) { run_case("random", impulse_world(64, 1234)); }
TEST_P(ImpulsesComputeThenApply, Random5000) { run_case("random", impulse_world(65, 5000)); }

TEST_P(ImpulsesComputeThenApply, FarFromOrigin) {
  Rng rng(66);
  const float rmax = 0.05f;
  auto pos = random_cloud(rng, 1234, rmax, dense_side(1234, rmax), vec3(1e5f, -1e5f, 1e5f));
  run_case("far_1e5", make_world(rng, std::move(pos), MOTES_FLAG_IMPULSE, false, 0.1f));
}

INSTANTIATE_TEST_SUITE_P(Conformance, ImpulsesComputeThenApply, testing::ValuesIn(device_params()),
                         param_name);

/// The same worlds through a substep of position contacts.
class PositionsComputeThenApply : public ImpulsesComputeThenApply {
 protected:
  PositionsComputeThenApply() { position_ = true; }
};

TEST_P(PositionsComputeThenApply, One) { run_case("random", impulse_world(71, 1)); }
TEST_P(PositionsComputeThenApply, Random31) { run_case("random", impulse_world(72, 31)); }
TEST_P(PositionsComputeThenApply, Random1234) { run_case("random", impulse_world(73, 1234)); }
TEST_P(PositionsComputeThenApply, Random5000) { run_case("random", impulse_world(74, 5000)); }

INSTANTIATE_TEST_SUITE_P(Conformance, PositionsComputeThenApply, testing::ValuesIn(device_params()),
                         param_name);

/// impulses_compute alone, one call: the counting pass from the contacts' memory.
class ImpulsesCompute : public DeviceTest {
 protected:
  void run_count(const std::string& name, World w, const motes_ref::Grid& g,
                 const motes_ref::Neighbours& nb, uint capacity, std::uint32_t seed) {
    w.sizes.neighbour_capacity = capacity;
    w.params.neighbour_capacity = capacity;
    w.sizes.impulse = 1;
    const std::size_t nr = w.particles.rigid;
    const motes_ref::ImpulseState s = contact_memory(w, nb, capacity, seed);
    StepParams count = w.params;
    count.flags |= MOTES_FLAG_IMPULSE_COUNT;
    motes_ref::ImpulseState want = s;
    motes_ref::impulses_compute(w.particles, w.bodies, nb, w.laws, w.planes, count, want);

    ASSERT_NO_FATAL_FAILURE(allocate(w.sizes));
    // The counting pass takes the stage's start from the bodies' velocities: BodyVelStart and
    // BodyAngVelStart stay poisoned.
    ASSERT_NO_FATAL_FAILURE(
        poison_all_but({Buffer::ParticlePos,      Buffer::ParticleVel,    Buffer::ParticleBody,
                        Buffer::ParticleMaterial, Buffer::NeighbourList,  Buffer::NeighbourCount,
                        Buffer::NeighbourRefPos,  Buffer::GridOrder,      Buffer::GridCellStart,
                        Buffer::SortedBody,       Buffer::ContactLaws,    Buffer::Planes,
                        Buffer::BodyPos,          Buffer::BodyQuat,       Buffer::BodyInvInertia,
                        Buffer::BodyVel,          Buffer::BodyAngMom,     Buffer::BodyAngVel,
                        Buffer::BodyFirst,        Buffer::NeighbourState, Buffer::ContactImpulse,
                        Buffer::ImpulseStamp,     Buffer::ParticleLocal}));
    const std::vector<uint> state = {0u, kBuilds, 0u, 0u};
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticlePos, w.particles.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleVel, w.particles.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleLocal, w.particles.local));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleBody, w.particles.body));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleMaterial, w.particles.material));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourList, list_buffer(nb, capacity)));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourCount, nb.count));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourRefPos, nb.ref));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::GridOrder, g.order));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::GridCellStart, g.cell_start));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::SortedBody, g.sorted_body));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ContactLaws, w.laws));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::Planes, w.planes));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyPos, w.bodies.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyQuat, w.bodies.quat));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyInvInertia, w.bodies.inv_inertia));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyVel, w.bodies.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyAngMom, w.bodies.angmom));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyAngVel, w.bodies.angvel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyFirst, w.bodies.first));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::NeighbourState, state));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ContactImpulse, s.acc));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ImpulseStamp, s.stamp));
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::ImpulsesCompute, count));
    std::vector<vec4> acc, force, moment;
    std::vector<uint> stamp;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ContactImpulse, acc));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ImpulseStamp, stamp));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticleForce, force));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ParticleMoment, moment));

    // The case must make contacts, or it proves little.
    std::size_t touching = 0;
    for (const vec4& j : want.impulse) touching += j.w > 0.0f ? 1 : 0;
    std::vector<uint> static_nonzero;
    for (std::size_t i = 0; i < nr && i < force.size() && i < moment.size(); ++i) {
      if (w.particles.vel[i].w != 0.0f) continue;
      const vec4 f = force[i], m = moment[i];
      static_nonzero.push_back(f.x != 0.0f || f.y != 0.0f || f.z != 0.0f || f.w != 0.0f ||
                                       m.x != 0.0f || m.y != 0.0f || m.z != 0.0f
                                   ? 1
                                   : 0);
    }
    begin_case("impulses_compute/" + name, w.particles.size());
    check_close("ContactImpulse", acc, want.acc, kImpulsesTolerance);
    check_identical("ImpulseStamp", stamp, want.stamp);
    check_close("ParticleForce (impulses)", slice(force, 0, nr), want.impulse, kImpulsesTolerance);
    check_close("ParticleMoment", slice(moment, 0, nr), want.moment, kImpulsesTolerance);
    check_identical("impulse and moment of static particles are 0", static_nonzero,
                    std::vector<uint>(static_nonzero.size(), 0u));
    check_that("a quarter of the rigid particles touch something", nr < 31 || touching >= nr / 4);
    end_case();
  }

  void run_case(const std::string& layout, const World& w) {
    const motes_ref::Grid g = motes_ref::grid_build(w.particles, w.params);
    const motes_ref::Neighbours nb = motes_ref::neighbours_build(w.particles, g, w.params);
    const auto seed = static_cast<std::uint32_t>(w.particles.size()) + 13u;
    run_count(layout + " count", w, g, nb, 16, seed);
    ASSERT_FALSE(HasFatalFailure());
    run_count(layout + " count (K = 2: walks)", w, g, nb, 2, seed);
  }
};

TEST_P(ImpulsesCompute, Empty) { run_case("random", impulse_world(71, 0)); }
TEST_P(ImpulsesCompute, One) { run_case("random", impulse_world(72, 1)); }
TEST_P(ImpulsesCompute, Random31) { run_case("random", impulse_world(73, 31)); }
TEST_P(ImpulsesCompute, Random1234) { run_case("random", impulse_world(74, 1234)); }
TEST_P(ImpulsesCompute, Random5000) { run_case("random", impulse_world(75, 5000)); }

INSTANTIATE_TEST_SUITE_P(Conformance, ImpulsesCompute, testing::ValuesIn(device_params()),
                         param_name);

}  // namespace
}  // namespace motes_conf
