// bodies_integrate against the oracle, the kernel alone: BodyPos, BodyQuat, BodyVel, BodyAngMom,
// BodyInvInertia, BodyForce and BodyTorque are written, every other buffer (BodyAngVel included)
// is poisoned; the five state buffers are read back. Static bodies keep their state and get a
// zero angular velocity; bodies with L = 0 or a tiny |w dt| take the no-rotation branches.
// BodyPos is compared by NMSE on xyz and bitwise on w (the inverse mass, kept); the other four
// by NMSE on all components (a quaternion; w = 0 for the vectors). `PushPose1234` runs the impulse
// stage's pose update (MOTES_FLAG_BODY_POSE | MOTES_FLAG_IMPULSE_PUSH): BodyVelPush and
// BodyAngMomPush written too (some zero), the pose moved with them (body_push_pose) while the
// bodies keep their own velocities; `SplitPose1234` the split pose (MOTES_FLAG_IMPULSE_SPLIT).
// Both move the centre as the pair BodyPos + BodyPosLow (random parts below the float of each
// centre written, BodyPosLow read back); `SplitPoseFarFromOrigin` 50 m out, at speeds whose
// moves are smaller than the spacing of floats there, which only BodyPosLow keeps. `Predict1234`
// runs the prediction of position contacts
// (MOTES_FLAG_POSITION: gravity alone, BodyForce and BodyTorque written but not applied).
//
// Tolerance: NMSE 1e-10. Per body the same shared body_integrate runs on the same floats, so
// openmp matches bitwise (measures 0). A GPU may fuse multiply-adds and has its own sin, cos and
// sqrt (a few ulps, or an absolute 2^-21 for sin/cos on some drivers): errors of ~1e-7 relative,
// NMSE ~1e-14. Faults measured by breaking the oracle: a time step 1% off gives 6e-8 (so the
// default 1e-7 would miss it), gravity's y and z swapped 2e-4, another body's inertia 3e-4.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "conformance.h"
#include "reference/reference.h"
#include "test_data.h"

