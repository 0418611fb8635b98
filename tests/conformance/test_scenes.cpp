// Whole scenes (examples/scenes/*.json) on every device: short windows compared with the oracle
// and with the openmp device, run-to-run determinism, and a long chaotic run compared by its
// statistics only.
//
// Short windows. Each starts from a state with contacts, computed once on openmp and written
// into every device, so that all start bitwise equal: dominoes 0.2 s in (the chain has started
// to fall; ~110 of 600 particles touch the floor or a neighbour); dice and bunny right after
// their first touch (the free fall skipped by fast_forward, then 300 steps: 4 and 2 particles
// touch; richer states of these two cost thousands of steps on a CPU); and W1 "settle" (free
// spheres: the lean path, no body state) at 16 x 8 x 16 = 2,048 spheres with the lattice pressed
// to 0.99 d, so that every sphere starts touching its lattice neighbours, the floor or a wall
// (up to six contacts, summed in list order on a device and in double by the oracle).
// After 1 step and after 50 steps the largest particle position and velocity differences must be
// within:
//
//   |dx| <= 1e-6 m and |dv| <= 1e-5 m/s after 1 step, |dx| <= 2e-5 m and |dv| <= 5e-4 m/s after 50.
//
// Why: the oracle and openmp agree bitwise on these scenes (their particles have at most two
// foreign contacts, so the summation order cannot matter). Another device differs through its
// arithmetic only. Measured with the oracle built with fused multiply-adds (-mfma
// -ffp-contract=fast, as GPUs contract) and, on top, sin and cos off by an absolute 2^-21 (the
// accuracy of NVIDIA's hardware sin/cos; quat_integrate takes sin of angles ~1e-4, so this is
// the largest term): |dx| <= 1.8e-7 m, |dv| <= 6.8e-7 m/s after 1 step, |dx| <= 2.1e-6 m and
// |dv| <= 3.6e-5 m/s after 50. The bounds leave 5x to 15x room. A real fault shows far above:
// gravity alone changes v by g dt = 3e-4 m/s in one step and 1.5e-2 m/s in 50; a lost contact
// changes it by k d dt / m ~ 3e-4 m/s per step; a race between kernels or a stale buffer by
// much more.
//
// Cloth and ropes (cloth.json: a cloth on two static bunnies; rope.json: a slack rope bridge under
// three falling boxes, and a swinging rope), right after their first contacts. Their positions
// meet the bounds above. Their velocities are Verlet's (x - x_prev) / dt, so a position that
// rounds one way on one backend and the other way on another (half an ulp of the coordinate, an
// FMA's doing) changes the velocity by ulp / dt: 1.5e-3 m/s for a coordinate of 0.2 m at dt = 1e-5
// s, 150 times the rigid bound. Their velocities are therefore bounded in those units: 4 ulp / dt
// after 1 step, 32 after 50. Measured on an H100 (CUDA and Vulkan, windows with contacts): at most
// 0.13 ulp / dt after 1 step and 3.2 after 50 (rope.json), positions within 1.8e-8 m after 1 step
// (cloth.json).
//
// Soft bodies (soft.json: three soft cubes landing on the floor and on each other) right after the
// lowest one's first contact: their particles are moved by the shape-matching pull, a projection
// as well, so their velocities take the cloth's bound.
//
// Impulse dominoes (impulse_dominoes.json) 0.2 s in, against openmp only: the oracle's whole
// step has no impulse stage (the impulses/* cases check the kernels against their oracle). After
// 1 step and after 10 (not 50), within the rigid bounds of 1 and of 50 steps. The impulse solver
// makes discrete decisions (a contact within reach or not counts for mass splitting; a parting
// contact drops its warm start), so a difference of rounding that tips one parts the two
// trajectories by a contact's share of an impulse, and the warm start, kept from list build to
// list build, carries it on. Measured on openmp alone, the start velocities of half the particles
// and bodies moved by one ulp: at most 1.3e-7 m/s apart through step 10, then 1e-5 to 2e-4 after
// the first such decision (steps 12 to 20) and 1e-4 to 2.5e-3 by step 50, whatever the split of
// sweeps; against openmp after 1, 10 and 50 steps: lavapipe 1.2e-6, 1.0e-4 and 2.3e-3 m/s, CUDA
// on an H200 2.0e-7 and 8.9e-5 after 1 and 10. Beyond 10 steps the comparison would measure the
// scene's chaos, not the backend.
//
// Every kind at once (mixed.json: a rigid die and a soft cube landing in a cloth hammock, a rope
// across it) right after the first touch: the soft, cloth and rope particles take the cloth's
// velocity bound.
//
// A cloth made from a mesh (tablecloth.json: a disc landing on a static cylinder) right after the
// first touch: its particles take the cloth's bounds; its never-touch pairs come from
// LinkExclusions.
//
// Rope pendulums with rigid bobs (pendulum.json) 0.1 s into the swing: the attachments (links to
// the bobs' particles, the bobs taking their pull); no contacts. A bob takes a projection's
// displacement / dt as an impulse, so its velocity is as sensitive to a coordinate rounded the
// other way as a rope particle's (divided by its 27 particles): every velocity takes the cloth's
// bound (measured on the H100, Vulkan: 1.5e-5 m/s after 1 step, 5.1e-4 after 50, where the
// rigid bounds are 1e-5 and 5e-4; the cloth's, 4 and 32 ulp(0.45 m) / dt, are 0.012 and 0.095 m/s).
//
// Determinism: the dice window run twice on one device gives the same Simulation::state_hash().
//
// Chaos: dominoes for 1 s (33,333 steps, a wave in the middle of the chain; 6 s on openmp) is
// compared with openmp by statistics only: the number of fallen dominoes (tilt of the long axis
// > 45 degrees) within 1, the mean centre height within 1 mm. Openmp itself, with the first
// domino's angular momentum perturbed by 1e-7 to 1e-2 relative, gives 22 or 23 fallen (23
// unperturbed) and mean heights within 0.44 mm; one domino more or less fallen moves the mean
// by 0.38 mm. A wrong friction or damping law changes the wave's speed by several dominoes.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "conformance.h"
#include "motes/workloads.h"
#include "scene_support.h"
#include "shared/quaternion.h"

