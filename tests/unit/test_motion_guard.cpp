// The run-time motion guard (Simulation::check_motion, docs/reliability.md "Guards while
// running"), on every backend this machine has: the fastest particle named with its travel per
// substep and the largest safe dt, a tunnelling warning past a quarter diameter per substep, an
// error for speeds nothing in the scene can give and for a NaN; and in `motes run` and
// `motes resume`: the warning printed once per doubling, the guard's line in the summary, a run
// stopped with its frames kept and a non-zero exit.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "motes/checkpoint.h"
#include "motes/devices.h"
#include "motes/scene.h"
#include "motes/simulation.h"
#include "unit/cli_support.h"
#include "unit/test_support.h"

namespace motes {
namespace {

using motes_test::contains;
using motes_test::describe;
using motes_test::run_motes;
using motes_test::TempDir;

/// Balls of 1 cm, 1 m apart (no contact), without gravity unless `gravity`; dt 1e-4 s.
std::string balls(double fast_speed, double gravity = 0.0, double dt = 1e-4) {
  return fmt::format(
      R"({{"settings": {{"dt": {}, "substeps": 1, "particle_diameter": 0.01, "gravity": [0, {}, 0],
          "contact": {{"stiffness": 1000, "damping": 10}}}},
        "bodies": [{{"name": "still", "shape": {{"type": "particle"}}, "position": [0, 0, 0]}},
                   {{"name": "fast", "shape": {{"type": "particle"}}, "position": [1, 0, 0],
                     "velocity": [{}, 0, 0]}}]}})",
      dt, -gravity, fast_speed);
}

std::unique_ptr<Simulation> simulation(const std::string& text, const std::string& backend) {
  return motes_test::simulate_text(text, "balls", "", backend);
}

void names_the_fastest_warns_and_stops(const std::string& backend) {
  SCOPED_TRACE(backend);
  auto sim = simulation(balls(20.0), backend);
  ASSERT_TRUE(sim);
  // 20 m/s, 1 cm, 1e-4 s: 0.2 of a diameter per substep; the safe dt (a quarter) 1.25e-4 s.
  Result<MotionReport> r = sim->check_motion();
  ASSERT_TRUE(r) << r.message();
  EXPECT_TRUE(r->moving);
  EXPECT_EQ(r->body, 1u);
  EXPECT_EQ(r->particle, 1u);
  EXPECT_NEAR(r->speed, 20.0, 20.0 * 1e-6);
  EXPECT_NEAR(r->diameter, 0.01, 0.01 * 1e-6);
  EXPECT_NEAR(r->travel, 0.2, 0.2 * 1e-6);
  EXPECT_NEAR(r->safe_dt, 1.25e-4, 1.25e-4 * 1e-6);
  EXPECT_TRUE(r->warning.empty()) << r->warning;

  // 40 m/s after a kick: 0.4 of a diameter per substep, a warning with the safe dt 6.25e-5 s.
  ASSERT_TRUE(sim->set_body_velocities({{0, 0, 0}, {40, 0, 0}}));
  r = sim->check_motion();
  ASSERT_TRUE(r) << r.message();
  EXPECT_NEAR(r->travel, 0.4, 0.4 * 1e-6);
  EXPECT_TRUE(contains(r->warning,
                       "step 0 (t = 0 s): particle 1 of body 1 'fast' moves 0.4 of "
                       "its diameter (0.01 m) per substep at 40 m/s"))
      << r->warning;
  EXPECT_TRUE(contains(r->warning, "the largest safe dt at this speed is 6.25e-05 s at substeps 1"))
      << r->warning;

  // The start speed (20 m/s) and the contact scale (25 m/s) give 45 m/s: 1000 times more is
  // an error; just under it only a warning.
  ASSERT_TRUE(sim->set_body_velocities({{0, 0, 0}, {44000, 0, 0}}));
  r = sim->check_motion();
  ASSERT_TRUE(r) << r.message();
  EXPECT_FALSE(r->warning.empty());
  ASSERT_TRUE(sim->set_body_velocities({{0, 0, 0}, {46000, 0, 0}}));
  r = sim->check_motion();
  ASSERT_FALSE(r);
  EXPECT_TRUE(contains(r.message(),
                       "speed out of bounds at step 0 (t = 0 s): particle 1 of body 1 "
                       "'fast' moves at 4.6e+04 m/s"))
      << r.message();

  // At rest: nothing moves.
  ASSERT_TRUE(sim->set_body_velocities({{0, 0, 0}, {0, 0, 0}}));
  r = sim->check_motion();
  ASSERT_TRUE(r) << r.message();
  EXPECT_FALSE(r->moving);
}

void non_finite_is_an_error(const std::string& backend) {
  SCOPED_TRACE(backend);
  auto sim = simulation(balls(1.0), backend);
  ASSERT_TRUE(sim);
  ASSERT_TRUE(sim->step(10));
  std::vector<shared::vec4> vel(sim->particle_count());
  ASSERT_TRUE(sim->device().read(Buffer::ParticleVel, vel.data(), vel.size() * sizeof vel[0]));
  vel[1].y = std::numeric_limits<float>::quiet_NaN();
  ASSERT_TRUE(sim->device().write(Buffer::ParticleVel, vel.data(), vel.size() * sizeof vel[0]));
  Result<MotionReport> r = sim->check_motion();
  ASSERT_FALSE(r);
  EXPECT_TRUE(contains(r.message(),
                       "non-finite state at step 10 (t = 0.001 s): particle 1 of "
                       "body 1 'fast': position (1.001"))
      << r.message();
}

