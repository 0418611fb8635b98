// Position-based fluids (issue 29; docs/fluids.md) on the OpenMP device, against answers that do
// not come from motes:
// - hydrostatics: a tank of 12 x 14 x 12 particles (d = 1 cm, the settled parameter set: 16
//   substeps of 1/60 s, 2 sweeps) at rest for 2 s: the bulk's mean density within 1% of the rest
//   density (the bulk: particles more than h = 2 d from the walls, the floor and the surface, the
//   97th percentile of the heights; the surface layer is excluded), and the pressure of the last
//   0.25 s's mean summed lambda (fluid_pressure), Shepard-filtered, fitted against the depth and
//   times the bulk's mean kernel-gradient moment M_yy, within 5% of rho_0 g (docs/fluids.md,
//   "Settled with the prototype", says why each step of this reading is needed);
// - the dam break of Martin and Moyce (1952), n^2 = 2: a column a = 8 d wide and 2 a high, rested
//   1 s behind a wall that is then taken away; its surge front (the 99th percentile of the
//   particles' leading edges, so that the few squeezed out along the floor do not lead it) over
//   the floor, Z = x / a against T = t sqrt(2 g / a), within 10% of every point of both of their
//   series up to T = 9.2 (figure 3, a = 1.125 and 2.25 in, as digitized in PySPH's
//   db_exp_data.py); the largest density error of any particle at the end of a frame below 2%;
// In the sanitizer build the three long tests step their first frames and check only the paths
// (motes_test::frames_to_run), as the seeded tests run one seed there.
// - Archimedes: cubes of 250, 500 and 750 kg/m^3 (8 particles a side, d = 5 mm) dropped into a
//   tank of water float with their density ratio of their volume under the level the liquid's
//   own rest volume fills (the particles' lattice cells below it; the free surface's particles
//   sit loose above that level, so their heights would read it high), within 5%, averaged over
//   the last half second of 1 s (at 4 particles a side the lighter cubes float 6 to 12% high:
//   the error is a fraction of a particle diameter, docs/fluids.md);
// - momentum: a ball of liquid thrown without gravity at a free rigid box: the linear momentum of
//   the liquid and the box kept to 1e-6 relative (the box takes the reaction of each fluid
//   particle's shift, fluid_solid_reaction, and of the contacts); the same at a soft cube and a
//   free cloth, whose particles take the reaction as their own shifts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "motes/cloth.h"
#include "motes/fluid.h"
#include "physics/physics_scenes.h"
#include "shared/fluid.h"

