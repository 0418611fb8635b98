// Determinism (VALIDATION.md section 10): the same scene gives a bitwise-identical state hash
// run after run, and at 1 and 2 OpenMP threads (grid by a stable sort, gathered contact forces,
// per-body sums in particle order: no order depends on the thread schedule).
//
// The scene: 36 tumbling bodies of three shapes (boxes, rods, free spheres) thrown into a box of
// five planes around a static body, with gravity, a Coulomb cap and the clamped dashpot, so every
// code path of the step runs; the test also checks that they really collide.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "physics/physics_scenes.h"

namespace {

motes::Scene tumbling_scene() {
  // k = 2e3 N/m on 8 g particles: t_c = 4.4 ms, dt = 1e-4 s = t_c / 44.
  const motes::Material mat = motes_test::material(1000.0, 2.0e3, 300.0, 300.0, 0.4);
  motes::Scene scene = motes_test::scene_with(1.0e-4, Eigen::Vector3d(0.0, -9.81, 0.0), mat, true);
  scene.planes.push_back(motes_test::plane(Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero()));
  scene.planes.push_back(
      motes_test::plane(Eigen::Vector3d::UnitX(), Eigen::Vector3d(-0.15, 0.0, 0.0)));
  scene.planes.push_back(
      motes_test::plane(-Eigen::Vector3d::UnitX(), Eigen::Vector3d(0.15, 0.0, 0.0)));
  scene.planes.push_back(
      motes_test::plane(Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0.0, 0.0, -0.15)));
  scene.planes.push_back(
      motes_test::plane(-Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0.0, 0.0, 0.15)));

  const double d = 0.02;
  std::vector<std::shared_ptr<const motes::ParticleSet>> shapes = {motes_test::lattice(2, 2, 2, d),
                                                                   motes_test::lattice(1, 1, 4, d),
                                                                   motes_test::single_particle(d)};
  // A static block in the middle of the floor.
  motes::BodySpec block =
      motes_test::body(motes_test::lattice(4, 2, 4, d), Eigen::Vector3d(0.0, 0.02, 0.0));
  block.kind = motes::BodyKind::Static;
  scene.bodies.push_back(block);

  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int index = 0;
  for (int iy = 0; iy < 4; ++iy) {
    for (int iz = 0; iz < 3; ++iz) {
      for (int ix = 0; ix < 3; ++ix, ++index) {
        // 7 cm apart, thrown at up to 2 m/s: they collide within a few hundred steps.
        const Eigen::Vector3d pos(-0.07 + 0.07 * ix, 0.08 + 0.07 * iy, -0.07 + 0.07 * iz);
        const Eigen::Vector3d vel(2.0 * u(rng), 2.0 * u(rng), 2.0 * u(rng));
        const Eigen::Vector3d spin(10.0 * u(rng), 10.0 * u(rng), 10.0 * u(rng));
        const Eigen::Quaterniond rot(
            Eigen::AngleAxisd(3.0 * u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized()));
        scene.bodies.push_back(
            motes_test::body(shapes[static_cast<std::size_t>(index % 3)], pos, vel, spin, rot));
      }
    }
  }
  return scene;
}

/// True when particles of two different bodies overlap.
bool bodies_touch(const motes::Snapshot& s) {
  for (std::size_t i = 0; i < s.particle_pos.size(); ++i) {
    for (std::size_t j = i + 1; j < s.particle_pos.size(); ++j) {
      if (s.particle_body[i] == s.particle_body[j]) continue;
      const Eigen::Vector3d d =
          motes_test::to_vec3(s.particle_pos[i]) - motes_test::to_vec3(s.particle_pos[j]);
      const double r = static_cast<double>(s.particle_pos[i].w + s.particle_pos[j].w);
      if (d.squaredNorm() < r * r) return true;
    }
  }
  return false;
}