TEST(MotionGuard, NamesTheFastestParticleWarnsAndStops) {
  for (const std::string& backend : motes_test::cpu_backends())
    names_the_fastest_warns_and_stops(backend);
}

TEST(MotionGuard, NonFiniteStateIsAnErrorNamingTheParticle) {
  for (const std::string& backend : motes_test::cpu_backends()) non_finite_is_an_error(backend);
}

TEST(MotionGuard, CudaNamesTheFastestAndStopsOnNaN) {
  if (!open_device("cuda")) GTEST_SKIP() << "no CUDA device (the GPU machine runs this)";
  names_the_fastest_warns_and_stops("cuda");
  non_finite_is_an_error("cuda");
}

TEST(MotionGuard, RunWarnsOncePerDoublingAndSummarizes) {
  // A ball falling from rest at dt 1e-3 s: a quarter diameter per substep at 2.5 m/s (t = 0.255 s);
  // the frames (every 0.1 s) check it: warnings at 0.3, 0.4 and 0.5 s (0.294 to 0.49), printed
  // once (no doubling).
  TempDir tmp;
  const std::string scene = tmp / "fall.json";
  std::ofstream(scene) << balls(0.0, 9.81, 1e-3);
  const auto o = run_motes(tmp, {"run", scene, "--duration", "0.5", "--every", "100", "--format",
                                 "none", "--backend", "openmp"});
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  EXPECT_TRUE(contains(o.err,
                       "motes: warning: step 300 (t = 0.3 s): particle 0 of body 0 'still' "
                       "moves 0.294 of its diameter"))
      << describe(o);
  EXPECT_EQ(o.err.find("motes: warning:", o.err.find("motes: warning:") + 1), std::string::npos)
      << describe(o);
  EXPECT_TRUE(contains(o.out,
                       "guards          6 motion checks, 3 with a tunnelling warning "
                       "(the worst: 0.49 of a diameter per substep)"))
      << describe(o);
}

TEST(MotionGuard, RunChecksAtLeastEveryThousandSteps) {
  // Frames at 0, 5000 and 10000; checks also at 1000, 2000, 3000, 4000, 6000, ..., 9000.
  TempDir tmp;
  const std::string scene = tmp / "balls.json";
  std::ofstream(scene) << balls(1.0);
  const auto o = run_motes(tmp, {"run", scene, "--steps", "10000", "--every", "5000", "--format",
                                 "none", "--backend", "openmp"});
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  EXPECT_TRUE(contains(o.out, "guards          11 motion checks, no warning")) << describe(o);
}

TEST(MotionGuard, ResumedNonFiniteStateStopsTheRunKeepingItsFrames) {
  TempDir tmp;
  const std::string scene = tmp / "balls.json";
  std::ofstream(scene) << balls(1.0);
  const auto first =
      run_motes(tmp, {"run", scene, "--steps", "200", "--every", "50", "--checkpoint-every", "100",
                      "--out", tmp / "out", "--backend", "openmp"});
  ASSERT_EQ(first.exit_code, 0) << describe(first);
  const std::string checkpoint = tmp / "out/checkpoints/checkpoint-000000000200.mck";
  Result<CheckpointInfo> info = read_checkpoint_info(checkpoint);
  ASSERT_TRUE(info) << info.message();

  // The same checkpoint with a NaN velocity, as a run that went wrong would leave it.
  auto sim = simulation(balls(1.0), "openmp");
  ASSERT_TRUE(sim);
  ASSERT_TRUE(sim->load_state(checkpoint));
  std::vector<shared::vec4> vel(sim->particle_count());
  ASSERT_TRUE(sim->device().read(Buffer::ParticleVel, vel.data(), vel.size() * sizeof vel[0]));
  vel[0].x = std::numeric_limits<float>::infinity();
  ASSERT_TRUE(sim->device().write(Buffer::ParticleVel, vel.data(), vel.size() * sizeof vel[0]));
  ASSERT_TRUE(sim->save_state(checkpoint, info->run));

  const auto r = run_motes(tmp, {"resume", checkpoint, "--steps", "100"});
  EXPECT_EQ(r.exit_code, 2) << describe(r);
  EXPECT_TRUE(contains(r.err,
                       "non-finite state at step 200 (t = 0.02 s): particle 0 of body 0 "
                       "'still'"))
      << describe(r);
  EXPECT_TRUE(contains(r.err, "motes: run stopped; 5 frames written")) << describe(r);
  EXPECT_TRUE(contains(r.err, "no checkpoint was written")) << describe(r);
  EXPECT_TRUE(contains(motes_test::read_text(tmp / "out/particles.pvd"), "</VTKFile>"))
      << describe(r);
}

}  // namespace
}  // namespace motes
