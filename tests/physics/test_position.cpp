// Position contacts ("contact_model": "position"; shared/position.h), against rigid-body theory,
// at frame-sized steps (dt = 1/60 s in the default 8 substeps) on the OpenMP device:
// - friction: a box of 3 x 3 x 3 particles of 1 cm sliding at 1 m/s on a floor with mu = 0.5
//   stops after v^2 / (2 mu g); on a slope below the friction angle (20 degrees, tan 0.36 < 0.5)
//   it stays, above it (35 degrees) it slides at g (sin - mu cos). Pass: 5% (issue 27); a box at
//   rest on the slope moves less than 1% of a particle diameter in 2.5 s.
// - restitution: a sphere meets a plane at 1 m/s without gravity and leaves at e times that
//   (e = 0, 0.5, 0.9); flat boxes of 3 x 1 x 3 to 8 x 1 x 8 particles do the same, and dropped
//   from 10 cm with gravity rise to e^2 of it (e = 0.5, 0.9). Pass: 5%. Seeded boxes dropped
//   tilted up to 5 degrees never gain energy (1% of its scale), never rebound above 1.05 e^2 of
//   their drop, and rest after 3 s.
// - stacking: two boxes, the upper laid up to 10% of a particle diameter off centre, stand: from
//   1 s to 5 s no particle moves 1% of a diameter. Columns of ten boxes and pyramids of five rows,
//   each box laid up to 10% of a diameter off centre (seeded), stand for 10 s: from 2 s on no
//   particle moves 1% of a diameter (issue 27), no box drops a diameter.
// - momentum: two spinning boxes collide without gravity; the total linear momentum is the same
//   before and after to 1e-6 relative.
// Soft bodies, cloth and ropes with position contacts, and with rigid bodies:
// test_position_particles.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "physics/physics_scenes.h"