namespace fluid_physics {

using motes_test::to_vec3;

constexpr double kFluidFrame = 1.0 / 60.0;
constexpr double kFluidD = 0.01;

motes::Material water() {
  motes::Material m = motes_test::material(1000.0, 0.0, 0.0, 0.0, 0.0);
  m.name = "water";
  return m;
}

/// A scene of position contacts with the settled fluid defaults (16 substeps, 2 sweeps, 64 list
/// entries) and a water material (0).
motes::Scene fluid_scene(const Eigen::Vector3d& gravity) {
  motes::Scene scene = motes_test::scene_with(kFluidFrame, gravity, water());
  scene.settings.contact_model = motes::ContactModel::Positions;
  scene.settings.substeps = motes::kFluidSubsteps;
  scene.settings.fluid_iterations = motes::kFluidIterations;
  scene.settings.neighbour_capacity = motes::kFluidNeighbourCapacity;
  return scene;
}

/// A block of nx x ny x nz fluid particles on the rest lattice, its lowest corner particle's
/// centre at `corner`.
motes::FluidSpec fluid_block(int nx, int ny, int nz, const Eigen::Vector3d& corner) {
  motes::FluidSpec f;
  f.name = "water";
  f.diameter = kFluidD;
  for (int x = 0; x < nx; ++x) {
    for (int y = 0; y < ny; ++y) {
      for (int z = 0; z < nz; ++z) f.points.push_back(corner + kFluidD * Eigen::Vector3d(x, y, z));
    }
  }
  return f;
}

/// A tank of planes: the floor y = 0 and walls at x = 0, x = length, z = 0 and z = depth.
void add_tank(motes::Scene& scene, double length, double depth) {
  scene.planes.push_back(motes_test::plane({0, 1, 0}, {0, 0, 0}));
  scene.planes.push_back(motes_test::plane({1, 0, 0}, {0, 0, 0}));
  scene.planes.push_back(motes_test::plane({-1, 0, 0}, {length, 0, 0}));
  scene.planes.push_back(motes_test::plane({0, 0, 1}, {0, 0, 0}));
  scene.planes.push_back(motes_test::plane({0, 0, -1}, {0, 0, depth}));
}

TEST(Fluid, TankAtRestHoldsItsDensityAndItsPressureGrowsWithDepth) {
  constexpr int kSide = 12;
  constexpr int kLayers = 14;
  const double width = kSide * kFluidD;
  motes::Scene scene = fluid_scene(Eigen::Vector3d(0.0, -9.81, 0.0));
  scene.fluids.push_back(
      fluid_block(kSide, kLayers, kSide, Eigen::Vector3d::Constant(0.5 * kFluidD)));
  add_tank(scene, width, width);
  auto sim_r = motes_test::simulate(scene, 2);
  ASSERT_TRUE(sim_r) << sim_r.status().message();
  motes::Simulation& sim = *sim_r.value();

  // The fluid is the scene's only object: device particle k is the scene's k, FluidState[k].
  const std::size_t n = scene.fluids[0].points.size();
  const double hs = kFluidFrame / motes::kFluidSubsteps;
  const motes::shared::FluidMaterial f = motes::fluid_material(water(), kFluidD, hs);
  const double rho0 = f.density_h.x;
  const double h = f.density_h.y;
  const double m = f.density_h.z;
  const int frames = motes_test::frames_to_run(120, 16);  // 2 s
  constexpr int kMeanFrames = 15;                         // the last 0.25 s
  std::vector<double> lambda_sum(n, 0.0);
  std::vector<motes::shared::vec4> state;
  for (int frame = 0; frame < frames; ++frame) {
    ASSERT_TRUE(sim.step(1));
    if (frame < frames - kMeanFrames) continue;
    auto read = motes_test::read_vec4(sim, motes::Buffer::FluidState);
    ASSERT_TRUE(read) << read.status().message();
    state = read.value();
    for (std::size_t k = 0; k < n; ++k) lambda_sum[k] += static_cast<double>(state[k].z);
  }
  auto snap = sim.snapshot();
  ASSERT_TRUE(snap) << snap.status().message();
  if (!motes_test::physics_checked()) return;  // the sanitizer build: the paths only
  std::vector<Eigen::Vector3d> x(n);
  std::vector<double> heights(n);
  for (std::size_t k = 0; k < n; ++k) {
    x[k] = to_vec3(snap.value().particle_pos[k]);
    heights[k] = x[k].y();
    ASSERT_TRUE(x[k].allFinite());
  }
  std::vector<double> sorted = heights;
  std::sort(sorted.begin(), sorted.end());
  const double surface = sorted[static_cast<std::size_t>(0.97 * static_cast<double>(n - 1))];
  // The column stands where it was filled (14 layers: 0.14 m) within a layer.
  EXPECT_NEAR(surface, kLayers * kFluidD - 0.5 * kFluidD, kFluidD)
      << "surface (97th percentile of centres)";

  // The bulk, the pressure (Shepard-filtered) and the kernel gradient's moment, over all pairs.
  std::vector<double> pressure(n);
  for (std::size_t k = 0; k < n; ++k) {
    pressure[k] = static_cast<double>(
        motes::shared::fluid_pressure(static_cast<float>(lambda_sum[k] / kMeanFrames),
                                      f.density_h.x, f.density_h.z, static_cast<float>(hs)));
  }
  double density_sum = 0.0;
  double worst_density = 0.0;
  double myy_sum = 0.0;
  std::vector<double> depth, filtered;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& xi = x[i];
    const bool bulk = xi.x() > h && xi.x() < width - h && xi.z() > h && xi.z() < width - h &&
                      xi.y() > h && xi.y() < surface - h;
    if (!bulk) continue;
    double wsum = 0.0;
    double psum = 0.0;
    double myy = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
      const Eigen::Vector3d r = xi - x[j];
      const double r2 = r.squaredNorm();
      if (r2 >= h * h) continue;
      const double w = static_cast<double>(
          motes::shared::fluid_poly6(static_cast<float>(r2), static_cast<float>(h)));
      wsum += w;
      psum += w * pressure[j];
      if (j == i) continue;
      const motes::shared::vec3 term = motes::shared::fluid_gradient_moment_term(
          motes::shared::vec3(static_cast<float>(r.x()), static_cast<float>(r.y()),
                              static_cast<float>(r.z())),
          static_cast<float>(m), static_cast<float>(rho0), static_cast<float>(h));
      myy += static_cast<double>(term.y);
    }
    const double c = static_cast<double>(state[i].x) / rho0 - 1.0;
    density_sum += c;
    worst_density = std::max(worst_density, std::abs(c));
    myy_sum += myy;
    depth.push_back(surface - xi.y());
    filtered.push_back(psum / wsum);
  }
  const auto bulk = static_cast<double>(depth.size());
  ASSERT_GT(bulk, 200.0) << "too few bulk particles to measure";
  const double mean_density = density_sum / bulk;
  EXPECT_LT(std::abs(mean_density), 0.01) << "bulk density error (mean), worst " << worst_density;
  // Least squares of the filtered pressure against the depth.
  double sd = 0.0, sp = 0.0, sdd = 0.0, sdp = 0.0;
  for (std::size_t k = 0; k < depth.size(); ++k) {
    sd += depth[k];
    sp += filtered[k];
    sdd += depth[k] * depth[k];
    sdp += depth[k] * filtered[k];
  }
  const double slope = (bulk * sdp - sd * sp) / (bulk * sdd - sd * sd);
  const double myy = myy_sum / bulk;
  const double measured = slope * myy / (rho0 * 9.81);
  EXPECT_NEAR(measured, 1.0, 0.05) << "pressure slope x M_yy / (rho_0 g); raw slope / rho_0 g "
                                   << slope / (rho0 * 9.81) << ", M_yy " << myy;
  std::printf(
      "tank: %zu particles, bulk %zu, density %+.3f%% (worst %.2f%%), slope x M_yy / "
      "rho_0 g %.4f (M_yy %.4f), surface %.4f m\n",
      n, depth.size(), 100.0 * mean_density, 100.0 * worst_density, measured, myy, surface);
}

