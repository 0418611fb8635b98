// Cloth and ropes in scene files (docs/scene-format.md, "Cloth and ropes"): what they load into,
// their defaults, the two settings, the stability check, one located error per kind of mistake,
// and every example scene.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "motes/cloth.h"
#include "motes/scene.h"
#include "unit/test_support.h"

namespace motes {
namespace {

using motes_test::example_path;
using motes_test::kPi;
using motes_test::stable_substep;

/// A scene with the given "bodies" entries (and extra "settings" keys), default contact k = 1000.
std::string scene_text(const std::string& bodies, const std::string& settings = "",
                       const std::string& rest = "") {
  return fmt::format(R"({{"settings": {{{}"contact": {{"stiffness": 1000}}}}, "bodies": [{}]{}}})",
                     settings.empty() ? "" : settings + ", ", bodies, rest);
}

Scene load_text_or_fail(const std::string& text) {
  Result<Scene> r = load_scene_text(text, "s.json", "");
  if (!r) ADD_FAILURE() << r.message();
  return r ? std::move(r).value() : Scene{};
}

const char* const kSheet =
    R"({"name": "sheet", "kind": "cloth", "material": "silk", "diameter": 0.01,
        "cloth": {"corner": [-0.12, 0.35, -0.12], "edge_u": [0.24, 0, 0], "edge_v": [0, 0, 0.24],
                  "particles": [25, 25], "pin": [[0, 0], [24, 0]]},
        "velocity": [0, -1, 0], "color": [1, 0.5, 0]})";

TEST(SceneLinked, ClothLoadsItsLatticePinsAndLinks) {
  const Scene s = load_text_or_fail(
      scene_text(std::string(kSheet) + R"(, {"name": "ball", "shape": {"type": "particle"}})", "",
                 R"(, "materials": {"silk": {"density": 300}})"));
  ASSERT_EQ(s.linked.size(), 1u);
  ASSERT_EQ(s.bodies.size(), 1u);
  EXPECT_EQ(s.particle_count(), 626u);
  const LinkedSpec& c = s.linked[0];
  EXPECT_EQ(c.name, "sheet");
  EXPECT_EQ(c.kind, LinkedKind::Cloth);
  EXPECT_EQ(s.materials[static_cast<std::size_t>(c.material)].name, "silk");
  EXPECT_EQ(c.diameter, 0.01);
  ASSERT_EQ(c.points.size(), 625u);
  ASSERT_EQ(c.lattice.size(), 625u);
  for (std::uint32_t j = 0; j < 25; ++j) {
    for (std::uint32_t i = 0; i < 25; ++i) {
      const std::size_t k = j * 25 + i;
      EXPECT_EQ(c.lattice[k], (std::array<std::uint32_t, 2>{i, j}));
      EXPECT_TRUE(c.points[k].isApprox(Eigen::Vector3d(-0.12 + 0.01 * i, 0.35, -0.12 + 0.01 * j)))
          << k;
    }
  }
  EXPECT_EQ(c.pinned, (std::vector<std::uint32_t>{0, 24}));
  // Bend is on by default: structural (nu-1)nv + nu(nv-1), shear 2(nu-1)(nv-1), bend
  // (nu-2)nv + nu(nv-2).
  const std::size_t n = 25;
  EXPECT_EQ(c.links.size(),
            (n - 1) * n + n * (n - 1) + 2 * (n - 1) * (n - 1) + (n - 2) * n + n * (n - 2));
  for (const LinkSpec& l : c.links) EXPECT_EQ(l.stiffness, 1.0);
  EXPECT_EQ(c.velocity, Eigen::Vector3d(0, -1, 0));
  ASSERT_TRUE(c.color.has_value());
  EXPECT_EQ(*c.color, Eigen::Vector3d(1, 0.5, 0));
}

