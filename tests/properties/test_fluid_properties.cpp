// Property tests of liquids with every other kind of scene (issue 29: "energy never grows in the
// randomized property scenes with liquid added"; docs/validation.md, section 16): the seeded
// scenes of random_scenes.h (domino chains, piles, stacks, drops, wedged bodies) with position
// contacts at frames of 1/60 s, each given a block of water from its own seed (3 to 7 particles a
// side, dropped from up to 10 cm above its bodies, anywhere over them, thrown sideways and down at
// up to 0.5 m/s), many side by side in one simulation, each checked on its own:
// - energy: the case's kinetic + potential energy (its bodies' and each water particle's) never
//   rises above its start by more than kEnergyMargin of its scale (the start's kinetic energy + m g
//   h above the floor of everything in it), as in RandomPositionScenes; the water's energy counts
//   the potential of its artificial pressure (motes::fluid_s_corr_energy: s_corr is a pair
//   repulsion, which at a free surface turns it into motion);
// - no guard warning: no particle travels more than Simulation::kSafeTravel of its diameter in a
//   substep, nothing is NaN;
// - nothing tunnels: no particle's centre goes below the floor by more than a quarter of its
//   diameter.
// A failure prints the seed and how to replay it.
//
// Environment: MOTES_PROPERTY_SEEDS (seeds per kind; default openmp 10, vulkan 1, cuda 8; the
// sanitizer build 1, its first 0.25 s), MOTES_PROPERTY_FIRST, MOTES_PROPERTY_SEED (one alone),
// MOTES_PROPERTY_KIND, MOTES_PROPERTY_DURATION (s, default 1.5), MOTES_PROPERTY_TRACE=1 (each
// case's energy and its water's every frame).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "motes/devices.h"
#include "motes/fluid.h"
#include "motes/shapes.h"
#include "motes/simulation.h"
#include "random_scenes.h"
#include "sanitized_build.h"

namespace motes_fluid_props {
namespace {

using motes_props::Case;
using motes_props::Kind;

constexpr double kEnergyMargin = 0.01;  // as RandomPositionScenes'
constexpr double kFrame = 1.0 / 60.0;
constexpr int kSubsteps = 24;  // RandomPositionScenes': the fastest drops need them
constexpr double kG = 9.81;
// The sanitizer build (tests/sanitized_build.h): fewer seeds, the first 0.5 s.
constexpr bool kQuick = motes_test::kSanitized;

int env_int(const char* name, int fallback) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' ? std::atoi(v) : fallback;
}

Eigen::Vector3d v3(const motes::shared::vec4& v) {
  return {static_cast<double>(v.x), static_cast<double>(v.y), static_cast<double>(v.z)};
}

/// The water of case c: a box of particles of the cases' diameter on the rest lattice (as a scene
/// file's fill: fluid_rest_spacing), from its own seed.
motes::FluidSpec water_of(const Case& c) {
  motes_props::Rng rng(0xF1D0ull + 131ull * c.seed + static_cast<std::uint64_t>(c.kind));
  const double d = motes_props::kDiameter;
  const double s = motes::fluid_rest_spacing(d);
  // Over the bodies: their centres' extent (x, z) and the top of their particles (y).
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e30), hi = -lo;
  for (const motes::BodySpec& b : c.bodies) {
    double reach = 0.0;
    for (const Eigen::Vector3f& p : b.shape->points)
      reach = std::max(reach, p.cast<double>().norm());
    lo = lo.cwiseMin(b.position - Eigen::Vector3d::Constant(reach));
    hi = hi.cwiseMax(b.position + Eigen::Vector3d::Constant(reach));
  }
  const int nx = rng.integer(3, 7), ny = rng.integer(3, 7), nz = rng.integer(3, 7);
  // Draws that fill one vector: last component first (random_scenes.cpp says why).
  const double over_z = rng.uniform(lo.z(), hi.z()), over_x = rng.uniform(lo.x(), hi.x());
  const Eigen::Vector3d over(over_x, 0.0, over_z);
  const Eigen::Vector3d corner(over.x() - 0.5 * nx * d, hi.y() + d + rng.uniform(0.0, 0.1),
                               over.z() - 0.5 * nz * d);
  motes::FluidSpec water;
  water.name = fmt::format("water {}", c.seed);
  water.diameter = d;
  for (int z = 0; z < nz; ++z) {
    for (int y = 0; y < ny; ++y) {
      for (int x = 0; x < nx; ++x) water.points.push_back(corner + s * Eigen::Vector3d(x, y, z));
    }
  }
  const double vz = rng.uniform(-0.5, 0.5), vy = rng.uniform(-0.5, 0.0),
               vx = rng.uniform(-0.5, 0.5);
  water.velocity = Eigen::Vector3d(vx, vy, vz);
  return water;
}

