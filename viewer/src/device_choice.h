// Which physical device and queue family the viewer draws with (Gpu::open), as a function of
// plain data so that it can be tested without such devices.
#pragma once

#include <vulkan/vulkan_core.h>

#include <cstdint>
#include <string>
#include <vector>

namespace motes::viewer {

/// What Gpu::open reads of one physical device.
struct DeviceFacts {
  std::uint32_t api_version = 0;
  VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  std::vector<VkQueueFamilyProperties> families;
  /// Per family: it presents to the window's surface (read only with a surface; may be short).
  std::vector<bool> presents;
};

/// The device and family chosen, or why none could be (a one-line message).
struct DeviceChoice {
  int device = -1;  ///< index into the facts; -1: none, see `error`
  std::uint32_t family = 0;
  bool family_computes = false;  ///< the family has compute too
  std::string error;
};

/// Among the Vulkan 1.2 devices with a graphics family (that presents, when `surface`): device
/// `wanted` when it is one of them, else the first of the best type (discrete, integrated,
/// virtual, CPU, other); on it, the first such family that also computes, else the first such.
DeviceChoice choose_device(const std::vector<DeviceFacts>& devices, bool surface, int wanted);

}  // namespace motes::viewer
