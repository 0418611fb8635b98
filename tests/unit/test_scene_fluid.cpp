// Fluids in scene files (issue 29; docs/scene-format.md, "Fluids"): the box and sphere fills at the
// rest spacing, the material's fluid fields and their defaults, the located errors, and the
// fluid's place among a Simulation's bodies.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "motes/devices.h"
#include "motes/fluid.h"
#include "motes/scene.h"
#include "motes/simulation.h"

namespace motes {
namespace {

/// A position-solver scene of the given bodies (the text of the array's elements) and materials.
std::string fluid_scene(const std::string& bodies, const std::string& materials = "{}",
                        const std::string& settings = R"("contact_model": "position")") {
  return R"({"settings": {)" + settings + R"(}, "materials": )" + materials + R"(, "bodies": [)" +
         bodies + "]}";
}

Result<Scene> load_fluid_text(const std::string& text) {
  return load_scene_text(text, "s.json", ".");
}

TEST(SceneFluid, BoxIsFilledAtTheRestSpacingInsideTheBox) {
  Result<Scene> r = load_fluid_text(fluid_scene(
      R"({"name": "water", "kind": "fluid", "velocity": [0.1, 0, 0], "color": "#3060ff",
          "fluid": {"type": "box", "min": [0, 0, 0], "max": [0.0505, 0.031, 0.0405]}})"));
  ASSERT_TRUE(r) << r.message();
  ASSERT_EQ(r->fluids.size(), 1u);
  const FluidSpec& f = r->fluids[0];
  EXPECT_EQ(f.name, "water");
  EXPECT_EQ(f.diameter, 0.01);  // settings.particle_diameter's default
  // The rest spacing s = 1.003075 d (fluid_rest_spacing): 1 + floor((L - d) / s) per axis, so a
  // box of exactly n diameters would hold n - 1 (its particles n s wide).
  const double s = fluid_rest_spacing(0.01);
  ASSERT_EQ(f.points.size(), 5u * 3u * 4u);
  EXPECT_TRUE(f.points.front().isApprox(Eigen::Vector3d(0.005, 0.005, 0.005)));
  EXPECT_TRUE(f.points[1].isApprox(Eigen::Vector3d(0.005 + s, 0.005, 0.005)));  // x fastest
  EXPECT_TRUE(
      f.points.back().isApprox(Eigen::Vector3d(0.005 + 4 * s, 0.005 + 2 * s, 0.005 + 3 * s)));
  Result<Scene> exact = load_fluid_text(fluid_scene(
      R"({"kind": "fluid", "fluid": {"type": "box", "min": [0, 0, 0], "max": [0.05, 0.05, 0.05]}})"));
  ASSERT_TRUE(exact) << exact.message();
  EXPECT_EQ(exact->fluids[0].points.size(), 4u * 4u * 4u);
  EXPECT_TRUE(f.velocity.isApprox(Eigen::Vector3d(0.1, 0.0, 0.0)));
  ASSERT_TRUE(f.color.has_value());
  EXPECT_EQ(r->particle_count(), 60u);
  EXPECT_TRUE(r->bodies.empty());

  Result<Scene> coarse = load_fluid_text(fluid_scene(
      R"({"kind": "fluid", "fluid": {"type": "box", "min": [0, 0, 0], "max": [0.05, 0.05, 0.05],
          "diameter": 0.02}})"));
  ASSERT_TRUE(coarse) << coarse.message();
  EXPECT_EQ(coarse->fluids[0].points.size(), 8u);
  EXPECT_EQ(coarse->fluids[0].name, "body0");
}

TEST(SceneFluid, SettingsDefaultToTheSettledSetWithFluid) {
  // 16 substeps and 64 list entries unless the file gives them; fluid_iterations 2
  // (docs/fluids.md).
  const std::string water =
      R"({"kind": "fluid", "fluid": {"type": "box", "min": [0, 0, 0], "max": [0.02, 0.02, 0.02]}})";
  Result<Scene> r = load_fluid_text(fluid_scene(water));
  ASSERT_TRUE(r) << r.message();
  EXPECT_EQ(r->settings.substeps, 16);
  EXPECT_EQ(r->settings.neighbour_capacity, 64);
  EXPECT_EQ(r->settings.fluid_iterations, 2);
  EXPECT_EQ(Settings{}.fluid_iterations, kFluidIterations);
  Result<Scene> given = load_fluid_text(
      fluid_scene(water, "{}",
                  R"("contact_model": "position", "substeps": 12, "neighbour_capacity": 40,
         "fluid_iterations": 3)"));
  ASSERT_TRUE(given) << given.message();
  EXPECT_EQ(given->settings.substeps, 12);
  EXPECT_EQ(given->settings.neighbour_capacity, 40);
  EXPECT_EQ(given->settings.fluid_iterations, 3);
  // Without fluid the position model's defaults stay.
  Result<Scene> dry =
      load_fluid_text(fluid_scene(R"({"shape": {"type": "particle"}, "position": [0, 1, 0]})"));
  ASSERT_TRUE(dry) << dry.message();
  EXPECT_EQ(dry->settings.substeps, 8);
  EXPECT_EQ(dry->settings.neighbour_capacity, 16);
  Result<Scene> bad = load_fluid_text(
      fluid_scene(water, "{}", R"("contact_model": "position", "fluid_iterations": 0)"));
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.message().find("/settings/fluid_iterations"), std::string::npos) << bad.message();
}

TEST(SceneFluid, SphereIsFilledOnALatticeAboutItsCentre) {
  // Reach 0.0251 - 0.005 = 2 rest spacings (2 s = 0.02006): the lattice points with |n|^2 <= 4,
  // 1 + 6 + 12 + 8 + 6.
  Result<Scene> r = load_fluid_text(fluid_scene(
      R"({"kind": "fluid", "fluid": {"type": "sphere", "center": [1, 2, 3], "radius": 0.0251}})"));
  ASSERT_TRUE(r) << r.message();
  const FluidSpec& f = r->fluids[0];
  ASSERT_EQ(f.points.size(), 33u);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : f.points) {
    EXPECT_LE((p - Eigen::Vector3d(1, 2, 3)).norm(), 0.0201 + 1e-12);
    mean += p;
  }
  EXPECT_TRUE((mean / 33.0).isApprox(Eigen::Vector3d(1, 2, 3)));
}

