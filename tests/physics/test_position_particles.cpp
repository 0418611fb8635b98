// Soft bodies, cloth and ropes with position contacts ("contact_model": "position";
// shared/particle_shift.h), at frame-sized steps (dt = 1/60 s), on the OpenMP device, against
// answers that do not come from motes:
// - a 25 x 25 cloth draped over a static sphere of particles never enters it: no cloth particle's
//   centre comes within the sphere's radius (its surface particles reach radius + d/2), and it
//   comes to rest on it (the highest cloth particle slower than 1 cm/s at the end);
// - a cloth dropped flat on the floor never goes through it (every centre at least 0.9 of its
//   radius above) and ends at rest;
// - a cloth falling onto a rope held at its ends (no gravity but the cloth's speed): the linear
//   momentum of everything that can move is kept; constraint averaging (a particle moves by the
//   mean of its contacts' shifts) is not exact, so the bound is what it measured with a margin.
// - a soft cube dropped on the floor (tilted, rigid goal at 30 Hz, damping 40 1/s) comes to rest
//   above it: no centre below 0.9 of its radius, every particle slower than 1 cm/s after 4 s (it
//   rocks on its face after landing, the rocking halving every 0.6 s: 8 cm/s at 1.2 s, 7 mm/s at
//   3 s);
// - two soft cubes thrown at each other without gravity, one spinning: linear momentum kept to
//   1e-6 relative (mass splitting in the shifts, the shape pull's own momentum corrections);
// - seeded random drops of a die and a soft cube onto a held cloth with a rope across it, a floor
//   below: the mechanical energy never above its start by 1%, nothing past the guard's travel,
//   neither body's centre through the cloth while over it (6 seeds; bodies that bounce off the
//   taut cloth and leave over its edges land on the floor);
// - a chain of 20 links hanging between two pins comes to the exact discrete catenary's sag within
//   1e-2 relative at the default 8 substeps of 8 link sweeps, 1e-3 at 40 substeps (issue 27);
// - a die dropped on a cloth held at its corners comes to rest on it (issue 27); a cloth thrown at
//   a spinning box without gravity: linear momentum kept to 1e-6 relative (the box takes the
//   reaction of each particle's shift in the same sweep).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <tuple>
#include <vector>

#include "motes/cloth.h"
#include "physics/physics_scenes.h"

