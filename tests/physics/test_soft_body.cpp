// Soft bodies by shape matching (Mueller et al. 2005) against answers that do not come from motes
// (docs/validation.md, "Soft bodies"):
//  - a soft body placed moved and rotated rigidly stays undeformed: its goal is its current shape
//    (every particle within 1e-6 m after 100 substeps at rest; pair distances of a spinning one
//    within 1e-6 relative);
//  - linear momentum of a free, spinning and moving soft body is conserved to 1e-6 relative in
//    every mode, with internal damping on (it acts on velocities relative to the rigid motion);
//  - its angular momentum about the centre of mass to 1e-4 relative, where the method's own loss
//    is (w dt)^2 / 2 per substep (a projected step's velocity is a chord of the turn: 1.1e-5 here)
//    and float rounding of the velocities 4e-7;
//  - a beam split into overlapping clusters sags where one cluster stays straight;
//  - a stretched body recovers at the rate alpha predicts: with the goal fixed (a symmetric
//    stretch keeps R = 1 and the centre), each particle's error e and step u = v dt follow
//    e' = (1 - a)(e + u), u' = e' - e, whose 2 x 2 matrix power gives e after n substeps;
//  - degenerate rest shapes (one particle, a line, a plane) and an inverted body never give NaN,
//    and the rotation extraction (shared/shape_matching.h: polar_rotation) returns a unit
//    quaternion for zero, rank-1, rank-2, reflected and huge matrices;
//  - a soft box dropped on the floor comes to rest (no creep).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "motes/soft.h"
#include "physics/physics_scenes.h"
#include "shared/shape_matching.h"

namespace {

using motes::shared::vec4;
using motes_test::to_vec3;

constexpr double kDiameter = 0.01;

motes::Material soft_material() { return motes_test::material(1000.0, 1.0e4, 1.0e4, 4.0e4, 0.5); }

motes::Scene soft_scene(double dt, const Eigen::Vector3d& gravity = Eigen::Vector3d::Zero()) {
  return motes_test::scene_with(dt, gravity, soft_material(), true);
}

motes::SoftSpec soft_spec(double stiffness, motes::SoftMode mode = motes::SoftMode::Rigid,
                          double beta = 0.0) {
  motes::SoftSpec s;
  s.stiffness = stiffness;
  s.mode = mode;
  s.beta = beta;
  return s;
}

motes::BodySpec soft_box(int nx, int ny, int nz, const motes::SoftSpec& soft,
                         const Eigen::Vector3d& at,
                         const Eigen::Vector3d& v = Eigen::Vector3d::Zero(),
                         const Eigen::Vector3d& w = Eigen::Vector3d::Zero(),
                         const Eigen::Quaterniond& rot = Eigen::Quaterniond::Identity()) {
  motes::BodySpec b = motes_test::body(motes_test::lattice(nx, ny, nz, kDiameter), at, v, w, rot);
  b.name = "soft";
  b.soft = soft;
  return b;
}

std::vector<Eigen::Vector3d> positions(const motes::Snapshot& s) {
  std::vector<Eigen::Vector3d> x;
  for (const vec4& p : s.particle_pos) x.push_back(to_vec3(p));
  return x;
}

struct Momenta {
  Eigen::Vector3d linear = Eigen::Vector3d::Zero();
  Eigen::Vector3d spin = Eigen::Vector3d::Zero();  // angular momentum about the centre of mass
};

Momenta momenta(const motes::Snapshot& s, double particle_mass) {
  Momenta m;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const vec4& x : s.particle_pos) centre += to_vec3(x);
  centre /= static_cast<double>(s.particle_pos.size());
  for (std::size_t i = 0; i < s.particle_pos.size(); ++i) {
    const Eigen::Vector3d x = to_vec3(s.particle_pos[i]) - centre;
    const Eigen::Vector3d v = to_vec3(s.particle_vel[i]);
    m.linear += particle_mass * v;
    m.spin += particle_mass * x.cross(v);
  }
  return m;
}

Eigen::Quaterniond tilt() {
  return Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()));
}