/// Martin and Moyce 1952, figure 3, n^2 = 2: (T, Z) of the surge front for a = 1.125 in and
/// a = 2.25 in (digitized in PySPH's pysph/examples/db_exp_data.py).
constexpr double kMartinMoyce[][2] = {
    {0.849, 1.245}, {1.212, 1.443},  {1.602, 1.884},  {2.283, 2.689},  {2.950, 3.728},
    {3.598, 4.528}, {3.905, 4.999},  {4.592, 5.841},  {4.961, 6.271},  {5.316, 6.717},
    {0.832, 1.217}, {1.219, 1.474},  {1.997, 2.292},  {2.547, 2.995},  {3.345, 4.134},
    {4.034, 4.944}, {4.418, 5.881},  {5.091, 6.980},  {5.685, 7.945},  {6.306, 8.966},
    {6.822, 9.986}, {7.439, 10.963}, {8.031, 11.977}, {8.633, 13.005}, {9.237, 13.970}};

TEST(Fluid, DamBreakFrontFollowsMartinAndMoyce) {
  constexpr int kWide = 8;  // a = 8 d
  const double a = kWide * kFluidD;
  const double length = 130 * kFluidD;
  const double depth = 8 * kFluidD;
  motes::Scene scene = fluid_scene(Eigen::Vector3d(0.0, -9.81, 0.0));
  scene.fluids.push_back(
      fluid_block(kWide, 2 * kWide, 8, Eigen::Vector3d::Constant(0.5 * kFluidD)));
  add_tank(scene, length, depth);
  motes::Scene held = scene;
  held.planes.push_back(motes_test::plane({-1, 0, 0}, {a, 0, 0}));  // the dam
  auto rest_r = motes_test::simulate(held, 2);
  ASSERT_TRUE(rest_r) << rest_r.status().message();
  ASSERT_TRUE(rest_r.value()->step(motes_test::frames_to_run(60, 4)));  // 1 s behind the dam
  auto rested = rest_r.value()->snapshot();
  ASSERT_TRUE(rested) << rested.status().message();
  auto sim_r = motes_test::simulate(scene, 2);
  ASSERT_TRUE(sim_r) << sim_r.status().message();
  motes::Simulation& sim = *sim_r.value();
  motes::Snapshot start = rested.value();
  start.time = 0.0;
  start.step = 0;
  ASSERT_TRUE(sim.write_state(start));

  const std::size_t n = scene.fluids[0].points.size();
  const double rho0 = 1000.0;
  const double t_scale = std::sqrt(2.0 * 9.81 / a);
  std::vector<double> times{0.0}, fronts;
  const auto front = [&](const motes::Snapshot& s) {
    std::vector<double> edge(n);
    for (std::size_t k = 0; k < n; ++k)
      edge[k] = static_cast<double>(s.particle_pos[k].x) + 0.5 * kFluidD;
    std::sort(edge.begin(), edge.end());
    return edge[static_cast<std::size_t>(0.99 * static_cast<double>(n - 1))] / a;
  };
  fronts.push_back(front(start));
  double worst_density = 0.0;
  const int kFrames = motes_test::frames_to_run(38, 4);  // 0.63 s: T = 9.9
  for (int frame = 1; frame <= kFrames; ++frame) {
    ASSERT_TRUE(sim.step(1));
    auto state = motes_test::read_vec4(sim, motes::Buffer::FluidState);
    ASSERT_TRUE(state) << state.status().message();
    double largest = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      largest = std::max(largest, static_cast<double>(state.value()[k].x) / rho0 - 1.0);
    }
    auto snap = sim.snapshot();
    ASSERT_TRUE(snap);
    times.push_back(frame * kFluidFrame * t_scale);
    fronts.push_back(front(snap.value()));
    worst_density = std::max(worst_density, largest);
    std::printf("dam break: T %.3f Z %.3f, largest density error %.2f%%\n", times.back(),
                fronts.back(), 100.0 * largest);
  }
  if (!motes_test::physics_checked()) return;  // the sanitizer build: the paths only
  EXPECT_LT(worst_density, 0.02) << "the largest density error of a frame";
  double worst = 0.0;
  for (const auto& [t, z] : kMartinMoyce) {
    const auto after = std::upper_bound(times.begin(), times.end(), t);
    ASSERT_NE(after, times.end()) << "T " << t << " is past the run";
    const std::size_t k = static_cast<std::size_t>(after - times.begin());
    const double u = (t - times[k - 1]) / (times[k] - times[k - 1]);
    const double zs = fronts[k - 1] + u * (fronts[k] - fronts[k - 1]);
    EXPECT_NEAR(zs / z, 1.0, 0.10) << "at T " << t << ": Z " << zs << " against " << z;
    worst = std::max(worst, std::abs(zs / z - 1.0));
  }
  std::printf(
      "dam break: the front within %.1f%% of Martin and Moyce's points; largest density "
      "error %.2f%%\n",
      100.0 * worst, 100.0 * worst_density);
}