TEST(SceneLinked, RopeLoadsWithNegativePinsSortedAndNoBendByDefault) {
  const Scene s = load_text_or_fail(scene_text(
      R"({"name": "line", "kind": "rope", "rope": {"from": [0, 1, 0], "to": [0.19, 1, 0],
          "particles": 20, "stiffness": 0.5, "pin": [-1, 0]}})"));
  ASSERT_EQ(s.linked.size(), 1u);
  EXPECT_TRUE(s.bodies.empty());
  EXPECT_EQ(s.particle_count(), 20u);
  const LinkedSpec& r = s.linked[0];
  EXPECT_EQ(r.kind, LinkedKind::Rope);
  EXPECT_EQ(r.material, 0);
  EXPECT_EQ(r.diameter, s.settings.particle_diameter);
  ASSERT_EQ(r.points.size(), 20u);
  EXPECT_TRUE(r.points.back().isApprox(Eigen::Vector3d(0.19, 1, 0)));
  EXPECT_EQ(r.lattice[19], (std::array<std::uint32_t, 2>{19, 0}));
  EXPECT_EQ(r.pinned, (std::vector<std::uint32_t>{0, 19}));
  ASSERT_EQ(r.links.size(), 19u);
  for (const LinkSpec& l : r.links) EXPECT_EQ(l.stiffness, 0.5);
  EXPECT_TRUE(r.velocity.isZero());
  EXPECT_FALSE(r.color.has_value());
}

TEST(SceneLinked, RopeAlongAPath) {
  const Scene s = load_text_or_fail(scene_text(
      R"({"kind": "rope", "rope": {"path": [[0, 1, 0], [0.1, 0.9, 0], [0.2, 1, 0]],
          "particles": 5, "pin": [0, -1]}})"));
  ASSERT_EQ(s.linked.size(), 1u);
  const LinkedSpec& r = s.linked[0];
  ASSERT_EQ(r.points.size(), 5u);
  EXPECT_TRUE(r.points[2].isApprox(Eigen::Vector3d(0.1, 0.9, 0)));
  EXPECT_TRUE(r.points[4].isApprox(Eigen::Vector3d(0.2, 1, 0)));
  EXPECT_EQ(r.links.size(), 4u);
}

TEST(SceneLinked, BendOptionsAndDefaultNamesInFileOrder) {
  const Scene s = load_text_or_fail(scene_text(
      R"({"kind": "rope", "rope": {"from": [0, 1, 0], "to": [1, 1, 0], "particles": 10,
          "bend": true, "bend_stiffness": 0.25}},
         {"shape": {"type": "particle"}},
         {"kind": "cloth", "diameter": 0.02, "cloth": {"corner": [0, 0, 0], "edge_u": [0.3, 0, 0],
          "edge_v": [0, 0.2, 0], "particles": [4, 3], "bend": false}})"));
  ASSERT_EQ(s.linked.size(), 2u);
  EXPECT_EQ(s.linked[0].name, "rope0");
  EXPECT_EQ(s.bodies[0].name, "body1");
  EXPECT_EQ(s.linked[1].name, "cloth2");
  EXPECT_EQ(s.linked[0].links.size(), 9u + 8u);
  EXPECT_EQ(s.linked[0].links.back().stiffness, 0.25);
  EXPECT_EQ(s.linked[1].diameter, 0.02);
  EXPECT_EQ(s.linked[1].links.size(), 3u * 3u + 4u * 2u + 2u * 3u * 2u);  // no bend links
  EXPECT_TRUE(s.linked[1].pinned.empty());
  EXPECT_EQ(s.particle_count(), 10u + 1u + 12u);
}

TEST(SceneLinked, SettingsAreReadWithDefaults) {
  const Scene d = load_text_or_fail(scene_text(R"({"shape": {"type": "particle"}})"));
  EXPECT_EQ(d.settings.constraint_iterations, 8);
  EXPECT_EQ(d.settings.link_damping, 0.0);
  const Scene s = load_text_or_fail(scene_text(
      R"({"shape": {"type": "particle"}})", R"("constraint_iterations": 12, "link_damping": 1.5)"));
  EXPECT_EQ(s.settings.constraint_iterations, 12);
  EXPECT_EQ(s.settings.link_damping, 1.5);
}

