// The CUDA device's sweeps of impulse contacts over the particles its counting pass found within
// reach of a contact (impulses_compute.cu; MOTES_CUDA_IMPULSE_LIST_FROM=0 lists them at every size)
// or over every particle (a limit above the scene's particles, as below one wave by default): the
// same state to the bit, with the step in CUDA graphs and with timing on (calls launched one by
// one), in impulse_dominoes.json and in seeded variations of it (every domino moved, turned and
// set going a little, so that they fall at other times and land across each other). Skipped, and
// saying so, without a CUDA device.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "motes/devices.h"
#include "motes/scene.h"
#include "motes/simulation.h"
#include "unit/test_support.h"

namespace {

/// `steps` steps of impulse_dominoes.json on CUDA with MOTES_CUDA_IMPULSE_LIST_FROM=`from`, timing
/// on when `timed`; a nonzero `seed` moves each dynamic domino by up to 2 mm, turns it by up to 3
/// degrees about a random axis and gives it up to 5 cm/s. The state hash in `hash`.
void run_dominoes(const char* from, bool timed, std::uint32_t seed, std::uint64_t steps,
                  std::uint64_t& hash) {
  auto scene = motes::load_scene_file(motes_test::example_path("impulse_dominoes.json"));
  ASSERT_TRUE(scene) << scene.message();
  if (seed != 0) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (motes::BodySpec& b : scene.value().bodies) {
      if (b.kind != motes::BodyKind::Dynamic) continue;
      b.position += 0.002 * Eigen::Vector3d(u(rng), 0.0, u(rng));
      const Eigen::Vector3d axis = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
      b.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.05 * u(rng), axis)) * b.rotation;
      b.velocity += 0.05 * Eigen::Vector3d(u(rng), 0.0, u(rng));
    }
  }
  // The device reads the variable when it is opened.
  ::setenv("MOTES_CUDA_IMPULSE_LIST_FROM", from, 1);
  auto device = motes::open_device("cuda");
  ::unsetenv("MOTES_CUDA_IMPULSE_LIST_FROM");
  ASSERT_TRUE(device) << device.message();
  auto sim = motes::Simulation::create(scene.value(), std::move(device).value());
  ASSERT_TRUE(sim) << sim.message();
  ASSERT_NO_FATAL_FAILURE(motes_test::step_and_hash(*sim.value(), steps, timed, hash));
}

/// Never listed: more particles than any scene here has.
constexpr const char* kNever = "4294967295";

TEST(ImpulseSweepsListed, SameStateAsEveryParticle) {
  std::string why;
  if (!motes_test::has_device("cuda", why)) GTEST_SKIP() << "no cuda device: " << why;
  // 1,500 steps: the chain falls from about 0.1 s (dt 0.5 ms: 0.75 s of its 2.5 s).
  const std::uint64_t steps = 1500;
  std::vector<std::uint64_t> hashes;
  for (std::uint32_t seed = 0; seed <= 3; ++seed) {
    SCOPED_TRACE(seed);
    std::uint64_t listed = 0, every = 0, listed_timed = 0;
    ASSERT_NO_FATAL_FAILURE(run_dominoes("0", false, seed, steps, listed));
    ASSERT_NO_FATAL_FAILURE(run_dominoes(kNever, false, seed, steps, every));
    ASSERT_NO_FATAL_FAILURE(run_dominoes("0", true, seed, steps, listed_timed));
    EXPECT_EQ(listed, every) << "the sweeps over the listed particles change the state";
    EXPECT_EQ(listed_timed, every) << "launched one by one, the listed sweeps change the state";
    hashes.push_back(listed);
  }
  for (std::size_t k = 1; k < hashes.size(); ++k) {
    EXPECT_NE(hashes[k], hashes[k - 1]) << "the variations did not vary the run";
  }
}

// A value that is not a whole number is refused when the device is opened, naming the variable.
TEST(ImpulseSweepsListed, NotANumberIsRefused) {
  std::string why;
  if (!motes_test::has_device("cuda", why)) GTEST_SKIP() << "no cuda device: " << why;
  for (const char* bad : {"many", "-1", "12k", " 5", "99999999999999999999999"}) {
    SCOPED_TRACE(bad);
    ::setenv("MOTES_CUDA_IMPULSE_LIST_FROM", bad, 1);
    auto device = motes::open_device("cuda");
    ::unsetenv("MOTES_CUDA_IMPULSE_LIST_FROM");
    ASSERT_FALSE(device);
    EXPECT_NE(device.message().find("MOTES_CUDA_IMPULSE_LIST_FROM"), std::string::npos)
        << device.message();
    EXPECT_NE(device.message().find(bad), std::string::npos) << device.message();
  }
}

}  // namespace
