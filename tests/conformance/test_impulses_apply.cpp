// impulses_apply against the oracle, the kernel alone (test_impulses_compute.cpp runs it after
// impulses_compute as the core does). Written: the bodies of random_world (poses, velocities,
// angular momenta and velocities, inverse inertia, about 10% static; runs of 1 to 64 particles),
// BodyFirst, random impulses in ParticleForce (xyz up to 1e-3 N s: velocity changes of the order of
// the bodies' own, w a whole count of contacts 0 to 6) and moments in ParticleMoment for every
// particle (static bodies' and free spheres' too: they must not be summed), random BodyVelStart,
// BodyAngVelStart, BodyVelPush and BodyAngMomPush, ImpulseStamp 6 or 7 and NeighbourState with
// builds = 9. Every other buffer is poisoned. Read back: BodyVel, BodyAngMom, BodyAngVel (a static
// body's angular velocity from its angular momentum), BodyVelStart and BodyAngVelStart,
// ImpulseStamp, BodyVelPush and BodyAngMomPush. Without MOTES_FLAG_IMPULSE_COUNT the start and the
// stamps must come back as written, bitwise; with it the start is (BodyVel, the summed count) and
// BodyAngVel as they were, and the dynamic bodies' particles are stamped 9. Without
// MOTES_FLAG_IMPULSE_PUSH the pushed velocities must come back as written; with it they are the
// velocities the call leaves. With MOTES_FLAG_POSITION (the projection of position contacts) the
// call moves the dynamic bodies' poses too (BodyPos, BodyQuat read back and compared); otherwise
// they must come back as written, bitwise. With MOTES_FLAG_POSITION_GRAM (a counting pass of
// position contacts) ParticleForce and ParticleMoment hold each particle's sum of n n^T over 0 to 6
// random unit normals, ParticlePos is written too, nothing is applied (the velocities come back
// as they were) and BodyAngVelStart.w is each body's contact Gram bound (shared/contact_gram.h).
//
// LargeBodies*: the same with a few bodies of 1 to 3,000 particles (large_bodies_world), which the
// GPU backends sum with a block or workgroup per body.
//
// Tolerance: NMSE 1e-7, as for the same outputs in test_impulses_compute.cpp. The sums are in
// float in particle order on every backend and the update is the shared body_apply_impulse, so
// openmp matches bitwise (0); a GPU may fuse multiply-adds in the angular velocity. The counts
// are sums of whole numbers (exact). The oracle made to leave each body's last particle out fails
// every case but the empty one (NMSE 0.5 to 2.4); made to stamp nothing, or to keep no count, the
// three count cases; made to sum static bodies' counts, the count cases of 1,234 and 65,536
// particles (BodyVelStart, NMSE 6e-2 and 9e-2); made to keep no BodyAngMomPush, the two push
// cases.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "conformance.h"
#include "reference/reference.h"
#include "shared/impulse.h"
#include "test_data.h"