// A named namespace: the unity build compiles this file with its neighbours, whose anonymous
// namespaces have constants of the same names (kFrame, kDensity).
namespace position_physics {

using motes_test::to_vec3;

constexpr double kDensity = 1000.0;
constexpr double kG = 9.81;
constexpr double kFrame = 1.0 / 60.0;

motes::Scene position_scene(const Eigen::Vector3d& gravity, double restitution, double friction) {
  motes::Material mat = motes_test::material(kDensity, 0.0, 0.0, 0.0, friction);
  mat.restitution = restitution;
  motes::Scene scene = motes_test::scene_with(kFrame, gravity, mat);
  scene.settings.contact_model = motes::ContactModel::Positions;
  scene.settings.substeps = motes::kPositionSubsteps;
  return scene;
}

std::uint64_t frames(double seconds) {
  return static_cast<std::uint64_t>(std::lround(seconds / kFrame));
}

/// Largest distance any particle moves between two snapshots.
double largest_particle_move(const motes::Snapshot& a, const motes::Snapshot& b) {
  double m = 0.0;
  for (std::size_t i = 0; i < a.particle_pos.size(); ++i) {
    m = std::max(m, (to_vec3(a.particle_pos[i]) - to_vec3(b.particle_pos[i])).norm());
  }
  return m;
}

TEST(PositionContact, SlidingBoxStopsAfterVSquaredOverTwoMuG) {
  constexpr double kD = 0.01;
  constexpr double kMu = 0.5;
  constexpr double kV = 1.0;
  motes::Scene scene = position_scene(Eigen::Vector3d(0.0, -kG, 0.0), 0.0, kMu);
  scene.planes.push_back(motes_test::plane(Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero()));
  auto box = motes_test::lattice(3, 3, 3, kD);
  scene.bodies.push_back(
      motes_test::body(box, Eigen::Vector3d(0.0, 1.5 * kD, 0.0), Eigen::Vector3d(kV, 0.0, 0.0)));
  auto sim = motes_test::simulate(scene);
  ASSERT_TRUE(sim) << sim.status().message();
  ASSERT_TRUE((*sim)->step(frames(0.6)));  // stops at v / (mu g) = 0.2 s
  auto end = (*sim)->snapshot();
  ASSERT_TRUE(end);
  const double distance = static_cast<double>(end->body_pos[0].x);
  const double expected = kV * kV / (2.0 * kMu * kG);
  std::printf("sliding box: stops after %.5g m, v^2 / (2 mu g) = %.5g m\n", distance, expected);
  EXPECT_NEAR(distance, expected, 0.05 * expected);
  EXPECT_LT(to_vec3(end->body_vel[0]).norm(), 1e-3);
}

/// A box of 3 x `layers` x 3 particles of 1 cm at rest on a plane through the origin tilted by
/// `degrees` about z (downhill towards -x), friction 0.5: snapshots at 0.5 s, 1.5 s and 3 s.
struct SlopeRun {
  motes::Snapshot a, b, c;
};

SlopeRun slope(double degrees, int layers = 3) {
  constexpr double kD = 0.01;
  const double t = degrees * std::numbers::pi / 180.0;
  const Eigen::Vector3d n(-std::sin(t), std::cos(t), 0.0);
  motes::Scene scene = position_scene(Eigen::Vector3d(0.0, -kG, 0.0), 0.0, 0.5);
  scene.planes.push_back(motes_test::plane(n, Eigen::Vector3d::Zero()));
  auto box = motes_test::lattice(3, layers, 3, kD);
  scene.bodies.push_back(
      motes_test::body(box, 0.5 * layers * kD * n, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                       Eigen::Quaterniond(Eigen::AngleAxisd(t, Eigen::Vector3d::UnitZ()))));
  SlopeRun r;
  auto sim = motes_test::simulate(scene);
  if (!sim) {
    ADD_FAILURE() << sim.status().message();
    return r;
  }
  for (auto [seconds, out] : {std::pair{0.5, &r.a}, std::pair{1.0, &r.b}, std::pair{1.5, &r.c}}) {
    if (!(*sim)->step(frames(seconds))) ADD_FAILURE() << "step";
    auto s = (*sim)->snapshot();
    if (!s) ADD_FAILURE() << s.status().message();
    if (s) *out = std::move(s).value();
  }
  return r;
}

TEST(PositionContact, BoxOnASlopeBelowTheFrictionAngleStays) {
  const SlopeRun r = slope(20.0);
  ASSERT_FALSE(r.c.particle_pos.empty());
  const double move = std::max(largest_particle_move(r.a, r.b), largest_particle_move(r.a, r.c));
  std::printf("box on a 20 degree slope, mu 0.5: moves at most %.3g d from 0.5 s to 3 s\n",
              move / 0.01);
  EXPECT_LT(move, 0.01 * 0.01);
}

// Kinetic friction all the way down: the acceleration from 0.5 s to 1.5 s and from 1.5 s to 3 s
// each (a wrong friction can average out: before session 8 the box slid at 1.775 then 1.444
// m/s^2, 1.58 over both), for the 3 x 3 x 3 box and a flat 3 x 1 x 3 one (whose contacts took
// most of their normal correction in the sweeps that had no friction: 2.30 m/s^2).
TEST(PositionContact, BoxOnASlopeAboveTheFrictionAngleSlidesAtGSinMinusMuCos) {
  const double t = 35.0 * std::numbers::pi / 180.0;
  const double expected = kG * (std::sin(t) - 0.5 * std::cos(t));
  for (const int layers : {3, 1}) {
    const SlopeRun r = slope(35.0, layers);
    ASSERT_FALSE(r.c.body_vel.empty());
    const double v0 = to_vec3(r.a.body_vel[0]).norm();
    const double v1 = to_vec3(r.b.body_vel[0]).norm();
    const double v2 = to_vec3(r.c.body_vel[0]).norm();
    const double first = (v1 - v0) / 1.0;
    const double second = (v2 - v1) / 1.5;
    std::printf(
        "3 x %d x 3 box on a 35 degree slope, mu 0.5: accelerates at %.5g then %.5g m/s^2, "
        "g (sin - mu cos) = %.5g\n",
        layers, first, second, expected);
    EXPECT_NEAR(first, expected, 0.05 * expected) << layers << " layers";
    EXPECT_NEAR(second, expected, 0.05 * expected) << layers << " layers";
  }
}

/// A bar of n x 1 x 1 particles of 1 cm lying on the floor, turned by `yaw` about the vertical,
/// pushed at the horizontal velocity v with friction mu and restitution e, stepped `frames`
/// frames: its largest kinetic energy after the start (a fraction of the start's), how far its
/// centre went, and its speeds at the end.
struct Push {
  double most = 0.0;
  double distance = 0.0;
  double speed = 0.0;
  double spin = 0.0;
};

Push push_bar(int n, double yaw, const Eigen::Vector3d& v, double mu, double e, int frames) {
  constexpr double kD = 0.01;
  Push r;
  motes::Scene scene = position_scene(Eigen::Vector3d(0.0, -kG, 0.0), e, mu);
  scene.planes.push_back(motes_test::plane(Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero()));
  scene.bodies.push_back(
      motes_test::body(motes_test::lattice(n, 1, 1, kD), Eigen::Vector3d(0.0, 0.5 * kD, 0.0), v,
                       Eigen::Vector3d::Zero(),
                       Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()))));
  auto sim = motes_test::simulate(scene);
  if (!sim) {
    ADD_FAILURE() << sim.status().message();
    return r;
  }
  auto start = (*sim)->snapshot();
  if (!start) {
    ADD_FAILURE() << start.status().message();
    return r;
  }
  const double e0 = motes_test::kinetic_energy(*start);
  for (int frame = 0; frame < frames; ++frame) {
    auto s = (*sim)->step(1) ? (*sim)->snapshot() : motes::Result<motes::Snapshot>(motes::Status());
    if (!s) {
      ADD_FAILURE() << "frame " << frame;
      return r;
    }
    r.most = std::max(r.most, motes_test::kinetic_energy(*s) / e0);
    if (frame + 1 == frames) {
      const Eigen::Vector3d moved = to_vec3(s->body_pos[0]) - to_vec3(start->body_pos[0]);
      r.distance = Eigen::Vector3d(moved.x(), 0.0, moved.z()).norm();
      r.speed = to_vec3(s->body_vel[0]).norm();
      r.spin = to_vec3(s->body_angvel[0]).norm();
    }
  }
  return r;
}

