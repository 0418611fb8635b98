// Scene loading (docs/scene-format.md): the example scenes, defaults, repeats, shapes, planes, the
// stability check, and one error per kind of malformed scene (tests/data/scenes/bad/).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "motes/scene.h"
#include "unit/test_support.h"

namespace motes {
namespace {

using motes_test::example_path;
using motes_test::kPi;
using motes_test::stable_substep;

std::string data(const std::string& name) {
  std::string path = MOTES_TEST_DATA_DIR;  // appended, not +: GCC 12 warns falsely (-Warray-bounds)
  path += "/scenes/";
  path += name;
  return path;
}

Scene load_or_fail(const std::string& path) {
  Result<Scene> r = load_scene_file(path);
  if (!r) ADD_FAILURE() << r.message();
  return r ? std::move(r).value() : Scene{};
}

/// Contact time pi / w0 of the stiffest, lightest contact: w0 = sqrt(k / m*), VALIDATION.md 1.
double contact_time(double stiffness, double m_eff) { return kPi / std::sqrt(stiffness / m_eff); }

double particle_mass(const Scene& s, const BodySpec& b) {
  const double d = b.shape->diameter;
  return s.materials[static_cast<std::size_t>(b.material)].density * d * d * d;
}

Eigen::Vector3d extent(const ParticleSet& p) {
  Eigen::Vector3f lo = p.points[0], hi = p.points[0];
  for (const auto& x : p.points) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  return (hi - lo).cast<double>();
}

// ---- example scenes ----

TEST(SceneExamples, DominoesIsAChainOf40With15ParticlesEach) {
  const Scene s = load_or_fail(example_path("dominoes.json"));
  ASSERT_EQ(s.bodies.size(), 40u);
  EXPECT_EQ(s.particle_count(), 600u);
  EXPECT_EQ(s.bodies[0].name, "first");
  EXPECT_EQ(s.bodies[1].name, "domino[0]");
  EXPECT_EQ(s.bodies[39].name, "domino[38]");
  const double d = s.bodies[0].shape->diameter;
  EXPECT_DOUBLE_EQ(d, 0.01);
  for (const BodySpec& b : s.bodies) {
    EXPECT_EQ(b.shape, s.bodies[0].shape) << b.name << ": identical shapes share one set";
    EXPECT_EQ(b.kind, BodyKind::Dynamic);
  }
  // 1 x 5 x 3 particles: thin along the chain (x), 5 high.
  const Eigen::Vector3d e = extent(*s.bodies[0].shape);
  EXPECT_NEAR(e.x(), 0.0, 1e-7);
  EXPECT_NEAR(e.y(), 4 * d, 1e-7);
  EXPECT_NEAR(e.z(), 2 * d, 1e-7);
  // Spacing 0.6 x the height (5 d), in a straight line along x, standing on the floor.
  const double height = 5 * d;
  for (std::size_t i = 1; i < s.bodies.size(); ++i) {
    const Eigen::Vector3d step = s.bodies[i].position - s.bodies[i - 1].position;
    EXPECT_NEAR(step.x(), 0.6 * height, 1e-12);
    EXPECT_NEAR(step.y(), 0.0, 1e-12);
    EXPECT_NEAR(step.z(), 0.0, 1e-12);
    EXPECT_TRUE(s.bodies[i].angular_velocity.isZero()) << s.bodies[i].name;
  }
  EXPECT_NEAR(s.bodies[0].position.y(), height / 2, 1e-12);
  // Only the first is tipped, towards the chain (+x at the top: rotation about -z).
  EXPECT_LT(s.bodies[0].angular_velocity.z(), 0.0);
  ASSERT_EQ(s.planes.size(), 1u);
  EXPECT_EQ(s.planes[0].normal, Eigen::Vector3d(0, 1, 0));
  EXPECT_EQ(s.planes[0].point.y(), 0.0);
  // dt about t_c / 50 for two particles (m* = m / 2).
  const double m = particle_mass(s, s.bodies[0]);
  const double tc = contact_time(s.materials[0].stiffness, m / 2);
  EXPECT_GT(tc / s.settings.dt, 40.0);
  EXPECT_LT(tc / s.settings.dt, 60.0);
}

TEST(SceneExamples, DiceArePileOf4x4x4CubesInABox) {
  const Scene s = load_or_fail(example_path("dice.json"));
  ASSERT_EQ(s.bodies.size(), 36u);
  EXPECT_EQ(s.particle_count(), 36u * 64u);
  for (const BodySpec& b : s.bodies) EXPECT_EQ(b.shape, s.bodies[0].shape);
  EXPECT_EQ(s.bodies[35].name, "die[35]");
  // Each copy turned a little further.
  EXPECT_GT(s.bodies[0].rotation.angularDistance(s.bodies[1].rotation), 0.1);
  ASSERT_EQ(s.planes.size(), 5u);
  EXPECT_EQ(s.planes[0].name, "tray.floor");
  EXPECT_EQ(s.planes[0].normal, Eigen::Vector3d(0, 1, 0));
  EXPECT_EQ(s.planes[0].point.y(), 0.0);
  // Every particle of every die starts clear of the floor and the walls.
  const ParticleSet& die = *s.bodies[0].shape;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& p : die.points) centre += p.cast<double>();
  centre /= static_cast<double>(die.points.size());
  for (const BodySpec& b : s.bodies) {
    for (const auto& local : die.points) {
      const Eigen::Vector3d x = b.position + b.rotation * (local.cast<double>() - centre);
      for (const PlaneSpec& p : s.planes) {
        EXPECT_GT(p.normal.dot(x - p.point), die.diameter / 2) << b.name << " vs " << p.name;
      }
    }
  }
  const double m = particle_mass(s, s.bodies[0]);
  const double k = s.materials[static_cast<std::size_t>(s.bodies[0].material)].stiffness;
  const double tc = contact_time(k, m / 2);
  EXPECT_GT(tc / s.settings.dt, 40.0);
  EXPECT_LT(tc / s.settings.dt, 60.0);
}

TEST(SceneExamples, BunnyIsVoxelizedNearItsParticleCount) {
  const Scene s = load_or_fail(example_path("bunny.json"));
  ASSERT_EQ(s.bodies.size(), 1u);
  const std::size_t n = s.particle_count();
  EXPECT_NEAR(static_cast<double>(n), 3000.0, 150.0);
  const Eigen::Vector3d e = extent(*s.bodies[0].shape);
  EXPECT_GT(e.maxCoeff(), 0.2);
  EXPECT_LT(e.maxCoeff(), 0.3);
  EXPECT_NEAR(s.bodies[0].rotation.angularDistance(Eigen::Quaterniond::Identity()), kPi / 6, 1e-9);
  // One dynamic body: its only contacts are with the floor (m* = m).
  const double m = particle_mass(s, s.bodies[0]);
  const double tc = contact_time(s.materials[0].stiffness, m);
  EXPECT_GT(tc / s.settings.dt, 40.0);
  EXPECT_LT(tc / s.settings.dt, 60.0);
}

TEST(SceneExamples, BuiltInSceneIsTheDominoChain) {
  Result<Scene> r = builtin_default_scene();
  ASSERT_TRUE(r) << r.message();
  const Scene file = load_or_fail(example_path("dominoes.json"));
  EXPECT_EQ(r->source, "<built-in>");
  EXPECT_EQ(r->bodies.size(), file.bodies.size());
  EXPECT_EQ(r->particle_count(), file.particle_count());
  EXPECT_EQ(r->settings.dt, file.settings.dt);
}

// ---- defaults, repeats, shapes and planes ----

TEST(SceneLoad, SoftBodiesAreReadAndCheckedWithLocatedErrors) {
  const auto load = [](const std::string& soft, const std::string& kind = "soft") {
    const std::string text = R"({"settings": {"contact": {"stiffness": 1000}}, "bodies": [
      {"kind": ")" + kind + R"(", "shape": {"type": "box", "particles": [3, 3, 3]}, "soft": )" +
                             soft + "}]}";
    return load_scene_text(text, "s.json", ".");
  };
  Result<Scene> ok = load(
      R"({"frequency": 20, "damping": 40, "mode": "quadratic", "beta": 0.3, "clusters": [2, 1, 3]})");
  ASSERT_TRUE(ok) << ok.message();
  ASSERT_TRUE(ok->bodies[0].soft.has_value());
  const motes::SoftSpec& soft = *ok->bodies[0].soft;
  EXPECT_EQ(soft.frequency, 20.0);
  EXPECT_EQ(soft.damping, 40.0);
  EXPECT_EQ(soft.mode, motes::SoftMode::Quadratic);
  EXPECT_EQ(soft.beta, 0.3);
  EXPECT_EQ(soft.clusters, (std::array<int, 3>{2, 1, 3}));
  // "kind": "soft" alone: the defaults.
  Result<Scene> plain = load_scene_text(
      R"({"settings": {"contact": {"stiffness": 1000}}, "bodies": [
        {"kind": "soft", "shape": {"type": "box", "particles": [2, 2, 2]}}]})",
      "s.json", ".");
  ASSERT_TRUE(plain) << plain.message();
  EXPECT_EQ(plain->bodies[0].soft->stiffness, 0.5);
  EXPECT_EQ(plain->bodies[0].soft->mode, motes::SoftMode::Rigid);
  const std::vector<std::pair<std::string, std::string>> bad = {
      {R"({"stiffness": 1.5})", "s.json: /bodies/0/soft/stiffness: the stiffness is a fraction"},
      {R"({"stiffness": 0})", "s.json: /bodies/0/soft/stiffness: must be a positive number"},
      {R"({"stiffness": 0.5, "frequency": 10})",
       "s.json: /bodies/0/soft/frequency: give \"stiffness\" (per substep) or \"frequency\""},
      {R"({"mode": "cubic"})", "s.json: /bodies/0/soft/mode: must be \"rigid\", \"linear\" or"},
      {R"({"beta": 0.5})", "s.json: /bodies/0/soft/beta: beta needs \"mode\""},
      {R"({"mode": "linear", "beta": 2})", "s.json: /bodies/0/soft/beta: beta blends"},
      {R"({"damping": -1})", "s.json: /bodies/0/soft/damping:"},
      {R"({"clusters": [0, 1, 1]})", "s.json: /bodies/0/soft/clusters/0:"},
      {R"({"stiffnes": 0.5})", "s.json: /bodies/0/soft/stiffnes: unknown key \"stiffnes\""},
  };
  for (const auto& [soft_text, want] : bad) {
    Result<Scene> r = load(soft_text);
    ASSERT_FALSE(r) << soft_text;
    EXPECT_NE(r.message().find(want), std::string::npos) << soft_text << ": " << r.message();
  }
  Result<Scene> not_soft = load("{}", "dynamic");
  ASSERT_FALSE(not_soft);
  EXPECT_NE(not_soft.message().find("s.json: /bodies/0/soft: \"soft\" settings need"),
            std::string::npos)
      << not_soft.message();
}