namespace motes_conf {
namespace {

constexpr double kStep1Position = 1e-6;  // m
constexpr double kStep1Velocity = 1e-5;  // m/s
constexpr double kStep50Position = 2e-5;
constexpr double kStep50Velocity = 5e-4;
constexpr double kStep1LinkedUlps = 4.0;  // ulp(largest coordinate) / dt
constexpr double kStep50LinkedUlps = 32.0;

/// A scene ready for the short window: the (possibly fast-forwarded) scene and its state when
/// the window starts, computed on openmp.
struct Window {
  motes::Scene scene;
  DynamicState start;
};

/// How each example scene reaches a state with contacts.
struct WindowRecipe {
  double fast_forward = 0.0;  // s of free fall skipped
  double warm = 0.0;          // s then simulated on openmp
};

const std::map<std::string, WindowRecipe>& recipes() {
  // First contacts on openmp: dice at 0.0554 s, bunny at 0.0785 s.
  static const std::map<std::string, WindowRecipe> r = {
      {"dominoes.json", {0.0, 0.2}},
      {"impulse_dominoes.json", {0.0, 0.2}},
      {"dice.json", {0.055, 300 * 1.5e-5}},
      {"bunny.json", {0.078, 300 * 1.4e-5}},
      {"settle_pressed", {0.0, 0.0}},
      // The cloth reaches the bunnies at about 0.22 s. The boxes reach the bridge after about
      // 0.16 s and bounce once; at 0.18 s they lie on it (the pinned ropes are not fast-forwarded:
      // they start from rest when the window's warm-up starts).
      {"cloth.json", {0.21, 0.02}},
      {"rope.json", {0.14, 0.04}},
      // The lowest soft cube reaches the floor after about 0.045 s.
      {"soft.json", {0.04, 0.01}},
      // The die and the soft cube reach the hammock after about 0.17 s (the pinned cloth and
      // rope start from rest when the warm-up starts).
      {"mixed.json", {0.16, 0.04}},
      // The tablecloth (a cloth from a mesh) reaches the table after about 0.13 s.
      {"tablecloth.json", {0.12, 0.03}},
      // Swinging: the bobs pull on their ropes and the ropes on the bobs from the start.
      {"pendulum.json", {0.0, 0.1}},
  };
  return r;
}

/// W1 at 16 x 8 x 16 with every position scaled by 0.9: lattice spacing 0.99 d, the bottom layer
/// 0.1 mm into the floor, so that contacts start at once.
motes::Scene settle_pressed() {
  motes::Scene scene = motes::settle_workload(16, 8, 16);
  for (motes::BodySpec& b : scene.bodies) b.position *= 0.9;
  return scene;
}

/// The window of a scene, computed once per process.
const motes::Result<Window>& window(const std::string& name) {
  static std::map<std::string, motes::Result<Window>> cache;
  auto it = cache.find(name);
  if (it != cache.end()) return it->second;
  auto make = [&]() -> motes::Result<Window> {
    const motes::Result<motes::Scene>& loaded = name == "settle_pressed"
                                                    ? motes::Result<motes::Scene>(settle_pressed())
                                                    : example_scene(name);
    if (!loaded) return loaded.status();
    const WindowRecipe recipe = recipes().at(name);
    if (recipe.fast_forward > 0.0) {
      for (const motes::BodySpec& b : loaded.value().bodies) {
        if (!b.angular_velocity.isZero()) return motes::Status::error("fast_forward: a body turns");
      }
    }
    Window w{fast_forward(loaded.value(), recipe.fast_forward), {}};
    auto sim = simulate(w.scene, "openmp", 0);
    if (!sim) return sim.status();
    const auto steps = static_cast<std::uint64_t>(std::lround(recipe.warm / w.scene.settings.dt));
    motes::Status s = sim.value()->step(steps);
    if (s) s = read_state(*sim.value(), w.start);
    if (!s) return s;
    return w;
  };
  return cache.emplace(name, make()).first->second;
}

class Scenes : public DeviceTest {
 protected:
  [[nodiscard]] bool wants_device() const override { return false; }
  [[nodiscard]] bool is_openmp() const { return GetParam().backend == "openmp"; }

