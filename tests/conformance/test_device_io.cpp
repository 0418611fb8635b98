// Device::write_at on every backend (docs/fluids.md, "Emitters"): a write into the middle of a
// buffer changes exactly its bytes, on the backends' own copies and on the default's read, patch
// and write (BodyFirst on Vulkan and CUDA); a range past the end is refused and changes nothing.
// Then an emitter on the device: its particles leave at its schedule, and the ones waiting stay
// exactly where they were parked.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "conformance/conformance.h"
#include "conformance/scene_support.h"
#include "motes/devices.h"
#include "motes/scene.h"
#include "motes/simulation.h"

namespace motes_conf {
namespace {

class DeviceIo : public DeviceTest {};

motes::Sizes small_sizes() {
  motes::Sizes s;
  s.particles = 40;
  s.rigid_particles = 8;
  s.bodies = 2;
  s.table = motes::grid_table_size(s.particles);
  s.materials = 1;
  s.planes = 1;
  s.neighbour_capacity = 4;
  return s;
}

TEST_P(DeviceIo, WriteAtChangesOnlyItsRange) {
  const motes::Sizes sizes = small_sizes();
  allocate(sizes);
  std::vector<motes::shared::vec4> pos(sizes.particles);
  for (std::size_t i = 0; i < pos.size(); ++i) {
    pos[i] = motes::shared::vec4(static_cast<float>(i), 1.0f, 2.0f, 0.005f);
  }
  write(motes::Buffer::ParticlePos, pos);
  const std::vector<motes::shared::vec4> patch(5, motes::shared::vec4(-1.0f, -2.0f, -3.0f, -4.0f));
  ASSERT_TRUE(device().write_at(motes::Buffer::ParticlePos, 10 * sizeof(motes::shared::vec4),
                                patch.data(), patch.size() * sizeof(motes::shared::vec4)));
  for (std::size_t k = 10; k < 15; ++k) pos[k] = patch[0];
  std::vector<motes::shared::vec4> got;
  read(motes::Buffer::ParticlePos, got);
  ASSERT_EQ(got.size(), pos.size());
  for (std::size_t i = 0; i < pos.size(); ++i) {
    EXPECT_EQ(got[i].x, pos[i].x) << i;
    EXPECT_EQ(got[i].w, pos[i].w) << i;
  }
  // BodyFirst (B + 1 words): a patch of one word.
  std::vector<std::uint32_t> first = {0u, 4u, 8u};
  write(motes::Buffer::BodyFirst, first);
  const std::uint32_t five = 5u;
  ASSERT_TRUE(device().write_at(motes::Buffer::BodyFirst, sizeof five, &five, sizeof five));
  std::vector<std::uint32_t> words;
  read(motes::Buffer::BodyFirst, words);
  ASSERT_GE(words.size(), 3u);
  EXPECT_EQ(words[0], 0u);
  EXPECT_EQ(words[1], 5u);
  EXPECT_EQ(words[2], 8u);
  // Past the end: refused, nothing written.
  const motes::Status past =
      device().write_at(motes::Buffer::ParticlePos, (sizes.particles - 2) * sizeof(patch[0]),
                        patch.data(), patch.size() * sizeof(patch[0]));
  EXPECT_FALSE(past);
  read(motes::Buffer::ParticlePos, got);
  EXPECT_EQ(got.back().x, pos.back().x);
}

class EmitterOnDevice : public DeviceTest {
 protected:
  [[nodiscard]] bool wants_device() const override { return false; }
};

TEST_P(EmitterOnDevice, ParticlesLeaveOnScheduleAndTheWaitingOnesStayParked) {
  motes::Result<motes::Scene> scene = motes::load_scene_text(
      R"({"settings": {"contact_model": "position", "dt": 0.016666666666666666},
          "materials": {"water": {"density": 1000}},
          "planes": [{"normal": [0, 1, 0], "point": [0, 0, 0]}],
          "bodies": [{"name": "tap", "kind": "fluid", "material": "water",
                      "fluid": {"type": "emitter", "position": [0, 0.2, 0],
                                "direction": [0, -1, 0], "speed": 0.5, "rate": 1000,
                                "max_particles": 250}}]})",
      "tap.json", ".");
  ASSERT_TRUE(scene) << scene.message();
  auto sim = simulate(scene.value(), GetParam().backend, GetParam().index);
  ASSERT_TRUE(sim) << sim.message();
  const motes::FluidSpec& spec = scene->fluids[0];
  for (int frame = 0; frame < 20; ++frame) {  // 0.33 s: all 250 (12 layers of 21)
    const double t = sim.value()->time();
    ASSERT_TRUE(sim.value()->step(1));
    const std::uint64_t want = motes::emitter_particles_by(*spec.emitter, t);
    ASSERT_EQ(sim.value()->emitters()[0].emitted, want);
    auto s = sim.value()->snapshot();
    ASSERT_TRUE(s) << s.message();
    for (std::size_t k = 0; k < spec.points.size(); ++k) {
      const motes::shared::vec4 x = s->particle_pos[k];
      const motes::shared::vec4 v = s->particle_vel[k];
      ASSERT_TRUE(std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z)) << k;
      if (k < want) {
        EXPECT_GT(v.w, 0.0f) << k;
        EXPECT_GT(x.y, 0.0f) << k;
      } else {
        EXPECT_EQ(v.w, 0.0f) << k;
        EXPECT_EQ(x.x, static_cast<float>(spec.points[k].x())) << k;
        EXPECT_EQ(x.y, static_cast<float>(spec.points[k].y())) << k;
      }
    }
  }
  EXPECT_EQ(sim.value()->emitters()[0].emitted, 250u);
}

INSTANTIATE_TEST_SUITE_P(Conformance, DeviceIo, testing::ValuesIn(device_params()), param_name);
INSTANTIATE_TEST_SUITE_P(Conformance, EmitterOnDevice, testing::ValuesIn(device_params()),
                         param_name);

}  // namespace
}  // namespace motes_conf