TEST(Fluid, CubesFloatWithTheirDensityRatioUnderWater) {
  constexpr double d = 0.005;
  constexpr double kLength = 0.24, kDepth = 0.08, kFill = 0.05;
  motes::Scene scene = fluid_scene(Eigen::Vector3d(0.0, -9.81, 0.0));
  scene.materials[0].viscosity = 0.05;
  const double densities[3] = {250.0, 500.0, 750.0};
  for (int k = 0; k < 3; ++k) {
    motes::Material wood = motes_test::material(densities[k], 0.0, 0.0, 0.0, 0.2);
    wood.name = "wood" + std::to_string(k);
    scene.materials.push_back(wood);
    motes::BodySpec cube = motes_test::body(motes_test::lattice(8, 8, 8, d),
                                            Eigen::Vector3d(0.04 + 0.08 * k, kFill + 0.024, 0.04));
    cube.name = wood.name;
    cube.material = k + 1;
    scene.bodies.push_back(cube);
  }
  motes::FluidSpec water;
  water.name = "water";
  water.diameter = d;
  for (double z = 0.5 * d; z < kDepth; z += d) {
    for (double y = 0.5 * d; y < kFill; y += d) {
      for (double x = 0.5 * d; x < kLength; x += d) water.points.emplace_back(x, y, z);
    }
  }
  scene.fluids.push_back(water);
  add_tank(scene, kLength, kDepth);
  auto sim_r = motes_test::simulate(scene, 2);
  ASSERT_TRUE(sim_r) << sim_r.status().message();
  motes::Simulation& sim = *sim_r.value();
  const std::vector<motes::BodyInfo>& bodies = sim.bodies();
  ASSERT_EQ(bodies.size(), 4u);
  const double cell = d * d * d;
  const double liquid = static_cast<double>(bodies[3].particle_count) * cell;
  double fraction[3] = {0.0, 0.0, 0.0};
  const int kFrames = motes_test::frames_to_run(60, 3);
  const int kMean = std::min(30, kFrames);
  for (int frame = 0; frame < kFrames; ++frame) {
    ASSERT_TRUE(sim.step(1));
    if (frame < kFrames - kMean) continue;
    auto snap = sim.snapshot();
    ASSERT_TRUE(snap);
    // The part of each cube particle's lattice cell below the level H; H such that the liquid's
    // rest volume and the cubes' cells below it fill the tank to it.
    const auto under = [&](int k, double level) {
      double sum = 0.0;
      for (std::uint32_t p = 0; p < bodies[k].particle_count; ++p) {
        const double y =
            static_cast<double>(snap.value().particle_pos[bodies[k].first_particle + p].y);
        sum += std::clamp((level - (y - 0.5 * d)) / d, 0.0, 1.0);
      }
      return sum / bodies[k].particle_count;
    };
    double level = liquid / (kLength * kDepth);
    for (int it = 0; it < 50; ++it) {
      double solid = 0.0;
      for (int k = 0; k < 3; ++k) solid += under(k, level) * bodies[k].particle_count * cell;
      level = (liquid + solid) / (kLength * kDepth);
    }
    for (int k = 0; k < 3; ++k) fraction[k] += under(k, level) / static_cast<double>(kMean);
  }
  if (!motes_test::physics_checked()) return;  // the sanitizer build: the paths only
  for (int k = 0; k < 3; ++k) {
    const double want = densities[k] / 1000.0;
    EXPECT_NEAR(fraction[k] / want, 1.0, 0.05)
        << bodies[k].name << ": " << fraction[k] << " of it under water, " << want << " expected";
    std::printf("Archimedes: %.0f kg/m^3 floats %.3f under water (%.2f)\n", densities[k],
                fraction[k], want);
  }
}