  /// A simulation of the window's scene on this test's device, at the window's start.
  void start(const Window& w, const std::string& backend, int index,
             std::unique_ptr<motes::Simulation>& out) {
    auto sim = simulate(w.scene, backend, index);
    ASSERT_TRUE(sim) << backend << ": " << sim.message();
    out = std::move(sim).value();
    const motes::Status s = write_state(*out, w.start);
    ASSERT_TRUE(s) << s.message();
  }

  /// Checks the largest position and velocity differences of one comparison; the velocities of
  /// the cloth and rope particles [linked, N) against their own bound.
  void compare(const std::string& name, std::size_t n, const DynamicState& got,
               const std::vector<vec4>& pos, const std::vector<vec4>& vel, double pos_bound,
               double vel_bound, std::size_t linked, double linked_vel_bound) {
    begin_case(name, n);
    check_at_most("ParticlePos", "max dx (m)", max_distance(got.particle_pos, pos), pos_bound);
    const std::size_t split = std::min({linked, got.particle_vel.size(), vel.size()});
    check_at_most("ParticleVel", "max dv (m/s)",
                  max_distance(slice(got.particle_vel, 0, split), slice(vel, 0, split)), vel_bound);
    if (split < got.particle_vel.size()) {
      check_at_most("ParticleVel (cloth, ropes)", "max dv (m/s)",
                    max_distance(slice(got.particle_vel, split, got.particle_vel.size()),
                                 slice(vel, split, vel.size())),
                    linked_vel_bound);
    }
    end_case();
  }

  /// The velocity bound of cloth and rope particles after `steps` steps: `ulps` units in the last
  /// place of the largest coordinate, divided by dt (see the file comment).
  static double linked_velocity_bound(const std::vector<vec4>& pos, double dt, double ulps) {
    return ulps * coordinate_ulp(pos) / dt;
  }

