// VALIDATION.md section 1: the linear spring-dashpot normal contact, head-on.
//
// Two free spheres (bodies of one particle), or one sphere and a static plane, meet with no
// gravity. Model: F = k d - gamma_n m* d' (d = overlap, m* = m1 m2 / (m1 + m2), m for a wall),
// so c = gamma_n m*, w0 = sqrt(k / m*), zeta = gamma_n / (2 w0), wd = w0 sqrt(1 - zeta^2).
//
// Unclamped closed form: e = exp(-zeta pi / sqrt(1 - zeta^2)), t_c = pi / wd; gamma_n comes from
// the inverse formula zeta = -ln e / sqrt(pi^2 + ln^2 e).
//
// Clamped (settings.clamp_attraction): with d(t) = v0/wd e^(-zeta w0 t) sin(wd t) the force
// k d + c d' vanishes where tan(wd t) = -2 zeta sqrt(1 - zeta^2) / (1 - 2 zeta^2), i.e. at
// wd t* = pi - 2 asin(zeta); the rate there is exactly -v0 e^(-zeta w0 t*), and with no force
// left the spheres separate at that speed: e = exp(-zeta w0 t*). The overlap is still
// d(t*) = v0/wd e 2 zeta sqrt(1 - zeta^2) and closes at constant speed, so the overlap lasts
// t* + 2 zeta sqrt(1 - zeta^2) / wd.
//
// Each case checks the device (a) against the exact discrete solution of the same semi-implicit
// Euler recurrence computed here in double (float round-off only: 1e-4 relative), (b) against the
// continuous closed form: restitution and overlap time within 1% at dt = t_c / 100 (the issue's
// criterion); for the clamped variant also the time at which the force vanishes, within one
// step dt (the force is sampled once per step; at e = 0.2 the discrete force vanishes 0.7 dt
// early, 1.0% of t*), (c) momentum to 1e-6 relative (pair), tangential velocity kept (wall).
//
// Set-up choice that matters: the force jumps at the first overlapping step (by the dashpot term
// c v0), so the O(dt) error of the restitution depends on where between two steps the contact
// begins. The gap is chosen so that the first overlapping state has overlap v_approach dt / 2
// (contact begins mid-step), which centres that error. docs/validation.md lists the spread over
// all entry phases.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

#include "physics/physics_scenes.h"