namespace {

using motes_test::to_vec3;

constexpr double kFrame = 1.0 / 60.0;
constexpr double kSpacing = 0.01;

motes::Scene particle_scene(const Eigen::Vector3d& gravity, int substeps) {
  motes::Material mat = motes_test::material(1000.0, 0.0, 0.0, 0.0, 0.5);
  motes::Scene scene = motes_test::scene_with(kFrame, gravity, mat);
  scene.settings.contact_model = motes::ContactModel::Positions;
  scene.settings.substeps = substeps;
  scene.settings.constraint_iterations = 2;
  scene.settings.link_damping = 1.0;
  return scene;
}

motes::LinkedSpec flat_cloth(int side, const Eigen::Vector3d& corner) {
  motes::ClothOptions o;
  o.corner = corner;
  o.edge_u = Eigen::Vector3d(kSpacing * (side - 1), 0.0, 0.0);
  o.edge_v = Eigen::Vector3d(0.0, 0.0, kSpacing * (side - 1));
  o.nu = side;
  o.nv = side;
  o.diameter = kSpacing;
  o.bend = true;
  o.bend_stiffness = 0.1;
  motes::LinkedSpec c = motes::make_cloth(o).value();
  c.name = "cloth";
  return c;
}

/// Steps `frames` frames; the lowest particle centre seen and the fastest particle's speed in
/// the last frame.
struct Settled {
  double lowest = 1.0;
  double fastest = 0.0;
};
Settled settle(motes::Simulation& sim, int frames) {
  Settled r;
  for (int frame = 0; frame < frames; ++frame) {
    EXPECT_TRUE(sim.step(1));
    const auto s = sim.snapshot();
    if (!s) {
      ADD_FAILURE() << s.message();
      return r;
    }
    r.fastest = 0.0;
    for (std::size_t i = 0; i < s->particle_pos.size(); ++i) {
      r.lowest = std::min(r.lowest, static_cast<double>(s->particle_pos[i].y));
      r.fastest = std::max(r.fastest, to_vec3(s->particle_vel[i]).norm());
    }
  }
  return r;
}

TEST(PositionCloth, DrapedOverASphereStaysOutsideAndComesToRest) {
  constexpr double kRadius = 0.05;
  motes::Scene scene = particle_scene(Eigen::Vector3d(0.0, -9.81, 0.0), 20);
  auto ball =
      std::make_shared<motes::ParticleSet>(motes::sphere_particles(kRadius, kSpacing).value());
  motes::BodySpec sphere = motes_test::body(ball, Eigen::Vector3d::Zero());
  sphere.kind = motes::BodyKind::Static;
  scene.bodies.push_back(sphere);
  scene.linked.push_back(flat_cloth(25, Eigen::Vector3d(-0.12, 0.08, -0.12)));
  auto created = motes_test::simulate(scene);
  ASSERT_TRUE(created) << created.message();
  motes::Simulation& sim = *created.value();
  const std::uint32_t first = sim.bodies()[1].first_particle;
  double closest = 1.0;
  double top_speed = 0.0;
  for (int frame = 0; frame < 120; ++frame) {  // 2 s
    ASSERT_TRUE(sim.step(1));
    const auto s = sim.snapshot();
    ASSERT_TRUE(s);
    std::size_t top = first;
    for (std::size_t i = first; i < s->particle_pos.size(); ++i) {
      closest = std::min(closest, to_vec3(s->particle_pos[i]).norm());
      if (s->particle_pos[i].y > s->particle_pos[top].y) top = i;
    }
    top_speed = to_vec3(s->particle_vel[top]).norm();
  }
  std::printf(
      "[position cloth] over a sphere of radius %.3f m: closest cloth particle centre %.4f m "
      "from its centre; the highest cloth particle ends at %.2g m/s\n",
      kRadius, closest, top_speed);
  EXPECT_GT(closest, kRadius);
  EXPECT_LT(top_speed, 0.01);
}

TEST(PositionCloth, DroppedOnTheFloorStaysAboveIt) {
  motes::Scene scene = particle_scene(Eigen::Vector3d(0.0, -9.81, 0.0), 20);
  scene.planes.push_back(
      motes::PlaneSpec{"floor", Eigen::Vector3d(0.0, 1.0, 0.0), Eigen::Vector3d::Zero(), 0});
  scene.linked.push_back(flat_cloth(15, Eigen::Vector3d(-0.07, 0.3, -0.07)));
  auto created = motes_test::simulate(scene);
  ASSERT_TRUE(created) << created.message();
  motes::Simulation& sim = *created.value();
  const auto [lowest, fastest] = settle(sim, 90);  // 1.5 s
  std::printf(
      "[position cloth] dropped on the floor from 0.3 m: lowest centre %.5f m (radius %.3f); "
      "the fastest particle ends at %.2g m/s\n",
      lowest, 0.5 * kSpacing, fastest);
  EXPECT_GT(lowest, 0.9 * 0.5 * kSpacing);
  EXPECT_LT(fastest, 0.01);
}

TEST(PositionCloth, CollisionWithARopeWithoutGravityKeepsMomentum) {
  motes::Scene scene = particle_scene(Eigen::Vector3d::Zero(), 10);
  scene.settings.link_damping = 0.0;
  motes::LinkedSpec cloth = flat_cloth(11, Eigen::Vector3d(-0.05, 0.05, -0.05));
  cloth.velocity = Eigen::Vector3d(0.1, -1.0, 0.2);
  scene.linked.push_back(cloth);
  motes::LinkedSpec rope;
  rope.name = "rope";
  rope.kind = motes::LinkedKind::Rope;
  rope.diameter = kSpacing;
  for (int k = 0; k <= 14; ++k) {
    rope.points.push_back(Eigen::Vector3d(-0.07 + kSpacing * k, 0.0, 0.003));
    rope.lattice.push_back({static_cast<std::uint32_t>(k), 0u});
    if (k > 0) {
      rope.links.push_back({static_cast<std::uint32_t>(k - 1), static_cast<std::uint32_t>(k), 1.0});
    }
  }
  scene.linked.push_back(rope);
  auto created = motes_test::simulate(scene);
  ASSERT_TRUE(created) << created.message();
  motes::Simulation& sim = *created.value();
  const auto momentum = [](const motes::Snapshot& s) -> Eigen::Vector3d {
    return motes_test::linear_momentum(s) + motes_test::particle_momentum(s, 0);
  };
  auto before = sim.snapshot();
  ASSERT_TRUE(before);
  const Eigen::Vector3d p0 = momentum(*before);
  ASSERT_TRUE(sim.step(9));  // 0.15 s: the cloth meets the rope and carries it along
  auto after = sim.snapshot();
  ASSERT_TRUE(after);
  const Eigen::Vector3d p1 = momentum(*after);
  const std::uint32_t rope_first = sim.bodies()[1].first_particle;
  double rope_speed = 0.0;
  for (std::size_t i = rope_first; i < after->particle_vel.size(); ++i) {
    rope_speed = std::max(rope_speed, to_vec3(after->particle_vel[i]).norm());
  }
  const double drift = (p1 - p0).norm() / p0.norm();
  std::printf(
      "[position cloth] free collision with a rope: momentum (%.6g, %.6g, %.6g) -> (%.6g, %.6g, "
      "%.6g), %.2e relative; the rope's fastest particle at %.3f m/s after\n",
      p0.x(), p0.y(), p0.z(), p1.x(), p1.y(), p1.z(), drift, rope_speed);
  EXPECT_GT(rope_speed, 0.1) << "the cloth must have hit the rope";
  EXPECT_LT(drift, 1e-6);
}

motes::BodySpec position_soft_cube(const Eigen::Vector3d& at, const Eigen::Vector3d& velocity,
                                   const Eigen::Vector3d& spin) {
  motes::BodySpec b = motes_test::body(motes_test::lattice(5, 5, 5, kSpacing), at, velocity, spin);
  b.soft = motes::SoftSpec{};
  b.soft->frequency = 30.0;
  b.soft->damping = 40.0;
  return b;
}

TEST(PositionSoft, CubeDroppedOnTheFloorComesToRestAboveIt) {
  motes::Scene scene = particle_scene(Eigen::Vector3d(0.0, -9.81, 0.0), 20);
  scene.planes.push_back(
      motes::PlaneSpec{"floor", Eigen::Vector3d(0.0, 1.0, 0.0), Eigen::Vector3d::Zero(), 0});
  motes::BodySpec cube = position_soft_cube(Eigen::Vector3d(0.0, 0.1, 0.0), Eigen::Vector3d::Zero(),
                                            Eigen::Vector3d::Zero());
  cube.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.6, Eigen::Vector3d(1.0, 0.0, 0.5).normalized()));
  scene.bodies.push_back(cube);
  auto created = motes_test::simulate(scene);
  ASSERT_TRUE(created) << created.message();
  motes::Simulation& sim = *created.value();
  const auto [lowest, fastest] = settle(sim, 240);  // 4 s
  std::printf(
      "[position soft] cube dropped on the floor: lowest centre %.5f m (radius %.3f); the "
      "fastest particle ends at %.2g m/s\n",
      lowest, 0.5 * kSpacing, fastest);
  EXPECT_GT(lowest, 0.9 * 0.5 * kSpacing);
  EXPECT_LT(fastest, 0.01);
}

