// Device limits before allocation (docs/reliability.md, "Device limits"): a simulation that needs
// more than the device has, in memory or in one buffer, is refused before anything is allocated,
// with both numbers and the largest particle count that fits; that count, tried, passes the same
// check, and one more does not. Nothing here allocates more than one buffer at the device's limit
// (128 MiB on lavapipe); the memory cases ask for terabytes and are only counted.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <memory>
#include <regex>
#include <string>

#include "conformance/conformance.h"
#include "motes/devices.h"
#include "motes/scene.h"
#include "motes/simulation.h"

namespace motes_conf {
namespace {

class DeviceLimits : public DeviceTest {};

/// The number after `before` and before `after` in a message, or -1.
std::int64_t number_in(const std::string& text, const std::string& pattern) {
  std::smatch m;
  if (!std::regex_search(text, m, std::regex(pattern))) return -1;
  return std::stoll(m[1].str());
}

/// n free spheres of 1 cm in a row with `capacity` list entries per particle: the neighbour list
/// holds n x capacity x 4 bytes.
motes::Scene spheres(std::int64_t n, int capacity) {
  const std::string text = fmt::format(
      R"({{"settings": {{"dt": 5e-5, "particle_diameter": 0.01, "neighbour_capacity": {},
                        "contact": {{"stiffness": 500, "damping": 50}}}},
          "materials": {{"m": {{"density": 700}}}},
          "bodies": [{{"name": "grain", "shape": {{"type": "particle"}}, "material": "m",
                       "repeat": {{"count": {}, "offset": [0.011, 0, 0]}}}}]}})",
      capacity, n);
  motes::Result<motes::Scene> scene = motes::load_scene_text(text, "spheres.json", "");
  EXPECT_TRUE(scene) << scene.message();
  return scene ? std::move(scene).value() : motes::Scene{};
}

// Two billion particles with 1,024 list entries each need about 9 TB: more than any device's
// memory. The message gives both numbers and a largest count that fits the bytes it reports, and
// one particle more does not.
TEST_P(DeviceLimits, MoreMemoryThanTheDeviceHasIsRefusedWithTheLargestCountThatFits) {
  motes::Sizes sizes;
  sizes.particles = (std::uint32_t{1} << 31) - 1;
  sizes.rigid_particles = sizes.particles / 2;
  sizes.bodies = sizes.rigid_particles / 27;
  sizes.table = motes::grid_table_size(sizes.particles);
  sizes.materials = 2;
  sizes.planes = 1;
  sizes.neighbour_capacity = 1024;
  const motes::Status st = motes::check_device_fits(device(), sizes);
  ASSERT_FALSE(st) << "a device with 9 TB?";
  const std::string& msg = st.message();
  EXPECT_NE(msg.find(std::to_string(device().required_bytes(sizes)) + " bytes"), std::string::npos)
      << msg;
  const std::int64_t have = number_in(msg, R"(the device has [0-9.]+ [GM]iB \(([0-9]+) bytes\))");
  const std::int64_t largest = number_in(msg, R"(at most ([0-9]+) particles fit)");
  ASSERT_GT(have, 0) << msg;
  ASSERT_GT(largest, 0) << msg;
  // Against the available bytes the message reports (host memory moves between two reads).
  const auto fits = [&](std::int64_t n) {
    return motes::device_fit(device(), motes::scale_sizes(sizes, static_cast<std::uint32_t>(n)),
                             static_cast<std::uint64_t>(have))
        .fits();
  };
  EXPECT_TRUE(fits(largest)) << msg;
  EXPECT_FALSE(fits(largest + 1)) << msg;
  // The limit on one buffer, where the device has one, is reported too when it is passed.
  const motes::BufferLimit limit = device().buffer_limit();
  if (device().largest_buffer(sizes).bytes > limit.bytes) {
    EXPECT_NE(msg.find(std::to_string(limit.bytes) + " bytes one buffer may hold"),
              std::string::npos)
        << msg;
    EXPECT_NE(msg.find(limit.what), std::string::npos) << msg;
  }
}

// A scene whose neighbour list is larger than one buffer may be is split into column blocks
// (Vulkan: up to four buffers); one whose list would need more is refused by Simulation::create
// with the buffer, its bytes, the limit and the largest count; a scene of that many particles is
// created. Lavapipe: maxStorageBufferRange = 128 MiB, so 131,072 particles with 1,024 entries each
// (four blocks of 256 columns, 128 MiB each).
TEST_P(DeviceLimits, OneBufferOverTheDeviceLimitIsRefusedWithTheLargestCountThatFits) {
  const motes::BufferLimit limit = device().buffer_limit();
  constexpr int kCapacity = 1024;
  // The bytes per particle of the largest buffer: the whole list, or the first of its blocks.
  const bool blocks = GetParam().backend == "vulkan";
  const std::uint64_t per_particle = blocks ? kCapacity : kCapacity * 4;
  if (limit.bytes > (std::uint64_t{256} << 20)) {
    GTEST_SKIP() << "one buffer may hold " << limit.bytes
                 << " bytes here: this case needs a device whose limit is at most 256 MiB "
                    "(lavapipe's is 128 MiB)";
  }
  const std::int64_t n = static_cast<std::int64_t>(limit.bytes / per_particle) * 5 / 4;
  const DeviceParam& p = GetParam();
  const auto open = [&]() {
    auto opened = motes::open_device(p.backend, p.index);
    EXPECT_TRUE(opened) << opened.message();
    return opened ? std::move(opened).value() : nullptr;
  };
  auto refused = motes::Simulation::create(spheres(n, kCapacity), open());
  ASSERT_FALSE(refused) << "created " << n << " particles";
  const std::string& msg = refused.message();
  EXPECT_NE(msg.find("spheres.json: " + std::to_string(n) + " particles do not fit"),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find("buffer NeighbourList would need " + std::to_string(n * per_particle)),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find(std::to_string(limit.bytes) + " bytes one buffer may hold"), std::string::npos)
      << msg;
  EXPECT_NE(msg.find("neighbour_capacity (now 1024)"), std::string::npos) << msg;
  const std::int64_t largest = number_in(msg, R"(at most ([0-9]+) particles fit)");
  // The neighbour list decides: the largest whole number of lists (or of blocks of a quarter of
  // each list) in the limit.
  EXPECT_EQ(largest, static_cast<std::int64_t>(limit.bytes / per_particle)) << msg;

  auto fits = motes::Simulation::create(spheres(largest, kCapacity), open());
  ASSERT_TRUE(fits) << fits.message();
  EXPECT_EQ(fits.value()->particle_count(), static_cast<std::uint32_t>(largest));
  const motes::Status stepped = fits.value()->step(1);
  EXPECT_TRUE(stepped) << stepped.message();
  auto one_more = motes::Simulation::create(spheres(largest + 1, kCapacity), open());
  EXPECT_FALSE(one_more);
}

INSTANTIATE_TEST_SUITE_P(Conformance, DeviceLimits, testing::ValuesIn(device_params()), param_name);

}  // namespace
}  // namespace motes_conf