TEST(SceneLoad, OpenMeshIsFilledWithAWarning) {
  // A box without its top (4 open edges): filled by the generalized winding number, with a warning
  // naming the file and the condition.
  Result<Scene> s = load_scene_file(data("open_mesh.json"));
  ASSERT_TRUE(s) << s.message();
  ASSERT_FALSE(s->bodies.empty());
  const auto& warnings = s->bodies[0].shape->warnings;
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("open_box.obj"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("not closed (4 open edges"), std::string::npos) << warnings[0];
  EXPECT_GT(s->bodies[0].shape->points.size(), 0u);
}

TEST(SceneLoad, CameraIsOptionalAndReadWithDefaults) {
  const std::string base =
      R"({"settings": {"contact": {"stiffness": 1000}}, "bodies": [{"shape": {"type": "particle"}}])";
  Result<Scene> none = load_scene_text(base + "}", "s", "");
  ASSERT_TRUE(none) << none.message();
  EXPECT_FALSE(none->camera.has_value());
  Result<Scene> some = load_scene_text(
      base + R"(, "camera": {"position": [1, 2, 3], "target": [0, 0.5, 0], "up": [0, 0, 2]}})", "s",
      "");
  ASSERT_TRUE(some) << some.message();
  ASSERT_TRUE(some->camera.has_value());
  EXPECT_EQ(some->camera->position, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(some->camera->target, Eigen::Vector3d(0, 0.5, 0));
  EXPECT_EQ(some->camera->up, Eigen::Vector3d(0, 0, 1));  // normalized
  EXPECT_EQ(some->camera->fov, CameraSpec{}.fov);
}

TEST(SceneLoad, BodyColorIsOptionalAsNumbersOrHex) {
  Result<Scene> s = load_scene_text(
      R"({"settings": {"contact": {"stiffness": 1000}}, "bodies": [
          {"shape": {"type": "particle"}, "color": [1, 0.5, 0]},
          {"shape": {"type": "particle"}, "position": [1, 0, 0], "color": "#00FF80"},
          {"shape": {"type": "particle"}, "position": [2, 0, 0]}]})",
      "s", "");
  ASSERT_TRUE(s) << s.message();
  ASSERT_TRUE(s->bodies[0].color.has_value());
  EXPECT_EQ(*s->bodies[0].color, Eigen::Vector3d(1, 0.5, 0));
  ASSERT_TRUE(s->bodies[1].color.has_value());
  EXPECT_EQ(*s->bodies[1].color, Eigen::Vector3d(0, 1, 128 / 255.0));
  EXPECT_FALSE(s->bodies[2].color.has_value());
}

