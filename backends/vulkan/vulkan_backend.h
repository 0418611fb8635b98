// What the registry needs from the Vulkan backend: the device list and opening one.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "motes/backend/device.h"
#include "motes/status.h"

namespace motes::vulkan {

/// The Vulkan devices of this machine, or why there are none.
struct Listing {
  std::vector<DeviceInfo> devices;  ///< in the loader's order; DeviceInfo::index is that order
  int preferred = -1;               ///< discrete GPU, then integrated, then virtual, then CPU
  bool preferred_is_gpu = false;    ///< false when the best device is a CPU (lavapipe)
  std::string reason;               ///< why `devices` is empty
};

Listing list_devices();

/// Opens device `index` (-1: MOTES_VULKAN_DEVICE if set, else the preferred device).
/// MOTES_VULKAN_VALIDATION=1 turns on the Khronos validation layer with synchronization
/// validation; every message it prints then makes synchronize() fail.
Result<std::unique_ptr<Device>> open_device(int index);

}  // namespace motes::vulkan
