// VALIDATION.md section 3: free fall and a spinning projectile.
//
// Semi-implicit Euler (v += g dt, then x += v dt) gives exactly
//   x_n = x0 + v0 t + g t^2 / 2 + g t dt / 2,   v_n = v0 + g t,   t = n dt
// (sum over k = 1..n of (v0 + g k dt) dt). With no contact the body force is exactly zero, so
// the device must follow this up to float round-off: 1e-5 relative after 1000 steps, relative to
// the scale |x0| + |v0| t + |g| t^2 / 2 of the trajectory (x itself may pass through zero).
// A spinning body must follow the same centre-of-mass path bitwise (spin does not leak into
// translation: its particles touch each other but never push each other), and with no torque
// its angular momentum L (the integrated state) stays constant.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "physics/physics_scenes.h"

namespace {

using motes_test::as_float;
using motes_test::to_quat;
using motes_test::to_vec3;

struct FallRun {
  std::vector<Eigen::Vector3d> pos;  // body centre after n steps
  std::vector<Eigen::Vector3d> vel;
  std::vector<Eigen::Vector3d> angmom;
  std::vector<Eigen::Quaterniond> quat;
  motes::Snapshot first;
  motes::Snapshot last;
};

constexpr double kFreeFallDt = 1.0e-3;
constexpr int kSteps = 1000;

motes::Scene fall_scene(const Eigen::Vector3d& w) {
  const motes::Material mat = motes_test::material(2500.0, 1.0e4, 50.0, 10.0, 0.5);
  motes::Scene scene = motes_test::scene_with(kFreeFallDt, Eigen::Vector3d(0.3, -9.81, 0.1), mat);
  // A 3 x 4 x 5 lattice: the three principal moments differ, so w changes while L must not.
  auto shape = motes_test::lattice(3, 4, 5, 0.05);
  scene.bodies.push_back(motes_test::body(
      shape, Eigen::Vector3d(1.5, 4.0, -2.0), Eigen::Vector3d(1.0, 3.0, -0.5), w,
      Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 1, 0).normalized()))));
  return scene;
}

void run_fall(const Eigen::Vector3d& w, FallRun& out) {
  auto created = motes_test::simulate(fall_scene(w));
  ASSERT_TRUE(created) << created.message();
  motes::Simulation& sim = *created.value();
  auto s0 = sim.snapshot();
  ASSERT_TRUE(s0) << s0.message();
  out.first = s0.value();
  for (int i = 0; i <= kSteps; ++i) {
    if (i > 0) {
      ASSERT_TRUE(sim.step(1));
    }
    auto s = sim.snapshot();
    ASSERT_TRUE(s) << s.message();
    out.pos.push_back(to_vec3(s->body_pos[0]));
    out.vel.push_back(to_vec3(s->body_vel[0]));
    out.angmom.push_back(to_vec3(s->body_angmom[0]));
    out.quat.push_back(to_quat(s->body_quat[0]));
    if (i == kSteps) out.last = s.value();
  }
  ASSERT_TRUE(sim.check_finite());
}

TEST(FreeFall, MatchesExactDiscreteSolution) {
  FallRun run;
  ASSERT_NO_FATAL_FAILURE(run_fall(Eigen::Vector3d::Zero(), run));
  const Eigen::Vector3d x0 = run.pos[0];
  const Eigen::Vector3d v0 = run.vel[0];
  EXPECT_NEAR((x0 - Eigen::Vector3d(1.5, 4.0, -2.0)).norm(), 0.0, 1e-6)
      << "the centre of mass goes at BodySpec::position";
  EXPECT_NEAR((v0 - Eigen::Vector3d(1.0, 3.0, -0.5)).norm(), 0.0, 1e-6);
  const double dt = as_float(kFreeFallDt);
  const Eigen::Vector3d g(as_float(0.3), as_float(-9.81), as_float(0.1));
  double worst_x = 0.0;
  double worst_v = 0.0;
  for (int n = 0; n <= kSteps; ++n) {
    const double t = n * dt;
    const Eigen::Vector3d x = x0 + v0 * t + g * (0.5 * t * t) + g * (0.5 * t * dt);
    const Eigen::Vector3d v = v0 + g * t;
    const double x_scale = x0.norm() + v0.norm() * t + 0.5 * g.norm() * t * t;
    const double v_scale = v0.norm() + g.norm() * t;
    worst_x = std::max(worst_x, (run.pos[n] - x).norm() / x_scale);
    worst_v = std::max(worst_v, (run.vel[n] - v).norm() / v_scale);
  }
  std::printf("[free fall] 1000 steps of %.0e s: max relative error x %.2e, v %.2e\n", kFreeFallDt,
              worst_x, worst_v);
  EXPECT_LE(worst_x, 1e-5);
  EXPECT_LE(worst_v, 1e-5);
  // The discrete answer differs from the continuous one by g t dt / 2: make sure the test can
  // tell them apart (1.6e-3 relative at t = 1 s here, far above the tolerance).
  const double t_end = kSteps * dt;
  EXPECT_GT(0.5 * g.norm() * t_end * dt / (x0.norm() + v0.norm() * t_end), 1e-4);
}

TEST(FreeFall, SpinDoesNotLeakIntoTranslation) {
  const Eigen::Vector3d w(7.0, -3.0, 11.0);
  FallRun spinning;
  FallRun still;
  ASSERT_NO_FATAL_FAILURE(run_fall(w, spinning));
  ASSERT_NO_FATAL_FAILURE(run_fall(Eigen::Vector3d::Zero(), still));
  // Initial angular momentum L = R I R^T w, with I from the particles (core::mass_properties).
  auto shape = motes_test::lattice(3, 4, 5, 0.05);
  const motes::MassProperties mp = motes::mass_properties(*shape, 2500.0);
  const Eigen::Matrix3d rot =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  const Eigen::Vector3d l_expected = rot * mp.inertia * rot.transpose() * w;
  const Eigen::Vector3d l0 = to_vec3(spinning.first.body_angmom[0]);
  EXPECT_NEAR((l0 - l_expected).norm(), 0.0, 1e-5 * l_expected.norm())
      << "L0 = " << l0.transpose() << ", expected " << l_expected.transpose();
  EXPECT_NEAR((to_vec3(spinning.first.body_angvel[0]) - w).norm(), 0.0, 1e-5 * w.norm());

  double worst_l = 0.0;
  double turned = 0.0;
  for (int n = 0; n <= kSteps; ++n) {
    turned = std::max(turned, spinning.quat[0].angularDistance(spinning.quat[n]));
    // Bitwise: the centre of mass never sees the spin.
    ASSERT_EQ(spinning.pos[n], still.pos[n]) << "step " << n;
    ASSERT_EQ(spinning.vel[n], still.vel[n]) << "step " << n;
    worst_l = std::max(worst_l, (spinning.angmom[n] - l0).norm() / l0.norm());
  }
  std::printf("[spinning fall] |L - L0| / |L0| max %.2e over %d steps\n", worst_l, kSteps);
  EXPECT_LE(worst_l, 1e-6);
  // The body really tumbled: its orientation and its world angular velocity changed (an
  // asymmetric body conserves L, not w).
  EXPECT_GT(turned, 3.0);
  EXPECT_GT((to_vec3(spinning.last.body_angvel[0]) - w).norm(), 0.01 * w.norm());
}

}  // namespace
