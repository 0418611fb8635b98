// Picking through the grid (motes/view_pick.h): on seeded random clouds of spheres, the grid
// finds exactly the particle, at exactly the distance, that a scan of every sphere finds.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "motes/view_pick.h"

namespace {

using Eigen::Vector3f;
using motes::shared::vec4;
using motes::viewer::PickGrid;
using motes::viewer::PickHit;

struct Cloud {
  std::vector<vec4> spheres;
  std::vector<std::uint8_t> pickable;
  Vector3f lo, hi;  ///< the box the centres were drawn in
};

/// A cloud of `count` spheres in a random box (flat along some axis now and then), radii from a
/// random range (all equal now and then), about a quarter not pickable.
Cloud random_cloud(std::mt19937& rng, int count) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Cloud cloud;
  const float size = std::pow(10.0f, -1.0f + 3.0f * u(rng));  // 0.1 .. 100
  cloud.lo = Vector3f(u(rng), u(rng), u(rng)) * 20.0f - Vector3f::Constant(10.0f);
  Vector3f extent(size * (0.2f + u(rng)), size * (0.2f + u(rng)), size * (0.2f + u(rng)));
  if (u(rng) < 0.2f) extent[static_cast<int>(u(rng) * 2.99f)] = 0.0f;
  cloud.hi = cloud.lo + extent;
  const float r_max = size * std::pow(10.0f, -2.5f + 2.0f * u(rng));
  const float r_min = u(rng) < 0.3f ? r_max : r_max * u(rng) * u(rng);
  for (int i = 0; i < count; ++i) {
    const Vector3f c = cloud.lo + Vector3f(u(rng), u(rng), u(rng)).cwiseProduct(extent);
    cloud.spheres.push_back({c.x(), c.y(), c.z(), r_min + (r_max - r_min) * u(rng)});
    cloud.pickable.push_back(u(rng) < 0.75f ? 1 : 0);
  }
  return cloud;
}

Vector3f random_direction(std::mt19937& rng) {
  std::normal_distribution<float> n(0.0f, 1.0f);
  Vector3f d(n(rng), n(rng), n(rng));
  return d.norm() > 1e-6f ? d : Vector3f::UnitX();
}

void expect_same(const PickHit& grid, const PickHit& scan, const std::string& what) {
  ASSERT_EQ(grid.hit, scan.hit) << what;
  if (!scan.hit) return;
  EXPECT_EQ(grid.particle, scan.particle) << what;
  EXPECT_EQ(grid.t, scan.t) << what;
}

TEST(ViewPick, GridFindsWhatTheScanFindsOnRandomClouds) {
  std::mt19937 rng(20261130);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int hits = 0, misses = 0;
  for (int cloud_no = 0; cloud_no < 60; ++cloud_no) {
    const int count = 1 + static_cast<int>(std::pow(3000.0f, u(rng)));
    const Cloud cloud = random_cloud(rng, count);
    const motes::viewer::Pickable pickable = [&](std::uint32_t i) {
      return cloud.pickable[i] != 0;
    };
    const PickGrid grid(cloud.spheres, pickable);
    const Vector3f centre = 0.5f * (cloud.lo + cloud.hi);
    const float size = (cloud.hi - cloud.lo).norm() + 1e-3f;
    const float h = grid.cell_size();
    for (int ray = 0; ray < 200; ++ray) {
      Vector3f origin;
      Vector3f dir = random_direction(rng);
      const int kind = ray % 7;
      const Vector3f inside =
          cloud.lo + Vector3f(u(rng), u(rng), u(rng)).cwiseProduct(cloud.hi - cloud.lo);
      switch (kind) {
        case 0:  // starting inside the grid
          origin = inside;
          break;
        case 1:  // from outside, towards a point of the cloud
          origin = centre + random_direction(rng).normalized() * size * (1.0f + 3.0f * u(rng));
          dir = inside - origin;
          break;
        case 2: {  // axis-parallel, either way
          origin = inside;
          const int a = ray % 3;
          origin[a] = u(rng) < 0.5f ? cloud.lo[a] - size : cloud.hi[a] + size;
          dir = Vector3f::Zero();
          dir[a] = origin[a] < cloud.lo[a] ? 1.0f : -1.0f;
          if (u(rng) < 0.3f) dir *= -1.0f;  // away: misses everything
          break;
        }
        case 3: {  // along a cell boundary, axis-parallel, from inside or outside
          const int a = ray % 3;
          origin = inside;
          for (int b = 0; b < 3; ++b) {
            if (b == a) continue;
            origin[b] = grid.corner()[b] + std::floor(u(rng) * 6.0f) * h;
          }
          if (u(rng) < 0.5f) origin[a] = cloud.lo[a] - size;
          dir = Vector3f::Zero();
          dir[a] = u(rng) < 0.5f ? 1.0f : -1.0f;
          break;
        }
        case 4:  // pointing away from the cloud: a miss
          origin = centre + random_direction(rng).normalized() * size * 2.0f;
          dir = origin - centre + 0.1f * size * random_direction(rng);
          break;
        case 5:  // from far away (10 to 1,000 times the cloud's size), towards a point of it
          origin = centre + random_direction(rng).normalized() * size *
                                std::pow(10.0f, 1.0f + 2.0f * u(rng));
          dir = inside - origin;
          break;
        default:  // a pixel ray's length (|dir| > 1), from anywhere near
          origin = centre + random_direction(rng) * size;
          dir = random_direction(rng).normalized() * (1.0f + u(rng));
          break;
      }
      const std::string what = "cloud " + std::to_string(cloud_no) + " ray " + std::to_string(ray) +
                               " kind " + std::to_string(kind);
      const PickHit scan = motes::viewer::pick_every_sphere(cloud.spheres, pickable, origin, dir);
      expect_same(grid.pick(origin, dir), scan, what);
      (scan.hit ? hits : misses)++;
    }
  }
  // Both kinds of answer were checked many times.
  EXPECT_GT(hits, 2000);
  EXPECT_GT(misses, 2000);
}

