// Device limits before allocation through Simulation::create (docs/reliability.md, "Device
// limits"), on the openmp device with less memory than it has: a forwarding device that reports
// a few MiB available, so that the whole path runs without allocating gigabytes. The real limits
// of every device (host memory, lavapipe's maxStorageBufferRange) are tested in
// tests/conformance/test_device_limits.cpp.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <regex>
#include <string>

#include "motes/backend/device.h"
#include "motes/devices.h"
#include "motes/scene.h"
#include "motes/simulation.h"

namespace {

using motes::Buffer;
using motes::Sizes;
using motes::Status;
using motes::shared::StepParams;

/// The openmp device, reporting `available` bytes of memory and passing everything else on.
class LimitedDevice final : public motes::Device {
 public:
  /// `allocations` (optional) counts the calls to allocate(); it is owned by the caller so that
  /// it outlives a device that Simulation::create destroys when it refuses.
  LimitedDevice(std::unique_ptr<motes::Device> inner, std::uint64_t available,
                int* allocations = nullptr)
      : inner_(std::move(inner)), available_(available), allocations_(allocations) {}
  [[nodiscard]] const motes::DeviceInfo& info() const override { return inner_->info(); }
  [[nodiscard]] std::uint64_t required_bytes(const Sizes& s) const override {
    return inner_->required_bytes(s);
  }
  [[nodiscard]] std::uint64_t available_bytes() const override { return available_; }
  [[nodiscard]] motes::BufferSize largest_buffer(const Sizes& s) const override {
    return inner_->largest_buffer(s);
  }
  [[nodiscard]] motes::BufferLimit buffer_limit() const override { return inner_->buffer_limit(); }
  Status allocate(const Sizes& s) override {
    if (allocations_ != nullptr) ++*allocations_;
    return inner_->allocate(s);
  }
  Status write(Buffer b, const void* src, std::size_t n) override {
    return inner_->write(b, src, n);
  }
  Status read(Buffer b, void* dst, std::size_t n) override { return inner_->read(b, dst, n); }
  void enqueue(motes::Kernel k, const StepParams& p) override { inner_->enqueue(k, p); }
  [[nodiscard]] bool supports(motes::Kernel k) const override {
    return k != unsupported && inner_->supports(k);
  }
  /// A family this device claims not to run (Kernel::Count: none).
  motes::Kernel unsupported = motes::Kernel::Count;
  Status synchronize() override { return inner_->synchronize(); }
  Status check_guards() override { return inner_->check_guards(); }
  void set_timing(bool on) override { inner_->set_timing(on); }
  [[nodiscard]] motes::KernelTimes kernel_times() const override { return inner_->kernel_times(); }
  void reset_kernel_times() override { inner_->reset_kernel_times(); }

 private:
  std::unique_ptr<motes::Device> inner_;
  std::uint64_t available_;
  int* allocations_;
};

constexpr std::uint64_t kAvailable = 4u << 20;  // 4 MiB

std::unique_ptr<LimitedDevice> limited_openmp(int* allocations = nullptr) {
  auto opened = motes::open_device("openmp");
  EXPECT_TRUE(opened) << opened.message();
  return std::make_unique<LimitedDevice>(std::move(opened).value(), kAvailable, allocations);
}

/// `boxes` boxes of 3 x 3 x 3 particles (rigid) and `spheres` free spheres of 1 cm.
motes::Scene scene(std::int64_t boxes, std::int64_t spheres) {
  std::string bodies = fmt::format(
      R"({{"name": "grain", "shape": {{"type": "particle"}}, "material": "m",
          "position": [0, 0.1, 0], "repeat": {{"count": {}, "offset": [0.011, 0, 0]}}}})",
      spheres);
  if (boxes > 0) {
    bodies += fmt::format(
        R"(, {{"name": "box", "shape": {{"type": "box", "particles": [3, 3, 3]}}, "material": "m",
              "repeat": {{"count": {}, "offset": [0.04, 0, 0]}}}})",
        boxes);
  }
  const std::string text = fmt::format(
      R"({{"settings": {{"dt": 5e-5, "particle_diameter": 0.01,
                        "contact": {{"stiffness": 500, "damping": 50}}}},
          "materials": {{"m": {{"density": 700}}}}, "bodies": [{}]}})",
      bodies);
  motes::Result<motes::Scene> s = motes::load_scene_text(text, "limits.json", "");
  EXPECT_TRUE(s) << s.message();
  return s ? std::move(s).value() : motes::Scene{};
}

