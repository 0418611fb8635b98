// Emitters of liquid (issue 29; docs/fluids.md, "Emitters"; docs/scene-format.md, "Emitters"):
// the nozzle, the schedule, the scene format and its errors, and a run on openmp: particles leave
// at the rate, from the nozzle, at the speed, until the limit or the stop; the ones still waiting
// are hidden from pictures; a checkpoint taken mid-stream resumes bit for bit; the motion guard
// sees no warning and the energy guard keeps its reference through the emission.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "motes/devices.h"
#include "motes/fluid.h"
#include "motes/scene.h"
#include "motes/simulation.h"

namespace motes {
namespace {

std::string emitter_scene(const std::string& emitter, const std::string& settings = "") {
  return R"({"settings": {"contact_model": "position", "dt": 0.016666666666666666,
    "duration": 1.0)" +
         settings + R"(}, "materials": {"water": {"density": 1000}},
    "planes": [{"normal": [0, 1, 0], "point": [0, 0, 0]}],
    "bodies": [{"name": "tap", "kind": "fluid", "material": "water", "fluid": )" +
         emitter + "}]}";
}

const std::string kTap =
    R"({"type": "emitter", "position": [0, 0.2, 0], "direction": [0, -2, 0], "speed": 0.5,
        "rate": 1000, "max_particles": 250})";

TEST(FluidEmitter, NozzleHoldsTheLayerTheRateAndSpeedAsk) {
  // rate d / speed particles a layer: 20 -> the disc of 21 (q = 5), 1 -> 1, 5 -> 5, 9 -> 9.
  const Eigen::Vector3d down(0.0, -1.0, 0.0);
  EXPECT_EQ(emitter_nozzle(down, 1000.0, 0.5, 0.01).size(), 21u);
  EXPECT_EQ(emitter_nozzle(down, 50.0, 0.5, 0.01).size(), 1u);
  EXPECT_EQ(emitter_nozzle(down, 250.0, 0.5, 0.01).size(), 5u);
  EXPECT_EQ(emitter_nozzle(down, 450.0, 0.5, 0.01).size(), 9u);
  // The largest nozzle: about kEmitterNozzleLimit points, found quickly.
  const std::size_t largest = emitter_nozzle(down, 5e6, 0.5, 0.01).size();
  EXPECT_NEAR(static_cast<double>(largest), 1e5, 100.0);
  // Across the direction, d apart, centred on the nozzle.
  const Eigen::Vector3d slant = Eigen::Vector3d(1.0, -1.0, 0.5).normalized();
  const std::vector<Eigen::Vector3d> disc = emitter_nozzle(slant, 1000.0, 0.5, 0.01);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : disc) {
    EXPECT_NEAR(p.dot(slant), 0.0, 1e-15);
    mean += p;
  }
  EXPECT_LT(mean.norm(), 1e-15);
  EXPECT_NEAR((disc[1] - disc[0]).norm(), 0.01, 1e-15);
}

TEST(FluidEmitter, ScheduleIsWholeLayersUntilTheLimitOrTheStop) {
  FluidEmitter e;
  e.nozzle.assign(21, Eigen::Vector3d::Zero());
  e.rate = 1000.0;
  e.layer_period = 0.021;
  e.max_particles = 250;
  e.start = 0.1;
  EXPECT_EQ(emitter_particles_by(e, 0.0), 0u);
  EXPECT_EQ(emitter_particles_by(e, 0.1), 21u);  // the first layer at start
  EXPECT_EQ(emitter_particles_by(e, 0.1 + 0.021), 42u);
  EXPECT_EQ(emitter_particles_by(e, 0.1 + 0.0419), 42u);
  EXPECT_EQ(emitter_particles_by(e, 10.0), 250u);  // the limit cuts the last layer
  e.stop = 0.1 + 0.05;                             // layers at 0.1, 0.121, 0.142
  EXPECT_EQ(emitter_particles_by(e, 10.0), 63u);
}