TEST(SceneFluid, MeshIsFilledOnTheVoxelizersLattice) {
  // A closed cube of 0.5 scaled by 0.1 (5 cm): 5 x 5 x 5 particles of 1 cm inside it, moved by
  // "position"; a missing file and an unknown key are located errors.
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("motes_fluid_mesh_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  {
    std::ofstream obj(dir / "cube.obj");
    obj << "v 0 0 0\nv 0.5 0 0\nv 0.5 0.5 0\nv 0 0.5 0\nv 0 0 0.5\nv 0.5 0 0.5\nv 0.5 0.5 0.5\n"
           "v 0 0.5 0.5\nf 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\n"
           "f 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";
  }
  const auto load = [&](const std::string& fluid) {
    return load_scene_text(fluid_scene(R"({"kind": "fluid", "fluid": )" + fluid + "}"), "s.json",
                           dir.string());
  };
  Result<Scene> r =
      load(R"({"type": "mesh", "file": "cube.obj", "scale": 0.1, "position": [1, 2, 3]})");
  ASSERT_TRUE(r) << r.message();
  const FluidSpec& f = r->fluids[0];
  EXPECT_EQ(f.points.size(), 125u);
  for (const Eigen::Vector3d& p : f.points) {
    EXPECT_TRUE((p - Eigen::Vector3d(1, 2, 3)).minCoeff() > 0.0 &&
                (p - Eigen::Vector3d(1.05, 2.05, 3.05)).maxCoeff() < 0.0)
        << p.transpose();
  }
  Result<Scene> missing = load(R"({"type": "mesh", "file": "nope.obj"})");
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.message().find("s.json: /bodies/0/fluid/file: cannot open mesh"),
            std::string::npos)
      << missing.message();
  Result<Scene> extra = load(R"({"type": "mesh", "file": "cube.obj", "radius": 1})");
  ASSERT_FALSE(extra);
  EXPECT_NE(extra.message().find("s.json: /bodies/0/fluid"), std::string::npos) << extra.message();
  std::filesystem::remove_all(dir);
}