TEST(SceneLoad, DefaultsAreApplied) {
  const Scene s = load_or_fail(data("defaults.json"));
  const Settings def;
  EXPECT_EQ(s.settings.dt, def.dt);
  EXPECT_EQ(s.settings.substeps, 1);
  EXPECT_EQ(s.settings.gravity, Eigen::Vector3d(0, -9.81, 0));
  EXPECT_EQ(s.settings.particle_diameter, 0.01);
  EXPECT_FALSE(s.settings.clamp_attraction);
  EXPECT_EQ(s.settings.duration, def.duration);
  EXPECT_EQ(s.settings.output_interval, def.output_interval);

  ASSERT_EQ(s.materials.size(), 3u);
  const Material& d = s.materials[0];
  EXPECT_EQ(d.name, "default");
  EXPECT_EQ(d.density, 1000.0);
  EXPECT_EQ(d.stiffness, 1000.0);
  EXPECT_EQ(d.damping, 0.0);
  EXPECT_EQ(d.tangential, 0.0);
  EXPECT_EQ(d.friction, 0.3);
  // Missing fields come from settings.contact; null friction removes the cap.
  EXPECT_EQ(s.materials[1].name, "heavy");
  EXPECT_EQ(s.materials[1].density, 5000.0);
  EXPECT_EQ(s.materials[1].stiffness, 1000.0);
  EXPECT_EQ(s.materials[1].friction, 0.3);
  EXPECT_EQ(s.materials[2].name, "slippery");
  EXPECT_LT(s.materials[2].friction, 0.0);
  EXPECT_EQ(s.materials[2].damping, 4.0);

  ASSERT_EQ(s.bodies.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    const BodySpec& b = s.bodies[static_cast<std::size_t>(i)];
    EXPECT_EQ(b.name, fmt::format("body{}", i));
    EXPECT_EQ(b.material, i);
    EXPECT_EQ(b.kind, BodyKind::Dynamic);
    EXPECT_TRUE(b.rotation.isApprox(Eigen::Quaterniond::Identity()));
    EXPECT_TRUE(b.velocity.isZero());
    EXPECT_TRUE(b.angular_velocity.isZero());
    ASSERT_EQ(b.shape->points.size(), 1u);
    EXPECT_EQ(b.shape->diameter, 0.01);
  }
  EXPECT_TRUE(s.planes.empty());
  EXPECT_EQ(s.source, data("defaults.json"));
}

