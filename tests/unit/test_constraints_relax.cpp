// Cloth and rope constraints relaxed in one launch (constraints_relax;
// MOTES_CONSTRAINTS_RELAX_LIMIT above the scene's constraints) or a launch per colour and sweep
// (constraints_solve; the limit 0): the same state to the bit on each backend, in whole scenes with
// cloth, ropes and attachments, under the force law and under position contacts; and the launches
// the core makes are the ones it says (kernel timing counts them). Which way a device takes by
// itself (DeviceInfo::one_launch_constraints) is a matter of speed only.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "motes/devices.h"
#include "motes/scene.h"
#include "motes/simulation.h"
#include "sanitized_build.h"
#include "unit/test_support.h"

namespace {

/// Every scene's constraints in one launch.
constexpr const char* kAll = "4294967295";

struct RelaxRun {
  std::uint64_t hash = 0;
  std::uint64_t relax_launches = 0;
  std::uint64_t solve_launches = 0;
};

/// `steps` steps of example scene `name` on `backend` with MOTES_CONSTRAINTS_RELAX_LIMIT=`limit`;
/// timing on for the launch counts when `timed`. A nonzero `seed` moves each cloth and rope by a
/// random offset (up to 1 cm across, 5 mm up or down) and each of its points by up to 0.3 mm,
/// so that its links start stretched or slack by different amounts and it lands elsewhere.
void run_scene(const std::string& backend, const std::string& name, std::uint64_t steps,
               const char* limit, bool timed, RelaxRun& out, std::uint32_t seed = 0) {
  auto scene = motes::load_scene_file(motes_test::example_path(name));
  ASSERT_TRUE(scene) << scene.message();
  if (seed != 0) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (motes::LinkedSpec& l : scene.value().linked) {
      const Eigen::Vector3d shift(0.01 * u(rng), 0.005 * u(rng), 0.01 * u(rng));
      for (Eigen::Vector3d& x : l.points) {
        x += shift + 0.0003 * Eigen::Vector3d(u(rng), u(rng), u(rng));
      }
    }
  }
  motes::DeviceOptions options;
  if (backend == "openmp") {
    options.cpu_threads = 2;
    options.cpu_min_parallel = 1;  // every colour on the team, however small
  }
  auto device = motes::open_device(backend, -1, options);
  ASSERT_TRUE(device) << device.message();
  // The simulation reads the limit when it is made.
  ::setenv("MOTES_CONSTRAINTS_RELAX_LIMIT", limit, 1);
  auto sim = motes::Simulation::create(scene.value(), std::move(device).value());
  ::unsetenv("MOTES_CONSTRAINTS_RELAX_LIMIT");
  ASSERT_TRUE(sim) << sim.message();
  motes::Simulation& s = *sim.value();
  ASSERT_NO_FATAL_FAILURE(motes_test::step_and_hash(s, steps, timed, out.hash));
  const motes::KernelTimes times = s.device().kernel_times();
  out.relax_launches = times.launches[static_cast<std::size_t>(motes::Kernel::ConstraintsRelax)];
  out.solve_launches = times.launches[static_cast<std::size_t>(motes::Kernel::ConstraintsSolve)];
}

class ConstraintsOneLaunch : public ::testing::TestWithParam<std::string> {};

