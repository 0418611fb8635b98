// VALIDATION.md section 4: torque-free rigid bodies.
//
// Symmetric top: a flat 8 x 8 x 2 lattice has I1 = I2 (in-plane axes) != I3 (normal). Euler's
// equations with no torque give, in the body frame, w3 constant and (w1, w2) turning at
//   W = (I3 - I1) w3 / I1
// (I1 w1' = (I2 - I3) w2 w3, I2 w2' = (I3 - I1) w3 w1). The test measures W by a least-squares
// line through the unwrapped angle of (w_a, w_b) in the body frame ((a, b, 3) right-handed, so
// the sign is checked too) over 1.25 periods, and requires the period within 0.5%.
// |L_world| and the rotational energy L.w / 2 must stay constant to 1e-4 relative.
//
// dt = 5e-5 s. The step keeps |L| exactly (L is the integrated state, torque = 0) and turns the
// body by w taken at the half-step orientation (a midpoint Lie step, second order). An earlier
// first-order version (w from the start of the step) added energy every step,
// dE = dt^2/2 (w x L).I^-1(w x L) > 0, about 1.8e-5 relative over the 1.25 periods measured here
// and enough to shift the Dzhanibekov flips by 20%; this test and the flip test below catch that.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "physics/physics_scenes.h"

namespace {

using motes_test::to_quat;
using motes_test::to_vec3;

constexpr double kPi = std::numbers::pi;

/// Inertia of equal spheres about their centroid, computed here from the definition
/// I = sum m (|r|^2 1 - r r^T) + N 2/5 m (d/2)^2 1, independently of motes::mass_properties.
Eigen::Matrix3d lattice_inertia(const motes::ParticleSet& set, double particle_mass) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& p : set.points) c += p.cast<double>();
  c /= static_cast<double>(set.points.size());
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
  for (const auto& p : set.points) {
    const Eigen::Vector3d r = p.cast<double>() - c;
    inertia += particle_mass * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
  }
  const double rp = 0.5 * set.diameter;
  inertia += static_cast<double>(set.points.size()) * 0.4 * particle_mass * rp * rp *
             Eigen::Matrix3d::Identity();
  return inertia;
}

TEST(TorqueFree, SymmetricTopPrecessesAtClosedFormRate) {
  const double diameter = 0.02;
  const double density = 1000.0;
  const double dt = 5.0e-5;
  auto shape = motes_test::lattice(8, 8, 2, diameter);
  ASSERT_TRUE(shape);
  const double particle_mass = density * diameter * diameter * diameter;
  const Eigen::Matrix3d inertia = lattice_inertia(*shape, particle_mass);
  const motes::MassProperties mp = motes::mass_properties(*shape, density);
  ASSERT_NEAR((mp.inertia - inertia).norm(), 0.0, 1e-9 * inertia.norm());
  // The lattice is centred and symmetric: the shape axes are principal.
  const double i1 = inertia(0, 0);
  const double i3 = inertia(2, 2);
  ASSERT_DOUBLE_EQ(inertia(1, 1), i1);
  ASSERT_NEAR(inertia(0, 1), 0.0, 1e-15);

  // Spin mostly about the symmetry axis, with an in-plane part; a tilted start orientation.
  const Eigen::Quaterniond start(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 3).normalized()));
  const Eigen::Vector3d w_shape(1.0, 0.0, 10.0);
  const motes::Material mat = motes_test::material(density, 1.0e4, 10.0, 0.0, -1.0);
  motes::Scene scene = motes_test::scene_with(dt, Eigen::Vector3d::Zero(), mat);
  scene.bodies.push_back(motes_test::body(shape, Eigen::Vector3d(0.3, 1.0, -0.2),
                                          Eigen::Vector3d::Zero(), start * w_shape, start));
  auto created = motes_test::simulate(scene);
  ASSERT_TRUE(created) << created.message();
  motes::Simulation& sim = *created.value();

  // The device's principal moments: two equal ones (I1) and the distinct one (I3), whose index
  // is the body-frame symmetry axis.
  auto inv_inertia = motes_test::read_vec4(sim, motes::Buffer::BodyInvInertia);
  ASSERT_TRUE(inv_inertia) << inv_inertia.message();
  const Eigen::Vector3d moments = to_vec3(inv_inertia.value()[0]).cwiseInverse();
  int axis = 0;
  for (int i = 1; i < 3; ++i) {
    if (std::abs(moments[i] - i3) < std::abs(moments[axis] - i3)) axis = i;
  }
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(moments[i], i == axis ? i3 : i1, 1e-6 * i3) << "principal moment " << i;
  }
  const int a = (axis + 1) % 3;
  const int b = (axis + 2) % 3;

  auto s0 = sim.snapshot();
  ASSERT_TRUE(s0) << s0.message();
  const Eigen::Vector3d l0 = to_vec3(s0->body_angmom[0]);
  const double e0 = 0.5 * l0.dot(to_vec3(s0->body_angvel[0]));
  const Eigen::Vector3d wb0 = to_quat(s0->body_quat[0]).conjugate() * to_vec3(s0->body_angvel[0]);
  // w3 in the body frame (its sign depends on which way the principal axis points).
  const double w3 = wb0[axis];
  ASSERT_NEAR(std::abs(w3), 10.0, 1e-4);
  const double rate = (i3 - i1) * w3 / i1;
  const double period = 2.0 * kPi / std::abs(rate);
  const auto steps = static_cast<std::uint64_t>(std::ceil(1.25 * period / dt));
  const std::uint64_t every = 10;

  std::vector<double> t;
  std::vector<double> angle;
  double worst_l = 0.0;
  double worst_e = 0.0;
  double unwrapped = 0.0;
  double previous = 0.0;
  for (std::uint64_t i = 0; i <= steps; i += every) {
    if (i > 0) {
      ASSERT_TRUE(sim.step(every));
    }
    auto s = sim.snapshot();
    ASSERT_TRUE(s) << s.message();
    const Eigen::Vector3d l = to_vec3(s->body_angmom[0]);
    const Eigen::Vector3d w = to_vec3(s->body_angvel[0]);
    const Eigen::Vector3d wb = to_quat(s->body_quat[0]).conjugate() * w;
    const double phi = std::atan2(wb[b], wb[a]);
    if (!angle.empty()) unwrapped += std::remainder(phi - previous, 2.0 * kPi);
    previous = phi;
    t.push_back(static_cast<double>(i) * static_cast<double>(static_cast<float>(dt)));
    angle.push_back(unwrapped);
    worst_l = std::max(worst_l, std::abs(l.norm() / l0.norm() - 1.0));
    worst_e = std::max(worst_e, std::abs(0.5 * l.dot(w) / e0 - 1.0));
  }
  // Least-squares slope of the unwrapped angle.
  const auto n = static_cast<double>(t.size());
  double st = 0.0, sa = 0.0, stt = 0.0, sta = 0.0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    st += t[i];
    sa += angle[i];
    stt += t[i] * t[i];
    sta += t[i] * angle[i];
  }
  const double slope = (n * sta - st * sa) / (n * stt - st * st);
  const double measured_period = 2.0 * kPi / std::abs(slope);
  std::printf(
      "[symmetric top] dt=%.1e, %llu steps: W=%.6f rad/s (closed form %.6f), period rel error "
      "%+.2e; |L| drift %.1e, energy drift %.1e\n",
      dt, static_cast<unsigned long long>(steps), slope, rate, measured_period / period - 1.0,
      worst_l, worst_e);
  EXPECT_GT(slope * rate, 0.0) << "precession in the wrong direction";
  EXPECT_NEAR(measured_period, period, 0.005 * period);
  EXPECT_LE(worst_l, 1e-4);
  EXPECT_LE(worst_e, 1e-4);
}

}  // namespace