TEST(SceneFluid, MaterialFieldsAndTheirDefaults) {
  const std::string box =
      R"({"kind": "fluid", "material": "MAT", "fluid": {"type": "box", "min": [0, 0, 0],
          "max": [0.02, 0.02, 0.02]}})";
  std::string water = box;
  water.replace(water.find("MAT"), 3, "water");
  Result<Scene> r =
      load_fluid_text(fluid_scene(water, R"({"water": {"rest_density": 998, "viscosity": 0.05,
      "vorticity": 0.2, "cohesion": 0.3, "adhesion": 0.4}})"));
  ASSERT_TRUE(r) << r.message();
  const Material& m = r->materials[static_cast<std::size_t>(r->fluids[0].material)];
  EXPECT_EQ(m.name, "water");
  EXPECT_EQ(m.rest_density, 998.0);
  EXPECT_EQ(m.viscosity, 0.05);
  EXPECT_EQ(m.vorticity, 0.2);
  EXPECT_EQ(m.cohesion, 0.3);
  EXPECT_EQ(m.adhesion, 0.4);
  std::string plain = box;
  plain.replace(plain.find("MAT"), 3, "default");
  Result<Scene> d = load_fluid_text(fluid_scene(plain));
  ASSERT_TRUE(d) << d.message();
  const Material& def = d->materials[0];
  EXPECT_EQ(def.rest_density, 0.0);  // the material's density
  EXPECT_EQ(def.viscosity, 0.01);
  EXPECT_EQ(def.vorticity, 0.0);
  EXPECT_EQ(def.cohesion, 0.0);
  EXPECT_EQ(def.adhesion, 0.0);
}

TEST(SceneFluid, ErrorsNameTheFileThePlaceAndTheReason) {
  const std::string box =
      R"("fluid": {"type": "box", "min": [0, 0, 0], "max": [0.0201, 0.0201, 0.0201]})";
  const std::vector<std::pair<std::string, std::string>> bad = {
      {fluid_scene(R"({"kind": "fluid", )" + box + "}", "{}", R"("contact_model": "impulse")"),
       "s.json: /bodies/0/kind: a fluid needs \"contact_model\": \"position\""},
      {fluid_scene(R"({"kind": "fluid", )" + box + "}", "{}", R"("dt": 1e-4)"),
       "s.json: /bodies/0/kind: a fluid needs \"contact_model\": \"position\""},
      {fluid_scene(R"({"kind": "fluid"})"), "s.json: /bodies/0: missing required key \"fluid\""},
      {fluid_scene(R"({"kind": "fluid", "fluid": {"min": [0, 0, 0]}})"),
       "s.json: /bodies/0/fluid: missing required key \"type\""},
      {fluid_scene(R"({"kind": "fluid", "fluid": {"type": "cone"}})"),
       "s.json: /bodies/0/fluid/type: unknown fluid volume \"cone\" (allowed: box, sphere, mesh"},
      {fluid_scene(R"({"kind": "fluid", "fluid": {"type": "box", "min": [0, 0, 0],
                     "max": [0.02, 0, 0.02]}})"),
       "s.json: /bodies/0/fluid/max/1: must be greater than min[1]"},
      {fluid_scene(R"({"kind": "fluid", "fluid": {"type": "box", "min": [0, 0, 0],
                     "max": [0.02, 0.02, 0.005]}})"),
       "s.json: /bodies/0/fluid/max/2: the box is 0.005 m wide on this axis, less than one "
       "particle diameter (0.01 m)"},
      {fluid_scene(R"({"kind": "fluid", "fluid": {"type": "sphere", "center": [0, 0, 0],
                     "radius": 0.004}})"),
       "s.json: /bodies/0/fluid/radius: a sphere of radius 0.004 m holds no particle"},
      {fluid_scene(R"({"kind": "fluid", "fluid": {"type": "sphere", "centre": [0, 0, 0]}})"),
       "s.json: /bodies/0/fluid/centre: unknown key \"centre\""},
      {fluid_scene(R"({"kind": "fluid", "fluid": {"type": "box", "min": [0, 0, 0],
                     "max": [0.02, 0.02, 0.02], "diameter": -1}})"),
       "s.json: /bodies/0/fluid/diameter: must be a positive number"},
      {fluid_scene(R"({"kind": "fluid", "shape": {"type": "particle"}, )" + box + "}"),
       "s.json: /bodies/0/shape: unknown key \"shape\""},
      {fluid_scene(R"({"shape": {"type": "particle"}, )" + box + "}"),
       "s.json: /bodies/0/fluid: \"fluid\" settings need \"kind\": \"fluid\""},
      {fluid_scene(R"({"kind": "fluid", "material": "water", )" + box + "}",
                   R"({"water": {"viscosity": 1.5}})"),
       "s.json: /materials/water/viscosity: XSPH viscosity is the fraction"},
      {fluid_scene(R"({"kind": "fluid", "material": "water", )" + box + "}",
                   R"({"water": {"rest_density": -1}})"),
       "s.json: /materials/water/rest_density: must be a positive number"},
      {fluid_scene(R"({"kind": "fluid", "material": "oil", )" + box + "}"),
       "s.json: /bodies/0/material: unknown material \"oil\""},
      {fluid_scene(R"({"kind": "fluid", )" + box + "}", "{}",
                   R"("contact_model": "position", "max_particles": 7)"),
       "s.json: /bodies/0/fluid: the fluid would have 8 particles, more than "
       "settings.max_particles (7)"},
      {fluid_scene(R"({"name": "a", "kind": "fluid", )" + box + R"(}, {"name": "a", )" + box +
                   R"(, "kind": "fluid"})"),
       "s.json: /bodies/1/name: duplicate body name \"a\" (also made by /bodies/0)"},
      {fluid_scene(R"({"kind": "fluid", "velocity": [1000, 0, 0], )" + box + "}"),
       "s.json: /bodies/0/velocity: fluid \"body0\""},
  };
  for (const auto& [text, want] : bad) {
    Result<Scene> r = load_fluid_text(text);
    ASSERT_FALSE(r) << text;
    EXPECT_NE(r.message().find(want), std::string::npos) << text << "\n  got: " << r.message();
  }
}