TEST(FluidEmitter, SceneFormatAndItsErrors) {
  Result<Scene> r = load_scene_text(emitter_scene(kTap), "s.json", ".");
  ASSERT_TRUE(r) << r.message();
  const FluidSpec& f = r->fluids[0];
  ASSERT_TRUE(f.emitter.has_value());
  EXPECT_EQ(f.points.size(), 250u);  // the limit's particles, parked
  EXPECT_TRUE(f.emitter->direction.isApprox(Eigen::Vector3d(0, -1, 0)));
  std::string huge = kTap;
  huge.replace(huge.find("[0, -2, 0]"), 10, "[3e38, -3e38, 0]");
  Result<Scene> far = load_scene_text(emitter_scene(huge), "s.json", ".");
  ASSERT_TRUE(far) << far.message();
  EXPECT_TRUE(far->fluids[0].emitter->direction.isApprox(Eigen::Vector3d(1, -1, 0).normalized()));
  EXPECT_EQ(f.emitter->nozzle.size(), 21u);
  EXPECT_DOUBLE_EQ(f.emitter->layer_period, 0.021);
  for (const Eigen::Vector3d& p : f.points) EXPECT_LT(p.y(), 0.2 - kEmitterParkDepth + 1e-9);
  const std::pair<std::string, std::string> bad[] = {
      {R"({"type": "emitter", "position": [0, 0, 0], "direction": [0, 0, 0], "speed": 1,
           "rate": 10, "max_particles": 5})",
       "/bodies/0/fluid/direction: must not be zero"},
      {R"({"type": "emitter", "position": [0, 0, 0], "direction": [0, 1, 0], "speed": -1,
           "rate": 10, "max_particles": 5})",
       "/bodies/0/fluid/speed"},
      {R"({"type": "emitter", "position": [0, 0, 0], "direction": [0, 1, 0], "speed": 1,
           "rate": 10, "max_particles": 0})",
       "/bodies/0/fluid/max_particles"},
      {R"({"type": "emitter", "position": [0, 0, 0], "direction": [0, 1, 0], "speed": 1,
           "rate": 10})",
       "/bodies/0/fluid: missing required key \"max_particles\""},
      {R"({"type": "emitter", "position": [0, 0, 0], "direction": [0, 1, 0], "speed": 1,
           "rate": 10, "max_particles": 5, "start": 2, "stop": 1})",
       "/bodies/0/fluid/stop: must be later than start"},
      {R"({"type": "emitter", "position": [0, 0, 0], "direction": [0, 1, 0], "speed": 1e-30,
           "rate": 1e30, "max_particles": 5})",
       "/bodies/0/fluid/rate: 1e+30 particles a second at 1e-30 m/s is a nozzle of"},
      {R"({"type": "emitter", "position": [0, 0, 0], "direction": [0, 1, 0], "speed": 1,
           "rate": 10, "max_particles": 5, "min": [0, 0, 0]})",
       "/bodies/0/fluid/min: unknown key \"min\""},
  };
  for (const auto& [fluid, want] : bad) {
    Result<Scene> s = load_scene_text(emitter_scene(fluid), "s.json", ".");
    ASSERT_FALSE(s) << fluid;
    EXPECT_NE(s.message().find(want), std::string::npos) << s.message();
  }
  Result<Scene> limit =
      load_scene_text(emitter_scene(kTap, R"(, "max_particles": 100)"), "s.json", ".");
  ASSERT_FALSE(limit);
  EXPECT_NE(limit.message().find("/bodies/0/fluid/max_particles: 250 particles, more than "
                                 "settings.max_particles (100)"),
            std::string::npos)
      << limit.message();
  std::string moving = emitter_scene(kTap);
  moving.replace(moving.find("\"fluid\": {"), 0, R"("velocity": [1, 0, 0], )");
  Result<Scene> v = load_scene_text(moving, "s.json", ".");
  ASSERT_FALSE(v);
  EXPECT_NE(v.message().find("/bodies/0/velocity: an emitter's particles leave at its"),
            std::string::npos)
      << v.message();
}

std::unique_ptr<Simulation> make(const Scene& scene) {
  auto device = open_device("openmp");
  EXPECT_TRUE(device) << device.message();
  auto sim = Simulation::create(scene, std::move(device).value());
  EXPECT_TRUE(sim) << sim.message();
  return sim ? std::move(sim).value() : nullptr;
}