TEST(PositionSoft, CollisionWithoutGravityKeepsMomentum) {
  motes::Scene scene = particle_scene(Eigen::Vector3d::Zero(), 10);
  scene.bodies.push_back(position_soft_cube(Eigen::Vector3d(-0.04, 0.0, 0.0),
                                            Eigen::Vector3d(1.0, 0.1, 0.0),
                                            Eigen::Vector3d(0.0, 0.0, 20.0)));
  scene.bodies.push_back(position_soft_cube(Eigen::Vector3d(0.04, 0.01, 0.005),
                                            Eigen::Vector3d(-0.5, 0.0, 0.2),
                                            Eigen::Vector3d::Zero()));
  auto created = motes_test::simulate(scene);
  ASSERT_TRUE(created) << created.message();
  motes::Simulation& sim = *created.value();
  const auto momentum = [](const motes::Snapshot& s) -> Eigen::Vector3d {
    return motes_test::linear_momentum(s) + motes_test::particle_momentum(s, 0);
  };
  auto before = sim.snapshot();
  ASSERT_TRUE(before);
  const Eigen::Vector3d p0 = momentum(*before);
  ASSERT_TRUE(sim.step(6));  // 0.1 s: they meet and part
  auto after = sim.snapshot();
  ASSERT_TRUE(after);
  const Eigen::Vector3d p1 = momentum(*after);
  const double right_speed = to_vec3(after->body_vel[1]).x();
  const double drift = (p1 - p0).norm() / p0.norm();
  std::printf(
      "[position soft] free collision: momentum (%.6g, %.6g, %.6g) -> (%.6g, %.6g, %.6g), %.2e "
      "relative; the right cube's x velocity %.3f m/s after (-0.5 before)\n",
      p0.x(), p0.y(), p0.z(), p1.x(), p1.y(), p1.z(), drift, right_speed);
  EXPECT_GT(right_speed, 0.0) << "the cubes must have met";
  EXPECT_LT(drift, 1e-6);
}

