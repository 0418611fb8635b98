// Impulse contacts (Guendelman et al. 2003; shared/impulse.h), against rigid-body theory:
// - VALIDATION.md section 2: a solid sphere hits a wall obliquely (no gravity, no spin). With
//   I = 2/5 m R^2, restitution e and friction mu it leaves with vn' = e vn and, when
//   vt >= 7/2 mu (1 + e) vn (sliding throughout), vt' = vt - mu (1 + e) vn,
//   w' = 5/2 mu (1 + e) vn / R; otherwise it ends rolling: vt' = 5/7 vt, w' = 5/7 vt / R.
//   Pass: 1e-4 relative to the incoming speed, angles 10 to 85 degrees (both branches).
// - A tilted box lands on one corner particle (frictionless): the normal impulse
//   j = (1 + e) |vn_c| / (1/M + (r x n) . I^-1 (r x n)) at the contact point gives
//   v' = v + j n / M and L' = r x j n; every term computed here in double from the body's mass
//   properties. Pass: 1e-3 relative (the bound).
// - Stacking: a column of 10 boxes (3 x 3 x 3 particles) and a 5-row pyramid of 15 boxes
//   (4 x 4 x 4) stand still for 5 s: after settling into the slop in the first 0.1 s (at most
//   0.002 d per contact, plus, for the column, the give of the soft position correction under
//   the weight each contact carries: soft_give), no particle moves more than 1% of a particle
//   diameter.
// - Rocking (Housner 1963): a block rocking from edge to edge keeps r^2 of the height its centre
//   rises to at each landing, r = 1 - 2 m b^2 / I_O. Pass: 2% with the impact converged (128
//   sweeps a step), 6% with the default 16 (measured 3 to 4% more kept); 12 seeded blocks of
//   other sizes and leans: 2% converged, and no landing gains energy with the default sweeps.
// - Momentum: two spinning boxes collide without gravity; the total linear momentum is the same
//   before and after to 1e-6 relative.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "physics/physics_scenes.h"
#include "shared/impulse.h"