// A rod of three particles lying on the floor, pushed across its length: friction at the
// particles' centres slows it as a sliding box (v^2 / (2 mu g)) and never adds energy. Before
// session 8 the correction acted on the particles' surfaces, spun the rod about its axis instead
// of stopping it and gained 19% of its kinetic energy in 0.05 s (the CUDA pile's runaway).
TEST(PositionContact, RodPushedAcrossItsLengthStopsWithoutGainingEnergy) {
  constexpr double kMu = 0.67;
  constexpr double kV = 0.5;
  // Stops at v / (mu g) = 0.08 s.
  const Push r = push_bar(3, 0.0, Eigen::Vector3d(0.0, 0.0, kV), kMu, 0.18, 30);
  const double expected = kV * kV / (2.0 * kMu * kG);
  std::printf(
      "rod pushed across its length: stops after %.4g m (v^2 / (2 mu g) = %.4g), kinetic energy "
      "at most %.4g of its start\n",
      r.distance, expected, r.most);
  EXPECT_LE(r.most, 1.0);
  EXPECT_NEAR(r.distance, expected, 0.05 * expected);
  EXPECT_LT(r.speed, 1e-3);
  EXPECT_LT(r.spin, 0.1);
}

// Seeded variations of the rod: bars of 1 to 5 particles (a single sphere to a long rod) turned
// at random about the vertical, pushed in a random horizontal direction at 0.2 to 1 m/s, mu 0.3
// to 0.8, e 0 to 0.5. Whatever the angle between bar and push, the kinetic energy never rises,
// friction is never weaker than mu (the bar goes no further than v^2 / (2 mu g)), and it stops.
TEST(PositionContact, BarsPushedAtRandomNeverGainEnergyAndStop) {
  for (const std::uint32_t seed : {1u, 2u, 3u, 4u, 5u, 6u, 7u, 8u, 9u, 10u, 11u, 12u}) {
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> length(1, 5);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const int n = length(rng);
    const double yaw = std::numbers::pi * unit(rng);
    const double heading = 2.0 * std::numbers::pi * unit(rng);
    const double speed = 0.2 + 0.8 * unit(rng);
    const double mu = 0.3 + 0.5 * unit(rng);
    const double e = 0.5 * unit(rng);
    const Eigen::Vector3d v(speed * std::cos(heading), 0.0, speed * std::sin(heading));
    // Stops by v / (mu g) <= 0.34 s; 0.75 s stepped.
    const Push r = push_bar(n, yaw, v, mu, e, 45);
    const double bound = speed * speed / (2.0 * mu * kG);
    std::printf(
        "seed %2u: %d x 1 x 1 bar, pushed %.0f degrees off its length at %.2f m/s, mu %.2f: goes "
        "%.4g m (at most %.4g), kinetic energy at most %.4g of its start\n",
        seed, n, std::acos(std::abs(std::cos(heading + yaw))) * 180.0 / std::numbers::pi, speed, mu,
        r.distance, bound, r.most);
    EXPECT_LE(r.most, 1.0) << "seed " << seed;
    EXPECT_LE(r.distance, 1.05 * bound) << "seed " << seed;
    EXPECT_LT(r.speed, 1e-3) << "seed " << seed;
    EXPECT_LT(r.spin, 0.1) << "seed " << seed;
  }
}

