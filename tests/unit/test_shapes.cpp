// Primitive shapes: exact lattice counts, volumes of curved shapes, parameter errors.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <set>
#include <string>
#include <tuple>

#include "motes/shapes.h"

namespace motes {
namespace {

double particle_volume(const ParticleSet& set) {
  return static_cast<double>(set.points.size()) * std::pow(set.diameter, 3);
}

Eigen::Vector3d centroid(const ParticleSet& set) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& p : set.points) sum += p.cast<double>();
  return sum / static_cast<double>(set.points.size());
}

/// Lattice indices of the points (position / d - offset, rounded), with a check that every point
/// lies on the lattice.
std::set<std::tuple<long, long, long>> lattice_indices(const ParticleSet& set,
                                                       const Eigen::Vector3d& offset) {
  std::set<std::tuple<long, long, long>> out;
  for (const auto& p : set.points) {
    const Eigen::Vector3d q = p.cast<double>() / set.diameter - offset;
    const Eigen::Vector3d r = q.array().round();
    EXPECT_LT((q - r).cwiseAbs().maxCoeff(), 1e-4) << "point off the lattice: " << p.transpose();
    out.emplace(std::lround(r.x()), std::lround(r.y()), std::lround(r.z()));
  }
  return out;
}

TEST(BoxParticles, CubeOfNCellsGivesExactlyNCubed) {
  for (const double d : {0.01, 0.1, 0.003, 0.25, 1.0 / 3.0}) {
    for (const int n : {1, 2, 3, 7, 10, 13, 20}) {
      const double side = n * d;
      auto box = box_particles(Eigen::Vector3d::Constant(side), d);
      ASSERT_TRUE(box) << box.message();
      EXPECT_EQ(box->points.size(), static_cast<std::size_t>(n * n * n)) << "n " << n << " d " << d;
      EXPECT_EQ(box->diameter, d);
      // Distinct lattice points, all inside the box, centred on the origin.
      const double offset = n % 2 == 0 ? 0.5 : 0.0;
      EXPECT_EQ(lattice_indices(*box, Eigen::Vector3d::Constant(offset)).size(),
                box->points.size());
      for (const auto& p : box->points) {
        EXPECT_LE(p.cast<double>().cwiseAbs().maxCoeff(), 0.5 * side - 0.5 * d + 1e-6);
      }
      EXPECT_LT(centroid(*box).norm(), 1e-6 * (1.0 + side));
    }
  }
}

TEST(BoxParticles, NonCubicBoxAndPartialCells) {
  const double d = 0.02;
  auto box = box_particles({3 * d, 5 * d, 7 * d}, d);
  ASSERT_TRUE(box) << box.message();
  EXPECT_EQ(box->points.size(), 105U);
  // Only whole cells that fit: 2.5 cells -> 2, 4.99 cells -> 4.
  auto partial = box_particles({2.5 * d, 4.99 * d, 1.0 * d}, d);
  ASSERT_TRUE(partial) << partial.message();
  EXPECT_EQ(partial->points.size(), 8U);
}

TEST(BoxLattice, ExactCountsAndSpacing) {
  const double d = 0.05;
  auto lattice = box_lattice({4, 1, 3}, d);
  ASSERT_TRUE(lattice) << lattice.message();
  ASSERT_EQ(lattice->points.size(), 12U);
  const auto indices = lattice_indices(*lattice, {0.5, 0.0, 0.0});
  EXPECT_EQ(indices.size(), 12U);
  EXPECT_EQ(std::get<0>(*indices.begin()), -2);
  EXPECT_EQ(std::get<0>(*indices.rbegin()), 1);
  EXPECT_LT(centroid(*lattice).norm(), 1e-7);
}

TEST(SphereParticles, VolumeWithinThreePercentAtTenDiameters) {
  for (const double d : {0.01, 0.037}) {
    const double radius = 10.0 * d;
    auto sphere = sphere_particles(radius, d);
    ASSERT_TRUE(sphere) << sphere.message();
    const double exact = 4.0 / 3.0 * std::numbers::pi * std::pow(radius, 3);
    EXPECT_NEAR(particle_volume(*sphere) / exact, 1.0, 0.03);
    for (const auto& p : sphere->points) EXPECT_LE(p.cast<double>().norm(), radius * (1 + 1e-6));
    EXPECT_LT(centroid(*sphere).norm(), 1e-6 * radius);
    EXPECT_EQ(lattice_indices(*sphere, Eigen::Vector3d::Zero()).size(), sphere->points.size());
  }
}

TEST(SphereParticles, SmallestSphereIsOneParticle) {
  auto sphere = sphere_particles(0.005, 0.01);
  ASSERT_TRUE(sphere) << sphere.message();
  EXPECT_EQ(sphere->points.size(), 1U);
}