namespace {

using motes_test::to_quat;
using motes_test::to_vec3;

constexpr double kImpulseDensity = 1000.0;

motes::Scene impulse_scene(double dt, const Eigen::Vector3d& gravity, double restitution,
                           double friction, int iterations = 16) {
  motes::Material mat = motes_test::material(kImpulseDensity, 0.0, 0.0, 0.0, friction);
  mat.restitution = restitution;
  motes::Scene scene = motes_test::scene_with(dt, gravity, mat);
  scene.settings.contact_model = motes::ContactModel::Impulses;
  scene.settings.impulse_iterations = iterations;
  return scene;
}

struct ObliqueCase {
  double angle_deg;  // from the wall's normal
  double e;
  double mu;
};

class ObliqueSphere : public ::testing::TestWithParam<ObliqueCase> {};

TEST_P(ObliqueSphere, MatchesRigidBodyTheory) {
  const ObliqueCase c = GetParam();
  constexpr double kDiameter = 0.1;
  constexpr double kR = 0.5 * kDiameter;
  constexpr double kSpeed = 2.0;
  constexpr double kDt = 1e-4;
  const double angle = c.angle_deg * std::numbers::pi / 180.0;
  const double vt = kSpeed * std::sin(angle);
  const double vn = kSpeed * std::cos(angle);
  motes::Scene scene = impulse_scene(kDt, Eigen::Vector3d::Zero(), c.e, c.mu);
  scene.planes.push_back(motes_test::plane(Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero()));
  // Half a step's travel above the wall: the contact closes during the first step.
  const double gap = 0.5 * vn * kDt;
  scene.bodies.push_back(motes_test::body(motes_test::single_particle(kDiameter),
                                          Eigen::Vector3d(0.0, kR + gap, 0.0),
                                          Eigen::Vector3d(vt, -vn, 0.0)));
  auto sim = motes_test::simulate(scene);
  ASSERT_TRUE(sim) << sim.status().message();
  ASSERT_TRUE((*sim)->step(20));  // the impact, then free flight away from the wall
  auto snap = (*sim)->snapshot();
  ASSERT_TRUE(snap);
  const Eigen::Vector3d v = to_vec3(snap->body_vel[0]);
  const Eigen::Vector3d w = to_vec3(snap->body_angvel[0]);

  const double jn = (1.0 + c.e) * vn;  // per unit mass
  const bool sliding = vt >= 3.5 * c.mu * jn;
  const double vt_after = sliding ? vt - c.mu * jn : 5.0 / 7.0 * vt;
  const double w_after = sliding ? 2.5 * c.mu * jn / kR : 5.0 / 7.0 * vt / kR;
  const double tol = 1e-4 * kSpeed;
  EXPECT_NEAR(v.y(), c.e * vn, tol) << (sliding ? "sliding" : "rolling");
  EXPECT_NEAR(v.x(), vt_after, tol) << (sliding ? "sliding" : "rolling");
  EXPECT_NEAR(v.z(), 0.0, tol);
  // The wall's friction turns the sphere about -z (it rolls towards +x).
  EXPECT_NEAR(-w.z() * kR, w_after * kR, tol) << (sliding ? "sliding" : "rolling");
  EXPECT_NEAR(w.x(), 0.0, tol / kR);
  EXPECT_NEAR(w.y(), 0.0, tol / kR);
}

// 10 to 40 degrees end rolling at mu = 0.3, e = 0.5 (tan > 7/2 mu (1 + e) = 1.575 slides: 57.6
// degrees and up); e = 0 and a frictionless wall too.
INSTANTIATE_TEST_SUITE_P(Angles, ObliqueSphere,
                         ::testing::Values(ObliqueCase{10.0, 0.5, 0.3}, ObliqueCase{40.0, 0.5, 0.3},
                                           ObliqueCase{65.0, 0.5, 0.3}, ObliqueCase{85.0, 0.5, 0.3},
                                           ObliqueCase{30.0, 0.0, 0.2}, ObliqueCase{75.0, 0.0, 0.2},
                                           ObliqueCase{45.0, 0.9, 0.0}));

TEST(ImpulseContact, TiltedBoxLandingOnACornerMatchesRigidBodyTheory) {
  constexpr double kDiameter = 0.05;
  constexpr double kDt = 1e-4;
  constexpr double kE = 0.6;
  constexpr double kVn = 1.5;
  motes::Scene scene = impulse_scene(kDt, Eigen::Vector3d::Zero(), kE, 0.0);
  scene.planes.push_back(motes_test::plane(Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero()));
  auto shape = motes_test::lattice(3, 4, 5, kDiameter);
  ASSERT_TRUE(shape);
  const Eigen::Quaterniond tilt(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitX()) *
                                Eigen::AngleAxisd(0.35, Eigen::Vector3d::UnitZ()));
  const motes::MassProperties mp = motes::mass_properties(*shape, kImpulseDensity);
  // The lowest particle, and the gap to the next one (only one may touch).
  Eigen::Vector3d lowest(0.0, 1e9, 0.0);
  double second = 1e9;
  for (const Eigen::Vector3f& pt : shape->points) {
    const Eigen::Vector3d r = tilt * (pt.cast<double>() - mp.center);
    if (r.y() < lowest.y()) {
      second = lowest.y();
      lowest = r;
    } else {
      second = std::min(second, r.y());
    }
  }
  ASSERT_GT(second - lowest.y(), 0.2 * kDiameter);
  const double gap = 0.5 * kVn * kDt;
  const Eigen::Vector3d centre(0.0, 0.5 * kDiameter + gap - lowest.y(), 0.0);
  scene.bodies.push_back(motes_test::body(shape, centre, Eigen::Vector3d(0.0, -kVn, 0.0),
                                          Eigen::Vector3d::Zero(), tilt));
  auto sim = motes_test::simulate(scene);
  ASSERT_TRUE(sim) << sim.status().message();
  ASSERT_TRUE((*sim)->step(1));
  auto snap = (*sim)->snapshot();
  ASSERT_TRUE(snap);

