// VALIDATION.md section 6: a settled stack stays put.
//
// Five 4 x 4 x 4-particle boxes (0.2 m cubes, M = 8 kg) stacked on an analytic floor, each
// dropped from a gap of a hundredth of a particle diameter, with the normal spring-dashpot, the
// viscous tangential force and a Coulomb cap mu = 0.5 (settings.clamp_attraction off).
// Parameters: k = 2e4 N/m; dt = 1.1e-4 s is t_c / 50 of an undamped particle pair (the
// production default); gamma_n = gamma_t = 1500 1/s, i.e. zeta = 1.3 for a particle pair but
// only sqrt(16 m* / M) times that, 0.47, for a box on its 16 contacts (the dashpot scales with
// particle masses): with gamma_n = 640 the column still rings after a second.
//
// Closed form of the rest state: the 16 contacts under box i carry (5 - i) M g, each with
// overlap (5 - i) M g / (16 k) (1.2 mm at the floor), so box i rests at
//   y_i = (i + 1/2) a - sum_{j <= i} (5 - j) M g / (16 k).
// After 0.5 s of settling, over the next 1 s no particle moves more than 1% of the box size a,
// and at the end every box is within 1e-3 d of y_i and has not turned (1e-4 rad). The step after
// which the kinetic energy stays below 1e-6 of M_total g h is the same in a second run, and so
// is the state hash there. (The kinetic energy does not reach 0: float positions near y = 1 m
// cannot move by less than half an ulp, 3e-8 m, so a resting box keeps a velocity of up to
// ulp / (2 dt) = 2.7e-4 m/s that the dashpot balances; about 6e-7 J for the stack.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "physics/physics_scenes.h"