TEST(SceneLinked, MaxObjectsIsTheLimit) {
  std::string ropes;
  for (std::uint32_t i = 0; i <= kLinkedMaxObjects; ++i) {
    if (i > 0) ropes += ", ";
    ropes += R"({"kind": "rope", "rope": {"from": [0, 0, 0], "to": [0.01, 0, 0], "particles": 2}})";
  }
  // Exactly the limit loads; one more is an error at the extra entry.
  const std::string at_limit = ropes.substr(0, ropes.rfind(", {"));
  Result<Scene> ok = load_scene_text(scene_text(at_limit), "s.json", "");
  ASSERT_TRUE(ok) << ok.message();
  EXPECT_EQ(ok->linked.size(), kLinkedMaxObjects);
  Result<Scene> bad = load_scene_text(scene_text(ropes), "s.json", "");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.message().find(
                fmt::format("s.json: /bodies/{}: more than {} cloth and rope objects in one scene",
                            kLinkedMaxObjects, kLinkedMaxObjects)),
            std::string::npos)
      << bad.message();
}

// ---- stability: lone-sphere particle mass, self contact, pins as static partners ----

std::string linked_scene(double dt, const std::string& rope) {
  return fmt::format(
      R"({{"settings": {{"dt": {}, "contact": {{"stiffness": 100000, "damping": 2000,
          "density": 500}}}}, "bodies": [{{"name": "r", "kind": "rope", "rope": {}}}]}})",
      dt, rope);
}

TEST(SceneLinkedStability, ParticlesAreLoneSpheresThatMeetThemselvesAndTheirPins) {
  const double m = 500.0 * kPi / 6.0 * 1e-6;  // density x pi/6 d^3, d = 0.01
  struct Case {
    const char* rope;
    double m_eff;  ///< 0: no contact at all
  };
  const Case cases[] = {
      // 3 particles, all within two lattice steps, nothing else: no contact to check.
      {R"({"from": [0, 0, 0], "to": [0.02, 0, 0], "particles": 3})", 0.0},
      // ... but a pinned one is a static partner (m* = m).
      {R"({"from": [0, 0, 0], "to": [0.02, 0, 0], "particles": 3, "pin": [0]})", m},
      // 4 particles: the ends may touch (m* = m / 2).
      {R"({"from": [0, 0, 0], "to": [0.03, 0, 0], "particles": 4})", m / 2},
  };
  for (const Case& c : cases) {
    if (c.m_eff == 0.0) {
      Result<Scene> ok = load_scene_text(linked_scene(1.0, c.rope), "s.json", "");
      EXPECT_TRUE(ok) << c.rope << ": " << ok.message();
      continue;
    }
    const double limit = stable_substep(1e5, 2000, c.m_eff);
    Result<Scene> ok = load_scene_text(linked_scene(0.99 * limit, c.rope), "s.json", "");
    EXPECT_TRUE(ok) << c.rope << ": " << ok.message();
    Result<Scene> bad = load_scene_text(linked_scene(1.01 * limit, c.rope), "s.json", "");
    ASSERT_FALSE(bad) << c.rope;
    EXPECT_NE(bad.message().find("s.json: /settings/dt: unstable"), std::string::npos)
        << bad.message();
    EXPECT_NE(bad.message().find(fmt::format("rope \"r\" (material \"default\", particle mass "
                                             "{:.4g} kg)",
                                             m)),
              std::string::npos)
        << bad.message();
    EXPECT_NE(bad.message().find(fmt::format("largest stable dt is just under {:.4g} s", limit)),
              std::string::npos)
        << bad.message();
  }
}

TEST(SceneLinkedStability, ClothMeetsBodiesAndPlanesOfOtherMaterials) {
  // A stiff floor material: the cloth against the floor is the worst contact.
  const std::string text = fmt::format(
      R"({{"settings": {{"dt": {}, "contact": {{"stiffness": 1000}}}},
          "materials": {{"steel": {{"stiffness": 199000}}}},
          "bodies": [{{"name": "sheet", "kind": "cloth", "cloth": {{"corner": [0, 1, 0],
            "edge_u": [0.01, 0, 0], "edge_v": [0, 0, 0.01], "particles": [2, 2]}}}}],
          "planes": [{{"name": "floor", "normal": [0, 1, 0], "material": "steel"}}]}})",
      3e-4);
  Result<Scene> bad = load_scene_text(text, "s.json", "");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.message().find("cloth \"sheet\""), std::string::npos) << bad.message();
  EXPECT_NE(bad.message().find("against plane \"floor\" (material \"steel\")"), std::string::npos)
      << bad.message();
}

