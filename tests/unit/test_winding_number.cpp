// The generalized winding number (core/src/winding_number.h): solid angles, the hierarchy's
// far-field approximation, the boundary-curtain identity, mesh topology, the agreement of every
// inside test on the closed bunny, and the warning of `motes voxelize` and `motes run`.
// In the sanitizer build (clang's, CI) these tests check fewer points and coarser lattices: there
// the library's calls into Eigen that clang did not inline land on the test executable's -O0 copies
// of those templates (the linker keeps the first copy of an inline function, and the test objects
// come first; cmake/MotesBuildSpeed.cmake), about 4 us a triangle for the exact sum.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "../core/src/winding_number.h"
#include "motes/shapes.h"
#include "sanitized_build.h"
#include "unit/cli_support.h"
#include "unit/test_support.h"

namespace motes {
namespace {

using winding::InsideTest;
using Clock = std::chrono::steady_clock;

using motes_test::bunny_path;
using motes_test::mesh_path;
using motes_test::sorted_points;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// The bunny without the triangles whose centroid has y < 0.5 and |x| < 1: holes in its base.
TriangleMesh bunny_with_holes(const TriangleMesh& bunny) {
  TriangleMesh open = bunny;
  open.source = "bunny with holes";
  open.triangles.clear();
  for (const auto& t : bunny.triangles) {
    const Eigen::Vector3d c =
        (bunny.vertices[t[0]] + bunny.vertices[t[1]] + bunny.vertices[t[2]]) / 3.0;
    if (c.y() < 0.5 && std::abs(c.x()) < 1.0) continue;
    open.triangles.push_back(t);
  }
  return open;
}

Result<ParticleSet> voxelize_with(const TriangleMesh& mesh, double diameter, InsideTest test) {
  VoxelizeOptions options;
  options.diameter = diameter;
  return winding::voxelize_with(mesh, options, test);
}

TEST(WindingNumber, SolidAngleOfAnOctant) {
  // The triangle (x, y, z unit points) covers one octant of the sphere around the origin, which
  // lies behind it (its normal (1, 1, 1) points away).
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                        z = Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(winding::solid_angle_fraction(x, y, z), 0.125, 1e-15);
  EXPECT_NEAR(winding::solid_angle_fraction(x, z, y), -0.125, 1e-15);
  EXPECT_NEAR(winding::solid_angle_fraction(2.0 * x, 3.0 * y, 0.5 * z), 0.125, 1e-15);
  EXPECT_EQ(winding::solid_angle_fraction(x, 2.0 * x, y + x), 0.0);  // collinear with the origin
}

TEST(WindingNumber, ClosedBoxIsOneInsideAndZeroOutside) {
  const TriangleMesh box = motes_test::box_mesh(
      Eigen::Vector3d(1.0, 2.0, 0.5),
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix(),
      Eigen::Vector3d(0.2, 0.0, -0.1));
  TriangleMesh inverted = box;
  for (auto& t : inverted.triangles) std::swap(t[1], t[2]);
  const winding::WindingNumber w(box.vertices, box.triangles);
  const winding::WindingNumber v(inverted.vertices, inverted.triangles);
  for (const auto& [p, inside] : {std::pair{Eigen::Vector3d(0.2, 0.0, -0.1), 1.0},
                                  {Eigen::Vector3d(0.3, 0.4, 0.0), 1.0},
                                  {Eigen::Vector3d(3.0, 0.0, 0.0), 0.0},
                                  {Eigen::Vector3d(0.2, 0.0, 2.0), 0.0}}) {
    EXPECT_NEAR(w.exact(p), inside, 1e-12) << p.transpose();
    EXPECT_NEAR(w(p), inside, 0.05) << p.transpose();
    EXPECT_NEAR(v.exact(p), -inside, 1e-12) << p.transpose();
  }
}

TEST(WindingNumber, HierarchyAgreesWithTheExactSum) {
  auto bunny = load_mesh(bunny_path());
  ASSERT_TRUE(bunny) << bunny.message();
  for (const TriangleMesh& mesh : {*bunny, bunny_with_holes(*bunny)}) {
    Eigen::Vector3d lo = mesh.vertices.front(), hi = lo;
    for (const auto& v : mesh.vertices) {
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
    }
    const auto built = Clock::now();
    const winding::WindingNumber w(mesh.vertices, mesh.triangles);
    const double build_s = seconds_since(built);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-0.1, 1.1);
    std::vector<Eigen::Vector3d> points(motes_test::sanitized_or<std::size_t>(3000, 300));
    for (auto& p : points) p = lo + (hi - lo).cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    std::vector<double> exact;
    const auto t0 = Clock::now();
    for (const auto& p : points) exact.push_back(w.exact(p));
    const double exact_s = seconds_since(t0);
    double error = 0.0, refined_error = 0.0;
    const auto t1 = Clock::now();
    for (std::size_t i = 0; i < points.size(); ++i) {
      error = std::max(error, std::abs(w(points[i]) - exact[i]));
    }
    const double fast_s = seconds_since(t1);
    const auto t2 = Clock::now();
    for (std::size_t i = 0; i < points.size(); ++i) {
      refined_error = std::max(refined_error, std::abs(w(points[i], 8.0) - exact[i]));
    }
    const double refined_s = seconds_since(t2);
    EXPECT_LT(error, 0.06) << mesh.source;
    EXPECT_LT(refined_error, 2e-3) << mesh.source;
    const auto n = static_cast<double>(points.size());
    std::printf(
        "%s (%zu triangles): build %.2f ms; per query: exact %.1f us, hierarchy %.2f us (max "
        "error %.1e), accuracy 8 %.1f us (max error %.1e)\n",
        mesh.source.c_str(), mesh.triangles.size(), build_s * 1e3, exact_s / n * 1e6,
        fast_s / n * 1e6, error, refined_s / n * 1e6, refined_error);
  }
}

TEST(WindingNumber, TriangleIsItsCrossingPlusItsCurtains) {
  // For one triangle T and a point q: w_T(q) = (+-1 when the ray from q up through z crosses T,
  // + when T faces up) + the curtains hanging below its three edges (oriented_boundary's identity).
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto random_point = [&] {  // drawn in order: a constructor's arguments are in no fixed order
    const double x = u(rng), y = u(rng), z = u(rng);
    return Eigen::Vector3d(x, y, z);
  };
  auto cross_z = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return a.x() * b.y() - a.y() * b.x();
  };
  int crossed = 0;  // about 4% of random triangles cross q's ray: some 150 of 4000
  for (int trial = 0; trial < 4000; ++trial) {
    const std::array<Eigen::Vector3d, 3> t = {random_point(), random_point(), random_point()};
    const Eigen::Vector3d q = random_point();
    std::array<Eigen::Vector3d, 3> r;
    for (int k = 0; k < 3; ++k) r[k] = t[k] - q;
    // Crossing: q's vertical line inside the projected triangle, the triangle above q.
    const double area = cross_z(r[1] - r[0], r[2] - r[0]);
    const double w0 = cross_z(r[1], r[2]), w1 = cross_z(r[2], r[0]), w2 = cross_z(r[0], r[1]);
    double expected = 0.0;
    const bool inside = area > 0 ? (w0 > 0 && w1 > 0 && w2 > 0) : (w0 < 0 && w1 < 0 && w2 < 0);
    if (inside && (w0 * r[0].z() + w1 * r[1].z() + w2 * r[2].z()) / area > 0.0) {
      expected = area > 0 ? 1.0 : -1.0;
      ++crossed;
    }
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d& a = r[k];
      const Eigen::Vector3d& b = r[(k + 1) % 3];
      const double s = cross_z(a, b);
      expected += winding::curtain_fraction(a, b, s > 0 ? 1 : (s < 0 ? -1 : 0));
    }
    EXPECT_NEAR(winding::solid_angle_fraction(r[0], r[1], r[2]), expected, 1e-12) << trial;
  }
  EXPECT_GT(crossed, 100);
}