  // Rigid-body theory in double: contact point c on the lowest particle's surface, arm r.
  const Eigen::Vector3d n = Eigen::Vector3d::UnitY();
  const Eigen::Vector3d r = lowest - 0.5 * kDiameter * n;
  const Eigen::Matrix3d inertia_world =
      tilt.toRotationMatrix() * mp.inertia * tilt.toRotationMatrix().transpose();
  const Eigen::Matrix3d inv_inertia = inertia_world.inverse();
  const Eigen::Vector3d rn = r.cross(n);
  const double j = (1.0 + kE) * kVn / (1.0 / mp.mass + rn.dot(inv_inertia * rn));
  const Eigen::Vector3d v_expected = Eigen::Vector3d(0.0, -kVn, 0.0) + j * n / mp.mass;
  const Eigen::Vector3d l_expected = j * rn;
  const Eigen::Vector3d v = to_vec3(snap->body_vel[0]);
  const Eigen::Vector3d l = to_vec3(snap->body_angmom[0]);
  EXPECT_LT((v - v_expected).norm(), 1e-3 * kVn)
      << v.transpose() << " vs " << v_expected.transpose();
  EXPECT_LT((l - l_expected).norm(), 1e-3 * l_expected.norm())
      << l.transpose() << " vs " << l_expected.transpose();
  // The contact point leaves at e times its approach speed (Newton's law at c).
  const Eigen::Vector3d w = to_vec3(snap->body_angvel[0]);
  EXPECT_NEAR((v + w.cross(r)).dot(n), kE * kVn, 1e-3 * kVn);
}

/// How far the resting contacts under a box sink beyond their slop (shared/impulse.h): in the
/// sweeps that correct overlaps, a contact's leak L j balances its bias MS B e / (h k_n) at an
/// overlap e = L / (MS B) h j k_n beyond the slop, with j the contact's share of the weight it
/// carries per impulse substep (h) and k_n the inverse mass it meets, at most n (1/m + r^2/I_min)
/// for a body of n contacts, mass m, least moment I_min and farthest contact arm r. For a box of
/// `shape` carrying `load` boxes of its own mass on `contacts` contacts, with `n` of its own.
double soft_give(const motes::ParticleSet& shape, double h, int load, int contacts, int n) {
  const motes::MassProperties mp = motes::mass_properties(shape, kImpulseDensity);
  double r2 = 0.0;
  for (const Eigen::Vector3f& p : shape.points) {
    const Eigen::Vector3d arm =
        p.cast<double>() - mp.center - Eigen::Vector3d(0.0, 0.5 * shape.diameter, 0.0);
    r2 = std::max(r2, arm.squaredNorm());
  }
  const double leak = MOTES_IMPULSE_LEAK / (MOTES_IMPULSE_MASS_SCALE * MOTES_IMPULSE_BIAS);
  const double j_kn = (load * mp.mass * 9.81 * h / contacts) * n *
                      (1.0 / mp.mass + r2 / mp.principal_moments.minCoeff());
  return leak * h * j_kn;
}

/// Largest distance any particle moves between two snapshots.
double largest_move(const motes::Snapshot& a, const motes::Snapshot& b) {
  double m = 0.0;
  for (std::size_t i = 0; i < a.particle_pos.size(); ++i) {
    m = std::max(m, (to_vec3(a.particle_pos[i]) - to_vec3(b.particle_pos[i])).norm());
  }
  return m;
}

/// Boxes of `side`^3 particles of diameter d placed touching at `centres` on a floor (e = 0.2,
/// mu = 0.6, dt = 1 ms): how far they settle in the first 0.1 s (each contact sinks into the
/// overlap the solver leaves alone, MOTES_IMPULSE_SLOP), then how far any particle moves in the
/// next `seconds` (the drift), and the fastest body at the end.
struct StackResult {
  double settle = 0.0;
  double move = 0.0;
  double speed = 0.0;
};