// ---- errors: each names the file, the JSON path and the reason ----

struct BadLinked {
  const char* name;
  std::string text;
  std::vector<std::string> expected;  ///< substrings of the message
};

std::string cloth(const std::string& fields, const std::string& entry_extra = "") {
  return fmt::format(
      R"({{"name": "c", "kind": "cloth", "cloth": {{"corner": [0, 0, 0], "edge_u": [0.04, 0, 0],
          "edge_v": [0, 0, 0.04]{}}}{}}})",
      fields, entry_extra);
}
std::string rope(const std::string& fields, const std::string& entry_extra = "") {
  return fmt::format(
      R"({{"name": "r", "kind": "rope", "rope": {{"from": [0, 0, 0], "to": [0.09, 0, 0]{}}}{}}})",
      fields, entry_extra);
}
const std::string kGoodCloth = R"(, "particles": [5, 5])";
const std::string kGoodRope = R"(, "particles": 10)";

std::vector<BadLinked> bad_cases() {
  const std::string ball = R"({"name": "ball", "shape": {"type": "particle"}})";
  return {
      {"ClothParticlesNotPair",
       scene_text(cloth(R"(, "particles": 25)")),
       {"s.json: /bodies/0/cloth/particles: must be an array of 2 integers [nu, nv], got 25"}},
      {"ClothParticlesTooFew",
       scene_text(cloth(R"(, "particles": [5, 1])")),
       {"s.json: /bodies/0/cloth/particles/1: must be an integer from 2 to 1024, got 1"}},
      {"ClothParticlesTooMany",
       scene_text(cloth(R"(, "particles": [1025, 5])")),
       {"s.json: /bodies/0/cloth/particles/0: must be an integer from 2 to 1024, got 1025"}},
      {"RopeParticlesTooMany",
       scene_text(rope(R"(, "particles": 2000)")),
       {"s.json: /bodies/0/rope/particles: must be an integer from 2 to 1024, got 2000"}},
      {"RopePathAndEnds",
       scene_text(rope(R"(, "particles": 10, "path": [[0, 0, 0], [1, 0, 0]])")),
       {"s.json: /bodies/0/rope/from: give either \"path\" or \"from\" and \"to\", not both"}},
      {"RopePathOnePoint",
       scene_text(R"({"kind": "rope", "rope": {"path": [[0, 0, 0]], "particles": 3}})"),
       {"s.json: /bodies/0/rope/path: must hold at least two points [x, y, z]"}},
      {"RopePathNotPoints",
       scene_text(R"({"kind": "rope", "rope": {"path": [[0, 0, 0], 5], "particles": 3}})"),
       {"s.json: /bodies/0/rope/path/1:"}},
      {"RopeMissingParticles",
       scene_text(rope("")),
       {"s.json: /bodies/0/rope: missing required key \"particles\""}},
      {"ClothMissingObject",
       scene_text(R"({"kind": "cloth"})"),
       {"s.json: /bodies/0: missing required key \"cloth\""}},
      {"ClothStiffnessZero",
       scene_text(cloth(kGoodCloth + R"(, "stiffness": 0)")),
       {"s.json: /bodies/0/cloth/stiffness: must be a number in (0, 1]", "got 0"}},
      {"RopeBendStiffnessAboveOne",
       scene_text(rope(kGoodRope + R"(, "bend_stiffness": 1.5)")),
       {"s.json: /bodies/0/rope/bend_stiffness: must be a number in (0, 1]", "got 1.5"}},
      {"RopeBendNotBool",
       scene_text(rope(kGoodRope + R"(, "bend": 1)")),
       {"s.json: /bodies/0/rope/bend: must be true or false, got 1"}},
      {"ClothPinOutside",
       scene_text(cloth(kGoodCloth + R"(, "pin": [[0, 0], [2, 5]])")),
       {"s.json: /bodies/0/cloth/pin/1/1: must be an integer from 0 to 4, got 5"}},
      {"ClothPinNegative",
       scene_text(cloth(kGoodCloth + R"(, "pin": [[-1, 0]])")),
       {"s.json: /bodies/0/cloth/pin/0/0: must be an integer from 0 to 4, got -1"}},
      {"ClothPinNotPair",
       scene_text(cloth(kGoodCloth + R"(, "pin": [3])")),
       {"s.json: /bodies/0/cloth/pin/0: must be an array of 2 integers [i, j], got 3"}},
      {"ClothPinNotArray",
       scene_text(cloth(kGoodCloth + R"(, "pin": 3)")),
       {"s.json: /bodies/0/cloth/pin: must be an array, got 3"}},
      {"ClothPinDuplicate",
       scene_text(cloth(kGoodCloth + R"(, "pin": [[1, 2], [0, 0], [1, 2]])")),
       {"s.json: /bodies/0/cloth/pin/2: duplicate pin: point 11 is already pinned by "
        "/bodies/0/cloth/pin/0"}},
      {"RopePinOutside",
       scene_text(rope(kGoodRope + R"(, "pin": [10])")),
       {"s.json: /bodies/0/rope/pin/0: must be an integer from -10 to 9, got 10"}},
      {"RopePinTooNegative",
       scene_text(rope(kGoodRope + R"(, "pin": [-11])")),
       {"s.json: /bodies/0/rope/pin/0: must be an integer from -10 to 9, got -11"}},
      {"RopePinDuplicateFromEnd",
       scene_text(rope(kGoodRope + R"(, "pin": [9, 0, -1])")),
       {"s.json: /bodies/0/rope/pin/2: duplicate pin: point 9 is already pinned by "
        "/bodies/0/rope/pin/0"}},
      {"ClothEdgesParallel",
       scene_text(R"({"kind": "cloth", "cloth": {"corner": [0, 0, 0], "edge_u": [0.04, 0, 0],
          "edge_v": [0.08, 0, 0], "particles": [5, 5]}})"),
       {"s.json: /bodies/0/cloth: its edges must be finite, non-zero and not parallel"}},
      {"RopeEndsTogether",
       scene_text(R"({"kind": "rope", "rope": {"from": [1, 0, 0], "to": [1, 0, 0],
          "particles": 5}})"),
       {"s.json: /bodies/0/rope: its ends must be apart (length 0)"}},
      {"ClothBeyondFloat",
       scene_text(R"({"kind": "cloth", "cloth": {"corner": [3e38, 0, 0], "edge_u": [3e38, 0, 0],
          "edge_v": [0, 0, 1], "particles": [2, 2]}})"),
       {"s.json: /bodies/0/cloth: a particle lands outside the float range"}},
      {"ClothCornerNotVector",
       scene_text(cloth(kGoodCloth).replace(cloth(kGoodCloth).find("[0, 0, 0]"), 9, "[0, 0]")),
       {"s.json: /bodies/0/cloth/corner: must be an array of 3 numbers"}},
      {"EntryUnknownKey",
       scene_text(cloth(kGoodCloth, R"(, "size": 3)")),
       {"s.json: /bodies/0/size: unknown key \"size\"",
        "(allowed: name, kind, material, diameter, cloth, velocity, color)"}},
      {"ClothWithRopeObject",
       scene_text(cloth(kGoodCloth, R"(, "rope": {})")),
       {"s.json: /bodies/0/rope: unknown key \"rope\""}},
      {"ClothObjectUnknownKey",
       scene_text(cloth(kGoodCloth + R"(, "spacing": 0.01)")),
       {"s.json: /bodies/0/cloth/spacing: unknown key \"spacing\"",
        "corner, edge_u, edge_v, particles, bend, stiffness, bend_stiffness, pin"}},
      {"RopeObjectUnknownKey",
       scene_text(rope(kGoodRope + R"(, "corner": [0, 0, 0])")),
       {"s.json: /bodies/0/rope/corner: unknown key \"corner\"",
        "from, to, path, particles, bend, stiffness, bend_stiffness, pin"}},
      {"ClothShape",
       scene_text(cloth(kGoodCloth, R"(, "shape": {"type": "particle"})")),
       {"s.json: /bodies/0/shape: not allowed on a cloth: its particles are laid out by its "
        "\"cloth\" object"}},
      {"RopeRepeat",
       scene_text(rope(kGoodRope, R"(, "repeat": {"count": 2})")),
       {"s.json: /bodies/0/repeat: not allowed on a rope: give each rope an entry of its own"}},
      {"ClothRotation",
       scene_text(cloth(kGoodCloth, R"(, "rotation": {"axis": [0, 1, 0], "degrees": 9})")),
       {"s.json: /bodies/0/rotation: not allowed on a cloth"}},
      {"RopeAngularVelocity",
       scene_text(rope(kGoodRope, R"(, "angular_velocity": [0, 0, 1])")),
       {"s.json: /bodies/0/angular_velocity: not allowed on a rope: a rope is not a rigid body"}},
      {"UnknownMaterial",
       scene_text(rope(kGoodRope, R"(, "material": "hemp")")),
       {"s.json: /bodies/0/material: unknown material \"hemp\" (defined: default)"}},
      {"BadVelocity",
       scene_text(rope(kGoodRope, R"(, "velocity": [1, 2])")),
       {"s.json: /bodies/0/velocity: must be an array of 3 numbers [x, y, z], got an array of 2"}},
      {"BadColor",
       scene_text(cloth(kGoodCloth, R"(, "color": [2, 0, 0])")),
       {"s.json: /bodies/0/color/0: must be from 0 to 1 (a colour component), got 2"}},
      {"BadDiameter",
       scene_text(cloth(kGoodCloth, R"(, "diameter": -0.01)")),
       {"s.json: /bodies/0/diameter: must be a positive number, got -0.01"}},
      {"BadName",
       scene_text(cloth(kGoodCloth, "").replace(0, 14, R"({"name": "", )")),
       {"s.json: /bodies/0/name: must not be empty"}},
      {"NameOfABody",
       scene_text(R"({"name": "c", "shape": {"type": "particle"}}, )" + cloth(kGoodCloth)),
       {"s.json: /bodies/1/name: duplicate body name \"c\" (also made by /bodies/0)"}},
      {"NameOfARepeat",
       scene_text(rope(kGoodRope, "").replace(0, 14, R"({"name": "b[1]", )") + R"(, {"name": "b",
          "shape": {"type": "particle"}, "repeat": {"count": 2, "offset": [1, 0, 0]}})"),
       {"s.json: /bodies/1/name: duplicate body name \"b[1]\" (also made by /bodies/0)"}},
      {"NameOfAnotherRope",
       scene_text(rope(kGoodRope) + ", " + rope(kGoodRope)),
       {"s.json: /bodies/1/name: duplicate body name \"r\" (also made by /bodies/0)"}},
      {"BadKind",
       scene_text(R"({"kind": "curtain", "shape": {"type": "particle"}})"),
       {"s.json: /bodies/0/kind: must be \"dynamic\", \"static\", \"soft\", \"cloth\", \"rope\" or "
        "\"fluid\", got \"curtain\""}},
      {"MaxParticles",
       scene_text(ball + ", " + rope(R"(, "particles": 100)"), R"("max_particles": 100)"),
       {"s.json: /bodies/1: the scene would have 101 particles, more than "
        "settings.max_particles (100)"}},
      {"MaxParticlesBodyAfterCloth",
       scene_text(cloth(R"(, "particles": [10, 10])") + ", " + ball, R"("max_particles": 100)"),
       {"s.json: /bodies/1: the scene would have 101 particles"}},
      {"AttachToNoBody",
       scene_text(ball + ", " + rope(kGoodRope + R"(, "attach": [{"point": -1, "body": "bal"}])")),
       {"s.json: /bodies/1/rope/attach/0/body: no body named \"bal\" in this scene"}},
      {"AttachToARope",
       scene_text(rope(kGoodRope + R"(, "attach": [{"point": 0, "body": "r"}])")),
       {"s.json: /bodies/0/rope/attach/0/body: \"r\" is a cloth or rope"}},
      {"AttachToASoftBody",
       scene_text(
           R"({"name": "jelly", "kind": "soft", "shape": {"type": "box", "particles": [2, 2, 2]},
                      "position": [0, 1, 0]}, )" +
           cloth(kGoodCloth + R"(, "attach": [{"point": [4, 4], "body": "jelly"}])")),
       {"s.json: /bodies/1/cloth/attach/0/body: \"jelly\" is a soft body"}},
      {"AttachAPinnedPoint",
       scene_text(
           ball + ", " +
           rope(kGoodRope + R"(, "pin": [0, -1], "attach": [{"point": 9, "body": "ball"}])")),
       {"s.json: /bodies/1/rope/attach/0/point: point 9 is already held by \"pin\""}},
      {"AttachTwice",
       scene_text(ball + ", " +
                  cloth(kGoodCloth + R"(, "attach": [{"point": [1, 1], "body": "ball"},
                                                       {"point": [1, 1], "body": "ball"}])")),
       {"s.json: /bodies/1/cloth/attach/1/point: point 6 is already held by "
        "/bodies/1/cloth/attach/0/point"}},
      {"AttachPointOutside",
       scene_text(ball + ", " + rope(kGoodRope + R"(, "attach": [{"point": 10, "body": "ball"}])")),
       {"s.json: /bodies/1/rope/attach/0/point: must be an integer from -10 to 9, got 10"}},
      {"AttachUnknownKey",
       scene_text(ball + ", " +
                  rope(kGoodRope + R"(, "attach": [{"point": 1, "body": "ball", "at": 2}])")),
       {"s.json: /bodies/1/rope/attach/0/at: unknown key \"at\" (allowed: point, body)"}},
      {"MaterialWithoutStiffness",
       R"({"materials": {"hemp": {"density": 500}}, "bodies": [)" +
           rope(kGoodRope, R"(, "material": "hemp")") + "]}",
       {"s.json: /materials/hemp: missing required key \"stiffness\""}},
      {"IterationsZero",
       scene_text(rope(kGoodRope), R"("constraint_iterations": 0)"),
       {"s.json: /settings/constraint_iterations: must be an integer from 1 to 1000, got 0"}},
      {"IterationsTooMany",
       scene_text(rope(kGoodRope), R"("constraint_iterations": 1001)"),
       {"s.json: /settings/constraint_iterations: must be an integer from 1 to 1000, got 1001"}},
      {"IterationsFraction",
       scene_text(rope(kGoodRope), R"("constraint_iterations": 2.5)"),
       {"s.json: /settings/constraint_iterations: must be an integer from 1 to 1000, got 2.5"}},
      {"LinkDampingNegative",
       scene_text(rope(kGoodRope), R"("link_damping": -1)"),
       {"s.json: /settings/link_damping: must be a non-negative number, got -1"}},
      {"LinkDampingText",
       scene_text(rope(kGoodRope), R"("link_damping": "fast")"),
       {"s.json: /settings/link_damping: must be a non-negative number, got \"fast\""}},
      {"LinkDampingHuge",
       scene_text(rope(kGoodRope), R"("link_damping": 1e39)"),
       {"s.json: /settings/link_damping: out of range"}},
      {"SettingsUnknownKey",
       scene_text(rope(kGoodRope), R"("link_dampening": 1)"),
       {"s.json: /settings/link_dampening: unknown key", "constraint_iterations, link_damping"}},
  };
}

