// Mass, centre and inertia from particles, against closed forms.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "motes/shapes.h"
#include "unit/test_support.h"

namespace motes {
namespace {

using motes_test::box_mesh;

/// Inertia of a solid box of the given mass and size about its centre, in its own axes.
Eigen::Matrix3d solid_box_inertia(double mass, const Eigen::Vector3d& s) {
  return Eigen::Vector3d(s.y() * s.y() + s.z() * s.z(), s.x() * s.x() + s.z() * s.z(),
                         s.x() * s.x() + s.y() * s.y())
             .asDiagonal() *
         (mass / 12.0);
}

double relative_error(const Eigen::Matrix3d& got, const Eigen::Matrix3d& expected) {
  return (got - expected).norm() / expected.norm();
}

/// Checks that `mp.principal_frame` is a proper rotation that diagonalizes the inertia into
/// the principal moments.
void expect_consistent_frame(const MassProperties& mp) {
  const Eigen::Matrix3d r = mp.principal_frame.toRotationMatrix();
  EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  const Eigen::Matrix3d diagonal = r.transpose() * mp.inertia * r;
  const Eigen::Matrix3d expected = mp.principal_moments.asDiagonal();
  EXPECT_LT((diagonal - expected).norm(), 1e-9 * mp.inertia.norm());
  EXPECT_LE(mp.principal_moments[0], mp.principal_moments[1]);
  EXPECT_LE(mp.principal_moments[1], mp.principal_moments[2]);
}

TEST(MassProperties, VoxelizedBoxMatchesTheSolidBox) {
  const double d = 0.05;
  const double density = 700.0;
  const Eigen::Vector3d size(20 * d, 16 * d, 24 * d);
  const Eigen::Vector3d offset(1.5, -0.25, 4.0);
  VoxelizeOptions options;
  options.diameter = d;
  auto particles = voxelize(box_mesh(size, Eigen::Matrix3d::Identity(), offset), options);
  ASSERT_TRUE(particles) << particles.message();
  ASSERT_EQ(particles->points.size(), 20U * 16U * 24U);
  const MassProperties mp = mass_properties(*particles, density);
  const double mass = density * size.prod();
  EXPECT_NEAR(mp.particle_mass, density * d * d * d, 1e-12 * mp.particle_mass);
  EXPECT_NEAR(mp.mass / mass, 1.0, 1e-12);
  EXPECT_LT((mp.center - offset).norm(), 1e-5);
  EXPECT_LT(relative_error(mp.inertia, solid_box_inertia(mass, size)), 0.02);
  // Principal moments ascending: z (a^2 + b^2), x (b^2 + c^2), y (a^2 + c^2).
  const Eigen::Matrix3d r = mp.principal_frame.toRotationMatrix();
  EXPECT_GT(std::abs(r.col(0).dot(Eigen::Vector3d::UnitZ())), 0.9999);
  EXPECT_GT(std::abs(r.col(1).dot(Eigen::Vector3d::UnitX())), 0.9999);
  EXPECT_GT(std::abs(r.col(2).dot(Eigen::Vector3d::UnitY())), 0.9999);
  expect_consistent_frame(mp);
}

TEST(MassProperties, RotatedBoxHasRotatedPrincipalAxes) {
  const double d = 0.05;
  const double density = 1200.0;
  const Eigen::Vector3d size(20 * d, 16 * d, 24 * d);
  for (const auto& axis : {Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(-2, 0.5, 1)}) {
    const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, axis.normalized()).toRotationMatrix();
    VoxelizeOptions options;
    options.diameter = d;
    auto particles = voxelize(box_mesh(size, rotation, Eigen::Vector3d(0.3, 0.2, -0.1)), options);
    ASSERT_TRUE(particles) << particles.message();
    const MassProperties mp = mass_properties(*particles, density);
    const double mass = density * size.prod();
    EXPECT_NEAR(mp.mass / mass, 1.0, 0.02);
    const Eigen::Matrix3d expected =
        rotation * solid_box_inertia(mass, size) * rotation.transpose();
    EXPECT_LT(relative_error(mp.inertia, expected), 0.02);
    const Eigen::Vector3d moments = solid_box_inertia(mass, size).diagonal();
    // Box axes in order of ascending moment: z, x, y.
    const std::array<int, 3> order = {2, 0, 1};
    const Eigen::Matrix3d frame = mp.principal_frame.toRotationMatrix();
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(mp.principal_moments[k] / moments[order[k]], 1.0, 0.02);
      EXPECT_GT(std::abs(frame.col(k).dot(rotation.col(order[k]))), 0.995) << "axis " << k;
    }
    expect_consistent_frame(mp);
  }
}