class SphereBounce : public ::testing::TestWithParam<double> {};

TEST_P(SphereBounce, LeavesAtETimesItsApproach) {
  const double e = GetParam();
  constexpr double kV = 1.0;
  motes::Scene scene = position_scene(Eigen::Vector3d::Zero(), e, 0.3);
  scene.planes.push_back(motes_test::plane(Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero()));
  scene.bodies.push_back(motes_test::body(motes_test::single_particle(0.02),
                                          Eigen::Vector3d(0.0, 0.03, 0.0),
                                          Eigen::Vector3d(0.0, -kV, 0.0)));
  auto sim = motes_test::simulate(scene);
  ASSERT_TRUE(sim) << sim.status().message();
  ASSERT_TRUE((*sim)->step(frames(0.3)));  // meets the plane at 0.02 s
  auto end = (*sim)->snapshot();
  ASSERT_TRUE(end);
  const double v = static_cast<double>(end->body_vel[0].y);
  std::printf("sphere, e = %.2g: leaves at %.5g m/s after meeting the plane at %.3g m/s\n", e, v,
              kV);
  EXPECT_NEAR(v, e * kV, 0.05 * kV);
}

INSTANTIATE_TEST_SUITE_P(Restitution, SphereBounce, ::testing::Values(0.0, 0.5, 0.9));

/// A box of nx x ny x nz particles of 1 cm meeting a plane flat (its ny side down), e and mu 0.3:
/// without gravity at 1 m/s (the speed it leaves at), or with gravity dropped from 10 cm above
/// the plane (e measured as sqrt of the height its centre rises to over the height it fell).
double flat_box_bounce(int nx, int ny, int nz, double e, bool gravity) {
  constexpr double kD = 0.01;
  constexpr double kV = 1.0;
  constexpr double kDrop = 0.1;
  motes::Scene scene =
      position_scene(gravity ? Eigen::Vector3d(0.0, -kG, 0.0) : Eigen::Vector3d::Zero(), e, 0.3);
  scene.planes.push_back(motes_test::plane(Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero()));
  const double bottom = 0.5 * ny * kD;  // centre above the plane when it touches
  scene.bodies.push_back(
      motes_test::body(motes_test::lattice(nx, ny, nz, kD),
                       Eigen::Vector3d(0.0, bottom + (gravity ? kDrop : 0.01), 0.0),
                       gravity ? Eigen::Vector3d::Zero() : Eigen::Vector3d(0.0, -kV, 0.0)));
  auto sim = motes_test::simulate(scene);
  EXPECT_TRUE(sim) << sim.status().message();
  if (!sim) return -1.0;
  if (!gravity) {
    EXPECT_TRUE((*sim)->step(frames(0.3)));  // meets the plane at 0.01 s
    auto end = (*sim)->snapshot();
    EXPECT_TRUE(end);
    return end ? static_cast<double>(end->body_vel[0].y) / kV : -1.0;
  }
  // Falls 10 cm in 0.143 s; rises at most e^2 10 cm, for at most e 0.143 s after.
  EXPECT_TRUE((*sim)->step(frames(0.2)));
  double top = 0.0;
  for (int f = 0; f < 30; ++f) {
    EXPECT_TRUE((*sim)->step(1));
    auto now = (*sim)->snapshot();
    EXPECT_TRUE(now);
    if (now) top = std::max(top, static_cast<double>(now->body_pos[0].y) - bottom);
  }
  return std::sqrt(std::max(top, 0.0) / kDrop);
}

