// Cloth made from a triangle mesh (motes/cloth.h make_mesh_cloth, link_neighbourhoods; scene
// format "cloth": {"mesh": ...}): its particles and links, the pairs that never touch (checked
// against graph distances found by a breadth-first search), the located scene errors, and on the
// backends CI has that those pairs really do not touch while the rest of the cloth does.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>
#include <queue>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "motes/cloth.h"
#include "motes/devices.h"
#include "motes/scene.h"
#include "motes/shapes.h"
#include "motes/simulation.h"
#include "unit/test_support.h"

namespace motes {
namespace {

using motes_test::TempDir;

/// An nx x nz grid of squares of side h in the xz plane at height y, each cut into two triangles
/// along alternating diagonals; vertex (i, k) is k * (nx + 1) + i.
TriangleMesh grid_mesh(int nx, int nz, double h, double y = 0.0) {
  TriangleMesh m;
  m.source = "grid.obj";
  for (int k = 0; k <= nz; ++k) {
    for (int i = 0; i <= nx; ++i) m.vertices.emplace_back(i * h, y, k * h);
  }
  motes_test::add_grid_triangles(m, nx + 1, nz + 1);
  return m;
}

std::string obj_text(const TriangleMesh& m) {
  std::string s;
  for (const Eigen::Vector3d& v : m.vertices) s += fmt::format("v {} {} {}\n", v.x(), v.y(), v.z());
  for (const Eigen::Vector3i& t : m.triangles) {
    s += fmt::format("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
  }
  return s;
}

void write_file(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

TEST(MeshCloth, TwoTrianglesMakeFiveEdgesAndOneBendLink) {
  TriangleMesh m;
  m.source = "quad.obj";
  // Vertex 4 is used by no triangle; the last triangle is degenerate (a repeated vertex).
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}, {5, 5, 5}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 0, 1}};
  MeshClothOptions o;
  o.diameter = 0.5;
  o.stiffness = 0.25;
  o.bend_stiffness = 0.125;
  Result<LinkedSpec> c = make_mesh_cloth(m, o);
  ASSERT_TRUE(c) << c.message();
  EXPECT_EQ(c->kind, LinkedKind::Cloth);
  EXPECT_TRUE(c->lattice.empty());
  ASSERT_EQ(c->points.size(), 4u);  // the unused vertex is dropped
  std::set<std::pair<std::uint32_t, std::uint32_t>> structural, bend;
  for (const LinkSpec& l : c->links) {
    (l.stiffness == 0.25 ? structural : bend).insert({std::min(l.a, l.b), std::max(l.a, l.b)});
  }
  const std::set<std::pair<std::uint32_t, std::uint32_t>> edges = {
      {0, 1}, {1, 2}, {0, 2}, {2, 3}, {0, 3}};
  EXPECT_EQ(structural, edges);
  // Across the shared edge 0-2: the opposite vertices 1 and 3.
  EXPECT_EQ(bend, (std::set<std::pair<std::uint32_t, std::uint32_t>>{{1, 3}}));
  o.bend = false;
  EXPECT_EQ(make_mesh_cloth(m, o)->links.size(), 5u);
}

TEST(MeshCloth, BadMeshesAndOptionsAreRefusedByName) {
  TriangleMesh empty;
  empty.source = "empty.obj";
  EXPECT_EQ(make_mesh_cloth(empty, {}).message(), "empty.obj: the mesh has no triangles");
  TriangleMesh m = grid_mesh(2, 2, 0.1);
  m.vertices[4].x() = std::nan("");
  EXPECT_EQ(make_mesh_cloth(m, {}).message(), "grid.obj: vertex 4 is not finite");
  MeshClothOptions o;
  o.diameter = -1.0;
  EXPECT_EQ(make_mesh_cloth(grid_mesh(1, 1, 0.1), o).message(),
            "cloth: diameter must be > 0 (got -1)");
  // A fan: one vertex in 4,000 triangles makes every rim vertex two links from every other.
  TriangleMesh fan;
  fan.source = "fan.obj";
  fan.vertices.emplace_back(0, 0, 0);
  const int rim = 4000;
  for (int k = 0; k < rim; ++k) {
    const double a = 2.0 * std::numbers::pi * k / rim;
    fan.vertices.emplace_back(std::cos(a), 0.0, std::sin(a));
    fan.triangles.emplace_back(0, 1 + k, 1 + (k + 1) % rim);
  }
  const std::string message = make_mesh_cloth(fan, {}).message();
  EXPECT_NE(message.find("fan.obj: the vertex at [0, 0, 0] has 4000 links (a fan of triangles)"),
            std::string::npos)
      << message;
}

/// Graph distances from `from` over the links, by breadth-first search (-1: unreachable).
std::vector<int> distances(const LinkedSpec& c, std::uint32_t from) {
  std::vector<std::vector<std::uint32_t>> next(c.points.size());
  for (const LinkSpec& l : c.links) {
    next[l.a].push_back(l.b);
    next[l.b].push_back(l.a);
  }
  std::vector<int> d(c.points.size(), -1);
  std::queue<std::uint32_t> q;
  d[from] = 0;
  q.push(from);
  while (!q.empty()) {
    const std::uint32_t a = q.front();
    q.pop();
    for (const std::uint32_t b : next[a]) {
      if (d[b] < 0) {
        d[b] = d[a] + 1;
        q.push(b);
      }
    }
  }
  return d;
}

TEST(MeshCloth, NeverTouchingPairsAreExactlyThoseWithinTwoLinks) {
  Result<TriangleMesh> disc =
      load_mesh(std::string(MOTES_SOURCE_DIR) + "/examples/assets/tablecloth.obj");
  ASSERT_TRUE(disc) << disc.message();
  for (const bool bend : {false, true}) {
    MeshClothOptions o;
    o.bend = bend;
    Result<LinkedSpec> c = make_mesh_cloth(*disc, o);
    ASSERT_TRUE(c) << c.message();
    ASSERT_EQ(c->points.size(), 721u);
    const auto n = static_cast<std::uint32_t>(c->points.size());
    const LinkNeighbourhoods near = link_neighbourhoods(c->links, n);
    ASSERT_EQ(near.start.size(), n + 1u);
    std::size_t pairs = 0;
    for (std::uint32_t k = 0; k < n; ++k) {
      const std::vector<int> d = distances(*c, k);
      std::vector<std::uint32_t> want;
      for (std::uint32_t j = 0; j < n; ++j) {
        if (j != k && d[j] >= 1 && d[j] <= 2) want.push_back(j);
      }
      const std::vector<std::uint32_t> got(near.list.begin() + near.start[k],
                                           near.list.begin() + near.start[k + 1]);
      ASSERT_EQ(got, want) << "point " << k << (bend ? " with bend links" : "");
      pairs += got.size();
    }
    // Edges only: an interior vertex of this mesh has 6 neighbours and 12 more two links away.
    if (!bend) {
      EXPECT_GT(pairs, 15u * n);
    }
  }
}

std::unique_ptr<Simulation> simulate(const std::string& text, const std::string& dir,
                                     const std::string& backend) {
  return motes_test::simulate_text(text, "cloth.json", dir, backend);
}

std::string cloth_scene(const std::string& cloth, double diameter, double gravity = 0.0) {
  return fmt::format(
      R"({{"settings": {{"dt": 1e-5, "particle_diameter": {0}, "gravity": [0, {1}, 0],
          "constraint_iterations": 4, "contact": {{"stiffness": 1000, "damping": 10}}}},
        "bodies": [{{"name": "sheet", "kind": "cloth", "diameter": {0}, "cloth": {2}}}]}})",
      diameter, -gravity, cloth);
}