TEST(WindingNumber, EdgesBoundaryAndOrientation) {
  auto cube = load_mesh(mesh_path("cube.obj"));
  auto open = load_mesh(mesh_path("cube_open.obj"));
  auto duplicate = load_mesh(mesh_path("cube_duplicate_face.obj"));
  auto flipped = load_mesh(mesh_path("cube_open_flipped.obj"));
  auto inverted = load_mesh(mesh_path("cube_inverted.obj"));
  for (const auto* m : {&cube, &open, &duplicate, &flipped, &inverted}) {
    ASSERT_TRUE(*m) << m->message();
  }
  auto edges = winding::count_edges(cube->triangles);
  EXPECT_EQ(edges.open, 0U);
  EXPECT_EQ(edges.non_manifold, 0U);
  EXPECT_TRUE(winding::oriented_boundary(cube->triangles).empty());
  edges = winding::count_edges(open->triangles);
  EXPECT_EQ(edges.open, 4U);
  EXPECT_EQ(edges.non_manifold, 0U);
  EXPECT_EQ(winding::oriented_boundary(open->triangles).size(), 4U);
  // The duplicated face: its rim is used three times, its diagonal four times; orientation cancels
  // on the diagonal only.
  edges = winding::count_edges(duplicate->triangles);
  EXPECT_EQ(edges.open, 0U);
  EXPECT_EQ(edges.non_manifold, 5U);
  const auto rim = winding::oriented_boundary(duplicate->triangles);
  EXPECT_EQ(rim.size(), 4U);
  for (const auto& e : rim) EXPECT_EQ(std::abs(e.multiplicity), 1);

  // Two inward faces of five: turned back, after which the boundary is that of the open cube.
  std::vector<Eigen::Vector3i> triangles = flipped->triangles;
  auto turned = winding::orient_consistently(flipped->vertices, triangles);
  EXPECT_EQ(turned.reversed, 4U);
  EXPECT_TRUE(turned.orientable);
  EXPECT_EQ(winding::oriented_boundary(triangles).size(), 4U);
  const winding::WindingNumber w(flipped->vertices, triangles);
  EXPECT_NEAR(w.exact(Eigen::Vector3d(0.3, 0.5, 0.5)), 1.0, 0.2);
  // Consistently inverted: the majority keeps its orientation.
  triangles = inverted->triangles;
  turned = winding::orient_consistently(inverted->vertices, triangles);
  EXPECT_EQ(turned.reversed, 0U);
  EXPECT_EQ(triangles, inverted->triangles);

  // A Moebius strip of 12 quads cannot be oriented.
  TriangleMesh strip;
  const int n = 12;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * 3.141592653589793 * i / n;
    const Eigen::Vector3d centre(std::cos(a), std::sin(a), 0.0);
    const Eigen::Vector3d across =
        std::cos(a / 2) * Eigen::Vector3d(std::cos(a), std::sin(a), 0.0) +
        std::sin(a / 2) * Eigen::Vector3d::UnitZ();
    strip.vertices.push_back(centre - 0.2 * across);
    strip.vertices.push_back(centre + 0.2 * across);
  }
  for (int i = 0; i < n; ++i) {
    const int a = 2 * i, b = 2 * i + 1;
    // The last quad joins the first with its sides swapped: the half twist.
    const int c = i + 1 < n ? 2 * i + 2 : 1;
    const int d = i + 1 < n ? 2 * i + 3 : 0;
    strip.triangles.emplace_back(a, c, d);
    strip.triangles.emplace_back(a, d, b);
  }
  EXPECT_EQ(winding::count_edges(strip.triangles).non_manifold, 0U);
  triangles = strip.triangles;
  EXPECT_FALSE(winding::orient_consistently(strip.vertices, triangles).orientable);
}