TEST(SceneFluid, SimulationLaysTheFluidOutAfterTheBodiesInTheSceneOrder) {
  // A rigid box, a free sphere and a fluid: the fluid is the scene's third entry, its particles
  // follow the bodies' in a Snapshot, where they keep the fill's places, velocity and mass.
  Result<Scene> r = load_fluid_text(fluid_scene(
      R"({"name": "box", "shape": {"type": "box", "size": [0.02, 0.02, 0.02]},
          "position": [0.5, 0.5, 0.5]},
         {"name": "ball", "shape": {"type": "sphere", "radius": 0.005}, "position": [-0.5, 0, 0]},
         {"name": "water", "kind": "fluid", "velocity": [0.25, 0, 0], "material": "water",
          "fluid": {"type": "box", "min": [0, 0, 0], "max": [0.0201, 0.0201, 0.0301]}})",
      R"({"water": {"density": 1000, "rest_density": 998}})"));
  ASSERT_TRUE(r) << r.message();
  auto device = open_device("openmp");
  ASSERT_TRUE(device) << device.message();
  auto created = Simulation::create(r.value(), std::move(device).value());
  ASSERT_TRUE(created) << created.message();
  Simulation& sim = *created.value();
  const std::vector<BodyInfo>& bodies = sim.bodies();
  ASSERT_EQ(bodies.size(), 3u);
  const BodyInfo& water = bodies[2];
  EXPECT_EQ(water.name, "water");
  EXPECT_TRUE(water.fluid);
  EXPECT_FALSE(water.has_body_state());
  ASSERT_EQ(water.particle_count, 12u);
  EXPECT_EQ(water.first_particle, bodies[1].first_particle + bodies[1].particle_count);
  const double mass = 998.0 * 1e-6;  // rest density x d^3
  EXPECT_NEAR(water.mass, 12.0 * mass, 1e-12);
  EXPECT_EQ(sim.sizes().fluid_particles, 12u);
  auto snap = sim.snapshot();
  ASSERT_TRUE(snap) << snap.message();
  const FluidSpec& spec = r.value().fluids[0];
  for (std::uint32_t k = 0; k < water.particle_count; ++k) {
    const shared::vec4 x = snap->particle_pos[water.first_particle + k];
    const shared::vec4 v = snap->particle_vel[water.first_particle + k];
    EXPECT_TRUE(Eigen::Vector3d(x.x, x.y, x.z).isApprox(spec.points[k], 1e-6)) << k;
    EXPECT_FLOAT_EQ(x.w, 0.005f);
    EXPECT_FLOAT_EQ(v.x, 0.25f);
    EXPECT_NEAR(1.0 / static_cast<double>(v.w), mass, 1e-6 * mass);
    EXPECT_EQ(snap->particle_body[water.first_particle + k], 2u);
  }
  EXPECT_NEAR(snap->body_vel[2].x, 0.25f, 1e-6f);  // its mean
  // A step runs (the density constraint's kernels on the OpenMP device).
  ASSERT_TRUE(sim.step(1));
}

}  // namespace
}  // namespace motes