namespace {

using motes_test::as_float;
using motes_test::to_vec3;

constexpr double kPi = std::numbers::pi;

/// A contact history: overlap and relative normal velocity of state n (after n steps), and the
/// repulsive normal force computed from state n (applied during step n + 1).
struct Trace {
  double dt = 0.0;
  std::vector<double> overlap;
  std::vector<double> normal_velocity;  // d(separation)/dt: < 0 approaching
  std::vector<double> force;
};

struct Measured {
  bool complete = false;  // contact began and ended inside the trace
  double restitution = 0.0;
  double overlap_time = 0.0;  // time with overlap > 0 (interpolated crossings)
  double force_time = 0.0;    // from contact start to the force's zero (clamped only)
};

/// Same measurement for the device and the reference: crossings of the overlap through zero
/// interpolated linearly between states (free flight is linear, so entry is exact).
Measured measure(const Trace& tr, bool clamped) {
  Measured m;
  const std::size_t n = tr.overlap.size();
  std::size_t in = 0;
  while (in < n && tr.overlap[in] <= 0.0) ++in;
  if (in == 0 || in >= n) return m;
  std::size_t out = in;
  while (out < n && tr.overlap[out] > 0.0) ++out;
  if (out >= n) return m;
  const double t_in = tr.dt * (static_cast<double>(in - 1) +
                               -tr.overlap[in - 1] / (tr.overlap[in] - tr.overlap[in - 1]));
  const double t_out = tr.dt * (static_cast<double>(out - 1) +
                                tr.overlap[out - 1] / (tr.overlap[out - 1] - tr.overlap[out]));
  m.overlap_time = t_out - t_in;
  m.restitution = -tr.normal_velocity.back() / tr.normal_velocity.front();
  if (clamped) {
    // Last state with a positive force; extrapolate the (smooth) force linearly to zero.
    std::size_t last = in;
    while (last + 1 < out && tr.force[last + 1] > 0.0) ++last;
    if (last == in) return m;
    const double f1 = tr.force[last];
    const double f0 = tr.force[last - 1];
    m.force_time = tr.dt * (static_cast<double>(last) + f1 / (f0 - f1)) - t_in;
  }
  m.complete = true;
  return m;
}

/// The exact discrete solution: semi-implicit Euler on the separation s and its rate w, with
/// the force evaluated from the state at the start of the step (as the device's step does).
Trace discrete_reference(double s0, double w0, double contact_distance, double k, double gamma,
                         double meff, bool clamped, double dt, std::size_t steps) {
  Trace tr;
  tr.dt = dt;
  double s = s0;
  double w = w0;
  for (std::size_t i = 0; i <= steps; ++i) {
    const double ov = contact_distance - s;
    double f = ov > 0.0 ? k * ov - gamma * meff * w : 0.0;
    if (clamped && f < 0.0) f = 0.0;
    tr.overlap.push_back(ov);
    tr.normal_velocity.push_back(w);
    tr.force.push_back(f);
    w += f / meff * dt;
    s += w * dt;
  }
  return tr;
}

struct Expected {
  double restitution;
  double overlap_time;
  double force_time;
};

Expected closed_form(double zeta, double w0, bool clamped) {
  const double root = std::sqrt(1.0 - zeta * zeta);
  const double wd = w0 * root;
  if (!clamped) {
    return {std::exp(-zeta * kPi / root), kPi / wd, kPi / wd};
  }
  const double t_star = (kPi - 2.0 * std::asin(zeta)) / wd;
  return {std::exp(-zeta * w0 * t_star), t_star + 2.0 * zeta * root / wd, t_star};
}

// (target restitution, clamped, sphere on a wall instead of two spheres)
using Case = std::tuple<double, bool, bool>;

class HeadOnContact : public ::testing::TestWithParam<Case> {};

TEST_P(HeadOnContact, MatchesDiscreteAndClosedForm) {
  const auto [e_target, clamped, wall] = GetParam();
  const double diameter = 0.01;
  const double radius = 0.5 * diameter;
  const double density = 1000.0;
  const double mass = density * diameter * diameter * diameter;  // lattice-cell mass
  const double meff_design = wall ? mass : 0.5 * mass;
  // Stiffness so that the largest overlap, about v/w0, is 2% of the diameter.
  const double v_approach = 0.2;
  const double w0_design = v_approach / (0.02 * diameter);
  const double k = meff_design * w0_design * w0_design;
  const double ln_e = std::log(e_target);
  const double zeta_design = -ln_e / std::sqrt(kPi * kPi + ln_e * ln_e);
  const double gamma = 2.0 * zeta_design * w0_design;
  const double tc_design = kPi / (w0_design * std::sqrt(1.0 - zeta_design * zeta_design));
  const double dt = tc_design / 100.0;

  const motes::Material mat = motes_test::material(density, k, gamma, 0.0, -1.0);
  motes::Scene scene = motes_test::scene_with(dt, Eigen::Vector3d::Zero(), mat, clamped);
  auto sphere = motes_test::single_particle(diameter);
  // Off-axis line of centres and a common drift across it: a generic 3-D configuration.
  const Eigen::Vector3d n = Eigen::Vector3d(1.0, 2.0, 2.0) / 3.0;
  const Eigen::Vector3d drift = Eigen::Vector3d(2.0, -1.0, 0.0).normalized() * 0.05;
  // Gap such that the first overlapping state has overlap v_approach dt / 2 (mid-step entry).
  const double gap = 2.5 * v_approach * dt;
  const double contact_distance = wall ? radius : diameter;
  if (wall) {
    const Eigen::Vector3d p0(0.001, -0.002, 0.003);
    scene.planes.push_back(motes_test::plane(n, p0));
    scene.bodies.push_back(
        motes_test::body(sphere, p0 + n * (radius + gap), -v_approach * n + drift));
  } else {
    scene.bodies.push_back(
        motes_test::body(sphere, -n * (radius + 0.5 * gap), 0.5 * v_approach * n + drift));
    scene.bodies.push_back(
        motes_test::body(sphere, n * (radius + 0.5 * gap), -0.5 * v_approach * n + drift));
  }

  auto created = motes_test::simulate(scene);
  ASSERT_TRUE(created) << created.message();
  motes::Simulation& sim = *created.value();
  ASSERT_EQ(sim.particle_count(), wall ? 1u : 2u);

  // Device-side values: masses from the stored inverse masses, parameters as floats.
  auto snap0 = sim.snapshot();
  ASSERT_TRUE(snap0) << snap0.message();
  const double inv_m0 = static_cast<double>(snap0->particle_vel[0].w);
  ASSERT_NEAR(1.0 / inv_m0, mass, 1e-6 * mass) << "particle mass must be density * d^3";
  const double meff =
      wall ? 1.0 / inv_m0 : 1.0 / (inv_m0 + static_cast<double>(snap0->particle_vel[1].w));
  const double k_f = as_float(k);
  const double gamma_f = as_float(gamma);
  const double dt_f = as_float(dt);
  const double w0 = std::sqrt(k_f / meff);
  const double zeta = gamma_f / (2.0 * w0);
  const Expected expect = closed_form(zeta, w0, clamped);

  // wall is copied into the lambdas: clang 14 cannot capture a structured binding by reference.
  auto separation = [&, wall = wall](const motes::Snapshot& s) {
    if (wall) return (to_vec3(s.particle_pos[0]) - scene.planes[0].point).dot(n);
    return (to_vec3(s.particle_pos[1]) - to_vec3(s.particle_pos[0])).norm();
  };
  auto separation_rate = [&, wall = wall](const motes::Snapshot& s) {
    if (wall) return to_vec3(s.body_vel[0]).dot(n);
    return (to_vec3(s.body_vel[1]) - to_vec3(s.body_vel[0])).dot(n);
  };
  auto momentum = [&](const motes::Snapshot& s) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (std::size_t b = 0; b < s.body_vel.size(); ++b) {
      p += to_vec3(s.body_vel[b]) / static_cast<double>(s.body_pos[b].w);
    }
    return p;
  };