/// Akinci's adhesion beta of the splash tests' second runs: the liquid clings to the solids it
/// touches, and they take the reaction (fluid_velocity's solid side).
constexpr double kSplashAdhesion = 2.0;

void splash_on_a_free_box(double adhesion) {
  motes::Scene scene = fluid_scene(Eigen::Vector3d::Zero());
  scene.materials[0].adhesion = adhesion;
  // A 4 x 4 x 4 box of particles of d, at rest, and a 6 x 6 x 6 block of water moving at it.
  motes::BodySpec box =
      motes_test::body(motes_test::lattice(4, 4, 4, kFluidD), Eigen::Vector3d(0.1, 0.0, 0.0));
  box.name = "box";
  scene.bodies.push_back(box);
  motes::FluidSpec ball = fluid_block(6, 6, 6, Eigen::Vector3d(-0.025, -0.02, -0.03));
  ball.velocity = Eigen::Vector3d(1.0, 0.1, 0.0);
  scene.fluids.push_back(ball);
  auto sim_r = motes_test::simulate(scene, 2);
  ASSERT_TRUE(sim_r) << sim_r.status().message();
  motes::Simulation& sim = *sim_r.value();
  const std::vector<motes::BodyInfo>& bodies = sim.bodies();
  ASSERT_EQ(bodies.size(), 2u);
  ASSERT_TRUE(bodies[1].fluid);
  const auto momentum = [&](const motes::Snapshot& s) {
    Eigen::Vector3d p = bodies[0].mass * to_vec3(s.body_vel[0]);
    for (std::uint32_t k = 0; k < bodies[1].particle_count; ++k) {
      const motes::shared::vec4 v = s.particle_vel[bodies[1].first_particle + k];
      p += to_vec3(v) / static_cast<double>(v.w);
    }
    return p;
  };
  auto start = sim.snapshot();
  ASSERT_TRUE(start);
  const Eigen::Vector3d p0 = momentum(start.value());
  ASSERT_TRUE(sim.step(12));  // 0.2 s: the liquid reaches the box and splashes on it
  auto end = sim.snapshot();
  ASSERT_TRUE(end);
  const Eigen::Vector3d p1 = momentum(end.value());
  const double box_speed = to_vec3(end.value().body_vel[0]).x();
  EXPECT_GT(box_speed, 0.05) << "the liquid pushed the box";
  EXPECT_LT((p1 - p0).norm(), 1e-6 * p0.norm())
      << "momentum before " << p0.transpose() << ", after " << p1.transpose();
  std::printf("splash, adhesion %.1f: momentum kept to %.2g relative\n", adhesion,
              (p1 - p0).norm() / p0.norm());
}