namespace motes_conf {
namespace {

using motes::Buffer;

constexpr double kApplyTolerance = 1.0e-7;
constexpr uint kApplyBuilds = 9;

/// A contact's normal n added to a particle's sums as a Gram counting pass adds it.
void shared_impulse_add_gram(vec4& sum, vec4& moment, vec3 n) {
  vec3 m = motes::shared::xyz(moment);
  motes::shared::impulse_add(sum, m, vec4(n, 1.0f), vec3(0.0f), MOTES_FLAG_POSITION_GRAM);
  moment = vec4(m, 0.0f);
}

class ImpulsesApply : public DeviceTest {
 protected:
  void run_case(const std::string& layout, World w, uint flags) {
    w.sizes.impulse = 1;
    w.params.flags |= flags;
    const bool counting = (flags & MOTES_FLAG_IMPULSE_COUNT) != 0u;
    const bool push = (flags & MOTES_FLAG_IMPULSE_PUSH) != 0u;
    // A projection of position contacts moves the poses; their counting pass does not.
    const bool moves = (flags & MOTES_FLAG_POSITION) != 0u && !counting;
    const std::size_t n = w.particles.size();
    const std::size_t nr = w.particles.rigid;
    const std::size_t b = w.bodies.size();
    Rng rng(static_cast<std::uint32_t>(n) + 17u);
    // A Gram counting pass (MOTES_FLAG_POSITION_GRAM) sums n n^T of each particle's contacts:
    // 0 to 6 random unit normals (diagonal in ParticleForce.xyz, the rest in ParticleMoment).
    const bool gram = (flags & MOTES_FLAG_POSITION_GRAM) != 0u;
    std::vector<vec4> force;  // N: ParticleForce
    std::vector<vec4> moment;
    for (std::size_t i = 0; i < n; ++i) {
      if (!gram) {
        force.emplace_back(rng.uniform(-1e-3f, 1e-3f), rng.uniform(-1e-3f, 1e-3f),
                           rng.uniform(-1e-3f, 1e-3f), static_cast<float>(rng.below(7)));
        moment.emplace_back(rng.uniform(-1e-4f, 1e-4f), rng.uniform(-1e-4f, 1e-4f),
                            rng.uniform(-1e-4f, 1e-4f), 0.0f);
        continue;
      }
      vec4 f(0.0f), m(0.0f);
      const uint contacts = rng.below(7);
      for (uint c = 0; c < contacts; ++c) {
        const vec3 u(rng.uniform(-1.0f, 1.0f), rng.uniform(-1.0f, 1.0f), rng.uniform(-1.0f, 1.0f));
        const vec3 nrm = u / std::max(motes::shared::length(u), 1e-3f);
        shared_impulse_add_gram(f, m, nrm);
      }
      force.push_back(f);
      moment.push_back(m);
    }
    motes_ref::ImpulseState s;
    s.builds = kApplyBuilds;
    s.impulse = slice(force, 0, nr);
    s.moment = slice(moment, 0, nr);
    for (std::size_t i = 0; i < nr; ++i) s.stamp.push_back(rng.chance(0.5f) ? 7u : 6u);
    const auto random_body_vectors = [&](float scale) {
      std::vector<vec4> out;
      for (std::size_t k = 0; k < b; ++k) {
        out.emplace_back(rng.uniform(-scale, scale), rng.uniform(-scale, scale),
                         rng.uniform(-scale, scale), rng.uniform(0.0f, scale));
      }
      return out;
    };
    s.vel0 = random_body_vectors(1.0f);
    s.angvel0 = random_body_vectors(20.0f);
    s.vel_push = random_body_vectors(1.0f);
    s.angmom_push = random_body_vectors(1e-3f);
    const motes_ref::ImpulseState given = s;
    motes_ref::Bodies want = w.bodies;
    motes_ref::impulses_apply(want, w.params, s, w.particles.pos);

    ASSERT_NO_FATAL_FAILURE(allocate(w.sizes));
    ASSERT_NO_FATAL_FAILURE(poison_all_but(
        {Buffer::ParticleForce, Buffer::ParticleMoment, Buffer::BodyPos, Buffer::BodyQuat,
         Buffer::BodyVel, Buffer::BodyAngMom, Buffer::BodyAngVel, Buffer::BodyInvInertia,
         Buffer::BodyFirst, Buffer::BodyVelStart, Buffer::BodyAngVelStart, Buffer::NeighbourState,
         Buffer::ImpulseStamp, Buffer::BodyVelPush, Buffer::BodyAngMomPush, Buffer::ParticlePos}));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticlePos, w.particles.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleForce, force));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ParticleMoment, given.moment));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyPos, w.bodies.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyQuat, w.bodies.quat));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyVel, w.bodies.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyAngMom, w.bodies.angmom));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyAngVel, w.bodies.angvel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyInvInertia, w.bodies.inv_inertia));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyFirst, w.bodies.first));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyVelStart, given.vel0));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyAngVelStart, given.angvel0));
    ASSERT_NO_FATAL_FAILURE(
        write(Buffer::NeighbourState, std::vector<uint>{0u, kApplyBuilds, 0u, 0u}));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::ImpulseStamp, given.stamp));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyVelPush, given.vel_push));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyAngMomPush, given.angmom_push));
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::ImpulsesApply, w.params));
    std::vector<vec4> pos, quat, vel, angmom, angvel, vel0, angvel0, vel_push, angmom_push;
    std::vector<uint> stamp;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyPos, pos));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyQuat, quat));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyVel, vel));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyAngMom, angmom));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyAngVel, angvel));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyVelStart, vel0));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyAngVelStart, angvel0));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::ImpulseStamp, stamp));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyVelPush, vel_push));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyAngMomPush, angmom_push));

    // The impulses must change most bodies' velocities, and the counting pass count contacts and
    // stamp particles, or the case proves little.
    std::size_t changed = 0;
    for (std::size_t k = 0; k < b; ++k) {
      const vec4 a = want.vel[k], o = w.bodies.vel[k];
      changed += a.x != o.x || a.y != o.y || a.z != o.z ? 1 : 0;
    }
    std::size_t counted = 0;
    for (const vec4& v : s.vel0) counted += counting && v.w > 0.0f ? 1 : 0;
    std::size_t stamped = 0;
    for (std::size_t i = 0; i < nr; ++i) stamped += s.stamp[i] != given.stamp[i] ? 1 : 0;

    std::size_t turned = 0;
    for (std::size_t k = 0; k < b; ++k) {
      const vec4 a = want.quat[k], o = w.bodies.quat[k];
      turned += a.x != o.x || a.y != o.y || a.z != o.z || a.w != o.w ? 1 : 0;
    }

    begin_case("impulses_apply/" + layout, b);
    if (moves) {
      check_close("BodyPos", pos, want.pos, kApplyTolerance);
      check_close("BodyQuat", quat, want.quat, kApplyTolerance);
    } else {
      check_identical("BodyPos untouched", pos, w.bodies.pos);
      check_identical("BodyQuat untouched", quat, w.bodies.quat);
    }
    check_close("BodyVel", vel, want.vel, kApplyTolerance);
    check_close("BodyAngMom", angmom, want.angmom, kApplyTolerance);
    check_close("BodyAngVel", angvel, want.angvel, kApplyTolerance);
    if (counting) {
      check_close("BodyVelStart", vel0, s.vel0, kApplyTolerance);
      check_close("BodyAngVelStart", angvel0, s.angvel0, kApplyTolerance);
    } else {
      check_identical("BodyVelStart untouched", vel0, given.vel0);
      check_identical("BodyAngVelStart untouched", angvel0, given.angvel0);
    }
    check_identical("ImpulseStamp", stamp, s.stamp);
    if (push) {
      check_close("BodyVelPush", vel_push, s.vel_push, kApplyTolerance);
      check_close("BodyAngMomPush", angmom_push, s.angmom_push, kApplyTolerance);
    } else {
      check_identical("BodyVelPush untouched", vel_push, given.vel_push);
      check_identical("BodyAngMomPush untouched", angmom_push, given.angmom_push);
    }
    check_that("the impulses change most bodies' velocities", gram || b < 3 || changed >= b / 2);
    std::size_t bounded = 0;
    for (const vec4& v : s.angvel0) bounded += v.w > 0.0f ? 1 : 0;
    check_that("the Gram counting pass bounds most bodies' steps", !gram || bounded >= b / 2);
    check_that("the projection turns most bodies", !moves || b < 3 || turned >= b / 2);
    check_that("the counting pass counts contacts and stamps particles",
               !counting || nr < 31 || (counted >= b / 2 && stamped > 0));
    end_case();
  }
};