TEST(CylinderParticles, VolumeAndAxisAlongY) {
  const double d = 0.01;
  const double radius = 10 * d;
  const double height = 20 * d;
  auto cylinder = cylinder_particles(radius, height, d);
  ASSERT_TRUE(cylinder) << cylinder.message();
  const double exact = std::numbers::pi * radius * radius * height;
  EXPECT_NEAR(particle_volume(*cylinder) / exact, 1.0, 0.03);
  for (const auto& p : cylinder->points) {
    EXPECT_LE(std::hypot(p.x(), p.z()), radius * (1 + 1e-6));
    EXPECT_LE(std::abs(p.y()), 0.5 * height);
  }
  EXPECT_LT(centroid(*cylinder).norm(), 1e-6);
}

TEST(CapsuleParticles, VolumeAndAxisAlongY) {
  const double d = 0.01;
  const double radius = 10 * d;
  const double height = 15 * d;
  auto capsule = capsule_particles(radius, height, d);
  ASSERT_TRUE(capsule) << capsule.message();
  const double exact = std::numbers::pi * radius * radius * (height + 4.0 / 3.0 * radius);
  EXPECT_NEAR(particle_volume(*capsule) / exact, 1.0, 0.03);
  float top = 0.0F;
  for (const auto& p : capsule->points) {
    const double beyond = std::max(0.0, std::abs(static_cast<double>(p.y())) - 0.5 * height);
    EXPECT_LE(std::hypot(std::hypot(p.x(), p.z()), beyond), radius * (1 + 1e-6));
    top = std::max(top, p.y());
  }
  EXPECT_NEAR(top, 0.5 * height + radius, d);
  EXPECT_LT(centroid(*capsule).norm(), 1e-6);
}

class PrimitiveRejects : public ::testing::TestWithParam<double> {};

TEST_P(PrimitiveRejects, InvalidSizesAndDiameters) {
  const double bad = GetParam();
  const double d = 0.01;
  const auto expect_error = [](const Result<ParticleSet>& r, const std::string& field) {
    ASSERT_FALSE(r) << field;
    EXPECT_NE(r.message().find(field), std::string::npos) << r.message();
    EXPECT_NE(r.message().find("positive"), std::string::npos) << r.message();
  };
  expect_error(box_particles({bad, 0.1, 0.1}, d), "box size x");
  expect_error(box_particles({0.1, 0.1, bad}, d), "box size z");
  expect_error(box_particles({0.1, 0.1, 0.1}, bad), "box particle diameter");
  expect_error(box_lattice({2, 2, 2}, bad), "box lattice particle diameter");
  expect_error(sphere_particles(bad, d), "sphere radius");
  expect_error(sphere_particles(0.1, bad), "sphere particle diameter");
  expect_error(cylinder_particles(bad, 0.1, d), "cylinder radius");
  expect_error(cylinder_particles(0.1, bad, d), "cylinder height");
  expect_error(cylinder_particles(0.1, 0.1, bad), "cylinder particle diameter");
  expect_error(capsule_particles(bad, 0.1, d), "capsule radius");
  expect_error(capsule_particles(0.1, bad, d), "capsule height");
  expect_error(capsule_particles(0.1, 0.1, bad), "capsule particle diameter");
}

INSTANTIATE_TEST_SUITE_P(Values, PrimitiveRejects,
                         ::testing::Values(0.0, -0.1, std::numeric_limits<double>::quiet_NaN(),
                                           std::numeric_limits<double>::infinity(),
                                           -std::numeric_limits<double>::infinity()));

TEST(PrimitiveErrors, ShapeSmallerThanOneParticle) {
  auto sphere = sphere_particles(0.001, 0.01);
  ASSERT_FALSE(sphere);
  EXPECT_NE(sphere.message().find("sphere radius 0.001 m"), std::string::npos) << sphere.message();
  EXPECT_NE(sphere.message().find("no particle fits"), std::string::npos) << sphere.message();
  auto box = box_particles({0.1, 0.005, 0.1}, 0.01);
  ASSERT_FALSE(box);
  EXPECT_NE(box.message().find("box size y 0.005 m"), std::string::npos) << box.message();
  auto cylinder = cylinder_particles(0.1, 0.009, 0.01);
  ASSERT_FALSE(cylinder);
  EXPECT_NE(cylinder.message().find("cylinder height"), std::string::npos) << cylinder.message();
  auto capsule = capsule_particles(0.004, 0.1, 0.01);
  ASSERT_FALSE(capsule);
  EXPECT_NE(capsule.message().find("capsule radius"), std::string::npos) << capsule.message();
  auto lattice = box_lattice({3, 0, 3}, 0.01);
  ASSERT_FALSE(lattice);
  EXPECT_NE(lattice.message().find("count along y"), std::string::npos) << lattice.message();
}

TEST(PrimitiveErrors, TooManyParticles) {
  auto sphere = sphere_particles(1.0, 1e-4);
  ASSERT_FALSE(sphere);
  EXPECT_NE(sphere.message().find("limit"), std::string::npos) << sphere.message();
  auto box = box_particles({1e6, 1.0, 1.0}, 1e-3);
  ASSERT_FALSE(box);
  EXPECT_NE(box.message().find("limit"), std::string::npos) << box.message();
}

}  // namespace
}  // namespace motes