/// What one case did.
struct Outcome {
  double scale = 0.0, rise = 0.0, travel = 0.0, lowest = 1e30;
  std::string failure;
};

/// The artificial pressure's pair energy (motes::fluid_s_corr_energy) tabulated over [0, h].
class PairEnergy {
 public:
  PairEnergy(const motes::shared::FluidMaterial& f, double substep, int sweeps)
      : h_(static_cast<double>(f.density_h.y)) {
    for (int k = 0; k <= kSteps; ++k) {
      table_.push_back(motes::fluid_s_corr_energy(h_ * k / kSteps, f, substep, sweeps));
    }
  }
  [[nodiscard]] double operator()(double r) const {
    if (!(r < h_)) return 0.0;
    const double at = r / h_ * kSteps;
    const auto k = std::min(static_cast<std::size_t>(at), table_.size() - 2);
    const double t = at - static_cast<double>(k);
    return (1.0 - t) * table_[k] + t * table_[k + 1];
  }
  [[nodiscard]] double support() const { return h_; }

 private:
  static constexpr int kSteps = 4096;
  double h_;
  std::vector<double> table_;
};

/// Energy of body entries [first, last) in a snapshot: a rigid body's kinetic + m g y from its
/// body state; water's from its particles, with the artificial pressure's pair energy (the
/// potential its s_corr repulsion releases at a free surface, docs/fluids.md, "Energy").
double energy(const motes::Snapshot& s, const std::vector<motes::BodyInfo>& info,
              const std::vector<std::size_t>& entries, const PairEnergy& pair) {
  double e = 0.0;
  for (const std::size_t b : entries) {
    if (info[b].fluid) {
      const std::size_t lo = info[b].first_particle, hi = lo + info[b].particle_count;
      for (std::size_t i = lo; i < hi; ++i) {
        const double w = static_cast<double>(s.particle_vel[i].w);
        if (!(w > 0.0)) continue;
        e += (0.5 * v3(s.particle_vel[i]).squaredNorm() +
              kG * static_cast<double>(s.particle_pos[i].y)) /
             w;
        for (std::size_t j = i + 1; j < hi; ++j) {
          const double r = (v3(s.particle_pos[i]) - v3(s.particle_pos[j])).norm();
          if (r < pair.support()) e += pair(r);
        }
      }
      continue;
    }
    const double inv_m = static_cast<double>(s.body_pos[b].w);
    if (inv_m == 0.0) continue;
    e += 0.5 * v3(s.body_vel[b]).squaredNorm() / inv_m;
    e += 0.5 * v3(s.body_angmom[b]).dot(v3(s.body_angvel[b]));
    e += kG * static_cast<double>(s.body_pos[b].y) / inv_m;
  }
  return e;
}