TEST(SceneLoad, RepeatGridExpandsInOrderWithRotationSteps) {
  const Scene s = load_or_fail(data("repeat_grid.json"));
  ASSERT_EQ(s.bodies.size(), 12u + 4u);
  const Eigen::Quaterniond base(Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitZ()));
  const Eigen::Quaterniond step(Eigen::AngleAxisd(kPi / 18, Eigen::Vector3d::UnitY()));
  Eigen::Quaterniond expected_rotation = base;
  std::size_t i = 0;
  for (int z = 0; z < 2; ++z) {
    for (int y = 0; y < 3; ++y) {
      for (int x = 0; x < 2; ++x, ++i) {
        const BodySpec& b = s.bodies[i];
        EXPECT_EQ(b.name, fmt::format("p[{}]", i));
        EXPECT_TRUE(b.position.isApprox(Eigen::Vector3d(1 + 0.1 * x, 2 + 0.2 * y, 3 + 0.3 * z)))
            << b.name << ": " << b.position.transpose();
        EXPECT_LT(b.rotation.angularDistance(expected_rotation), 1e-9) << b.name;
        EXPECT_EQ(b.velocity, Eigen::Vector3d(0, -1, 0));
        EXPECT_EQ(b.shape, s.bodies[0].shape);
        expected_rotation = step * expected_rotation;
      }
    }
  }
  EXPECT_EQ(s.bodies[0].shape->points.size(), 8u);
  EXPECT_EQ(s.bodies[0].shape->diameter, 0.02);
  for (int k = 0; k < 4; ++k) {
    const BodySpec& b = s.bodies[12 + static_cast<std::size_t>(k)];
    EXPECT_EQ(b.name, fmt::format("row[{}]", k));
    EXPECT_EQ(b.kind, BodyKind::Static);
    EXPECT_NEAR(b.position.z(), 0.5 * k, 1e-12);
    EXPECT_EQ(b.shape, s.bodies[12].shape);
  }
  EXPECT_EQ(s.particle_count(), 12u * 8u + 4u * s.bodies[12].shape->points.size());
}