/// The sag of the V chain hanging at rest (6 s) with position contacts at `substeps` a frame.
double position_chain_sag(int substeps, int iterations, double* stretch) {
  constexpr int kLinks = 20;
  constexpr double kLink = 0.02, kSpan = 0.3, kY = 1.0;
  motes::Scene scene = particle_scene(Eigen::Vector3d(0.0, -9.81, 0.0), substeps);
  scene.settings.constraint_iterations = iterations;
  scene.settings.link_damping = 4.0;
  scene.linked.push_back(motes_test::v_chain(kLinks, kLink, kSpan, kY, 0.5 * kLink));
  auto created = motes_test::simulate(scene);
  if (!created || !created.value()->step(360)) return -1.0;
  const auto s = created.value()->snapshot();
  if (!s) return -1.0;
  double lowest = kY;
  *stretch = 0.0;
  for (std::size_t k = 0; k < s->particle_pos.size(); ++k) {
    lowest = std::min(lowest, static_cast<double>(s->particle_pos[k].y));
    if (k > 0) {
      const double len = (to_vec3(s->particle_pos[k]) - to_vec3(s->particle_pos[k - 1])).norm();
      *stretch = std::max(*stretch, std::abs(len - kLink) / kLink);
    }
  }
  return kY - lowest;
}

TEST(PositionRope, HangingChainIsTheDiscreteCatenary) {
  const double want = motes_test::catenary_sag(20, 0.02, 0.3);
  for (const auto& [substeps, iterations, bound] :
       {std::tuple{motes::kPositionSubsteps, 8, 1e-2}, std::tuple{40, 8, 1e-3}}) {
    double stretch = 0.0;
    const double got = position_chain_sag(substeps, iterations, &stretch);
    std::printf(
        "[position rope] 20 links, %d substeps of %d sweeps: sag %.6f m, exact %.6f m (%.2e "
        "rel); largest stretch %.2e\n",
        substeps, iterations, got, want, std::abs(got - want) / want, stretch);
    EXPECT_NEAR(got, want, bound * want) << substeps << " substeps";
  }
}

