// Every kind of object in one gravity-free collision (issue 11, two-way coupling): a rigid box, a
// one-particle rigid sphere, a soft box, a cloth and a rope, thrown at one point from six sides,
// meet in the one collision grid. Whatever one object takes from another, the other gets back in
// the same step, so the total linear momentum, sum of m v over every object, must stay as it was
// up to single-precision rounding after 0.1 s (the objects meet after about 0.02 s and tangle).
// Run with the force law everywhere, and with impulse contacts between the rigid bodies (the other
// pairs keep the force law). Each object must have changed its velocity, or it did not take part.
//
// The rounding: every pair's impulses are bitwise opposite, but each body adds its particles'
// impulses in float and rounds v += J / m, so every sweep leaves an error of about 6e-8 of the
// impulse it applied, a random walk over the sweeps. Measured (openmp, the rigid box's start
// velocity scaled by 1 + 3e-7 k for k = 0..9, which changes nothing but the rounding): the force
// law drifts 0.9e-7 to 8.0e-7 of the total, the impulse model (16 sweeps a step, 4 of them in
// each of 4 substeps) 3.0e-7 to 1.9e-6 (and 1.7e-7 to 3.1e-6 with one of the 4 sweeps correcting
// instead of 2). Bounds: 1e-6 for the force law, 1e-5 for impulses. A real
// leak shows far above: one contact's impulse applied to one side only (m dv ~ 1e-3 kg m/s against
// a total of 0.021) is 5e-2.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "motes/cloth.h"
#include "physics/physics_scenes.h"

namespace {

using motes_test::to_vec3;

constexpr double kAllKindsD = 0.01;

motes::Scene all_kinds(motes::ContactModel model) {
  motes::Material mat = motes_test::material(1000.0, 2000.0, 500.0, 200.0, 0.5);
  mat.restitution = 0.3;
  motes::Scene scene = motes_test::scene_with(1.0e-4, Eigen::Vector3d::Zero(), mat);
  scene.settings.contact_model = model;
  auto box = motes_test::lattice(3, 3, 3, kAllKindsD);
  // Rigid box from -x, spinning; a one-particle sphere from +z.
  scene.bodies.push_back(motes_test::body(box, Eigen::Vector3d(-0.05, 0.0, 0.0),
                                          Eigen::Vector3d(1.0, 0.0, 0.0),
                                          Eigen::Vector3d(0.0, 4.0, 2.0)));
  scene.bodies.back().name = "rigid box";
  scene.bodies.push_back(motes_test::body(motes_test::single_particle(kAllKindsD),
                                          Eigen::Vector3d(0.0, 0.0, 0.05),
                                          Eigen::Vector3d(0.0, 0.0, -1.0)));
  scene.bodies.back().name = "sphere";
  // Soft box from +x.
  motes::BodySpec soft =
      motes_test::body(box, Eigen::Vector3d(0.05, 0.005, 0.0), Eigen::Vector3d(-1.0, 0.0, 0.0));
  motes::SoftSpec spec;
  spec.frequency = 20.0;
  spec.damping = 20.0;
  spec.mode = motes::SoftMode::Linear;
  spec.beta = 0.3;
  soft.soft = spec;
  soft.name = "soft box";
  scene.bodies.push_back(soft);
  // A 7 x 7 cloth from above, a rope of 9 from below.
  motes::ClothOptions c;
  c.corner = Eigen::Vector3d(-0.03, 0.05, -0.03);
  c.edge_u = Eigen::Vector3d(0.06, 0.0, 0.0);
  c.edge_v = Eigen::Vector3d(0.0, 0.0, 0.06);
  c.nu = 7;
  c.nv = 7;
  c.diameter = kAllKindsD;
  motes::LinkedSpec cloth = motes::make_cloth(c).value();
  cloth.name = "cloth";
  cloth.velocity = Eigen::Vector3d(0.0, -1.0, 0.0);
  scene.linked.push_back(cloth);
  motes::RopeOptions r;
  r.from = Eigen::Vector3d(0.0, -0.05, -0.04);
  r.to = Eigen::Vector3d(0.0, -0.05, 0.04);
  r.count = 9;
  r.diameter = kAllKindsD;
  motes::LinkedSpec rope = motes::make_rope(r).value();
  rope.name = "rope";
  rope.velocity = Eigen::Vector3d(0.0, 1.0, 0.0);
  scene.linked.push_back(rope);
  return scene;
}

/// m v of each object (scene order): a rigid body's mass times its velocity; a soft body, cloth
/// or rope (particles of equal mass) its mass times the mean of its particles' velocities, in
/// double.
std::vector<Eigen::Vector3d> momenta(const motes::Simulation& sim, const motes::Snapshot& s) {
  std::vector<Eigen::Vector3d> out;
  for (std::size_t b = 0; b < sim.bodies().size(); ++b) {
    const motes::BodyInfo& info = sim.bodies()[b];
    if (!info.soft && !info.linked) {
      out.push_back(info.mass * to_vec3(s.body_vel[b]));
      continue;
    }
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::uint32_t k = 0; k < info.particle_count; ++k) {
      sum += to_vec3(s.particle_vel[info.first_particle + k]);
    }
    out.push_back(info.mass / info.particle_count * sum);
  }
  return out;
}

class AllKinds : public ::testing::TestWithParam<motes::ContactModel> {};

TEST_P(AllKinds, GravityFreeCollisionKeepsMomentum) {
  auto created = motes_test::simulate(all_kinds(GetParam()));
  ASSERT_TRUE(created) << created.message();
  motes::Simulation& sim = *created.value();
  const auto before = momenta(sim, sim.snapshot().value());
  ASSERT_TRUE(sim.step(1000));
  const auto after = momenta(sim, sim.snapshot().value());
  ASSERT_EQ(before.size(), after.size());
  Eigen::Vector3d p0 = Eigen::Vector3d::Zero();
  Eigen::Vector3d p1 = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < before.size(); ++k) {
    p0 += before[k];
    p1 += after[k];
    const motes::BodyInfo& info = sim.bodies()[k];
    const double change = (after[k] - before[k]).norm() / before[k].norm();
    std::printf("[all kinds] %s: |m v| changed by %.2f of itself\n", info.name.c_str(), change);
    EXPECT_GT(change, 0.05) << info.name << " took no part in the collision";
  }
  const double drift = (p1 - p0).norm() / p0.norm();
  std::printf(
      "[all kinds] total momentum (%.6g, %.6g, %.6g) -> (%.6g, %.6g, %.6g): %.2e relative\n",
      p0.x(), p0.y(), p0.z(), p1.x(), p1.y(), p1.z(), drift);
  EXPECT_LT(drift, GetParam() == motes::ContactModel::Impulses ? 1e-5 : 1e-6);
}

INSTANTIATE_TEST_SUITE_P(ContactModels, AllKinds,
                         ::testing::Values(motes::ContactModel::Forces,
                                           motes::ContactModel::Impulses),
                         [](const ::testing::TestParamInfo<motes::ContactModel>& model) {
                           return std::string(
                               model.param == motes::ContactModel::Forces ? "Forces" : "Impulses");
                         });

}  // namespace
