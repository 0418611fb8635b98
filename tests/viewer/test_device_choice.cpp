// The viewer's choice of Vulkan device and queue family (viewer/src/device_choice.h), on made-up
// devices: a GPU without graphics queues, a window no family presents to, old devices, device
// types, --device, and the family preferred.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "device_choice.h"

namespace {

using motes::viewer::choose_device;
using motes::viewer::DeviceChoice;
using motes::viewer::DeviceFacts;

constexpr VkQueueFlags kGraphics = VK_QUEUE_GRAPHICS_BIT;
constexpr VkQueueFlags kCompute = VK_QUEUE_COMPUTE_BIT;
constexpr VkQueueFlags kTransfer = VK_QUEUE_TRANSFER_BIT;

/// A device of `type` and Vulkan `version` with a family of each of `flags` (one queue each),
/// presenting where `presents` says (none when empty).
DeviceFacts device(VkPhysicalDeviceType type, const std::vector<VkQueueFlags>& flags,
                   std::vector<bool> presents = {}, std::uint32_t version = VK_API_VERSION_1_3) {
  DeviceFacts d;
  d.api_version = version;
  d.type = type;
  for (const VkQueueFlags f : flags) {
    VkQueueFamilyProperties p{};
    p.queueFlags = f;
    p.queueCount = 1;
    d.families.push_back(p);
  }
  d.presents = std::move(presents);
  return d;
}

constexpr VkPhysicalDeviceType kDiscrete = VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU;
constexpr VkPhysicalDeviceType kIntegrated = VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU;
constexpr VkPhysicalDeviceType kCpu = VK_PHYSICAL_DEVICE_TYPE_CPU;

TEST(ViewDeviceChoice, AGpuWithoutGraphicsQueuesIsAOneLineError) {
  // A compute-only accelerator: compute and transfer families, no graphics.
  const DeviceChoice c =
      choose_device({device(kDiscrete, {kCompute | kTransfer, kTransfer, kCompute})}, false, -1);
  EXPECT_EQ(c.device, -1);
  EXPECT_EQ(c.error, "viewer: no Vulkan 1.2 device with a graphics queue");
  EXPECT_EQ(choose_device({}, false, -1).error,
            "viewer: no Vulkan 1.2 device with a graphics queue");
  // Asked for by --device, still not.
  EXPECT_EQ(choose_device({device(kDiscrete, {kCompute})}, false, 0).device, -1);
}

TEST(ViewDeviceChoice, AWindowNoFamilyPresentsToIsAOneLineError) {
  const DeviceChoice c =
      choose_device({device(kDiscrete, {kGraphics | kCompute, kCompute}, {false, true})}, true, -1);
  EXPECT_EQ(c.device, -1);
  EXPECT_EQ(c.error, "viewer: no Vulkan 1.2 device draws to this window");
  // Presenting is read only with a window: offscreen the same device draws.
  EXPECT_EQ(choose_device({device(kDiscrete, {kGraphics | kCompute}, {false})}, false, -1).device,
            0);
}

TEST(ViewDeviceChoice, AVulkan11DeviceIsSkipped) {
  const DeviceFacts old = device(kDiscrete, {kGraphics | kCompute}, {}, VK_API_VERSION_1_1);
  const DeviceChoice c = choose_device({old, device(kCpu, {kGraphics | kCompute})}, false, -1);
  EXPECT_EQ(c.device, 1);
  EXPECT_TRUE(c.error.empty());
  // Even when asked for.
  EXPECT_EQ(choose_device({old, device(kCpu, {kGraphics | kCompute})}, false, 0).device, 1);
  EXPECT_EQ(choose_device({old}, false, 0).error,
            "viewer: no Vulkan 1.2 device with a graphics queue");
  EXPECT_EQ(choose_device({device(kCpu, {kGraphics}, {}, VK_API_VERSION_1_2)}, false, -1).device,
            0);
}

TEST(ViewDeviceChoice, ADiscreteGpuRanksBeforeAnIntegratedOne) {
  const std::vector<DeviceFacts> three = {device(kCpu, {kGraphics | kCompute}),
                                          device(kIntegrated, {kGraphics | kCompute}),
                                          device(kDiscrete, {kGraphics | kCompute})};
  EXPECT_EQ(choose_device(three, false, -1).device, 2);
  EXPECT_EQ(choose_device({three[0], three[1]}, false, -1).device, 1);
  // Of two of one type, the first.
  EXPECT_EQ(choose_device({three[2], three[2]}, false, -1).device, 0);
}

TEST(ViewDeviceChoice, TheDeviceIndexWins) {
  const std::vector<DeviceFacts> two = {device(kDiscrete, {kGraphics | kCompute}),
                                        device(kCpu, {kGraphics})};
  const DeviceChoice c = choose_device(two, false, 1);
  EXPECT_EQ(c.device, 1);
  EXPECT_EQ(c.family, 0u);
  EXPECT_FALSE(c.family_computes);
  // An index out of range: the best.
  EXPECT_EQ(choose_device(two, false, 7).device, 0);
}

TEST(ViewDeviceChoice, AFamilyThatAlsoComputesIsPreferred) {
  DeviceChoice c = choose_device(
      {device(kDiscrete, {kGraphics, kTransfer, kGraphics | kCompute | kTransfer})}, false, -1);
  EXPECT_EQ(c.device, 0);
  EXPECT_EQ(c.family, 2u);
  EXPECT_TRUE(c.family_computes);
  // None computes: the first graphics family.
  c = choose_device({device(kDiscrete, {kCompute, kGraphics, kGraphics})}, false, -1);
  EXPECT_EQ(c.family, 1u);
  EXPECT_FALSE(c.family_computes);
  // With a window, among the families that present.
  c = choose_device({device(kDiscrete, {kGraphics | kCompute, kGraphics, kGraphics | kCompute},
                            {false, true, true})},
                    true, -1);
  EXPECT_EQ(c.family, 2u);
  EXPECT_TRUE(c.family_computes);
  c = choose_device({device(kDiscrete, {kGraphics | kCompute, kGraphics}, {false, true})}, true,
                    -1);
  EXPECT_EQ(c.family, 1u);
  EXPECT_FALSE(c.family_computes);
}

}  // namespace
