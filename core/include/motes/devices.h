// The backend registry: which backends were built, their devices, and opening one.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "motes/api.h"
#include "motes/backend/device.h"
#include "motes/status.h"

MOTES_API_BEGIN
namespace motes {

/// What `motes devices` prints for one backend.
struct BackendReport {
  std::string backend;              ///< "openmp", "cuda", "vulkan"
  bool compiled = false;            ///< built into this binary
  std::vector<DeviceInfo> devices;  ///< empty when unavailable
  std::string unavailable_reason;   ///< why there are no devices (not built, no driver, ...)
};

/// Every backend motes knows, in preference order (cuda, vulkan, openmp).
std::vector<BackendReport> list_backends();

/// Options for opening a device.
struct DeviceOptions {
  int cpu_threads = 0;  ///< OpenMP backend threads; 0 = OpenMP's default (OMP_NUM_THREADS or cores)
  /// OpenMP backend: loops over fewer items run on one thread (-1: the backend's default, 2048).
  int cpu_min_parallel = -1;
};

/// Opens device `index` (-1: the backend's default) of `backend`; "auto" picks a Vulkan GPU when
/// there is one, else the CPU backend (OpenMP is faster than a CPU Vulkan driver).
Result<std::unique_ptr<Device>> open_device(const std::string& backend, int index = -1,
                                            const DeviceOptions& options = {});

}  // namespace motes
MOTES_API_END