std::int64_t number_in(const std::string& text, const std::string& pattern) {
  std::smatch m;
  if (!std::regex_search(text, m, std::regex(pattern))) return -1;
  return std::stoll(m[1].str());
}

TEST(DeviceLimits, ScaledSizesKeepTheSceneProportions) {
  Sizes s;
  s.particles = 1000;
  s.rigid_particles = 540;
  s.bodies = 20;
  s.soft_particles = 100;
  s.constraints = 3000;
  s.clusters = 10;
  s.cluster_members = 400;
  s.materials = 3;
  s.planes = 2;
  s.neighbour_capacity = 16;
  s.table = motes::grid_table_size(1000);
  s.halo_index = 300;
  s.halo_data = 800;
  s.partition = 1;
  const Sizes half = motes::scale_sizes(s, 500);
  EXPECT_EQ(half.particles, 500u);
  EXPECT_EQ(half.rigid_particles, 270u);
  EXPECT_EQ(half.bodies, 10u);
  EXPECT_EQ(half.soft_particles, 50u);
  EXPECT_EQ(half.constraints, 1500u);
  EXPECT_EQ(half.clusters, 5u);
  EXPECT_EQ(half.cluster_members, 200u);
  EXPECT_EQ(half.materials, 3u);
  EXPECT_EQ(half.planes, 2u);
  EXPECT_EQ(half.neighbour_capacity, 16u);
  EXPECT_EQ(half.table, motes::grid_table_size(500));
  EXPECT_EQ(half.halo_index, 150u);
  EXPECT_EQ(half.halo_data, 400u);
  EXPECT_EQ(half.partition, 1u);
  EXPECT_EQ(motes::scale_sizes(s, 0).particles, 0u);
}

// The buffers of runs over MPI ranks: empty in one process (every Sizes field 0), so a scene
// needs the same bytes as before they existed; sized by Sizes when a rank asks for them.
TEST(DeviceLimits, HaloAndPartitionBuffersAreEmptyInOneProcess) {
  Sizes s;
  s.particles = 1000;
  s.bodies = 20;
  s.table = motes::grid_table_size(1000);
  for (const Buffer b :
       {Buffer::HaloIndex, Buffer::HaloData, Buffer::PartitionRefPos, Buffer::PartitionCheck}) {
    EXPECT_EQ(motes::buffer_layout(b, s).bytes(), 0u) << motes::buffer_name(b);
  }
  const std::uint64_t single = motes::buffers_bytes(s);
  s.halo_index = 300;
  s.halo_data = 800;
  s.partition = 1;
  EXPECT_EQ(motes::buffer_layout(Buffer::HaloIndex, s).bytes(), 300u * 4u);
  EXPECT_EQ(motes::buffer_layout(Buffer::HaloData, s).bytes(), 800u * 16u);
  EXPECT_EQ(motes::buffer_layout(Buffer::PartitionRefPos, s).bytes(), 1000u * 16u);
  EXPECT_EQ(motes::buffer_layout(Buffer::PartitionCheck, s).bytes(), 4u);
  EXPECT_EQ(motes::buffers_bytes(s), single + 300u * 4u + 800u * 16u + 1000u * 16u + 4u);
}