std::vector<Outcome> run(const std::string& backend, const std::vector<Case>& cases,
                         std::string& skip) {
  std::vector<Outcome> out(cases.size());
  std::string why;
  motes_props::Batch batch = motes_props::make_batch(cases, why);
  if (!why.empty()) {
    for (Outcome& o : out) o.failure = why;
    return out;
  }
  motes::Scene& scene = batch.scene;
  scene.settings.contact_model = motes::ContactModel::Positions;
  scene.settings.dt = kFrame;
  scene.settings.substeps = kSubsteps;
  scene.settings.neighbour_capacity = motes::kFluidNeighbourCapacity;
  motes::Material water;
  water.name = "water";
  water.density = 1000.0;
  water.friction = 0.0;
  water.restitution = 0.0;
  const int material = static_cast<int>(scene.materials.size());
  scene.materials.push_back(water);
  for (const Case& c : cases) {
    scene.fluids.push_back(water_of(c));
    scene.fluids.back().material = material;
  }
  motes::Result<std::unique_ptr<motes::Device>> device =
      motes::open_device(backend, -1, motes_props::device_options());
  if (!device) {
    skip = device.message();
    return out;
  }
  auto created = motes::Simulation::create(scene, std::move(device).value());
  if (!created) {
    for (Outcome& o : out) o.failure = created.message();
    return out;
  }
  motes::Simulation& sim = *created.value();
  const std::vector<motes::BodyInfo>& info = sim.bodies();
  // Case k: its bodies, then its water (the fluids follow every body, in the cases' order).
  std::vector<std::vector<std::size_t>> entries(cases.size());
  for (std::size_t k = 0; k < cases.size(); ++k) {
    for (std::size_t b = batch.first_body[k]; b < batch.first_body[k + 1]; ++b) {
      entries[k].push_back(b);
    }
    entries[k].push_back(scene.bodies.size() + k);
  }
  auto start = sim.snapshot();
  if (!start) {
    for (Outcome& o : out) o.failure = start.message();
    return out;
  }
  const PairEnergy pair(motes::fluid_material(water, motes_props::kDiameter, kFrame / kSubsteps),
                        kFrame / kSubsteps, scene.settings.fluid_iterations);
  std::vector<double> e0(cases.size());
  for (std::size_t k = 0; k < cases.size(); ++k) {
    e0[k] = energy(*start, info, entries[k], pair);
    out[k].scale = e0[k];  // the floor is y = 0: m g y is the height energy
  }
  double duration = kQuick ? 0.25 : 1.5;
  if (const char* cap = std::getenv("MOTES_PROPERTY_DURATION"); cap != nullptr && *cap != '\0') {
    duration = std::atof(cap);
  }
  const auto frames = static_cast<int>(std::lround(duration / kFrame));
  const double hs = kFrame / kSubsteps;
  const bool trace = env_int("MOTES_PROPERTY_TRACE", 0) != 0;  // each case's energy every frame
  for (int f = 0; f < frames; ++f) {
    motes::Status st = sim.step(1);
    auto snap = st ? sim.snapshot() : motes::Result<motes::Snapshot>(st);
    if (!snap) {
      for (Outcome& o : out) o.failure = "the run stopped: " + snap.message();
      return out;
    }
    for (std::size_t k = 0; k < cases.size(); ++k) {
      Outcome& o = out[k];
      const double rise = (energy(*snap, info, entries[k], pair) - e0[k]) / o.scale;
      if (!std::isfinite(rise)) {
        if (o.failure.empty()) o.failure = fmt::format("non-finite state at frame {}", f + 1);
        continue;
      }
      o.rise = std::max(o.rise, rise);
      if (trace) {
        double water_k = 0.0, water_p = 0.0;
        const motes::BodyInfo& wb = info[entries[k].back()];
        for (std::size_t i = wb.first_particle; i < wb.first_particle + wb.particle_count; ++i) {
          const double w = static_cast<double>(snap->particle_vel[i].w);
          water_k += 0.5 * v3(snap->particle_vel[i]).squaredNorm() / w;
          water_p += kG * static_cast<double>(snap->particle_pos[i].y) / w;
        }
        std::printf(
            "trace %s %u frame %d: energy %+.4f of the scale; water kinetic %.4g J, m g y %.4g J\n",
            motes_props::kind_name(cases[k].kind), cases[k].seed, f + 1, rise, water_k, water_p);
      }
      for (const std::size_t b : entries[k]) {
        for (std::size_t i = info[b].first_particle;
             i < info[b].first_particle + info[b].particle_count; ++i) {
          const motes::shared::vec4 p = snap->particle_pos[i];
          const double d = 2.0 * static_cast<double>(p.w);
          o.travel = std::max(o.travel, v3(snap->particle_vel[i]).norm() * hs / d);
          o.lowest = std::min(o.lowest, static_cast<double>(p.y) / d);
        }
      }
    }
  }
  for (Outcome& o : out) {
    if (!o.failure.empty()) continue;
    if (o.rise > kEnergyMargin) {
      o.failure = fmt::format("energy rose {:.3g} of its scale ({:.3g} J), more than {}", o.rise,
                              o.scale, kEnergyMargin);
    } else if (!(o.travel <= motes::Simulation::kSafeTravel)) {
      o.failure = fmt::format("a particle travelled {:.3g} of its diameter in a substep", o.travel);
    } else if (o.lowest < -0.25) {
      o.failure = fmt::format("a particle's centre went {:.3g} d below the floor", -o.lowest);
    }
  }
  return out;
}

int default_seeds(const std::string& backend) {
  if (backend == "openmp") return kQuick ? 1 : 10;
  if (backend == "vulkan") return 1;  // lavapipe in CI
  return 8;
}

using Param = std::tuple<std::string, Kind>;
class RandomFluidScenes : public ::testing::TestWithParam<Param> {};

