// A static body made of particles is a floor: a box dropped on a static particle slab (no
// analytic plane anywhere) comes to rest on it at the contact height, and the slab never moves.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "physics_scenes.h"

namespace {

constexpr double kD = 0.01;  // particle diameter (m)

TEST(StaticBody, BoxRestsOnAStaticParticleSlabThatNeverMoves) {
  // k = 2000 N/m on 1 g particles against an immovable one: w0 = 1414 rad/s, t_c = 2.2 ms.
  const motes::Material mat = motes_test::material(1000.0, 2000.0, 1500.0, 500.0, 0.5);
  motes::Scene scene = motes_test::scene_with(2e-5, {0.0, -9.81, 0.0}, mat, true);
  motes::BodySpec slab = motes_test::body(motes_test::lattice(9, 1, 9, kD), {0.0, 0.0, 0.0});
  slab.name = "slab";
  slab.kind = motes::BodyKind::Static;
  scene.bodies.push_back(slab);
  // 3 x 3 x 3 box, its bottom layer 2 mm above touching the slab.
  const double rest_height = 2.0 * kD;  // slab centres at 0, box layers at d, 2d, 3d
  scene.bodies.push_back(
      motes_test::body(motes_test::lattice(3, 3, 3, kD), {0.0, rest_height + 0.002, 0.0}));

  auto sim = motes_test::simulate(scene);
  ASSERT_TRUE(sim) << sim.message();
  auto before = sim.value()->snapshot();
  ASSERT_TRUE(before) << before.message();

  ASSERT_TRUE(sim.value()->step(25000));  // 0.5 s: falls 2 mm, lands, settles
  auto after = sim.value()->snapshot();
  ASSERT_TRUE(after) << after.message();

  // The slab's particles and pose are bitwise unchanged.
  const motes::BodyInfo& info = sim.value()->bodies()[0];
  for (std::uint32_t i = info.first_particle; i < info.first_particle + info.particle_count; ++i) {
    EXPECT_EQ(std::memcmp(&before->particle_pos[i], &after->particle_pos[i], 16), 0) << i;
  }
  EXPECT_EQ(std::memcmp(&before->body_pos[0], &after->body_pos[0], 16), 0);

  // The box rests at the contact height: weight 0.265 N on 9 contacts of 2000 N/m sinks it
  // about 15 um; it must neither fall through nor float.
  const Eigen::Vector3d com = motes_test::to_vec3(after->body_pos[1]);
  EXPECT_NEAR(com.y(), rest_height, 0.05 * kD);
  EXPECT_LT(com.y(), rest_height);  // compressed, not hovering
  EXPECT_NEAR(com.x(), 0.0, 0.01 * kD);
  EXPECT_NEAR(com.z(), 0.0, 0.01 * kD);
  EXPECT_LT(motes_test::to_vec3(after->body_vel[1]).norm(), 1e-3);
  std::printf("[static body] box centre of mass at y = %.6f m (contact height %.6f m)\n", com.y(),
              rest_height);
}

}  // namespace