// The GPU backends' launch guard for the families of runs over MPI ranks: entries beyond
// HaloIndex or HaloData, particles or bodies beyond theirs, a displacement without the
// partition's buffers are named; a call that fits, and every other family, pass.
TEST(DeviceLimits, HaloLaunchesBeyondTheirBuffersAreNamed) {
  Sizes s;
  s.particles = 100;
  s.bodies = 10;
  s.halo_index = 20;
  s.halo_data = 2 * 8 + 5 * 4;
  StepParams p{};
  p.particle_count = 100;
  p.body_count = 10;
  p.halo_first = 8;
  p.halo_particles = 8;
  p.halo_bodies = 4;
  using motes::Kernel;
  EXPECT_EQ(motes::halo_launch_error(Kernel::HaloPack, p, s), "");  // exactly fits
  EXPECT_EQ(motes::halo_launch_error(Kernel::HaloUnpack, p, s), "");
  p.halo_first = 9;  // one word past HaloIndex
  EXPECT_NE(motes::halo_launch_error(Kernel::HaloPack, p, s).find("HaloIndex word 9 (21 words"),
            std::string::npos);
  EXPECT_NE(motes::halo_launch_error(Kernel::HaloUnpack, p, s), "");
  EXPECT_EQ(motes::halo_launch_error(Kernel::ContactsCompute, p, s), "");  // not its business
  p.halo_first = 0;
  p.halo_bodies = 5;  // 21 words fit, 41 vec4s do not
  EXPECT_NE(motes::halo_launch_error(Kernel::HaloPack, p, s).find("41 vec4s"), std::string::npos);
  p.halo_bodies = 4;
  p.body_count = 11;
  EXPECT_NE(motes::halo_launch_error(Kernel::HaloUnpack, p, s), "");
  p.body_count = 10;
  EXPECT_NE(motes::halo_launch_error(Kernel::ParticlesDisplacement, p, s).find("partition"),
            std::string::npos);
  s.partition = 1;
  EXPECT_EQ(motes::halo_launch_error(Kernel::ParticlesDisplacement, p, s), "");
  p.particle_count = 101;
  EXPECT_NE(motes::halo_launch_error(Kernel::ParticlesDisplacement, p, s), "");
}

// Every backend's launch guard for energy_reduce: parameters with more items (bodies, then the
// particles that are not a rigid body's) than EnergyPartials has blocks for are named; the
// allocation's own parameters, fewer items, and every other family pass.
TEST(DeviceLimits, EnergyReduceBeyondItsBlocksIsNamed) {
  Sizes s;
  s.particles = 300;
  s.rigid_particles = 100;
  s.bodies = 10;  // 10 + 200 items: one block of 256
  EXPECT_EQ(motes::buffer_layout(motes::Buffer::EnergyPartials, s).count, 4u + 4u);
  StepParams p{};
  p.particle_count = 300;
  p.rigid_particle_count = 100;
  p.body_count = 10;
  using motes::Kernel;
  EXPECT_EQ(motes::energy_launch_error(Kernel::EnergyReduce, p, s), "");
  p.rigid_particle_count = 54;  // 256 items: still one block
  EXPECT_EQ(motes::energy_launch_error(Kernel::EnergyReduce, p, s), "");
  p.rigid_particle_count = 53;  // 257 items: a second block EnergyPartials does not have
  EXPECT_NE(motes::energy_launch_error(Kernel::EnergyReduce, p, s).find("energy_reduce launched"),
            std::string::npos);
  EXPECT_EQ(motes::energy_launch_error(Kernel::ParticlesCheck, p, s), "");  // not its business
  p.rigid_particle_count = 100;
  p.body_count = 11;
  EXPECT_NE(motes::energy_launch_error(Kernel::EnergyReduce, p, s), "");
  p.body_count = 10;
  p.particle_count = 301;
  EXPECT_NE(motes::energy_launch_error(Kernel::EnergyReduce, p, s), "");
  p.particle_count = 99;  // fewer particles than rigid ones
  EXPECT_NE(motes::energy_launch_error(Kernel::EnergyReduce, p, s), "");
}