class SceneLinkedErrors : public ::testing::TestWithParam<BadLinked> {};

TEST_P(SceneLinkedErrors, NamePathAndReason) {
  const BadLinked& c = GetParam();
  Result<Scene> r = load_scene_text(c.text, "s.json", "");
  ASSERT_FALSE(r) << c.name << " loaded:\n" << c.text;
  for (const std::string& e : c.expected) {
    EXPECT_NE(r.message().find(e), std::string::npos)
        << "expected \"" << e << "\" in: " << r.message();
  }
}

INSTANTIATE_TEST_SUITE_P(Bad, SceneLinkedErrors, ::testing::ValuesIn(bad_cases()),
                         [](const ::testing::TestParamInfo<BadLinked>& param) {
                           return std::string(param.param.name);
                         });

// ---- example scenes ----

TEST(SceneLinkedExamples, EveryExampleSceneLoads) {
  std::size_t count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(example_path(""))) {
    if (entry.path().extension() != ".json") continue;
    ++count;
    Result<Scene> r = load_scene_file(entry.path().string());
    EXPECT_TRUE(r) << r.message();
  }
  EXPECT_GE(count, 5u);
}

TEST(SceneLinkedExamples, ClothFallsOnTwoStaticBunnies) {
  Result<Scene> r = load_scene_file(example_path("cloth.json"));
  ASSERT_TRUE(r) << r.message();
  const Scene& s = *r;
  ASSERT_EQ(s.linked.size(), 1u);
  const LinkedSpec& c = s.linked[0];
  EXPECT_EQ(c.kind, LinkedKind::Cloth);
  EXPECT_EQ(c.points.size(), 625u);
  EXPECT_EQ(c.diameter, 0.01);
  EXPECT_NEAR((c.points[1] - c.points[0]).norm(), c.diameter, 1e-12);  // spacing = diameter
  EXPECT_TRUE(c.pinned.empty());
  ASSERT_EQ(s.bodies.size(), 2u);
  for (const BodySpec& b : s.bodies) {
    EXPECT_EQ(b.kind, BodyKind::Static) << b.name;
    EXPECT_NEAR(static_cast<double>(b.shape->points.size()), 402.0, 40.0) << b.name;
  }
  EXPECT_EQ(s.settings.constraint_iterations, 8);
  EXPECT_NEAR(s.settings.link_damping, 1.0, 0.5);
  // The cloth starts above every bunny particle.
  double lowest = 1e9;
  for (const Eigen::Vector3d& p : c.points) lowest = std::min(lowest, p.y());
  for (const BodySpec& b : s.bodies) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const auto& q : b.shape->points) centre += q.cast<double>();
    centre /= static_cast<double>(b.shape->points.size());
    for (const auto& q : b.shape->points) {
      const Eigen::Vector3d x = b.position + b.rotation * (q.cast<double>() - centre);
      EXPECT_GT(lowest - x.y(), c.diameter) << b.name;
      EXPECT_GT(x.y(), 0.0) << b.name << " is above the floor";
    }
  }
}