StackResult stand(const std::vector<Eigen::Vector3d>& centres, int side, double diameter,
                  double seconds) {
  constexpr double kDt = 1e-3;
  motes::Scene scene = impulse_scene(kDt, Eigen::Vector3d(0.0, -9.81, 0.0), 0.2, 0.6);
  scene.planes.push_back(motes_test::plane(Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero()));
  auto box = motes_test::lattice(side, side, side, diameter);
  for (const Eigen::Vector3d& c : centres) scene.bodies.push_back(motes_test::body(box, c));
  auto sim = motes_test::simulate(scene);
  if (!sim) {
    ADD_FAILURE() << sim.status().message();
    return {};
  }
  auto placed = (*sim)->snapshot();
  if (!(*sim)->step(100)) ADD_FAILURE() << "step";
  auto start = (*sim)->snapshot();
  // The sanitizer build stands them 0.5 s (the paths; the whole time in the first stage).
  const int steps = motes_test::frames_to_run(static_cast<int>(std::lround(seconds / kDt)), 500);
  if (!(*sim)->step(static_cast<std::uint64_t>(steps))) {
    ADD_FAILURE() << "step";
  }
  auto end = (*sim)->snapshot();
  StackResult r;
  r.settle = largest_move(*placed, *start);
  r.move = largest_move(*start, *end);
  for (const motes::shared::vec4& v : end->body_vel) r.speed = std::max(r.speed, to_vec3(v).norm());
  return r;
}

TEST(ImpulseContact, ColumnOfTenBoxesStandsStillForFiveSeconds) {
  constexpr double kD = 0.02;
  constexpr double kSize = 3 * kD;
  std::vector<Eigen::Vector3d> centres;
  for (int i = 0; i < 10; ++i) centres.emplace_back(0.0, 0.5 * kSize + i * kSize, 0.0);
  const StackResult r = stand(centres, 3, kD, 5.0);
  std::printf("column of 10: settles %.3g d, then moves %.3g d in 5 s, last speed %.3g m/s\n",
              r.settle / kD, r.move / kD, r.speed);
  // 11 contacts of at most the slop each (0.002 d between boxes, 0.001 d on the floor), and the
  // give under the weight above: the k-th interface from the top carries k boxes on 9 contacts;
  // a box has 18 contacts (9 below, 9 above). stand() runs dt = 1 ms in the default substeps.
  auto box = motes_test::lattice(3, 3, 3, kD);
  ASSERT_TRUE(box);
  const double h = 1e-3 / motes::Settings{}.impulse_substeps;
  double give = 0.0;
  for (int k = 1; k <= 10; ++k) give += soft_give(*box, h, k, 9, 18);
  std::printf("column of 10: slop 0.022 d, give under the load at most %.3g d\n", give / kD);
  EXPECT_LT(r.settle, 11 * 0.002 * kD + give);
  EXPECT_LT(r.move, 0.01 * kD);
}

// Issue 25's column: ten boxes of 3 x 3 x 3 particles of 1 cm, each laid 0.4 mm to the side of
// the one below as a stack built by hand would be (e = 0, mu = 0.5, dt = 0.5 ms, 16 iterations).
// The contact normals at the boxes' edges tilt by about 0.04 rad, which friction 0.5 must hold:
// the column may settle into its slop and give in the first second, then no particle may move
// 1% of a diameter from 1 s to 5 s. On the code the issue was filed against, the top box slid
// 0.5 d in the first second and still 0.09 d from 1 s to 5 s, and the column sank 0.37 d.
TEST(ImpulseContact, MisalignedColumnOfTenBoxesHolds) {
  constexpr double kD = 0.01;
  constexpr double kSize = 3 * kD;
  constexpr double kDt = 5e-4;
  motes::Scene scene = impulse_scene(kDt, Eigen::Vector3d(0.0, -9.81, 0.0), 0.0, 0.5);
  scene.planes.push_back(motes_test::plane(Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero()));
  auto box = motes_test::lattice(3, 3, 3, kD);
  for (int i = 0; i < 10; ++i) {
    scene.bodies.push_back(
        motes_test::body(box, Eigen::Vector3d(4e-4 * i, 0.5 * kSize + i * kSize, 0.0)));
  }
  auto sim = motes_test::simulate(scene);
  ASSERT_TRUE(sim) << sim.status().message();
  auto placed = (*sim)->snapshot();
  ASSERT_TRUE((*sim)->step(2000));
  auto settled = (*sim)->snapshot();
  // The sanitizer build: 0.5 s more instead of 4 (the paths; the whole time in the first stage).
  ASSERT_TRUE((*sim)->step(static_cast<std::uint64_t>(motes_test::frames_to_run(8000, 1000))));
  auto end = (*sim)->snapshot();
  ASSERT_TRUE(placed && settled && end);
  const double first = largest_move(*placed, *settled);
  const double later = largest_move(*settled, *end);
  const double sink = static_cast<double>(placed->body_pos[9].y - end->body_pos[9].y);
  std::printf(
      "misaligned column of 10: moves %.3g d in the first second, %.3g d from 1 s to 5 s; the top "
      "box sinks %.3g d\n",
      first / kD, later / kD, sink / kD);
  // The first second: the slop of 11 contacts (0.022 d) and the give under the load, as the
  // aligned column's (at most 0.006 d there at twice the substep, so less here), with room.
  EXPECT_LT(first, 0.05 * kD);
  EXPECT_LT(sink, 0.05 * kD);
  EXPECT_LT(later, 0.01 * kD);
}