// Asymmetric body (Dzhanibekov effect). A 6 x 4 x 2 lattice has three distinct moments
// I_min < I_mid < I_max. Spun about the middle axis with a small perturbation it flips again and
// again; spun about the smallest or largest axis it stays close to it. The reference is the exact
// solution of Euler's equations I w' = (I w) x w in the body frame (RK4 at h = 1e-5 s, from the
// device's own initial body-frame w and moments; RK4's error there is below 1e-9 relative).
// Pass (VALIDATION.md section 4): |L_world| constant to 1e-3 (it is exact here), at least three
// flips, each flip time within 1% of the exact one, so the flip period is reproduced flip after
// flip; for the stable axes, w stays within 0.1 rad of the axis.
class Dzhanibekov : public ::testing::Test {
 protected:
  struct Spin {
    std::vector<double> t;
    std::vector<Eigen::Vector3d> w_body;
    Eigen::Vector3d moments = Eigen::Vector3d::Zero();  // device body frame
    double l_drift = 0.0;
  };

  static constexpr double kDt = 1.0e-4;

  static void spin(const Eigen::Vector3d& w_shape, double seconds, Spin& out) {
    const double density = 1000.0;
    auto shape = motes_test::lattice(6, 4, 2, 0.02);
    ASSERT_TRUE(shape);
    const Eigen::Quaterniond start(Eigen::AngleAxisd(1.1, Eigen::Vector3d(2, 1, -1).normalized()));
    const motes::Material mat = motes_test::material(density, 1.0e4, 10.0, 0.0, -1.0);
    motes::Scene scene = motes_test::scene_with(kDt, Eigen::Vector3d::Zero(), mat);
    scene.bodies.push_back(motes_test::body(shape, Eigen::Vector3d(-0.4, 0.2, 0.1),
                                            Eigen::Vector3d::Zero(), start * w_shape, start));
    auto created = motes_test::simulate(scene);
    ASSERT_TRUE(created) << created.message();
    motes::Simulation& sim = *created.value();
    auto inv_inertia = motes_test::read_vec4(sim, motes::Buffer::BodyInvInertia);
    ASSERT_TRUE(inv_inertia) << inv_inertia.message();
    out.moments = to_vec3(inv_inertia.value()[0]).cwiseInverse();
    const auto steps = static_cast<std::uint64_t>(std::lround(seconds / kDt));
    const std::uint64_t every = 5;
    Eigen::Vector3d l0 = Eigen::Vector3d::Zero();
    for (std::uint64_t i = 0; i <= steps; i += every) {
      if (i > 0) {
        ASSERT_TRUE(sim.step(every));
      }
      auto s = sim.snapshot();
      ASSERT_TRUE(s) << s.message();
      const Eigen::Vector3d l = to_vec3(s->body_angmom[0]);
      if (i == 0) l0 = l;
      out.l_drift = std::max(out.l_drift, std::abs(l.norm() / l0.norm() - 1.0));
      out.t.push_back(static_cast<double>(i) * static_cast<double>(static_cast<float>(kDt)));
      out.w_body.push_back(to_quat(s->body_quat[0]).conjugate() * to_vec3(s->body_angvel[0]));
    }
  }