TEST(MeshCloth, SceneLoadsTheMeshWithPinsAtTheNearestVertex) {
  TempDir dir;
  write_file(dir / "grid.obj", obj_text(grid_mesh(4, 3, 0.1)));
  const Result<Scene> s =
      load_scene_text(cloth_scene(R"({"mesh": "grid.obj", "scale": 2, "position": [1, 2, 3],
                      "rotation": {"axis": [0, 1, 0], "degrees": 90},
                      "stiffness": 0.5, "pin": [[1.01, 2, 3], [1.62, 2, 2.21]]})",
                                  0.05),
                      "cloth.json", dir.path().string());
  ASSERT_TRUE(s) << s.message();
  ASSERT_EQ(s->linked.size(), 1u);
  const LinkedSpec& c = s->linked[0];
  EXPECT_EQ(c.points.size(), 20u);
  EXPECT_TRUE(c.lattice.empty());
  // Points in the order the triangles use them: the second is vertex (0.1, 0, 0), scaled by 2,
  // turned 90 degrees about y (x -> -z) and moved: (1, 2, 2.8) (the OBJ file holds floats).
  EXPECT_LT((c.points[1] - Eigen::Vector3d(1.0, 2.0, 2.8)).norm(), 1e-6);
  // Pins: the vertices nearest to them, the mesh's (0, 0, 0) -> (1, 2, 3) and its corner
  // (0.4, 0, 0.3) -> (1.6, 2, 2.2).
  ASSERT_EQ(c.pinned.size(), 2u);
  EXPECT_LT((c.points[c.pinned[0]] - Eigen::Vector3d(1.0, 2.0, 3.0)).norm(), 1e-6);
  EXPECT_LT((c.points[c.pinned[1]] - Eigen::Vector3d(1.6, 2.0, 2.2)).norm(), 1e-6);
  for (const LinkSpec& l : c.links) EXPECT_TRUE(l.stiffness == 0.5 || l.stiffness == 1.0);
}