World apply_world(std::uint32_t seed, std::size_t n) {
  return random_world(seed, n, MOTES_FLAG_IMPULSE);
}

/// random_world's rigid particles in a few large bodies (1, 300, 700 and 3,000 particles, then the
/// rest): the GPU kernels for large bodies (a block or workgroup per body) take their particles
/// in rounds of 64 and 256, which runs of random_world's size (1 to 64) never fill twice.
World large_bodies_world(std::uint32_t seed, std::size_t n) {
  World w = apply_world(seed, n);
  const uint nr = static_cast<uint>(w.particles.rigid);
  std::vector<uint> first = {0u};
  for (const uint size : {1u, 300u, 700u, 3000u}) {
    if (first.back() + size < nr) first.push_back(first.back() + size);
  }
  first.push_back(nr);
  const std::size_t b = first.size() - 1;
  motes_ref::Bodies& bodies = w.bodies;
  for (std::vector<vec4>* v :
       {&bodies.pos, &bodies.quat, &bodies.vel, &bodies.angmom, &bodies.angvel, &bodies.inv_inertia,
        &bodies.force, &bodies.torque}) {
    v->resize(b);
  }
  bodies.first = first;
  w.sizes.bodies = static_cast<uint>(b);
  w.params.body_count = static_cast<uint>(b);
  return w;
}