// Issue 27: a flat box bounces with the material's e within 5%, as the sphere does. Its contacts
// share the body; with mass splitting two velocity sweeps gave a 3 x 1 x 3 box 0.12 of its e
// (docs/position-solver.md); the Gram bound's step (shared/contact_gram.h) closes the flat face's
// error in one sweep.
TEST(PositionContact, FlatBoxBouncesWithE) {
  struct Box {
    int nx, ny, nz;
  };
  for (const Box b : {Box{3, 1, 3}, Box{3, 3, 3}, Box{5, 2, 4}, Box{4, 2, 4}, Box{8, 1, 8}}) {
    for (const double e : {0.5, 0.9}) {
      const double free = flat_box_bounce(b.nx, b.ny, b.nz, e, false);
      const double dropped = flat_box_bounce(b.nx, b.ny, b.nz, e, true);
      std::printf(
          "%d x %d x %d box, e = %.2g: leaves at %.4g of its approach without gravity, "
          "rises to %.4g e^2 of its drop\n",
          b.nx, b.ny, b.nz, e, free, dropped * dropped / (e * e));
      EXPECT_NEAR(free, e, 0.05 * e) << b.nx << " x " << b.ny << " x " << b.nz;
      EXPECT_NEAR(dropped, e, 0.05 * e) << b.nx << " x " << b.ny << " x " << b.nz;
    }
  }
}

// Seeded variations of the flat box's bounce: box sizes, drop heights, tilts of up to 5 degrees
// about a random horizontal axis, a random yaw, a sideways speed, e and mu at random. A tilted
// box lands on an edge or a corner first, where the Gram step meets one to a few contacts of
// unequal arms: the energy (kinetic plus the centre's height) never rises above its start by 1%
// of it (the property tests' bound), the centre never rises above e^2 of its drop by more than
// 5% (a rigid body's centre cannot rebound faster than e times its approach), and the box is at
// rest after 3 s.
TEST(PositionContact, BoxesDroppedAtRandomNeverGainEnergyAndSettle) {
  constexpr double kD = 0.01;
  for (const std::uint32_t seed : {1u, 2u, 3u, 4u, 5u, 6u, 7u, 8u}) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::uniform_int_distribution<int> side(2, 6);
    std::uniform_int_distribution<int> height(1, 3);
    const int nx = side(rng), ny = height(rng), nz = side(rng);
    const double e = 0.3 + 0.5 * unit(rng);
    const double mu = 0.3 + 0.4 * unit(rng);
    const double drop = 0.05 + 0.1 * unit(rng);
    const double axis_angle = 2.0 * std::numbers::pi * unit(rng);
    const double tilt = 5.0 * std::numbers::pi / 180.0 * unit(rng);
    const double yaw = 2.0 * std::numbers::pi * unit(rng);
    const double sideways = 0.3 * unit(rng);
    const Eigen::Quaterniond rotation =
        Eigen::Quaterniond(Eigen::AngleAxisd(
            tilt, Eigen::Vector3d(std::cos(axis_angle), 0.0, std::sin(axis_angle)))) *
        Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()));
    motes::Scene scene = position_scene(Eigen::Vector3d(0.0, -kG, 0.0), e, mu);
    scene.planes.push_back(motes_test::plane(Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero()));
    // The lowest particle (a corner, tilted) starts `drop` above the plane.
    const double half = 0.5 * kD * (nx * std::sin(tilt) + ny + nz * std::sin(tilt));
    const double y0 = half + drop;
    scene.bodies.push_back(
        motes_test::body(motes_test::lattice(nx, ny, nz, kD), Eigen::Vector3d(0.0, y0, 0.0),
                         Eigen::Vector3d(sideways, 0.0, 0.0), Eigen::Vector3d::Zero(), rotation));
    auto sim = motes_test::simulate(scene);
    ASSERT_TRUE(sim) << sim.status().message();
    auto start = (*sim)->snapshot();
    ASSERT_TRUE(start);
    const double mass = 1.0 / static_cast<double>(start->body_pos[0].w);
    const auto energy = [&](const motes::Snapshot& s) {
      return motes_test::kinetic_energy(s) + mass * kG * static_cast<double>(s.body_pos[0].y);
    };
    const double e0 = energy(*start);
    const double scale = motes_test::kinetic_energy(*start) + mass * kG * drop;
    double most = 0.0;     // the largest energy rise, over the scale
    double landed = 0.0;   // the lowest centre so far
    double rebound = 0.0;  // the highest centre after the first landing, above where it landed
    bool down = false;
    double y_prev = y0;
    for (std::uint64_t f = 0; f < frames(3.0); ++f) {
      ASSERT_TRUE((*sim)->step(1));
      auto now = (*sim)->snapshot();
      ASSERT_TRUE(now);
      most = std::max(most, (energy(*now) - e0) / scale);
      const double y = static_cast<double>(now->body_pos[0].y);
      if (!down && y > y_prev && f > 0) {
        down = true;
        landed = y_prev;
      }
      if (down) rebound = std::max(rebound, y - landed);
      y_prev = y;
    }
    auto end = (*sim)->snapshot();
    ASSERT_TRUE(end);
    const double speed = to_vec3(end->body_vel[0]).norm();
    const double spin = to_vec3(end->body_angvel[0]).norm();
    std::printf(
        "seed %u: %d x %d x %d box, tilt %.2f degrees, e %.2f, mu %.2f, dropped %.3f m: energy at "
        "most %.3g of its scale above its start, rebound %.3f of e^2 drop, at the end %.2g m/s, "
        "%.2g rad/s\n",
        seed, nx, ny, nz, tilt * 180.0 / std::numbers::pi, e, mu, drop, most,
        rebound / (e * e * drop), speed, spin);
    EXPECT_LE(most, 0.01) << "seed " << seed;
    EXPECT_LE(rebound, 1.05 * e * e * drop) << "seed " << seed;
    EXPECT_LT(speed, 1e-2) << "seed " << seed;
    EXPECT_LT(spin, 1e-1) << "seed " << seed;
  }
}

