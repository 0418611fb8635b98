// What the registry needs from the CUDA backend: the device list and opening one.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "motes/backend/device.h"
#include "motes/status.h"

namespace motes::cuda {

/// The CUDA devices of this machine, or why there are none (no driver, no GPU...).
struct Listing {
  std::vector<DeviceInfo> devices;  ///< in CUDA's device order; DeviceInfo::index is that order
  std::string reason;               ///< why `devices` is empty
};

Listing list_devices();

/// Opens device `index` (-1: MOTES_CUDA_DEVICE if set, else device 0).
Result<std::unique_ptr<Device>> open_device(int index);

}  // namespace motes::cuda