// More than the device has: refused before any allocation, naming the scene, both numbers and
// the largest count; a scene of that many free spheres is created on the same device.
TEST(DeviceLimits, SimulationRefusesMoreThanTheDeviceHasBeforeAllocating) {
  int allocations = 0;
  auto device = limited_openmp(&allocations);
  const motes::Scene big = scene(0, 40000);
  auto refused = motes::Simulation::create(big, std::move(device));
  ASSERT_FALSE(refused);
  const std::string& msg = refused.message();
  EXPECT_EQ(allocations, 0) << "refused after allocating";
  EXPECT_NE(msg.find("limits.json: 40000 particles do not fit on openmp device 0"),
            std::string::npos)
      << msg;
  const std::int64_t need =
      number_in(msg, R"(would need [0-9.]+ MiB \(([0-9]+) bytes\) of device memory)");
  EXPECT_GT(need, static_cast<std::int64_t>(kAvailable)) << msg;
  EXPECT_NE(msg.find(fmt::format("the device has 4.00 MiB ({} bytes) available", kAvailable)),
            std::string::npos)
      << msg;
  const std::int64_t largest = number_in(msg, R"(at most ([0-9]+) particles fit)");
  ASSERT_GT(largest, 1000) << msg;
  ASSERT_LT(largest, 40000) << msg;

  auto fits = motes::Simulation::create(scene(0, largest), limited_openmp());
  ASSERT_TRUE(fits) << fits.message();
  const Status stepped = fits.value()->step(2);
  EXPECT_TRUE(stepped) << stepped.message();
  auto one_more = motes::Simulation::create(scene(0, largest + 1), limited_openmp());
  EXPECT_FALSE(one_more);
}

// A device that does not run a family the simulation may call is refused before anything is
// allocated, naming the family.
TEST(DeviceLimits, SimulationRefusesADeviceWithoutAFamily) {
  int allocations = 0;
  auto device = limited_openmp(&allocations);
  device->unsupported = motes::Kernel::ClustersGoal;
  auto refused = motes::Simulation::create(scene(2, 10), std::move(device));
  ASSERT_FALSE(refused);
  EXPECT_EQ(allocations, 0) << "refused after allocating";
  EXPECT_NE(refused.message().find(
                "limits.json: the openmp device does not run the kernel family clusters_goal"),
            std::string::npos)
      << refused.message();
}

// A scene of rigid boxes and free spheres: the largest count keeps the proportions (here a box
// of 27 particles per 100 spheres), and such a scene fits.
TEST(DeviceLimits, LargestCountOfAMixedSceneFits) {
  auto refused = motes::Simulation::create(scene(400, 40000), limited_openmp());
  ASSERT_FALSE(refused);
  const std::int64_t largest = number_in(refused.message(), R"(at most ([0-9]+) particles fit)");
  ASSERT_GT(largest, 0) << refused.message();
  // In the scene's proportions: 27 x 400 of 50,800 particles are the boxes'.
  const std::int64_t boxes = largest * 400 / 50800;
  const std::int64_t spheres = largest - 27 * boxes;
  auto fits = motes::Simulation::create(scene(boxes, spheres), limited_openmp());
  ASSERT_TRUE(fits) << fits.message();
}

// The real host memory: a few hundred particles fit (MemAvailable of /proc/meminfo).
TEST(DeviceLimits, OpenmpReportsTheHostsAvailableMemory) {
  auto opened = motes::open_device("openmp");
  ASSERT_TRUE(opened) << opened.message();
  const std::uint64_t have = opened.value()->available_bytes();
  EXPECT_GT(have, std::uint64_t{16} << 20);
  EXPECT_EQ(opened.value()->buffer_limit().bytes, UINT64_MAX);
  auto sim = motes::Simulation::create(scene(2, 100), std::move(opened).value());
  EXPECT_TRUE(sim) << sim.message();
}

}  // namespace