TEST(SoftBody, RigidlyPlacedBodyStaysUndeformed) {
  for (const motes::SoftMode mode :
       {motes::SoftMode::Rigid, motes::SoftMode::Linear, motes::SoftMode::Quadratic}) {
    SCOPED_TRACE(static_cast<int>(mode));
    motes::Scene scene = soft_scene(1.0e-4);
    motes::SoftSpec soft = soft_spec(1.0, mode, mode == motes::SoftMode::Rigid ? 0.0 : 0.5);
    soft.clusters = {2, 2, 1};
    scene.bodies.push_back(soft_box(5, 4, 3, soft, Eigen::Vector3d(0.3, -0.2, 0.1),
                                    Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), tilt()));
    auto sim = motes_test::simulate(scene);
    ASSERT_TRUE(sim) << sim.message();
    const auto before = positions((*sim)->snapshot().value());
    ASSERT_TRUE((*sim)->step(100));
    const auto after = positions((*sim)->snapshot().value());
    double moved = 0.0;
    for (std::size_t i = 0; i < before.size(); ++i) {
      moved = std::max(moved, (after[i] - before[i]).norm());
    }
    std::printf("[soft] mode %d: largest move of a rigidly placed body %.3g m\n",
                static_cast<int>(mode), moved);
    EXPECT_LT(moved, 1e-6);
  }
}

TEST(SoftBody, SpinningRigidGoalKeepsTheShape) {
  motes::Scene scene = soft_scene(1.0e-4);
  scene.bodies.push_back(soft_box(5, 4, 3, soft_spec(1.0), Eigen::Vector3d(0.0, 0.0, 0.0),
                                  Eigen::Vector3d(0.2, 0.0, 0.0), Eigen::Vector3d(2.0, -1.0, 3.0),
                                  tilt()));
  auto sim = motes_test::simulate(scene);
  ASSERT_TRUE(sim);
  const auto before = positions((*sim)->snapshot().value());
  ASSERT_TRUE((*sim)->step(1000));
  const auto after = positions((*sim)->snapshot().value());
  double worst = 0.0;
  for (std::size_t i = 0; i < before.size(); ++i) {
    for (std::size_t j = i + 1; j < before.size(); ++j) {
      const double d0 = (before[i] - before[j]).norm();
      worst = std::max(worst, std::abs((after[i] - after[j]).norm() - d0) / d0);
    }
  }
  std::printf("[soft] spinning rigid goal: worst pair distance change %.3g relative\n", worst);
  EXPECT_LT(worst, 1e-6);
  // It turned: about 3.7 rad/s for 0.1 s.
  EXPECT_GT((after[0] - before[0] - Eigen::Vector3d(0.02, 0.0, 0.0)).norm(), 5e-3);
}

/// Momenta of a free 6 x 4 x 3 soft box (alpha 0.3, beta 0.5 unless rigid, two clusters,
/// damping 50/s) at the start and after `steps` substeps of 1e-4 s.
struct FreeRun {
  Momenta before;
  Momenta after;
  double mass = 0.0;
};

FreeRun free_soft_box(motes::SoftMode mode, const Eigen::Vector3d& at, const Eigen::Vector3d& v,
                      const Eigen::Vector3d& w, std::uint64_t steps) {
  motes::Scene scene = soft_scene(1.0e-4);
  motes::SoftSpec soft = soft_spec(0.3, mode, mode == motes::SoftMode::Rigid ? 0.0 : 0.5);
  soft.clusters = {2, 1, 1};
  soft.damping = 50.0;
  scene.bodies.push_back(soft_box(6, 4, 3, soft, at, v, w, tilt()));
  FreeRun run;
  auto sim = motes_test::simulate(scene);
  EXPECT_TRUE(sim) << sim.message();
  if (!sim) return run;
  run.mass = (*sim)->bodies()[0].mass;
  run.before = momenta((*sim)->snapshot().value(), run.mass / 72.0);
  EXPECT_TRUE((*sim)->step(steps));
  run.after = momenta((*sim)->snapshot().value(), run.mass / 72.0);
  return run;
}

