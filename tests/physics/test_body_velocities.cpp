// Simulation::set_body_velocities (the Python module's too): a rigid body's new motion reaches its
// particles (v + w x r), its angular momentum is I w, a free sphere takes a velocity but never a
// spin, a static body stays still, and a refused call changes nothing.
#include <gtest/gtest.h>

#include <vector>

#include "physics_scenes.h"

namespace motes_test {
namespace {

TEST(BodyVelocities, RigidBodyParticlesFollowAndFreeSpheresAndStaticBodiesAreChecked) {
  const double d = 0.01;
  motes::Scene scene =
      scene_with(1e-4, Eigen::Vector3d::Zero(), material(1000.0, 1000.0, 10.0, 10.0, -1.0));
  scene.bodies.push_back(body(lattice(3, 2, 4, d), {0.0, 1.0, 0.0}));
  scene.bodies.push_back(body(single_particle(d), {1.0, 1.0, 0.0}));
  motes::BodySpec wall = body(lattice(2, 2, 2, d), {2.0, 1.0, 0.0});
  wall.kind = motes::BodyKind::Static;
  scene.bodies.push_back(wall);
  auto created = simulate(scene);
  ASSERT_TRUE(created) << created.message();
  motes::Simulation& sim = *created.value();
  ASSERT_TRUE(sim.bodies()[1].free_sphere);

  const std::vector<Eigen::Vector3d> v = {{0.1, -0.2, 0.3}, {-0.5, 0.0, 0.25}, {0.0, 0.0, 0.0}};
  const std::vector<Eigen::Vector3d> w = {{1.0, 2.0, -3.0}, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
  ASSERT_TRUE(sim.set_body_velocities(v, w));
  auto s = sim.snapshot();
  ASSERT_TRUE(s) << s.message();
  EXPECT_LT((to_vec3(s->body_vel[0]) - v[0]).norm(), 1e-7);
  EXPECT_LT((to_vec3(s->body_angvel[0]) - w[0]).norm(), 1e-6);
  EXPECT_LT((to_vec3(s->body_vel[1]) - v[1]).norm(), 1e-7);
  // L = R I R^T w: back through the body's own inertia.
  auto inv = read_vec4(sim, motes::Buffer::BodyInvInertia);
  ASSERT_TRUE(inv) << inv.message();
  const Eigen::Matrix3d rot = to_quat(s->body_quat[0]).toRotationMatrix();
  const Eigen::Vector3d moments(1.0 / double{inv.value()[0].x}, 1.0 / double{inv.value()[0].y},
                                1.0 / double{inv.value()[0].z});
  const Eigen::Vector3d l = rot * moments.asDiagonal() * rot.transpose() * w[0];
  EXPECT_LT((to_vec3(s->body_angmom[0]) - l).norm(), 1e-6 * l.norm());
  // Every particle of the box moves as v + w x r; the sphere's particle as v.
  const motes::BodyInfo& box = sim.bodies()[0];
  for (std::uint32_t i = box.first_particle; i < box.first_particle + box.particle_count; ++i) {
    const Eigen::Vector3d r = to_vec3(s->particle_pos[i]) - to_vec3(s->body_pos[0]);
    EXPECT_LT((to_vec3(s->particle_vel[i]) - (v[0] + w[0].cross(r))).norm(), 1e-6) << i;
  }
  EXPECT_LT((to_vec3(s->particle_vel[sim.bodies()[1].first_particle]) - v[1]).norm(), 1e-7);

  // Refused, naming the body, and nothing changes.
  const std::uint64_t before = sim.state_hash().value();
  std::vector<Eigen::Vector3d> bad = v;
  bad[2] = {0.0, 1.0, 0.0};
  motes::Status st = sim.set_body_velocities(bad, w);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message().find("is static"), std::string::npos) << st.message();
  std::vector<Eigen::Vector3d> spin = w;
  spin[1] = {0.0, 5.0, 0.0};
  st = sim.set_body_velocities(v, spin);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message().find("free sphere"), std::string::npos) << st.message();
  st = sim.set_body_velocities({v[0]}, {});
  ASSERT_FALSE(st);
  EXPECT_NE(st.message().find("for 3 bodies"), std::string::npos) << st.message();
  EXPECT_EQ(sim.state_hash().value(), before);

  // The motion goes on from there: one step moves the box by v dt (no gravity, no contact), to
  // float precision at 1 m (an ulp is 1.2e-7 m; v dt is 3.7e-5 m).
  ASSERT_TRUE(sim.step(1));
  auto after = sim.snapshot();
  ASSERT_TRUE(after) << after.message();
  EXPECT_LT((to_vec3(after->body_pos[0]) - to_vec3(s->body_pos[0]) - v[0] * 1e-4).norm(), 2.5e-7);
}

}  // namespace
}  // namespace motes_test