TEST(ImpulseContact, PyramidOfFiveRowsStandsStillForFiveSeconds) {
  constexpr double kD = 0.02;
  constexpr double kSize = 4 * kD;
  std::vector<Eigen::Vector3d> centres;
  for (int row = 0; row < 5; ++row) {
    for (int k = 0; k < 5 - row; ++k) {
      // Boxes of a row touching, each row centred on the one below: a box rests on half of each
      // of two boxes (4 x 4 x 4 particles, so the half is two whole particle columns).
      const double x = (k - 0.5 * (4 - row)) * kSize;
      centres.emplace_back(x, 0.5 * kSize + row * kSize, 0.0);
    }
  }
  const StackResult r = stand(centres, 4, kD, 5.0);
  std::printf("pyramid of 15: settles %.3g d, then moves %.3g d in 5 s, last speed %.3g m/s\n",
              r.settle / kD, r.move / kD, r.speed);
  EXPECT_LT(r.settle, 6 * 0.002 * kD);
  EXPECT_LT(r.move, 0.01 * kD);
}

/// A block of 3 x 6 x 2 particles (1 cm, e = 0, mu = 0.8) stood on one edge of its base at 0.8 of
/// its tipping angle and let go: it falls back, lands on the other edge and rocks from edge to
/// edge. Each landing is an impact about the new edge that keeps the angular momentum about it
/// (Housner 1963): the angular velocity after is r = 1 - 2 m b^2 / I_O times the one before (b the
/// half distance between the edges' contact points, I_O the moment about an edge), so the height
/// the centre of mass rises to above its upright height shrinks by r^2 each landing. Returns the
/// ratio of each turning point's height to the one before, for the first `landings` landings.
std::vector<double> rocking_height_ratios(int iterations, int landings, double& expected,
                                          int nx = 3, int ny = 6, double lean = 0.8) {
  constexpr double kD = 0.01;
  motes::Scene scene = impulse_scene(5e-4, Eigen::Vector3d(0.0, -9.81, 0.0), 0.0, 0.8, iterations);
  scene.planes.push_back(motes_test::plane(Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero()));
  auto block = motes_test::lattice(nx, ny, 2, kD);
  const motes::MassProperties mp = motes::mass_properties(*block, kImpulseDensity);
  // Contact points at x = -b and b; the centre at hc when upright.
  const double b = 0.5 * (nx - 1) * kD, hc = 0.5 * ny * kD;
  const double io = mp.inertia(2, 2) + mp.mass * (b * b + hc * hc);
  expected = std::pow(1.0 - 2.0 * mp.mass * b * b / io, 2);
  // Turned about the centre of the particle it stands on (that particle still touches the floor).
  const Eigen::Vector3d edge(b, 0.5 * kD, 0.0);
  const Eigen::Quaterniond tilt(
      Eigen::AngleAxisd(-lean * std::atan(b / hc), Eigen::Vector3d::UnitZ()));
  scene.bodies.push_back(motes_test::body(block,
                                          edge + tilt * (Eigen::Vector3d(0.0, hc, 0.0) - edge),
                                          Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), tilt));
  scene.bodies.push_back(motes_test::body(block, Eigen::Vector3d(1.0, hc, 0.0)));  // upright
  auto sim = motes_test::simulate(scene);
  if (!sim) {
    ADD_FAILURE() << sim.status().message();
    return {};
  }
  std::vector<double> heights;  // above the upright block's centre: the start, then each turn
  double last_w = 0.0, last_y = 0.0;
  for (int i = 0; i < 4000 && static_cast<int>(heights.size()) <= landings; ++i) {
    if (!(*sim)->step(1)) break;
    auto s = (*sim)->snapshot();
    if (!s) break;
    const double w = s->body_angvel[0].z;
    const double y = static_cast<double>(s->body_pos[0].y - s->body_pos[1].y);
    if (i == 0) heights.push_back(y);
    if (i > 0 && w * last_w < 0.0) heights.push_back(std::max(y, last_y));
    last_w = w;
    last_y = y;
  }
  std::vector<double> ratios;
  for (std::size_t k = 0; k + 1 < heights.size(); ++k)
    ratios.push_back(heights[k + 1] / heights[k]);
  return ratios;
}