TEST(MeshCloth, SceneErrorsNameTheFieldAndTheReason) {
  TempDir dir;
  write_file(dir / "grid.obj", obj_text(grid_mesh(2, 2, 0.1)));
  const auto error = [&](const std::string& cloth) {
    const Result<Scene> s =
        load_scene_text(cloth_scene(cloth, 0.05), "cloth.json", dir.path().string());
    return s ? std::string("loaded") : s.message();
  };
  EXPECT_EQ(error(R"({"mesh": "grid.obj", "pin": [[0.5, 0, 0]]})"),
            "cloth.json: /bodies/0/cloth/pin/0: no vertex of the mesh within one particle "
            "diameter (0.05 m) of this point; the nearest, [0.2, 0, 0], is 0.3 m away");
  EXPECT_EQ(error(R"({"mesh": "grid.obj", "pin": [[0, 0, 0], [0.01, 0, 0]]})"),
            "cloth.json: /bodies/0/cloth/pin/1: duplicate pin: point 0 is already pinned by "
            "/bodies/0/cloth/pin/0");
  EXPECT_EQ(error(R"({"mesh": "grid.obj", "corner": [0, 0, 0]})"),
            "cloth.json: /bodies/0/cloth/corner: a cloth is a \"mesh\" or a rectangle "
            "(\"corner\", \"edge_u\", \"edge_v\", \"particles\"), not both");
  const std::string missing = error(R"({"mesh": "nowhere.obj"})");
  EXPECT_NE(missing.find("/bodies/0/cloth/mesh: cannot open mesh"), std::string::npos) << missing;
  EXPECT_NE(missing.find("nowhere.obj\": no such file"), std::string::npos) << missing;
  EXPECT_NE(error(R"({"mesh": "grid.obj", "stiffness": 2})").find("/bodies/0/cloth/stiffness"),
            std::string::npos);
  EXPECT_NE(error(R"({"mesh": "grid.obj", "scale": -1})").find("/bodies/0/cloth/scale"),
            std::string::npos);
  EXPECT_NE(error(R"({"mesh": "grid.obj", "particles": [3, 3]})").find("not both"),
            std::string::npos);
}