TEST_P(RandomFluidScenes, KeepEnergyAndNothingTunnels) {
  const auto& [backend, kind] = GetParam();
  if (const char* only = std::getenv("MOTES_PROPERTY_KIND"); only != nullptr && *only != '\0') {
    if (only != std::string(motes_props::kind_name(kind))) GTEST_SKIP() << "another kind";
  }
  std::vector<Case> cases;
  if (const int one = env_int("MOTES_PROPERTY_SEED", -1); one >= 0) {
    cases.push_back(motes_props::make_case(kind, static_cast<std::uint32_t>(one)));
  } else {
    const int first = env_int("MOTES_PROPERTY_FIRST", 1);
    const int count = env_int("MOTES_PROPERTY_SEEDS", default_seeds(backend));
    for (int s = first; s < first + count; ++s) {
      cases.push_back(motes_props::make_case(kind, static_cast<std::uint32_t>(s)));
    }
  }
  std::string skip;
  const std::vector<Outcome> got = run(backend, cases, skip);
  if (!skip.empty()) GTEST_SKIP() << "no " << backend << " device: " << skip;
  double rise = 0.0, travel = 0.0, lowest = 1e30;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const Outcome& o = got[k];
    rise = std::max(rise, o.rise);
    travel = std::max(travel, o.travel);
    lowest = std::min(lowest, o.lowest);
    if (o.failure.empty()) continue;
    ADD_FAILURE() << fmt::format(
        "{} seed {} on {} with water: {}\n  replay: MOTES_PROPERTY_KIND={} "
        "MOTES_PROPERTY_FIRST={} MOTES_PROPERTY_SEEDS={}",
        motes_props::kind_name(kind), cases[k].seed, backend, o.failure,
        motes_props::kind_name(kind), cases.front().seed, cases.size());
  }
  std::printf(
      "%s with water on %s: %zu cases; largest energy rise %.3g of the scale, travel %.3g d a "
      "substep, lowest centre %.3g d\n",
      motes_props::kind_name(kind), backend.c_str(), cases.size(), rise, travel, lowest);
}

// Adhesion's reaction (docs/fluids.md, "Solids in the density, and two-way coupling") on seeded
// splashes without gravity: each seed a block of water (3 to 6 particles a side, thrown at 0.6 to
// 1.2 m/s with a sideways part) with a random adhesion beta (0.5 to 4) at a rigid box (2 to 5
// particles a side, any orientation) and a soft cube of 3 particles a side, each placed at random
// across the water's path; many seeds side by side, 2 m apart. Each case's linear momentum
// (the box's m v, the soft cube's and the water's particles' v / w) is kept to 1e-6 of its start
// after 0.25 s, and both solids were pushed (each gained 1% of it at least).
constexpr double kAdhesionMomentumBound = 1e-6;

class RandomAdhesionSplashes : public ::testing::TestWithParam<std::string> {};