TEST(FluidEmitter, PoursAtItsRateFromItsNozzleUntilItsLimit) {
  Result<Scene> scene = load_scene_text(emitter_scene(kTap), "s.json", ".");
  ASSERT_TRUE(scene) << scene.message();
  std::unique_ptr<Simulation> sim = make(scene.value());
  ASSERT_TRUE(sim);
  const FluidEmitter& e = *scene->fluids[0].emitter;
  const BodyInfo& tap = sim->bodies()[0];
  for (int frame = 0; frame < 20; ++frame) {
    const double t = sim->time();
    ASSERT_TRUE(sim->step(1));
    Result<MotionReport> guard = sim->check_motion();
    ASSERT_TRUE(guard) << guard.message();
    EXPECT_TRUE(guard->warning.empty()) << guard->warning;
    const std::uint64_t want = emitter_particles_by(e, t);
    EXPECT_EQ(sim->emitters()[0].emitted, want) << "frame " << frame;
    Result<Snapshot> s = sim->snapshot();
    ASSERT_TRUE(s);
    std::uint64_t moving = 0;
    for (std::uint32_t k = 0; k < tap.particle_count; ++k) {
      const shared::vec4 x = s->particle_pos[tap.first_particle + k];
      const shared::vec4 v = s->particle_vel[tap.first_particle + k];
      if (v.w > 0.0f) {
        ++moving;
        EXPECT_GT(x.y, 0.0f);          // in the scene, above the floor
        EXPECT_LT(x.y, 0.2f + 1e-4f);  // never above the nozzle
      } else {
        EXPECT_LT(x.y, 0.2f - 999.0f);  // still parked
      }
    }
    EXPECT_EQ(moving, want);
    // The liquid's body state is the mean of the particles that have left (at the nozzle before).
    const double mean_y = static_cast<double>(s->body_pos[0].y);
    EXPECT_GT(mean_y, 0.0);
    EXPECT_LE(mean_y, 0.2 + 1e-6);
    // The ones still parked are hidden from pictures.
    Snapshot shown = s.value();
    sim->hide_parked(shown);
    for (std::uint32_t k = 0; k < tap.particle_count; ++k) {
      EXPECT_EQ(std::isnan(shown.particle_pos[tap.first_particle + k].x), k >= want);
    }
  }
  EXPECT_EQ(sim->emitters()[0].emitted, 250u);  // 0.33 s: 250 at 1000 a second (12 layers)
  // The first layer fell from the nozzle: at 0.5 m/s, then under gravity, down to the floor.
  Result<Snapshot> s = sim->snapshot();
  ASSERT_TRUE(s);
  EXPECT_LT(s->particle_pos[tap.first_particle].y, 0.05f);
}

TEST(FluidEmitter, CheckpointMidStreamResumesBitForBit) {
  Result<Scene> scene = load_scene_text(emitter_scene(kTap), "s.json", ".");
  ASSERT_TRUE(scene) << scene.message();
  std::unique_ptr<Simulation> whole = make(scene.value());
  std::unique_ptr<Simulation> first = make(scene.value());
  ASSERT_TRUE(whole && first);
  ASSERT_TRUE(whole->step(14));
  ASSERT_TRUE(first->step(7));
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("motes_emitter_" + std::to_string(::getpid()) + ".mck"))
                               .string();
  ASSERT_TRUE(first->save_state(path));
  std::unique_ptr<Simulation> resumed = make(scene.value());
  ASSERT_TRUE(resumed);
  ASSERT_TRUE(resumed->load_state(path)) << "load";
  std::filesystem::remove(path);
  EXPECT_EQ(resumed->emitters()[0].emitted, first->emitters()[0].emitted);
  ASSERT_TRUE(resumed->step(7));
  EXPECT_EQ(resumed->emitters()[0].emitted, whole->emitters()[0].emitted);
  Result<std::uint64_t> a = whole->state_hash();
  Result<std::uint64_t> b = resumed->state_hash();
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a.value(), b.value());
}

}  // namespace
}  // namespace motes