TEST(WindingNumber, EveryInsideTestPicksTheSameParticlesOfTheClosedBunny) {
  // The closed bunny: ray parity (today's method), signed crossings (automatic), the winding
  // number summed over the triangles through the hierarchy, and the one from crossings and
  // curtains (no boundary here) pick exactly the same cells. No cell centre lies on the surface.
  auto bunny = load_mesh(bunny_path());
  ASSERT_TRUE(bunny) << bunny.message();
  ASSERT_EQ(count_open_edges(*bunny), 0U);
  const std::vector<double> diameters =
      motes_test::kSanitized ? std::vector<double>{0.5} : std::vector<double>{0.5, 0.27, 0.2};
  for (const double d : diameters) {
    std::vector<std::tuple<float, float, float>> reference;
    for (const auto& [test, label] :
         {std::pair{InsideTest::parity, "parity"},
          {InsideTest::automatic, "automatic"},
          {InsideTest::winding_number, "winding number (hierarchy)"},
          {InsideTest::winding_boundary, "winding number (crossings and curtains)"}}) {
      const auto start = Clock::now();
      auto particles = voxelize_with(*bunny, d, test);
      const double took = seconds_since(start);
      ASSERT_TRUE(particles) << particles.message();
      EXPECT_TRUE(particles->warnings.empty()) << label;
      std::printf("bunny, diameter %.2f, %s: %zu particles, %.1f ms\n", d, label,
                  particles->points.size(), took * 1e3);
      if (reference.empty()) {
        reference = sorted_points(*particles);
      } else {
        EXPECT_EQ(sorted_points(*particles), reference) << label << ", diameter " << d;
      }
    }
  }
}