TEST_P(RandomAdhesionSplashes, KeepMomentum) {
  const std::string& backend = GetParam();
  const int seeds = env_int("MOTES_PROPERTY_SEEDS", kQuick ? 2 : 8);
  const double d = motes_props::kDiameter;
  {
    motes::Scene scene;
    scene.source = "<random adhesion splashes>";
    scene.settings.contact_model = motes::ContactModel::Positions;
    scene.settings.dt = kFrame;
    scene.settings.gravity = Eigen::Vector3d::Zero();
    scene.settings.substeps = motes::kFluidSubsteps;
    scene.settings.fluid_iterations = motes::kFluidIterations;
    scene.settings.neighbour_capacity = motes::kFluidNeighbourCapacity;
    scene.settings.particle_diameter = d;
    motes::Material solid;
    solid.name = "pine";
    solid.density = 500.0;
    scene.materials.push_back(solid);
    for (int k = 0; k < seeds; ++k) {
      motes_props::Rng rng(0xAD4E5ull + 977ull * static_cast<std::uint64_t>(k));
      const Eigen::Vector3d origin(2.0 * k, 0.0, 0.0);
      motes::Material water;
      water.name = fmt::format("water {}", k);
      water.density = 1000.0;
      water.adhesion = rng.uniform(0.5, 4.0);
      scene.materials.push_back(water);
      const int n = rng.integer(3, 6);
      motes::FluidSpec ball;
      ball.name = water.name;
      ball.diameter = d;
      ball.material = static_cast<int>(scene.materials.size()) - 1;
      const double s = motes::fluid_rest_spacing(d);
      for (int z = 0; z < n; ++z) {
        for (int y = 0; y < n; ++y) {
          for (int x = 0; x < n; ++x) ball.points.push_back(origin + s * Eigen::Vector3d(x, y, z));
        }
      }
      const double mid = 0.5 * (n - 1) * s;
      const double vz = rng.uniform(-0.2, 0.2), vy = rng.uniform(-0.2, 0.2),
                   vx = rng.uniform(0.6, 1.2);
      ball.velocity = Eigen::Vector3d(vx, vy, vz);
      scene.fluids.push_back(ball);
      const int nz = rng.integer(2, 5), ny = rng.integer(2, 5), nx = rng.integer(2, 5);
      const Eigen::Vector3i dims(nx, ny, nz);
      motes::BodySpec box;
      box.name = fmt::format("box {}", k);
      box.shape = std::make_shared<motes::ParticleSet>(motes::box_lattice(dims, d).value());
      const double bz = rng.uniform(-0.03, -0.01), by = rng.uniform(-0.02, 0.0),
                   bx = rng.uniform(0.07, 0.1);
      box.position = origin + Eigen::Vector3d(mid + bx, mid + by, mid + bz);
      const double az = rng.uniform(-1, 1), ay = rng.uniform(-1, 1), ax = rng.uniform(-1, 1);
      const double angle = rng.uniform(0.0, 6.283);
      box.rotation =
          Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d(ax, ay, az).normalized()));
      scene.bodies.push_back(box);
      motes::BodySpec cube;
      cube.name = fmt::format("jelly {}", k);
      cube.shape = std::make_shared<motes::ParticleSet>(
          motes::box_lattice(Eigen::Vector3i(3, 3, 3), d).value());
      const double cz = rng.uniform(0.02, 0.04), cy = rng.uniform(0.0, 0.02),
                   cx = rng.uniform(0.07, 0.1);
      cube.position = origin + Eigen::Vector3d(mid + cx, mid + cy, mid + cz);
      motes::SoftSpec soft;
      soft.frequency = 15.0;
      soft.damping = 10.0;
      soft.mode = motes::SoftMode::Linear;
      cube.soft = soft;
      scene.bodies.push_back(cube);
    }
    motes::Result<std::unique_ptr<motes::Device>> device =
        motes::open_device(backend, -1, motes_props::device_options());
    if (!device) GTEST_SKIP() << "no " << backend << " device: " << device.message();
    auto created = motes::Simulation::create(scene, std::move(device).value());
    ASSERT_TRUE(created) << created.message();
    motes::Simulation& sim = *created.value();
    const std::vector<motes::BodyInfo>& info = sim.bodies();
    // Body entries: the boxes and cubes in the scene's order, then the waters.
    const auto particles = [&](const motes::Snapshot& snap, std::size_t b) {
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      for (std::size_t i = info[b].first_particle;
           i < info[b].first_particle + info[b].particle_count; ++i) {
        p += v3(snap.particle_vel[i]) / static_cast<double>(snap.particle_vel[i].w);
      }
      return p;
    };
    const auto parts = [&](const motes::Snapshot& snap, int k) {
      const std::size_t box = 2 * static_cast<std::size_t>(k), cube = box + 1;
      const std::size_t wet = scene.bodies.size() + static_cast<std::size_t>(k);
      return std::array<Eigen::Vector3d, 3>{info[box].mass * v3(snap.body_vel[box]),
                                            particles(snap, cube), particles(snap, wet)};
    };
    auto start = sim.snapshot();
    ASSERT_TRUE(start) << start.message();
    ASSERT_TRUE(sim.step(15));  // 0.25 s
    auto end = sim.snapshot();
    ASSERT_TRUE(end) << end.message();
    double worst = 0.0;
    for (int k = 0; k < seeds; ++k) {
      const auto a = parts(*start, k), b = parts(*end, k);
      const Eigen::Vector3d p0 = a[0] + a[1] + a[2], p1 = b[0] + b[1] + b[2];
      const double drift = (p1 - p0).norm() / p0.norm();
      worst = std::max(worst, drift);
      EXPECT_LT(drift, kAdhesionMomentumBound) << backend << " seed " << k << ": momentum "
                                               << p0.transpose() << " -> " << p1.transpose();
      EXPECT_GT(b[0].norm(), 0.01 * p0.norm()) << backend << " seed " << k << ": box not pushed";
      EXPECT_GT(b[1].norm(), 0.01 * p0.norm()) << backend << " seed " << k << ": cube not pushed";
    }
    std::printf("adhesion splashes on %s: %d seeds, momentum kept to %.2g relative at worst\n",
                backend.c_str(), seeds, worst);
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, RandomAdhesionSplashes,
                         ::testing::Values("openmp", "vulkan", "cuda"),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

std::string param_name(const ::testing::TestParamInfo<Param>& p) {
  return std::get<0>(p.param) + "_" + motes_props::kind_name(std::get<1>(p.param));
}

INSTANTIATE_TEST_SUITE_P(Backends, RandomFluidScenes,
                         ::testing::Combine(::testing::Values("openmp", "vulkan", "cuda"),
                                            ::testing::ValuesIn(motes_props::kKinds)),
                         param_name);

}  // namespace
}  // namespace motes_fluid_props