  Trace dev;
  dev.dt = dt_f;
  dev.overlap.push_back(contact_distance - separation(*snap0));
  dev.normal_velocity.push_back(separation_rate(*snap0));
  const Eigen::Vector3d p0 = momentum(*snap0);
  double p_scale = 0.0;
  for (std::size_t b = 0; b < snap0->body_vel.size(); ++b) {
    p_scale += to_vec3(snap0->body_vel[b]).norm() / static_cast<double>(snap0->body_pos[b].w);
  }
  double worst_momentum = 0.0;
  const std::size_t max_steps = 400;
  std::size_t steps_after_exit = 0;
  for (std::size_t i = 0; i < max_steps && steps_after_exit < 5; ++i) {
    ASSERT_TRUE(sim.step(1));
    auto force = motes_test::read_vec4(sim, motes::Buffer::ParticleForce);
    ASSERT_TRUE(force) << force.message();
    // Repulsive magnitude on particle 0: it is pushed along -n (pair) or +n (wall).
    const double f = to_vec3(force.value()[0]).dot(n) * (wall ? 1.0 : -1.0);
    dev.force.push_back(f);
    auto s = sim.snapshot();
    ASSERT_TRUE(s) << s.message();
    dev.overlap.push_back(contact_distance - separation(*s));
    dev.normal_velocity.push_back(separation_rate(*s));
    worst_momentum = std::max(worst_momentum, (momentum(*s) - p0).norm() / p_scale);
    if (dev.overlap.size() > 3 && dev.overlap.back() <= 0.0 &&
        dev.overlap[dev.overlap.size() - 2] > 0.0) {
      steps_after_exit = 1;
    } else if (steps_after_exit > 0) {
      ++steps_after_exit;
    }
  }
  dev.force.push_back(0.0);  // force of the last state (not applied)
  const Measured got = measure(dev, clamped);
  ASSERT_TRUE(got.complete) << "contact did not begin and end within " << max_steps << " steps";

  const Trace ref = discrete_reference(contact_distance - dev.overlap.front(),
                                       dev.normal_velocity.front(), contact_distance, k_f, gamma_f,
                                       meff, clamped, dt_f, dev.overlap.size() - 1);
  const Measured want = measure(ref, clamped);
  ASSERT_TRUE(want.complete);

  char momentum_text[32] = "n/a (wall)";
  if (!wall) std::snprintf(momentum_text, sizeof momentum_text, "%.1e", worst_momentum);
  std::printf(
      "[contact] %s %s e_target=%.2f: e=%.6f (discrete %.6f, closed %.6f, rel %+.2e) "
      "t_overlap=%.6e (discrete %.6e, closed %.6e, rel %+.2e) t_force=%.6e (discrete %.6e, "
      "closed %.6e) "
      "momentum drift=%s\n",
      wall ? "wall" : "pair", clamped ? "clamped" : "unclamped", e_target, got.restitution,
      want.restitution, expect.restitution, got.restitution / expect.restitution - 1.0,
      got.overlap_time, want.overlap_time, expect.overlap_time,
      got.overlap_time / expect.overlap_time - 1.0, got.force_time, want.force_time,
      expect.force_time, momentum_text);

  // (a) the exact discrete solution, up to float round-off of positions and forces.
  EXPECT_NEAR(got.restitution, want.restitution, 1e-4 * want.restitution);
  EXPECT_NEAR(got.overlap_time, want.overlap_time, 1e-4 * want.overlap_time);
  if (clamped) {
    EXPECT_NEAR(got.force_time, want.force_time, 1e-4 * want.force_time);
  }
  // (b) the continuous closed form, 1% at dt = t_c / 100.
  EXPECT_NEAR(got.restitution, expect.restitution, 0.01 * expect.restitution);
  EXPECT_NEAR(got.overlap_time, expect.overlap_time, 0.01 * expect.overlap_time);
  if (clamped) {
    EXPECT_NEAR(got.force_time, expect.force_time, dt_f);
  }
  // (c) linear momentum (for the wall the plane takes momentum: only the tangential part).
  if (!wall) {
    EXPECT_LE(worst_momentum, 1e-6);
  } else {
    auto s = sim.snapshot();
    ASSERT_TRUE(s);
    const Eigen::Vector3d v = to_vec3(s->body_vel[0]);
    EXPECT_NEAR((v - v.dot(n) * n - drift).norm(), 0.0, 1e-6 * drift.norm());
  }
}

std::string case_name(const ::testing::TestParamInfo<Case>& info) {
  const auto [e, clamped, wall] = info.param;
  return std::string(wall ? "Wall" : "Pair") + (clamped ? "Clamped" : "Unclamped") + "E" +
         std::to_string(static_cast<int>(std::lround(e * 100.0)));
}

INSTANTIATE_TEST_SUITE_P(Restitution, HeadOnContact,
                         ::testing::Combine(::testing::Values(0.2, 0.5, 0.9), ::testing::Bool(),
                                            ::testing::Bool()),
                         case_name);

}  // namespace
