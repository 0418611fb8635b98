// The viewer's choice of physical device and queue family (device_choice.h).
#include "device_choice.h"

namespace motes::viewer {

namespace {

int type_rank(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return 3;
    default:
      return 4;
  }
}

}  // namespace

DeviceChoice choose_device(const std::vector<DeviceFacts>& devices, bool surface, int wanted) {
  DeviceChoice best;
  int best_rank = 1000;
  for (std::size_t d = 0; d < devices.size(); ++d) {
    const DeviceFacts& dev = devices[d];
    if (dev.api_version < VK_API_VERSION_1_2) continue;
    // A graphics family that presents; one that computes too ranks first.
    int chosen = -1;
    bool computes = false;
    for (std::size_t f = 0; f < dev.families.size(); ++f) {
      const VkQueueFlags flags = dev.families[f].queueFlags;
      if ((flags & VK_QUEUE_GRAPHICS_BIT) == 0) continue;
      if (surface && !(f < dev.presents.size() && dev.presents[f])) continue;
      computes = (flags & VK_QUEUE_COMPUTE_BIT) != 0;
      if (chosen < 0 || computes) chosen = static_cast<int>(f);
      if (computes) break;
    }
    if (chosen < 0) continue;
    const int rank = static_cast<int>(d) == wanted ? -1 : type_rank(dev.type);
    if (rank < best_rank) {
      best_rank = rank;
      best.device = static_cast<int>(d);
      best.family = static_cast<std::uint32_t>(chosen);
      best.family_computes = computes;
    }
  }
  if (best.device < 0) {
    best.error = surface ? "viewer: no Vulkan 1.2 device draws to this window"
                         : "viewer: no Vulkan 1.2 device with a graphics queue";
  }
  return best;
}

}  // namespace motes::viewer