TEST_P(ImpulsesApply, Empty) { run_case("random", apply_world(81, 0), 0u); }
TEST_P(ImpulsesApply, One) { run_case("random", apply_world(82, 1), 0u); }
TEST_P(ImpulsesApply, Random31) { run_case("random", apply_world(83, 31), 0u); }
TEST_P(ImpulsesApply, Random1234) { run_case("random", apply_world(84, 1234), 0u); }
TEST_P(ImpulsesApply, Random65536) { run_case("random", apply_world(85, 65536), 0u); }
TEST_P(ImpulsesApply, Count31) { run_case("count", apply_world(86, 31), MOTES_FLAG_IMPULSE_COUNT); }
TEST_P(ImpulsesApply, Count1234) {
  run_case("count", apply_world(87, 1234), MOTES_FLAG_IMPULSE_COUNT);
}
TEST_P(ImpulsesApply, Count65536) {
  run_case("count", apply_world(88, 65536), MOTES_FLAG_IMPULSE_COUNT);
}
TEST_P(ImpulsesApply, Push1234) {
  run_case("push", apply_world(89, 1234), MOTES_FLAG_IMPULSE_PUSH);
}
TEST_P(ImpulsesApply, Push65536) {
  run_case("push", apply_world(90, 65536), MOTES_FLAG_IMPULSE_PUSH);
}
TEST_P(ImpulsesApply, Position31) {
  run_case("position", apply_world(91, 31), MOTES_FLAG_POSITION);
}
TEST_P(ImpulsesApply, Position1234) {
  run_case("position", apply_world(92, 1234), MOTES_FLAG_POSITION);
}
TEST_P(ImpulsesApply, Position65536) {
  run_case("position", apply_world(93, 65536), MOTES_FLAG_POSITION);
}
// Position contacts count before each projection sweep: the first keeps the velocities as the
// substep's start, the later ones only the counts.
TEST_P(ImpulsesApply, PositionFirstCount1234) {
  run_case("position count", apply_world(94, 1234),
           MOTES_FLAG_POSITION | MOTES_FLAG_POSITION_FIRST | MOTES_FLAG_IMPULSE_COUNT);
}
TEST_P(ImpulsesApply, PositionCount1234) {
  run_case("position count", apply_world(95, 1234), MOTES_FLAG_POSITION | MOTES_FLAG_IMPULSE_COUNT);
}
// The counting pass before the last projection sweep: each body's contact Gram bound
// (shared/contact_gram.h) in BodyAngVelStart.w, nothing applied.
TEST_P(ImpulsesApply, PositionGram1234) {
  run_case("position gram", apply_world(96, 1234),
           MOTES_FLAG_POSITION | MOTES_FLAG_IMPULSE_COUNT | MOTES_FLAG_POSITION_GRAM);
}
TEST_P(ImpulsesApply, PositionGram65536) {
  run_case("position gram", apply_world(97, 65536),
           MOTES_FLAG_POSITION | MOTES_FLAG_IMPULSE_COUNT | MOTES_FLAG_POSITION_GRAM);
}

TEST_P(ImpulsesApply, LargeBodies5000) {
  run_case("large bodies", large_bodies_world(98, 5000), 0u);
}
TEST_P(ImpulsesApply, LargeBodiesCount5000) {
  run_case("large bodies count", large_bodies_world(99, 5000), MOTES_FLAG_IMPULSE_COUNT);
}
TEST_P(ImpulsesApply, LargeBodiesPosition5000) {
  run_case("large bodies position", large_bodies_world(100, 5000), MOTES_FLAG_POSITION);
}
TEST_P(ImpulsesApply, LargeBodiesGram5000) {
  run_case("large bodies gram", large_bodies_world(101, 5000),
           MOTES_FLAG_POSITION | MOTES_FLAG_IMPULSE_COUNT | MOTES_FLAG_POSITION_GRAM);
}

INSTANTIATE_TEST_SUITE_P(Conformance, ImpulsesApply, testing::ValuesIn(device_params()),
                         param_name);

}  // namespace
}  // namespace motes_conf