TEST(SceneLoad, EveryShapeTypeBuildsItsParticles) {
  const Scene s = load_or_fail(data("shapes.json"));
  ASSERT_EQ(s.bodies.size(), 9u);
  const auto count = [&](std::size_t i) {
    return static_cast<double>(s.bodies[i].shape->points.size());
  };
  EXPECT_EQ(count(0), 4 * 2 * 3);  // box 4 x 2 x 3 cm at d = 1 cm
  EXPECT_EQ(count(1), 3 * 1 * 2);  // exact lattice
  EXPECT_EQ(s.bodies[1].shape->diameter, 0.05);
  EXPECT_NEAR(count(2), 4.0 / 3.0 * kPi * 125, 0.1 * 4.0 / 3.0 * kPi * 125);  // r = 5 d
  EXPECT_NEAR(count(3), kPi * 9 * 10, 0.1 * kPi * 9 * 10);                    // r = 3 d, h = 10 d
  EXPECT_NEAR(count(4), kPi * 9 * 10 + 4.0 / 3.0 * kPi * 27, 0.1 * 400);      // + two caps
  EXPECT_EQ(count(5), 1);                                                     // one sphere
  EXPECT_EQ(s.bodies[5].shape->diameter, 0.2);
  EXPECT_NEAR(count(6), 1000, 100);  // 10 cm cube at 1 cm
  EXPECT_EQ(s.bodies[7].shape, s.bodies[6].shape) << "the same mesh shape is built once";
  EXPECT_NEAR(count(8), 200, 20);  // target count on a 2:1:1 brick
  // Outer size (centre extent + one diameter) keeps the 2:1 aspect, to a cell.
  const Eigen::Vector3d brick =
      extent(*s.bodies[8].shape) + Eigen::Vector3d::Constant(s.bodies[8].shape->diameter);
  EXPECT_NEAR(brick.x() / brick.y(), 2.0, 0.35);

  std::size_t total = 0;
  for (const BodySpec& b : s.bodies) total += b.shape->points.size();
  EXPECT_EQ(s.particle_count(), total);
}

TEST(SceneLoad, PlanesAreNormalizedAndBoxesExpand) {
  const Scene s = load_or_fail(data("shapes.json"));
  ASSERT_EQ(s.planes.size(), 1u + 6u);
  EXPECT_TRUE(s.planes[0].normal.isApprox(Eigen::Vector3d(0, 1, 1).normalized()));
  EXPECT_EQ(s.planes[0].point, Eigen::Vector3d(0, -1, 0));
  struct Face {
    const char* name;
    Eigen::Vector3d normal;
    double offset;  // normal . point
  };
  const std::vector<Face> faces = {{"bin.floor", {0, 1, 0}, -2},   {"bin.x_min", {1, 0, 0}, -1},
                                   {"bin.x_max", {-1, 0, 0}, -10}, {"bin.z_min", {0, 0, 1}, -3},
                                   {"bin.z_max", {0, 0, -1}, -3},  {"bin.top", {0, -1, 0}, -5}};
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const PlaneSpec& p = s.planes[1 + i];
    EXPECT_EQ(p.name, faces[i].name);
    EXPECT_EQ(p.normal, faces[i].normal) << p.name;
    EXPECT_DOUBLE_EQ(p.normal.dot(p.point), faces[i].offset) << p.name;
  }
}

TEST(SceneLoad, TextResolvesMeshesFromBaseDir) {
  const std::string text = R"({"settings": {"contact": {"stiffness": 1000}},
    "bodies": [{"shape": {"type": "mesh", "file": "cube.obj", "scale": 0.05}}]})";
  Result<Scene> ok = load_scene_text(text, "inline", std::string(MOTES_TEST_DATA_DIR) + "/scenes");
  ASSERT_TRUE(ok) << ok.message();
  EXPECT_NEAR(static_cast<double>(ok->particle_count()), 125, 20);
  Result<Scene> bad = load_scene_text(text, "inline", "/nonexistent-folder");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.message().find("inline: /bodies/0/shape/file: cannot open mesh"), std::string::npos)
      << bad.message();
}

// ---- stability ----

std::string two_balls(double dt, int substeps, bool planes_only) {
  return fmt::format(
      R"({{"settings": {{"dt": {}, "substeps": {}, "contact": {{"stiffness": 100000, "damping": 2000}}}},
          "bodies": [{{"name": "b", "shape": {{"type": "particle"}}, "repeat": {{"count": {},
          "offset": [0.1, 0, 0]}}}}], "planes": [{{"normal": [0, 1, 0]}}]}})",
      dt, substeps, planes_only ? 1 : 2);
}