TEST(WindingNumber, BunnyWithHolesAgreesWithTheExactSum) {
  // The bunny with holes in its base (open: the automatic test uses crossings and curtains) is
  // filled about like the closed bunny. Compared with the hierarchy, cells may differ only where
  // the exact winding number is within 1e-3 of 0.5; the automatic result agrees with the exact sum
  // on every particle checked.
  auto bunny = load_mesh(bunny_path());
  ASSERT_TRUE(bunny) << bunny.message();
  const TriangleMesh open = bunny_with_holes(*bunny);
  const auto boundary = winding::oriented_boundary(open.triangles);
  ASSERT_GT(boundary.size(), 10U);
  const winding::WindingNumber w(open.vertices, open.triangles);
  const double d = motes_test::kSanitized ? 0.27 : 0.2;
  auto closed = voxelize_with(*bunny, d, InsideTest::automatic);
  const auto start = Clock::now();
  auto automatic = voxelize_with(open, d, InsideTest::automatic);
  const double automatic_s = seconds_since(start);
  const auto start_tree = Clock::now();
  auto tree = voxelize_with(open, d, InsideTest::winding_number);
  const double tree_s = seconds_since(start_tree);
  ASSERT_TRUE(closed) << closed.message();
  ASSERT_TRUE(automatic) << automatic.message();
  ASSERT_TRUE(tree) << tree.message();
  std::printf(
      "bunny with holes (%zu boundary edges), diameter %.2f: %zu particles (closed: %zu); "
      "crossings and curtains %.1f ms, hierarchy %.1f ms\n",
      boundary.size(), d, automatic->points.size(), closed->points.size(), automatic_s * 1e3,
      tree_s * 1e3);
  ASSERT_EQ(automatic->warnings.size(), 1U);
  EXPECT_TRUE(automatic->warnings.front().find(fmt::format(
                  "bunny with holes: the mesh is not closed ({} open edges", boundary.size())) == 0)
      << automatic->warnings.front();
  EXPECT_NEAR(
      static_cast<double>(automatic->points.size()) / static_cast<double>(closed->points.size()),
      1.0, 0.02);
  const auto a = sorted_points(*automatic);
  const auto b = sorted_points(*tree);
  std::vector<std::tuple<float, float, float>> differ;
  std::set_symmetric_difference(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(differ));
  EXPECT_LT(differ.size(), 10U);
  for (const auto& [x, y, z] : differ) {
    EXPECT_NEAR(std::abs(w.exact(Eigen::Vector3d(x, y, z))), 0.5, 1e-3)
        << x << " " << y << " " << z;
  }
  for (std::size_t i = 0; i < automatic->points.size(); i += 17) {
    const Eigen::Vector3d p = automatic->points[i].cast<double>();
    EXPECT_GT(std::abs(w.exact(p)), 0.5 - 1e-6) << p.transpose();
  }
}

