// The brick grid of runs over MPI ranks (motes/decomposition.h): ownership is plain geometry,
// the same on every rank.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "motes/decomposition.h"
#include "motes/workloads.h"

namespace motes {
namespace {

std::vector<Eigen::Vector3d> box_corners(double x, double y, double z) {
  return {Eigen::Vector3d::Zero(), Eigen::Vector3d(x, y, z)};
}

TEST(Decomposition, SlabsAcrossTheLongestExtent) {
  Result<Decomposition> d = choose_decomposition(box_corners(4.0, 1.0, 1.0), 4);
  ASSERT_TRUE(d) << d.message();
  EXPECT_EQ(d->cells, (std::array<int, 3>{4, 1, 1}));
  d = choose_decomposition(box_corners(1.0, 1.0, 4.0), 2);
  ASSERT_TRUE(d);
  EXPECT_EQ(d->cells, (std::array<int, 3>{1, 1, 2}));
}

TEST(Decomposition, BricksWhenTheyCutLess) {
  // A square slab of 4 x 1 x 4: 2 x 1 x 2 cuts 2 faces of 4 (area 8), 4 x 1 x 1 cuts 3 of 4 (12).
  Result<Decomposition> d = choose_decomposition(box_corners(4.0, 1.0, 4.0), 4);
  ASSERT_TRUE(d);
  EXPECT_EQ(d->cells, (std::array<int, 3>{2, 1, 2}));
  // A cube of 8 ranks: 2 x 2 x 2.
  d = choose_decomposition(box_corners(1.0, 1.0, 1.0), 8);
  ASSERT_TRUE(d);
  EXPECT_EQ(d->cells, (std::array<int, 3>{2, 2, 2}));
  // Equal cuts go along x first.
  d = choose_decomposition(box_corners(1.0, 1.0, 1.0), 2);
  ASSERT_TRUE(d);
  EXPECT_EQ(d->cells, (std::array<int, 3>{2, 1, 1}));
}

TEST(Decomposition, EveryPointHasOneOwner) {
  Decomposition d;
  d.cells = {2, 3, 1};
  d.lower = Eigen::Vector3d(0.0, 0.0, 0.0);
  d.upper = Eigen::Vector3d(2.0, 3.0, 1.0);
  EXPECT_EQ(d.ranks(), 6);
  EXPECT_EQ(d.owner({0.5, 0.5, 0.5}), 0);
  EXPECT_EQ(d.owner({1.5, 0.5, 0.5}), 1);
  EXPECT_EQ(d.owner({0.5, 1.5, 0.5}), 2);
  EXPECT_EQ(d.owner({1.5, 2.5, 0.5}), 5);
  // The outer bricks reach to infinity; NaN counts as the lowest brick.
  EXPECT_EQ(d.owner({-100.0, -100.0, 9.0}), 0);
  EXPECT_EQ(d.owner({100.0, 100.0, -9.0}), 5);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(d.owner({nan, nan, nan}), 0);
  EXPECT_EQ(d.owner({1.0, 1.0, 0.0}), 3);  // on a face: the upper brick
  EXPECT_EQ(d.describe(), "2 x 3 x 1");
}

TEST(Decomposition, ForcedAndParsed) {
  Result<std::array<int, 3>> cells = parse_decomposition("1,2,2");
  ASSERT_TRUE(cells) << cells.message();
  Result<Decomposition> d = choose_decomposition(box_corners(9.0, 1.0, 1.0), 4, cells.value());
  ASSERT_TRUE(d);
  EXPECT_EQ(d->cells, (std::array<int, 3>{1, 2, 2}));
  d = choose_decomposition(box_corners(1.0, 1.0, 1.0), 4, std::array<int, 3>{3, 1, 1});
  ASSERT_FALSE(d);
  EXPECT_NE(d.message().find("must multiply to the 4 ranks"), std::string::npos) << d.message();
  for (const char* bad :
       {"", "2", "2,2", "2,2,0", "-1,1,1", "2,2,2,", "a,b,c", "2.5,1,1", "99999999999,1,1"}) {
    Result<std::array<int, 3>> p = parse_decomposition(bad);
    EXPECT_FALSE(p) << bad;
    if (!p) {
      EXPECT_NE(p.message().find("expected X,Y,Z"), std::string::npos) << p.message();
    }
  }
}

TEST(Decomposition, BodyCentresOfAScene) {
  const Scene scene = cloth_workload(4);
  const std::vector<Eigen::Vector3d> centres = body_centres(scene);
  ASSERT_EQ(centres.size(), scene.bodies.size() + scene.linked.size());
  // A cloth's centre is its points' mean.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : scene.linked.back().points) mean += p;
  mean /= static_cast<double>(scene.linked.back().points.size());
  EXPECT_TRUE(centres.back().isApprox(mean));
}

}  // namespace
}  // namespace motes