  /// `contacts`: the window must have contacts (pendulum.json has none: it tests the ropes'
  /// attachments to their bobs).
  /// `last`: the second comparison's step (50; fewer where the scene's own chaos would decide).
  void run_window(const std::string& name, bool contacts = true, std::uint64_t last = 50) {
    const motes::Result<Window>& w = window(name);
    ASSERT_TRUE(w) << name << ": " << w.message();
    std::unique_ptr<motes::Simulation> sim;
    std::unique_ptr<motes::Simulation> reference;
    ASSERT_NO_FATAL_FAILURE(start(w.value(), GetParam().backend, GetParam().index, sim));
    if (!is_openmp()) {
      ASSERT_NO_FATAL_FAILURE(start(w.value(), "openmp", 0, reference));
    }
    OracleRun oracle;
    const motes::Status captured = capture(*sim, oracle);
    ASSERT_TRUE(captured) << captured.message();
    const std::size_t n = sim->particle_count();
    const std::string stem = fmt::format("scene/{}", name.substr(0, name.find('.')));
    const bool impulses = w.value().scene.settings.contact_model == motes::ContactModel::Impulses;

    std::uint64_t done = 0;
    for (const std::uint64_t steps : {std::uint64_t{1}, last}) {
      ASSERT_TRUE(sim->step(steps - done));
      oracle.step(steps - done);
      if (reference) {
        ASSERT_TRUE(reference->step(steps - done));
      }
      done = steps;
      DynamicState got;
      ASSERT_TRUE(read_state(*sim, got));
      std::vector<vec4> force(n);
      ASSERT_TRUE(sim->device().read(motes::Buffer::ParticleForce, force.data(), n * sizeof(vec4)));
      std::size_t touching = 0;
      for (const vec4& f : force) touching += f.x != 0.0f || f.y != 0.0f || f.z != 0.0f ? 1 : 0;
      const double pos_bound = steps == 1 ? kStep1Position : kStep50Position;
      const double vel_bound = steps == 1 ? kStep1Velocity : kStep50Velocity;
      const std::string when = fmt::format("{} {} {}", stem, steps, steps == 1 ? "step" : "steps");
      // The window must have contacts, or it would only test free flight.
      std::printf("[scenes] %s: %zu of %zu particles touch something\n", when.c_str(), touching, n);
      if (contacts) {
        EXPECT_GE(touching, 1u) << when << ": no contact at all";
      }
      // Soft bodies' particles [soft_first, linked_first) are moved by projections too; with
      // attachments (Sizes::absorb) so are the attached bodies' particles, and every body takes
      // their displacement / dt as an impulse: every velocity takes the projections' bound.
      const std::size_t linked = sim->sizes().absorb != 0 ? 0 : sim->step_params().soft_first;
      const double linked_vel_bound =
          linked_velocity_bound(got.particle_pos, sim->settings().dt / sim->settings().substeps,
                                steps == 1 ? kStep1LinkedUlps : kStep50LinkedUlps);
      if (impulses) {
        record(
            {label(), when + " vs oracle", std::to_string(n), "-", 0.0, 0.0,
             "skip: the oracle's whole step has no impulse stage (impulses/* check its kernels)"});
      } else {
        compare(when + " vs oracle", n, got, oracle.particles.pos, oracle.particles.vel, pos_bound,
                vel_bound, linked, linked_vel_bound);
      }
      if (reference) {
        DynamicState want;
        ASSERT_TRUE(read_state(*reference, want));
        compare(when + " vs openmp", n, got, want.particle_pos, want.particle_vel, pos_bound,
                vel_bound, linked, linked_vel_bound);
      } else {
        record({label(), when + " vs openmp", std::to_string(n), "-", 0.0, 0.0,
                "skip: this is the openmp device"});
      }
    }
    ASSERT_TRUE(sim->check_finite());
    ASSERT_NO_FATAL_FAILURE(expect_clean(sim->device()));
  }