TEST(WindingNumber, CurtainRunsDecideEveryCellAsTheExactSum) {
  // A sliver of ten triangles, open and non-manifold (the input the mesh fuzzer found slow:
  // tests/data/fuzz-regressions/mesh/raw_open_sliver_slow). The automatic rule decides whole runs
  // of cells from bounds on the curtains (core/src/voxelize.cpp, fill_run); every cell of the
  // lattice is checked here against the exact sum over the triangles.
  TriangleMesh sliver;
  sliver.source = "sliver";
  sliver.vertices = {{3, 0, 0}, {115, 99, 110}, {-3, 0, 0}, {0, 2, 0}, {0, 0, -1}, {-1, 0, -3}};
  sliver.triangles = {{0, 0, 0}, {3, 0, 0}, {1, 0, 2}, {4, 2, 1}, {4, 1, 3},
                      {4, 3, 0}, {4, 2, 0}, {5, 1, 2}, {3, 3, 1}, {5, 0, 3}};
  std::vector<Eigen::Vector3i> oriented = sliver.triangles;
  (void)winding::orient_consistently(sliver.vertices, oriented);
  const winding::WindingNumber w(sliver.vertices, oriented);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(HUGE_VAL), hi = -lo;
  for (const auto& v : sliver.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const std::vector<double> diameters = motes_test::kSanitized
                                            ? std::vector<double>{1.8225806431134892}
                                            : std::vector<double>{1.8225806431134892, 1.0};
  for (const double d : diameters) {
    SCOPED_TRACE(d);
    auto set = voxelize_with(sliver, d, InsideTest::automatic);
    ASSERT_TRUE(set) << set.message();
    const auto chosen = sorted_points(*set);
    // The lattice of make_lattice: the fewest cells covering the box, centred on it.
    std::array<long, 3> n{};
    Eigen::Vector3d first;
    for (int a = 0; a < 3; ++a) {
      n[a] = static_cast<long>(std::max(1.0, std::ceil((hi[a] - lo[a]) / d * (1.0 - 1e-9))));
      first[a] = 0.5 * (lo[a] + hi[a]) - 0.5 * (static_cast<double>(n[a]) - 1.0) * d;
    }
    std::size_t inside = 0, wrong = 0, near_half = 0;
    for (long i = 0; i < n[0]; ++i) {
      for (long j = 0; j < n[1]; ++j) {
        for (long k = 0; k < n[2]; ++k) {
          const Eigen::Vector3d p =
              first + d * Eigen::Vector3d(static_cast<double>(i), static_cast<double>(j),
                                          static_cast<double>(k));
          const double exact = std::abs(w.exact(p));
          const bool found = std::binary_search(
              chosen.begin(), chosen.end(),
              std::make_tuple(static_cast<float>(p.x()), static_cast<float>(p.y()),
                              static_cast<float>(p.z())));
          inside += found ? 1 : 0;
          if (std::abs(exact - 0.5) < 1e-9) {
            ++near_half;
          } else if (found != (exact > 0.5)) {
            ++wrong;
          }
        }
      }
    }
    EXPECT_EQ(inside, chosen.size());
    EXPECT_GT(inside, 10U);
    EXPECT_EQ(wrong, 0U);
    EXPECT_EQ(near_half, 0U);
  }
}

TEST(WindingNumber, CommandLineWarnsOnceNamingTheFile) {
  motes_test::TempDir tmp;
  const std::string open = mesh_path("cube_open.obj");
  const auto v = motes_test::run_motes(tmp, {"voxelize", open, "--diameter", "0.1"});
  ASSERT_EQ(v.exit_code, 0) << motes_test::describe(v);
  EXPECT_TRUE(motes_test::contains(v.out, "1000")) << motes_test::describe(v);
  const std::string warning = "motes: warning: " + open + ": the mesh is not closed (4 open edges";
  const auto first = v.err.find(warning);
  EXPECT_NE(first, std::string::npos) << motes_test::describe(v);
  EXPECT_EQ(v.err.find("motes: warning:", first + 1), std::string::npos) << motes_test::describe(v);
  const auto closed =
      motes_test::run_motes(tmp, {"voxelize", mesh_path("cube.obj"), "--count", "100"});
  ASSERT_EQ(closed.exit_code, 0) << motes_test::describe(closed);
  EXPECT_FALSE(motes_test::contains(closed.err, "warning")) << motes_test::describe(closed);
  const auto sheet =
      motes_test::run_motes(tmp, {"voxelize", mesh_path("sheet.obj"), "--count", "100"});
  EXPECT_EQ(sheet.exit_code, 2) << motes_test::describe(sheet);
  EXPECT_TRUE(motes_test::contains(sheet.err, mesh_path("sheet.obj") + ": the mesh is flat"))
      << motes_test::describe(sheet);

  // A scene with two bodies of the open cube (one shared particle set) and one at another size:
  // each distinct warning once.
  const std::string scene = tmp / "open.json";
  std::ofstream(scene) << R"({
  "settings": {"contact": {"stiffness": 1000}},
  "bodies": [
    {"name": "a", "shape": {"type": "mesh", "file": ")"
                       << open << R"(", "scale": 0.1, "particle_diameter": 0.01}},
    {"name": "b", "shape": {"type": "mesh", "file": ")"
                       << open << R"(", "scale": 0.1, "particle_diameter": 0.01},
     "position": [1, 0, 0]}
  ]
})";
  const auto r = motes_test::run_motes(
      tmp, {"run", scene, "--steps", "1", "--format", "none", "--backend", "openmp"});
  ASSERT_EQ(r.exit_code, 0) << motes_test::describe(r);
  const auto at = r.err.find("motes: warning: " + open + ": the mesh is not closed");
  EXPECT_NE(at, std::string::npos) << motes_test::describe(r);
  EXPECT_EQ(r.err.find("motes: warning:", at + 1), std::string::npos) << motes_test::describe(r);
}

}  // namespace
}  // namespace motes