TEST(SceneStability, DtJustBelowTheLimitLoadsAndJustAboveFails) {
  const double m = 1000.0 * 1e-6;  // default density and diameter
  for (bool single : {false, true}) {
    // One ball meets only the floor (m* = m); two balls can meet each other (m* = m / 2).
    const double h = stable_substep(1e5, 2000, single ? m : m / 2);
    for (int substeps : {1, 3}) {
      const double limit = h * substeps;
      Result<Scene> ok = load_scene_text(two_balls(0.99 * limit, substeps, single), "s", "");
      EXPECT_TRUE(ok) << ok.message();
      Result<Scene> bad = load_scene_text(two_balls(1.01 * limit, substeps, single), "s", "");
      ASSERT_FALSE(bad);
      EXPECT_NE(bad.message().find("s: /settings/dt: unstable"), std::string::npos)
          << bad.message();
      EXPECT_NE(bad.message().find(fmt::format("largest stable dt is just under {:.4g} s", limit)),
                std::string::npos)
          << bad.message();
    }
  }
}

// ---- initial speeds (docs/reliability.md) ----

/// A ball of 1 cm (or a cloth of them) at `speed` m/s along x, or a 3 x 3 x 3 box spinning at
/// `spin` rad/s about y, with dt and substeps.
std::string moving(const std::string& body, double dt, int substeps) {
  return fmt::format(
      R"({{"settings": {{"dt": {}, "substeps": {}, "particle_diameter": 0.01,
          "contact": {{"stiffness": 1000, "damping": 10}}}}, "bodies": [{}]}})",
      dt, substeps, body);
}

TEST(SceneInitialSpeed, JustUnderTheLimitLoadsAndJustOverFails) {
  // Half a particle radius (2.5 mm) per substep: 25 m/s at dt = 1e-4 s, 75 m/s at 3 substeps.
  for (int substeps : {1, 3}) {
    const double limit = 0.0025 * substeps / 1e-4;
    const auto ball = [&](double v) {
      return moving(fmt::format(R"({{"name": "ball", "shape": {{"type": "particle"}},
                                     "velocity": [{}, 0, 0]}})",
                                v),
                    1e-4, substeps);
    };
    Result<Scene> ok = load_scene_text(ball(0.99 * limit), "s", "");
    EXPECT_TRUE(ok) << ok.message();
    Result<Scene> bad = load_scene_text(ball(1.01 * limit), "s", "");
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.message().find("s: /bodies/0/velocity: body \"ball\" starts too fast"),
              std::string::npos)
        << bad.message();
    EXPECT_NE(bad.message().find(fmt::format("largest safe speed at this dt is {:.4g} m/s", limit)),
              std::string::npos)
        << bad.message();
    // The largest safe dt at this speed loads (a hair under it: the message rounds).
    const double safe_dt = 0.0025 * substeps / (1.01 * limit);
    EXPECT_NE(bad.message().find(fmt::format("largest safe dt at this speed {:.4g} s", safe_dt)),
              std::string::npos)
        << bad.message();
    const std::string at_safe_dt =
        moving(fmt::format(R"({{"name": "ball", "shape": {{"type": "particle"}},
                               "velocity": [{}, 0, 0]}})",
                           1.01 * limit),
               0.999 * safe_dt, substeps);
    Result<Scene> slower = load_scene_text(at_safe_dt, "s", "");
    EXPECT_TRUE(slower) << slower.message();
  }
  // A spinning box: its corner particles, sqrt(3) cm from the centre, go fastest.
  const double reach = std::sqrt(3.0) * 0.01;
  const double spin_limit = 25.0 / reach;
  for (double f : {0.99, 1.01}) {
    const std::string box =
        moving(fmt::format(R"({{"name": "box", "shape": {{"type": "box", "particles": [3, 3, 3]}},
                        "angular_velocity": [0, {}, 0]}})",
                           f * spin_limit),
               1e-4, 1);
    Result<Scene> r = load_scene_text(box, "s", "");
    EXPECT_EQ(static_cast<bool>(r), f < 1.0) << f << ": " << (r ? "" : r.message());
    if (!r) {
      EXPECT_NE(r.message().find("s: /bodies/0/angular_velocity: body \"box\""), std::string::npos)
          << r.message();
    }
  }
  // A cloth: its velocity, its particle diameter.
  for (double f : {0.99, 1.01}) {
    const std::string cloth =
        moving(fmt::format(R"({{"name": "sheet", "kind": "cloth", "cloth": {{"corner": [0, 1, 0],
                        "edge_u": [0.1, 0, 0], "edge_v": [0, 0, 0.1], "particles": [11, 11]}},
                        "velocity": [0, {}, 0]}})",
                           -f * 25.0),
               1e-4, 1);
    Result<Scene> r = load_scene_text(cloth, "s", "");
    EXPECT_EQ(static_cast<bool>(r), f < 1.0) << f << ": " << (r ? "" : r.message());
    if (!r) {
      EXPECT_NE(r.message().find("s: /bodies/0/velocity: cloth \"sheet\" starts too fast"),
                std::string::npos)
          << r.message();
    }
  }
}