TEST(SoftBody, FreeBodyConservesLinearMomentum) {
  for (const motes::SoftMode mode :
       {motes::SoftMode::Rigid, motes::SoftMode::Linear, motes::SoftMode::Quadratic}) {
    SCOPED_TRACE(static_cast<int>(mode));
    const FreeRun r =
        free_soft_box(mode, Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Vector3d(0.5, -0.2, 0.1),
                      Eigen::Vector3d(3.0, -2.0, 5.0), 2000);
    const double change = (r.after.linear - r.before.linear).norm();
    std::printf("[soft] mode %d: momentum change %.3g relative\n", static_cast<int>(mode),
                change / r.before.linear.norm());
    EXPECT_LT(change, 1e-6 * r.before.linear.norm());
  }
}

TEST(SoftBody, FreeBodyConservesAngularMomentum) {
  for (const motes::SoftMode mode :
       {motes::SoftMode::Rigid, motes::SoftMode::Linear, motes::SoftMode::Quadratic}) {
    SCOPED_TRACE(static_cast<int>(mode));
    const FreeRun r = free_soft_box(mode, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                    Eigen::Vector3d(1.0, -0.5, 1.0), 1000);
    const double change = (r.after.spin - r.before.spin).norm();
    std::printf("[soft] mode %d: angular momentum change %.3g relative\n", static_cast<int>(mode),
                change / r.before.spin.norm());
    EXPECT_LT(change, 1e-4 * r.before.spin.norm());
    EXPECT_LT(r.after.linear.norm(), 1e-6 * r.mass * 0.01);  // at rest: below 1e-6 of 1 cm/s
  }
}

TEST(SoftBody, StretchedBodyRecoversAtTheRateAlphaPredicts) {
  for (const double alpha : {0.1, 0.5}) {
    SCOPED_TRACE(alpha);
    motes::Scene scene = soft_scene(1.0e-4);
    scene.bodies.push_back(soft_box(4, 4, 4, soft_spec(alpha), Eigen::Vector3d::Zero()));
    auto sim = motes_test::simulate(scene);
    ASSERT_TRUE(sim);
    // Stretch by 10% along x about the centre (symmetric: R stays 1, the centre stays put).
    std::vector<vec4> pos = (*sim)->snapshot().value().particle_pos;
    std::vector<Eigen::Vector3d> rest = positions((*sim)->snapshot().value());
    for (vec4& p : pos) p.x *= 1.1f;
    ASSERT_TRUE((*sim)->device().write(motes::Buffer::ParticlePos, pos.data(), pos.size() * 16));
    Eigen::Matrix2d step;  // (e, u) -> (e', u')
    step << 1.0 - alpha, 1.0 - alpha, -alpha, 1.0 - alpha;
    Eigen::Vector2d state(1.0, 0.0);  // e / e0, u / e0
    double worst = 0.0;
    for (int n = 1; n <= 40; ++n) {
      ASSERT_TRUE((*sim)->step(1));
      state = step * state;
      const auto x = positions((*sim)->snapshot().value());
      for (std::size_t i = 0; i < x.size(); ++i) {
        const double e0 = 0.1 * static_cast<double>(static_cast<float>(rest[i].x()));
        if (std::abs(e0) < 1e-3) continue;
        const double got = (x[i].x() - rest[i].x()) / e0;
        worst = std::max(worst, std::abs(got - state[0]));
        ASSERT_NEAR(got, state[0], 1e-4) << "particle " << i << " substep " << n;
      }
    }
    std::printf("[soft] alpha %.1f: recovery vs the recurrence, worst %.3g of the stretch\n", alpha,
                worst);
  }
}