  /// The window of `name` run twice for `steps` steps on this device: the same state_hash.
  void same_hash(const std::string& name, std::uint64_t steps) {
    const motes::Result<Window>& w = window(name);
    ASSERT_TRUE(w) << w.message();
    std::uint64_t hash[2] = {0, 0};
    std::size_t n = 0;
    for (std::uint64_t& h : hash) {
      std::unique_ptr<motes::Simulation> sim;
      ASSERT_NO_FATAL_FAILURE(start(w.value(), GetParam().backend, GetParam().index, sim));
      ASSERT_TRUE(sim->step(steps));
      ASSERT_TRUE(sim->check_finite());
      auto got = sim->state_hash();
      ASSERT_TRUE(got) << got.message();
      h = got.value();
      n = sim->particle_count();
      ASSERT_NO_FATAL_FAILURE(expect_clean(sim->device()));
    }
    begin_case(fmt::format("scene/{} {} steps, run twice: same hash",
                           name.substr(0, name.find('.')), steps),
               n);
    check_identical("state_hash", std::vector<std::uint64_t>{hash[0]},
                    std::vector<std::uint64_t>{hash[1]});
    end_case();
  }
};

TEST_P(Scenes, DominoesWindow) { run_window("dominoes.json"); }
TEST_P(Scenes, ImpulseDominoesWindow) { run_window("impulse_dominoes.json", true, 10); }
TEST_P(Scenes, DiceWindow) { run_window("dice.json"); }
TEST_P(Scenes, BunnyWindow) { run_window("bunny.json"); }
TEST_P(Scenes, SettleWindow) { run_window("settle_pressed"); }
TEST_P(Scenes, ClothWindow) { run_window("cloth.json"); }
TEST_P(Scenes, RopeWindow) { run_window("rope.json"); }
TEST_P(Scenes, SoftWindow) { run_window("soft.json"); }
TEST_P(Scenes, MixedWindow) { run_window("mixed.json"); }
TEST_P(Scenes, PendulumWindow) { run_window("pendulum.json", false); }
TEST_P(Scenes, TableclothWindow) { run_window("tablecloth.json"); }

TEST_P(Scenes, SameHashRunToRun) { same_hash("dice.json", 400); }
TEST_P(Scenes, ImpulseSameHashRunToRun) { same_hash("impulse_dominoes.json", 100); }

/// Statistics of the domino chain: fallen dominoes and mean centre height.
struct ChainStats {
  int fallen = 0;
  double mean_height = 0.0;
  double lowest = 0.0;
};

void chain_run(const std::string& backend, int index, double seconds, ChainStats& out) {
  const motes::Result<motes::Scene>& scene = example_scene("dominoes.json");
  ASSERT_TRUE(scene) << scene.message();
  auto created = simulate(scene.value(), backend, index);
  ASSERT_TRUE(created) << backend << ": " << created.message();
  motes::Simulation& sim = *created.value();
  std::vector<vec4> inv_inertia(sim.body_count());
  ASSERT_TRUE(sim.device().read(motes::Buffer::BodyInvInertia, inv_inertia.data(),
                                inv_inertia.size() * sizeof(vec4)));
  ASSERT_TRUE(sim.step(static_cast<std::uint64_t>(std::lround(seconds / sim.settings().dt))));
  ASSERT_TRUE(sim.check_finite());
  auto snap = sim.snapshot();
  ASSERT_TRUE(snap) << snap.message();
  out.lowest = HUGE_VAL;
  for (std::size_t b = 0; b < inv_inertia.size(); ++b) {
    // The long axis has the smallest moment, i.e. the largest inverse moment.
    const vec4 inv = inv_inertia[b];
    const int axis = inv.x >= inv.y && inv.x >= inv.z ? 0 : (inv.y >= inv.z ? 1 : 2);
    const vec3 e(axis == 0 ? 1.0f : 0.0f, axis == 1 ? 1.0f : 0.0f, axis == 2 ? 1.0f : 0.0f);
    const vec3 world = motes::shared::quat_rotate(snap->body_quat[b], e);
    // The axis is a direction either way: tilt from the vertical in [0, 90] degrees.
    out.fallen += std::fabs(world.y) < std::cos(45.0f * 3.14159265f / 180.0f) ? 1 : 0;
    const double y = static_cast<double>(snap->body_pos[b].y);
    out.mean_height += y / static_cast<double>(inv_inertia.size());
    out.lowest = std::min(out.lowest, y);
  }
  ASSERT_NO_FATAL_FAILURE(expect_clean(sim.device()));
}

TEST_P(Scenes, DominoChainStatistics) {
  constexpr double kSeconds = 1.0;
  ChainStats got;
  ASSERT_NO_FATAL_FAILURE(chain_run(GetParam().backend, GetParam().index, kSeconds, got));
  std::printf("[scenes] dominoes after %.1f s on %s: %d fallen, mean height %.5f m\n", kSeconds,
              label().c_str(), got.fallen, got.mean_height);
  begin_case(fmt::format("scene/dominoes 1 s: {} fallen, mean height {:.2f} mm", got.fallen,
                         1e3 * got.mean_height),
             600);
  // The wave has started and not finished at 1 s; no domino sinks into the floor.
  check_that("more than 10 dominoes fallen", got.fallen > 10);
  check_that("more than 5 dominoes standing", got.fallen < 35);
  // A domino lying flat has its centre 5 mm up (less a fraction of a mm of overlap).
  check_that("no domino centre below 4 mm", got.lowest > 0.004);
  end_case();
  if (is_openmp()) {
    record({label(), "scene/dominoes 1 s vs openmp", "600", "-", 0.0, 0.0,
            "skip: this is the openmp device"});
    return;
  }
  ChainStats want;
  ASSERT_NO_FATAL_FAILURE(chain_run("openmp", 0, kSeconds, want));
  begin_case("scene/dominoes 1 s vs openmp", 600);
  check_at_most("fallen count", "fallen diff", std::abs(got.fallen - want.fallen), 1.0);
  check_at_most("mean height", "mean height diff (m)",
                std::fabs(got.mean_height - want.mean_height), 1e-3);
  end_case();
}

INSTANTIATE_TEST_SUITE_P(Conformance, Scenes, testing::ValuesIn(device_params()), param_name);

}  // namespace
}  // namespace motes_conf