TEST(MeshCloth, LinkedNeighboursOverlapWithoutPushing) {
  // Without gravity, a grid cloth whose particles are 1.9 edges wide: each overlaps its
  // neighbours within two links by up to 0.9 edge. Those pairs never touch, so nothing moves
  // (the links are at their rest lengths); one pair let through would push at 1000 N/m.
  TempDir dir;
  const double h = 0.01, d = 1.9 * h;
  write_file(dir / "grid.obj", obj_text(grid_mesh(10, 10, h)));
  for (const std::string& backend : motes_test::cpu_backends()) {
    SCOPED_TRACE(backend);
    auto sim = simulate(cloth_scene(R"({"mesh": "grid.obj"})", d), dir.path().string(), backend);
    ASSERT_TRUE(sim);
    const Result<Snapshot> before = sim->snapshot();
    ASSERT_TRUE(sim->step(1000));
    const Result<Snapshot> after = sim->snapshot();
    ASSERT_TRUE(before && after);
    double moved = 0.0;
    for (std::size_t k = 0; k < before->particle_pos.size(); ++k) {
      const shared::vec4 a = before->particle_pos[k], b = after->particle_pos[k];
      moved = std::max({moved, std::abs(double(a.x) - double(b.x)),
                        std::abs(double(a.y) - double(b.y)), std::abs(double(a.z) - double(b.z))});
    }
    // Float rounding of the link lengths moves particles by about 1e-6 m in 1,000 steps; one
    // touching pair would move them by millimetres.
    EXPECT_LT(moved, 1e-5);
  }
}

TEST(MeshCloth, PartsFarApartInLinksCollide) {
  // One mesh file holding two sheets, the small one 0.6 diameters above the large one: the same
  // cloth, but no link joins them, so their particles touch and push the sheets apart.
  TempDir dir;
  const double h = 0.01, d = 1.9 * h;
  TriangleMesh two = grid_mesh(10, 10, h);
  const TriangleMesh top = grid_mesh(4, 4, h, 0.6 * d);
  const int base = static_cast<int>(two.vertices.size());
  for (const Eigen::Vector3d& v : top.vertices) {
    two.vertices.push_back(v + Eigen::Vector3d(0.03, 0.0, 0.03));
  }
  for (const Eigen::Vector3i& t : top.triangles) {
    two.triangles.push_back(t + Eigen::Vector3i::Constant(base));
  }
  write_file(dir / "two.obj", obj_text(two));
  for (const std::string& backend : motes_test::cpu_backends()) {
    SCOPED_TRACE(backend);
    auto sim = simulate(cloth_scene(R"({"mesh": "two.obj"})", d), dir.path().string(), backend);
    ASSERT_TRUE(sim);
    const Result<Snapshot> before = sim->snapshot();
    ASSERT_TRUE(sim->step(1000));
    const Result<Snapshot> after = sim->snapshot();
    ASSERT_TRUE(before && after);
    const std::size_t n = before->particle_pos.size();
    ASSERT_EQ(n, 121u + 25u);
    double gap = HUGE_VAL;
    for (std::size_t k = 121; k < n; ++k) {
      EXPECT_GT(after->particle_pos[k].y, before->particle_pos[k].y) << k;  // pushed up
      for (std::size_t j = 0; j < 121; ++j) {
        const shared::vec4 a = after->particle_pos[k], b = after->particle_pos[j];
        const double dx = double(a.x - b.x), dy = double(a.y - b.y), dz = double(a.z - b.z);
        gap = std::min(gap, std::sqrt(dx * dx + dy * dy + dz * dz));
      }
    }
    // The sheets started 0.6 d apart and end at least a diameter apart.
    EXPECT_GT(gap, d);
  }
}

}  // namespace
}  // namespace motes