namespace {

using motes_test::to_quat;
using motes_test::to_vec3;

constexpr double kStackDiameter = 0.05;
constexpr int kPerSide = 4;
constexpr double kSize = kPerSide * kStackDiameter;
constexpr int kBoxes = 5;
constexpr double kDt = 1.1e-4;
constexpr double kSettle = 0.5;
constexpr double kObserve = 1.0;
constexpr double kDensity = 1000.0;
constexpr double kStiffness = 2.0e4;
constexpr double kGravity = 9.81;

motes::Scene stack_scene() {
  const motes::Material mat = motes_test::material(kDensity, kStiffness, 1500.0, 1500.0, 0.5);
  motes::Scene scene = motes_test::scene_with(kDt, Eigen::Vector3d(0.0, -kGravity, 0.0), mat);
  scene.planes.push_back(motes_test::plane(Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero()));
  auto box = motes_test::lattice(kPerSide, kPerSide, kPerSide, kStackDiameter);
  const double gap = 0.01 * kStackDiameter;
  for (int i = 0; i < kBoxes; ++i) {
    const double y = 0.5 * kSize + gap + i * (kSize + gap);
    scene.bodies.push_back(motes_test::body(box, Eigen::Vector3d(0.0, y, 0.0)));
  }
  return scene;
}

struct StackRun {
  std::uint64_t settled_step = 0;  // first step after which KE stays under the threshold
  std::uint64_t settled_hash = 0;  // state hash at the end of the settling phase
  motes::Snapshot initial;
  motes::Snapshot settled;
  motes::Snapshot last;
  double final_ke = 0.0;
  double max_move = 0.0;  // largest particle displacement during the observation (m)
};

void run_stack(bool observe, StackRun& out) {
  auto created = motes_test::simulate(stack_scene());
  ASSERT_TRUE(created) << created.message();
  motes::Simulation& sim = *created.value();
  ASSERT_EQ(sim.particle_count(), static_cast<std::uint32_t>(kBoxes * 64));
  const double box_mass = kDensity * kSize * kSize * kSize;
  const double threshold = 1e-6 * kBoxes * box_mass * kGravity * (kBoxes * kSize);
  auto initial = sim.snapshot();
  ASSERT_TRUE(initial) << initial.message();
  out.initial = initial.value();

  const auto settle_steps = static_cast<std::uint64_t>(std::lround(kSettle / kDt));
  std::uint64_t last_above = 0;
  for (std::uint64_t i = 1; i <= settle_steps; ++i) {
    ASSERT_TRUE(sim.step(1));
    auto s = sim.snapshot();
    ASSERT_TRUE(s) << s.message();
    if (motes_test::kinetic_energy(*s) >= threshold) last_above = i;
  }
  out.settled_step = last_above + 1;
  auto hash = sim.state_hash();
  ASSERT_TRUE(hash) << hash.message();
  out.settled_hash = hash.value();
  auto settled = sim.snapshot();
  ASSERT_TRUE(settled) << settled.message();
  out.settled = settled.value();
  if (!observe) return;

  const auto observe_steps = static_cast<std::uint64_t>(std::lround(kObserve / kDt));
  for (std::uint64_t i = 0; i < observe_steps; i += 100) {
    ASSERT_TRUE(sim.step(100));
    auto s = sim.snapshot();
    ASSERT_TRUE(s) << s.message();
    for (std::size_t p = 0; p < s->particle_pos.size(); ++p) {
      const double move =
          (to_vec3(s->particle_pos[p]) - to_vec3(out.settled.particle_pos[p])).norm();
      out.max_move = std::max(out.max_move, move);
    }
  }
  ASSERT_TRUE(sim.check_finite());
  auto last = sim.snapshot();
  ASSERT_TRUE(last) << last.message();
  out.final_ke = motes_test::kinetic_energy(*last);
  out.last = last.value();
  std::printf(
      "[stack] KE under %.2e J after step %llu (%.3f s); KE at the end %.2e J; largest particle "
      "move over %.1f s after settling %.2e m (%.3f%% of the box size)\n",
      threshold, static_cast<unsigned long long>(out.settled_step),
      static_cast<double>(out.settled_step) * kDt, out.final_ke, kObserve, out.max_move,
      100.0 * out.max_move / kSize);
}

TEST(Stack, FiveBoxesSettleAndStayPut) {
  StackRun first;
  ASSERT_NO_FATAL_FAILURE(run_stack(true, first));
  const auto settle_steps = static_cast<std::uint64_t>(std::lround(kSettle / kDt));
  EXPECT_LE(first.settled_step, settle_steps) << "the stack did not settle in " << kSettle << " s";
  EXPECT_LE(first.max_move, 0.01 * kSize);

  // Rest heights against the spring closed form, and no tilt.
  const double box_mass = kDensity * kSize * kSize * kSize;
  double sunk = 0.0;
  double worst_height = 0.0;
  double worst_turn = 0.0;
  for (int i = 0; i < kBoxes; ++i) {
    sunk += (kBoxes - i) * box_mass * kGravity / (16.0 * kStiffness);
    const double want = (i + 0.5) * kSize - sunk;
    const double got = static_cast<double>(first.last.body_pos[i].y);
    worst_height = std::max(worst_height, std::abs(got - want));
    EXPECT_NEAR(got, want, 1e-3 * kStackDiameter) << "box " << i;
    const double turn =
        to_quat(first.initial.body_quat[i]).angularDistance(to_quat(first.last.body_quat[i]));
    worst_turn = std::max(worst_turn, turn);
    EXPECT_LT(turn, 1e-4) << "box " << i << " turned";
  }
  std::printf(
      "[stack] rest heights: largest error %.2e m (%.2e of a diameter); largest turn %.1e "
      "rad\n",
      worst_height, worst_height / kStackDiameter, worst_turn);

  StackRun second;
  ASSERT_NO_FATAL_FAILURE(run_stack(false, second));
  EXPECT_EQ(first.settled_step, second.settled_step);
  EXPECT_EQ(first.settled_hash, second.settled_hash);
}

}  // namespace