/// True when a moving particle overlaps one of the scene's planes.
bool touches_plane(const motes::Snapshot& s, const motes::Scene& scene) {
  for (std::size_t i = 0; i < s.particle_pos.size(); ++i) {
    if (s.particle_vel[i].w == 0.0f) continue;  // the static block
    for (const motes::PlaneSpec& pl : scene.planes) {
      const double gap = pl.normal.dot(motes_test::to_vec3(s.particle_pos[i]) - pl.point);
      if (gap < static_cast<double>(s.particle_pos[i].w)) return true;
    }
  }
  return false;
}

struct RunResult {
  std::uint64_t hash = 0;
  std::uint64_t contact_steps = 0;   // samples with any contact force (planes included)
  std::uint64_t body_contacts = 0;   // samples with particles of two bodies overlapping
  std::uint64_t plane_contacts = 0;  // samples with a moving particle against a plane
};

/// threads = 0: the default device (OpenMP's thread count, small loops on one thread). Otherwise
/// exactly `threads` threads with every loop split among them, however small (this scene has
/// fewer particles than the backend's default threshold for going parallel).
void run(int threads, std::uint64_t steps, RunResult& out, double skin = -1.0) {
  motes::DeviceOptions options;
  options.cpu_threads = threads;
  if (threads > 0) options.cpu_min_parallel = 1;
  auto device = motes::open_device("openmp", -1, options);
  ASSERT_TRUE(device) << device.message();
  if (threads > 0) {
    // The device must really use the thread count asked for.
    const std::string want = std::to_string(threads) + (threads == 1 ? " thread" : " threads");
    ASSERT_EQ(device.value()->info().detail.rfind(want, 0), 0u) << device.value()->info().detail;
  }
  motes::Scene scene = tumbling_scene();
  scene.settings.neighbour_skin = skin;
  auto created = motes::Simulation::create(scene, std::move(device).value());
  ASSERT_TRUE(created) << created.message();
  motes::Simulation& sim = *created.value();
  for (std::uint64_t done = 0; done < steps; done += 10) {
    ASSERT_TRUE(sim.step(10));
    auto force = motes_test::read_vec4(sim, motes::Buffer::ParticleForce);
    ASSERT_TRUE(force) << force.message();
    for (const auto& f : force.value()) {
      if (f.x != 0.0f || f.y != 0.0f || f.z != 0.0f) {
        ++out.contact_steps;
        break;
      }
    }
    auto s = sim.snapshot();
    ASSERT_TRUE(s) << s.message();
    if (bodies_touch(*s)) ++out.body_contacts;
    if (touches_plane(*s, scene)) ++out.plane_contacts;
  }
  ASSERT_TRUE(sim.check_finite());
  auto hash = sim.state_hash();
  ASSERT_TRUE(hash) << hash.message();
  out.hash = hash.value();
}

constexpr std::uint64_t kSteps = 1000;  // 0.1 s: bodies hit the walls, the block and each other
// Forcing threads on a few hundred particles costs a fork per loop; fewer steps keep it quick.
constexpr std::uint64_t kThreadSteps = 200;

TEST(Determinism, SameHashRunToRun) {
  RunResult a;
  RunResult b;
  ASSERT_NO_FATAL_FAILURE(run(0, kSteps, a));
  ASSERT_NO_FATAL_FAILURE(run(0, kSteps, b));
  // Sampled every 10 steps: bodies touching each other in many samples, or the test would
  // prove little.
  EXPECT_GT(a.body_contacts, kSteps / 40) << "the bodies hardly collided: the test is too weak";
  EXPECT_EQ(a.hash, b.hash);
  std::printf(
      "[determinism] %llu steps: contact forces in %llu and body-body contacts in %llu of %llu "
      "samples, hash %016llx\n",
      static_cast<unsigned long long>(kSteps), static_cast<unsigned long long>(a.contact_steps),
      static_cast<unsigned long long>(a.body_contacts),
      static_cast<unsigned long long>(kSteps / 10), static_cast<unsigned long long>(a.hash));
}