TEST(Fluid, ASplashOnAFreeBoxKeepsMomentum) { splash_on_a_free_box(0.0); }
TEST(Fluid, ASplashOnAFreeBoxKeepsMomentumWithAdhesion) { splash_on_a_free_box(kSplashAdhesion); }

void splash_on_a_soft_cube_and_a_cloth(double adhesion) {
  motes::Scene scene = fluid_scene(Eigen::Vector3d::Zero());
  scene.materials[0].adhesion = adhesion;
  scene.settings.constraint_iterations = 2;
  motes::BodySpec cube =
      motes_test::body(motes_test::lattice(4, 4, 4, kFluidD), Eigen::Vector3d(0.1, 0.0, 0.0));
  cube.name = "jelly";
  motes::SoftSpec soft;
  soft.frequency = 15.0;
  soft.damping = 10.0;
  soft.mode = motes::SoftMode::Linear;
  cube.soft = soft;
  scene.bodies.push_back(cube);
  motes::ClothOptions o;
  o.corner = Eigen::Vector3d(0.06, 0.025, -0.05);  // a sheet across the ball's upper half
  o.edge_u = Eigen::Vector3d(0.0, 0.0, 0.1);
  o.edge_v = Eigen::Vector3d(0.0, 0.05, 0.0);
  o.nu = 11;
  o.nv = 6;
  o.diameter = kFluidD;
  motes::LinkedSpec cloth = motes::make_cloth(o).value();
  cloth.name = "sheet";
  scene.linked.push_back(cloth);
  motes::FluidSpec ball = fluid_block(6, 8, 6, Eigen::Vector3d(-0.025, -0.02, -0.03));
  ball.velocity = Eigen::Vector3d(1.0, 0.2, 0.0);
  scene.fluids.push_back(ball);
  auto sim_r = motes_test::simulate(scene, 2);
  ASSERT_TRUE(sim_r) << sim_r.status().message();
  motes::Simulation& sim = *sim_r.value();
  // Every particle is free here (no rigid body): the momentum is the particles' sum.
  const auto momentum = [](const motes::Snapshot& s) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (const motes::shared::vec4& v : s.particle_vel) p += to_vec3(v) / static_cast<double>(v.w);
    return p;
  };
  const auto body_momentum = [&](const motes::Snapshot& s, const motes::BodyInfo& b) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (std::uint32_t k = 0; k < b.particle_count; ++k) {
      const motes::shared::vec4 v = s.particle_vel[b.first_particle + k];
      p += to_vec3(v) / static_cast<double>(v.w);
    }
    return p;
  };
  auto start = sim.snapshot();
  ASSERT_TRUE(start);
  const Eigen::Vector3d p0 = momentum(start.value());
  ASSERT_TRUE(sim.step(15));  // 0.25 s: the liquid reaches both and splashes on them
  auto end = sim.snapshot();
  ASSERT_TRUE(end);
  const Eigen::Vector3d p1 = momentum(end.value());
  const std::vector<motes::BodyInfo>& bodies = sim.bodies();
  ASSERT_EQ(bodies.size(), 3u);
  EXPECT_GT(body_momentum(end.value(), bodies[0]).x(), 0.05 * p0.x())
      << "the liquid pushed the cube";
  EXPECT_GT(body_momentum(end.value(), bodies[1]).x(), 0.02 * p0.x())
      << "the liquid pushed the cloth";
  EXPECT_LT((p1 - p0).norm(), 1e-6 * p0.norm())
      << "momentum before " << p0.transpose() << ", after " << p1.transpose();
  std::printf("splash, adhesion %.1f: momentum kept to %.2g relative\n", adhesion,
              (p1 - p0).norm() / p0.norm());
}

TEST(Fluid, ASplashOnASoftCubeAndAClothKeepsMomentum) { splash_on_a_soft_cube_and_a_cloth(0.0); }
TEST(Fluid, ASplashOnASoftCubeAndAClothKeepsMomentumWithAdhesion) {
  splash_on_a_soft_cube_and_a_cloth(kSplashAdhesion);
}

}  // namespace fluid_physics
