// Cloth and ropes (motes/cloth.h): make_rope and make_cloth (counts, rest geometry, option
// errors) and colour_constraints (a valid, stable, deterministic colouring).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "motes/cloth.h"

namespace motes {
namespace {

std::vector<shared::Constraint> constraints_of(const LinkedSpec& spec) {
  std::vector<shared::Constraint> out;
  for (const LinkSpec& l : spec.links) {
    const double rest = (spec.points[l.b] - spec.points[l.a]).norm();
    out.push_back({l.a, l.b, static_cast<float>(rest), static_cast<float>(l.stiffness)});
  }
  return out;
}

/// Number of links of each rest length in lattice steps (1: structural, sqrt 2: shear, 2: bend).
std::map<std::string, std::size_t> link_kinds(const LinkedSpec& spec, double step) {
  std::map<std::string, std::size_t> kinds;
  for (const LinkSpec& l : spec.links) {
    const double r = (spec.points[l.b] - spec.points[l.a]).norm() / step;
    if (std::abs(r - 1.0) < 1e-9) {
      ++kinds["structural"];
    } else if (std::abs(r - std::sqrt(2.0)) < 1e-9) {
      ++kinds["shear"];
    } else if (std::abs(r - 2.0) < 1e-9) {
      ++kinds["bend"];
    } else {
      ++kinds["other"];
    }
  }
  return kinds;
}

void expect_error(const Result<LinkedSpec>& r, const std::string& part) {
  ASSERT_FALSE(r) << "expected an error with \"" << part << "\"";
  EXPECT_NE(r.message().find(part), std::string::npos) << r.message();
}

// ---- make_rope ----

TEST(ClothRope, EvenlySpacedPointsAndLinks) {
  RopeOptions o;
  o.from = {0, 1, 0};
  o.to = {0.39, 1, 0};
  o.count = 40;
  o.diameter = 0.01;
  o.stiffness = 0.5;
  Result<LinkedSpec> r = make_rope(o);
  ASSERT_TRUE(r) << r.message();
  EXPECT_EQ(r->kind, LinkedKind::Rope);
  EXPECT_EQ(r->diameter, 0.01);
  ASSERT_EQ(r->points.size(), 40u);
  ASSERT_EQ(r->lattice.size(), 40u);
  EXPECT_TRUE(r->points.front().isApprox(o.from));
  EXPECT_TRUE(r->points.back().isApprox(o.to));
  for (std::uint32_t i = 0; i < 40; ++i) {
    EXPECT_EQ(r->lattice[i][0], i);
    EXPECT_EQ(r->lattice[i][1], 0u);
  }
  ASSERT_EQ(r->links.size(), 39u);
  for (std::uint32_t i = 0; i < 39; ++i) {
    EXPECT_EQ(r->links[i].a, i);
    EXPECT_EQ(r->links[i].b, i + 1);
    EXPECT_EQ(r->links[i].stiffness, 0.5);
    EXPECT_NEAR((r->points[i + 1] - r->points[i]).norm(), 0.01, 1e-12);
  }
  EXPECT_TRUE(r->pinned.empty());
}

TEST(ClothRope, BendLinksSkipOne) {
  RopeOptions o;
  o.count = 10;
  o.bend = true;
  o.bend_stiffness = 0.25;
  Result<LinkedSpec> r = make_rope(o);
  ASSERT_TRUE(r) << r.message();
  ASSERT_EQ(r->links.size(), 9u + 8u);
  for (std::uint32_t i = 0; i < 8; ++i) {
    const LinkSpec& l = r->links[9 + i];
    EXPECT_EQ(l.a, i);
    EXPECT_EQ(l.b, i + 2);
    EXPECT_EQ(l.stiffness, 0.25);
  }
}

TEST(ClothRope, OptionErrors) {
  RopeOptions o;
  o.count = 1;
  expect_error(make_rope(o), "rope: the particle count must be from 2 to 1024 (got 1)");
  o.count = 1025;
  expect_error(make_rope(o), "got 1025");
  o = RopeOptions{};
  o.diameter = 0.0;
  expect_error(make_rope(o), "rope: diameter must be > 0");
  o = RopeOptions{};
  o.stiffness = 1.5;
  expect_error(make_rope(o), "rope: stiffness must be in (0, 1]");
  o = RopeOptions{};
  o.bend_stiffness = 0.0;
  expect_error(make_rope(o), "stiffness must be in (0, 1]");
  o = RopeOptions{};
  o.to = o.from;
  expect_error(make_rope(o), "rope: its ends must be apart (length 0)");
  o = RopeOptions{};
  o.to.x() = std::nan("");
  expect_error(make_rope(o), "rope: point 1 is not finite");
  o = RopeOptions{};
  o.path = {Eigen::Vector3d::Zero()};
  expect_error(make_rope(o), "rope: a path needs at least two points");
}

TEST(Cloth, RopeAlongAPolylineIsEvenlySpacedAndSlack) {
  // A V: 0.3 m down and right, then 0.3 m up and right; 7 particles, 0.1 m of path apart.
  RopeOptions o;
  o.path = {{0.0, 0.0, 0.0},
            {0.3 * std::sqrt(0.5), -0.3 * std::sqrt(0.5), 0.0},
            {0.6 * std::sqrt(0.5), 0.0, 0.0}};
  o.count = 7;
  const LinkedSpec r = make_rope(o).value();
  ASSERT_EQ(r.points.size(), 7u);
  EXPECT_NEAR((r.points[3] - o.path[1]).norm(), 0.0, 1e-12);  // the corner is a particle
  EXPECT_NEAR((r.points[6] - o.path[2]).norm(), 0.0, 0.0);
  for (std::size_t k = 0; k + 1 < r.points.size(); ++k) {
    EXPECT_NEAR((r.points[k + 1] - r.points[k]).norm(), 0.1, 1e-12) << k;
  }
  // Slack: the links' total length exceeds the distance between the ends.
  EXPECT_NEAR((r.points[6] - r.points[0]).norm(), 0.6 * std::sqrt(0.5), 1e-12);
}

// ---- make_cloth ----

TEST(ClothSheet, LatticeRestGeometryAndLinkCounts) {
  ClothOptions o;
  o.corner = {-0.12, 0.35, -0.12};
  o.edge_u = {0.24, 0, 0};
  o.edge_v = {0, 0, 0.24};
  o.nu = 25;
  o.nv = 25;
  o.diameter = 0.01;
  Result<LinkedSpec> c = make_cloth(o);
  ASSERT_TRUE(c) << c.message();
  EXPECT_EQ(c->kind, LinkedKind::Cloth);
  ASSERT_EQ(c->points.size(), 625u);
  for (int j = 0; j < 25; ++j) {
    for (int i = 0; i < 25; ++i) {
      const std::uint32_t k = cloth_index(o, i, j);
      EXPECT_EQ(c->lattice[k][0], static_cast<std::uint32_t>(i));
      EXPECT_EQ(c->lattice[k][1], static_cast<std::uint32_t>(j));
      EXPECT_TRUE(c->points[k].isApprox(o.corner + Eigen::Vector3d(0.01 * i, 0, 0.01 * j)));
    }
  }
  const int nu = 25, nv = 25;
  const auto kinds = link_kinds(*c, 0.01);
  EXPECT_EQ(kinds.at("structural"), static_cast<std::size_t>((nu - 1) * nv + nu * (nv - 1)));
  EXPECT_EQ(kinds.at("shear"), static_cast<std::size_t>(2 * (nu - 1) * (nv - 1)));
  EXPECT_EQ(kinds.at("bend"), static_cast<std::size_t>((nu - 2) * nv + nu * (nv - 2)));
  EXPECT_EQ(kinds.count("other"), 0u);
  EXPECT_EQ(c->links.size(), 1200u + 1152u + 1150u);
}

TEST(ClothSheet, RectangularWithoutBendAndItsStiffnesses) {
  ClothOptions o;
  o.edge_u = {0.3, 0, 0};  // 4 x 3 steps of 0.1
  o.edge_v = {0, 0.2, 0};
  o.nu = 4;
  o.nv = 3;
  o.bend = false;
  o.stiffness = 0.75;
  Result<LinkedSpec> c = make_cloth(o);
  ASSERT_TRUE(c) << c.message();
  ASSERT_EQ(c->points.size(), 12u);
  const auto kinds = link_kinds(*c, 0.1);
  EXPECT_EQ(kinds.at("structural"), 3u * 3u + 4u * 2u);
  EXPECT_EQ(kinds.at("shear"), 2u * 3u * 2u);
  EXPECT_EQ(kinds.count("bend"), 0u);
  for (const LinkSpec& l : c->links) EXPECT_EQ(l.stiffness, 0.75);
  o.bend = true;
  o.bend_stiffness = 0.5;
  Result<LinkedSpec> b = make_cloth(o);
  ASSERT_TRUE(b) << b.message();
  std::size_t bend = 0;
  for (const LinkSpec& l : b->links) bend += l.stiffness == 0.5 ? 1 : 0;
  EXPECT_EQ(bend, 2u * 3u + 4u * 1u);
}

TEST(ClothSheet, OptionErrors) {
  ClothOptions o;
  o.nu = 1;
  expect_error(make_cloth(o), "cloth: the particle count along u must be from 2 to 1024 (got 1)");
  o = ClothOptions{};
  o.nv = 2000;
  expect_error(make_cloth(o), "cloth: the particle count along v must be from 2 to 1024");
  o = ClothOptions{};
  o.diameter = -1;
  expect_error(make_cloth(o), "cloth: diameter must be > 0");
  o = ClothOptions{};
  o.stiffness = 0.0;
  expect_error(make_cloth(o), "cloth: stiffness must be in (0, 1]");
  o = ClothOptions{};
  o.edge_v = 2.0 * o.edge_u;
  expect_error(make_cloth(o), "cloth: its edges must be finite, non-zero and not parallel");
  o = ClothOptions{};
  o.edge_u = Eigen::Vector3d::Zero();
  expect_error(make_cloth(o), "not parallel");
}

// ---- colour_constraints ----

/// Checks that `out` is a valid colouring of `in`: no two constraints of a colour share a
/// particle, every colour is non-empty, it is a permutation of the input, and each colour keeps
/// the input order. Returns the number of colours.
std::size_t check_colouring(const std::vector<shared::Constraint>& in,
                            const ConstraintColouring& out, std::uint32_t particles) {
  EXPECT_EQ(out.constraints.size(), in.size());
  EXPECT_EQ(out.first.front(), 0u);
  EXPECT_EQ(out.first.back(), in.size());
  // The input's (a, b) pairs are unique here, so each output constraint names its input index.
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::size_t> index;
  for (std::size_t k = 0; k < in.size(); ++k) index[{in[k].a, in[k].b}] = k;
  EXPECT_EQ(index.size(), in.size()) << "test input has repeated pairs";
  std::vector<int> seen(in.size(), 0);
  for (std::size_t c = 0; c < out.colours(); ++c) {
    EXPECT_LT(out.first[c], out.first[c + 1]) << "colour " << c << " is empty";
    std::vector<int> touched(particles, 0);
    std::size_t previous = 0;
    for (std::uint32_t k = out.first[c]; k < out.first[c + 1]; ++k) {
      const shared::Constraint& con = out.constraints[k];
      EXPECT_EQ(touched[con.a]++, 0) << "colour " << c << " touches particle " << con.a << " twice";
      EXPECT_EQ(touched[con.b]++, 0) << "colour " << c << " touches particle " << con.b << " twice";
      const auto it = index.find({con.a, con.b});
      if (it == index.end()) {
        ADD_FAILURE() << "constraint " << con.a << "-" << con.b << " is not in the input";
        continue;
      }
      const shared::Constraint& orig = in[it->second];
      EXPECT_EQ(con.rest, orig.rest);
      EXPECT_EQ(con.stiffness, orig.stiffness);
      ++seen[it->second];
      if (k > out.first[c]) {
        EXPECT_GT(it->second, previous) << "colour " << c << " is not in input order";
      }
      previous = it->second;
    }
  }
  for (std::size_t k = 0; k < in.size(); ++k) EXPECT_EQ(seen[k], 1) << "input constraint " << k;
  return out.colours();
}

void expect_same(const ConstraintColouring& x, const ConstraintColouring& y) {
  ASSERT_EQ(x.first, y.first);
  ASSERT_EQ(x.constraints.size(), y.constraints.size());
  for (std::size_t k = 0; k < x.constraints.size(); ++k) {
    EXPECT_EQ(std::tie(x.constraints[k].a, x.constraints[k].b, x.constraints[k].rest),
              std::tie(y.constraints[k].a, y.constraints[k].b, y.constraints[k].rest));
  }
}

TEST(ClothColouring, Cloth25x25WithBendIsValidStableAndDeterministic) {
  ClothOptions o;
  o.edge_u = {0.24, 0, 0};
  o.edge_v = {0, 0, 0.24};
  o.nu = 25;
  o.nv = 25;
  Result<LinkedSpec> c = make_cloth(o);
  ASSERT_TRUE(c) << c.message();
  const std::vector<shared::Constraint> in = constraints_of(*c);
  const auto n = static_cast<std::uint32_t>(c->points.size());
  const ConstraintColouring out = colour_constraints(in, n);
  const std::size_t colours = check_colouring(in, out, n);
  // An inner particle has 12 links (4 structural, 4 shear, 4 bend): at least 12 colours; greedy
  // needs at most 2 x 12 - 1.
  EXPECT_GE(colours, 12u);
  EXPECT_LE(colours, 23u);
  RecordProperty("colours", static_cast<int>(colours));
  std::printf("25 x 25 cloth with bend: %zu constraints in %zu colours\n", in.size(), colours);
  expect_same(out, colour_constraints(in, n));
}

TEST(ClothColouring, RopeWithAndWithoutBend) {
  for (const bool bend : {false, true}) {
    RopeOptions o;
    o.count = 40;
    o.bend = bend;
    Result<LinkedSpec> r = make_rope(o);
    ASSERT_TRUE(r) << r.message();
    const std::vector<shared::Constraint> in = constraints_of(*r);
    const ConstraintColouring out = colour_constraints(in, 40);
    const std::size_t colours = check_colouring(in, out, 40);
    if (!bend) {
      EXPECT_EQ(colours, 2u);  // a path: alternate links
    } else {
      EXPECT_GE(colours, 3u);  // 0-1, 1-2 and 0-2 share particles pairwise
      EXPECT_LE(colours, 7u);  // degree 4: greedy needs at most 2 x 4 - 1
    }
    expect_same(out, colour_constraints(in, 40));
  }
}

TEST(ClothColouring, EmptyInputHasNoColours) {
  const ConstraintColouring out = colour_constraints({}, 5);
  EXPECT_TRUE(out.constraints.empty());
  EXPECT_EQ(out.colours(), 0u);
}

}  // namespace
}  // namespace motes