TEST(ViewPick, PackedLatticeAndItsTies) {
  // Touching spheres on a lattice (as a settled pile), rays along the rows through the centres:
  // equal distances are common, and both take the lower index.
  std::vector<vec4> spheres;
  for (int z = 0; z < 20; ++z)
    for (int y = 0; y < 20; ++y)
      for (int x = 0; x < 20; ++x)
        spheres.push_back({0.1f * static_cast<float>(x), 0.1f * static_cast<float>(y),
                           0.1f * static_cast<float>(z), 0.05f});
  // Duplicates at the same place: equal t.
  spheres.push_back(spheres[4321]);
  spheres.push_back(spheres[0]);
  const PickGrid grid(spheres, nullptr);
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> k(0, 19);
  for (int ray = 0; ray < 600; ++ray) {
    Vector3f origin(0.1f * static_cast<float>(k(rng)), 0.1f * static_cast<float>(k(rng)),
                    0.1f * static_cast<float>(k(rng)));
    const int a = ray % 3;
    origin[a] = ray % 2 ? -1.0f : 3.0f;
    Vector3f dir = Vector3f::Zero();
    dir[a] = ray % 2 ? 1.0f : -1.0f;
    if (ray % 5 == 0) origin[(a + 1) % 3] += 0.05f;  // grazing the spheres' sides
    expect_same(grid.pick(origin, dir),
                motes::viewer::pick_every_sphere(spheres, nullptr, origin, dir),
                "ray " + std::to_string(ray));
  }
}

TEST(ViewPick, TestsFewSpheresOfALargeCloud) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<vec4> spheres;
  for (int i = 0; i < 200000; ++i)
    spheres.push_back({u(rng) * 10.0f, u(rng) * 10.0f, u(rng) * 10.0f, 0.02f});
  const PickGrid grid(spheres, nullptr);
  for (int ray = 0; ray < 20; ++ray) {
    const Vector3f origin(5.0f, 5.0f, 30.0f);
    const Vector3f dir = Vector3f(u(rng) * 10.0f, u(rng) * 10.0f, 10.0f) - origin;
    const PickHit hit = grid.pick(origin, dir);
    const PickHit scan = motes::viewer::pick_every_sphere(spheres, nullptr, origin, dir);
    expect_same(hit, scan, "ray " + std::to_string(ray));
    EXPECT_LT(hit.tests, spheres.size() / 100);
  }
}

TEST(ViewPick, NothingPickableOrNothingToPick) {
  const std::vector<vec4> spheres = {{0, 0, 0, 1}, {3, 0, 0, 1}};
  const PickGrid none(spheres, [](std::uint32_t) { return false; });
  EXPECT_FALSE(none.pick({0, 0, -5}, {0, 0, 1}).hit);
  const PickGrid empty(std::vector<vec4>{}, nullptr);
  EXPECT_FALSE(empty.pick({0, 0, -5}, {0, 0, 1}).hit);
  // A sphere the ray starts inside is not picked (t < 0); the next one along is.
  const PickGrid both(spheres, nullptr);
  const PickHit from_inside = both.pick({0, 0, 0}, {1, 0, 0});
  ASSERT_TRUE(from_inside.hit);
  EXPECT_EQ(from_inside.particle, 1u);
  EXPECT_FLOAT_EQ(from_inside.t, 2.0f);
  // Spread wider than float's range (the extent is infinite): one cell, still the scan's answer.
  const std::vector<vec4> wide = {{-3e38f, 0, 0, 1}, {3e38f, 0, 0, 1}, {0, 0, 0, 1}};
  const PickHit middle = PickGrid(wide, nullptr).pick({0, 0, -5}, {0, 0, 1});
  ASSERT_TRUE(middle.hit);
  EXPECT_EQ(middle.particle, 2u);
  EXPECT_EQ(middle.t, motes::viewer::pick_every_sphere(wide, nullptr, {0, 0, -5}, {0, 0, 1}).t);
  // Not finite: left out.
  const std::vector<vec4> bad = {{NAN, 0, 0, 1}, {0, 0, 0, INFINITY}, {3, 0, 0, 1}};
  const PickHit past = PickGrid(bad, nullptr).pick({-5, 0, 0}, {1, 0, 0});
  ASSERT_TRUE(past.hit);
  EXPECT_EQ(past.particle, 2u);
}

}  // namespace