TEST_P(ConstraintsOneLaunch, SameStateAsALaunchPerColour) {
  const std::string backend = GetParam();
  std::string why;
  if (!motes_test::has_device(backend, why)) GTEST_SKIP() << "no " << backend << " device: " << why;
  // mixed.json: a cloth and a rope pinned, a soft cube and dice, dt = 10 us, 8 sweeps;
  // pendulum.json: ropes attached to rigid bodies (60 steps of each; the sanitizer build: 20);
  // position_mixed.json: mixed.json's position version, frames of 1/60 s in 20 substeps of 4
  // sweeps (2 frames).
  const std::uint64_t force_steps = motes_test::sanitized_or<std::uint64_t>(60, 20);
  for (const auto& [name, steps] :
       {std::pair<std::string, std::uint64_t>{"mixed.json", force_steps},
        {"pendulum.json", force_steps},
        {"position_mixed.json", 2}}) {
    SCOPED_TRACE(name);
    RelaxRun one;
    RelaxRun per_colour;
    ASSERT_NO_FATAL_FAILURE(run_scene(backend, name, steps, kAll, false, one));
    ASSERT_NO_FATAL_FAILURE(run_scene(backend, name, steps, "0", false, per_colour));
    EXPECT_EQ(one.hash, per_colour.hash) << "the two ways of relaxing differ";
    // The launches each way makes (timing on: CUDA launches one by one then; the same bits).
    RelaxRun one_timed;
    RelaxRun per_colour_timed;
    ASSERT_NO_FATAL_FAILURE(run_scene(backend, name, 1, kAll, true, one_timed));
    ASSERT_NO_FATAL_FAILURE(run_scene(backend, name, 1, "0", true, per_colour_timed));
    EXPECT_GT(one_timed.relax_launches, 0u);
    EXPECT_EQ(one_timed.solve_launches, 0u);
    EXPECT_EQ(per_colour_timed.relax_launches, 0u);
    EXPECT_GT(per_colour_timed.solve_launches, one_timed.relax_launches);
  }
}

// Seeded variations of mixed.json (its cloth and rope moved and their points jittered): the two
// ways still give the same state, every position finite.
TEST_P(ConstraintsOneLaunch, SameStateInSeededVariations) {
  const std::string backend = GetParam();
  std::string why;
  if (!motes_test::has_device(backend, why)) GTEST_SKIP() << "no " << backend << " device: " << why;
  const std::uint64_t steps = motes_test::sanitized_or<std::uint64_t>(30, 10);
  std::vector<std::uint64_t> hashes;
  for (std::uint32_t seed = 1; seed <= 3; ++seed) {
    SCOPED_TRACE(seed);
    RelaxRun one;
    RelaxRun per_colour;
    ASSERT_NO_FATAL_FAILURE(run_scene(backend, "mixed.json", steps, kAll, false, one, seed));
    ASSERT_NO_FATAL_FAILURE(run_scene(backend, "mixed.json", steps, "0", false, per_colour, seed));
    EXPECT_EQ(one.hash, per_colour.hash) << "the two ways of relaxing differ";
    hashes.push_back(one.hash);
  }
  EXPECT_NE(hashes[0], hashes[1]) << "the variations did not vary the run";
  EXPECT_NE(hashes[1], hashes[2]) << "the variations did not vary the run";
}

// A limit that is not a whole number is refused when the simulation is made, naming the variable.
TEST(ConstraintsOneLaunchLimit, NotANumberIsRefused) {
  auto scene = motes::load_scene_file(motes_test::example_path("rope.json"));
  ASSERT_TRUE(scene) << scene.message();
  for (const char* bad : {"many", "-1", "12k", " 5", "99999999999999999999999"}) {
    SCOPED_TRACE(bad);
    auto device = motes::open_device("openmp");
    ASSERT_TRUE(device) << device.message();
    ::setenv("MOTES_CONSTRAINTS_RELAX_LIMIT", bad, 1);
    auto sim = motes::Simulation::create(scene.value(), std::move(device).value());
    ::unsetenv("MOTES_CONSTRAINTS_RELAX_LIMIT");
    ASSERT_FALSE(sim);
    EXPECT_NE(sim.message().find("MOTES_CONSTRAINTS_RELAX_LIMIT"), std::string::npos)
        << sim.message();
    EXPECT_NE(sim.message().find(bad), std::string::npos) << sim.message();
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, ConstraintsOneLaunch,
                         ::testing::Values("openmp", "vulkan", "cuda"),
                         [](const auto& param) { return param.param; });

}  // namespace