TEST(PositionCloth, DieDroppedOnAClothHeldAtItsCornersComesToRestOnIt) {
  // A 4 cm die of 64 particles (77 g) dropped from 10 cm onto a 15 x 15 cloth (0.5 g a
  // particle) pinned at its four corners: it sinks into the cloth, stops, and lies on it.
  motes::Scene scene = particle_scene(Eigen::Vector3d(0.0, -9.81, 0.0), 20);
  scene.settings.constraint_iterations = 8;
  motes::LinkedSpec cloth = flat_cloth(15, Eigen::Vector3d(-0.07, 0.2, -0.07));
  cloth.pinned = {0u, 14u, 210u, 224u};
  scene.linked.push_back(cloth);
  motes::BodySpec die =
      motes_test::body(motes_test::lattice(4, 4, 4, kSpacing), Eigen::Vector3d(0.0, 0.3, 0.0));
  die.name = "die";
  scene.bodies.push_back(die);
  auto created = motes_test::simulate(scene);
  ASSERT_TRUE(created) << created.message();
  motes::Simulation& sim = *created.value();
  const std::uint32_t first = sim.bodies()[1].first_particle;
  double die_speed = 1.0, die_low = 1.0, cloth_low = 1.0, under = 1.0;
  for (int frame = 0; frame < 180; ++frame) {  // 3 s
    ASSERT_TRUE(sim.step(1));
    const auto s = sim.snapshot();
    ASSERT_TRUE(s);
    die_speed = to_vec3(s->body_vel[0]).norm();
    die_low = 1.0;
    for (std::uint32_t i = 0; i < first; ++i) {
      die_low = std::min(die_low, static_cast<double>(s->particle_pos[i].y));
    }
    cloth_low = 1.0;
    for (std::size_t i = first; i < s->particle_pos.size(); ++i) {
      cloth_low = std::min(cloth_low, static_cast<double>(s->particle_pos[i].y));
    }
    under = std::min(under, die_low - cloth_low);
  }
  std::printf(
      "[position cloth] die on a cloth held at its corners: ends at %.2g m/s, its lowest "
      "particle %.4f m, the cloth's %.4f m; never closer than %.4f m above the cloth's lowest\n",
      die_speed, die_low, cloth_low, under);
  EXPECT_LT(die_speed, 0.01);
  // It lies on the cloth: above the cloth's lowest particle by at least a diameter's worth of
  // contact, and the cloth sags under it below its corners (0.2 m).
  EXPECT_GT(under, 0.5 * kSpacing);
  EXPECT_LT(cloth_low, 0.2);
}

TEST(PositionCloth, BoxHitByAClothWithoutGravityKeepsMomentum) {
  motes::Scene scene = particle_scene(Eigen::Vector3d::Zero(), 10);
  scene.settings.link_damping = 0.0;
  scene.bodies.push_back(motes_test::body(motes_test::lattice(3, 3, 3, kSpacing),
                                          Eigen::Vector3d(0.01, 0.0, 0.005),
                                          Eigen::Vector3d::Zero(), Eigen::Vector3d(0.0, 5.0, 0.0)));
  motes::LinkedSpec cloth = flat_cloth(11, Eigen::Vector3d(-0.05, 0.04, -0.05));
  cloth.velocity = Eigen::Vector3d(0.1, -1.0, 0.2);
  scene.linked.push_back(cloth);
  auto created = motes_test::simulate(scene);
  ASSERT_TRUE(created) << created.message();
  motes::Simulation& sim = *created.value();
  const std::uint32_t first = sim.bodies()[1].first_particle;
  // The box's momentum (the snapshot's later bodies are the cloth's mean) and the cloth's.
  const auto momentum = [&](const motes::Snapshot& s) -> Eigen::Vector3d {
    return to_vec3(s.body_vel[0]) / static_cast<double>(s.body_pos[0].w) +
           motes_test::particle_momentum(s, first);
  };
  auto before = sim.snapshot();
  ASSERT_TRUE(before);
  const Eigen::Vector3d p0 = momentum(*before);
  ASSERT_TRUE(sim.step(9));  // 0.15 s: the cloth meets the box and wraps around it
  auto after = sim.snapshot();
  ASSERT_TRUE(after);
  const Eigen::Vector3d p1 = momentum(*after);
  const double box_speed = to_vec3(after->body_vel[0]).norm();
  const double drift = (p1 - p0).norm() / p0.norm();
  std::printf(
      "[position cloth] a cloth hits a spinning box without gravity: momentum (%.6g, %.6g, "
      "%.6g) -> (%.6g, %.6g, %.6g), %.2e relative; the box at %.3f m/s after\n",
      p0.x(), p0.y(), p0.z(), p1.x(), p1.y(), p1.z(), drift, box_speed);
  EXPECT_GT(box_speed, 0.05) << "the cloth must have hit the box";
  EXPECT_LT(drift, 1e-6);
}