TEST(SoftBody, RotationExtractionNeverGivesNaN) {
  using motes::shared::Mat3;
  using motes::shared::vec3;
  const auto unit = [](const vec4& q) {
    const double n = std::sqrt(static_cast<double>(motes::shared::dot(q, q)));
    return std::isfinite(n) && std::abs(n - 1.0) < 1e-5;
  };
  const vec4 start(0.0f, 0.0f, 0.0f, 1.0f);
  const auto mat = [](vec3 a, vec3 b, vec3 c) {
    Mat3 m;
    m.c0 = a;
    m.c1 = b;
    m.c2 = c;
    return m;
  };
  const vec3 o(0.0f);
  // Zero, a line (rank 1), a plane (rank 2), a reflection, an inversion, huge and tiny scales.
  const Mat3 cases[] = {
      mat(o, o, o),
      mat(vec3(1.0f, 2.0f, 3.0f), o, o),
      mat(vec3(1.0f, 0.0f, 0.0f), vec3(0.0f, 0.5f, 0.0f), o),
      mat(vec3(-1.0f, 0.0f, 0.0f), vec3(0.0f, 1.0f, 0.0f), vec3(0.0f, 0.0f, 1.0f)),
      mat(vec3(-1.0f, 0.0f, 0.0f), vec3(0.0f, -1.0f, 0.0f), vec3(0.0f, 0.0f, -1.0f)),
      mat(vec3(1e30f, 0.0f, 0.0f), vec3(0.0f, 1e30f, 0.0f), vec3(0.0f, 0.0f, 1e30f)),
      mat(vec3(1e-30f, 0.0f, 0.0f), vec3(0.0f, 1e-30f, 0.0f), vec3(0.0f, 0.0f, 1e-30f)),
  };
  for (const Mat3& m : cases) EXPECT_TRUE(unit(motes::shared::polar_rotation(m, start)));
  // A pure rotation is found exactly (to float) from identity.
  const Eigen::Matrix3d r = tilt().toRotationMatrix();
  const auto col = [&](int k) {
    return vec3(static_cast<float>(r(0, k)), static_cast<float>(r(1, k)),
                static_cast<float>(r(2, k)));
  };
  const vec4 q = motes::shared::polar_rotation(mat(col(0), col(1), col(2)), start);
  const Eigen::Quaterniond found(static_cast<double>(q.w), static_cast<double>(q.x),
                                 static_cast<double>(q.y), static_cast<double>(q.z));
  EXPECT_LT(found.angularDistance(tilt()), 1e-5);
}

TEST(SoftBody, DegenerateAndInvertedBodiesStayFinite) {
  motes::Scene scene = soft_scene(1.0e-4, Eigen::Vector3d(0.0, -9.81, 0.0));
  scene.planes.push_back(motes_test::plane({0, 1, 0}, {0, 0, 0}));
  for (const motes::SoftMode mode :
       {motes::SoftMode::Rigid, motes::SoftMode::Linear, motes::SoftMode::Quadratic}) {
    const motes::SoftSpec s = soft_spec(0.5, mode, mode == motes::SoftMode::Rigid ? 0.0 : 1.0);
    const double x = 0.2 * static_cast<double>(scene.bodies.size());
    scene.bodies.push_back(soft_box(1, 1, 1, s, Eigen::Vector3d(x, 0.05, 0.0)));  // one particle
    scene.bodies.push_back(soft_box(8, 1, 1, s, Eigen::Vector3d(x, 0.1, 0.1)));   // a line
    scene.bodies.push_back(soft_box(5, 1, 5, s, Eigen::Vector3d(x, 0.2, 0.3)));   // a plane
    scene.bodies.push_back(soft_box(4, 4, 4, s, Eigen::Vector3d(x, 0.3, 0.6)));   // inverted below
  }
  auto sim = motes_test::simulate(scene);
  ASSERT_TRUE(sim) << sim.message();
  // Invert every 4 x 4 x 4 box through its centre (a reflection: det A < 0).
  motes::Snapshot state = (*sim)->snapshot().value();
  std::vector<vec4> pos = state.particle_pos;
  for (std::size_t b = 0; b < (*sim)->bodies().size(); ++b) {
    const motes::BodyInfo& info = (*sim)->bodies()[b];
    if (info.particle_count != 64) continue;
    const Eigen::Vector3d c = to_vec3(state.body_pos[b]);
    for (std::uint32_t i = info.first_particle; i < info.first_particle + 64; ++i) {
      pos[i].x = static_cast<float>(2.0 * c.x()) - pos[i].x;
    }
  }
  ASSERT_TRUE((*sim)->device().write(motes::Buffer::ParticlePos, pos.data(), pos.size() * 16));
  ASSERT_TRUE((*sim)->step(3000));
  EXPECT_TRUE((*sim)->check_finite());
  const motes::Snapshot end = (*sim)->snapshot().value();
  for (const vec4& p : end.particle_pos) {
    ASSERT_GT(p.y, -0.01f);  // on the floor, not through it
  }
}