TEST(Determinism, SameHashAtOneAndTwoThreads) {
  RunResult one;
  RunResult two;
  ASSERT_NO_FATAL_FAILURE(run(1, kThreadSteps, one));
  ASSERT_NO_FATAL_FAILURE(run(2, kThreadSteps, two));
  EXPECT_GT(one.body_contacts, kThreadSteps / 40) << "the bodies hardly collided";
  EXPECT_EQ(one.hash, two.hash);
  std::printf(
      "[determinism] %llu steps at 1 and 2 threads: body-body contacts in %llu of %llu "
      "samples\n",
      static_cast<unsigned long long>(kThreadSteps),
      static_cast<unsigned long long>(one.body_contacts),
      static_cast<unsigned long long>(kThreadSteps / 10));
}

TEST(Determinism, ThreeThreadsOnTwoCoresToo) {
  // An odd thread count splits every loop differently again; still the same state.
  RunResult two;
  RunResult three;
  ASSERT_NO_FATAL_FAILURE(run(2, kThreadSteps, two));
  ASSERT_NO_FATAL_FAILURE(run(3, kThreadSteps, three));
  EXPECT_EQ(two.hash, three.hash);
}

// contacts_compute on openmp evaluates a contact of two particles that list each other once and
// gives it to both (a half list: docs/architecture.md). Its sums are those of each particle
// evaluating its own list, term for term in list order: the same state to the bit, at 1 and 2
// threads, whether the pairs are shared always (MOTES_OPENMP_SHARED_PAIRS=1) or never (0).
TEST(Determinism, SharedContactPairsGiveTheStateOfOwnEvaluations) {
  const auto with = [](const char* pairs, int threads, RunResult& out) {
    ::setenv("MOTES_OPENMP_SHARED_PAIRS", pairs, 1);
    run(threads, kThreadSteps, out);
    ::unsetenv("MOTES_OPENMP_SHARED_PAIRS");
  };
  RunResult own;
  RunResult shared_one;
  RunResult shared_two;
  ASSERT_NO_FATAL_FAILURE(with("0", 1, own));
  ASSERT_NO_FATAL_FAILURE(with("1", 1, shared_one));
  ASSERT_NO_FATAL_FAILURE(with("1", 2, shared_two));
  EXPECT_GT(own.body_contacts, kThreadSteps / 40) << "the bodies hardly collided";
  EXPECT_EQ(own.hash, shared_one.hash);
  EXPECT_EQ(own.hash, shared_two.hash);
}

// contacts_compute on openmp tests only the planes a particle may reach before the next list
// build (backends/openmp/plane_masks.cpp); a skipped plane would have added exactly 0. The state
// is that of every particle testing every plane (MOTES_OPENMP_PLANE_MASKS=0), to the bit: with
// the default skin, at 1 and 2 threads, and with no skin (lists made every step). A mask that
// left out a plane coming into reach between two builds fails it.
TEST(Determinism, PlaneMasksGiveTheStateOfEveryPlaneTested) {
  // The bodies reach the walls and the floor after about 0.03 s: all of kSteps.
  const auto with = [](const char* masks, int threads, double skin, RunResult& out) {
    ::setenv("MOTES_OPENMP_PLANE_MASKS", masks, 1);
    run(threads, kSteps, out, skin);
    ::unsetenv("MOTES_OPENMP_PLANE_MASKS");
  };
  RunResult every;
  RunResult masked_one;
  RunResult masked_two;
  ASSERT_NO_FATAL_FAILURE(with("0", 1, -1.0, every));
  ASSERT_NO_FATAL_FAILURE(with("1", 1, -1.0, masked_one));
  ASSERT_NO_FATAL_FAILURE(with("1", 2, -1.0, masked_two));
  EXPECT_GT(every.plane_contacts, kSteps / 40) << "hardly anything hit a plane: too weak";
  EXPECT_EQ(every.hash, masked_one.hash);
  EXPECT_EQ(every.hash, masked_two.hash);
  RunResult every_unskinned;
  RunResult masked_unskinned;
  ASSERT_NO_FATAL_FAILURE(with("0", 1, 0.0, every_unskinned));
  ASSERT_NO_FATAL_FAILURE(with("1", 1, 0.0, masked_unskinned));
  EXPECT_GT(every_unskinned.plane_contacts, kSteps / 40) << "hardly anything hit a plane";
  EXPECT_EQ(every_unskinned.hash, masked_unskinned.hash);
}

}  // namespace