/// Mechanical energy of every moving part, from y = 0: the rigid bodies' (kinetic_energy and
/// m g y of their centres) and the other particles' [rigid, N).
double scene_energy(const motes::Snapshot& s, std::size_t rigid, double g) {
  double e = motes_test::kinetic_energy(s);
  for (std::size_t b = 0; b < s.body_pos.size(); ++b) {
    const double inv_m = static_cast<double>(s.body_pos[b].w);
    if (inv_m != 0.0) e += g * static_cast<double>(s.body_pos[b].y) / inv_m;
  }
  for (std::size_t i = rigid; i < s.particle_vel.size(); ++i) {
    const double inv_m = static_cast<double>(s.particle_vel[i].w);
    if (inv_m == 0.0) continue;
    e += (0.5 * to_vec3(s.particle_vel[i]).squaredNorm() +
          g * static_cast<double>(s.particle_pos[i].y)) /
         inv_m;
  }
  return e;
}

// Enabled 2026-11-28 (session 11). It was disabled as "bodies fall through the held cloth" (5 of 6
// seeds ended with the die or the soft cube below it, falling freely). They do not go through: a
// cloth pinned at its corners at its rest size is taut, a trampoline; the bodies bounce off it,
// land off centre and leave over its edges (their centres 0.08 to 0.25 m from the middle, past
// its 0.07 m half-width, when their lowest particles pass below the cloth's lowest), and with 16
// or 64 link sweeps instead of 4, or 10 shift sweeps instead of 3, they leave all the same. So the
// scene has a floor now, and "through the cloth" is what it says: a body's centre passing below
// the cloth's lowest particle while it is over the cloth.
TEST(PositionMixed, RandomDropsOntoAHeldClothKeepEnergyAndStayUnderTheGuard) {
  // Seeded: a die of 2 to 4 particles a side in a random pose and a soft cube above it (apart:
  // the die's centre at 0.28 to 0.35 m, the cube's at 0.45 to 0.5 m; drawn from 0.3 to 0.45 and
  // 0.4 to 0.45 they could start inside each other, and the shifts that part them added 0.4% to
  // 1.7% to the energy in seed 4) dropped onto a 15 x 15 cloth held at its corners 0.2 m above a
  // floor, a
  // rope pinned across it at a random place, friction 0.3 to 0.8. Invariants over 2 s: the
  // mechanical energy never above its start by 1%, no particle past the guard's quarter diameter
  // a substep, neither body's centre passing below the cloth's lowest particle while within
  // 0.065 m of its middle in x and z (the cloth reaches 0.07 m).
  constexpr double kG = 9.81;
  // 30 substeps: a body that bounces off the cloth and leaves over its edge falls onto the floor
  // from up to 0.5 m (3.1 m/s: 0.17 d a substep; at 20 substeps 0.27 d, past the guard's 0.25).
  constexpr int kSubsteps = 30;
  for (std::uint32_t seed = 1; seed <= motes_test::seeds_to_run(6, 2); ++seed) {
    std::mt19937 rng(seed);
    const auto uniform = [&](double lo, double hi) {
      return std::uniform_real_distribution<double>(lo, hi)(rng);
    };
    motes::Scene scene = particle_scene(Eigen::Vector3d(0.0, -kG, 0.0), kSubsteps);
    scene.planes.push_back(
        motes::PlaneSpec{"floor", Eigen::Vector3d(0.0, 1.0, 0.0), Eigen::Vector3d::Zero(), 0});
    scene.settings.constraint_iterations = 4;
    scene.materials[0].friction = uniform(0.3, 0.8);
    motes::LinkedSpec cloth = flat_cloth(15, Eigen::Vector3d(-0.07, 0.2, -0.07));
    cloth.pinned = {0u, 14u, 210u, 224u};
    scene.linked.push_back(cloth);
    motes::LinkedSpec rope;
    rope.name = "rope";
    rope.kind = motes::LinkedKind::Rope;
    rope.diameter = kSpacing;
    const double rz = uniform(-0.04, 0.04);
    for (int k = 0; k <= 16; ++k) {
      rope.points.push_back(Eigen::Vector3d(-0.08 + kSpacing * k, 0.215, rz));
      rope.lattice.push_back({static_cast<std::uint32_t>(k), 0u});
      if (k > 0) {
        rope.links.push_back(
            {static_cast<std::uint32_t>(k - 1), static_cast<std::uint32_t>(k), 1.0});
      }
    }
    rope.pinned = {0u, 16u};
    scene.linked.push_back(rope);
    const int side = std::uniform_int_distribution<int>(2, 4)(rng);
    motes::BodySpec die = motes_test::body(
        motes_test::lattice(side, side, side, kSpacing),
        Eigen::Vector3d(uniform(-0.03, 0.03), uniform(0.28, 0.35), uniform(-0.03, 0.03)));
    die.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(
        uniform(0.0, 3.14),
        Eigen::Vector3d(uniform(-1.0, 1.0), uniform(-1.0, 1.0), uniform(-1.0, 1.0)).normalized()));
    scene.bodies.push_back(die);
    scene.bodies.push_back(position_soft_cube(
        Eigen::Vector3d(uniform(-0.04, 0.04), uniform(0.45, 0.5), uniform(-0.04, 0.04)),
        Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()));
    auto created = motes_test::simulate(scene);
    ASSERT_TRUE(created) << created.message();
    motes::Simulation& sim = *created.value();
    const std::size_t rigid = sim.sizes().rigid_particles;
    const std::size_t cloth_first = sim.bodies()[2].first_particle;
    const double h = scene.settings.dt / kSubsteps;
    auto start = sim.snapshot();
    ASSERT_TRUE(start);
    const double e0 = scene_energy(*start, rigid, kG);
    double rise = 0.0, travel = 0.0;
    // The die's particles [0, rigid), the soft cube's [rigid, cloth_first), the cloth's next 225.
    const std::size_t ranges[2][2] = {{0, rigid}, {rigid, cloth_first}};
    bool above[2] = {true, true};
    int through[2] = {0, 0}, left[2] = {0, 0};
    for (int frame = 0; frame < 120; ++frame) {
      ASSERT_TRUE(sim.step(1)) << "seed " << seed;
      auto s = sim.snapshot();
      ASSERT_TRUE(s);
      rise = std::max(rise, (scene_energy(*s, rigid, kG) - e0) / e0);
      for (std::size_t i = 0; i < s->particle_vel.size(); ++i) {
        travel = std::max(travel, to_vec3(s->particle_vel[i]).norm() * h /
                                      (2.0 * static_cast<double>(s->particle_pos[i].w)));
      }
      double cloth_low = 1.0;
      for (std::size_t i = cloth_first; i < cloth_first + 225; ++i) {
        cloth_low = std::min(cloth_low, static_cast<double>(s->particle_pos[i].y));
      }
      for (int b = 0; b < 2; ++b) {
        Eigen::Vector3d c = Eigen::Vector3d::Zero();
        for (std::size_t i = ranges[b][0]; i < ranges[b][1]; ++i) c += to_vec3(s->particle_pos[i]);
        c /= static_cast<double>(ranges[b][1] - ranges[b][0]);
        const bool now_above = c.y() >= cloth_low;
        if (above[b] && !now_above) {
          const bool over = std::abs(c.x()) < 0.065 && std::abs(c.z()) < 0.065;
          (over ? through : left)[b] += 1;
          if (over) {
            ADD_FAILURE() << "seed " << seed << ": the " << (b == 0 ? "die" : "soft cube")
                          << " went through the cloth at frame " << frame << ", centre ("
                          << c.transpose() << "), the cloth's lowest " << cloth_low << " m";
          }
        }
        above[b] = now_above;
      }
    }
    std::printf(
        "[position mixed] seed %u (die of %d, mu %.2f): energy at most %+.2e of its start, "
        "travel at most %.3f d a substep; left over the cloth's edge: die %d, soft cube %d; "
        "through it: %d, %d\n",
        seed, side, scene.materials[0].friction, rise, travel, left[0], left[1], through[0],
        through[1]);
    EXPECT_LT(rise, 0.01) << "seed " << seed;
    EXPECT_LT(travel, motes::Simulation::kSafeTravel) << "seed " << seed;
  }
}

}  // namespace