namespace motes_conf {
namespace {

using motes::Buffer;

constexpr double kBodiesIntegrateTolerance = 1.0e-10;

class BodiesIntegrate : public DeviceTest {
 protected:
  /// push: the impulse stage's pose (MOTES_FLAG_BODY_POSE | MOTES_FLAG_IMPULSE_PUSH), moved with
  /// random BodyVelPush and BodyAngMomPush (written too) while the bodies keep their velocities;
  /// with split (MOTES_FLAG_IMPULSE_SPLIT in place of MOTES_FLAG_IMPULSE_PUSH), moved with their
  /// velocities, which then take the push copies.
  void run_case(const std::string& layout, World w, bool push = false, bool split = false,
                float far = 0.0f) {
    std::vector<vec4> vel_push, angmom_push, pos_low, want_low;
    if (far != 0.0f) {
      // Far from the origin, moving by less than the spacing of floats there (3.8e-6 m at 50 m):
      // only BodyPosLow keeps such moves.
      for (vec4& x : w.bodies.pos) x = vec4(x.x + far, x.y, x.z - far, x.w);
    }
    motes_ref::Bodies want = w.bodies;
    if (push) {
      Rng rng(static_cast<std::uint32_t>(w.sizes.bodies) + 5u);
      const float speed = far != 0.0f ? 2.0e-3f : 2.0f;
      for (std::size_t b = 0; b < w.bodies.size(); ++b) {
        // The part of the centre below its float: up to half the spacing of floats there.
        const float half_ulp = 0.5f * std::nextafter(std::fabs(w.bodies.pos[b].x), 1e30f) -
                               0.5f * std::fabs(w.bodies.pos[b].x);
        pos_low.emplace_back(rng.uniform(-half_ulp, half_ulp), rng.uniform(-half_ulp, half_ulp),
                             rng.uniform(-half_ulp, half_ulp), 0.0f);
        if (far != 0.0f) {  // the velocities the pose moves with are pushed ones or the body's
          w.bodies.vel[b] = vec4(rng.uniform(-speed, speed), rng.uniform(-speed, speed),
                                 rng.uniform(-speed, speed), 0.0f);
        }
        vel_push.emplace_back(rng.uniform(-speed, speed), rng.uniform(-speed, speed),
                              rng.uniform(-speed, speed), 0.0f);
        // Some bodies do not turn with the push (L = 0: the no-rotation branch).
        // |L| up to 1e-3 with I^-1 up to 1e5: |w| up to 100 rad/s, as random_bodies' own.
        angmom_push.push_back(rng.chance(0.2f)
                                  ? vec4(0.0f)
                                  : vec4(rng.uniform(-1e-3f, 1e-3f), rng.uniform(-1e-3f, 1e-3f),
                                         rng.uniform(-1e-3f, 1e-3f), 0.0f));
      }
      w.sizes.impulse = 1;
      want = w.bodies;
      want_low = pos_low;
      if (split) {
        w.params.flags |= MOTES_FLAG_BODY_POSE | MOTES_FLAG_IMPULSE_SPLIT;
        motes_ref::bodies_split_pose(want, want_low, vel_push, angmom_push, w.params);
      } else {
        w.params.flags |= MOTES_FLAG_BODY_POSE | MOTES_FLAG_IMPULSE_PUSH;
        motes_ref::bodies_push_pose(want, want_low, vel_push, angmom_push, w.params);
      }
    } else {
      motes_ref::bodies_integrate(want, w.params);
    }
    ASSERT_NO_FATAL_FAILURE(allocate(w.sizes));
    ASSERT_NO_FATAL_FAILURE(
        poison_all_but({Buffer::BodyPos, Buffer::BodyQuat, Buffer::BodyVel, Buffer::BodyAngMom,
                        Buffer::BodyInvInertia, Buffer::BodyForce, Buffer::BodyTorque}));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyPos, w.bodies.pos));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyQuat, w.bodies.quat));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyVel, w.bodies.vel));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyAngMom, w.bodies.angmom));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyInvInertia, w.bodies.inv_inertia));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyForce, w.bodies.force));
    ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyTorque, w.bodies.torque));
    if (push) {
      ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyVelPush, vel_push));
      ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyAngMomPush, angmom_push));
      ASSERT_NO_FATAL_FAILURE(write(Buffer::BodyPosLow, pos_low));
    }
    ASSERT_NO_FATAL_FAILURE(run(motes::Kernel::BodiesIntegrate, w.params));
    ASSERT_NO_FATAL_FAILURE(finish_kernel());
    motes_ref::Bodies got;
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyPos, got.pos));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyQuat, got.quat));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyVel, got.vel));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyAngMom, got.angmom));
    ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyAngVel, got.angvel));
    std::vector<vec4> got_low;
    if (push) {
      ASSERT_NO_FATAL_FAILURE(read(Buffer::BodyPosLow, got_low));
    }

    begin_case("bodies_integrate/" + layout, w.sizes.bodies);
    check_close("BodyPos", got.pos, want.pos, kBodiesIntegrateTolerance, Part::Xyz);
    check_w_identical("BodyPos.w (inverse mass) kept", got.pos, want.pos);
    check_close("BodyQuat", got.quat, want.quat, kBodiesIntegrateTolerance);
    check_close("BodyVel", got.vel, want.vel, kBodiesIntegrateTolerance);
    check_close("BodyAngMom", got.angmom, want.angmom, kBodiesIntegrateTolerance);
    check_close("BodyAngVel", got.angvel, want.angvel, kBodiesIntegrateTolerance);
    if (push) check_close("BodyPosLow", got_low, want_low, kBodiesIntegrateTolerance);
    end_case();
  }
};

TEST_P(BodiesIntegrate, Empty) { run_case("random", random_bodies(51, 0)); }
TEST_P(BodiesIntegrate, One) { run_case("random", random_bodies(52, 1)); }
TEST_P(BodiesIntegrate, Random31) { run_case("random", random_bodies(53, 31)); }
TEST_P(BodiesIntegrate, Random1234) { run_case("random", random_bodies(54, 1234)); }
TEST_P(BodiesIntegrate, Random65536) { run_case("random", random_bodies(55, 65536)); }
TEST_P(BodiesIntegrate, PushPose1234) { run_case("push pose", random_bodies(56, 1234), true); }
TEST_P(BodiesIntegrate, SplitPose1234) {
  run_case("split pose", random_bodies(58, 1234), true, true);
}
TEST_P(BodiesIntegrate, SplitPoseFarFromOrigin) {
  // 50 m out, moving by at most 1 um a step: the centre moves only through BodyPosLow.
  run_case("split pose far from the origin", random_bodies(59, 1234), true, true, 50.0f);
}
TEST_P(BodiesIntegrate, Predict1234) {
  // Position contacts' prediction (MOTES_FLAG_POSITION): gravity alone, the random BodyForce and
  // BodyTorque written but not applied.
  World w = random_bodies(57, 1234);
  w.params.flags |= MOTES_FLAG_POSITION;
  run_case("predict", std::move(w));
}

INSTANTIATE_TEST_SUITE_P(Conformance, BodiesIntegrate, testing::ValuesIn(device_params()),
                         param_name);

}  // namespace
}  // namespace motes_conf