// A static body has no speed to check, and a body at rest none either: every example scene loads.
TEST(SceneInitialSpeed, ExampleScenesLoad) {
  for (const char* name : {"dominoes", "dice", "bunny", "cloth", "rope", "soft"}) {
    Result<Scene> r =
        load_scene_file(std::string(MOTES_SOURCE_DIR) + "/examples/scenes/" + name + ".json");
    EXPECT_TRUE(r) << name << ": " << r.message();
  }
}

// ---- malformed scenes: each gives its path and reason ----

struct BadCase {
  const char* file;
  std::vector<std::string> expected;  ///< substrings after "FILE"
};

class SceneErrors : public ::testing::TestWithParam<BadCase> {};

TEST_P(SceneErrors, NamesFilePathAndReason) {
  const BadCase& c = GetParam();
  const std::string path = data(std::string("bad/") + c.file);
  Result<Scene> r = load_scene_file(path);
  ASSERT_FALSE(r) << c.file << " loaded";
  const std::string& msg = r.message();
  EXPECT_EQ(msg.rfind(path + ":", 0), 0u) << msg;
  for (const std::string& e : c.expected) {
    EXPECT_NE(msg.find(e), std::string::npos) << "expected \"" << e << "\" in: " << msg;
  }
}

const BadCase kBadCases[] = {
    {"syntax_error.json", {":3:3: syntax error while parsing object"}},
    {"nan_literal.json", {":3:59: syntax error while parsing value - invalid literal"}},
    {"empty.json", {":1:1: syntax error", "unexpected end of input"}},
    {"overflow_double.json", {":3:62: number 1e400 is out of range"}},
    {"not_object.json", {": /: must be an object, got an array of 3 values"}},
    {"unknown_top_key.json",
     {": /bodys: unknown key \"bodys\"",
      "(allowed: description, settings, materials, bodies, planes, camera)"}},
    {"unknown_body_key.json", {": /bodies/0/colour: unknown key \"colour\"", "angular_velocity"}},
    {"unknown_settings_key.json", {": /settings/timestep: unknown key \"timestep\"", "dt"}},
    {"unknown_repeat_key.json", {": /bodies/0/repeat/offsets: unknown key \"offsets\""}},
    {"wrong_type.json", {": /settings/dt: must be a positive number, got \"fast\""}},
    {"negative_dt.json", {": /settings/dt: must be a positive number, got -0.0001"}},
    {"zero_substeps.json", {": /settings/substeps: must be an integer from 1 to", "got 0"}},
    {"fractional_substeps.json", {": /settings/substeps: must be an integer", "got 2.5"}},
    {"unknown_material.json",
     {": /bodies/0/material: unknown material \"rubber\" (defined: default, steel)"}},
    {"bad_shape_type.json", {": /bodies/0/shape/type: unknown shape type \"cone\""}},
    {"missing_shape.json", {": /bodies/0: missing required key \"shape\""}},
    {"missing_bodies.json", {": /: missing required key \"bodies\""}},
    {"no_bodies.json", {": /bodies: a scene needs at least one body"}},
    {"negative_radius.json", {": /bodies/3/shape/radius: must be a positive number, got -1"}},
    {"missing_mesh.json", {": /bodies/0/shape/file: cannot open mesh", "no_such_mesh.obj"}},
    {"unreadable_mesh.json", {": /bodies/0/shape/file: ", "garbage.obj"}},
    {"mesh_diameter_and_count.json",
     {": /bodies/0/shape: give either \"particle_diameter\" or \"particle_count\""}},
    {"zero_normal.json", {": /planes/0/normal: must be a non-zero vector"}},
    {"bad_plane_type.json", {": /planes/0/type: unknown plane type \"sphere\""}},
    {"box_planes_inverted.json", {": /planes/0/max/1: must be greater than min[1]"}},
    {"huge_number.json", {": /settings/particle_diameter: out of range", "32-bit float"}},
    {"tiny_diameter.json", {": /bodies/0/shape/particle_diameter: out of range", "too small"}},
    {"repeat_far_away.json", {": /bodies/0/repeat: copy 2 lands outside the float range"}},
    {"unstable_dt.json",
     {": /settings/dt: unstable", "body \"ball\"", "plane \"floor\"", "largest stable dt"}},
    {"repeat_count_zero.json", {": /bodies/0/repeat/count: must be an integer from 1", "got 0"}},
    {"zero_density.json", {": /materials/steel/density: must be a positive number, got 0"}},
    {"escaped_material_name.json", {": /materials/a~1b~0c/density: must be a positive number"}},
    {"negative_friction.json",
     {": /settings/contact/friction: must be a non-negative number, got -0.5"}},
    {"missing_stiffness.json", {": /settings/contact: missing required key \"stiffness\""}},
    {"static_moving.json", {": /bodies/0/velocity: a static body cannot move"}},
    {"duplicate_key.json", {": /settings/dt: duplicate key \"dt\""}},
    {"duplicate_name.json",
     {": /bodies/1/name: duplicate body name \"a\" (also made by /bodies/0)"}},
    {"too_many_particles.json",
     {": /bodies/0/shape/particles: 2000 x 2000 x 2000 particles is more than "
      "settings.max_particles"}},
    {"huge_sphere.json",
     {": /bodies/0/shape: would make about 4.19e+12 particles, more than settings.max_particles"}},
    {"huge_mesh.json",
     {": /bodies/0/shape: would make about 1e+12 particles, more than settings.max_particles"}},
    {"max_particles_repeat.json",
     {": /bodies/0: the scene would have 150 particles, more than settings.max_particles (100)"}},
    {"box_size_and_particles.json", {": /bodies/0/shape: a box needs exactly one of"}},
    {"short_vector.json",
     {": /bodies/0/position: must be an array of 3 numbers [x, y, z], got an array of 2 values"}},
    {"shape_too_small.json", {": /bodies/0/shape: ", "no particle fits"}},
    {"zero_axis.json", {": /bodies/0/rotation/axis: must be a non-zero vector"}},
    {"bad_kind.json",
     {": /bodies/0/kind: must be \"dynamic\", \"static\", \"soft\", \"cloth\", \"rope\" or "
      "\"fluid\", got \"kinematic\""}},
    {"camera_same_point.json", {": /camera/target: must differ from /camera/position"}},
    {"camera_bad_fov.json",
     {": /camera/fov: must be a vertical field of view in degrees between 0 and 180", "got 200"}},
    {"camera_up_parallel.json",
     {": /camera/up: must not be parallel to the view direction (target - position)"}},
    {"camera_unknown_key.json",
     {": /camera/look_at: unknown key \"look_at\" (allowed: position, target, up, fov)"}},
    {"camera_missing_target.json", {": /camera: missing required key \"target\""}},
    {"bad_color.json", {": /bodies/0/color/1: must be from 0 to 1 (a colour component), got 1.5"}},
    {"bad_color_text.json",
     {": /bodies/0/color: must be a colour: [r, g, b] with each from 0 to 1, or \"#rrggbb\", "
      "got \"red\""}},
    {"initial_speed_1e30.json",
     {": /bodies/1/velocity: body \"bullet\" starts too fast for this dt: 1e+30 m/s",
      "would move 1e+26 m in the first substep of 0.0001 s",
      "the largest safe speed at this dt is 25 m/s, the largest safe dt at this speed 2.5e-33 s"}},
    {"initial_spin.json",
     {": /bodies/0/angular_velocity: body \"spinner\" starts too fast for this dt: 173.7 m/s",
      "|w| = 5000 rad/s at 0.03464 m from its centre of mass", "use substeps >= 7"}},
    {"initial_speed_rope.json",
     {": /bodies/0/velocity: rope \"lasso\" starts too fast for this dt: 30 m/s",
      "largest safe speed at this dt is 25 m/s", "largest safe dt at this speed 8.333e-05 s"}},
};

INSTANTIATE_TEST_SUITE_P(Bad, SceneErrors, ::testing::ValuesIn(kBadCases),
                         [](const ::testing::TestParamInfo<BadCase>& param) {
                           std::string name = param.param.file;
                           name = name.substr(0, name.find('.'));
                           return name;
                         });

TEST(SceneErrors, MissingFileSaysCannotOpen) {
  const std::string path = data("no_such_scene.json");
  Result<Scene> r = load_scene_file(path);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.message(), path + ": cannot open: No such file or directory");
  Result<Scene> dir = load_scene_file(data("bad"));
  ASSERT_FALSE(dir);
  EXPECT_EQ(dir.message(), data("bad") + ": cannot open: is a directory");
}

}  // namespace
}  // namespace motes