  /// Index of the smallest (0), middle (1) or largest (2) moment.
  static int axis_of(const Eigen::Vector3d& moments, int rank) {
    int order[3] = {0, 1, 2};
    std::sort(order, order + 3, [&](int x, int y) { return moments[x] < moments[y]; });
    return order[rank];
  }

  /// Times at which component `axis` changes sign (linear interpolation between samples).
  static std::vector<double> sign_changes(const std::vector<double>& t,
                                          const std::vector<Eigen::Vector3d>& w, int axis) {
    std::vector<double> out;
    for (std::size_t i = 1; i < t.size(); ++i) {
      const double a = w[i - 1][axis];
      const double b = w[i][axis];
      if ((a > 0.0) != (b > 0.0)) out.push_back(t[i - 1] + (t[i] - t[i - 1]) * a / (a - b));
    }
    return out;
  }

  /// Exact body-frame w(t) of Euler's equations by RK4, sampled every `h`.
  static void euler_reference(const Eigen::Vector3d& moments, const Eigen::Vector3d& w0,
                              double seconds, std::vector<double>& t,
                              std::vector<Eigen::Vector3d>& w) {
    const double h = 1.0e-5;
    auto rate = [&](const Eigen::Vector3d& x) -> Eigen::Vector3d {
      return (moments.cwiseProduct(x)).cross(x).cwiseQuotient(moments);
    };
    Eigen::Vector3d x = w0;
    const auto n = static_cast<std::size_t>(std::lround(seconds / h));
    for (std::size_t i = 0; i <= n; ++i) {
      t.push_back(static_cast<double>(i) * h);
      w.push_back(x);
      const Eigen::Vector3d k1 = rate(x);
      const Eigen::Vector3d k2 = rate(x + 0.5 * h * k1);
      const Eigen::Vector3d k3 = rate(x + 0.5 * h * k2);
      const Eigen::Vector3d k4 = rate(x + h * k3);
      x += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
  }
};

TEST_F(Dzhanibekov, MiddleAxisFlipsWithTheExactPeriod) {
  Spin s;
  const double seconds = 3.5;
  // The lattice's shape axes are its principal axes: x smallest, y middle, z largest.
  ASSERT_NO_FATAL_FAILURE(spin(Eigen::Vector3d(0.5, 20.0, 0.5), seconds, s));
  const int mid = axis_of(s.moments, 1);
  std::vector<double> rt;
  std::vector<Eigen::Vector3d> rw;
  euler_reference(s.moments, s.w_body.front(), seconds, rt, rw);
  const std::vector<double> got = sign_changes(s.t, s.w_body, mid);
  const std::vector<double> want = sign_changes(rt, rw, mid);
  std::printf("[dzhanibekov] dt=%.0e: flips at", kDt);
  for (double f : got) std::printf(" %.4f", f);
  std::printf(" s; exact:");
  for (double f : want) std::printf(" %.4f", f);
  std::printf(" s; |L| drift %.1e\n", s.l_drift);
  ASSERT_GE(want.size(), 3u) << "the reference should flip three times in " << seconds << " s";
  ASSERT_GE(got.size(), 3u) << "the body did not flip three times";
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(got[i], want[i], 0.01 * want[i]) << "flip " << i;
  }
  EXPECT_LE(s.l_drift, 1e-3);
}

TEST_F(Dzhanibekov, SmallestAndLargestAxesAreStable) {
  for (int rank : {0, 2}) {
    Spin s;
    Eigen::Vector3d w_shape(0.5, 0.5, 0.5);
    w_shape[rank] = 20.0;  // shape axis x (rank 0) and z (rank 2)
    ASSERT_NO_FATAL_FAILURE(spin(w_shape, 1.0, s));
    const int axis = axis_of(s.moments, rank);
    double worst = 0.0;
    for (const Eigen::Vector3d& w : s.w_body) {
      const double c = std::abs(w[axis]) / w.norm();
      worst = std::max(worst, std::acos(std::min(1.0, c)));
      ASSERT_GT(w[axis] * s.w_body.front()[axis], 0.0)
          << "spin about axis rank " << rank << " flipped";
    }
    std::printf("[dzhanibekov] spin about the %s axis: largest angle from it %.3f rad\n",
                rank == 0 ? "smallest" : "largest", worst);
    EXPECT_LT(worst, 0.1);
  }
}