TEST(ImpulseContact, RockingBlockLosesHousnersFractionEachLanding) {
  double expected = 0.0;
  // Sweeps enough to converge the impact: the rigid-body answer.
  const std::vector<double> converged = rocking_height_ratios(128, 3, expected);
  // The default sweeps (16 a step): Jacobi sweeps that have not converged the impact keep a
  // little more (measured 0.760, 0.752, 0.756 against 0.729).
  const std::vector<double> plain = rocking_height_ratios(16, 3, expected);
  ASSERT_EQ(converged.size(), 3u);
  ASSERT_EQ(plain.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    std::printf(
        "rocking block, landing %d: height kept %.4f (128 sweeps), %.4f (16); Housner %.4f\n",
        k + 1, converged[k], plain[k], expected);
    EXPECT_NEAR(converged[k], expected, 0.02 * expected);
    EXPECT_NEAR(plain[k], expected, 0.06 * expected);
  }
  // Seeded blocks 2 to 4 particles wide and 4 to 8 high, leaning 0.5 to 0.9 of their tipping
  // angle: converged, each landing keeps Housner's fraction within 2% (measured at most 1.7%);
  // with the default sweeps a landing never gains energy. It keeps more than a rigid body the
  // wider the base (2 wide: within 1.4%; 3: 2 to 8% more; 4 x 6: 18%; 4 x 5: up to 37%).
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int seed = 0; seed < 12; ++seed) {
    const int nx = 2 + static_cast<int>(rng() % 3), ny = 4 + static_cast<int>(rng() % 5);
    const double lean = 0.5 + 0.4 * unit(rng);
    double housner = 0.0;
    const std::vector<double> c = rocking_height_ratios(128, 3, housner, nx, ny, lean);
    const std::vector<double> d = rocking_height_ratios(16, 3, housner, nx, ny, lean);
    ASSERT_EQ(c.size(), 3u) << "seed " << seed;
    ASSERT_EQ(d.size(), 3u) << "seed " << seed;
    std::printf(
        "seed %2d, %d x %d leaning %.2f: Housner %.4f; kept %.4f %.4f %.4f (128 sweeps), "
        "%.4f %.4f %.4f (16)\n",
        seed, nx, ny, lean, housner, c[0], c[1], c[2], d[0], d[1], d[2]);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(c[k], housner, 0.02 * housner) << "seed " << seed << " landing " << k + 1;
      EXPECT_LT(d[k], 1.0) << "seed " << seed << " landing " << k + 1;
    }
  }
}

TEST(ImpulseContact, CollisionWithoutGravityKeepsMomentum) {
  motes::Scene scene = impulse_scene(1e-3, Eigen::Vector3d::Zero(), 0.5, 0.4);
  motes_test::add_colliding_boxes(scene);
  auto sim = motes_test::simulate(scene);
  ASSERT_TRUE(sim) << sim.status().message();
  auto before = (*sim)->snapshot();
  ASSERT_TRUE((*sim)->step(150));
  auto after = (*sim)->snapshot();
  // They did collide: both changed velocity.
  EXPECT_GT((to_vec3(after->body_vel[0]) - to_vec3(before->body_vel[0])).norm(), 0.1);
  const Eigen::Vector3d p0 = motes_test::linear_momentum(*before);
  const Eigen::Vector3d p1 = motes_test::linear_momentum(*after);
  EXPECT_LT((p1 - p0).norm(), 1e-6 * p0.norm()) << p0.transpose() << " -> " << p1.transpose();
}

}  // namespace