TEST(SceneLinkedExamples, RopeBridgeAndHangingRope) {
  Result<Scene> r = load_scene_file(example_path("rope.json"));
  ASSERT_TRUE(r) << r.message();
  const Scene& s = *r;
  ASSERT_EQ(s.linked.size(), 2u);
  const LinkedSpec& bridge = s.linked[0];
  EXPECT_EQ(bridge.points.size(), 40u);
  EXPECT_EQ(bridge.pinned, (std::vector<std::uint32_t>{0, 39}));
  // Laid along a V through a point 5 cm below its ends: slack, so that it sags.
  double length = 0.0;
  for (std::size_t k = 0; k + 1 < bridge.points.size(); ++k) {
    length += (bridge.points[k + 1] - bridge.points[k]).norm();
  }
  EXPECT_GT(length, (bridge.points.back() - bridge.points.front()).norm() + 0.005);
  const LinkedSpec& hanging = s.linked[1];
  EXPECT_EQ(hanging.points.size(), 20u);
  EXPECT_EQ(hanging.pinned, (std::vector<std::uint32_t>{0}));
  EXPECT_NEAR(hanging.points.front().y(), hanging.points.back().y(), 1e-12);  // horizontal
  ASSERT_EQ(s.bodies.size(), 3u);
  for (const BodySpec& b : s.bodies) {
    EXPECT_EQ(b.kind, BodyKind::Dynamic);
    EXPECT_EQ(b.shape->points.size(), 27u);
  }
  EXPECT_EQ(s.particle_count(), 40u + 20u + 3u * 27u);
}

}  // namespace
}  // namespace motes