TEST(MassProperties, SingleParticleIsASolidSphere) {
  ParticleSet one;
  one.diameter = 0.02;
  one.points = {Eigen::Vector3f(1.0F, 2.0F, 3.0F)};
  const MassProperties mp = mass_properties(one, 1000.0);
  const double m = 1000.0 * 0.02 * 0.02 * 0.02;
  EXPECT_DOUBLE_EQ(mp.mass, m);
  EXPECT_LT((mp.center - Eigen::Vector3d(1, 2, 3)).norm(), 1e-6);
  const Eigen::Matrix3d expected = Eigen::Matrix3d::Identity() * (0.4 * m * 0.01 * 0.01);
  EXPECT_LT(relative_error(mp.inertia, expected), 1e-12);
  expect_consistent_frame(mp);
}

TEST(MassProperties, FlatAndCollinearSetsAreNotSingular) {
  const double d = 0.01;
  const double density = 500.0;
  const double m = density * d * d * d;
  const double sphere = 0.4 * m * 0.25 * d * d;
  // Sum over a centred lattice of n points of (i - (n-1)/2)^2 = n (n^2 - 1) / 12.
  auto line_sum = [](int n) { return n * (n * n - 1) / 12.0; };

  auto line = box_lattice({10, 1, 1}, d);
  ASSERT_TRUE(line) << line.message();
  const MassProperties line_mp = mass_properties(*line, density);
  EXPECT_NEAR(line_mp.principal_moments[0], 10 * sphere, 1e-9 * sphere);
  EXPECT_NEAR(line_mp.inertia(0, 0), 10 * sphere, 1e-9 * sphere);
  // Particle positions are floats: 1e-6 relative covers their rounding.
  const double line_yy = m * d * d * line_sum(10) + 10 * sphere;
  EXPECT_NEAR(line_mp.inertia(1, 1), line_yy, 1e-6 * line_yy);
  EXPECT_GT(line_mp.inertia.determinant(), 0.0);
  expect_consistent_frame(line_mp);

  auto plate = box_lattice({10, 1, 6}, d);
  ASSERT_TRUE(plate) << plate.message();
  const MassProperties plate_mp = mass_properties(*plate, density);
  const double xx = m * d * d * 6 * line_sum(10);  // sum m x^2
  const double zz = m * d * d * 10 * line_sum(6);  // sum m z^2
  const double n = 60.0;
  EXPECT_NEAR(plate_mp.inertia(0, 0), zz + n * sphere, 1e-6 * xx);
  EXPECT_NEAR(plate_mp.inertia(1, 1), xx + zz + n * sphere, 1e-6 * xx);
  EXPECT_NEAR(plate_mp.inertia(2, 2), xx + n * sphere, 1e-6 * xx);
  EXPECT_NEAR(plate_mp.inertia(0, 2), 0.0, 1e-6 * xx);
  EXPECT_GT(plate_mp.principal_moments[0], 0.0);
  expect_consistent_frame(plate_mp);
}

TEST(MassProperties, PrincipalFrameIsAlwaysAProperRotation) {
  // Random-looking point sets whose eigen solver output can come out as a reflection.
  for (int seed = 1; seed <= 20; ++seed) {
    ParticleSet set;
    set.diameter = 0.1;
    unsigned state = static_cast<unsigned>(seed) * 2654435761U;
    auto next = [&state]() {
      state = state * 1664525U + 1013904223U;
      return static_cast<float>(state >> 8) / 16777216.0F - 0.5F;
    };
    for (int i = 0; i < 50; ++i) set.points.emplace_back(next(), 2.0F * next(), 0.5F * next());
    const MassProperties mp = mass_properties(set, 1000.0);
    expect_consistent_frame(mp);
  }
}

TEST(MassProperties, SphereParticlesHaveSphereInertia) {
  const double d = 0.01;
  const double radius = 10 * d;
  auto sphere = sphere_particles(radius, d);
  ASSERT_TRUE(sphere) << sphere.message();
  const MassProperties mp = mass_properties(*sphere, 1000.0);
  const double solid = 0.4 * mp.mass * radius * radius;
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(mp.principal_moments[k] / solid, 1.0, 0.03);
  EXPECT_LT(mp.center.norm(), 1e-6);
}

}  // namespace
}  // namespace motes