TEST(PositionContact, TwoBoxesLaidOffCentreStand) {
  constexpr double kD = 0.01;
  constexpr double kSize = 3 * kD;
  motes::Scene scene = position_scene(Eigen::Vector3d(0.0, -kG, 0.0), 0.0, 0.5);
  scene.planes.push_back(motes_test::plane(Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero()));
  auto box = motes_test::lattice(3, 3, 3, kD);
  scene.bodies.push_back(motes_test::body(box, Eigen::Vector3d(0.0, 0.5 * kSize, 0.0)));
  // 10% of a particle diameter off centre, along both horizontal axes.
  scene.bodies.push_back(motes_test::body(box, Eigen::Vector3d(0.1 * kD, 1.5 * kSize, -0.1 * kD)));
  auto sim = motes_test::simulate(scene);
  ASSERT_TRUE(sim) << sim.status().message();
  ASSERT_TRUE((*sim)->step(frames(1.0)));
  auto settled = (*sim)->snapshot();
  ASSERT_TRUE((*sim)->step(frames(4.0)));
  auto end = (*sim)->snapshot();
  ASSERT_TRUE(settled && end);
  const double later = largest_particle_move(*settled, *end);
  const double sink = 1.5 * kSize - static_cast<double>(end->body_pos[1].y);
  std::printf(
      "two boxes, the upper 0.1 d off centre: move %.3g d from 1 s to 5 s, the upper "
      "sinks %.3g d\n",
      later / kD, sink / kD);
  EXPECT_LT(later, 0.01 * kD);
  EXPECT_LT(sink, 0.1 * kD);
}

/// Boxes of 3 x 3 x 3 particles of 1 cm (mu = 0.5, e = 0) on a floor at `centres`, stepped for
/// `seconds`: the largest particle move from 2 s to the end (after settling) and the largest
/// drop of a box's centre from where it was laid, both in diameters.
struct Stand {
  double drift = 0.0;
  double sink = 0.0;
};
Stand stand(const std::vector<Eigen::Vector3d>& centres, double seconds) {
  constexpr double kD = 0.01;
  motes::Scene scene = position_scene(Eigen::Vector3d(0.0, -kG, 0.0), 0.0, 0.5);
  scene.planes.push_back(motes_test::plane(Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero()));
  auto box = motes_test::lattice(3, 3, 3, kD);
  for (const Eigen::Vector3d& c : centres) scene.bodies.push_back(motes_test::body(box, c));
  Stand r;
  auto sim = motes_test::simulate(scene);
  EXPECT_TRUE(sim) << sim.status().message();
  if (!sim) return r;
  EXPECT_TRUE((*sim)->step(frames(2.0)));
  auto settled = (*sim)->snapshot();
  // The sanitizer build: 0.5 s after the settling (the paths; the whole time in the first stage).
  EXPECT_TRUE((*sim)->step(static_cast<std::uint64_t>(motes_test::frames_to_run(
      static_cast<int>(frames(seconds - 2.0)), static_cast<int>(frames(0.5))))));
  auto end = (*sim)->snapshot();
  EXPECT_TRUE(settled && end);
  if (!settled || !end) return r;
  r.drift = largest_particle_move(*settled, *end) / kD;
  for (std::size_t b = 0; b < centres.size(); ++b) {
    r.sink = std::max(r.sink, (centres[b].y() - static_cast<double>(end->body_pos[b].y)) / kD);
  }
  return r;
}