TEST(SoftBody, ClustersLetABeamBend) {
  // A 24 x 2 x 2 beam dropped across two static posts 20 cm apart: as one rigid-goal cluster it
  // stays straight, with 6 overlapping clusters its middle sags.
  const auto sag = [](int clusters) {
    motes::Scene scene = soft_scene(2.0e-5, Eigen::Vector3d(0.0, -9.81, 0.0));
    motes::SoftSpec soft = soft_spec(0.02, motes::SoftMode::Rigid);
    soft.clusters = {clusters, 1, 1};
    scene.bodies.push_back(soft_box(24, 2, 2, soft, Eigen::Vector3d(0.0, 0.021, 0.0)));
    for (const double x : {-0.1, 0.1}) {
      motes::BodySpec post =
          motes_test::body(motes_test::lattice(1, 1, 2, kDiameter), Eigen::Vector3d(x, 0.0, 0.0));
      post.kind = motes::BodyKind::Static;
      scene.bodies.push_back(post);
    }
    auto sim = motes_test::simulate(scene);
    EXPECT_TRUE(sim) << sim.message();
    EXPECT_TRUE((*sim)->step(10000));
    const motes::Snapshot s = (*sim)->snapshot().value();
    const auto x = positions(s);
    double middle = 0.0;
    double ends = 0.0;
    for (std::size_t i = 0; i < 96; ++i) {
      const std::size_t column = i % 24;
      if (column == 11 || column == 12) middle += x[i].y() / 8.0;
      if (column == 0 || column == 23) ends += x[i].y() / 8.0;
    }
    return ends - middle;
  };
  const double one = sag(1);
  const double six = sag(6);
  // Measured: 0 and 0.12 mm (a stiff beam: alpha 0.02 per substep at 50,000 substeps a second).
  std::printf("[soft] beam sag: one cluster %.3g m, six %.3g m\n", one, six);
  EXPECT_LT(std::abs(one), 1e-5);
  EXPECT_GT(six, 5e-5) << "one cluster " << one << " m, six " << six << " m";
}

TEST(SoftBody, BoxDroppedOnTheFloorComesToRest) {
  motes::Scene scene = soft_scene(1.5e-5, Eigen::Vector3d(0.0, -9.81, 0.0));
  scene.planes.push_back(motes_test::plane({0, 1, 0}, {0, 0, 0}));
  scene.bodies.push_back(soft_box(5, 5, 5, soft_spec(0.2, motes::SoftMode::Linear, 0.3),
                                  Eigen::Vector3d(0.0, 0.06, 0.0), Eigen::Vector3d::Zero(),
                                  Eigen::Vector3d::Zero(), tilt()));
  auto sim = motes_test::simulate(scene);
  ASSERT_TRUE(sim);
  ASSERT_TRUE((*sim)->step(40000));  // 0.6 s
  const Eigen::Vector3d c0 = to_vec3((*sim)->snapshot().value().body_pos[0]);
  ASSERT_TRUE((*sim)->step(20000));  // 0.3 s more
  const Eigen::Vector3d c1 = to_vec3((*sim)->snapshot().value().body_pos[0]);
  std::printf("[soft] box on the floor: moved %.3g m in 0.3 s, centre at %.4f m\n",
              (c1 - c0).norm(), c1.y());
  EXPECT_LT((c1 - c0).norm(), 1e-4) << "crept from " << c0.transpose() << " to " << c1.transpose();
  EXPECT_GT(c1.y(), 0.015);  // resting on the floor, not through it
}

}  // namespace