// Issue 27's column: ten boxes, each laid up to 10% of a diameter off the one below along both
// horizontal axes (seeded), stands for 10 s: from 2 s on no particle moves 1% of a diameter, and
// no box drops a diameter (a fallen box drops 3 to 27). Before the stack scaling and the three
// projection sweeps, columns of five or more fell within a second.
TEST(PositionContact, ColumnsOfTenBoxesLaidOffCentreStand) {
  constexpr double kD = 0.01;
  for (std::uint32_t seed = 1; seed <= motes_test::seeds_to_run(6); ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> off(-0.1 * kD, 0.1 * kD);
    std::vector<Eigen::Vector3d> centres;
    Eigen::Vector3d at(0.0, 1.5 * kD, 0.0);
    for (int k = 0; k < 10; ++k) {
      centres.push_back(at);
      at += Eigen::Vector3d(off(rng), 3 * kD, off(rng));
    }
    const Stand r = stand(centres, 10.0);
    std::printf(
        "column of 10, seed %u: moves %.3g d from 2 s to 10 s, a box sinks at most %.3g d\n", seed,
        r.drift, r.sink);
    EXPECT_LT(r.drift, 0.01) << "seed " << seed;
    EXPECT_LT(r.sink, 1.0) << "seed " << seed;
  }
}

// A pyramid of five rows of such boxes, each row's boxes touching and each box on half of each
// of two below, every box laid up to 10% of a diameter off its place (seeded), stands for 10 s.
TEST(PositionContact, PyramidOfFiveRowsLaidOffCentreStands) {
  constexpr double kD = 0.01;
  for (std::uint32_t seed = 1; seed <= motes_test::seeds_to_run(2); ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> off(-0.1 * kD, 0.1 * kD);
    std::vector<Eigen::Vector3d> centres;
    for (int row = 0; row < 5; ++row) {
      for (int k = 0; k < 5 - row; ++k) {
        const double x = (k - 0.5 * (4 - row)) * 3 * kD;
        centres.emplace_back(x + off(rng), 1.5 * kD + row * 3 * kD, off(rng));
      }
    }
    const Stand r = stand(centres, 10.0);
    std::printf(
        "pyramid of 5 rows, seed %u: moves %.3g d from 2 s to 10 s, a box sinks at most "
        "%.3g d\n",
        seed, r.drift, r.sink);
    EXPECT_LT(r.drift, 0.01) << "seed " << seed;
    EXPECT_LT(r.sink, 1.0) << "seed " << seed;
  }
}

TEST(PositionContact, CollisionWithoutGravityKeepsMomentum) {
  motes::Scene scene = position_scene(Eigen::Vector3d::Zero(), 0.5, 0.4);
  motes_test::add_colliding_boxes(scene);
  auto sim = motes_test::simulate(scene);
  ASSERT_TRUE(sim) << sim.status().message();
  auto before = (*sim)->snapshot();
  ASSERT_TRUE((*sim)->step(frames(0.15)));
  auto after = (*sim)->snapshot();
  ASSERT_TRUE(before && after);
  EXPECT_GT((to_vec3(after->body_vel[0]) - to_vec3(before->body_vel[0])).norm(), 0.1);
  const Eigen::Vector3d p0 = motes_test::linear_momentum(*before);
  const Eigen::Vector3d p1 = motes_test::linear_momentum(*after);
  EXPECT_LT((p1 - p0).norm(), 1e-6 * p0.norm()) << p0.transpose() << " -> " << p1.transpose();
}

}  // namespace position_physics
